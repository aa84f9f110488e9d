"""Where a mesh stiffness comes from: the registry of sources (``sources``), the
FE-calibrated tables (``calibration``, ``tables``) and the comparison of the FE with the
analytic models (``comparison``)."""

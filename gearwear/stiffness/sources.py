"""Where a mesh stiffness comes from: the method names the command line (``gearwear stiffness
--method``), the Python API (``gw.mesh_stiffness(method=...)``) and the reports accept, and the
pair FE's default resolution. One place, so the callers cannot drift apart."""

#: the stiffness methods: the slice model (Ishikawa/Weber), the potential-energy method, ISO 6336-1
#: method B (one constant) and the resolved pair FE
METHODS = ("ishikawa", "energy", "iso6336", "fem")

#: pair-FE positions per mesh period unless a command says otherwise (the 24-position cycle of the
#: paper pair: docs/accuracy-and-cost.md)
FE_POSITIONS = 24

"""Trend claims of the papers this tool reproduces (TOML), shipped as package data:
``paper.toml``, Zhang et al. (2019), read by gearwear.reports.paper. Not scenes: those
are the ``*.toml`` of gearwear.data."""

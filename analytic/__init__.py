"""Analytic mesh-stiffness models (Ishikawa slices, potential energy, ISO 6336).

``TABLE_POINTS_PER_MESH_PERIOD``: the default number of uniform nodes per mesh period of
the k_h(phi), e(phi) tables of analytic.tvms (the breakpoints of the load sharing come on
top). Chosen by the convergence study benchmarks/bench_table_points.py; here, not in
tvms, so that the scene schema can read it without importing the models."""

TABLE_POINTS_PER_MESH_PERIOD = 360

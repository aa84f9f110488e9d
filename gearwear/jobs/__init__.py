"""The commands' computations and their files, one module per job (geometry, stiffness,
verify, simulate, sweep, run-up); each takes a resolved scene and returns plain results."""

"""The commands' computations and their files, one module per job (geometry, stiffness,
verify, simulate, sweep, run-up); each takes a resolved scene and returns plain results."""

#: directions of a run-up (gearwear.jobs.runup); here, not in the job module, so that the
#: command line builds its parser without importing the job's dependencies (scipy, the scene model)
RUNUP_DIRECTIONS = ("up", "down", "both")

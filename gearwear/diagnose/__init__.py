"""Estimating wear depth and bearing clearance from a measured vibration: the features of a
signal, the surrogate of the simulation, the posterior, the measurement plan and the plots."""

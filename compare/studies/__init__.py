"""Studies made of many runs or comparisons: sweeps, Monte Carlo, calibration, uncertainty, sensitivity,
Campbell diagrams."""

"""Studies made of many runs or comparisons: sweeps, Monte Carlo, calibration, uncertainty, sensitivity,
Campbell diagrams."""

from gearcheck.shared.public import public  # noqa: E402

# the public names: the uncertainty study and its statistics
__all__, __getattr__, __dir__ = public(__name__, {
    "uncertainty_study": "uncertainty", "band": "uncertainty", "drivers": "uncertainty", "NOMINAL": "uncertainty",
})

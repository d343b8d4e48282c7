"""Studies made of many runs or comparisons: sweeps, Monte Carlo, calibration, uncertainty, sensitivity,
Campbell diagrams."""

from gearcheck.shared.public import public  # noqa: E402

# the public names: the uncertainty study and its statistics; order tracking and what a run-up's rate does
__all__, __getattr__, __dir__ = public(__name__, {
    "uncertainty_study": "uncertainty", "band": "uncertainty", "drivers": "uncertainty", "NOMINAL": "uncertainty",
    "order_track": "order_tracking", "waterfall": "order_tracking", "against_sweep": "order_curves",
    "resonance_speeds": "order_curves", "sweep_effect": "order_curves", "passage": "resonance_passage",
})

"""The comparison engine: two sides of one train run, aligned, measured and judged against tolerances."""

from gearcheck.shared.public import public  # noqa: E402

# the public names: the diagnosis of a model, the projection of a series on its lines, and the plan that says where
# a train's signals jump
__all__, __getattr__, __dir__ = public(__name__, {
    "diagnose": "diagnosis", "Evidence": "diagnosis", "COEFFICIENT_FLOOR": "diagnosis", "harmonics": "line_projection",
    "TrainPlan": "plan",
})

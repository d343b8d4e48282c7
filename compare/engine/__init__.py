"""The comparison engine: two sides of one train run, aligned, measured and judged against tolerances."""

from gearcheck.shared.public import public  # noqa: E402

# the public names: the diagnosis of a model and the projection of a series on its lines
__all__, __getattr__, __dir__ = public(__name__, {
    "diagnose": "diagnosis", "Evidence": "diagnosis", "COEFFICIENT_FLOOR": "diagnosis", "harmonics": "line_projection",
})

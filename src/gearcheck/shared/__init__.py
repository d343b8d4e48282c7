"""The floor both solvers stand on: errors, units, citations, the run settings, the result types,
the step rule, contact laws, the modal eigenproblem and Anderson acceleration.  Nothing here knows either solver's
equations, so the lumped model and the MuJoCo twin may both import it and stay independent."""

from gearcheck.shared.public import public  # noqa: E402

# the public names: what a time run is asked for
__all__, __getattr__, __dir__ = public(__name__, {
    "RunSettings": "settings",
})

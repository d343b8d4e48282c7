"""gearcheck's train description and reference lumped-parameter solver."""

from .assembly import LumpedModel, build_model
from .errors import DivergenceError, GearcheckError, SolverError, TrainFileError
from .kinematics import Kinematics, kinematics
from .loader import load_text, load_train, preset_names
from .spec import TrainSpec

__all__ = [
    "DivergenceError", "GearcheckError", "Kinematics", "LumpedModel", "SolverError", "TrainFileError",
    "TrainSpec", "build_model", "kinematics", "load_text", "load_train", "preset_names",
]

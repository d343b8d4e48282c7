"""gearcheck: cross-verify lumped-parameter gear-train models against MuJoCo multibody twins.

>>> import gearcheck
>>> result = gearcheck.crosscheck("demo-3p", duration=0.05)
>>> result.verdict
'PASS'

The front door:

* :class:`Train` -- a session: one train, its lumped model and MuJoCo twin built once, every study below a
  method (``modes``, ``simulate``, ``crosscheck``, ``campbell``, ``mac``, ``harmonic_response``, ``ste``,
  ``relief_sweep``, ``sweep``, ``animate``, ``view``, ``mjcf``, ``describe``, ``pin_loads``, ``stiffness``);
  every result draws itself with ``plot()`` (a matplotlib
  Figure, no pyplot) and a DataFrame carries its columns' units in ``attrs["units"]``;
* :func:`load` -- a train (preset name, train file, or TrainSpec), validated; :func:`load_text` one from TOML text,
  :func:`preset_text` a preset's text, :func:`edited` a preset with its text edited (pattern, replacement);
* :func:`kinematics`, :class:`Excitation` -- a train's nominal speeds and mesh frequencies, and its excitation
  (mesh stiffness and transmission error over time): the pieces of a user's own model;
* :func:`modes` -- natural frequencies and mode types, either solver;
* :func:`simulate` -- a time run, either solver: a :class:`TimeResult` with named signals; :func:`simulate_batch`
  the MuJoCo twin at many speeds at once (MJX, on a GPU where JAX has one);
* :func:`mjcf` -- the MuJoCo model of a train;
* :func:`crosscheck` -- both solvers compared, with measurements, tolerances and baselines;
* :func:`harmonic_response`, :func:`sensitivity` -- the steady forced response by harmonic methods and its
  derivatives to the numbers of a train file;
* :func:`sweep` -- speed sweeps, parameter studies and Monte Carlo, cached, on local processes or Dask;
* :func:`runup` -- a run-up through a speed ramp in both solvers, its mesh orders tracked; ``load(...,
  speed_profile=, torque_profile=, load_profile=)`` any operating history, :func:`preset_data` the presets' data;
* :func:`write_report` -- report.json, report.md, report.html and figures of a cross-check;
* :func:`describe`, :func:`pin_loads`, :func:`calibrate`, :func:`dashboard` -- what a train derives from its file,
  an RV reducer's static pin loads, a least-squares calibration to measurements, the regression dashboard;
* :func:`trust`, :func:`allow_data` -- a train file is data: the Python code it names runs only from modules you
  trust, and the files it names lie beside it or in folders you allow.

Every command of the command line is one of these (``ste``, ``animate``, ``view`` and ``stiffness`` are
:class:`Train` methods).

Packages: :mod:`gearcheck.train` (the train description), :mod:`gearcheck.lumped` (the reference solver),
:mod:`gearcheck.mbd_models` (the MuJoCo twin), :mod:`gearcheck.compare` (the cross-check, its studies and their
presentation), :mod:`gearcheck.shared` (what every package shares).
"""

import os
from importlib import import_module, metadata
from typing import TYPE_CHECKING

from gearcheck.shared.public import public

# MuJoCo picks its OpenGL platform when it is imported: without a display, offscreen rendering (animations)
# goes through EGL unless the user chose otherwise
if "MUJOCO_GL" not in os.environ and not (os.environ.get("DISPLAY") or os.environ.get("WAYLAND_DISPLAY")):
    os.environ["MUJOCO_GL"] = "egl"

__version__ = metadata.version("gearcheck")
_PACKAGES = ("train", "lumped", "mbd_models", "compare", "shared")
_DEFINED_IN = {  # module -> the public names it defines, imported on first use: ``gearcheck --version`` loads none
    "api": ("SOLVERS", "calibrate", "campbell", "crosscheck", "dashboard", "describe", "export_model",
            "harmonic_response", "load", "mjcf", "mode_pairing", "modes", "pin_loads", "preset_data", "presets",
            "runup", "sensitivity", "simulate", "simulate_batch", "sweep", "write_report"),
    "compare.engine.comparison": ("CrosscheckResult",),
    "lumped.linear_model": ("LinearModel", "Mesh", "Periodic"),
    "session": ("Train",),
    "train.excitation": ("Excitation",),
    "train.kinematics": ("kinematics",),
    "train.loader": ("load_text", "preset_text"),
    "train.spec": ("TrainSpec",),
    "train.variants": ("edited",),
    "shared.errors": ("DivergenceError", "GearcheckError", "SolverError", "TrainFileError"),
    "shared.modal": ("ModalResult",),
    "shared.results": ("TimeResult",),
    "shared.trust": ("allow_data", "trust"),
}
_, _public_name, _ = public(__name__, {name: module for module, names in _DEFINED_IN.items() for name in names})

if TYPE_CHECKING:  # what type checkers read; at run time :func:`__getattr__` imports each name when first asked
    from gearcheck.api import (
                               SOLVERS,
                               calibrate,
                               campbell,
                               crosscheck,
                               dashboard,
                               describe,
                               export_model,
                               harmonic_response,
                               load,
                               mjcf,
                               mode_pairing,
                               modes,
                               pin_loads,
                               preset_data,
                               presets,
                               runup,
                               sensitivity,
                               simulate,
                               simulate_batch,
                               sweep,
                               write_report,
    )
    from gearcheck.compare.engine.comparison import CrosscheckResult
    from gearcheck.lumped.linear_model import LinearModel, Mesh, Periodic
    from gearcheck.session import Train
    from gearcheck.train.excitation import Excitation
    from gearcheck.train.kinematics import kinematics
    from gearcheck.train.loader import load_text, preset_text
    from gearcheck.train.spec import TrainSpec
    from gearcheck.train.variants import edited
    from gearcheck.shared.errors import DivergenceError, GearcheckError, SolverError, TrainFileError
    from gearcheck.shared.modal import ModalResult
    from gearcheck.shared.results import TimeResult
    from gearcheck.shared.trust import allow_data, trust


def __getattr__(name: str):
    """A public name, or a package beneath (``gearcheck.lumped``), imported when first asked for (PEP 562)."""
    return import_module(f"{__name__}.{name}") if name in _PACKAGES else _public_name(name)


def __dir__() -> list[str]:
    """The front door and the packages beneath it, not the modules this file imports (``os``, ``metadata``)."""
    return sorted({*__all__, *_PACKAGES})


__all__ = ["SOLVERS", "CrosscheckResult", "DivergenceError", "Excitation", "GearcheckError", "LinearModel", "Mesh",
           "ModalResult", "Periodic", "SolverError", "TimeResult", "Train", "TrainFileError", "TrainSpec",
           "__version__", "allow_data", "calibrate", "campbell", "crosscheck", "dashboard", "describe", "edited",
           "export_model", "harmonic_response", "kinematics", "load", "load_text", "mjcf", "mode_pairing", "modes",
           "pin_loads", "preset_data", "preset_text", "presets", "runup", "sensitivity", "simulate", "simulate_batch",
           "sweep", "trust", "write_report"]

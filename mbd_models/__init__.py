"""gearcheck's MuJoCo half: the same train as real rigid bodies on real joints.

An independent second derivation of the train: the MJCF is generated from the train
description only (:mod:`lumped.spec`, description-level geometry and kinematics, and
the excitation functions of :mod:`lumped.excitation`); the dynamics, the mesh
deflection coefficients, the linearisation and the static state all come from
MuJoCo itself, never from the lumped model's matrices or equations.

* :func:`build_mjcf` -- deterministic MJCF text of a train;
* :func:`compile_train` -- the compiled model with named indices (bodies, joints, tendons);
* :func:`simulate_mujoco` -- the driven MuJoCo run, returning a :class:`lumped.results.TimeResult`;
* :func:`mujoco_modes` -- natural frequencies of MuJoCo's own linearisation.
"""

from .linearise import mujoco_modes
from .mjcf_builder import MbdModel, build_mjcf, compile_train
from .runner import simulate_mujoco, static_state

__all__ = ["MbdModel", "build_mjcf", "compile_train", "mujoco_modes", "simulate_mujoco", "static_state"]

"""The train description: what both models are built from, and nothing of either model's equations.

* ``schema``, ``files``, ``loader``, ``spec`` -- train files read, bounded and validated into a
  :class:`~gearcheck.train.spec.TrainSpec` in SI units (``json_schema`` and ``docs`` publish the format);
* ``geometry``, ``line_of_action``, ``kinematics``, ``cycloid`` -- involute and cycloid geometry, nominal
  speeds, flanks and mesh frequencies;
* ``mesh_stiffness`` (with ``tooth_stiffness``, ``helical_mesh``, ``tooth_pairs`` and ``iso6336``) and
  ``excitation`` -- time-varying mesh stiffness and transmission error as functions of the nominal clock;
* ``periods`` -- the drive's frequencies and its common period, over which both sides shoot for a periodic
  steady state;
* ``published_parameters`` -- the 4-DOF model of Matejic et al. (2021) read from a train;
* ``variants`` -- a train file with numbers changed by path (sweeps, calibration);
* ``presets`` -- the shipped trains.

It imports only :mod:`gearcheck.shared`; :mod:`gearcheck.lumped` and :mod:`gearcheck.mbd_models` both
import it and never each other (the import contracts in ``pyproject.toml``).
"""

from gearcheck.shared.public import public  # noqa: E402

# the public names: the axial coordinate's name
__all__, __getattr__, __dir__ = public(__name__, {
    "AXIAL": "spec",
})

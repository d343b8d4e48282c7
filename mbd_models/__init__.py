"""gearcheck's MuJoCo half: the same train as real rigid bodies on real joints.

An independent second derivation of the train: the MJCF is generated from the train description only
(:mod:`gearcheck.train`: the spec, geometry, kinematics and excitation functions); the dynamics, the mesh deflection
coefficients, the linearisation, the static state and the forces all come from MuJoCo itself, never from the lumped
model's matrices or equations: nothing here imports :mod:`gearcheck.lumped`, at any depth (the import contracts in
``pyproject.toml``).

* ``elements`` -- one file per kind of part: what it writes into the MJCF, and its contacts at run time;
* ``mjcf_text``, ``mjcf_builder`` -- the MJCF vocabulary and the text of a whole train;
* ``twin`` -- :func:`~gearcheck.mbd_models.twin.compile_train`, the compiled twin with named indices;
* ``linearise`` -- MuJoCo's own M and K, natural frequencies and the highest one;
* ``runner`` with ``compiled`` -- the driven run, its loop compiled;
* ``static_state`` -- the steady rotating state at the operating point (the runner's start);
* ``periodic_state`` -- the periodic steady state by shooting on the twin's own runs;
* ``forces`` -- mesh and bearing forces read from MuJoCo's generalized forces;
* ``published_twin`` -- the twin of the 4-DOF model of Matejic et al. (2021);
* ``gear_visuals`` -- tooth outlines for the viewer;
* ``side`` -- both as the cross-check sees them.
"""

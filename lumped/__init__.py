"""The reference lumped-parameter solver, built from the train description (:mod:`gearcheck.train`).

``assembly`` (M, G, K(t), C, F of the rotating-frame formulation) from ``elements`` (one file per kind of part:
supports, bearings, splines, couplings, the drive, meshes, cycloid-pin stages), ``static``, ``modal``,
``time_solver`` with ``compiled_steps``, ``periodic_steady_state``, ``harmonic``, ``forced_response`` and
``fourier_response`` (with ``response_sensitivity``), ``transmission_error``, ``pin_loads``, the user's own models
(``linear_model``, ``matrix_file``, ``linear_run``, ``export``), the 4-DOF models of a paper (``published``) and
``side``, their face towards the cross-check.  Nothing here imports :mod:`gearcheck.mbd_models`, at any depth."""

"""The reference lumped-parameter solver, built from the train description (:mod:`gearcheck.train`).

``assembly`` (M, G, K(t), C, F of the rotating-frame formulation) from ``elements`` (one file per kind of part:
supports, bearings, splines, couplings, the drive, meshes, cycloid-pin stages), ``static``, ``modal``,
``time_solver`` with ``compiled_steps``, ``periodic_steady_state``, ``harmonic``, ``forced_response`` and
``fourier_response`` (with ``response_sensitivity``), ``transmission_error``, ``pin_loads``, the user's own models
(``linear_model``, ``matrix_file``, ``linear_run``, ``export``), the 4-DOF models of a paper (``published``) and
``side``, their face towards the cross-check.  Nothing here imports :mod:`gearcheck.mbd_models`, at any depth."""

from gearcheck.shared.public import public  # noqa: E402

# the public names: a model, its modes, its time run and its harmonic solutions
__all__, __getattr__, __dir__ = public(__name__, {
    "build_model": "assembly", "modes": "modal", "modes_at_speed": "modal", "simulate": "time_solver",
    "parametric_problem": "forced_response", "fourier_series_response": "fourier_response",
    "harmonic_balance_response": "fourier_response", "CycloidRows": "elements.cycloid",
})

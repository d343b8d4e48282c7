"""The train description and the reference lumped-parameter solver.

Description (what both models are built from; the MuJoCo twin may import these): ``schema``,
``loader``, ``spec``, ``geometry``, ``line_of_action``, ``kinematics``, ``mesh_stiffness`` (with
``tooth_stiffness`` and ``iso6336``), ``excitation``, ``published_parameters``, ``variants``.

Equations (the reference model; the twin never imports these): ``assembly``, ``modal``, ``static``,
``time_solver``, ``harmonic``, ``published``, and ``side``, their face towards the cross-check.
"""

"""The cross-check: two models of one train compared, and what is built on that comparison.

* :mod:`gearcheck.compare.engine` -- the comparison itself: alignment, metrics, tolerances, the run plan,
  mode pairing, baselines, the diagnosis of a user's model, sides for user models and recorded results, and
  :func:`~gearcheck.compare.engine.crosscheck.crosscheck`, the whole workflow;
* :mod:`gearcheck.compare.studies` -- many comparisons: speed sweeps, parameter studies and Monte Carlo,
  calibration, uncertainty, sensitivity, Campbell diagrams;
* :mod:`gearcheck.compare.presentation` -- what people and CI read: reports, plots, the dashboard and its
  history, JUnit, animations and the live view.

Each room imports only the rooms before it (the import contracts in ``pyproject.toml``).
"""

"""Benchmarks of stochpound's solvers: speed against accuracy on the reference study's scenes.

Run the whole suite with ``python -m benchmarks`` (or ``python benchmarks/run.py``;
``--quick`` for a smoke run under a minute). It regenerates ``docs/benchmarks.md``
and ``docs/figures/work_precision.png``.

Modules
-------
scenes
    The study scenes and the synthetic scenes of the scaling runs.
outcome
    What is compared between solvers (:class:`Outcome`) and the error measures.
study_scheme
    An emulation of the reference study's own fixed-restart ODE scheme.
opensees_model
    The same scene in OpenSeesPy (optional dependency).
timing
    Best-of-N timing and measurements in fresh subprocesses.
suite
    The benchmark sections; :mod:`benchmarks.report` writes their results.
"""

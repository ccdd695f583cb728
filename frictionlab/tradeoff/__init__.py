"""The trade-off study, ``frictionlab study PRESET``: for one preset, the error
against the cost (wall time, peak memory) of each knob a user turns: grid
points, realizations, force steps, contact solver and the reference solver's
tolerance. Orchestration and measurement only; the physics is the plugins'.
Built on the framework's public modules only.

Modules: ``options`` (the axes and settings), ``axes`` runs the variants along
each axis, ``scenes`` builds and measures them, ``metrics`` holds the error
definitions and the Pareto front, ``outputs`` writes study.csv, study.md and
study.png and words the recommendation. Nothing is imported here, so
``frictionlab --help`` stays fast.
"""

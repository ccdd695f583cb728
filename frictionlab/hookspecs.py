"""pluggy hook specifications of frictionlab.

Two families:

* Registration hooks, one per plugin kind. Each takes a ``register`` callback
  owned by the host, so the callback can grow keyword arguments later without
  breaking a plugin. A plugin module or object implements any of them::

      from frictionlab import hookimpl

      @hookimpl
      def register_spectra(register):
          register(MySpectrum)

* Lifecycle hooks of an ensemble run. The engine calls them on the listeners of
  a run (the CLI's reporter, the TUI's, any passed to ``engine.run``) and on the
  installed plugins that implement them (the registry holds these specs too, so
  a plugin may, say, log every run), in the order: ``run_started``, then
  ``realization_done`` or ``realization_failed`` once per realization, then
  ``run_finished``.
"""

from __future__ import annotations

import pluggy

PROJECT_NAME = "frictionlab"

hookspec = pluggy.HookspecMarker(PROJECT_NAME)
hookimpl = pluggy.HookimplMarker(PROJECT_NAME)


class RegistrationSpecs:
    """Hooks that add plugin classes to the registry."""

    @hookspec
    def register_spectra(self, register):
        """Register spectrum generators: call ``register(cls)`` for each
        ``SpectrumGenerator`` subclass this plugin provides."""

    @hookspec
    def register_solvers(self, register):
        """Register contact solvers: call ``register(cls)`` for each
        ``ContactSolver`` subclass this plugin provides."""

    @hookspec
    def register_slope_estimators(self, register):
        """Register slope estimators: call ``register(cls)`` for each
        ``SlopeEstimator`` subclass this plugin provides."""


class LifecycleSpecs:
    """Hooks the engine calls on the listeners of one run and on the installed plugins
    that implement them."""

    @hookspec
    def run_started(self, run):
        """A run begins. ``run`` is the ``RunInfo``: scene, realizations to do,
        realizations already done, seed, workers."""

    @hookspec
    def realization_done(self, run, result, done, total):
        """One realization finished. ``result`` is its ``RealizationResult``;
        ``done`` of ``total`` realizations are now finished (ok or failed)."""

    @hookspec
    def realization_failed(self, run, result, done, total):
        """One realization raised. ``result.error`` holds the message; the run
        goes on with the others."""

    @hookspec
    def run_finished(self, run, outcome):
        """The run ended (completed, cancelled or failed). ``outcome`` is the
        ``RunOutcome`` with the statistics and the fit of what finished."""

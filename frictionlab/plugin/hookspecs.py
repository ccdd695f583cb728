"""pluggy hook specifications of frictionlab.

Two families:

* Registration hooks (here), one per plugin kind (``plugin.KINDS``, each kind's
  ``register_hook``). Each takes a ``register`` callback owned by the host, so
  the callback can grow keyword arguments later without breaking a plugin. A
  plugin module or object implements any of them::

      from frictionlab import hookimpl

      @hookimpl
      def register_spectra(register):
          register(MySpectrum)

* Lifecycle hooks of an ensemble run (``listeners.RunListener``). The engine
  calls them on the listeners of a run (the CLI's progress printer, the TUI's,
  any passed to ``engine.run``) and on the installed plugins that implement them
  (the registry holds these specs too, so a plugin may, say, log every run).
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

"""pytest helpers for frictionlab plugin authors.

This package is a pytest plugin. It is declared as the ``pytest11`` entry point
``frictionlab``, so it is active in every pytest session of an environment where
frictionlab is installed: you do not import anything to get the fixtures. The
check functions are plain functions; import them::

    from frictionlab.testing import check_plugin

Importing it is cheap and has no side effects: frictionlab, numpy and
pydantic are imported only when a fixture or a check runs.

Fixtures
========

``frictionlab_registry``
    A fresh ``frictionlab.plugin.registry.Registry(discover=False)`` for one test: the
    built-in plugins are loaded, entry-point discovery is blocked (so what other
    distributions happen to be installed cannot change your test).

``register_plugin``
    A function ``register_plugin(obj, name=None)`` that registers ``obj`` on
    ``frictionlab_registry`` for the duration of one test and unregisters it
    afterwards; it returns the registry. ``obj`` is what an entry point would
    point at: a module, or a class or instance carrying ``@frictionlab.hookimpl``
    functions. As a shortcut, a plugin class itself (a ``SpectrumGenerator``,
    ``ContactSolver`` or ``SlopeEstimator`` subclass) is accepted too and is
    registered through the hook of its kind::

        def test_my_plugin_is_found(register_plugin):
            import frictionlab_gaussian

            registry = register_plugin(frictionlab_gaussian)
            assert registry.get("spectrum", "gaussian") is frictionlab_gaussian.Gaussian

    Registration runs pluggy's ``check_pending()``, so a misspelled hook name
    fails here with ``pluggy.PluginValidationError``; a class that breaks the
    contract or takes a built-in's name fails with ``frictionlab.errors.PluginError``,
    in the words an installed plugin's failure to load says it.

Conformance checks
==================

Each check raises ``AssertionError`` with a readable message naming the class
and what is wrong (an exception raised by your plugin's code is turned into an
``AssertionError`` too, chained to the original, whose traceback starts in your
code); pytest shows the test that called the check and the message, not the
kit's own frames. Parametrise them over your own classes::

    import pytest
    from frictionlab.testing import check_plugin

    @pytest.mark.parametrize("params", [{}, {"correlation_length": 3.0}])
    def test_conformance(params):
        check_plugin("spectrum", Gaussian, **params)

``check_plugin_class(kind, cls, params=None)`` checks what every kind shares;
``check_spectrum``, ``check_solver`` and ``check_slope_estimator`` check one kind
each, every item the contract (``frictionlab.plugin``) declares for it: their
docstrings say how. ``check_plugin(kind, cls, **params)`` runs both.
"""

from __future__ import annotations

from .classes import check_plugin_class
from .common import reported
from .slopes import check_slope_estimator
from .solvers import check_solver
from .spectra import check_spectrum

try:  # the fixtures need pytest; the checks are plain functions, usable without it
    from .fixtures import frictionlab_registry, register_plugin
except ModuleNotFoundError as missing:
    if missing.name != "pytest":
        raise


@reported
def check_plugin(kind: str, cls, *, deterministic: bool = False, **params) -> None:
    """``check_plugin_class(kind, cls, params)`` followed by the check of ``kind``
    (``deterministic`` is passed on to ``check_spectrum`` only)."""
    check_plugin_class(kind, cls, params)
    if kind == "spectrum":
        check_spectrum(cls, deterministic=deterministic, **params)
    elif kind == "solver":
        check_solver(cls, **params)
    else:
        check_slope_estimator(cls, **params)


__all__ = [name for name in (
    "check_plugin",
    "check_plugin_class",
    "check_slope_estimator",
    "check_solver",
    "check_spectrum",
    "frictionlab_registry",
    "register_plugin",
) if name in globals()]  # the fixtures where pytest is

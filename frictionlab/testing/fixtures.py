"""The pytest fixtures of the plugin authors' kit (``frictionlab.testing``, a pytest plugin):
a fresh registry, and registering a plugin on it for one test."""

from __future__ import annotations

import pytest


@pytest.fixture
def frictionlab_registry():
    """A fresh registry: built-ins loaded, entry-point discovery blocked."""
    from frictionlab.plugin.registry import Registry

    return Registry(discover=False)


@pytest.fixture
def register_plugin(frictionlab_registry):
    """``register_plugin(obj, name=None) -> registry``: register ``obj`` on
    ``frictionlab_registry`` for this test only."""
    registered: list[object] = []

    def register(obj, name: str | None = None):
        plugin = _as_hook_plugin(obj)
        if name is None and plugin is not obj:
            name = f"{obj.__module__}.{obj.__qualname__}"
        frictionlab_registry.register_plugin(plugin, name=name)
        registered.append(plugin)
        return frictionlab_registry

    yield register

    for plugin in reversed(registered):
        if frictionlab_registry.pm.is_registered(plugin):
            frictionlab_registry.unregister_plugin(plugin)


def _as_hook_plugin(obj):
    """A plugin class (not a hook holder) becomes a namespace with one hookimpl."""
    from frictionlab.plugin import Plugin

    if isinstance(obj, type) and issubclass(obj, Plugin) and obj.kind:
        import types

        from frictionlab.plugin.hookspecs import hookimpl
        def _register(register):
            register(obj)

        return types.SimpleNamespace(**{obj.register_hook: hookimpl(_register)})
    return obj

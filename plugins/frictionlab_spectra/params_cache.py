"""What a spectrum derives from its parameters (a synthesis, a file read), computed once
per parameter values: ``Params`` may be edited in place (the TUI does), so the cache is
keyed on their current values, never on the instance alone."""

from __future__ import annotations

import functools


def cached_on_params(method):
    """Memoise ``method(self)`` on the values of ``self.params``."""
    slot = f"_cached_{method.__name__}"

    @functools.wraps(method)
    def cached(self):
        key = tuple(self.params.__dict__.items())
        hit = self.__dict__.get(slot)
        if hit is not None and hit[0] == key:
            return hit[1]
        value = method(self)
        self.__dict__[slot] = (key, value)
        return value

    return cached

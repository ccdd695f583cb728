"""Checking the arguments of the Python API (``frictionlab.run``, ``frictionlab.load``,
``Result``): a value of the wrong kind, or data beyond the limits a preset file has,
is a FrictionlabError naming the argument, never a TypeError or RecursionError from
deep inside."""

from __future__ import annotations

import numbers
import os
from collections.abc import Mapping
from pathlib import Path

from .errors import FrictionlabError, short_repr, too_long_path
from .io.safe_yaml import MAX_DEPTH, MAX_VALUES

_SCALARS = (str, int, float, bool, type(None), os.PathLike)


def path_argument(value, name: str, what: str) -> Path:
    """``value`` as a Path to ``what``: a str or os.PathLike, not empty, without NUL."""
    if isinstance(value, os.PathLike):
        value = os.fspath(value)
    if isinstance(value, bytes):
        value = os.fsdecode(value)
    if not isinstance(value, str):
        raise FrictionlabError(f"{name} must be a path to {what} (a str or pathlib.Path), got {type(value).__name__}")
    if not value:
        raise FrictionlabError(f"{name} must be a path to {what}, got an empty string")
    if "\0" in value:
        raise FrictionlabError(f"{name} must be a path to {what}, got a string with a NUL character")
    if (too_long := too_long_path(value)) is not None:  # else an OSError from the first look at it
        raise FrictionlabError(f"{name}: {too_long}")
    return Path(value)


def flag_argument(value, name: str) -> bool:
    """``value`` as a bool: True or False, or numpy's (``array.any()`` gives one)."""
    import numpy as np

    if not isinstance(value, bool | np.bool_):
        raise FrictionlabError(f"{name} must be True or False, got {short_repr(value)} ({type(value).__name__})")
    return bool(value)


def data_argument(value, name: str) -> None:
    """Refuse preset data a preset file could not hold: nesting deeper than the YAML
    limit, more values than it, a mapping key that is not a string, or an object that
    is not a str, number, bool, None, path, list or mapping. Walked without recursion,
    so a dict nested 10,000 deep (or one that contains itself) is refused, not a crash."""
    stack, count = [(value, 0, name)], 0
    while stack:
        item, depth, where = stack.pop()
        count += 1
        if count > MAX_VALUES:
            raise FrictionlabError(f"{name} holds more than {MAX_VALUES:,} values, the limit of a preset")
        if depth > MAX_DEPTH:
            raise FrictionlabError(f"{name} is nested more than {MAX_DEPTH} levels deep, the limit of a preset")
        if isinstance(item, Mapping):
            for key, child in item.items():
                if not isinstance(key, str):
                    raise FrictionlabError(f"{where}: keys must be strings, got {type(key).__name__} {short_repr(key, 40)}")
                stack.append((child, depth + 1, f"{where}.{key}"[:200]))
        elif isinstance(item, list | tuple):
            stack.extend((child, depth + 1, f"{where}[{i}]"[:200]) for i, child in enumerate(item))
        elif not isinstance(item, (*_SCALARS, numbers.Real)):  # numpy's numbers are Real: plain_copy makes them Python's
            kind = f"{type(item).__module__}.{type(item).__name__}".removeprefix("builtins.")  # numpy.bool, not bool
            raise FrictionlabError(f"{where} must be a str, number, bool, None, list or mapping, got {kind}")


def plain_copy(value):
    """A copy of preset data that ``data_argument`` took, its numbers Python's: a numpy integer
    (an int64 of an array's size) was refused as no number, and preset.yaml and sweep.json are
    written from the data, which YAML and JSON cannot hold."""
    if isinstance(value, Mapping):
        return {key: plain_copy(child) for key, child in value.items()}
    if isinstance(value, list | tuple):
        return [plain_copy(child) for child in value]
    if isinstance(value, numbers.Real) and type(value) not in (int, float, bool):  # np.float64 too: said as a float
        return int(value) if isinstance(value, numbers.Integral) else float(value)
    return value


def overrides_argument(value) -> dict:
    """``overrides`` (None, or a mapping of dotted paths to values) as a dict."""
    if value is None:
        return {}
    if not isinstance(value, Mapping):
        raise FrictionlabError(f"overrides must be a mapping of dotted keys to values, got {type(value).__name__}")
    for key in value:
        if not isinstance(key, str):
            raise FrictionlabError(
                f"overrides must be a mapping of dotted keys to values: key {short_repr(key, 40)} is of type "
                f"{type(key).__name__}, not str"
            )
    data_argument(value, "overrides")
    return plain_copy(value)

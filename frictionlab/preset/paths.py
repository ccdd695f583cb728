"""Dotted paths into preset data (``spectrum.params.hurst``): the one setter that
``--set``, the sweeps, the trade-off study's variants and the TUI's form all use,
and the ``--set`` spelling of a value."""

from __future__ import annotations

import copy
import json
import math
from collections.abc import Sequence
from typing import Any

import yaml

from ..errors import PresetError, short_repr, shown_name
from ..io.inputs import as_typed
from ..io.safe_yaml import YamlProblem, load_yaml

MISSING = object()
"""As a value for ``set_path``: remove the key (the model's default then applies)."""


def _keys(path: str | Sequence[str]) -> list[str]:
    return [k.strip() for k in path.split(".")] if isinstance(path, str) else list(path)


def is_dotted_path(path: str) -> bool:
    """Whether ``path`` names a field: a name between every two dots (``a..b``, ``.a``, ``a.``
    and ``""`` set a key named nothing, which no preset has)."""
    return all(_keys(path))


def get_path(data: dict, path: str | Sequence[str], default=MISSING):
    """``data[a][b][c]`` for ``a.b.c``, or ``default`` where the path does not lead."""
    node = data
    for key in _keys(path):
        if not isinstance(node, dict) or key not in node:
            return default
        node = node[key]
    return node


def first_unlike(data: dict, stated: dict[str, float]) -> tuple[str, Any, float] | None:
    """The first dotted path of ``stated`` whose value in ``data`` is not that number (to
    rounding), as ``(path, its value, the number)``; None when ``data`` holds them all. What
    a report states of a preset (H = 1, F = 1..20) is checked against the preset so."""
    for dotted, number in stated.items():
        value = get_path(data, dotted, None)
        if isinstance(value, bool) or not isinstance(value, float | int) or not math.isclose(value, number):
            return dotted, value, number
    return None


def set_path(data: dict, path: str | Sequence[str], value: Any, *, replace_values: bool = False) -> None:
    """Set ``data[a][b][c] = value`` for ``a.b.c`` (or ``("a", "b", "c")``), making mappings
    where keys are missing or None; ``MISSING`` removes the key. A value in the way
    (``a.b`` is 3) is a ValueError naming it, unless ``replace_values`` replaces it."""
    keys = _swept_path_as_one_key(_keys(path), value)
    node = data
    for depth, key in enumerate(keys[:-1]):
        child = node.get(key)
        if child is None or (replace_values and not isinstance(child, dict)):
            child = node[key] = {}
        elif isinstance(child, list):  # "values.0": an item of a list is not a key
            where = ".".join(keys[: depth + 1])
            raise ValueError(f"{where} is a list, not a mapping: set the whole list ({where}=[...])")
        elif not isinstance(child, dict):
            raise ValueError(f"{'.'.join(keys[: depth + 1])} is a value, not a mapping")
        node = child
    if value is MISSING:
        node.pop(keys[-1], None)
    else:
        node[keys[-1]] = copy.deepcopy(value)


def _swept_path_as_one_key(keys: list[str], value: Any) -> list[str]:
    """``sweep.parameters.spectrum.params.hurst.values``: the swept path is one key of
    ``sweep.parameters`` (``spectrum.params.hurst``), followed by a field of its values
    unless the value is their whole mapping."""
    if keys[:2] != ["sweep", "parameters"] or len(keys) <= 3:
        return keys
    from .schema import SweepParameter  # imported here: reading a preset needs no pydantic model

    if keys[-1] in SweepParameter.model_fields and not isinstance(value, dict):
        return [*keys[:2], ".".join(keys[2:-1]), keys[-1]]
    if len(keys) > 4 and keys[-2] in SweepParameter.model_fields and keys[-1].isdigit():  # values.0: into the list
        return [*keys[:2], ".".join(keys[2:-2]), keys[-2], keys[-1]]
    return [*keys[:2], ".".join(keys[2:])]


SWEPT = "is swept by the preset's sweep, which sets it at each point: it would be ignored"


def swept_paths(data: dict, paths: Sequence[str]) -> list[str]:
    """Those of ``paths`` that the preset's sweep sets at each of its points: an override of one
    (``--seed 9`` beside a sweep over seed) was ignored without a word."""
    sweep = data.get("sweep")
    swept = sweep.get("parameters") if isinstance(sweep, dict) else None
    return [path for path in paths if isinstance(swept, dict) and path in swept]


def apply_overrides(data: dict, assignments: Sequence[str]) -> dict:
    """A copy of ``data`` with ``dotted.path=value`` assignments applied (values read as YAML scalars)."""
    if isinstance(assignments, str | bytes) or not isinstance(assignments, Sequence):  # "seed=3": told letter by letter
        raise PresetError([f"overrides must be a list of 'dotted.path=value' strings, e.g. ['seed=3']. Got "
                           f"{short_repr(assignments, 80)} ({type(assignments).__name__}) instead"], source="overrides")  # fmt: skip
    data = copy.deepcopy(data)
    problems = []
    for assignment in map(as_typed, assignments):
        try:
            assignment.encode("utf-8")
        except UnicodeEncodeError:  # bytes of another encoding on the command line: pydantic's 'unable to parse raw data'
            problems.append(f"--set '{shown_name(assignment)}': not UTF-8 text (a byte of another encoding, shown as "
                            "\\xNN); a preset is UTF-8: type the value in UTF-8")  # fmt: skip
            continue
        path, sep, raw = assignment.partition("=")
        if not sep or not is_dotted_path(path):
            problems.append(f"--set {assignment!r}: must look like dotted.path=value, e.g. spectrum.params.hurst=0.8")
            continue
        try:
            value = load_yaml(raw) if raw.strip() else ""
        except YamlProblem as exc:
            if raw.lstrip().startswith(("{", "[")):  # a mapping or list mistyped (a key twice), not text: why is said
                problems.append(f"--set {short_repr(assignment, 120)}: a {{ mapping or [ list YAML cannot read: {exc}; "
                                "text that starts with { or [ is given quoted: 'description=\"[draft]\"'")  # fmt: skip
                continue
            value = raw  # text YAML does not read (a: b: c) is taken as it is
        try:
            set_path(data, path, value)
        except ValueError as exc:
            problems.append(f"--set {assignment!r}: {exc}")
    if problems:
        raise PresetError(problems, source="--set")
    return data


def yaml_scalar(value: Any) -> str:
    """The ``--set`` spelling of ``value``: YAML that ``--set`` reads back as the same value
    (nan and the infinities as ``.nan``, ``.inf``, ``-.inf``: a swept value its field refuses
    is then refused by the field, with its message; text that would read as a number, such
    as ``1e5``, double-quoted)."""
    if isinstance(value, float) and not math.isfinite(value):
        return ".nan" if math.isnan(value) else (".inf" if value > 0 else "-.inf")
    if isinstance(value, float):
        text = repr(value)
        if "e" in text and "." not in text:  # PyYAML reads 1e-05 as text; 1.0e-05 as a float
            text = text.replace("e", ".0e", 1)
        if "e" in text and text.split("e")[1][0] not in "+-":
            text = text.replace("e", "e+", 1)
    else:
        text = yaml.safe_dump(value, default_flow_style=True).removesuffix("\n...\n").strip()
        if isinstance(value, str) and not _reads_back(text, value):  # PyYAML's plain 1e5: a number to --set
            text = json.dumps(value)  # a JSON string is a YAML double-quoted one
    if not _reads_back(text, value):
        raise ValueError(f"cannot spell {value!r} as a YAML scalar")
    return text


def _reads_back(text: str, value: Any) -> bool:
    """Whether ``--set`` reads ``text`` as ``value``, of its type."""
    try:
        read = load_yaml(text) if text.strip() else ""
    except YamlProblem:
        return False
    return read == value and type(read) is type(value)


def differences(old, new, path: str = "") -> list[str]:
    """The dotted paths where two (resolved) presets differ, each with both values
    (the first as stored in a run directory, the second as given)."""
    if isinstance(old, dict) and isinstance(new, dict):
        out = []
        for key in list(old) + [k for k in new if k not in old]:
            where = f"{path}.{key}" if path else str(key)
            if key not in old or key not in new:
                out.append(f"{where}: {old.get(key, '(absent)')!r} in the run directory, {new.get(key, '(absent)')!r} given")
            else:
                out.extend(differences(old[key], new[key], where))
        return out
    if old != new:
        return [f"{path}: {old!r} in the run directory, {new!r} given"]
    return []


def with_new_defaults(stored: dict, resolved: dict, defaults: dict) -> dict:
    """``stored`` (a run folder's resolved preset) with each field it lacks taken from
    ``resolved`` where that value is the field's default (``defaults``, the shape of
    ``Scene.defaults()``): a run started before a field existed used what its default is
    now, so upgrading frictionlab does not orphan unfinished runs."""
    out = dict(stored)
    for key, value in resolved.items():
        default = defaults.get(key) if isinstance(defaults, dict) else None
        if key not in stored:
            if isinstance(defaults, dict) and key in defaults and default == value:
                out[key] = value
        elif isinstance(stored[key], dict) and isinstance(value, dict):
            out[key] = with_new_defaults(stored[key], value, default if isinstance(default, dict) else {})
    return out


# A value an older frictionlab took and this one refuses: (path, that value, what it now reads as, what that means).
RETIRED_VALUES = (
    ("fit.bootstrap", 1, 0, "a fit without intervals: one resample gives an interval of one point, not a spread; "
                            "run the preset again with fit.bootstrap 2 or more for intervals"),
)


def as_now(stored) -> tuple[Any, list[str]]:
    """``stored`` (a run folder's preset, or a sweep's base preset) with each of ``RETIRED_VALUES`` it
    holds read as what it now means, and a note for each saying so: a run started with one resumes
    (its realizations do not depend on it) rather than being refused as a preset no longer valid."""
    if not isinstance(stored, dict):
        return stored, []
    out, notes = copy.deepcopy(stored), []
    for path, old, new, means in RETIRED_VALUES:
        value = get_path(out, path, None)
        if value == old and type(value) is type(old):
            set_path(out, path, new)
            notes.append(f"its {path} is {old!r}, which an older frictionlab accepted and this one refuses: it is "
                         f"taken as {new!r}, {means}")  # fmt: skip
    return out, notes

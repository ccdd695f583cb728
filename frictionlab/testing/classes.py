"""The contract every plugin kind shares: the class's declarations and its ``Params``."""

from __future__ import annotations

import math
from collections.abc import Mapping
from typing import Any

from .common import fail, instantiate, reported


def _schema_bounds(prop: Mapping[str, Any]) -> list[tuple[str, float, bool]]:
    """(keyword, bound, is_integer) for a property of a JSON Schema (anyOf too)."""
    bounds = []
    alternatives = [prop]
    for key in ("anyOf", "oneOf", "allOf"):
        alternatives.extend(prop.get(key, []))
    for alt in alternatives:
        if not isinstance(alt, Mapping) or alt.get("type") not in ("number", "integer"):
            continue
        for keyword in ("minimum", "exclusiveMinimum", "maximum", "exclusiveMaximum"):
            value = alt.get(keyword)
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                bounds.append((keyword, float(value), alt.get("type") == "integer"))
    return bounds


def _metadata_bounds(info) -> list[tuple[str, float, bool]]:
    keywords = {"ge": "minimum", "gt": "exclusiveMinimum", "le": "maximum", "lt": "exclusiveMaximum"}
    is_int = info.annotation is int
    bounds = []
    for item in info.metadata:
        for attr, keyword in keywords.items():
            value = getattr(item, attr, None)  # annotated_types bounds: each item has one of them
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                bounds.append((keyword, float(value), is_int))
    return bounds


def _past(keyword: str, bound: float, is_int: bool):
    """A value just on the wrong side of a bound."""
    step = max(1.0, abs(bound))
    if keyword == "minimum":
        value = math.ceil(bound) - 1 if is_int else bound - step
    elif keyword == "exclusiveMinimum":
        value = math.floor(bound) if is_int else bound
    elif keyword == "maximum":
        value = math.floor(bound) + 1 if is_int else bound + step
    else:  # exclusiveMaximum
        value = math.ceil(bound) if is_int else bound
    return int(value) if is_int else float(value)


def _bounded_fields(cls, schema) -> list[tuple[str, str, float, bool]]:
    found = []
    props = (schema or {}).get("properties", {})
    for field_name, info in cls.Params.model_fields.items():
        key = info.alias or field_name
        bounds = _schema_bounds(props.get(key, {})) or _metadata_bounds(info)
        seen = set()
        for keyword, bound, is_int in bounds:
            if keyword not in seen:
                seen.add(keyword)
                found.append((key, keyword, bound, is_int))
    return found


@reported
def check_plugin_class(kind: str, cls, params: Mapping[str, Any] | None = None) -> None:
    """The contract every kind shares (``kind`` is ``"spectrum"``, ``"solver"`` or
    ``"slope"``): ``frictionlab.plugin.registry.validate_plugin_class`` passes (right
    base class, its required methods implemented, kebab-case ``name``, one-line ``summary``, pydantic ``Params``
    forbidding unknown keys, every field described, and every declaration well
    formed: ``kind`` and ``register_hook`` are the base class's own; a spectrum's
    ``dimension`` is 1 or 2, its ``deterministic`` a bool and its ``points_param`` names a field; the
    ``dimensions`` of a solver or an estimator are 1 and/or 2 and ``periodic_only``
    is a bool; a solver's ``normalisations`` give one ``normalisation`` per
    dimension, ``problem`` names the physical problem, ``approximation`` is a bool,
    ``contact_measure`` and ``indentation_reference`` take allowed values, ``mdr_lines`` is a bool,
    True only for a solver of lines alone,
    ``body_params`` and ``tolerance_param`` name fields); ``references`` is a tuple
    of strings; ``Params`` has a JSON Schema and every default passes its own bounds; ``Params(**params)`` and
    ``cls(**params)`` construct (``params`` defaults to ``{}``: give it when a
    field has no default); an unknown key raises ``pydantic.ValidationError``
    naming it; the name is not a built-in's of the kind (the built-in keeps it: the plugin would
    fail to load); the parameters survive a JSON round trip (presets are YAML);
    and, for every bounded numeric field (bounds read from the JSON Schema, or
    from the field's ``ge``/``gt``/``le``/``lt`` metadata), a value just past
    each bound is rejected, at construction and on assignment, with a message
    naming the field. That last part is skipped only when no field is bounded.

    ``params`` are keyword arguments that construct a valid instance (default:
    none, i.e. every field has a default).
    """
    from pydantic import ValidationError

    from frictionlab.errors import PluginError
    from frictionlab.plugin import KINDS
    from frictionlab.plugin.classcheck import params_problem
    from frictionlab.plugin.registry import Registry, normalize_name, validate_plugin_class

    if kind not in KINDS:
        raise ValueError(f"kind must be one of {', '.join(KINDS)}. Got {kind!r} instead.")
    params = dict(params or {})

    try:
        validate_plugin_class(kind, cls)
    except PluginError as exc:
        fail(cls, f"breaks the {kind} plugin contract: {exc}", exc)
    if normalize_name(cls.name) != cls.name:
        fail(cls, f"name must be in normalised kebab-case. Got {cls.name!r} instead.")
    builtins = Registry(discover=False, env={})
    builtin = builtins.get(kind, cls.name) if cls.name in builtins.names(kind) else cls
    if builtin is not cls:
        fail(cls, f"name {cls.name!r} is taken by the built-in {kind} {builtin.__module__}.{builtin.__qualname__}: "
                  "installed, the plugin would fail to load (the built-in keeps its name); choose another name")  # fmt: skip
    refs = cls.references
    if not isinstance(refs, (tuple, list)) or not all(isinstance(r, str) and r.strip() for r in refs):
        fail(cls, f"references must be a tuple of strings (DOIs). Got {refs!r} instead.")

    Params = cls.Params
    if problem := params_problem(cls):  # as an installed plugin's registration says it
        fail(cls, problem)
    schema = Params.model_json_schema()

    # defaults (or the given params) construct
    required = [info.alias or name for name, info in Params.model_fields.items() if info.is_required()]
    if missing := [name for name in required if name not in params]:
        fail(cls, f"Params.{', Params.'.join(missing)} has no default: pass the check a value (check_plugin("
                  f"{kind!r}, cls, {', '.join(name + '=...' for name in missing)})), or give the field a default "
                  "(Field(default, description=...)) so that a preset may leave it out")  # fmt: skip
    try:
        model = Params(**params)
    except ValidationError as exc:
        fail(cls, f"Params(**{params!r}) is invalid: {exc}", exc)
    instance = instantiate(cls, params)
    if instance.__dict__.get("params") != model:
        fail(cls, "the constructor must store its validated Params as self.params")

    # unknown keys are rejected
    unknown = "frictionlab_conformance_unknown_key"
    try:
        Params(**params, **{unknown: 1})
    except ValidationError as exc:
        if unknown not in str(exc):
            fail(cls, f"the error for an unknown key does not name it: {exc}")
    else:
        fail(cls, f"Params accepted the unknown key {unknown!r}; unknown keys must be rejected")

    # JSON round trip (presets and result files store params as YAML/JSON)
    try:
        again = Params.model_validate(model.model_dump(mode="json"))
    except Exception as exc:
        fail(cls, f"Params do not survive a JSON round trip: {type(exc).__name__}: {exc}", exc)
    if again != model:
        fail(cls, f"Params change in a JSON round trip: {model!r} -> {again!r}")

    # bounds are enforced, with messages naming the field
    for key, keyword, bound, is_int in _bounded_fields(cls, schema):
        bad = _past(keyword, bound, is_int)
        what = f"Params.{key} = {bad!r} (past its {keyword} {bound:g})"
        try:
            Params(**{**params, key: bad})
        except ValidationError as exc:
            if key not in str(exc):
                fail(cls, f"the error for {what} does not name the field: {exc}")
        else:
            fail(cls, f"{what} was accepted; out-of-range values must be rejected")
        fresh = Params(**params)
        try:
            setattr(fresh, key, bad)
        except ValidationError:
            pass
        except Exception as exc:
            fail(cls, f"assigning {what} raised {type(exc).__name__} instead of ValidationError", exc)
        else:
            fail(
                cls,
                f"assigning {what} was accepted; Params must validate on assignment "
                "(derive from frictionlab.PluginParams)",
            )

"""What a plugin class must declare to be registered: the right base class, a kebab-case name,
a one-line summary, pydantic ``Params`` forbidding unknown keys with every field described,
its required methods implemented with the arguments frictionlab passes, and every
declaration of its kind well formed. ``params_problem`` checks more (a JSON Schema, defaults
within their own bounds), at the cost of building the validator: for installed plugins and
the conformance kit, not for the built-ins at every start."""

from __future__ import annotations

import inspect
import math
from collections.abc import Mapping
from typing import get_args

import numpy as np
from pydantic import BaseModel, ValidationError

from ..errors import PluginError
from .base import NAME_PATTERN
from .data import Profile
from .kinds import KINDS, REQUIRED, ContactSolver, contract, IndentationReference, SlopeEstimator, SpectrumGenerator
from .normalisation import ContactMeasure, ForceNormalisation


def validate_plugin_class(kind: str, cls) -> None:
    """Raise PluginError if ``cls`` does not fulfil the plugin contract of ``kind``."""
    base = KINDS[kind]
    label = getattr(cls, "__qualname__", repr(cls))
    if not (isinstance(cls, type) and issubclass(cls, base)):
        raise PluginError(f"{label}: a {kind} plugin must subclass frictionlab.{base.__name__}")
    if not isinstance(cls.name, str) or not NAME_PATTERN.match(cls.name):
        raise PluginError(
            f"{label}: name must be kebab-case (lowercase words joined by '-'). "
            f"Got {cls.name!r} instead."
        )
    if not isinstance(cls.summary, str) or not cls.summary.strip() or "\n" in cls.summary.strip():
        raise PluginError(f"{label}: summary must be one non-empty line. Got {cls.summary!r} instead.")
    params = cls.Params
    if not (isinstance(params, type) and issubclass(params, BaseModel)):
        raise PluginError(f"{label}: Params must be a pydantic model")
    if params.model_config.get("extra") != "forbid":
        raise PluginError(f"{label}: Params must forbid unknown keys (model_config extra='forbid')")
    for field_name, info in params.model_fields.items():
        if not (info.description or "").strip():
            raise PluginError(
                f"{label}: Params.{field_name} has no description; give it one, {field_name}: ... = "
                f"Field(default, description=\"what it is (its unit)\"): presets, frictionlab schema and the "
                "edit form show it"
            )
    for problem in declaration_problems(cls):
        raise PluginError(f"{label}: {problem}")


def declaration_problems(cls) -> list[str]:
    """What is wrong with the contract declarations of a plugin class (see ``plugin.py``)."""
    fields = set(cls.Params.model_fields)
    problems = []

    def named_fields(what: str, names) -> None:
        unknown = [n for n in names if n not in fields]
        if unknown:
            problems.append(f"{what} names {', '.join(map(repr, unknown))}, not fields of Params ({', '.join(sorted(fields)) or 'none'})")

    base = next(base for base in KINDS.values() if issubclass(cls, base))
    missing = [f"{name}()" for name in REQUIRED[base.kind] if getattr(cls, name) is getattr(base, name)]
    if missing:
        problems.append(f"implements no {' nor '.join(missing)}: a {base.__name__} must (the base class's only "
                        "raises NotImplementedError)")  # fmt: skip
    problems += _signature_problems(cls, base)
    if (cls.kind, cls.register_hook) != (base.kind, base.register_hook):
        problems.append(
            f"kind and register_hook are {base.__name__}'s ({base.kind!r}, {base.register_hook!r}), "
            "not a plugin's to change"
        )
    if issubclass(cls, SpectrumGenerator):
        if cls.dimension not in (1, 2):
            problems.append(f"dimension must be 1 (lines) or 2 (surfaces). Got {cls.dimension!r} instead.")
        if cls.points_param is not None:
            named_fields("points_param", [cls.points_param])
        if not isinstance(cls.deterministic, bool):
            problems.append(f"deterministic must be True or False. Got {cls.deterministic!r} instead.")
    if issubclass(cls, (ContactSolver, SlopeEstimator)):
        dims = cls.dimensions
        if not (isinstance(dims, tuple) and dims and set(dims) <= {1, 2}):
            problems.append(f"dimensions must be a non-empty tuple of 1 and/or 2. Got {dims!r} instead.")
        if not isinstance(cls.periodic_only, bool):
            problems.append(f"periodic_only must be True or False. Got {cls.periodic_only!r} instead.")
    if issubclass(cls, ContactSolver):
        declared = cls.normalisations
        if not isinstance(declared, Mapping) or set(declared) != set(cls.dimensions) or not all(
            isinstance(n, ForceNormalisation) for n in declared.values()
        ):
            problems.append(
                "normalisations must map each of its dimensions "
                f"{cls.dimensions!r} to a ForceNormalisation (what its load means and how f is formed). "
                f"Got {declared!r} instead."
            )
        else:
            for dimension, normalisation in declared.items():
                try:
                    normalisation.extent_of(Profile(np.zeros((2,) * dimension), 1.0))
                except ValueError as exc:
                    problems.append(f"normalisations[{dimension}]: {exc}")
        for attr in ("approximation", "undefined_slopes", "mean_displacement_known", "corrected_area", "real_gradient",
                     "counts_spots", "mdr_lines"):
            if not isinstance(getattr(cls, attr), bool):
                problems.append(f"{attr} must be True or False. Got {getattr(cls, attr)!r} instead.")
        if cls.mdr_lines is True and tuple(cls.dimensions) != (1,):
            problems.append(f"mdr_lines is for a solver of lines alone (dimensions (1,)): one of surfaces presses them "
                            f"itself. Got mdr_lines True with dimensions {cls.dimensions!r}.")  # fmt: skip
        if not (isinstance(cls.problem, str) and cls.problem.strip()):
            problems.append(f"problem must name the physical problem solved (e.g. 'elastic half-space'). Got {cls.problem!r} instead.")
        for attr, value, allowed in (
            ("contact_measure", cls.contact_measure, ContactMeasure),
            ("indentation_reference", cls.indentation_reference, IndentationReference),
        ):
            if value not in get_args(allowed):
                problems.append(f"{attr} must be one of {', '.join(map(repr, get_args(allowed)))}. Got {value!r} instead.")
        named_fields("body_params", cls.body_params)
        if cls.tolerance_param is not None:
            named_fields("tolerance_param", [cls.tolerance_param])
        declared = cls.bytes_per_point
        if declared is not None and (isinstance(declared, bool) or not isinstance(declared, int) or declared <= 0):
            problems.append(f"bytes_per_point must be None or a whole number > 0. Got {declared!r} instead.")
    return problems


def _signature_problems(cls, base) -> list[str]:
    """Each method of the contract that ``cls`` overrides must take the arguments the framework
    passes, as the base class's does (``slopes(heights, spacing, periodic)``)."""
    problems = []
    for name in sorted(contract(base.kind)):
        declared, given = inspect.getattr_static(base, name, None), inspect.getattr_static(cls, name, None)
        if not inspect.isfunction(declared) or given is declared or not callable(given):
            continue
        wanted = list(inspect.signature(declared).parameters)[1:]  # after self
        try:
            inspect.signature(getattr(cls, name)).bind(None, *wanted)
        except TypeError:
            problems.append(f"{name}() must take ({', '.join(wanted)}), as frictionlab calls it. "
                            f"Got {name}{inspect.signature(getattr(cls, name))} instead.")  # fmt: skip
        except ValueError:  # no signature to read (a builtin): nothing to check
            pass
    return problems


def params_problem(cls) -> str | None:
    """What is wrong with ``cls.Params`` beyond its declaration: no JSON Schema (``frictionlab
    schema`` and the terminal UI's form read it), or a default its own bounds refuse (pydantic
    does not check defaults: a preset leaving the field out would pass the plugin that value), or
    infinity or NaN allowed or given as a default (the run's summary.json could not hold it)."""
    params = cls.Params
    try:
        params.model_json_schema()
    except Exception as exc:  # noqa: BLE001 - any failure to describe the parameters is the plugin's
        said = " ".join(str(exc).partition("For further information")[0].split())  # pydantic's link to its docs: not ours
        return (f"Params has no JSON Schema ({type(exc).__name__}: {said}): give every "
                "field a type pydantic can describe (numbers, strings, lists of them)")  # fmt: skip
    defaults = {info.alias or name: info.get_default(call_default_factory=True)
                for name, info in params.model_fields.items() if not info.is_required()}  # fmt: skip
    finite = "a parameter must be a finite number (results are JSON, which has no infinity or NaN)"
    for field, info in params.model_fields.items():  # summary.json holds every parameter
        if any(getattr(m, "allow_inf_nan", False) for m in info.metadata):
            return f"Params.{field} allows infinity and NaN (allow_inf_nan=True): {finite}; use None for none"
    for field, value in defaults.items():
        if isinstance(value, float) and not math.isfinite(value):
            return f"Params.{field} defaults to {value!r}: {finite}; give a finite default, or None for none"
    try:
        params.model_validate(defaults)
    except ValidationError as exc:
        for error in exc.errors():
            if error["loc"] and (field := error["loc"][0]) in defaults:
                return (f"Params.{field} defaults to {defaults[field]!r}, which its own bounds refuse "
                        f"({error['msg']}): a preset leaving it out would run with it")  # fmt: skip
    except Exception:  # noqa: BLE001 - a validator's own fault is told where a preset meets it
        pass
    return None

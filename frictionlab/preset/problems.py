"""Problems of preset data, each as ``dotted.path: what is wrong, got VALUE``:
pydantic's errors worded for people, and the numbers pydantic would let through."""

from __future__ import annotations

import math
import re
import types
import typing
from dataclasses import dataclass

from pydantic import BaseModel, ValidationError

from ..errors import close_names, did_you_mean, short_repr
from ..plugin import MAX_MAGNITUDE
from ..io.safe_yaml import past_double_precision
from .schema import NAME_PATTERN, NAME_RULE, SweepParameter


FIELD_CUTOFF = 0.7  # field names are short and alike (seed, sweep; stop, steps): only a near miss is a guess


def _model_at(model: type[BaseModel] | None, loc: tuple) -> type[BaseModel] | None:
    """The model reached by walking ``loc`` into ``model`` (None where it leads to no model); a
    key of a mapping of models (a sweep's parameters) leads to the model of its values."""
    values_of = None  # the model of a mapping's values, where the last part was such a mapping
    for part in loc:
        if values_of is not None:
            model, values_of = values_of, None
            continue
        if model is None or not isinstance(part, str) or part not in model.model_fields:
            return None
        annotation = model.model_fields[part].annotation
        if typing.get_origin(annotation) is dict:
            values_of, model = _nested_model(typing.get_args(annotation)[-1]), None
            if values_of is None:
                return None
            continue
        model = _nested_model(annotation)
    return model


def _allowed_keys(model: type[BaseModel] | None, loc: tuple) -> list[str]:
    """Field names of the model reached by walking ``loc`` into ``model``."""
    model = _model_at(model, loc)
    return sorted(model.model_fields) if model is not None else []


def _too_large_for_an_integer(model: type[BaseModel], loc: tuple) -> str:
    """What a whole field takes, said of a float past 2**63 (1e30) pydantic cannot make one:
    its upper bound, where it has one; it said 'unable to parse input string as an integer,
    exceeded maximum size', a number taken for text and no bound."""
    parent = _model_at(model, loc[:-1])
    field = parent.model_fields.get(loc[-1]) if parent is not None and loc and isinstance(loc[-1], str) else None
    for bound in getattr(field, "metadata", ()):
        for key, symbol in (("le", "<="), ("lt", "<")):
            if getattr(bound, key, None) is not None:
                return f"must be {symbol} {getattr(bound, key)}"
    return "must be a whole number, written in digits (one this large, written with an exponent, is a float)"


def _describe(error: dict, model: type[BaseModel]) -> str:
    kind, ctx = error["type"], error.get("ctx", {})
    comparisons = {
        "less_than_equal": ("<=", "le"),
        "less_than": ("<", "lt"),
        "greater_than_equal": (">=", "ge"),
        "greater_than": (">", "gt"),
    }
    if kind in comparisons:
        symbol, key = comparisons[kind]
        return f"must be {symbol} {ctx[key]}"
    if kind == "extra_forbidden":
        allowed = _allowed_keys(model, tuple(error["loc"][:-1]))
        if not allowed:
            return "is not a known field; none are allowed here"
        hint = did_you_mean(str(error["loc"][-1]), allowed, FIELD_CUTOFF)
        return f"is not a known field{hint or ';'} allowed: {', '.join(allowed)}"
    if kind == "missing":
        return "is required"
    if kind == "literal_error":
        return f"must be one of {ctx['expected']}"
    if kind == "int_parsing_size":
        return _too_large_for_an_integer(model, tuple(error["loc"]))
    if kind in {"int_parsing", "int_type", "int_from_float"}:
        return "must be a whole number"
    if kind in {"float_parsing", "float_type", "finite_number"}:
        return "must be a finite number" if kind == "finite_number" else "must be a number"
    if kind in {"bool_parsing", "bool_type"}:
        return "must be true or false"
    if kind in {"string_type"}:
        return "must be text"
    if kind == "string_unicode":  # !!binary bytes that are not UTF-8: 'unable to parse raw data as a unicode string'
        return "must be UTF-8 text"
    if kind in {"dict_type", "model_type", "model_attributes_type"}:
        target = _model_at(model, tuple(error["loc"]))
        if target is SweepParameter:  # a bare list is the likely slip
            return "must be a mapping: {values: [...]} for a list, or {start: ..., stop: ..., num: ...} for a range"
        keys = f" (keys: {', '.join(sorted(target.model_fields))})" if target is not None else ""
        return f"must be a mapping of keys to values{keys}"
    if kind in {"list_type", "tuple_type"}:
        return "must be a list"
    if kind == "string_too_short":
        return "must not be empty"
    if kind in {"too_short", "too_long"}:  # pydantic: 'Dictionary should have at least 1 item after validation, not 0'
        bound = ctx["min_length"] if kind == "too_short" else ctx["max_length"]
        return f"must hold {'at least' if kind == 'too_short' else 'at most'} {bound} item{'s' * (bound != 1)}"
    if kind == "string_pattern_mismatch" and ctx.get("pattern") == NAME_PATTERN:
        return NAME_RULE
    message = error["msg"]
    for prefix in ("Value error, ", "Assertion failed, "):
        message = message.removeprefix(prefix)
    return message[:1].lower() + message[1:]


def shown_value(value) -> str:
    """``value`` as a problem line quotes it: cut short, but a text (a path) long enough to
    keep its file's name."""
    return short_repr(value, 240 if isinstance(value, str) else 80)


KEY_SHOWN = 60


def _shown_key(part) -> str:
    """A part of a problem's path, its middle cut past KEY_SHOWN characters: a key is the
    preset's or the command line's own text, of any length."""
    text = str(part)
    return text if len(text) <= KEY_SHOWN else f"{text[: KEY_SHOWN // 2]}...{text[-KEY_SHOWN // 2 :]}"


def format_validation_error(exc: ValidationError, model: type[BaseModel], prefix: str = "") -> list[str]:
    """One line per pydantic error: ``path: message, got value``. A required field
    missing because it was misspelt is said once, by the misspelling's suggestion."""
    errors = exc.errors(include_url=False)
    misspelt = {
        (*error["loc"][:-1], name)
        for error in errors
        if error["type"] == "extra_forbidden"
        for name in close_names(str(error["loc"][-1]), _allowed_keys(model, tuple(error["loc"][:-1])), FIELD_CUTOFF)[:1]
    }
    lines = []
    for error in _one_per_union(_short_tuples(errors)):
        if error["type"] == "missing" and tuple(error["loc"]) in misspelt:
            continue
        if error["type"] == "invalid_key" or error["loc"][-1:] == ("[key]",):  # pydantic's loc: the key's repr, or the key and '[key]'
            parent = error["loc"][:-2] if error["loc"][-1] == "[key]" else error["loc"][:-1]
            path = ".".join(_shown_key(p) for p in (prefix, *parent) if p != "")
            lines.append(f"{path or '(preset)'}: {_key_problem(error['input'])}")
            continue
        path = ".".join(_shown_key(p) for p in (prefix, *error["loc"]) if p != "")
        line = f"{path or '(preset)'}: {_describe(error, model)}"
        checked_together = error["type"] == "value_error" and (not error["loc"] or isinstance(error["input"], dict))
        if error["type"] != "missing" and not checked_together:  # a check of several fields names their values
            line += f", got {shown_value(error['input'])}"
        lines.append(line)
    return lines


YAML_KINDS = {bool: "true or false", int: "a whole number", float: "a number", type(None): "null"}


def _key_problem(key) -> str:
    """A key that is no text (``2001-01-01:``, ``3:``, ``1.5:``), as the preset wrote it."""
    import datetime

    written = key.isoformat() if isinstance(key, datetime.date) else "null" if key is None else \
        str(key).lower() if isinstance(key, bool) else _shown_key(key)
    kind = "a date" if isinstance(key, datetime.date) else YAML_KINDS.get(type(key), "no text")
    return f"the key {written} must be text, and YAML reads it as {kind}: quote it ('{written}')"


def _short_tuples(errors: list[dict]) -> list[dict]:
    """pydantic's 'missing' of each item a pair lacks (``region.x.1`` for ``x: [5]``, both items
    for ``[]``) as one error of the pair itself: it must hold that many items."""
    def lacking(error):
        return error["type"] == "missing" and error["loc"] and isinstance(error["loc"][-1], int)

    last = {tuple(error["loc"][:-1]): error for error in errors if lacking(error)}
    return [{**error, "loc": error["loc"][:-1], "type": "too_short", "ctx": {"min_length": error["loc"][-1] + 1}}
            if lacking(error) else error for error in errors
            if not lacking(error) or last[tuple(error["loc"][:-1])] is error]  # fmt: skip


UNION_MEMBERS = {"str": "text", "bool": "true or false", "int": "a whole number", "float": "a number", "none": "null",
                 "constrained-int": "a whole number", "constrained-float": "a number", "constrained-str": "text"}
"""pydantic's tag of a plain type in a union (the last part of its error's path), as a person says it
(``constrained-int``: an ``Annotated[int, Field(ge=0)]``)."""
BOUND_ERRORS = {"greater_than", "greater_than_equal", "less_than", "less_than_equal", "string_too_short",
                "string_too_long", "multiple_of"}
"""pydantic's errors of a value of the right type past a bound: in a union, the one that says what is wrong."""


def _one_per_union(errors: list[dict]) -> list[dict]:
    """pydantic's errors, those of one value against each type of a union (``str | int | ...``:
    one error per type, its path ending in the type's name, ``values.0.str``, ``values.0.int``)
    made one error at the value's own path that lists what it may be."""

    def union_loc(error):  # the value's path if the error is one type's of a union
        loc = tuple(error["loc"])
        member = loc and loc[-1] in UNION_MEMBERS and error["type"] not in {"extra_forbidden", "missing"}
        return loc[:-1] if member else None

    groups: dict[tuple, list[dict]] = {}
    for error in errors:
        if (loc := union_loc(error)) is not None:
            groups.setdefault(loc, []).append(error)
    out = []
    for error in errors:
        group = groups.get(union_loc(error)) if union_loc(error) is not None else None
        if group is None or len(group) < 2:  # a key that happens to be named "int", say
            out.append(error)
        elif len(bounds := [e for e in group if e["type"] in BOUND_ERRORS]) == 1:  # -1 for text | int >= 0
            if error is bounds[0]:
                out.append({**error, "loc": union_loc(error)})
        elif error is group[0]:
            kinds = list(dict.fromkeys(UNION_MEMBERS[e["loc"][-1]] for e in group))
            out.append({**error, "loc": union_loc(error), "type": "union_of_plain_types",
                        "msg": f"must be {', '.join(kinds[:-1])} or {kinds[-1]}"})  # fmt: skip
    return out


# ------------------------------------------------------------------ numbers
# pydantic takes true as 1 for a number, and .inf / .nan for a float unless told
# otherwise; a plugin's Params would each have to say so. One walk over the
# data against the model's annotations refuses them everywhere instead.


def _kinds(annotation) -> set:
    """The plain types a field accepts (unions and Optional unpacked)."""
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        return set().union(*(_kinds(arg) for arg in typing.get_args(annotation)))
    if typing.get_origin(annotation) is typing.Annotated:  # Annotated[int, Field(ge=0)] in a union: an int
        return _kinds(typing.get_args(annotation)[0])
    return {annotation}


def _nested_model(annotation) -> type[BaseModel] | None:
    for kind in _kinds(annotation):
        if isinstance(kind, type) and issubclass(kind, BaseModel):
            return kind
    return None


def _sequence_kind(kinds: set):
    """The list or tuple type among a field's kinds (``tuple[float, float] | None``: the tuple), or None."""
    return next((kind for kind in kinds if typing.get_origin(kind) in (list, tuple)), None)


def _number_problem(
    value, path: str, allow_inf_nan: bool, what: str = "a number", positive: bool = False, own: Bounds | None = None
) -> str | None:
    """``positive``: the field's own bounds refuse 0 (gt=0, ge=1), so the range said leaves it out; ``own``:
    its bounds, said instead of the magnitudes any number must keep where the number lies outside them."""
    allowed = "between 1e-100 and 1e+100" if positive else "0 or between 1e-100 and 1e+100 in magnitude"
    if isinstance(value, bool):
        return f"{path}: must be {what}, not true or false, got {str(value).lower()}"
    if isinstance(value, str):  # YAML reads 1e308 (no dot) as text, which pydantic then takes as a number
        try:
            number = float(value)
        except ValueError:
            return None  # not a number at all: pydantic says so
        if past_double_precision(value, number):  # 1e400, 1e-400: not infinity, not zero
            return f"{path}: must be {own.said if own and not own.holds(number) else allowed}, got {short_repr(value)}"
        value = number
    if isinstance(value, float) and not math.isfinite(value):
        return None if allow_inf_nan else f"{path}: must be a finite number, got {value!r}"
    if isinstance(value, int | float) and (abs(value) > MAX_MAGNITUDE or 0 < abs(value) < 1 / MAX_MAGNITUDE):
        return f"{path}: must be {own.said if own and not own.holds(value) else allowed}, got {short_repr(value)}"
    return None


@dataclass(frozen=True)
class Bounds:
    """A field's lower and upper bounds (pydantic's ge or gt, and le or lt)."""

    low: float
    low_strict: bool
    high: float
    high_strict: bool

    @classmethod
    def of(cls, field) -> Bounds | None:
        """The field's bounds when it has both, or a lower one above the least magnitude, its top
        then that of every number (points: >= 8 and <= 1e+100, not 'between 1e-100 and 1e+100',
        which 2 is); else None (the magnitudes are said)."""
        said = _limits(field)
        low = said.get("ge", said.get("gt"))
        if not {"le", "lt"} & said.keys() and (low is None or low <= 1 / MAX_MAGNITUDE):
            return None
        return cls(low, "ge" not in said, said.get("le", said.get("lt", MAX_MAGNITUDE)), "lt" in said)

    @property
    def said(self) -> str:  # as pydantic's own refusal reads: >= 1 and <= 10000000
        return f"{'>' if self.low_strict else '>='} {self.low} and {'<' if self.high_strict else '<='} {self.high}"

    def holds(self, number: float) -> bool:
        above = number > self.low if self.low_strict else number >= self.low
        return above and (number < self.high if self.high_strict else number <= self.high)


def _limits(field) -> dict[str, float]:
    """A field's own bounds, by pydantic's names (ge, gt, le, lt)."""
    return {key: getattr(m, key) for m in field.metadata for key in ("ge", "gt", "le", "lt") if getattr(m, key, None) is not None}


def _refuses_zero(field) -> bool:
    """Whether a field's own bounds refuse 0 and every number below it (gt=0, ge=1)."""
    limits = _limits(field)
    return ("gt" in limits and limits["gt"] >= 0) or ("ge" in limits and limits["ge"] > 0)


def number_problems(model: type[BaseModel], data, prefix: str = "") -> list[str]:
    """Numeric fields of ``model`` given true/false, infinity or NaN (unless the
    field allows them), or a magnitude beyond MAX_MAGNITUDE, in ``data``; and true/false
    fields given anything else (pydantic takes 0, 1 and the text 'yes' or 'off' as a
    bool, where a numeric field takes no bool)."""
    if not isinstance(data, dict):
        return []
    problems = []
    for name, field in model.model_fields.items():
        if name not in data:
            continue
        value, path = data[name], f"{prefix}.{name}" if prefix else name
        nested = _nested_model(field.annotation)
        item = typing.get_args(field.annotation)[-1] if typing.get_origin(field.annotation) is dict else None
        kinds = _kinds(field.annotation)
        allow = any(getattr(m, "allow_inf_nan", False) for m in field.metadata)
        if nested is not None and isinstance(value, dict):
            problems += number_problems(nested, value, path)
        elif isinstance(item, type) and issubclass(item, BaseModel) and isinstance(value, dict):
            for key, entry in value.items():
                problems += number_problems(item, entry, f"{path}.{key}")
        elif kinds - {type(None)} == {bool} and value is not None and not isinstance(value, bool):
            problems.append(f"{path}: must be true or false, got {shown_value(value)}")
        elif kinds & {int, float} and bool not in kinds and not (str in kinds and isinstance(value, str)):
            problem = _number_problem(value, path, allow, "text or a number" if str in kinds else "a number",
                                      positive=_refuses_zero(field), own=Bounds.of(field))  # fmt: skip
            problems += [problem] if problem else []
        elif kinds & {typing.Any, object} and not allow:  # any value: none may hide an infinity JSON cannot hold
            problems += _non_finite(value, path)
        elif (sequence := _sequence_kind(kinds)) is not None and isinstance(value, list):
            items = set().union(*(_kinds(a) for a in typing.get_args(sequence) if a is not Ellipsis))
            if items & {int, float} and bool not in items:
                problems += [p for i, v in enumerate(value) if (p := _number_problem(v, f"{path}[{i}]", allow))]
    return problems


def _non_finite(value, path: str) -> list[str]:
    """Infinity or NaN anywhere in ``value`` (a field of any type): summary.json would write it as
    null, and a resume would then run with None (every other field refuses them by its type)."""
    if isinstance(value, float) and not math.isfinite(value):
        return [f"{path}: must be a finite number, got {value!r}"]
    if isinstance(value, dict):
        return [p for key, entry in value.items() for p in _non_finite(entry, f"{path}.{key}")]
    if isinstance(value, list | tuple):
        return [p for i, entry in enumerate(value) for p in _non_finite(entry, f"{path}[{i}]")]
    return []


def merge_problems(numbers: list[str], pydantic_lines: list[str]) -> list[str]:
    """Both lists, without a pydantic line for a field the number check already named (its
    items as ``x[0]``, pydantic's as ``x.0``), nor for a section holding one: a check across
    its fields read the refused value as another (true as 1: 'stop must be > start (1.0)'),
    and pydantic runs none of them when a field of the section fails."""

    def field(line: str) -> str:
        return re.sub(r"\[(\d+)\]", r".\1", line.split(": ", 1)[0])

    named = {field(line) for line in numbers}
    return numbers + [line for line in pydantic_lines if field(line) not in named
                      and not any(name.startswith(field(line) + ".") for name in named)]  # fmt: skip


def fold_point_problems(problems: list[tuple[int, str, str]], shown: int = 3) -> list[str]:
    """A sweep's ``(point number, label, problem)`` lines, as ``label: problem``, in their
    order, at most ``shown`` of one problem told apart only by its numbers (a value, a
    bound); then one line naming the other points with it: a log range over a whole-number
    field otherwise repeats one refusal for each of 40 sweep points."""
    lines, seen, folded = [], {}, {}
    for number, label, problem in problems:
        kind = re.sub(r"\d[\d.e+-]*", "#", problem)
        seen[kind] = seen.get(kind, 0) + 1
        if seen[kind] <= shown:
            lines.append(f"{label}: {problem}")
        else:
            folded.setdefault(kind, (problem.split(": ", 1)[0], []))[1].append(number)
    for field, numbers in folded.values():
        if numbers == list(range(numbers[0], numbers[-1] + 1)):
            listed = f"{numbers[0]} to {numbers[-1]}"
        else:  # the first few and the last: every point of a grid's other axis would fill the screen
            listed = ", ".join(map(str, numbers)) if len(numbers) <= 6 else f"{', '.join(map(str, numbers[:3]))}, ..., {numbers[-1]}"
        lines.append(f"sweep points {listed} ({len(numbers)} more): {field}: the same problem, with their own values")
    return lines

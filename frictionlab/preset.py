"""Presets: YAML scenes, validated in two phases into a ``Scene``.

Phase one checks the structure (``Preset``); phase two looks up each named
plugin and validates its ``params`` with the plugin's own ``Params`` model.
Every problem is reported, each as ``dotted.path: what is wrong, got VALUE``.
"""

from __future__ import annotations

import copy
import functools
import math
import os
import types
import typing
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, ValidationError, model_validator

from .errors import FrictionlabError, PluginError, PresetError, PresetFileError, short_repr
from .inputs import InputFileProblem, input_fields, is_relative, read_regular_file, regular_file_problem
from .plugin import ContactSolver, ForceNormalisation, SlopeEstimator, SpectrumGenerator
from .registry import Registry, default_registry
from .safe_yaml import YamlLimit, YamlProblem, load_yaml

PLUGIN_SLOTS = {"spectrum": "spectrum", "solver": "solver", "slope": "slope"}  # preset key -> kind

MAX_PRESET_BYTES = 256 * 1024  # presets are a few kB; refused by size before anything is read
MAX_SWEEP_POINTS = 1000  # counted from the axes, before any point is built
MAX_MAGNITUDE = 1e100  # numbers in a preset: 0, or 1e-100 <= |x| <= 1e100 (products of a few stay finite)
NAME_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9._+-]{0,99}$"
NAME_RULE = (
    "must be 1 to 100 letters, digits, '.', '_', '+' or '-', starting with a letter or digit "
    "(it names the output folder)"
)


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class PluginChoice(_Strict):
    name: str = Field(description="Name of the plugin (see `frictionlab plugins`).")
    params: dict[str, Any] = Field(
        default_factory=dict, description="The plugin's parameters (see `frictionlab schema`)."
    )


class Loading(_Strict):
    control: Literal["force", "indentation"] = Field(
        "force", description="Whether the loads are total normal forces or indentations (rigid-body approach)."
    )
    start: float = Field(gt=0, description="First load (force, or indentation), > 0.")
    stop: float = Field(gt=0, description="Last load, >= start.")
    steps: int = Field(ge=2, le=1_000_000, description="Number of load steps, start and stop included.")
    spacing: Literal["linear", "log"] = Field("linear", description="Load steps evenly spaced in value or in log.")

    @model_validator(mode="after")
    def _ordered(self):
        if self.stop <= self.start:
            raise ValueError(f"stop must be > start ({self.start}). Got {self.stop} instead.")
        return self

    def values(self) -> np.ndarray:
        if self.spacing == "log":
            return np.geomspace(self.start, self.stop, self.steps)
        return np.linspace(self.start, self.stop, self.steps)


class FitSettings(_Strict):
    bootstrap: int = Field(
        1000, ge=0, le=100_000, description="Bootstrap resamples over realizations for the intervals (0: none)."
    )
    confidence: float = Field(0.95, gt=0, lt=1, description="Confidence level of the intervals.")


class OutputSettings(_Strict):
    realizations: bool = Field(True, description="Keep per-realization curves in realizations.npz.")
    plot: bool = Field(True, description="Draw plot.png (xi against f with the fit).")


SweepScalar = str | bool | int | float | None


class SweepParameter(_Strict):
    """The values one swept parameter takes: a list, or a range start..stop with num values."""

    values: list[SweepScalar] | None = Field(None, description="Explicit values (YAML scalars); or give a range.")
    start: float | None = Field(None, allow_inf_nan=False, description="First value of a range.")
    stop: float | None = Field(None, allow_inf_nan=False, description="Last value of a range (included).")
    num: int | None = Field(None, ge=1, le=100_000, description="Number of values of a range, >= 1.")
    spacing: Literal["linear", "log"] = Field("linear", description="Range values evenly spaced in value or in log.")

    @model_validator(mode="after")
    def _one_form(self):
        ranged = {"start": self.start, "stop": self.stop, "num": self.num}
        given = [k for k, v in ranged.items() if v is not None]
        if self.values is not None and given:
            raise ValueError(f"give either values or a range (start, stop, num), not both. Got values and {', '.join(given)}")
        if self.values is None and not given:
            raise ValueError("give values: [...] or a range start, stop, num")
        if self.values is not None and not self.values:
            raise ValueError("values must not be empty")
        if given and len(given) < 3:
            missing = [k for k in ranged if k not in given]
            raise ValueError(f"a range needs start, stop and num; missing: {', '.join(missing)}")
        if given and self.spacing == "log" and (self.start <= 0 or self.stop <= 0):
            raise ValueError(f"a log range needs start > 0 and stop > 0. Got start={self.start!r}, stop={self.stop!r} instead")
        return self

    def count(self) -> int:
        """How many values, without making them."""
        return len(self.values) if self.values is not None else int(self.num)

    def points(self) -> list:
        """The values, in order (ranges rounded to 12 significant digits so labels and --set stay clean)."""
        if self.values is not None:
            return list(self.values)
        make = np.geomspace if self.spacing == "log" else np.linspace
        raw = [float(f"{v:.12g}") for v in make(self.start, self.stop, self.num)]
        whole = float(self.start).is_integer() and float(self.stop).is_integer()
        return [int(v) if whole and v.is_integer() else v for v in raw]


class SweepSettings(_Strict):
    """A sweep: every point is the preset with the swept paths set (see frictionlab/sweep.py)."""

    mode: Literal["grid", "zip"] = Field(
        "grid", description="grid: every combination of the values; zip: the i-th values of every list together."
    )
    parameters: dict[str, SweepParameter] = Field(
        min_length=1, description="Dotted preset path -> its values, e.g. spectrum.params.hurst: {values: [0.5, 1.0]}."
    )

    @model_validator(mode="after")
    def _zip_lengths(self):
        if self.mode == "zip":
            lengths = {path: p.count() for path, p in self.parameters.items()}
            if len(set(lengths.values())) > 1:
                listed = ", ".join(f"{path}: {n}" for path, n in lengths.items())
                raise ValueError(f"mode zip needs the same number of values for every parameter. Got {listed} instead")
        points = self.count()
        if points > MAX_SWEEP_POINTS:
            axes = " x ".join(str(p.count()) for p in self.parameters.values())
            raise ValueError(
                f"the sweep has {points:,} points ({self.mode} of {axes}); at most {MAX_SWEEP_POINTS:,} are allowed"
            )
        return self

    def count(self) -> int:
        """Points of the sweep, counted from its axes (none is made)."""
        counts = [p.count() for p in self.parameters.values()]
        return math.prod(counts) if self.mode == "grid" else (counts[0] if counts else 0)


class Preset(_Strict):
    name: str = Field(
        pattern=NAME_PATTERN,
        description="Short name of the scene (letters, digits, '.', '_', '+', '-'); names the default output folder.",
    )
    description: str = Field("", description="What the scene is and where its numbers come from.")
    seed: int = Field(0, ge=0, description="Root seed: realization i uses SeedSequence(seed, spawn_key=(0, i)).")
    realizations: int = Field(ge=1, le=10_000_000, description="Number of independent random lines (M).")
    spectrum: PluginChoice = Field(description="Spectrum generator: how the rough lines are made.")
    solver: PluginChoice = Field(
        default_factory=lambda: PluginChoice(name="mdr"), description="Contact solver."
    )
    slope: PluginChoice = Field(
        default_factory=lambda: PluginChoice(name="forward-difference"), description="Slope estimator."
    )
    loading: Loading = Field(description="The load sweep.")
    fit: FitSettings = Field(default_factory=FitSettings, description="Fit of xi = a + b ln f.")
    output: OutputSettings = Field(default_factory=OutputSettings, description="What is written.")
    sweep: SweepSettings | None = Field(
        None, description="Optional parameter sweep: `frictionlab run` then runs one ensemble per point."
    )


@dataclass(frozen=True)
class Scene:
    """A validated preset with its plugins instantiated: what the engine runs."""

    preset: Preset
    spectrum: SpectrumGenerator
    solver: ContactSolver
    slope: SlopeEstimator
    # The 2D generator the preset named when the solver presses lines only: ``spectrum`` is
    # then its MDR-equivalent line, and ``geometry`` says so.
    surface: SpectrumGenerator | None = None

    @property
    def geometry(self) -> str:
        """Which geometry runs: 'line', 'surface', or 'mdr-equivalent line of a surface'."""
        if self.surface is not None:
            return "mdr-equivalent line of a surface"
        return "surface" if self.spectrum.dimension == 2 else "line"

    @property
    def normalisation(self) -> ForceNormalisation:
        """What the loads mean and how f is formed, for the profiles that run."""
        return self.solver.normalisation(self.spectrum.dimension)

    @property
    def named_spectrum(self) -> SpectrumGenerator:
        """The spectrum the preset names (the surface, when its MDR-equivalent line runs)."""
        return self.surface if self.surface is not None else self.spectrum

    @functools.cached_property
    def loads(self) -> np.ndarray:
        return self.preset.loading.values()

    @property
    def control(self) -> str:
        return self.preset.loading.control

    def slot_plugins(self) -> dict:
        """The plugin the preset named in each slot (the surface, not its equivalent line)."""
        return {"spectrum": self.named_spectrum, "solver": self.solver, "slope": self.slope}

    def resolved(self) -> dict:
        """The preset with every default filled in, plugin params included."""
        data = self.preset.model_dump(mode="json")
        if data.get("sweep") is None:
            data.pop("sweep", None)  # a plain run (or one sweep point) has no sweep section
        for slot, plugin in self.slot_plugins().items():
            data[slot] = {"name": plugin.name, "params": plugin.params.model_dump(mode="json")}
        return data

    def input_files(self) -> dict[str, str]:
        """The files the run reads, by dotted parameter (absolute paths)."""
        return {
            f"{slot}.params.{field}": getattr(plugin.params, field)
            for slot, plugin in self.slot_plugins().items()
            for field in input_fields(type(plugin.params))
        }


# ------------------------------------------------------------------ messages


def _allowed_keys(model: type[BaseModel] | None, loc: tuple) -> list[str]:
    """Field names of the model reached by walking ``loc`` into ``model``."""
    for part in loc:
        if model is None or not isinstance(part, str) or part not in model.model_fields:
            return []
        annotation = model.model_fields[part].annotation
        model = annotation if isinstance(annotation, type) and issubclass(annotation, BaseModel) else None
    return sorted(model.model_fields) if model is not None else []


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
        return "is not a known field" + (f"; allowed: {', '.join(allowed)}" if allowed else "")
    if kind == "missing":
        return "is required"
    if kind == "literal_error":
        return f"must be one of {ctx['expected']}"
    if kind in {"int_parsing", "int_type", "int_from_float"}:
        return "must be a whole number"
    if kind in {"float_parsing", "float_type", "finite_number"}:
        return "must be a finite number" if kind == "finite_number" else "must be a number"
    if kind in {"bool_parsing", "bool_type"}:
        return "must be true or false"
    if kind in {"string_type"}:
        return "must be text"
    if kind in {"dict_type", "model_type", "model_attributes_type"}:
        return "must be a mapping of keys to values"
    if kind == "string_too_short":
        return "must not be empty"
    if kind == "string_pattern_mismatch" and ctx.get("pattern") == NAME_PATTERN:
        return NAME_RULE
    message = error["msg"]
    for prefix in ("Value error, ", "Assertion failed, "):
        message = message.removeprefix(prefix)
    return message[:1].lower() + message[1:]


def format_validation_error(exc: ValidationError, model: type[BaseModel], prefix: str = "") -> list[str]:
    """One line per pydantic error: ``path: message, got value``."""
    lines = []
    for error in exc.errors(include_url=False):
        path = ".".join(str(p) for p in (prefix, *error["loc"]) if p != "")
        line = f"{path or '(preset)'}: {_describe(error, model)}"
        if error["type"] != "missing" and not (error["type"] == "value_error" and not error["loc"]):
            line += f", got {short_repr(error['input'])}"
        lines.append(line)
    return lines


# ------------------------------------------------------------------ loading


def load_preset_file(path: str | Path) -> dict:
    """Read a preset file: a regular file of at most MAX_PRESET_BYTES of UTF-8
    YAML within the limits of ``safe_yaml``. A file that cannot be used is a
    PresetFileError, bad YAML a PresetError; neither quotes the file."""
    path = Path(path)
    try:
        raw = read_regular_file(path, limit=MAX_PRESET_BYTES, what="preset file")
    except InputFileProblem as exc:
        raise PresetFileError([f"(file): {exc}"], source=str(path)) from None
    try:
        text = raw.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise PresetFileError(
            [f"(file): not UTF-8 text (byte {exc.start + 1}, line {line}); save the preset as UTF-8"], source=str(path)
        ) from None
    try:
        data = load_yaml(text)
    except YamlLimit as exc:
        raise PresetFileError([f"(file): {exc}"], source=str(path)) from None
    except YamlProblem as exc:
        raise PresetError([f"(file): {exc}"], source=str(path)) from None
    if not isinstance(data, dict):
        raise PresetError(
            [f"(file): a preset must be a mapping of keys to values. Got {type(data).__name__} instead."],
            source=str(path),
        )
    return data


def resolve_input_paths(data: dict, base_dir: str | Path, registry: Registry | None = None) -> dict:
    """A copy of preset ``data`` whose relative input-file paths (plugin
    parameters declared ``InputFile``, and swept values of one) are taken from
    ``base_dir``, the folder of the preset file they were written in."""
    registry = registry or default_registry()
    data = copy.deepcopy(data)
    base = Path(os.path.abspath(base_dir))
    sweep = data.get("sweep") if isinstance(data.get("sweep"), dict) else {}
    swept = sweep.get("parameters") if isinstance(sweep.get("parameters"), dict) else {}
    for slot, kind in PLUGIN_SLOTS.items():
        choice = data.get(slot) if isinstance(data.get(slot), dict) else {}
        names = [choice.get("name")]
        if isinstance(swept.get(f"{slot}.name"), dict):
            names += list(swept[f"{slot}.name"].get("values") or [])
        fields: set[str] = set()
        for name in names:
            try:
                fields.update(input_fields(registry.get(kind, name).Params))
            except (FrictionlabError, TypeError, AttributeError):  # reported when the preset is validated
                continue
        for field in fields:
            params = choice.get("params")
            if isinstance(params, dict) and is_relative(params.get(field)):
                params[field] = str(base / params[field])
            axis = swept.get(f"{slot}.params.{field}")
            if isinstance(axis, dict) and isinstance(axis.get("values"), list):
                axis["values"] = [str(base / v) if is_relative(v) else v for v in axis["values"]]
    return data


def read_preset(path: str | Path, overrides: list[str] = (), registry: Registry | None = None) -> dict:
    """Preset data from a file, its relative input paths taken from the file's
    folder, then ``--set`` overrides applied (a relative path given there is
    taken from the current folder, as in any command line)."""
    data = resolve_input_paths(load_preset_file(path), Path(path).parent, registry)
    return apply_overrides(data, list(overrides))


def apply_overrides(data: dict, assignments: list[str]) -> dict:
    """Apply ``dotted.path=value`` assignments (values parsed as YAML scalars)."""
    data = copy.deepcopy(data)
    problems = []
    for assignment in assignments:
        path, sep, raw = assignment.partition("=")
        keys = [k.strip() for k in path.split(".")]
        if not sep or not all(keys):
            problems.append(f"--set {assignment!r}: must look like dotted.path=value, e.g. spectrum.params.hurst=0.8")
            continue
        try:
            value = load_yaml(raw) if raw.strip() else ""
        except YamlProblem:
            value = raw
        node = data
        for depth, key in enumerate(keys[:-1]):
            child = node.get(key)
            if child is None:
                child = node[key] = {}
            if not isinstance(child, dict):
                problems.append(
                    f"--set {assignment!r}: {'.'.join(keys[: depth + 1])} is a value, not a mapping"
                )
                break
            node = child
        else:
            node[keys[-1]] = value
    if problems:
        raise PresetError(problems, source="--set")
    return data


def build_scene(
    data: dict, registry: Registry | None = None, source: str | None = None, base_dir: str | Path | None = None
) -> Scene:
    """Validate preset data (structure, then each plugin's params) into a Scene.
    ``base_dir``: the folder relative input-file paths in ``data`` are taken
    from (the preset file's; without it, the current folder)."""
    registry = registry or default_registry()
    if not isinstance(data, dict):
        raise PresetError([f"(preset): must be a mapping of keys to values. Got {type(data).__name__} instead."], source)
    if base_dir is not None:
        data = resolve_input_paths(data, base_dir, registry)
    numbers = number_problems(Preset, data)
    try:
        preset = Preset.model_validate(data)
    except ValidationError as exc:
        problems = _merge_problems(numbers, format_validation_error(exc, Preset))
        # Check the plugin sections that are well formed too, so every problem shows at once.
        for slot, kind in PLUGIN_SLOTS.items():
            try:
                choice = PluginChoice.model_validate(data.get(slot))
            except ValidationError:
                continue
            problems += _plugin_problems(registry, slot, kind, choice)[1]
        raise PresetError(problems, source=source) from None
    plugins, problems = {}, list(numbers)
    for slot, kind in PLUGIN_SLOTS.items():
        instance, slot_problems = _plugin_problems(registry, slot, kind, getattr(preset, slot))
        plugins[slot] = instance
        problems += slot_problems
    if problems:
        raise PresetError(problems, source=source)
    problems = [
        f"{slot}.params.{field}: {problem}, got {short_repr(getattr(plugin.params, field))}"
        for slot, plugin in plugins.items()
        for field in input_fields(type(plugin.params))
        if (problem := regular_file_problem(getattr(plugin.params, field)))
    ]
    if problems:  # before anything reads them (an equivalent line reads its map now)
        raise PresetError(problems, source=source)
    # Store normalised plugin names so the resolved preset is canonical.
    for slot in PLUGIN_SLOTS:
        getattr(preset, slot).name = plugins[slot].name
    return Scene(preset=preset, **_match_dimensions(plugins, source))


def _match_dimensions(plugins: dict, source: str | None) -> dict:
    """Fit the geometry to what the solver and the slope estimator accept: a surface goes to a
    solver of lines as its MDR-equivalent line; any other mismatch is a PresetError, and so is
    a non-periodic profile (a scan) given to a solver or estimator of periodic profiles only."""
    spectrum, solver, slope = plugins["spectrum"], plugins["solver"], plugins["slope"]
    made = spectrum.dimension
    shape = {1: "lines", 2: "surfaces"}
    if made not in solver.dimensions:
        try:
            line = spectrum.equivalent_line() if made == 2 and 1 in solver.dimensions else None
        except ValueError as exc:
            raise PresetError([f"spectrum: its MDR-equivalent line is invalid: {exc}"], source=source) from None
        if line is None:
            raise PresetError(
                [f"solver.name: {solver.name} presses {' and '.join(shape[d] for d in solver.dimensions)} "
                 f"only, but spectrum {spectrum.name} makes {shape[made]}"
                 + (" and has no MDR-equivalent line" if made == 2 and 1 in solver.dimensions else "")],
                source=source,
            )
        plugins = {**plugins, "spectrum": line, "surface": spectrum}
        made = 1
    if made not in slope.dimensions:
        raise PresetError(
            [f"slope.name: {slope.name} takes {' and '.join(shape[d] for d in slope.dimensions)} only, "
             f"but the {shape[made][:-1]} that runs here is {'2D' if made == 2 else '1D'}"],
            source=source,
        )
    if not plugins["spectrum"].periodic():
        scan = f"spectrum {spectrum.name} is not periodic (periodic: false, a scan whose ends do not meet)"
        make_periodic = "set spectrum.params.periodic: true if its ends meet (after detrend)"
        problems = []
        if solver.periodic_only:
            problems.append(f"solver.name: {solver.name} presses periodic profiles only, but {scan}: "
                            f"use a solver of independent springs (mdr, winkler), or {make_periodic}")
        if slope.periodic_only:
            problems.append(f"slope.name: {slope.name} differentiates periodic profiles only, but {scan}: "
                            f"use forward-difference or central-difference, or {make_periodic}")
        if problems:
            raise PresetError(problems, source=source)
    return plugins


def _plugin_problems(registry: Registry, slot: str, kind: str, choice: PluginChoice):
    try:
        cls = registry.get(kind, choice.name)
    except PluginError as exc:
        return None, [f"{slot}.name: {exc}"]
    numbers = number_problems(cls.Params, choice.params, f"{slot}.params")
    try:
        params = cls.Params.model_validate(choice.params)
    except ValidationError as exc:
        return None, _merge_problems(numbers, format_validation_error(exc, cls.Params, prefix=f"{slot}.params"))
    return (None, numbers) if numbers else (cls(params), [])


# ------------------------------------------------------------------ numbers
# pydantic takes true as 1 for a number, and .inf / .nan for a float unless told
# otherwise; a plugin's Params would each have to say so. One walk over the
# data against the model's annotations refuses them everywhere instead.


def _kinds(annotation) -> set:
    """The plain types a field accepts (unions and Optional unpacked)."""
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        return set().union(*(_kinds(arg) for arg in typing.get_args(annotation)))
    return {annotation}


def _nested_model(annotation) -> type[BaseModel] | None:
    for kind in _kinds(annotation):
        if isinstance(kind, type) and issubclass(kind, BaseModel):
            return kind
    return None


def _number_problem(value, path: str, allow_inf_nan: bool) -> str | None:
    if isinstance(value, bool):
        return f"{path}: must be a number, not true or false, got {str(value).lower()}"
    if isinstance(value, str):  # YAML reads 1e308 (no dot) as text, which pydantic then takes as a number
        try:
            value = float(value)
        except ValueError:
            return None  # not a number at all: pydantic says so
    if isinstance(value, float) and not math.isfinite(value):
        return None if allow_inf_nan else f"{path}: must be a finite number, got {value!r}"
    if isinstance(value, int | float) and (abs(value) > MAX_MAGNITUDE or 0 < abs(value) < 1 / MAX_MAGNITUDE):
        return f"{path}: must be 0 or between 1e-100 and 1e+100 in magnitude, got {short_repr(value)}"
    return None


def number_problems(model: type[BaseModel], data, prefix: str = "") -> list[str]:
    """Numeric fields of ``model`` given true/false, infinity or NaN (unless the
    field allows them), or a magnitude beyond MAX_MAGNITUDE, in ``data``."""
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
        elif kinds & {int, float} and bool not in kinds:
            problem = _number_problem(value, path, allow)
            problems += [problem] if problem else []
        elif typing.get_origin(field.annotation) in (list, tuple) and isinstance(value, list):
            items = set().union(*(_kinds(a) for a in typing.get_args(field.annotation) if a is not Ellipsis))
            if items & {int, float} and bool not in items:
                problems += [p for i, v in enumerate(value) if (p := _number_problem(v, f"{path}[{i}]", allow))]
    return problems


def _merge_problems(numbers: list[str], pydantic_lines: list[str]) -> list[str]:
    """Both lists, without a pydantic line for a field the number check already named."""
    named = {line.split(": ", 1)[0] for line in numbers}
    return numbers + [line for line in pydantic_lines if line.split(": ", 1)[0] not in named]


def load_scene(
    path: str | Path, overrides: list[str] = (), registry: Registry | None = None
) -> Scene:
    """File -> overrides -> validated Scene."""
    return build_scene(read_preset(path, overrides, registry), registry=registry, source=str(path))


# ------------------------------------------------------------------ schema


def preset_json_schema(registry: Registry | None = None) -> dict:
    """JSON Schema of a preset, with each installed plugin's params, for editors."""
    registry = registry or default_registry()
    schema = Preset.model_json_schema()
    defs = schema.setdefault("$defs", {})
    for slot, kind in PLUGIN_SLOTS.items():
        variants = []
        for info in registry.infos(kind):
            params_schema = info.cls.Params.model_json_schema(ref_template="#/$defs/{model}")
            for def_name, definition in params_schema.pop("$defs", {}).items():
                defs.setdefault(def_name, definition)
            variants.append(
                {
                    "type": "object",
                    "title": info.name,
                    "description": info.summary,
                    "properties": {"name": {"const": info.name}, "params": params_schema},
                    "required": ["name"],
                    "additionalProperties": False,
                }
            )
        description = schema["properties"][slot].get("description", "")
        schema["properties"][slot] = {"description": description, "oneOf": variants}
    defs.pop("PluginChoice", None)
    schema["title"] = "frictionlab preset"
    return schema


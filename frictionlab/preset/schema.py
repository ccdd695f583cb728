"""The structure of a preset: pydantic models of every section (phase one of the
validation), and the JSON Schema of a preset with the installed plugins' params."""

from __future__ import annotations

import math
from fractions import Fraction
from typing import Annotated, Any, Literal

import numpy as np
from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from ..plugin import KINDS
from ..plugin.registry import Registry, default_registry

MAX_SWEEP_POINTS = 1000  # counted from the axes, before any point is built
NAME_PATTERN = r"^[A-Za-z0-9][A-Za-z0-9._+-]{0,99}$"
NAME_RULE = (
    "must be 1 to 100 of a-z, A-Z, 0-9, '.', '_', '+' or '-', starting with a letter or digit "
    "(it names the output folder)"
)


class _Strict(BaseModel):
    model_config = ConfigDict(extra="forbid")


class PluginChoice(_Strict):
    name: str = Field(description="Name of the plugin (see `frictionlab plugins`).")
    params: dict[str, Any] = Field(
        default_factory=dict, description="The plugin's parameters (see `frictionlab schema`)."
    )


MAX_STEPS = 40_000  # load steps of a preset: its curve.csv, 14 numbers a step at most, is read back (16 MiB at most)
MAX_REALIZATIONS = 10_000_000  # realizations of a preset


class Loading(_Strict):
    control: Literal["force", "indentation"] = Field(
        "force", description="Whether the loads are total normal forces or indentations (rigid-body approach)."
    )
    start: float = Field(gt=0, description="First load (force, or indentation), > 0.")
    stop: float = Field(gt=0, description="Last load, > start.")
    steps: int = Field(ge=2, le=MAX_STEPS, description="Number of load steps, start and stop included.")
    spacing: Literal["linear", "log"] = Field("linear", description="Load steps evenly spaced in value or in log.")
    unit: Literal["force", "f", "pressure", "contact-fraction"] = Field(
        "force",
        description="What start and stop are under force control: 'force' (the solver's load, in E* x length^2), "
        "'f' (the dimensionless force F / (E* h L)), 'pressure' (the nominal pressure over E*, p / E* = F / (E* A)), "
        "or 'contact-fraction' (a target real-contact fraction in (0, 1), the force found per surface by solving).",
    )

    @model_validator(mode="after")
    def _ordered(self):
        if self.stop <= self.start:
            raise ValueError(f"stop must be > start ({self.start}). Got {self.stop} instead.")
        if self.unit != "force" and self.control != "force":
            raise ValueError(f"unit {self.unit!r} gives loads, not indentations: it needs control 'force'")
        if self.unit == "contact-fraction" and self.stop >= 1:
            raise ValueError(
                f"stop must be < 1 under unit contact-fraction (a fraction of the area). Got {self.stop} instead."
            )
        return self

    def values(self) -> np.ndarray:
        if self.spacing == "log":
            return np.geomspace(self.start, self.stop, self.steps)
        return np.linspace(self.start, self.stop, self.steps)


MAX_BOOTSTRAP = 100_000  # resamples: a summary.json read back is held to it too


class FitSettings(_Strict):
    bootstrap: int = Field(
        1000, ge=0, le=MAX_BOOTSTRAP, description="Bootstrap resamples over realizations for the intervals (0: none, else at least 2)."
    )
    confidence: float = Field(0.95, gt=0, lt=1, description="Confidence level of the intervals.")

    @field_validator("bootstrap")
    @classmethod
    def _an_interval(cls, value: int) -> int:
        if value == 1:  # its '95% interval' was that resample's numbers: of no width, and off the estimate
            raise ValueError("must be 0 (no intervals) or at least 2: one resample gives an interval of one point, "
                             "not a spread")  # the value is said after it
        return value


class OutputSettings(_Strict):
    realizations: bool = Field(True, description="Keep per-realization curves in realizations.npz.")
    plot: bool = Field(True, description="Draw plot.png (xi against f with the fit).")


SweepScalar = str | bool | int | float | None


# an int within the magnitudes any number keeps, or a finite float: allow_inf_nan on the union ran
# math.isfinite on an int past a float's range (10**309), an OverflowError (exit 70), not a refusal
RangeEnd = Annotated[int, Field(ge=-(10**100), le=10**100)] | Annotated[float, Field(allow_inf_nan=False)]


class SweepParameter(_Strict):
    """The values one swept parameter takes: a list, or a range start..stop with num values."""

    values: list[SweepScalar] | None = Field(None, description="Explicit values (YAML scalars); or give a range.")
    # int kept as int: a seed of 20 digits is no float's
    start: RangeEnd | None = Field(None, description="First value of a range.")
    stop: RangeEnd | None = Field(None, description="Last value of a range (included).")
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
        if self.values is not None and self.spacing == "log":  # it was ignored: the values ran as listed
            raise ValueError("spacing: log spaces a range (start, stop, num); values are taken as listed: drop "
                             "spacing, or give a range instead of values")  # fmt: skip
        if given and len(given) < 3:
            missing = [k for k in ranged if k not in given]
            raise ValueError(f"a range needs start, stop and num; missing: {', '.join(missing)}")
        if given and self.num == 1 and self.start != self.stop:  # linspace of one value drops stop
            raise ValueError(f"a range of num 1 holds its start ({self.start:g}) only, never its stop ({self.stop:g}): "
                             f"give num >= 2 for both ends, or values: [{self.start:g}] for one value")  # fmt: skip
        if given and self.spacing == "log" and (self.start <= 0 or self.stop <= 0):
            raise ValueError(f"a log range needs start > 0 and stop > 0. Got start={self.start!r}, stop={self.stop!r} instead")
        return self

    def count(self) -> int:
        """How many values, without making them."""
        return len(self.values) if self.values is not None else int(self.num)

    def points(self) -> list:
        """The values, in order (ranges rounded to 12 significant digits so labels and --set stay clean;
        whole values between whole ends exact, and the ends as given: a seed of 13 digits was rounded)."""
        if self.values is not None:
            return list(self.values)
        whole = float(self.start).is_integer() and float(self.stop).is_integer()
        if whole and self.spacing == "linear":
            return _whole_range(int(self.start), int(self.stop), self.num)
        make = np.geomspace if self.spacing == "log" else np.linspace
        with np.errstate(over="ignore", invalid="ignore"):  # ends past 1e100 (stop - start overflows) are refused by name
            raw = [float(f"{v:.12g}") for v in make(float(self.start), float(self.stop), self.num)]
        if whole:
            raw[0], raw[-1] = int(self.start), int(self.stop)
        return [int(v) if whole and float(v).is_integer() else v for v in raw]


def _whole_range(start: int, stop: int, num: int) -> list:
    """``num`` values from ``start`` to ``stop``, evenly spaced: those that are whole exactly, as ints,
    the others rounded to 12 significant digits."""
    if num == 1:
        return [start]
    steps = [start + Fraction(stop - start, num - 1) * i for i in range(num)]
    return [int(v) if v.denominator == 1 else float(f"{float(v):.12g}") for v in steps]


def ensemble_settings(resolved: dict) -> dict:
    """What the numbers of a resolved preset depend on: all of it but its name, description and output."""
    return {key: value for key, value in resolved.items() if key not in ("name", "description", "output")}


def first_repeat(values: list) -> tuple[int, int] | None:
    """The first two places ``values`` holds one value (1 and 1.0 are one), or None."""
    for j, value in enumerate(values):
        for i in range(j):
            if values[i] == value and type(values[i]) is not bool and type(value) is not bool:  # true is no 1
                return i, j
    return None


class SweepSettings(_Strict):
    """A sweep: every point is the preset with the swept paths set, run as an ensemble of its own."""

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

    @model_validator(mode="after")
    def _no_point_twice(self):
        """Two points that set the same values run the same ensemble twice (a value listed twice, a
        range from a value to itself): refused, as loads from a value to itself are."""
        paths = list(self.parameters)
        columns = [self.parameters[path].points() for path in paths]  # at most MAX_SWEEP_POINTS each: counted above
        if self.mode == "grid":
            for path, values in zip(paths, columns, strict=True):
                if (pair := first_repeat(values)) is not None:
                    how = "values give" if self.parameters[path].values is not None else "range (start, stop, num) gives"
                    raise ValueError(f"{path}: its {how} {values[pair[1]]!r} twice (values {pair[0] + 1} and "
                                     f"{pair[1] + 1}): each point with it would run twice; give each value once")  # fmt: skip
        elif (pair := first_repeat(rows := list(zip(*columns, strict=True)))) is not None:
            shown = ", ".join(f"{path}={value!r}" for path, value in zip(paths, rows[pair[1]], strict=True))
            raise ValueError(f"mode zip: points {pair[0] + 1} and {pair[1] + 1} set the same values ({shown}): the same "
                             "ensemble would run twice; give each point once")  # fmt: skip
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
    realizations: int = Field(ge=1, le=MAX_REALIZATIONS, description="Number of independent random lines (M).")
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


def preset_json_schema(registry: Registry | None = None) -> dict:
    """JSON Schema of a preset, with each installed plugin's params, for editors."""
    registry = registry or default_registry()
    schema = Preset.model_json_schema()
    defs = schema.setdefault("$defs", {})
    for slot in KINDS:  # a preset names one plugin of each kind, under the kind's name
        variants = []
        for info in registry.infos(slot):
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


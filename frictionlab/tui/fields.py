"""Form fields derived from pydantic models, and the preset draft they edit.

Nothing here knows a particular plugin: a field's widget kind, bounds, default
and tooltip come from its ``Params`` model, so a third-party plugin's
parameters appear in the form with no code of its own. No Textual here.
"""

from __future__ import annotations

import copy
import types
import typing
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

from pydantic import BaseModel
from pydantic_core import PydanticUndefined

from ..errors import PresetError, shown
from ..io.inputs import describe_input, input_fields
from ..plugin import KINDS
from ..preset import MISSING, Preset, build_scene, resolve_input_paths
from ..io.safe_yaml import load_yaml

_BOUND_SYMBOLS = (("ge", ">="), ("gt", ">"), ("le", "<="), ("lt", "<"))


@dataclass(frozen=True)
class FieldSpec:
    path: tuple[str, ...]  # into the preset data, e.g. ("spectrum", "params", "hurst")
    kind: str  # int | float | choice | bool | text | section | other
    description: str
    required: bool
    default: Any
    optional: bool = False  # None is allowed (empty input)
    choices: tuple = ()
    bounds: str = ""
    model: type[BaseModel] | None = None  # for kind == "section"

    @property
    def name(self) -> str:
        return self.path[-1]

    @property
    def dotted(self) -> str:
        return ".".join(self.path)

    @property
    def widget_id(self) -> str:
        return "field--" + "--".join(self.path)

    def tooltip(self) -> str:
        return "\n".join(self._facts())

    def help_line(self) -> str:
        """The tooltip on one line (under the form): its parts joined by "; ", each
        without its own final full stop (a description ends with one)."""
        return "; ".join(part.removesuffix(".") for part in self._facts())

    def _facts(self) -> list[str]:
        lines = [self.description or self.name]
        if self.bounds:
            lines.append(f"allowed: {self.bounds}")
        if self.choices:
            lines.append("one of: " + ", ".join(map(str, self.choices)))
        lines.append("required" if self.required else f"default: {display(self.default) or 'none'}")
        return lines


def _unwrap_optional(annotation) -> tuple[Any, bool]:
    if typing.get_origin(annotation) in (typing.Union, types.UnionType):
        args = typing.get_args(annotation)
        rest = [a for a in args if a is not type(None)]
        if len(rest) == 1 and len(args) == 2:
            return rest[0], True
    return annotation, False


def _bounds(info) -> str:
    parts = []
    for item in info.metadata:
        for attr, symbol in _BOUND_SYMBOLS:
            value = getattr(item, attr, None)  # annotated_types bounds: each item has one of them
            if value is not None:
                parts.append(f"{symbol} {value}")
    return ", ".join(parts)


def field_specs(model: type[BaseModel], prefix: tuple[str, ...] = ()) -> list[FieldSpec]:
    """One spec per field of ``model``, in declaration order."""
    specs = []
    for name, info in model.model_fields.items():
        annotation, optional = _unwrap_optional(info.annotation)
        choices: tuple = ()
        sub_model = None
        if typing.get_origin(annotation) is Literal:
            kind, choices = "choice", typing.get_args(annotation)
        elif annotation is bool:
            kind = "bool"
        elif annotation is int:
            kind = "int"
        elif annotation is float:
            kind = "float"
        elif annotation is str:
            kind = "text"
        elif isinstance(annotation, type) and issubclass(annotation, BaseModel):
            kind, sub_model = "section", annotation
        else:
            kind = "other"  # lists, mappings, unions: kept as in the file, edited in YAML
        default = info.get_default(call_default_factory=True)
        specs.append(
            FieldSpec(
                path=(*prefix, name),
                kind=kind,
                description=info.description or "",
                required=info.is_required(),
                default=None if default is PydanticUndefined else default,
                optional=optional,
                choices=choices,
                bounds=_bounds(info),
                model=sub_model,
            )
        )
    return specs


def display(value) -> str:
    """A value as the text of an input."""
    if value is None or value is MISSING:
        return ""
    if isinstance(value, BaseModel):
        return ""
    if isinstance(value, float):
        return repr(value)
    if isinstance(value, str):  # one line (YAML folds keep a newline); an escape sequence in the file shown escaped
        return shown(" ".join(value.split("\n")).strip())
    return str(value)


def parse(spec: FieldSpec, text: str):
    """Input text -> the value stored in the draft. Unparseable text is kept as
    text, so the headless validator reports it (``must be a number, got 'abc'``)."""
    if spec.kind == "text":
        return text
    text = text.strip()
    if not text:
        return MISSING
    if spec.kind == "int":
        try:
            return int(text)
        except ValueError:
            pass
    if spec.kind == "float":
        try:
            return float(text)
        except ValueError:
            pass
    try:  # the same reading as the CLI's --set
        value = load_yaml(text)
    except ValueError:  # not YAML, or beyond its limits: kept as typed, and refused by the validator
        return text
    if spec.kind == "int" and isinstance(value, float) and value.is_integer() and abs(value) < 2**53:
        return int(value)  # 1e3 or 50.0 in a whole-number field: saved as 1000, not 1000.0 (1e30 is said as typed)
    return value if isinstance(value, str | int | float | bool) else text


# ------------------------------------------------------------------ draft


def default_plugin_name(slot: str) -> str | None:
    info = Preset.model_fields[slot]
    if info.default_factory is None:
        return None
    return info.default_factory().name


def default_spectrum(registry) -> str:
    """The spectrum a preset gets when it names none (else the first registered)."""
    return default_plugin_name("spectrum") or registry.names("spectrum")[0]


def validation_of(data: dict, registry, base_dir: Path | None = None) -> tuple[list[str], str]:
    """The headless validator's problems for ``data`` (empty when it is valid; relative
    input files taken from ``base_dir``, the preset file's folder, as ``frictionlab
    validate`` takes them) and, for a valid preset, the lines ``frictionlab validate`` prints
    on what its spectrum read from a file (shape, pixel size, unit, rms height), the caveats of
    what it read (a tilt left in, spikes, heights in another unit than the pixels) and those of
    its spectrum's parameters (few pixels on the short cut-off); else ""."""
    try:
        if base_dir is not None:
            data = resolve_input_paths(data, base_dir, registry)
        scene = build_scene(data, registry=registry)
    except PresetError as exc:
        return list(exc.problems), ""
    summary = scene.spectrum.input_summary() or {}
    read = [f"read {describe_input(summary)}"] if summary else []
    caveats = [*summary.get("caveats", ()), *scene.spectrum.caveats()]  # the file's (a tilt, spikes), then the parameters'
    return [], "\n".join(read + [f"caveat: {caveat}" for caveat in caveats])


def problem_path(problem: str) -> str:
    return problem.partition(": ")[0]


def problems_for(problems: list[str], dotted: str) -> list[str]:
    return [p for p in problems if problem_path(p) == dotted]


def preset_from_defaults(name: str, spectrum: str, registry) -> dict:
    """A new preset: every plugin parameter at its default (required ones left
    for the user), and a small starter scene for the preset's required fields."""
    data: dict = {
        "name": name,
        "description": "",
        "seed": 0,
        "realizations": 50,
    }
    for slot in KINDS:
        plugin_name = spectrum if slot == "spectrum" else default_plugin_name(slot)
        cls = registry.get(slot, plugin_name)
        params = {
            s.name: s.default
            for s in field_specs(cls.Params)
            if not s.required and s.default is not None and s.kind != "other"
        }
        data[slot] = {"name": cls.name, "params": params}
    data["loading"] = {"control": "force", "start": 1.0, "stop": 20.0, "steps": 40, "spacing": "log"}
    return data


def shared_params(registry, slot: str, old: str, new: str, params: dict) -> dict:
    """Of ``params`` (plugin ``old``'s), those plugin ``new`` of the same ``slot`` has too, by name:
    kept when the user switches from one to the other (a Hurst exponent from power-law to rolloff;
    they were left blank, "required"). None between spectra of lines and of surfaces (a line's
    points are not a surface's), nor to or from a plugin that reads a file: its spacing is the
    file's, not a generated line's."""
    before, after = registry.get(slot, old), registry.get(slot, new)
    if input_fields(before.Params) or input_fields(after.Params):
        return {}
    if slot == "spectrum" and before.dimension != after.dimension:
        return {}
    return {key: copy.deepcopy(value) for key, value in params.items() if key in after.Params.model_fields}

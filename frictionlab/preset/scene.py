"""The ``Scene``: a validated preset with its plugins instantiated, what the engine runs;
and ``build_scene``, phase two of the validation (each plugin's own ``Params``)."""

from __future__ import annotations

import functools
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from pydantic import BaseModel, TypeAdapter, ValidationError
from pydantic.errors import PydanticSchemaGenerationError

from ..errors import PluginError, PresetError
from ..io.inputs import input_fields, input_file_problem
from ..plugin import KINDS, ContactSolver, ForceNormalisation, SlopeEstimator, SpectrumGenerator
from ..plugin.outputs import answers_problem, refuse
from ..plugin.registry import Registry, default_registry
from .problems import format_validation_error, merge_problems, number_problems, shown_value
from .reading import NOT_A_MAPPING, read_preset, resolve_input_paths
from .schema import PluginChoice, Preset


def model_defaults(model: BaseModel) -> dict:
    """The JSON form of each defaulted field of ``model``, recursing into sub-models."""
    out = {}
    for name, field in type(model).model_fields.items():
        value = getattr(model, name)
        if isinstance(value, BaseModel):
            out[name] = model_defaults(value)
        elif not field.is_required():
            try:
                out[name] = TypeAdapter(field.annotation).dump_python(field.get_default(call_default_factory=True), mode="json")
            except (PydanticSchemaGenerationError, ValueError, TypeError):
                continue  # a default with no JSON form cannot have been stored either
    return out


@dataclass(frozen=True)
class Scene:
    """A validated preset with its plugins instantiated: what the engine runs."""

    preset: Preset
    spectrum: SpectrumGenerator  # the spectrum the preset names
    solver: ContactSolver
    slope: SlopeEstimator
    # When the solver presses lines only and the spectrum makes surfaces: the spectrum's
    # MDR-equivalent line, whose lines are pressed instead (``generator``).
    equivalent_line: SpectrumGenerator | None = None
    # Where the preset came from (a file, a built-in and its --set options): what names it in the
    # refusals made after it was built (its loads), as in those of building it.
    source: str | None = None

    @property
    def generator(self) -> SpectrumGenerator:
        """What makes the profiles that are pressed: the spectrum, or its MDR-equivalent line."""
        return self.equivalent_line if self.equivalent_line is not None else self.spectrum

    @property
    def geometry(self) -> str:
        """Which geometry runs: 'line', 'surface', or 'mdr-equivalent line of a surface'."""
        if self.equivalent_line is not None:
            return "mdr-equivalent line of a surface"
        return "surface" if self.spectrum.dimension == 2 else "line"

    @property
    def pressed(self) -> str:
        """What is pressed, in words and by the name the preset gives: 'power-law lines',
        'power-law-2d surfaces', 'MDR-equivalent lines of power-law-2d surfaces'."""
        return pressed_words(self.spectrum.name, self.spectrum.dimension, self.equivalent_line is not None)

    @property
    def normalisation(self) -> ForceNormalisation:
        """What the loads mean and how f is formed, for the profiles that are pressed (an
        MDR-equivalent line's length said as what it is for the surface)."""
        normalisation = self.solver.normalisation(self.generator.dimension)
        if self.equivalent_line is not None and normalisation.extent == "length":
            words = "L = 2 sqrt(A / pi) the MDR-equivalent line's length, A the surface's apparent area"
            normalisation = replace(normalisation, extent_words=words)
        return normalisation

    @functools.cached_property
    def loads(self) -> np.ndarray:
        return self.preset.loading.values()

    @property
    def control(self) -> str:
        return self.preset.loading.control

    @functools.cached_property
    def solver_loads(self) -> np.ndarray | None:
        """The loads the solver is given: ``loads`` converted from the preset's ``loading.unit``
        (``frictionlab.preset.loads``); None for contact fractions, whose forces are found per profile."""
        from .loads import solver_loads

        return solver_loads(self)

    @functools.cached_property
    def load_scales(self):
        """The force at f = 1, at p / E* = 1, and where full contact starts, for the profiles
        pressed (``frictionlab.preset.loads.load_scales``: realization 0's profile is made once)."""
        from .loads import load_scales

        return load_scales(self)

    @property
    def probed(self) -> bool:
        """Whether realization 0's profile was made and every plugin's answer on it checked
        (``load_scales``, which the run's front doors and validate ask for before a run)."""
        return "load_scales" in vars(self)

    @property
    def forces_vary(self) -> bool:
        """Whether each realization has forces of its own (indentation control, contact fractions)."""
        return self.control == "indentation" or self.preset.loading.unit == "contact-fraction"

    def for_pressing(self) -> Scene:
        """The scene with what pressing its profiles needs: with an MDR-equivalent line, the
        surface's spectrum without what it derived to make the line (its synthesis, its map, as
        large as the surface), which pressing the line never uses; the loads worked out here
        kept. What a worker process is sent, and what a sweep keeps of each point."""
        if self.equivalent_line is None:
            return self
        slim = replace(self, spectrum=type(self.spectrum)(self.spectrum.params))
        slim.__dict__.update({key: value for key, value in self.__dict__.items() if key not in slim.__dict__})
        return slim

    def plugins(self) -> dict:
        """The plugin the preset names for each kind (the spectrum, not its equivalent line)."""
        return {"spectrum": self.spectrum, "solver": self.solver, "slope": self.slope}

    def resolved(self) -> dict:
        """The preset with every default filled in, plugin params included."""
        data = self.preset.model_dump(mode="json")
        if data.get("sweep") is None:
            data.pop("sweep", None)  # a plain run (or one sweep point) has no sweep section
        for kind, plugin in self.plugins().items():
            data[kind] = {"name": plugin.name, "params": plugin.params.model_dump(mode="json")}
        return data

    def defaults(self) -> dict:
        """``resolved()``'s shape, holding only the fields that have a default, each at its
        default: what a run folder written before a field existed is taken to have used."""
        data = model_defaults(self.preset)
        for kind, plugin in self.plugins().items():
            data[kind] = {"params": model_defaults(plugin.params)}
        return data

    def input_files(self) -> dict[str, str]:
        """The files the run reads, by dotted parameter (absolute paths)."""
        return {
            f"{kind}.params.{field}": getattr(plugin.params, field)
            for kind, plugin in self.plugins().items()
            for field in input_fields(type(plugin.params))
        }


def pressed_words(spectrum: str, dimension: int, mdr_line: bool) -> str:
    """``Scene.pressed``: what a ``spectrum`` of ``dimension`` makes is pressed, or (``mdr_line``)
    its surfaces' MDR-equivalent lines."""
    if mdr_line:
        return f"MDR-equivalent lines of {spectrum} surfaces"
    return f"{spectrum} {'surfaces' if dimension == 2 else 'lines'}"


def recorded_pressed(spectrum: str, solver: str, registry: Registry | None = None) -> str | None:
    """``Scene.pressed`` of a run whose preset named the plugins ``spectrum`` and ``solver``,
    from what their installed classes declare, no scene built (a run folder read back: its
    input file may be gone); None where either is not installed. A surface goes to a solver
    of lines as its MDR-equivalent line, as ``_match_dimensions`` makes it."""
    registry = registry or default_registry()
    try:
        made, presses = registry.get("spectrum", spectrum).dimension, registry.get("solver", solver)
    except PluginError:
        return None
    return pressed_words(spectrum, made, made == 2 and made not in presses.dimensions and presses.mdr_lines)


def build_scene(
    data: dict,
    registry: Registry | None = None,
    source: str | None = None,
    base_dir: str | Path | None = None,
    before_reading: Callable[[Scene], None] | None = None,
) -> Scene:
    """Validate preset data (structure, then each plugin's params) into a Scene.
    ``base_dir``: the folder relative input-file paths in ``data`` are taken
    from (the preset file's; without it, the current folder). ``before_reading(scene)``
    is called before a measured file is read whole and before a surface's MDR-equivalent
    line is made (the memory check, which needs only the spectrum's ``grid_shape()``):
    then with the scene as it will be, less its line (``equivalent_line`` None)."""
    registry = registry or default_registry()
    if not isinstance(data, dict):
        raise PresetError([f"(preset): {NOT_A_MAPPING}, got {shown_value(data)}"], source)
    if base_dir is not None:
        data = resolve_input_paths(data, base_dir, registry)
    numbers = number_problems(Preset, data)
    try:
        preset = Preset.model_validate(data)
    except ValidationError as exc:
        problems = merge_problems(numbers, format_validation_error(exc, Preset))
        # Check the plugin sections that are well formed too, so every problem shows at once.
        for slot in KINDS:
            try:
                choice = PluginChoice.model_validate(data.get(slot))
            except ValidationError:
                continue
            problems += _plugin_problems(registry, slot, choice)[1]
        raise PresetError(problems, source=source) from None
    plugins, problems = {}, list(numbers)
    for slot in KINDS:
        instance, slot_problems = _plugin_problems(registry, slot, getattr(preset, slot))
        plugins[slot] = instance
        problems += slot_problems
    if problems:
        raise PresetError(problems, source=source)
    problems = [
        f"{slot}.params.{field}: {problem}, got {shown_value(getattr(plugin.params, field))}"
        for slot, plugin in plugins.items()
        for field in input_fields(type(plugin.params))
        if (problem := input_file_problem(getattr(plugin.params, field)))
    ]
    if problems:  # before anything reads them (an equivalent line reads its map now)
        raise PresetError(problems, source=source)
    spectrum = plugins["spectrum"]
    # A measured profile or surface is read and checked here, not by a worker: its header
    # first, the whole file once the memory check has seen its shape.
    measured = bool(input_fields(type(spectrum.params)))
    if measured:  # what the memory check needs (a table without a header is read whole here)
        _read_checked(spectrum.periodic, source)
        _read_checked(spectrum.grid_shape, source)
    for plugin in plugins.values():  # what the memory check and the geometry read next
        refuse(plugin, answers_problem(plugin))
    # Store normalised plugin names so the resolved preset is canonical.
    for slot in KINDS:
        getattr(preset, slot).name = plugins[slot].name
    checked = []

    def check_then_read(line_of: dict) -> None:
        """The memory check, then the whole measured file: before a line is made of the surface."""
        if before_reading is not None:
            before_reading(Scene(preset=preset, source=source, **line_of))
        checked.append(True)
        if measured:
            _read_checked(spectrum.rms_height, source)

    matched = _match_dimensions(plugins, registry, source, before_line=check_then_read)
    scene = Scene(preset=preset, source=source, **matched)
    if before_reading is not None and not checked:
        before_reading(scene)
    if measured:
        _read_checked(spectrum.rms_height, source)
    if scene.generator is not spectrum:  # the MDR-equivalent line
        refuse(scene.generator, answers_problem(scene.generator))
    return scene


def _read_checked(read: Callable[[], object], source: str | None) -> None:
    """Call a measured spectrum's ``read``: a problem with its file is a PresetError."""
    try:
        read()
    except ValueError as exc:
        raise PresetError([f"spectrum.params: {exc}"], source=source) from None


def _match_dimensions(plugins: dict, registry: Registry, source: str | None,
                      before_line: Callable[[dict], None] = lambda plugins: None) -> dict:  # fmt: skip
    """Fit the geometry to what the solver and the slope estimator accept: a surface goes to a
    solver of lines as its MDR-equivalent line (``before_line(plugins)`` is called before it is
    made); any other mismatch is a PresetError, and so is a non-periodic profile (a scan) given
    to a solver or estimator of periodic profiles only."""
    spectrum, solver, slope = plugins["spectrum"], plugins["solver"], plugins["slope"]
    made = spectrum.dimension
    shape = {1: "lines", 2: "surfaces"}
    if made not in solver.dimensions:
        mdr = made == 2 and solver.mdr_lines  # a line standing for the surface, as the solver declares
        if mdr:
            before_line(plugins)
        try:
            line = spectrum.equivalent_line() if mdr else None
        except ValueError as exc:
            raise PresetError([f"spectrum: its MDR-equivalent line is invalid: {exc}"], source=source) from None
        if line is None:
            able = [i.name for i in registry.infos("solver") if made in i.cls.dimensions or (made == 2 and i.cls.mdr_lines)]
            raise PresetError(
                [f"solver.name: {solver.name} presses {' and '.join(shape[d] for d in solver.dimensions)} "
                 f"only, but spectrum {spectrum.name} makes {shape[made]}"
                 + (" and has no MDR-equivalent line" if mdr else "")
                 + (f": use solver {' or '.join(able)}" if able and not mdr else "")],
                source=source,
            )
        plugins = {**plugins, "equivalent_line": line}
        made = 1
    if made not in slope.dimensions:
        raise PresetError(
            [f"slope.name: {slope.name} takes {' and '.join(shape[d] for d in slope.dimensions)} only, "
             f"but the {shape[made][:-1]} that runs here is {'2D' if made == 2 else '1D'}"],
            source=source,
        )
    if not plugins.get("equivalent_line", spectrum).periodic():
        scan, make_periodic = spectrum.not_periodic_advice()
        problems = []
        for kind, plugin, verb in (("solver", solver, "presses"), ("slope", slope, "differentiates")):
            if plugin.periodic_only:
                others = [i.name for i in registry.infos(kind) if not i.cls.periodic_only and made in i.cls.dimensions]
                instead = f"use {' or '.join(others)}, or " if others else ""
                problems.append(f"{kind}.name: {plugin.name} {verb} periodic profiles only, but {scan}: "
                                f"{instead}{make_periodic}")
        if problems:
            raise PresetError(problems, source=source)
    periodic = plugins.get("equivalent_line", spectrum).periodic()
    if slope.undefined_points(periodic) and not solver.undefined_slopes:
        able = [i.name for i in registry.infos("solver") if i.cls.undefined_slopes and made in i.cls.dimensions]
        raise PresetError(
            [f"slope.params: {slope.name} leaves points of this {'periodic' if periodic else 'non-periodic'} profile "
             f"without a slope, which solver {solver.name} cannot take: use "
             + (f"solver {' or '.join(able)}, or " if able else "")
             + "slope parameters that give every point a slope"],
            source=source,
        )
    return plugins


def _plugin_problems(registry: Registry, slot: str, choice: PluginChoice):
    try:
        cls = registry.get(slot, choice.name)
    except PluginError as exc:
        return None, [f"{slot}.name: {exc}"]
    numbers = number_problems(cls.Params, choice.params, f"{slot}.params")
    try:
        params = cls.Params.model_validate(choice.params)
    except ValidationError as exc:
        return None, merge_problems(numbers, format_validation_error(exc, cls.Params, prefix=f"{slot}.params"))
    except ArithmeticError:  # a plugin's own check computing with a number refused above (10**400 points)
        if not numbers:
            raise
        return None, numbers
    return (None, numbers) if numbers else (cls(params), [])


def load_scene(
    path: str | Path, overrides: list[str] = (), registry: Registry | None = None
) -> Scene:
    """A preset file, or a built-in's name (``"quickstart"``), with ``--set`` overrides
    (``["spectrum.params.hurst=0.5"]``) applied -> validated Scene."""
    from .builtin import locate_preset

    resolved, source = locate_preset(path)
    return build_scene(read_preset(resolved, overrides, registry), registry=registry, source=source)

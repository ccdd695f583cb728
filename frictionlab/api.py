"""The Python API, for notebooks and scripts: ``frictionlab.run`` and ``frictionlab.load``.

``run`` takes a preset in any form (a file, a built-in's name, YAML text, a dict, a
``Preset``), overrides by dotted path, and returns a ``Result``: the fit of
xi = a + b ln f with its intervals and R², the table per load step, a plot. With
``out=FOLDER`` it writes the same run folder as ``frictionlab run --out FOLDER``;
``load(FOLDER)`` reads any finished run back, with the same numbers.

    >>> import frictionlab
    >>> r = frictionlab.run("quickstart", realizations=8, workers=1, progress=False)
    >>> r.status, r.realizations
    ('completed', (8, 8))
    >>> import numpy as np
    >>> ln_f, xi = np.log(r.table["f"]), r.table["xi"]  # a least-squares line passes through the means:
    >>> bool(abs(r.fit.a + r.fit.b * ln_f.mean() - xi.mean()) < 1e-9)
    True
    >>> sorted(r.table)[:3]
    ['F', 'contact_count', 'contact_fraction']

Overrides are dotted paths into the preset. Python keywords cannot hold dots: give
them as a dict, or spell each dot as a double underscore:

    >>> a = frictionlab.run("quickstart", {"spectrum.params.hurst": 0.6}, realizations=8, workers=1, progress=False)
    >>> b = frictionlab.run("quickstart", spectrum__params__hurst=0.6, realizations=8, workers=1, progress=False)
    >>> a.fit.a == b.fit.a and a.preset["spectrum"]["params"]["hurst"] == 0.6
    True

A run folder, read back:

    >>> import tempfile, pathlib
    >>> folder = pathlib.Path(tempfile.mkdtemp()) / "run"
    >>> r = frictionlab.run("quickstart", realizations=8, workers=1, progress=False, plot=False, out=folder)
    >>> frictionlab.load(folder).fit == r.fit
    True

The CLI's ``frictionlab run`` goes through ``run_scene`` here, so both write the
same files; ``--no-plot`` is ``plot=False``.
"""

from __future__ import annotations

import os
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from .arguments import data_argument, flag_argument, overrides_argument, path_argument, plain_copy
from .errors import FrictionlabError, FrontEnd, PresetError, advising, raised_here, short_repr, shown, warn_user
from .compute.signals import RunInterrupted, interrupted_since, mark
from .options import RunOptions
from .result import Result, SweepResult, load
from .runs.results import CORRECTED_AREA, column_units, curve_headers

if TYPE_CHECKING:
    from .compute.ensemble import RunOutcome
    from .preset import Preset, Scene

__all__ = ["Result", "RunInterrupted", "SweepResult", "load", "read_preset_input", "run", "run_scene", "scene_record",
           "validate"]  # fmt: skip


def read_preset_input(
    preset: str | Path | Mapping[str, Any] | Preset, overrides: Mapping[str, Any] | None = None, /, **keys: Any
) -> tuple[dict, str, Path | None]:
    """Preset data from any input form, overrides applied; with a name for messages
    and the folder relative input files are taken from (a file's own; else None: the
    current folder). Forms: a ``Preset``; a dict; a string holding YAML (a newline,
    or a ``{...}`` flow mapping); else a path to a file, or a built-in's name.
    ``overrides`` may also come as a keyword (no preset has such a key); ``preset`` may not."""
    from .preset import Preset, load_preset_file, set_path
    from .preset.paths import SWEPT, is_dotted_path, swept_paths
    from .preset.builtin import locate_preset
    from .preset.reading import not_a_mapping, resolve_input_paths
    from .io.safe_yaml import YamlProblem, load_yaml

    if "overrides" in keys:  # run(preset, overrides={...}): the positional argument, named
        if overrides is not None:
            raise FrictionlabError("overrides given twice: as the second argument and as overrides=; give one")
        overrides = keys.pop("overrides")
    if "preset" in keys:
        raise FrictionlabError("preset given twice: as the first argument and as preset=; give it first, unnamed")
    overrides = overrides_argument(overrides)
    data_argument(keys, "keyword overrides")
    keys = plain_copy(keys)
    base_dir = None
    if isinstance(preset, Preset):
        data, source = preset.model_dump(mode="json", exclude_none=True), f"<Preset {preset.name}>"
    elif isinstance(preset, Mapping):
        data_argument(preset, "preset")  # before the copy, which recurses
        data, source = plain_copy(preset), "<dict>"  # never change the caller's dict
    elif isinstance(preset, str) and ("\n" in preset or preset.lstrip().startswith("{")):
        try:
            data = load_yaml(preset)
        except YamlProblem as exc:
            raise PresetError([f"(text): {exc}"], source="<YAML text>") from None
        if not isinstance(data, dict):
            raise PresetError([f"(text): {not_a_mapping(data, 'empty text (or comments only)')}"], "<YAML text>")
        source = "<YAML text>"
    elif isinstance(preset, str | os.PathLike):
        # a built-in is named as the CLI names it, not by the installed file the user never touched
        path, source = locate_preset(path_argument(preset, "preset", "a preset file, or a built-in's name"))
        try:
            data = load_preset_file(path)
        except PresetError as exc:
            raise type(exc)(exc.problems, source=source) from None
        base_dir = path.parent
    else:
        raise FrictionlabError(
            f"preset must be a path, a built-in's name, YAML text, a dict or a Preset. Got {type(preset).__name__}."
        )
    if base_dir is not None:
        data = resolve_input_paths(data, base_dir)
    typed = {key.replace("__", "."): key for key in keys}  # a keyword is named as given
    assignments = {**overrides, **{key.replace("__", "."): value for key, value in keys.items()}}
    problems = []
    for path, value in assignments.items():
        if not is_dotted_path(path):
            joined = ("__", "spectrum__params__hurst") if path in typed else ("dots", "spectrum.params.hurst")
            problems.append(f"{short_repr(typed.get(path, path))}: must be field names joined by {joined[0]}, "
                            f"e.g. {joined[1]}")  # fmt: skip
            continue
        try:
            set_path(data, str(path), value)
        except ValueError as exc:
            problems.append(f"{path}: {exc}")
    problems += [f"{typed.get(path, path)}: {SWEPT}; sweep other values, or run the preset once (sweep=None)"
                 for path in swept_paths(data, list(assignments))]  # fmt: skip
    if problems:
        raise PresetError(problems, source="overrides")
    return data, source, base_dir


def scene_record(scene: Scene) -> dict:
    """What a validated preset would run: its plugins, realizations, load steps, what
    its spectrum read from a file (``input``: shape, pixel size, unit, rms height), or None,
    and its loads (``loads``: the force unit, the range in every unit, where full contact
    starts: ``frictionlab.preset.loads.describe_loads``) and what a reader of its run should know
    from its spectrum's parameters alone (``caveats``: ``SpectrumGenerator.caveats()``). Loads the
    solver cannot take are refused."""
    from .plugin.outputs import input_summary_problem, refuse
    from .preset.loads import check_loads, describe_loads

    check_loads(scene)
    preset, read = scene.preset, scene.spectrum.input_summary()
    refuse(scene.spectrum, input_summary_problem(read))  # printed, and JSON under --json
    return {
        "name": preset.name, "realizations": preset.realizations, "spectrum": scene.spectrum.name,
        "pressed": scene.pressed, "solver": scene.solver.name, "slope": scene.slope.name,
        "steps": preset.loading.steps, "control": preset.loading.control, "input": read,
        "loads": describe_loads(scene), "caveats": list(scene.spectrum.caveats()),
    }  # fmt: skip


def _plugin_told(entry):
    """An exception raised in an installed plugin's code comes out of ``entry`` as the
    ``PluginError`` naming that plugin, its distribution and the line, as the CLI tells it
    (the original, frictionlab's frames and all, is its ``__context__``)."""
    import functools

    @functools.wraps(entry)
    def called(*args, **keys):
        from .errors.interrupts import interrupts_marked, raised_by_signal

        with interrupts_marked():  # Ctrl-C told from a plugin's own KeyboardInterrupt
            try:
                return entry(*args, **keys)
            except (Exception, SystemExit, KeyboardInterrupt) as exc:  # a plugin's sys.exit() or own interrupt: its fault
                from .plugin.registry import installed_plugin_fault, solve_failed

                if raised_by_signal(exc) or (fault := solve_failed(exc) or installed_plugin_fault(exc)) is None:
                    raise
                raise fault from None

    return called


@raised_here
@_plugin_told
def validate(preset: str | Path | Mapping[str, Any] | Preset, overrides: Mapping[str, Any] | None = None, /,
             **keys: Any) -> dict:  # fmt: skip
    """Check a preset (any form ``run`` takes, overrides as there) without running it, and
    return what would run (``scene_record``); a measured file is read once, here. Bad input
    raises a ``frictionlab.errors.FrictionlabError`` naming every field at fault.

    >>> import frictionlab
    >>> frictionlab.validate("quickstart")["input"] is None  # a synthetic spectrum reads no file
    True
    """
    from .preset import build_scene
    from .runs.runner import check_one_realization

    if given := [key for key in keys if key in _run_keywords()]:  # run's own, not a preset field: said as such
        raise FrictionlabError(f"validate takes no {', '.join(f'{key}=' for key in given)}: "
                               "that is how frictionlab.run runs a preset; validate checks the preset alone")
    data, source, _ = read_preset_input(preset, overrides, **keys)
    return scene_record(build_scene(data, source=source, before_reading=check_one_realization))


@raised_here
@_plugin_told
def run(
    preset: str | Path | Mapping[str, Any] | Preset,
    overrides: Mapping[str, Any] | None = None,
    /,
    *,
    out: str | Path | None = None,
    workers: int | None = None,
    executor: str | None = None,
    scheduler: str | None = None,
    resume: bool = False,
    force: bool = False,
    plot: bool = True,
    progress: bool = True,
    memory_check: bool = True,
    **keys: Any,
) -> Result | SweepResult:
    """Run a preset and return its ``Result`` (a sweep's: its ``SweepResult``).

    ``preset``: a path, a built-in's name (``"quickstart"``), YAML text, a dict or a
    ``frictionlab.preset.Preset``. ``overrides`` (second, or ``overrides=``): ``{"spectrum.params.hurst": 0.8}``;
    keywords too, a double underscore for each dot (``spectrum__params__hurst=0.8``,
    ``seed=3``, ``realizations=20``), given values taking precedence in that order.

    ``out``: a folder to write the run into (as ``frictionlab run --out``: resumable,
    locked while running; ``resume``, ``force`` as there); None keeps the run in
    memory. ``plot``: draw plot.png into ``out``. ``workers``, ``executor``,
    ``scheduler``: where realizations run (every core by default; the numbers are the
    same whatever they are). ``progress``: a bar on stderr (on a terminal, or in
    Jupyter with ipywidgets: the ``notebook`` extra), plain lines elsewhere.

    A preset with a ``sweep`` runs every point into ``out`` (required: a folder per
    point) and returns a ``SweepResult``. Bad input raises a
    ``frictionlab.errors.FrictionlabError`` naming the field, or the argument
    (``overrides must be a mapping of dotted keys to values, got int``); a dict (the
    preset, the overrides) is held to a preset file's limits: 64 levels of nesting,
    20,000 values. A built-in preset is named as the command line names it
    (``built-in preset 'quickstart'``).

    Ctrl-C (in Jupyter, interrupting the kernel) stops the run within about a second,
    keeps what finished (in ``out``, resumable) and raises ``RunInterrupted``, a
    ``KeyboardInterrupt`` whose ``result`` is the run as it ended: a cell or a loop of
    runs stops there too.
    """
    seen = mark()
    with advising(FrontEnd(options=frozenset(), python=True)):  # a refusal's advice in this function's keywords
        result = _run(preset, overrides, out, workers, executor, scheduler, resume, force, plot, progress, memory_check, keys)
    if interrupted_since(seen) or result.status == "interrupted":  # what finished is kept: the caller stops too
        raise RunInterrupted(result)
    if result.status == "failed" and isinstance(result, Result):  # said where the run was asked for, as the CLI's error
        warn_user(f"{result.name}: run failed: {result.error or 'no fit'}")
    return result


def _run_keywords() -> set[str]:
    """``run``'s keyword-only arguments (``out``, ``workers``...): options, not preset fields."""
    import inspect

    return {p.name for p in inspect.signature(run).parameters.values() if p.kind is p.KEYWORD_ONLY}


def _run(preset, overrides, out, workers, executor, scheduler, resume, force, plot, progress, memory_check, keys):
    from .preset import build_scene
    from .progress import ProgressReporter, SweepProgress
    from .runs.runner import memory_check_before_reading

    out = None if out is None else path_argument(out, "out", "a folder to write the run into")
    if scheduler is not None and not isinstance(scheduler, str):
        raise FrictionlabError(f"scheduler must be a Dask scheduler's address (a str), got {type(scheduler).__name__}")
    resume, force, plot, progress, memory_check = (
        flag_argument(value, name) for name, value in (("resume", resume), ("force", force), ("plot", plot),
                                                       ("progress", progress), ("memory_check", memory_check))
    )  # fmt: skip
    data, source, _ = read_preset_input(preset, overrides, **keys)
    options = RunOptions(
        workers=workers, executor=executor, scheduler=scheduler, resume=resume, force=force, memory_check=memory_check
    )
    reading = None if data.get("sweep") else memory_check_before_reading(options)  # a sweep checks each point
    scene = build_scene(data, source=source, before_reading=reading)
    if scene.preset.sweep is not None:
        scene = scene.for_pressing()  # its points are planned anew: of the base, what pressing needs is kept
        from .runs.sweep import plan_sweep, run_sweep

        if out is None:
            raise FrictionlabError(f"{shown(source)}: a sweep writes a run folder per point: give out=FOLDER")
        sweep = plan_sweep(data, source=source, before_reading=memory_check_before_reading(options))
        run_sweep(sweep, out, options, listeners=[SweepProgress()] if progress else [], plot=plot)
        return load(out)
    result = run_scene(scene, out, options, listeners=[ProgressReporter()] if progress else [], plot=plot)
    if resume:  # a sweep's point resumed alone: its sweep's tables take it, or say why not
        from .runs.sweep import refresh_point_tables

        if (refreshed := refresh_point_tables(out, plot)) is not None and not refreshed[0]:
            warn_user(refreshed[1])
    return result


def run_scene(
    scene: Scene,
    out: str | Path | None,
    options: RunOptions = RunOptions(),
    *,
    listeners: Sequence[object] = (),
    plot: bool = True,
    on_results=None,
    cancel=None,
    drawer=None,
) -> Result:
    """Run a validated ``Scene`` into the folder ``out`` (``runner.run_to_folder``) or,
    when None, in memory (``engine.run``); the one path of ``frictionlab.run`` and of
    ``frictionlab run``. ``on_results(result)`` is called before the figure is drawn
    (by ``drawer``, a ``runs.figures.DrawingProcess``, where one is given)."""
    if out is None:
        from .compute import engine
        from .preset.loads import check_loads
        from .runs.runner import check_memory

        if options.resume:
            raise FrictionlabError("resume needs the run folder: give out=FOLDER")
        if options.memory_check:
            check_memory(scene, options)
        check_loads(scene)  # as run_to_folder does
        outcome = engine.run(scene, options, listeners=listeners, cancel=cancel)
        result = _result(scene, outcome, None, {})
        if on_results is not None:
            on_results(result)
        return result
    from .runs.runner import run_to_folder

    def tell(outcome, files):
        if on_results is not None:
            on_results(_result(scene, outcome, Path(out), files))

    outcome, files = run_to_folder(
        scene, out, options, listeners=listeners, cancel=cancel, plot=plot, on_results=tell, drawer=drawer
    )
    return _result(scene, outcome, Path(out), files)


def _result(scene: Scene, outcome: RunOutcome, folder: Path | None, files: dict[str, Path]) -> Result:
    table = {
        "F": outcome.force, "f": outcome.f, "xi": outcome.xi, "xi_sem": outcome.xi_sem,
        "lines_used": outcome.lines_used, "contact_count": outcome.contact_count, "contact_fraction": outcome.contact_fraction,
        "indentation": outcome.indentation,
    }  # fmt: skip
    if outcome.half_load_points is not None:
        table["half_load_points"] = outcome.half_load_points
    if outcome.real_area_corrected is not None:  # the solvers that correct their area only
        table[CORRECTED_AREA] = outcome.real_area_corrected
    if outcome.real_gradient_rms is not None:  # the solvers that give g_r only
        table.update(real_gradient_rms=outcome.real_gradient_rms, kappa=outcome.kappa, kappa_r=outcome.kappa_r)
    if outcome.contact_spots is not None:  # the solvers that count spots only
        table["contact_spots"] = outcome.contact_spots
    return Result(
        name=scene.preset.name, status=outcome.status, fit=outcome.fit, table=table,
        realizations=(outcome.done, outcome.requested), normalisation=outcome.normalisation.definition,
        preset=scene.resolved(), elapsed=outcome.sessions_elapsed, caveats=outcome.caveats, folder=folder,
        outcome=outcome, files=dict(files), input=scene.spectrum.input_summary(),
        units=column_units(curve_headers(scene)), error=outcome.error,
    )  # fmt: skip

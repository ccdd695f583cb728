"""``frictionlab report``: run the paper's Figs. 2 to 5 and write REPRODUCTION.md with its
figures, the paper's numbers beside frictionlab's; with ``readings`` also the readings
of the paper's method and Fig. 5 with h calibrated at each H."""

from __future__ import annotations

import os
import re
import time
from collections.abc import Callable
from pathlib import Path

from ..compute.dask_session import one_dask_cluster
from ..errors import OutputRefused, first_names, shown_name, write_failed
from ..io.inputs import InputFileProblem, open_regular_file, read_regular_file
from ..io.files import atomic_write, output_path_problem, refuse_unreplaceable
from ..options import RunOptions
from ..runs.rundir import new_run_folder
from ..runs.runfolder import output_subfolder
from ..compute.signals import WorkInterrupted
from .figures import FIGURES, find_presets, kept_in, run_figures
from .markdown import HEADING, markdown
from .plots import FIGURE_MARK, plot_fig5, plot_fig5_calibrated, plot_figure
from .readings import (CALIBRATED_FOLDER, READINGS, READINGS_FOLDER, check_reading_folders, fig5_calibrated_readings,
                       run_readings)


MARK_BYTES = 4096  # of a PNG: matplotlib writes its text chunks right after the header
MARK_CHUNK = b"tEXtSoftware\x00" + FIGURE_MARK["Software"].encode()
MAX_MARKDOWN_BYTES = 16 << 20  # of a report's markdown, read for its image links (one is about 20 kB)
FIGURE_FILES = ("fig2.png", "fig3.png", "fig4.png", "fig5.png", "fig5-calibrated.png")
DEFAULT_MARKDOWN, DEFAULT_FIGURES = "REPRODUCTION.md", "figures"  # in --out


def report_paths(out_dir=None, markdown_path=None, figures_dir=None, *, force: bool = False) -> tuple[Path, Path, Path]:
    """The run folders, the markdown and the figures folder of a report: by
    default all in a fresh folder ``runs/report-<timestamp>/`` (``REPRODUCTION.md``,
    ``figures/``). An existing markdown or figure is refused unless ``force``, and so is a
    folder given for the markdown or a file for a folder. An --out that is not a report's, or
    a REPRODUCTION.md in it that no report wrote, is refused even with ``force``: it replaces
    only what a report wrote."""
    for option, folder in (("--out", out_dir), ("--figures", figures_dir)):
        problem = output_path_problem(Path(folder)) if folder else None
        if problem:
            raise OutputRefused(f"{option}: {problem}; give a folder")
    problem = output_path_problem(Path(markdown_path).parent) if markdown_path else None
    if problem:
        raise OutputRefused(f"--markdown: {problem}; give a file in a folder you can write to")
    if markdown_path and Path(markdown_path).is_dir():
        raise OutputRefused(f"--markdown {shown_name(markdown_path)} is a folder: give a file name (e.g. {shown_name(Path(markdown_path) / 'REPRODUCTION.md')})")
    if not out_dir:  # what a fresh folder would hold is new: only a --markdown or --figures given can be taken
        _refuse_overwriting(Path(markdown_path) if markdown_path else None, Path(figures_dir) if figures_dir else None, force)
    out_dir = Path(out_dir) if out_dir else new_run_folder("report")
    named = bool(markdown_path)
    markdown_path = Path(markdown_path) if markdown_path else out_dir / DEFAULT_MARKDOWN
    figures_dir = Path(figures_dir) if figures_dir else output_subfolder(out_dir, DEFAULT_FIGURES, "run the report again", make=False)
    _refuse_foreign_folder(out_dir, markdown_path, figures_dir)
    if not named:  # one there is replaced only if a report wrote it
        _refuse_foreign_markdown(markdown_path)
    _refuse_inside_runs(out_dir, markdown_path, figures_dir)  # first: 'or --force' would not lift them
    _refuse_markdown_among_figures(markdown_path, figures_dir)
    _refuse_overwriting(markdown_path, figures_dir, force)
    return out_dir, markdown_path, figures_dir


def _refuse_foreign_markdown(path: Path) -> None:
    """Refuse a REPRODUCTION.md in --out that does not begin as a report does (a link, a file of
    the user's that merely has its name): --force wrote the report over it."""
    if not os.path.lexists(path) or (path.is_dir() and not path.is_symlink()):
        return  # a folder is refused as one (refuse_unreplaceable), --force or not
    heading = (HEADING + "\n").encode()
    try:
        with open_regular_file(path, follow_links=False) as fh:
            ours = fh.read(len(heading)) == heading
    except (InputFileProblem, OSError):
        ours = False
    if not ours:
        raise OutputRefused(f"{shown_name(path)} was not written by frictionlab report: the report never replaces it, "
                            "--force or not; move it aside, or give --markdown another file")  # fmt: skip


def _refuse_markdown_among_figures(markdown_path: Path, figures_dir: Path) -> None:
    """Refuse a markdown that is a figure (written over Fig. 2, linking to itself) or the figures'
    folder, or a folder above it (every figure ran, then the markdown was a folder: exit 1)."""
    markdown, folder = os.path.realpath(markdown_path), os.path.realpath(figures_dir)
    if markdown in {os.path.realpath(figures_dir / name) for name in FIGURE_FILES}:
        raise OutputRefused(f"--markdown {shown_name(markdown_path)} is a figure the report draws in {shown_name(figures_dir)}: "
                            "give another file name")  # fmt: skip
    if folder == markdown or folder.startswith(markdown + os.sep):
        raise OutputRefused(f"--markdown {shown_name(markdown_path)} is the figures' folder {shown_name(figures_dir)}, "
                            "or a folder above it: give another file name, or other --figures")  # fmt: skip


def _refuse_foreign_folder(out_dir: Path, markdown_path: Path, figures_dir: Path) -> None:
    """Refuse an --out that holds anything but what a report writes there (its runs' folders, its
    figures folder, its markdown): the report filled a folder of the user's with runs and figures."""
    files = {DEFAULT_MARKDOWN}
    if os.path.realpath(markdown_path.parent) == os.path.realpath(out_dir):
        files.add(markdown_path.name)
    names = {*(fig.key for fig in FIGURES), READINGS_FOLDER, CALIBRATED_FOLDER, DEFAULT_FIGURES, *files}
    if os.path.realpath(figures_dir.parent) == os.path.realpath(out_dir):
        names.add(figures_dir.name)
    try:
        held = sorted(p.name for p in out_dir.iterdir() if not _written_by_a_report(p.name, names, files))
    except FileNotFoundError:
        return
    except OSError as exc:  # output_path_problem made a file there: only listing it failed
        raise OutputRefused(f"--out {shown_name(out_dir)} cannot be listed ({exc.strerror or exc}): give another folder") from None
    if held:
        listed = first_names(held)
        raise OutputRefused(
            f"--out {shown_name(out_dir)} is not empty and is not the folder of an earlier report (it holds {listed}): "
            "give a new or empty folder (the report writes into no other, --force or not)"
        )


def _written_by_a_report(name: str, names: set[str], files: set[str]) -> bool:
    """Whether ``name`` is one a report writes in its --out (a temporary file of its markdown too):
    one that is a link or of the wrong kind is refused as each is checked (``output_subfolder``...)."""
    return name in names or any(name.startswith(f".{file}.") and name.endswith(".tmp") for file in files)


def _refuse_inside_runs(out_dir: Path, markdown_path: Path, figures_dir: Path) -> None:
    """Refuse a markdown or figures folder in a folder of the report's runs: --markdown OUT/fig2/summary.json
    wrote the report over the run's summary, which was then damaged (a file or a folder the run writes)."""
    names = (*(fig.key for fig in FIGURES), READINGS_FOLDER, CALIBRATED_FOLDER)
    runs = [os.path.realpath(out_dir / name) for name in names]
    for option, path in (("--markdown", markdown_path), ("--figures", figures_dir)):
        where = os.path.realpath(path)
        inside = next((run for run in runs if where == run or where.startswith(run + os.sep)), None)
        if inside is not None:
            raise OutputRefused(f"{option} {shown_name(path)} is in {shown_name(inside)}, where the report keeps "
                                "its runs: give a path outside it")  # fmt: skip


def _refuse_overwriting(markdown_path: Path | None, figures_dir: Path | None, force: bool) -> None:
    figures = [figures_dir / name for name in FIGURE_FILES] if figures_dir else []
    taken = [p for p in ([markdown_path] if markdown_path else []) + figures if os.path.lexists(p)]
    refuse_unreplaceable(taken, "report", "give other --out/--markdown/--figures")
    if taken and not force:
        shown = ", ".join(str(p) for p in taken[:3]) + (", ..." if len(taken) > 3 else "")
        raise OutputRefused(f"the report would overwrite {shown}: give other --out/--markdown/--figures, or --force")
    linked = _linked_figures(markdown_path)
    for figure in (p for p in figures if p in taken and not p.is_symlink()):  # a link is replaced, never its target
        shown_as = os.path.relpath(figure, markdown_path.parent) if markdown_path else None
        if not (_marked(figure) or shown_as in linked):
            raise OutputRefused(f"{shown_name(figure)} was not drawn by frictionlab report: the report never replaces "
                                "it, --force or not; move it aside, or give --figures another folder")  # fmt: skip


def _marked(figure: Path) -> bool:
    """Whether ``figure`` is a PNG holding the mark every report's figure carries (FIGURE_MARK)."""
    try:
        with open_regular_file(figure, follow_links=False) as fh:
            head = fh.read(MARK_BYTES)
    except (InputFileProblem, OSError):
        return False
    return head.startswith(b"\x89PNG") and MARK_CHUNK in head


def _linked_figures(markdown_path: Path | None) -> set[str]:
    """The figures a report's markdown at ``markdown_path`` shows (its image links): those of a
    report drawn before its figures carried FIGURE_MARK are its own too."""
    if markdown_path is None or not os.path.lexists(markdown_path):
        return set()
    try:
        text = read_regular_file(markdown_path, MAX_MARKDOWN_BYTES, follow_links=False).decode("utf-8", "replace")
    except (InputFileProblem, OSError):  # a link, a FIFO, one too long: no report's
        return set()
    if not text.startswith(HEADING + "\n"):
        return set()
    return set(re.findall(r"^!\[[^\]\n]*\]\(([^)\n]+)\)$", text, flags=re.MULTILINE))


def write_report(
    *, presets_dir=None, out_dir=None, markdown_path=None, figures_dir=None,
    options: RunOptions = RunOptions(), readings=False, replicates: int = 1, dpi=90,
    log: Callable[[str], None] = lambda text: None, quiet: bool = True,
) -> Path:  # fmt: skip
    """Run Figs. 2 to 5 (and the readings, each on ``replicates`` independent ensembles), write the
    figures and the markdown; return its path.
    Paths default to a fresh folder (``report_paths``); nothing existing is overwritten unless
    ``options.force``. ``log`` hears what is going on, a line at a time; unless ``quiet``,
    every run shows its progress on stderr (``frictionlab.progress``)."""
    presets = find_presets(presets_dir)
    out_dir, markdown_path, figures_dir = report_paths(out_dir, markdown_path, figures_dir, force=options.force)
    if readings:  # before Figs. 2 to 5 run, not after
        check_reading_folders(out_dir)
    try:
        with one_dask_cluster(options):  # on Dask, every run uses one client and cluster
            started = time.perf_counter()
            log(f"report: running Figs. 2 to 5 from {shown_name(presets)}/ into {shown_name(out_dir)}/")
            runs = run_figures(presets, out_dir, options, progress=not quiet)
            log(f"report: Figs. 2 to 5 ran in {time.perf_counter() - started:.1f} s; drawing")
            images = {}
            for run in runs:
                name = f"{run.figure.key}.png"
                draw = plot_fig5 if run.sweep is not None else plot_figure
                atomic_write(figures_dir / name, lambda fh, run=run, draw=draw: draw(run, fh, dpi=dpi), binary=True)
                images[run.figure.key] = os.path.relpath(figures_dir / name, markdown_path.parent or Path("."))
            elapsed = time.perf_counter() - started
            reading_rows = readings_elapsed = fig5_rows = fig5_elapsed = None
            if readings:
                log(f"report: running {len(READINGS)} readings" + (f", each on {replicates} ensembles" if replicates > 1 else ""))
                t0 = time.perf_counter()
                reading_rows = run_readings(runs, out_dir, options, progress=not quiet, replicates=replicates)
                readings_elapsed = time.perf_counter() - t0
                fig5 = next(run for run in runs if run.sweep is not None)
                log(f"report: Fig. 5 with h calibrated at each of {len(fig5.sweep.points)} H")
                t0 = time.perf_counter()
                fig5_rows = run_readings(runs, out_dir, options, readings=fig5_calibrated_readings(fig5.sweep),
                                         folder_name=CALIBRATED_FOLDER, progress=not quiet)  # fmt: skip
                fig5_elapsed = time.perf_counter() - t0
                name = "fig5-calibrated.png"
                atomic_write(figures_dir / name, lambda fh: plot_fig5_calibrated(fig5, fig5_rows, fh, dpi=dpi), binary=True)
                images["fig5-calibrated"] = os.path.relpath(figures_dir / name, markdown_path.parent or Path("."))
    except KeyboardInterrupt as exc:  # Ctrl-C or SIGTERM: a run ended interrupted, or it came between two
        said = f"{exc}; " if isinstance(exc, WorkInterrupted) and str(exc) else ""
        raise WorkInterrupted(f"{said}the runs that finished are kept in {shown_name(out_dir)}; no {shown_name(markdown_path)} written") from None
    except OSError as exc:  # a full disk: what finished stays, as after an interrupt
        raise write_failed(exc, f"{kept_in(out_dir)}; no {shown_name(markdown_path)} written") from None
    command = "frictionlab report" + (" --readings" if readings else "") + (f" --replicates {replicates}" if replicates > 1 else "")
    text = markdown(runs, images, elapsed=elapsed, readings=reading_rows, readings_elapsed=readings_elapsed,
                    fig5_calibrated=fig5_rows, fig5_calibrated_elapsed=fig5_elapsed, workers=options.workers,
                    command=command)  # fmt: skip
    try:  # a path the user named: /dev/stdout is written into
        atomic_write(markdown_path, lambda fh: fh.write(text), devices=True)
    except OSError as exc:  # a full disk, /dev/full: every run finished
        raise write_failed(exc, f"{kept_in(out_dir)} (reading them back)") from None
    log(f"report: wrote {shown_name(markdown_path)} and {len(images)} figures in {shown_name(figures_dir)}/ ({elapsed:.1f} s for Figs. 2 to 5)")
    return markdown_path

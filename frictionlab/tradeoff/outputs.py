"""What the study writes: study.csv, study.md, study.png, and the recommendation.

Every file goes through ``files.atomic_write``. The plot draws each row's
error against its wall time with the Pareto front of all rows.
"""

from __future__ import annotations

import csv
import math
from pathlib import Path

import numpy as np

from ..errors import OutputRefused, shown, shown_name
from ..io.files import atomic_write, output_path_problem, refuse_unreplaceable
from .axes import COLUMNS, Row, Study, grid_side
from .metrics import pareto_front

METRICS = {
    "xi_err_f": "rms over the loads of (xi - xi_ref) / xi_ref, ensemble means compared at equal f "
    "(the reference's f points, ln-f interpolation if the grids differ)",
    "xi_bias_f": "the mean of the same signed: > 0 when xi lies above the reference",
    "approach_err_f": "as xi_err_f for the mean indentation over h, every solver's measured from the first touch of "
    "the highest point against the mean plane of the deformed elastic surface (MDR's springs: their indentation "
    "less their mean compression f h); solver axis only",
    "a_err, b_err": "|a - a_ref| / |a_ref|, |b - b_ref| / |b_ref| of the fits xi = a + b ln f",
    "a_ci_rel, b_ci_rel": "half-width of the bootstrap confidence interval of a, b (over realizations) / |a|, |b|: "
    "the statistical error",
    "xi_ci_rel": "rms over the loads of z sem(xi) / xi, the normal-theory half-width of the mean curve",
    "count_first, count_last": "mean number of points in contact at the first and the last load (MDR: springs of "
    "its line; a surface solver: pixels)",
    "real_area_first, real_area_last": "real contact area fraction at the first and the last load (of a surface; of "
    "a line's length on the half-plane); not defined for MDR",
    "mdr_springs_first, mdr_springs_last": "fraction of the MDR line's springs in contact: a length measure of the "
    "line, not the real contact area of the surface it stands for",
    "approach_first, approach_last": "mean indentation over h at the first and the last load, from the reference "
    "of approach_err_f",
    "seconds": "wall time of the whole ensemble (generate, solve, fit with bootstrap), serial in one process, "
    "best of the repeats",
    "peak_bytes": "tracemalloc peak above the level before the run (numpy buffers included; memory that C "
    "libraries allocate outside Python's allocator, e.g. FFT plans, is not seen)",
}


ROUNDING = 1e-12  # errors below this are agreement to rounding: not drawn on a log axis


def error_in_b(row: Row) -> float:
    """The plot's and the recommendation's error in b: the interval on the realizations axis, else against the reference."""
    return row.b_ci_rel if row.axis == "realizations" else row.b_err


def error_in_xi(row: Row) -> float:
    return row.xi_ci_rel if row.axis == "realizations" else row.xi_err_f


# ------------------------------------------------------------------ csv


def _cell(value) -> str:
    if isinstance(value, bool):
        return "yes" if value else ""
    if isinstance(value, float):
        return "" if not math.isfinite(value) else repr(value)
    return str(value)


def write_csv(fh, rows: list[Row]) -> None:
    writer = csv.writer(fh, lineterminator="\n")
    writer.writerow(COLUMNS)
    for row in rows:
        writer.writerow([_cell(getattr(row, c)) for c in COLUMNS])


# ------------------------------------------------------------------ markdown


def _pct(value: float) -> str:
    if not math.isfinite(value):
        return "–"
    return "0" if value == 0 else f"{100 * value:.3g} %"


def _signed_pct(value: float) -> str:
    return "–" if not math.isfinite(value) else f"{100 * value:+.3g} %"


def _num(value: float, digits: int = 4) -> str:
    return f"{value:.{digits}g}" if math.isfinite(value) else "–"


TABLES = {
    "grid": ("N", "xi_err_f", "a_err", "b_err", "b_ci_rel", "a", "b", "count_first", "count_last"),
    "grid (reference)": ("N", "xi_err_f", "a_err", "b_err", "b_ci_rel", "a", "b", "count_first", "count_last"),
    "realizations": ("M", "b_ci_rel", "a_ci_rel", "xi_ci_rel", "a", "b"),
    "steps": ("K", "a_err", "b_err", "a", "b"),
    "solver": ("solver", "xi_err_f", "xi_bias_f", "a_err", "b_err", "b_ci_rel", "a", "b", "approach_err_f",
               "approach_first", "approach_last", "real_area_first", "real_area_last", "mdr_springs_first",
               "mdr_springs_last"),
    "tolerance": ("tolerance", "xi_err_f", "a_err", "b_err", "a", "b"),
}
PERCENT = {"xi_err_f", "xi_bias_f", "approach_err_f", "a_err", "b_err", "a_ci_rel", "b_ci_rel", "xi_ci_rel"}


def _table_cell(row: Row, column: str) -> str:
    if column in ("N", "M", "K"):
        text = f"{int(row.value)}"
    elif column == "tolerance":
        text = f"{row.tolerance:g}"
    elif column == "solver":
        text = row.solver
    elif column in PERCENT:
        text = _pct(getattr(row, column))
    elif column.startswith(("count", "real_area", "mdr_springs", "approach")):
        text = _num(getattr(row, column), 3)
    else:
        text = _num(getattr(row, column))
    return f"**{text}**" if row.reference and column in ("N", "M", "K", "tolerance", "solver") else text


def axis_table(rows: list[Row], axis: str) -> str:
    columns = (*TABLES[axis], "seconds", "peak MiB")
    lines = ["| " + " | ".join(columns) + " |", "|" + "---|" * len(columns)]
    for row in rows:
        cells = [_table_cell(row, c) for c in TABLES[axis]]
        cells += [f"{row.seconds:.3g}", f"{row.peak_bytes / 2**20:.3g}"]
        lines.append("| " + " | ".join(cells) + " |")
    return "\n".join(lines)


def scene_summary(study: Study) -> str:
    base = study.base
    generator = base.spectrum
    preset, hurst, points = base.preset, generator.hurst_exponent(), grid_side(base)
    loading = preset.loading
    return (
        f"{preset.name}: {generator.name}" + (f", H = {hurst:g}" if hurst is not None else "")
        + (f", N = {points}" + (" per side" if generator.dimension == 2 else "") if points is not None else "")
        + f", M = {preset.realizations}, K = {loading.steps} "
        f"{loading.control} steps from {loading.start:g} to {loading.stop:g}, solver {base.solver.name}, "
        f"slope {base.slope.name}, seed {preset.seed}"
    )


def markdown(study: Study, recommendation: str, command: str = "") -> str:
    out = [heading(study.base.preset.name), ""]
    if command:
        out += [f"`{command}`", ""]
    out += [
        f"Scene: {scene_summary(study)}.",
        "",
        "Every timing is serial in one process (`workers=1`), so times add up and memory is seen by one tracer. "
        "On a shared machine they are noisy: compare orders of magnitude, not percent.",
        "",
        "What each axis holds fixed:",
        "",
        *[f"- {note}" for note in study.notes],
        "",
        "## Metrics (all relative: 1 % = 0.01)",
        "",
        *[f"- `{name}`: {text}." for name, text in METRICS.items()],
        "",
        "Bold: the axis's reference setting (its errors are 0 by definition).",
        "",
    ]
    for axis in dict.fromkeys(row.axis for row in study.rows):
        rows = [r for r in study.rows if r.axis == axis]
        out += [f"## {axis}", "", axis_table(rows, axis), ""]
        notes = [f"- {r.setting} ({r.solver}): {r.note}" for r in rows if r.note and r.note != "reference"]
        if notes:
            out += [*notes, ""]
    out += ["## Recommendation", "", recommendation, ""]
    return "\n".join(out)


# ------------------------------------------------------------------ plot


def plot(study: Study, fh) -> None:
    import matplotlib.ticker
    from matplotlib.figure import Figure  # no pyplot: headless, and a notebook's backend is left alone

    fig = Figure(figsize=(11, 4.8), layout="constrained")
    panels = fig.subplots(1, 2)
    axes_order = list(dict.fromkeys(r.axis for r in study.rows))
    markers = dict(zip(axes_order, "osD^v<>p"))
    for panel, (error, label) in zip(
        panels, [(error_in_b, "relative error in b"), (error_in_xi, "relative error in xi(f)")]
    ):
        rows = [r for r in study.rows if not r.reference]
        cost = np.array([r.seconds for r in rows])
        err = np.array([error(r) for r in rows])
        shown = np.isfinite(err) & (err > ROUNDING) & (cost > 0)
        for i, axis in enumerate(axes_order):
            pick = [j for j, r in enumerate(rows) if r.axis == axis and shown[j]]
            if not pick:
                continue
            panel.plot(cost[pick], err[pick], markers[axis], color=f"C{i}", label=axis, ms=6, alpha=0.85)
            for j in pick:
                text = rows[j].setting if rows[j].axis != "solver" else rows[j].solver
                panel.annotate(text, (cost[j], err[j]), fontsize=6, xytext=(3, 3), textcoords="offset points")
        front = np.flatnonzero(pareto_front(np.where(shown, cost, np.nan), np.where(shown, err, np.nan)))
        front = front[np.argsort(cost[front])]
        if front.size:
            panel.step(cost[front], err[front], "-", where="post", color="k", lw=1.2, alpha=0.7, label="Pareto front")
            panel.plot(cost[front], err[front], "o", mfc="none", mec="k", ms=11, mew=1.2)
        if study.options.target:
            panel.axhline(study.options.target, color="0.5", ls=":", lw=1, label=f"target {study.options.target:.0%}")
        panel.set_xscale("log")
        panel.set_yscale("log")
        panel.xaxis.set_minor_formatter(matplotlib.ticker.NullFormatter())
        panel.set_xlabel("wall time, serial [s]")
        panel.set_ylabel(label)
        panel.grid(True, which="both", alpha=0.3)
        panel.legend(fontsize=7, loc="best")
    fig.suptitle(f"{scene_summary(study)}\n(not drawn: reference rows and errors below 1e-12, agreement to rounding)", fontsize=8)
    fig.savefig(fh, format="png", dpi=110)


# ------------------------------------------------------------------ recommendation


def _smallest_within(rows: list[Row], target: float) -> Row | None:
    """The cheapest setting from which on every finer setting stays within ``target`` (rows sorted by value)."""
    chosen = None
    for row in reversed(rows):
        if not error_in_b(row) <= target:  # NaN counts as not within
            break
        chosen = row
    return chosen


def _unknown_m(measured: int) -> str:
    return (f"an unknown M (no interval of b at M = {measured} to extrapolate from: fit.bootstrap is 0, or there is a "
            "single realization)")  # fmt: skip


def _interval_of_b(row, what: str) -> str:
    if math.isfinite(row.b_ci_rel):
        return f"b's 95% interval from {row.realizations} {what}: +-{_pct(row.b_ci_rel)}"
    return f"no interval of b from {row.realizations} {what}"  # it read '+-–'


def _needed_realizations(measured: int, ci_rel: float, target: float) -> tuple[int, bool] | None:
    """(M, extrapolated?) for a half-width of ``target``, from a half-width ``ci_rel`` at ``measured`` lines (~ 1/sqrt(M));
    None without a half-width (``_unknown_m``): 'M = 50, extrapolated from M = 50' was said of no error at all."""
    if not math.isfinite(ci_rel):
        return None
    return max(2, math.ceil(measured * (ci_rel / target) ** 2)), ci_rel > target


def recommendation(study: Study) -> str:
    target = study.options.target
    hurst = study.base.spectrum.hurst_exponent()
    head = f"for {100 * target:g}% error in b" + (f" at H = {hurst:g}" if hurst is not None else "")
    by_axis = {axis: [r for r in study.rows if r.axis == axis] for axis in dict.fromkeys(r.axis for r in study.rows)}
    solver = study.base.solver.name
    parts = []

    # The preset's solver on the preset's own scene: N, M and K from their axes.
    needs = []
    seconds_per_line, grid_reached = None, True
    grid = by_axis.get("grid", [])
    if grid:
        row = _smallest_within(grid[:-1], target) if len(grid) > 1 else None
        if row is None:
            grid_reached = False
            needs.append(f"N > {int(grid[-2].value)} (not reached on the grid axis)" if len(grid) > 1 else
                         f"an N the grid axis did not measure (it ran only its reference, N = {int(grid[-1].value)}: see the notes)")
        else:
            needs.append(f"N = {int(row.value)} (against N = {int(grid[-1].value)})")
            seconds_per_line = row.seconds / max(1, row.realizations)
    m_needed = None
    realizations = by_axis.get("realizations", [])
    if realizations:
        within = [r for r in realizations if r.b_ci_rel <= target]
        if study.one_surface:  # every realization the same curve: one is the ensemble
            m_needed = 1
            needs.append("M = 1 (every realization is the same surface)")
        elif within:
            m_needed = int(within[0].value)
            needs.append(f"M = {m_needed}")
        elif (needed := _needed_realizations((largest := realizations[-1]).realizations, largest.b_ci_rel, target)):
            m_needed = needed[0]
            needs.append(f"M = {m_needed} (extrapolated as 1/sqrt(M) from M = {largest.realizations})")
        else:
            needs.append(_unknown_m(largest.realizations))
        if seconds_per_line is None:
            seconds_per_line = realizations[-1].seconds / max(1, realizations[-1].realizations)
    steps = by_axis.get("steps", [])
    if len(steps) > 1:
        row = _smallest_within(steps[:-1], target)
        needs.append(f"K = {int(row.value)} load steps" if row else f"K > {int(steps[-2].value)} load steps")
    if needs:
        cost = ""
        if seconds_per_line and m_needed:
            cost = f", {'about' if grid_reached else 'more than'} {seconds_per_line * m_needed:.2g} s serial"
        parts.append(f"{solver} needs " + ", ".join(needs) + cost)

    # The reference: its tolerance and M on the comparison scene.
    tolerance = by_axis.get("tolerance", [])
    solver_rows = by_axis.get("solver", [])
    reference = next((r for r in solver_rows if r.reference), None)
    if reference is not None:
        chosen = reference
        tol_text = ""
        if tolerance:
            loosest = next((r for r in tolerance if error_in_b(r) <= target), tolerance[-1])
            chosen, tol_text = loosest, f"tolerance {loosest.tolerance:g}, "
        per_line = chosen.seconds / max(1, chosen.realizations)
        if (needed := _needed_realizations(reference.realizations, reference.b_ci_rel, target)) is None:
            m_text = f"{_unknown_m(reference.realizations)} at N = {reference.points}"
        else:
            how = f" (extrapolated from M = {reference.realizations})" if needed[1] else ""
            m_text = f"M = {needed[0]}{how} at N = {reference.points}, about {per_line * needed[0]:.2g} s serial"
        parts.append(f"{reference.solver} needs {tol_text}{m_text}")
        what = "surfaces" if study.base.spectrum.dimension == 2 else "lines"
        for row in solver_rows:
            if row.reference:
                continue
            parts.append(
                f"against {reference.solver} on the same {row.realizations} {what} at N = {row.points} and equal f, "
                f"{row.solver}'s xi(f) is off by {_pct(row.xi_err_f)} rms (mean {_signed_pct(row.xi_bias_f)}), its b by "
                f"{_pct(row.b_err)} ({_interval_of_b(reference, what)}), "
                + (f"its indentation by {_pct(row.approach_err_f)} rms" if math.isfinite(row.approach_err_f)
                   else "its indentation not compared (see the notes)")
            )  # fmt: skip
    if not parts:  # why, on the terminal too: the axes asked that could not run on this preset (the notes')
        skipped = "".join(f"; {note}" for note in study.notes if ": skipped" in note)
        return f"{head}: no axis measured enough to recommend anything{skipped}."
    return f"{head}: " + "; ".join(parts) + "."


# ------------------------------------------------------------------ files


FILES = ("study.csv", "study.md", "study.png")


def heading(name: str) -> str:
    return f"# Trade-off study: {name}"


def claim_study_folder(out_dir: str | Path | None, name: str, *, force: bool = False) -> Path:
    """The study's folder: ``out_dir``, refused (OutputRefused) unless it is missing, empty,
    or a study of preset ``name`` (only the study's files, its study.md headed with that
    name), or ``force``; by default a new ``runs/<name>-study-<timestamp>``, made here so
    that two studies started in the same second get two folders."""
    if not out_dir:
        from ..runs.rundir import new_run_folder

        return new_run_folder(f"{name}-study")
    out = Path(out_dir)
    problem = output_path_problem(out)
    if problem:
        raise OutputRefused(f"--out: {shown(problem)}; give a folder")
    refuse_unreplaceable([out / name for name in FILES], "study", "give another --out")  # --force too
    if force or not out.is_dir():
        return out
    held = sorted(p.name for p in out.iterdir())
    if not held or (set(held) <= set(FILES) and is_study_of(out / "study.md", name)):
        return out
    others = [n for n in held if n not in FILES]
    study = bool(others) and is_study_of(out / "study.md", name)  # it said 'not a study of NAME' of one beside notes
    listed = ", ".join(repr(shown(n)) for n in (others if study else held)[:3])
    more = ", ..." if len(others if study else held) > 3 else ""
    what = f"a study of {name} and also {listed}{more}" if study else f"{listed}{more}, not a study of {name}"
    raise OutputRefused(f"--out {shown_name(out)} holds {what}: give another folder, or --force to write study.csv, "
                        "study.md and study.png into it (nothing else is touched)")  # fmt: skip


def is_study_of(page: Path, name: str) -> bool:
    try:
        if not page.is_file() or page.is_symlink():
            return False
        with open(page, encoding="utf-8", errors="replace") as fh:
            return fh.readline().rstrip("\n") == heading(name)
    except OSError:
        return False


def write_outputs(study: Study, out_dir: str | Path, recommendation_text: str, command: str = "") -> dict[str, Path]:
    out = Path(out_dir)
    files = {"csv": out / "study.csv", "md": out / "study.md"}
    atomic_write(files["csv"], lambda fh: write_csv(fh, study.rows))
    if study.rows:
        files["png"] = out / "study.png"
        atomic_write(files["png"], lambda fh: plot(study, fh), binary=True)
    atomic_write(files["md"], lambda fh: fh.write(markdown(study, recommendation_text, command)))
    return files

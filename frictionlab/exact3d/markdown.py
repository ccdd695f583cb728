"""The page "The exact 3D law": its tables, its plain answer and its method, in markdown,
from the study's numbers. Every sentence that states a result is formed from them."""

from __future__ import annotations

import math

import numpy as np

from ..fit import format_estimate, format_interval
from ..listeners import format_duration
from .analysis import FEW_SPOTS, KAPPA_BUSH, KAPPA_PERSSON, KAPPA_SIMULATIONS, KAPPA_WINDOW, Kappa, relative_gap
from .numbers import Numbers, Paired
from .plan import BROAD, MAIN, MIN_PIXELS_QUOTED, SIDE, SPECTRAL, Ensemble, StudyRuns

GOOD_R2 = 0.9  # a log law "holds" on a grid when its fit explains this much of the mean curve's variance
YASTREBOV = "Yastrebov, Anciaux and Molinari (Tribol. Int. 2017, arXiv 1701.02727)"
WINDOW_TEXT = f"{KAPPA_WINDOW[0]:.1%} to {KAPPA_WINDOW[1]:.0%}".replace(".0%", "%")
FEW_TEXT = f"{FEW_SPOTS[1]:.1%}"


def _pct(x: float) -> str:
    return f"{100 * x:+.0f} %" if math.isfinite(x) else "n/a"


def _span(values, fmt: str) -> str:
    """'low to high' of ``values`` in ``fmt``, or the one value when they print alike."""
    low, high = format(min(values), fmt), format(max(values), fmt)
    return low if low == high else f"{low} to {high}"


def _kappa(k: Kappa) -> str:
    return "n/a (no load in the window)" if not math.isfinite(k.value) else f"{k.value:.2f} {format_interval(k.interval, 2)}"


def _hs(hursts) -> str:
    return ", ".join(f"{h:g}" for h in sorted(hursts))


def _grid(e: Ensemble) -> str:
    return f"{e.points}² ({e.pixels_per_short_cutoff:g} px on λs)"


def kappa_place(k: Kappa) -> str:
    """Where kappa's interval sits against the literature's values."""
    low, high = k.interval if all(map(math.isfinite, k.interval)) else (k.value, k.value)
    sim_low, sim_high = KAPPA_SIMULATIONS
    if not math.isfinite(k.value):
        return "not measured"
    if sim_low <= k.value <= sim_high:
        return f"within the simulations' {sim_low:g} to {sim_high:g}"
    if low <= sim_high and high >= sim_low:
        edge = "upper" if k.value > sim_high else "lower"
        return f"at the {edge} edge of the simulations' {sim_low:g} to {sim_high:g} (its interval reaches into it)"
    if low > sim_high:
        where = f"above the simulations' {sim_low:g} to {sim_high:g}, "
        if high < KAPPA_BUSH:
            return where + f"below the vanishing-load limit {KAPPA_BUSH:.2f}"
        return where + (f"at the vanishing-load limit {KAPPA_BUSH:.2f}" if low <= KAPPA_BUSH
                        else f"above even the vanishing-load limit {KAPPA_BUSH:.2f}")  # fmt: skip
    where = f"below the simulations' {sim_low:g} to {sim_high:g}, "
    if low > KAPPA_PERSSON:
        return where + f"above Persson's {KAPPA_PERSSON:.2f}"
    return where + (f"at Persson's {KAPPA_PERSSON:.2f}" if high >= KAPPA_PERSSON else f"below Persson's {KAPPA_PERSSON:.2f}")


# ------------------------------------------------------------------ what ran


def plan_status(runs: StudyRuns) -> list[str]:
    """A table of the plan's ensembles: which finished, which did not run (or not to the end)."""
    groups: dict[tuple, dict[str, list[float]]] = {}
    for job in runs.plan.jobs():
        key = (job.family, job.points, job.exact, job.surfaces)
        groups.setdefault(key, {"done": [], "missing": []})
        groups[key]["missing" if job in runs.missing else "done"].append(job.hurst)
    family = {MAIN: "main (long cut-off = side / 4)", SIDE: "comparison (long cut-off = side)",
              SPECTRAL: "main, spectral gradient", BROAD: "broad band (long cut-off = side / 4)"}  # fmt: skip
    lines = ["| surfaces | grid | solver | per H | finished at H | not finished at H |", "|---|---|---|---|---|---|"]
    for (name, points, exact, surfaces), hs in groups.items():
        count = f"{surfaces} surfaces" if exact else f"{surfaces * runs.plan.mdr_lines} lines"
        lines.append(f"| {family[name]} | {points}² | {'exact' if exact else 'MDR'} | {count} "
                     f"| {_hs(hs['done']) or 'none'} | {_hs(hs['missing']) or 'none'} |")  # fmt: skip
    return lines


def missing_text(runs: StudyRuns) -> str:
    if not runs.missing:
        return "Every ensemble of the plan finished."
    return (f"{len(runs.missing)} of the plan's {len(runs.plan.jobs())} ensembles did not finish and are not on "
            "this page: " + "; ".join(job.describe() for job in runs.missing) + ". Every number below comes from "
            "the ensembles that finished, on the grids named beside it.")  # fmt: skip


# ------------------------------------------------------------------ the answer


def _mdr_area_ratio(runs: StudyRuns, hurst: float) -> np.ndarray:
    """MDR's fraction of springs in contact over the exact corrected real area, per load, same f."""
    exact, mdr = runs.find(hurst), runs.find(hurst, exact=False)
    return mdr.outcome.contact_fraction / exact.outcome.real_area_corrected


def _mdr_gap(runs: StudyRuns, hurst: float) -> np.ndarray:
    exact, mdr = runs.find(hurst), runs.find(hurst, exact=False)
    return relative_gap(mdr.outcome.xi, exact.outcome.xi)


def _half(ci) -> float:
    return 0.5 * (ci[1] - ci[0])


def two_finest_changes(runs: StudyRuns, numbers: Numbers) -> list[tuple[float, Ensemble, Ensemble, float, float, float]]:
    """(H, coarser, finer, change of a, of b, of kappa) between the two finest regular grids per H."""
    rows = []
    for hurst in runs.hursts():
        grids = [e for e in runs.exact_grids(hurst) if e.points in runs.plan.resolutions]
        if len(grids) >= 2:
            coarse, fine = grids[-2], grids[-1]
            rows.append((hurst, coarse, fine, fine.outcome.fit.a - coarse.outcome.fit.a,
                         fine.outcome.fit.b - coarse.outcome.fit.b,
                         numbers.kappa(fine).corrected.value - numbers.kappa(coarse).corrected.value))  # fmt: skip
    return rows


def convergence_text(runs: StudyRuns, numbers: Numbers) -> str:
    rows = two_finest_changes(runs, numbers)
    if not rows:
        return "Only one grid finished: no convergence can be shown."
    parts = []
    for index, name, digits in ((3, "a", 3), (4, "b", 4), (5, "κ", 2)):
        worst = max(rows, key=lambda r: abs(r[index]) if math.isfinite(r[index]) else -1)
        parts.append(f"{name} by {worst[index]:+.{digits}f} (H = {worst[0]:g})")
    grids = sorted({(r[1].points, r[2].points) for r in rows})
    text = (f"The largest changes between the two finest grids ({', '.join(f'{c}² to {f}²' for c, f in grids)}) "
            f"over H = {_hs(r[0] for r in rows)}: " + ", ".join(parts) + ".")  # fmt: skip
    for p in numbers.extra:
        e = p.other.outcome.fit
        text += (f" At H = {p.other.hurst:g}, doubling the resolution once more ({p.base.points}² to {p.other.points}², "
                 f"the same first {p.surfaces} surfaces) changes a by {e.a - p.base_fit.a:+.3f}, b by "
                 f"{e.b - p.base_fit.b:+.4f} and κ by {p.other_kappa.value - p.base_kappa.value:+.2f}.")  # fmt: skip
    return text


def self_averaging_text(runs: StudyRuns, numbers: Numbers) -> str:
    rows = []
    for hurst in runs.hursts():
        side = runs.exact_grids(hurst, SIDE)
        if side:
            main = runs.find(hurst, side[-1].points)
            if main is not None:
                rows.append((hurst, main, side[-1]))
    skew = {family: [s for (f, _), st in numbers.stats.items() if f == family for s in st.skewness]
            for family in (MAIN, SIDE)}  # fmt: skip
    text = ""
    if skew[MAIN]:
        text += f"Per-surface height skewness runs {_span(skew[MAIN], '+.2f')} in the main family"
        text += f" against {_span(skew[SIDE], '+.2f')} with the long cut-off at the side. " if skew[SIDE] else ". "
    if not rows:
        return text + "The comparison family did not run."
    da = [s.outcome.fit.a - m.outcome.fit.a for _, m, s in rows]
    db = [s.outcome.fit.b - m.outcome.fit.b for _, m, s in rows]
    dk = [numbers.kappa(s).corrected.value - numbers.kappa(m).corrected.value for _, m, s in rows]
    return text + (
        f"On the same grid ({rows[0][1].points}²), moving the long cut-off from a quarter of the side to the side "
        f"changes a by {_span(da, '+.3f')}, b by {_span(db, '+.4f')} and κ by {_span(dk, '+.2f')} over "
        f"H = {_hs(r[0] for r in rows)}."
    )


def gradient_text(numbers: Numbers) -> str:
    if not numbers.spectral:
        return "The spectral-gradient ensembles did not run."
    da = [p.other.outcome.fit.a - p.base_fit.a for p in numbers.spectral]
    db = [p.other.outcome.fit.b - p.base_fit.b for p in numbers.spectral]
    dxi = [float(np.max(np.abs(p.xi_gap))) for p in numbers.spectral]
    p0 = numbers.spectral[0]
    return (f"Spectral instead of forward-difference gradients (both in ξ's numerator and denominator), on "
            f"{p0.other.points}² and the same first {p0.surfaces} surfaces: a changes by {_span(da, '+.3f')}, "
            f"b by {_span(db, '+.4f')}, ξ by at most {max(dxi):.3f} at any load, over "
            f"H = {_hs(p.other.hurst for p in numbers.spectral)}.")  # fmt: skip


def answer(runs: StudyRuns, numbers: Numbers) -> list[str]:
    """The plain answer, formed from the numbers."""
    hursts = runs.hursts()
    answers = {h: runs.find(h) for h in hursts}
    fits = {h: e.outcome.fit for h, e in answers.items()}
    unquoted = [h for h, e in answers.items() if not e.quoted]
    caveat = ""
    if unquoted:
        caveat = (f" **Not converged:** at H = {_hs(unquoted)} the finest grid that ran has fewer than "
                  f"{MIN_PIXELS_QUOTED} pixels on the short cut-off; its numbers are shown, not quoted as the answer.")
    held = [h for h, fit in fits.items() if fit.r2 >= GOOD_R2]
    r2 = [fit.r2 for fit in fits.values()]
    if len(held) == len(fits):
        verdict = f"Yes, over this range of f: at every H the mean curve follows a + b ln f with R² {_span(r2, '.2f')}."
    elif held:
        verdict = (f"Only in part: a + b ln f explains the mean curve (R² >= {GOOD_R2}) at H = {_hs(held)}, not at "
                   f"the others (R² {_span([fits[h].r2 for h in fits if h not in held], '.2f')}).")  # fmt: skip
    else:
        verdict = f"No: at no H does a + b ln f explain the mean curve well (R² {_span(r2, '.2f')})."
    law = "; ".join(f"H = {h:g} ({answers[h].points}²): a = {format_estimate(fits[h].a, fits[h].a_ci, 3)}, "
                    f"b = {format_estimate(fits[h].b, fits[h].b_ci, 4)}" for h in hursts)  # fmt: skip
    xi_max = max(float(np.max(e.outcome.xi)) for e in answers.values())
    gaps = np.concatenate([_mdr_gap(runs, h) for h in hursts])
    ratio = np.concatenate([_mdr_area_ratio(runs, h) for h in hursts])
    mdr_fits = {h: runs.find(h, exact=False).outcome.fit for h in hursts}
    da = [mdr_fits[h].a - fits[h].a for h in hursts]
    db = [mdr_fits[h].b - fits[h].b for h in hursts]
    mdr_half_a = [_half(mdr_fits[h].a_ci) for h in hursts]
    mdr_half_b = [_half(mdr_fits[h].b_ci) for h in hursts]
    kappas = {h: numbers.kappa(answers[h]) for h in hursts}
    kappa_text = "; ".join(f"H = {h:g}: {_kappa(kappas[h].corrected)}, {kappa_place(kappas[h].corrected)}"
                           for h in hursts)  # fmt: skip
    few = [kappas[h].few_spots.value for h in hursts if math.isfinite(kappas[h].few_spots.value)]
    raw = [kappas[h].raw.value for h in hursts if math.isfinite(kappas[h].raw.value)]
    return [
        f"- **Does a log law hold for exact contact?** {verdict}{caveat}",
        f"- **Which a and b?** {law} (95 % bootstrap intervals over the surfaces). "
        + ("The exact ξ stays below 1: the points in contact are the tops of asperities, flatter than the surface "
           "on average, and they grow steeper as the load spreads the contact." if xi_max < 1 else ""),
        f"- **How far is MDR?** On the same surfaces at equal f ({runs.plan.mdr_lines} MDR-equivalent lines per "
        f"surface), MDR's mean ξ is {_pct(gaps.min())} to {_pct(gaps.max())} off the exact one over all loads and H; "
        f"its a is {_span(da, '+.3f')} from the exact a (MDR's own 95 % half-width ±{max(mdr_half_a):.3f} at most), "
        f"its b {_span(db, '+.4f')} from the exact b (half-width ±{max(mdr_half_b):.4f} at most). In area it is "
        f"further off: MDR's fraction of springs in contact is {ratio.min():.1f} to {ratio.max():.1f} times the "
        "exact real area at the same f. MDR is built to keep the force against the approach, not the area: its "
        "springs in contact are not the real contact area, and its ξ is an rms slope over a line.",
        f"- **κ against the literature.** A / A0 = κ p / (E* rms|∇z|) with the corrected area, averaged over the "
        f"loads at {WINDOW_TEXT} contact: {kappa_text}. The literature: √(2π) = {KAPPA_BUSH:.2f} at vanishing load, "
        f"√(8/π) = {KAPPA_PERSSON:.2f} in Persson's theory, about {KAPPA_SIMULATIONS[0]:g} to "
        f"{KAPPA_SIMULATIONS[1]:g} in simulations at 0.5 % to 5 % contact, falling slowly with load and with the "
        f"Nayak parameter. "
        + (f"Below {FEW_TEXT} contact (a few spots per surface) κ is {_span(few, '.2f')}, shown apart. " if few else "")
        + (f"The raw pixel count gives κ = {_span(raw, '.2f')} at {WINDOW_TEXT}." if raw else ""),
        f"- **Self-averaging.** {self_averaging_text(runs, numbers)}",
        f"- **Converged?** {convergence_text(runs, numbers)} {gradient_text(numbers)}",
    ]


# ------------------------------------------------------------------ tables


def law_table(runs: StudyRuns, numbers: Numbers) -> list[str]:
    lines = [
        "| H | grid | surfaces | Nayak α | a [95 % CI] | b [95 % CI] | R² | κ at " + WINDOW_TEXT + " [95 % CI] "
        "| κ below " + FEW_TEXT + " | MDR a [95 % CI] | MDR b [95 % CI] | MDR ξ / exact ξ - 1 | MDR springs / real area |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for hurst in runs.hursts():
        e, m = runs.find(hurst), runs.find(hurst, exact=False)
        fit, mfit, k = e.outcome.fit, m.outcome.fit, numbers.kappa(e)
        stats = numbers.stats.get((MAIN, hurst))
        nayak = f"{np.mean(stats.nayak):.1f}" if stats else "n/a"
        gap, ratio = _mdr_gap(runs, hurst), _mdr_area_ratio(runs, hurst)
        grid = _grid(e) + ("" if e.quoted else ", not quoted")
        lines.append(
            f"| {hurst:g} | {grid} | {e.outcome.done} | {nayak} | {format_estimate(fit.a, fit.a_ci, 3)} "
            f"| {format_estimate(fit.b, fit.b_ci, 4)} | {fit.r2:.2f} | {_kappa(k.corrected)} | {_kappa(k.few_spots)} "
            f"| {format_estimate(mfit.a, mfit.a_ci, 3)} | {format_estimate(mfit.b, mfit.b_ci, 4)} "
            f"| {_pct(gap.min())} to {_pct(gap.max())} | {ratio.min():.1f} to {ratio.max():.1f} |"
        )
    return lines


def convergence_table(runs: StudyRuns, numbers: Numbers) -> list[str]:
    lines = [
        "| H | family | grid | quoted | surfaces | real area (corrected) | a [95 % CI] | b [95 % CI] | R² "
        f"| κ at {WINDOW_TEXT}, corrected | κ, pixel count | compute time |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    family = {MAIN: "main", SIDE: "long cut-off = side", SPECTRAL: "main, spectral ∇", BROAD: "broad band"}
    for hurst in runs.hursts():
        for name in (MAIN, BROAD, SIDE, SPECTRAL):
            for e in runs.exact_grids(hurst, name):
                o, k = e.outcome, numbers.kappa(e)
                lines.append(
                    f"| {hurst:g} | {family[name]} | {_grid(e)} | {'yes' if e.quoted else 'no'} | {o.done} "
                    f"| {o.real_area_corrected.min():.2%} to {o.real_area_corrected.max():.1%} "
                    f"| {format_estimate(o.fit.a, o.fit.a_ci, 3)} | {format_estimate(o.fit.b, o.fit.b_ci, 4)} "
                    f"| {o.fit.r2:.2f} | {_kappa(k.corrected)} | {_kappa(k.raw)} | {format_duration(o.compute_seconds)} |"
                )
    return lines


def surfaces_table(runs: StudyRuns, numbers: Numbers) -> list[str]:
    lines = ["| H | family | surfaces | height skewness (min to max) | kurtosis (min to max) | Nayak α (min to max) |",
             "|---|---|---|---|---|---|"]  # fmt: skip
    for hurst in runs.plan.hursts:
        for name, label in ((MAIN, "long cut-off = side / 4"), (BROAD, "broad band"), (SIDE, "long cut-off = side")):
            s = numbers.stats.get((name, hurst))
            if s is not None:
                lines.append(f"| {hurst:g} | {label} | {s.skewness.size} | {_span(s.skewness, '+.2f')} "
                             f"| {_span(s.kurtosis, '.2f')} | {_span(s.nayak, '.1f')} |")  # fmt: skip
    return lines


def paired_table(pairs: list[Paired], what: str) -> list[str]:
    if not pairs:
        return []
    lines = [f"| H | surfaces | {what} | a [95 % CI] | b [95 % CI] | κ | largest change of ξ |",
             "|---|---|---|---|---|---|---|"]  # fmt: skip
    for p in pairs:
        for label, fit, kappa, gap in ((f"{p.base.points}², forward differences", p.base_fit, p.base_kappa, ""),
                                       (_paired_label(p), p.other.outcome.fit, p.other_kappa,
                                        f"{float(np.max(np.abs(p.xi_gap))):.4f}")):  # fmt: skip
            lines.append(f"| {p.other.hurst:g} | {p.surfaces} | {label} | {format_estimate(fit.a, fit.a_ci, 3)} "
                         f"| {format_estimate(fit.b, fit.b_ci, 4)} | {_kappa(kappa)} | {gap} |")  # fmt: skip
    return lines


def _paired_label(p: Paired) -> str:
    gradient = "spectral" if p.other.family == SPECTRAL else "forward differences"
    return f"{p.other.points}², {gradient}"


def ensemble_text(runs: StudyRuns) -> str:
    """Whether the ensembles resolve MDR's offset from the exact law, from the answer grids' intervals."""
    rows = []
    for hurst in runs.hursts():
        exact, mdr = runs.find(hurst).outcome.fit, runs.find(hurst, exact=False).outcome.fit
        for name in ("a", "b"):
            offset = abs(getattr(mdr, name) - getattr(exact, name))
            noise = _half(getattr(exact, f"{name}_ci")) + _half(getattr(mdr, f"{name}_ci"))
            rows.append((name, offset, noise))
    parts = []
    for name in ("a", "b"):
        sel = [(o, n) for k, o, n in rows if k == name]
        resolved = sum(o > n for o, n in sel)
        parts.append(f"for {name}, MDR's offset {_span([o for o, _ in sel], '.4f')} against the two half-widths "
                     f"summed {_span([n for _, n in sel], '.4f')} (resolved at {resolved} of {len(sel)} H)")  # fmt: skip
    return "On the answer grids: " + "; ".join(parts) + "."


"""The page "The exact 3D law": its tables, its plain answer and its method, in markdown,
from the study's numbers. Every sentence that states a result is formed from them."""

from __future__ import annotations

import math

import numpy as np

from ..compute.fit import format_estimate, format_interval
from ..plugin.listeners import format_duration
from .analysis import FEW_SPOTS, KAPPA_BUSH, KAPPA_PERSSON, KAPPA_SIMULATIONS, KAPPA_WINDOW, Kappa, relative_gap
from .numbers import Numbers, Paired
from .plan import BROAD, MAIN, MIN_PIXELS_QUOTED, SIDE, SPECTRAL, Ensemble, StudyRuns

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


def _half(ci) -> float:
    return 0.5 * (ci[1] - ci[0])


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


def _mdr_gap_interval(runs: StudyRuns, hurst: float) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """MDR's mean xi over the exact one, minus 1, per load, with a 95 % interval from the two
    ensembles' standard errors (independent ensembles: MDR's lines are not the surfaces)."""
    exact, mdr = runs.find(hurst).outcome, runs.find(hurst, exact=False).outcome
    gap = relative_gap(mdr.xi, exact.xi)
    half = 1.96 * np.hypot(mdr.xi_sem, exact.xi_sem) / exact.xi
    return gap, gap - half, gap + half


def answer(runs: StudyRuns, numbers: Numbers) -> list[str]:
    """The plain answer, formed from the numbers: no claim the evidence on the page does not carry."""
    from .evidence_text import SOURCE_STUDY, convergence_verdict, few_spots_text, limit_text, model_verdict

    hursts = runs.hursts()
    answers = {h: runs.find(h) for h in hursts}
    fits = {h: e.outcome.fit for h, e in answers.items()}
    unquoted = [h for h, e in answers.items() if not e.quoted]
    caveat = ""
    if unquoted:
        caveat = (f" **Not converged:** at H = {_hs(unquoted)} the finest grid that ran has fewer than "
                  f"{MIN_PIXELS_QUOTED} pixels on the short cut-off; its numbers are shown, not quoted as the answer.")
    law = "; ".join(f"H = {h:g} ({answers[h].points}², {answers[h].outcome.done} surfaces): a = "
                    f"{format_estimate(fits[h].a, fits[h].a_ci, 3)}, b = {format_estimate(fits[h].b, fits[h].b_ci, 4)}"
                    for h in hursts)  # fmt: skip
    limits = "; ".join(f"H = {h:g}: a = {limit_text(c.quantities['a'].limit, 3)}, b = {limit_text(c.quantities['b'].limit, 4)}"
                       for h, c in sorted(numbers.convergence.items()) if c.quantities["a"].limit is not None)  # fmt: skip
    xi_max = max(float(np.max(e.outcome.xi)) for e in answers.values())
    gaps = [_mdr_gap_interval(runs, h) for h in hursts]
    ratio = np.concatenate([_mdr_area_ratio(runs, h) for h in hursts])
    mdr_fits = {h: runs.find(h, exact=False).outcome.fit for h in hursts}
    kappas = {h: numbers.kappa(answers[h]) for h in hursts}
    kappa_text = "; ".join(f"H = {h:g}: {_kappa(kappas[h].corrected)}, {kappa_place(kappas[h].corrected)}"
                           for h in hursts)  # fmt: skip
    few = [kappas[h].few_spots for h in hursts if math.isfinite(kappas[h].few_spots.value)]
    converged = [convergence_verdict(c) for _, c in sorted(numbers.convergence.items())]
    return [
        f"- **Does a log law hold for exact contact?** {model_verdict(runs, numbers)}{caveat}",
        f"- **Which a and b?** On the finest grid: {law} (95 % bootstrap intervals over the surfaces). "
        + (f"Extrapolated to the continuum from the three finest grids on the same surfaces: {limits}. " if limits else "")
        + ("The exact ξ stays below 1: the points in contact are the tops of asperities, flatter than the surface "
           "on average." if xi_max < 1 else ""),
        "- **Converged?** " + ("; ".join(converged) + "." if converged else "Fewer than two grids finished: not shown."),
        f"- **How far is MDR?** The source study, {SOURCE_STUDY}, answers with the method of reduction of "
        "dimensionality (MDR); here MDR presses the "
        f"MDR-equivalent lines of the same surfaces at equal f ({runs.plan.mdr_lines} per surface). Its mean ξ is "
        + "; ".join(f"{_pct(g.min())} to {_pct(g.max())} (95 % from {_pct(lo.min())} to {_pct(hi.max())})"
                    f" off the exact one at H = {h:g}" for h, (g, lo, hi) in zip(hursts, gaps))  # fmt: skip
        + "; its a and b: "
        + "; ".join(f"H = {h:g}: a = {format_estimate(mdr_fits[h].a, mdr_fits[h].a_ci, 3)}, "
                    f"b = {format_estimate(mdr_fits[h].b, mdr_fits[h].b_ci, 4)}" for h in hursts)  # fmt: skip
        + f". At equal f, MDR has {ratio.min():.1f} to {ratio.max():.1f} times the real contact area in its springs "
        "in contact: MDR is built to keep the force against the approach, not the area.",
        f"- **κ against the literature.** A / A0 = κ p / (E* g) with the corrected area, averaged over the "
        f"loads at {WINDOW_TEXT} contact: {kappa_text}. "
        + (f"Below {FEW_TEXT} contact κ is {_span([k.value for k in few], '.2f')}"
           + (f", above the vanishing-load limit {KAPPA_BUSH:.2f} of an infinite surface: " if min(k.interval[0] for k in few) > KAPPA_BUSH
              else ": ")
           + "the few-spot regime of a finite surface, not an approach to that limit (below). " if few else "")
        + "See κ against the Nayak parameter below: the literature's band is for broad spectra.",
        f"- **Few spots.** {few_spots_text(runs, numbers)}",
    ]


# ------------------------------------------------------------------ tables


def law_table(runs: StudyRuns, numbers: Numbers) -> list[str]:
    lines = [
        "| H | grid | surfaces | Nayak α | a [95 % CI] | b [95 % CI] | κ at " + WINDOW_TEXT + " [95 % CI] "
        "| κ below " + FEW_TEXT + " [95 % CI] | MDR a [95 % CI] | MDR b [95 % CI] | MDR ξ / exact ξ - 1 (95 % over all loads) "
        "| MDR springs / real area |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for hurst in runs.hursts():
        e, m = runs.find(hurst), runs.find(hurst, exact=False)
        fit, mfit, k = e.outcome.fit, m.outcome.fit, numbers.kappa(e)
        stats = numbers.stats.get((MAIN, hurst))
        nayak = f"{np.mean(stats.nayak):.1f}" if stats else "n/a"
        (gap, low, high), ratio = _mdr_gap_interval(runs, hurst), _mdr_area_ratio(runs, hurst)
        grid = _grid(e) + ("" if e.quoted else ", not quoted")
        lines.append(
            f"| {hurst:g} | {grid} | {e.outcome.done} | {nayak} | {format_estimate(fit.a, fit.a_ci, 3)} "
            f"| {format_estimate(fit.b, fit.b_ci, 4)} | {_kappa(k.corrected)} | {_kappa(k.few_spots)} "
            f"| {format_estimate(mfit.a, mfit.a_ci, 3)} | {format_estimate(mfit.b, mfit.b_ci, 4)} "
            f"| {_pct(gap.min())} to {_pct(gap.max())} ({_pct(low.min())} to {_pct(high.max())}) "
            f"| {ratio.min():.1f} to {ratio.max():.1f} |"
        )
    return lines


def convergence_table(runs: StudyRuns, numbers: Numbers) -> list[str]:
    lines = [
        "| H | family | grid | quoted | surfaces | real area (corrected) | a [95 % CI] | b [95 % CI] "
        f"| κ at {WINDOW_TEXT}, corrected | κ, pixel count | compute time |",
        "|---|---|---|---|---|---|---|---|---|---|---|",
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
                    f"| {_kappa(k.corrected)} | {_kappa(k.raw)} | {format_duration(o.compute_seconds)} |"
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


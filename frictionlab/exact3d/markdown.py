"""The page "The exact 3D law": its tables, its plain answer and its method, in markdown,
from the study's numbers. Every sentence that states a result is formed from them."""

from __future__ import annotations

import math

import numpy as np

from ..fit import fit_log_law, format_estimate, format_interval
from ..seeds import bootstrap_rng
from ..listeners import format_duration
from .analysis import Kappa, relative_gap
from .plan import StudyRuns

GOOD_R2 = 0.9  # a log law "holds" on a grid when its fit explains this much of the mean curve's variance
YASTREBOV = "Yastrebov, Anciaux and Molinari 2017 (arXiv 1701.02727 and 1704.05650)"


def _pct(x: float) -> str:
    return f"{100 * x:+.0f} %" if math.isfinite(x) else "n/a"


def _mdr_gap(runs: StudyRuns, hurst: float) -> np.ndarray:
    """(MDR's mean xi - the exact one) / the exact one at each load, finest grid (same f)."""
    exact, mdr = runs.find(hurst), runs.find(hurst, exact=False)
    return relative_gap(mdr.outcome.xi, exact.outcome.xi)


def law_table(runs: StudyRuns, kappas: dict[tuple[float, int], Kappa]) -> list[str]:
    finest = runs.plan.resolutions[-1]
    lines = [
        f"| H | Nayak α | exact a [95 % CI] | exact b [95 % CI] | R² | MDR a [95 % CI] | MDR b [95 % CI] | MDR R² "
        "| MDR ξ / exact ξ - 1 (range over f) | κ [95 % CI] |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for hurst in runs.plan.hursts:
        e, m = runs.find(hurst), runs.find(hurst, exact=False)
        fit, mfit, kappa = e.outcome.fit, m.outcome.fit, kappas[(hurst, finest)]
        gap = _mdr_gap(runs, hurst)
        lines.append(
            f"| {hurst:g} | {e.nayak:.0f} | {format_estimate(fit.a, fit.a_ci, 3)} | {format_estimate(fit.b, fit.b_ci, 4)} "
            f"| {fit.r2:.2f} | {format_estimate(mfit.a, mfit.a_ci, 3)} | {format_estimate(mfit.b, mfit.b_ci, 4)} "
            f"| {mfit.r2:.2f} | {_pct(gap.min())} to {_pct(gap.max())} | {kappa.value:.2f} {format_interval(kappa.interval, 2)} |"
        )
    return lines


def convergence_table(runs: StudyRuns, kappas: dict[tuple[float, int], Kappa]) -> list[str]:
    lines = [
        "| H | pixels | px on λs | surfaces | contact fraction | a [95 % CI] | b [95 % CI] | R² | κ [95 % CI] "
        "| compute time |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for hurst in runs.plan.hursts:
        for e in runs.exact_grids(hurst):
            o, kappa = e.outcome, kappas[(e.hurst, e.points)]
            lines.append(
                f"| {hurst:g} | {e.points}² | {e.pixels_per_short_cutoff:g} | {o.done} "
                f"| {o.contact_fraction.min():.2%} to {o.contact_fraction.max():.1%} "
                f"| {format_estimate(o.fit.a, o.fit.a_ci, 3)} | {format_estimate(o.fit.b, o.fit.b_ci, 4)} | {o.fit.r2:.2f} "
                f"| {kappa.value:.2f} {format_interval(kappa.interval, 2)} | {format_duration(o.compute_seconds)} |"
            )
    return lines


def _shift_of_b(runs: StudyRuns, hurst: float) -> tuple[float, float]:
    """(b on the finest grid - b on the next coarser one, half-width of the finest b's interval)."""
    grids = [e for e in runs.exact_grids(hurst) if e.points in runs.plan.resolutions]
    finest, coarser = grids[-1].outcome.fit, grids[-2].outcome.fit
    return finest.b - coarser.b, 0.5 * (finest.b_ci[1] - finest.b_ci[0])


def kappa_trend(runs: StudyRuns, kappas: dict[tuple[float, int], Kappa]) -> str:
    """A sentence on how kappa moves as the grid is refined, from the numbers."""
    falling = rising = 0
    spans = []
    for hurst in runs.plan.hursts:
        values = [kappas[(e.hurst, e.points)].value for e in runs.exact_grids(hurst)]
        steps = np.diff(values)
        falling += bool(np.all(steps < 0))
        rising += bool(np.all(steps > 0))
        spans.append(f"{values[0]:.2f} to {values[-1]:.2f} at H = {hurst:g}")
    count = len(runs.plan.hursts)
    if falling == count:
        trend = ("κ falls at every H as the grid is refined, as for a contact area overestimated on coarse grids: "
                 "if the trend goes on, the converged κ lies below the finest grid's")
    elif rising == count:
        trend = "κ rises at every H as the grid is refined"
    else:
        trend = "κ does not move one way at every H as the grid is refined"
    return f"{trend} ({'; '.join(spans)}, coarsest to finest grid)."


def paired_extra_grids(runs: StudyRuns) -> list[str]:
    """Each extra (finer) grid against the finest regular one on the same surfaces: the
    extra grid runs the first M surfaces, so the regular grid's fit is redone on those."""
    lines = []
    finest = runs.plan.resolutions[-1]
    for hurst, points, count in runs.plan.extra:
        extra, regular = runs.find(hurst, points), runs.find(hurst, finest)
        if extra is None or regular is None:
            continue
        per = regular.outcome.per_realization
        keep = np.isin(per["index"], extra.outcome.per_realization["index"])
        refit = fit_log_law(regular.outcome.f, per["xi"][keep], bootstrap=runs.plan.bootstrap,
                            rng=bootstrap_rng(regular.scene.preset.seed))  # fmt: skip
        e = extra.outcome.fit
        lines.append(
            f"At H = {hurst:g} the same first {int(keep.sum())} surfaces on {points}² pixels "
            f"({extra.pixels_per_short_cutoff:g} on λs) give a = {format_estimate(e.a, e.a_ci, 3)}, "
            f"b = {format_estimate(e.b, e.b_ci, 4)}, and on {finest}² a = {format_estimate(refit.a, refit.a_ci, 3)}, "
            f"b = {format_estimate(refit.b, refit.b_ci, 4)}: a change of {e.a - refit.a:+.3f} in a and "
            f"{e.b - refit.b:+.4f} in b from doubling the resolution once more."
        )
    return lines


def _span(values, fmt: str) -> str:
    """'low to high' of ``values`` in ``fmt``, or the one value when they print alike."""
    low, high = format(min(values), fmt), format(max(values), fmt)
    return low if low == high else f"{low} to {high}"


def _mdr_full_contact(runs: StudyRuns) -> str:
    """How near MDR's line is to being pressed flat at the largest load, against the real area."""
    springs = [runs.find(h, exact=False).outcome.contact_fraction[-1] for h in runs.plan.hursts]
    real = [runs.find(h).outcome.contact_fraction[-1] for h in runs.plan.hursts]
    return (f"; at the largest f, {_span(springs, '.0%')} of MDR's springs are in contact (so its ξ "
            f"tends to 1 and its curve bends: MDR R² in the table) where the real contact area is "
            f"{_span(real, '.0%')}")


def ensemble_text(runs: StudyRuns) -> str:
    """Whether the ensembles resolve what the page concludes, from the intervals."""
    finest = [runs.find(h) for h in runs.plan.hursts]
    half = {name: [0.5 * (getattr(e.outcome.fit, f"{name}_ci")[1] - getattr(e.outcome.fit, f"{name}_ci")[0])
                   for e in finest] for name in ("a", "b")}  # fmt: skip
    mdr = {name: [abs(getattr(runs.find(e.hurst, exact=False).outcome.fit, name) - getattr(e.outcome.fit, name))
                  for e in finest] for name in ("a", "b")}  # fmt: skip
    parts = []
    for name in ("a", "b"):
        resolved = sum(m > h for m, h in zip(mdr[name], half[name]))
        parts.append(
            f"{name}: ±{min(half[name]):.4f} to ±{max(half[name]):.4f}, against MDR's offset of "
            f"{min(mdr[name]):.4f} to {max(mdr[name]):.4f} (resolved at {resolved} of {len(finest)} H)"
        )
    return ("On the finest grid the 95 % half-widths are, for " + "; for ".join(parts) + ". Quadrupling the "
            "surfaces would halve the half-widths.")


def answer(runs: StudyRuns, kappas: dict[tuple[float, int], Kappa]) -> list[str]:
    """The plain answer, formed from the numbers."""
    finest = runs.plan.resolutions[-1]
    fits = {h: runs.find(h).outcome.fit for h in runs.plan.hursts}
    held = [h for h, fit in fits.items() if fit.r2 >= GOOD_R2]
    r2 = [fit.r2 for fit in fits.values()]
    r2_missed = [fit.r2 for h, fit in fits.items() if h not in held]
    b_low = min(fit.b for fit in fits.values())
    b_high = max(fit.b for fit in fits.values())
    a_low = min(fit.a for fit in fits.values())
    a_high = max(fit.a for fit in fits.values())
    gaps = np.concatenate([_mdr_gap(runs, h) for h in runs.plan.hursts])
    settled = [h for h in runs.plan.hursts if abs(_shift_of_b(runs, h)[0]) <= _shift_of_b(runs, h)[1]]
    kappa_all = [kappas[(h, finest)].value for h in runs.plan.hursts]
    if len(held) == len(fits):
        verdict = f"Yes, over this range: at every H the mean curve follows a + b ln f with R² {_span(r2, '.2f')}."
    elif held:
        verdict = (
            f"Only in part: a + b ln f explains the mean curve (R² >= {GOOD_R2}) at H = "
            f"{', '.join(f'{h:g}' for h in held)}, not at the others (R² {_span(r2_missed, '.2f')})."
        )
    else:
        verdict = f"No: at no H does a + b ln f explain the mean curve well (R² {_span(r2, '.2f')})."
    return [
        f"- **Does a log law hold for exact contact?** {verdict}",
        f"- **Which a and b?** On the finest grid ({finest}² pixels), a runs from {a_low:.3f} to {a_high:.3f} and "
        f"b from {b_low:.4f} to {b_high:.4f} across H = {', '.join(f'{h:g}' for h in runs.plan.hursts)} "
        "(table below, with 95 % bootstrap intervals). "
        + ("The exact ξ stays below 1: the points in contact are the tops of asperities, flatter than the surface "
           "on average, and they grow steeper as the load spreads the contact." if max(
               float(np.max(runs.find(h).outcome.xi)) for h in runs.plan.hursts) < 1 else "")  # fmt: skip
        + f" b moved by less than its own interval's half-width from the next coarser grid at "
        f"{len(settled)} of {len(runs.plan.hursts)} H"
        + (f" ({', '.join(f'{h:g}' for h in settled)})." if settled else "."),
        f"- **How far is MDR?** On the same surfaces (their MDR-equivalent lines) at equal f, MDR's mean ξ is "
        f"{_pct(gaps.min())} to {_pct(gaps.max())} off the exact one over all loads and H; its a is "
        f"{min(runs.find(h, exact=False).outcome.fit.a - fits[h].a for h in fits):+.3f} to "
        f"{max(runs.find(h, exact=False).outcome.fit.a - fits[h].a for h in fits):+.3f} from the exact a, and its b "
        f"{min(runs.find(h, exact=False).outcome.fit.b - fits[h].b for h in fits):+.4f} to "
        f"{max(runs.find(h, exact=False).outcome.fit.b - fits[h].b for h in fits):+.4f} from the exact b"
        + _mdr_full_contact(runs) + ".",
        f"- **Known-answer check:** κ of the real contact area at small loads is {min(kappa_all):.2f} to "
        f"{max(kappa_all):.2f} over H on the finest grid (literature: about 1.6, Persson, to about 2, simulations); "
        + kappa_trend(runs, kappas),
    ]

"""The page's sections that weigh the evidence: definitions, convergence on paired grids,
the model test, kappa against the Nayak parameter, g_r and kappa_r, the few-spot regime
and the limitations. Every sentence that states a result is formed from the numbers,
and says no more than they show."""

from __future__ import annotations

import math

import numpy as np

from ..compute.fit import format_estimate, format_interval
from .analysis import KAPPA_BUSH, KAPPA_SIMULATIONS
from .evidence import GRADIENT_WINDOW, MANY_SPOTS, Convergence
from .numbers import Numbers
from .plan import BROAD, MAIN, MIN_PIXELS_QUOTED, SIDE, StudyRuns
from .statistics import MODELS, Extrapolation

SOURCE_STUDY = "J. Benad (Physical Mesomechanics, 2012)"
YASTREBOV_JMPS = "Yastrebov, Anciaux and Molinari, J. Mech. Phys. Solids 2017, arXiv 1704.05650"
DIGITS = {"a": 3, "b": 4, "κ": 2}


def _hs(hursts) -> str:
    return ", ".join(f"{h:g}" for h in sorted(hursts))


def _est(value: float, interval, digits: int) -> str:
    return format_estimate(value, tuple(interval), digits)


def _change(change: tuple[float, float, float], digits: int) -> str:
    value, low, high = change
    return f"{value:+.{digits}f} {format_interval((low, high), digits)}"


def contains_zero(change: tuple[float, float, float]) -> bool:
    return change[1] <= 0.0 <= change[2]


def limit_text(limit: Extrapolation | None, digits: int) -> str:
    if limit is None:
        return "n/a (fewer than three grids)"
    text = _est(limit.limit, limit.interval, digits)
    if limit.estimated:
        return f"{text} (order {limit.order:.2g})" if math.isfinite(limit.order) else f"{text} (no change)"
    return f"{text} (order not estimated: {limit.reason}; the interval spans the finest grid and a first-order limit)"


# ------------------------------------------------------------------ definitions


def definitions(runs: StudyRuns, numbers: Numbers) -> list[str]:
    first = runs.find(runs.hursts()[0])
    params = first.scene.resolved()["spectrum"]["params"]
    solver = first.scene.resolved()["solver"]["params"]
    side = first.spacing * first.points
    g = np.concatenate([e.outcome.per_realization["slope_rms_line"] for e in runs.exact_grids(first.hurst)[-1:]])
    spread = float(np.ptp(g) / np.mean(g)) if g.size else math.nan
    o = first.outcome
    return [
        "## Definitions",
        "",
        f"- **Surface.** A periodic square of side ℓ = {side:g} (length units), nominal area A0 = ℓ², sampled on N × N "
        f"pixels of size Δx = ℓ / N. Heights have the isotropic power spectrum C(q) ∝ q^(-2-2H) between the long "
        f"cut-off wavelength λL and the short one λs (main family: λL = {first.long_cutoff:g} = ℓ / 4, "
        f"λs = {first.short_cutoff:g}); h = {params.get('rms_height', 1):g} is the rms height.",
        "- **Fixed amplitudes.** Each Fourier mode has the amplitude of the spectrum and a random phase (no random "
        "amplitude), so every surface of a family has the same rms height, the same rms gradient g and the same "
        "Nayak parameter to rounding"
        + (f" (g spreads by {_relative_spread(spread)} of its mean over the surfaces)." if math.isfinite(spread)
           else "."),
        f"- **Elastic body.** E* = E / (1 - ν²) with E = {solver.get('youngs_modulus', 1):g} and "
        f"ν = {solver.get('poisson_ratio', 0):g}; the rigid rough surface is pressed with the force F.",
        "- **Load.** f = F / (E* h L) with L = 2 √(A0 / π), the dimensionless force of the source study; the "
        "literature on the contact area uses p / (E* g) with p = F / A0 the nominal pressure. The two differ by "
        "the surface's constants: p / (E* g) = f h L / (A0 g). Loads here: f = "
        f"{o.f.min():.3g} to {o.f.max():.3g} ({math.log10(o.f.max() / o.f.min()):.1f} decades).",
        "- **ξ** = rms |∇z| over the contact pixels / g, |∇z| from forward differences along both axes; averaged "
        "over the surfaces at each load. **g_r** = rms |∇z| over the real contact with each contact pixel weighted "
        "by its share of the corrected area (below), so ξ is exactly g_r / g when the edge pixels count whole.",
        "- **Area and κ.** A = N - c M pixels (N in contact, M contact/free edges along rows and columns, "
        "c = (π - 1 + ln 2) / 24), the correction of Yastrebov, Anciaux and Molinari (Tribol. Int. 2017, "
        "arXiv 1701.02727). κ = (A / A0) E* g / p and κ_r = (A / A0) E* g_r / p, per surface and load.",
        f"- **Solver and stop rule.** `{first.solver}`: FFT boundary elements on the periodic half-space, a "
        f"constrained conjugate gradient; a load is solved when its residual (largest gap error on the contact or "
        f"penetration elsewhere) is at most {solver.get('tolerance', first.scene.solver.tolerance()):g} of the rms "
        f"height, or (stop rule `{solver.get('stop', 'tolerance')}`) as soon as the contact set is certified "
        "unchanged; at most " + f"{solver.get('max_iterations', 'n/a')} iterations per load.",
        "",
    ]


# ------------------------------------------------------------------ convergence


def convergence_table(numbers: Numbers) -> list[str]:
    lines = ["| H | surfaces (paired) | quantity | " + "per grid [95 % CI] | " + "paired changes [95 % CI] | "
             "Richardson limit [95 % CI] |", "|---|---|---|---|---|---|"]  # fmt: skip
    for hurst, c in sorted(numbers.convergence.items()):
        for name, q in c.quantities.items():
            digits = DIGITS[name]
            grids = "; ".join(f"{e.points}²{'' if e.quoted else ' (not quoted)'}: {_est(v, (lo, hi), digits)}"
                              for e, v, lo, hi in zip(c.grids, q.values, q.low, q.high))  # fmt: skip
            changes = "; ".join(f"{a.points}²→{b.points}²: {_change(ch, digits)}"
                                for a, b, ch in zip(c.grids, c.grids[1:], q.changes))  # fmt: skip
            lines.append(f"| {hurst:g} | {c.surfaces} | {name} | {grids} | {changes} | {limit_text(q.limit, digits)} |")
    return lines


def convergence_verdict(c: Convergence) -> str:
    """Per H: whether the last paired change of b holds 0, and what is quoted."""
    b = c.quantities["b"]
    last = b.changes[-1]
    fine, coarse = c.grids[-1], c.grids[-2]
    if not (fine.quoted and coarse.quoted):
        return (f"H = {c.hurst:g}: not shown: the grids compared ({coarse.points}², {fine.points}²) do not both resolve "
                f"the short cut-off with {MIN_PIXELS_QUOTED} pixels; b changes by {_change(last, 4)} between them")
    if contains_zero(last):
        return (f"H = {c.hurst:g}: b changes by {_change(last, 4)} from {coarse.points}² to {fine.points}² on the same "
                f"{c.surfaces} surfaces, an interval that holds 0: converged within the ensemble's resolution")
    return (f"H = {c.hurst:g}: b still changes by {_change(last, 4)} from {coarse.points}² to {fine.points}² on the "
            f"same {c.surfaces} surfaces; quoted as its continuum limit {limit_text(b.limit, 4)}")


def convergence_text(numbers: Numbers) -> str:
    if not numbers.convergence:
        return "At no H did two grids of the main family finish: no convergence can be shown."
    verdicts = [convergence_verdict(c) for _, c in sorted(numbers.convergence.items())]
    xi = []
    for hurst, c in sorted(numbers.convergence.items()):
        last = c.xi_changes[-1]
        low, high = np.asarray(last.interval[0]), np.asarray(last.interval[1])
        holds = int(np.count_nonzero((low <= 0) & (high >= 0)))
        xi.append(f"H = {hurst:g}: at most {float(np.max(np.abs(last.value))):.4f}, its interval holding 0 at {holds} "
                  f"of {low.size} loads")
    return ("Every quantity is compared on the surfaces all grids ran (paired), so the surfaces' own scatter "
            "cancels from the changes; the intervals are percentile bootstraps over those surfaces. "
            + ". ".join(verdicts) + ". The change of the mean ξ between the two finest grids, per load: "
            + "; ".join(xi) + ".")  # fmt: skip


# ------------------------------------------------------------------ the model test


def _model_row(label: str, test, hurst: float, points: int) -> str:
    best = min(m.bic for m in test.mean.values())
    cells = " | ".join(f"{test.mean[name].bic - best:+.1f} / {test.mean[name].runs_z:+.1f}" for name in MODELS)
    choice = test.mean_choice or "undecided (ΔBIC < 2)"
    surfaces = ", ".join(f"{n} {name or 'undecided'}" for name, n in test.per_surface.items() if n)
    return (f"| {hurst:g} | {label} | {points}² | {test.f_range[0]:.3g} to {test.f_range[1]:.3g} | {cells} | {choice} "
            f"| {surfaces} |")


def model_table(runs: StudyRuns, numbers: Numbers) -> list[str]:
    lines = ["| H | family, loads | grid | f range | " + " | ".join(f"{m}: ΔBIC / runs z" for m in MODELS)
             + " | preferred (mean curve, BIC) | per surface (BIC) |", "|---|---|---|---|---|---|---|---|---|"]  # fmt: skip
    for family, name in ((MAIN, "main"), (BROAD, "broad band")):
        for hurst in runs.plan.hursts:
            grids = runs.exact_grids(hurst, family)
            models = numbers.models.get(grids[-1].folder.name) if grids else None
            if models is None:
                continue
            lines.append(_model_row(f"{name}, all", models.full, hurst, grids[-1].points))
            if models.many_spots is not None:
                lines.append(_model_row(f"{name}, ≥ {MANY_SPOTS} spots", models.many_spots, hurst, grids[-1].points))
    return lines


def model_verdict(runs: StudyRuns, numbers: Numbers) -> str:
    """What the model test supports, on the main family's finest grids."""
    choices = {}
    for hurst in runs.hursts():
        models = numbers.models.get(runs.exact_grids(hurst, MAIN)[-1].folder.name)
        if models is not None:
            choices[hurst] = models.full
    if not choices:
        return "The model test did not run."
    by_choice: dict[str | None, list[float]] = {}
    for hurst, test in choices.items():
        by_choice.setdefault(test.mean_choice, []).append(hurst)
    parts = [f"{c} at H = {_hs(h)}" for c, h in by_choice.items() if c is not None]
    verdict = f"the mean curve's BIC prefers (by 2 or more) {'; '.join(parts)}" if parts else ""
    if None in by_choice:  # the best two within 2 of each other
        undecided = f"does not tell the best two models apart (within 2) at H = {_hs(by_choice[None])}"
        verdict = f"{verdict}, and {undecided}" if verdict else f"the mean curve's BIC {undecided}"
    f_low, f_high = min(t.f_range[0] for t in choices.values()), max(t.f_range[1] for t in choices.values())
    log_only = set(by_choice) == {"log law"}
    return ((f"Yes, over f = {f_low:.3g} to {f_high:.3g}: " if log_only else
             f"Not as a rule, over f = {f_low:.3g} to {f_high:.3g}: ")
            + verdict + ". A log law is said to hold only "
            "where it is preferred over a power law and over a log law with curvature; the runs test on the "
            "residuals' signs (z below -2: a curve left in them) is in the model table.")  # fmt: skip


# ------------------------------------------------------------------ kappa, Nayak, g_r, few spots


def nayak_rows(runs: StudyRuns, numbers: Numbers) -> list[tuple[float, str, float, object]]:
    rows = []
    for hurst in runs.plan.hursts:
        for family in (MAIN, BROAD, SIDE):
            grids, stats = runs.exact_grids(hurst, family), numbers.stats.get((family, hurst))
            if grids and stats is not None:
                rows.append((hurst, family, float(np.mean(stats.nayak)), numbers.kappa(grids[-1]).corrected))
    return rows


def nayak_text(runs: StudyRuns, numbers: Numbers) -> str:
    rows = nayak_rows(runs, numbers)
    label = {MAIN: "main", BROAD: "broad band", SIDE: "long cut-off = side"}
    listed = "; ".join(f"H = {h:g}, {label[f]} (α = {a:.1f}): κ = {format_estimate(k.value, k.interval, 2)}"
                       for h, f, a, k in rows if math.isfinite(k.value))  # fmt: skip
    broad = _against_main(runs, numbers, BROAD)
    side = _against_main(runs, numbers, SIDE)
    trend = f" The broad band's κ against the main family's on the same grid: {broad}." if broad else ""
    if side:
        trend += (" The comparison family changes more than the breadth: each of its surfaces is dominated by its "
                  f"few longest waves (see the skewness below); its κ against the main family's on the same grid: {side}.")
    return (f"κ at 0.5 % to 5 % contact against the family's Nayak parameter α: {listed}.{trend} "
            f"{YASTREBOV_JMPS} find the contact area at fixed p / (E* g) falling as the spectrum broadens "
            f"(logarithmically in α); the literature's κ of about {KAPPA_SIMULATIONS[0]:g} to {KAPPA_SIMULATIONS[1]:g} "
            "comes from broad spectra (α of tens or more), so the main family's narrow band (α of 4 to 5) is "
            "expected above it, and the comparison is with the broad-band family, which changes the breadth alone.")  # fmt: skip


def _against_main(runs: StudyRuns, numbers: Numbers, family: str) -> str:
    """Per H, ``family``'s κ (its finest grid) against the main family's on that grid: lower with
    the 95 % intervals apart, higher so, or not resolved apart."""
    pairs = []
    for hurst in runs.plan.hursts:
        grids = runs.exact_grids(hurst, family)
        main = runs.find(hurst, points=grids[-1].points) if grids else None
        if main is None:
            continue
        other, reference = numbers.kappa(grids[-1]).corrected, numbers.kappa(main).corrected
        if not (math.isfinite(other.value) and math.isfinite(reference.value)):
            continue
        pairs.append(f"H = {hurst:g} ({grids[-1].points}²): {kappa_versus(other, reference)}")
    return "; ".join(pairs)


def kappa_versus(other, reference) -> str:
    """``other`` κ against ``reference`` (each a value with its 95 % interval)."""
    if other.interval[1] < reference.interval[0]:
        return "lower, the intervals apart"
    if other.interval[0] > reference.interval[1]:
        return "higher, the intervals apart"
    return "not resolved apart"


def gradient_text(runs: StudyRuns, numbers: Numbers) -> str:
    parts = []
    for family, name in ((MAIN, "main"), (BROAD, "broad band")):
        for hurst in runs.plan.hursts:
            grids = runs.exact_grids(hurst, family)
            g = numbers.gradients.get(grids[-1].folder.name) if grids else None
            if g is None or g.drift is None:
                continue
            value, (low, high) = np.asarray(g.drift.value), g.drift.interval
            closer = low[2] > 0
            parts.append(f"H = {hurst:g}, {name} ({grids[-1].points}²): κ drifts by "
                         f"{_est(value[0], (low[0], high[0]), 3)}, κ_r by {_est(value[1], (low[1], high[1]), 3)} "
                         f"per unit of ln p, relative to their means; κ_r is "
                         + ("closer to constant (the paired difference of the drifts' sizes excludes 0)" if closer else
                            "not shown closer to constant"))  # fmt: skip
    if not parts:
        return "No ensemble recorded g_r: the runs predate it."
    lo, hi = GRADIENT_WINDOW
    return (f"Over the loads at {lo:.1%} to {hi:.0%} contact: " + "; ".join(parts) + ". g_r is the normalisation "
            "Müser (2016) and Front. Mech. Eng. 6:59 (2020) argue for; we know of no published curve of g_r against "
            "load with numbers.")  # fmt: skip


GRADIENT_TABLE_FRACTIONS = (0.001, 0.01, 0.1)  # the loads tabulated: those nearest these mean contact fractions


def gradient_table(runs: StudyRuns, numbers: Numbers) -> list[str]:
    """g_r / g, kappa and kappa_r with 95 % intervals at a few loads, per H and family (finest grid)."""
    lines = ["| H | family, grid | A / A0 | p / (E* g) | g_r / g [95 % CI] | κ [95 % CI] | κ_r [95 % CI] |",
             "|---|---|---|---|---|---|---|"]  # fmt: skip
    for family, name in ((MAIN, "main"), (BROAD, "broad band")):
        for hurst in runs.plan.hursts:
            grids = runs.exact_grids(hurst, family)
            g = numbers.gradients.get(grids[-1].folder.name) if grids else None
            if g is None:
                continue
            area = g.ensemble.outcome.real_area_corrected
            for j in sorted({int(np.argmin(np.abs(np.log(area / target)))) for target in GRADIENT_TABLE_FRACTIONS}):
                cells = [_est(float(est.value[j]), (float(est.interval[0][j]), float(est.interval[1][j])), 3)
                         for est in (g.ratio, g.kappa, g.kappa_r)]  # fmt: skip
                lines.append(f"| {hurst:g} | {name}, {grids[-1].points}² | {area[j]:.2%} | {g.x[j]:.3g} | " + " | ".join(cells) + " |")
    return lines if len(lines) > 2 else []


def few_spots_text(runs: StudyRuns, numbers: Numbers) -> str:
    parts = []
    for hurst in runs.hursts():
        e = runs.exact_grids(hurst, MAIN)[-1]
        s = numbers.spots.get(e.folder.name)
        if s is None:
            continue
        f = s.force / e.outcome.force_unit
        where = f"at f ≤ {f[s.few].max():.3g}" if s.few.any() else "at no load"
        parts.append(f"H = {hurst:g} ({e.points}²): {s.spots[0]:.1f} to {s.spots.max():.0f} spots per surface, fewer "
                     f"than {MANY_SPOTS} {where}; d ln A / d ln f {np.min(s.exponent):.2f} to {np.max(s.exponent):.2f}")
    if not parts:
        return "No ensemble counted its contact spots: the runs predate it."
    return ("At the smallest loads each surface touches at a handful of spots, each a Hertzian contact a few pixels "
            "wide whose area grows as F^(2/3) while it stays isolated (a local exponent d ln A / d ln f of 2/3, "
            "against about 1 where new spots keep appearing). That is a finite-size regime of this surface, not "
            f"the vanishing-load limit √(2π) = {KAPPA_BUSH:.2f} of an infinite one: the finite surface stops "
            "standing for the infinite one once its spots are too few to average (marked at "
            + f"{MANY_SPOTS} per surface). " + "; ".join(parts) + ".")


def limitations(runs: StudyRuns) -> list[str]:
    return [
        "## Limitations",
        "",
        "- One spectrum shape (a power law between two cut-offs, fixed amplitudes), one side and one rms height: "
        "the numbers hold for these surfaces, not for every self-affine surface.",
        "- Frictionless, linear elastic, non-adhesive contact; ξ is a geometric quantity of the pressed state. "
        "How ξ maps to a friction coefficient is the source study's premise, not tested here.",
        "- Grid convergence is shown only for the grids and surfaces listed, and a Richardson limit assumes the "
        "error decays as a power of the pixel size over those grids.",
        "- The model test compares three models fitted to the mean curve and per surface; its criteria assume "
        "independent errors across loads, which the same surfaces at successive loads are not: the per-surface "
        "counts and the runs test are the check against that.",
        "- The few-spot loads depend on the surface's size: they show where this finite surface stops standing "
        "for an infinite one, not a property of the infinite surface.",
        "",
    ]


def _relative_spread(spread: float) -> str:
    """A relative spread as a number a reader can use: rounding-level agreement is a bound, not 0."""
    return f"{spread:.1g}" if spread >= 1e-12 else "less than 1e-12"

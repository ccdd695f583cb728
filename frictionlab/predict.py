"""The fitted law in 3D: the rms slope in contact of a rough
surface of apparent area A pressed with force F, by MDR.

MDR maps the surface to a line of length L = 2 sqrt(A / pi), so the line's
f = F / (E* h L) becomes

    f = sqrt(pi) F / (2 E* h sqrt(A)),    xi = grad_z_contact / grad_z = a + b ln f.

The interval of xi comes, in order of preference, from

* the run's own bootstrap pairs (a_j, b_j) (``bootstrap_pairs``: redrawn
  exactly from ``realizations.npz`` with the run's seed, the same pairs its
  ``summary.json`` intervals came from): xi_j = a_j + b_j ln f, percentiles.
  This keeps the strong anti-correlation of a and b, so it is the honest interval;
* only the intervals of a and b (``a_ci``, ``b_ci``): the range of a + b ln f
  over the rectangle a_ci x b_ci (its corners). That ignores the correlation
  and is much wider: a conservative bound, not a confidence interval.
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from .errors import FrictionlabError
from .fit import bootstrap_coefficients
from .plugin import mdr_length
from .seeds import bootstrap_rng


def dimensionless_force_3d(force: float, modulus: float, rms_height: float, area: float) -> float:
    """f = sqrt(pi) F / (2 E* h sqrt(A)) (= F / (E* h L) with L = 2 sqrt(A / pi))."""
    for name, value in (("force", force), ("modulus", modulus), ("rms_height", rms_height), ("area", area)):
        if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
            raise FrictionlabError(f"{name} must be a finite number > 0. Got {value!r} instead.")
    return force / (modulus * rms_height * mdr_length(area))


@dataclass(frozen=True)
class Prediction:
    f: float
    xi: float  # grad_z_contact / grad_z
    xi_ci: tuple[float, float]
    interval: str  # how xi_ci was formed: "bootstrap pairs", "rectangle of a_ci x b_ci", "none"
    confidence: float
    fitted_f: tuple[float, float] | None = None  # the run's f range, when known
    rms_slope: float | None = None  # grad_z of the whole surface, when given
    slope_contact: float | None = None  # xi * rms_slope
    slope_contact_ci: tuple[float, float] | None = None

    @property
    def extrapolated(self) -> bool:
        return self.fitted_f is not None and not (self.fitted_f[0] <= self.f <= self.fitted_f[1])

    @property
    def beyond_full_contact(self) -> bool:
        return self.xi > 1.0  # xi = 1 at full contact: the log law no longer holds


def predict_xi(
    a: float,
    b: float,
    *,
    force: float,
    modulus: float,
    rms_height: float,
    area: float,
    pairs: np.ndarray | None = None,
    a_ci: tuple[float, float] | None = None,
    b_ci: tuple[float, float] | None = None,
    confidence: float = 0.95,
    fitted_f: tuple[float, float] | None = None,
    rms_slope: float | None = None,
) -> Prediction:
    """xi = a + b ln f at f = sqrt(pi) F / (2 E* h sqrt(A)), with an interval (see the module doc)."""
    f = dimensionless_force_3d(force, modulus, rms_height, area)
    ln_f = math.log(f)
    xi = a + b * ln_f
    if pairs is not None and len(pairs):
        pairs = np.asarray(pairs, float)
        tail = 100 * (1 - confidence) / 2
        low, high = np.percentile(pairs[:, 0] + pairs[:, 1] * ln_f, [tail, 100 - tail])
        ci, how = (float(low), float(high)), "bootstrap pairs"
    elif a_ci is not None and b_ci is not None:
        corners = [ai + bi * ln_f for ai in a_ci for bi in b_ci]
        ci, how = (min(corners), max(corners)), "rectangle of a_ci x b_ci"
    else:
        ci, how = (math.nan, math.nan), "none"
    slope = slope_ci = None
    if rms_slope is not None:
        if not (math.isfinite(rms_slope) and rms_slope > 0):
            raise FrictionlabError(f"rms_slope must be a finite number > 0. Got {rms_slope!r} instead.")
        slope, slope_ci = xi * rms_slope, (ci[0] * rms_slope, ci[1] * rms_slope)
    return Prediction(f, xi, ci, how, confidence, fitted_f, rms_slope, slope, slope_ci)


@dataclass(frozen=True)
class RunLaw:
    """The law fitted by a run, read from its folder."""

    a: float
    b: float
    a_ci: tuple[float, float]
    b_ci: tuple[float, float]
    confidence: float
    fitted_f: tuple[float, float]
    pairs: np.ndarray | None  # (bootstrap, 2), or None without realizations.npz


def bootstrap_pairs(run_dir: str | Path) -> np.ndarray | None:
    """The run's bootstrap (a, b) pairs, redrawn from realizations.npz with the run's
    seed and resample count: the very pairs behind summary.json's intervals."""
    run_dir = Path(run_dir)
    summary = json.loads((run_dir / "summary.json").read_text(encoding="utf-8"))
    npz = run_dir / "realizations.npz"
    fit = summary.get("fit") or {}
    if not npz.exists() or not fit.get("bootstrap"):
        return None
    with np.load(npz) as data:
        xi, f = data["xi"], data["f"]
    if xi.shape[0] < 2:
        return None
    return bootstrap_coefficients(f, xi, int(fit["bootstrap"]), bootstrap_rng(int(summary["seed"])))


def read_run_law(run_dir: str | Path) -> RunLaw:
    run_dir = Path(run_dir)
    try:
        summary = json.loads((run_dir / "summary.json").read_text(encoding="utf-8"))
    except (OSError, ValueError) as exc:
        raise FrictionlabError(f"--from {run_dir}: no readable summary.json there ({exc})") from None
    fit = summary.get("fit")
    if not fit:
        raise FrictionlabError(f"--from {run_dir}: the run has no fit (status {summary.get('status')!r})")
    f_range = (math.nan, math.nan)
    npz = run_dir / "realizations.npz"
    if npz.exists():
        with np.load(npz) as data:
            f_range = (float(np.min(data["f"])), float(np.max(data["f"])))
    nan2 = (math.nan, math.nan)
    return RunLaw(
        a=fit["a"],
        b=fit["b"],
        a_ci=tuple(fit["a_ci"]) if fit.get("a_ci") and None not in fit["a_ci"] else nan2,
        b_ci=tuple(fit["b_ci"]) if fit.get("b_ci") and None not in fit["b_ci"] else nan2,
        confidence=fit.get("confidence", 0.95),
        fitted_f=f_range,
        pairs=bootstrap_pairs(run_dir),
    )


def prediction_text(p: Prediction) -> str:
    level = f"{100 * p.confidence:g}%"
    ci = "n/a" if p.xi_ci[0] != p.xi_ci[0] else f"[{p.xi_ci[0]:.4f}, {p.xi_ci[1]:.4f}]"
    lines = [
        f"f = sqrt(pi) F / (2 E* h sqrt(A)) = {p.f:.6g}   (ln f = {math.log(p.f):.4f})",
        f"xi = grad_z_contact / grad_z = {p.xi:.4f}   {level} interval {ci} ({p.interval})",
    ]
    if p.slope_contact is not None:
        lines.append(
            f"rms slope in contact = {p.slope_contact:.4g}   [{p.slope_contact_ci[0]:.4g}, {p.slope_contact_ci[1]:.4g}]"
        )
    if p.extrapolated:
        lines.append(f"warning: f is outside the run's fitted range [{p.fitted_f[0]:.3g}, {p.fitted_f[1]:.3g}]: extrapolated")
    if p.beyond_full_contact:
        lines.append("warning: xi > 1, beyond full contact (xi = 1 there): the log law does not hold")
    if p.xi <= 0:
        lines.append("warning: xi <= 0: below the law's range (too few points in contact)")
    return "\n".join(lines)


def cmd_predict(args) -> int:
    """``frictionlab predict``: print the law's xi (and interval) for the given A, E*, h, F."""
    from .errors import ExitCode

    if args.from_run:
        if args.a is not None or args.b is not None:
            raise FrictionlabError("give either --from RUN_DIR or --a/--b, not both")
        law = read_run_law(args.from_run)
        a, b, a_ci, b_ci, confidence = law.a, law.b, law.a_ci, law.b_ci, law.confidence
        pairs, fitted_f = law.pairs, law.fitted_f
    else:
        if args.a is None or args.b is None:
            raise FrictionlabError("give the law: --a A --b B (with --a-ci/--b-ci for an interval), or --from RUN_DIR")
        a, b, confidence, pairs, fitted_f = args.a, args.b, args.confidence, None, None
        a_ci = tuple(args.a_ci) if args.a_ci else None
        b_ci = tuple(args.b_ci) if args.b_ci else None
        if (a_ci is None) != (b_ci is None):
            raise FrictionlabError("--a-ci and --b-ci go together (an interval needs both)")
    prediction = predict_xi(
        a, b, force=args.force, modulus=args.modulus, rms_height=args.rms_height, area=args.area,
        pairs=pairs, a_ci=a_ci, b_ci=b_ci, confidence=confidence, fitted_f=fitted_f, rms_slope=args.rms_slope,
    )  # fmt: skip
    if args.json:
        out = {k: v for k, v in prediction.__dict__.items()}
        out.update(extrapolated=prediction.extrapolated, beyond_full_contact=prediction.beyond_full_contact, a=a, b=b)
        from .fit import json_safe

        print(json.dumps({k: json_safe(v) for k, v in out.items()}, indent=2))
    else:
        print(f"law: xi = {a:.4f} + {b:.4f} ln f")
        print(prediction_text(prediction))
    return ExitCode.OK


def add_parser(sub) -> None:
    """The ``predict`` subcommand (registered by cli.build_parser)."""
    p = sub.add_parser("predict", help="rms slope in contact of a 3D contact from a fitted law")
    p.add_argument("--a", type=float, help="the law's a")
    p.add_argument("--b", type=float, help="the law's b")
    p.add_argument("--a-ci", type=float, nargs=2, metavar=("LO", "HI"), help="interval of a")
    p.add_argument("--b-ci", type=float, nargs=2, metavar=("LO", "HI"), help="interval of b")
    p.add_argument("--confidence", type=float, default=0.95, help="level of the given intervals (default 0.95)")
    p.add_argument("--from", dest="from_run", metavar="RUN_DIR", help="take the law from a run folder (summary.json)")
    p.add_argument("--area", type=float, required=True, metavar="A", help="apparent contact area A")
    p.add_argument("--modulus", type=float, required=True, metavar="ESTAR", help="effective modulus E*")
    p.add_argument("--rms-height", type=float, required=True, metavar="H", help="rms height h of the surface")
    p.add_argument("--force", type=float, required=True, metavar="F", help="normal force F")
    p.add_argument("--rms-slope", type=float, metavar="S", help="the surface's rms slope: also print S * xi")
    p.add_argument("--json", action="store_true", help="as JSON")
    p.set_defaults(handler=cmd_predict)

"""The fitted law in 3D (``frictionlab predict``): the rms slope in contact of a rough
surface of apparent area A pressed with force F, by MDR, as the paper applies it.

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

from ..errors import FrictionlabError
from ..fit import LogFit, bootstrap_coefficients, format_interval, percentile_interval
from ..plugin import ForceNormalisation, mdr_length
from ..seeds import bootstrap_rng

MDR_OF_A_SURFACE = ForceNormalisation(load="force", modulus="E*", extent="mdr length")
"""f of MDR pressing the line that stands for a surface: F / (E* h L), L = 2 sqrt(A / pi)."""


def dimensionless_force_3d(force: float, modulus: float, rms_height: float, area: float) -> float:
    """f = sqrt(pi) F / (2 E* h sqrt(A)) (= F / (E* h L) with L = 2 sqrt(A / pi))."""
    for name, value in (("force", force), ("modulus", modulus), ("rms_height", rms_height), ("area", area)):
        if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
            raise FrictionlabError(f"{name} must be a finite number > 0. Got {value!r} instead.")
    return force / MDR_OF_A_SURFACE.force_unit(modulus, rms_height, mdr_length(area))


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
    law: LogFit,
    *,
    force: float,
    modulus: float,
    rms_height: float,
    area: float,
    pairs: np.ndarray | None = None,
    fitted_f: tuple[float, float] | None = None,
    rms_slope: float | None = None,
) -> Prediction:
    """xi = a + b ln f of ``law`` at f = sqrt(pi) F / (2 E* h sqrt(A)), with an interval
    (see the module doc): from the bootstrap ``pairs`` if given, else from the corners of
    the law's ``a_ci`` x ``b_ci`` if known."""
    f = dimensionless_force_3d(force, modulus, rms_height, area)
    ln_f = math.log(f)
    xi = law.a + law.b * ln_f
    if pairs is not None and len(pairs):
        pairs = np.asarray(pairs, float)
        low, high = percentile_interval(pairs[:, 0] + pairs[:, 1] * ln_f, law.confidence)
        ci, how = (float(low), float(high)), "bootstrap pairs"
    elif all(math.isfinite(v) for v in (*law.a_ci, *law.b_ci)):
        corners = [ai + bi * ln_f for ai in law.a_ci for bi in law.b_ci]
        ci, how = (min(corners), max(corners)), "rectangle of a_ci x b_ci"
    else:
        ci, how = (math.nan, math.nan), "none"
    slope = slope_ci = None
    if rms_slope is not None:
        if not (math.isfinite(rms_slope) and rms_slope > 0):
            raise FrictionlabError(f"rms_slope must be a finite number > 0. Got {rms_slope!r} instead.")
        slope, slope_ci = xi * rms_slope, (ci[0] * rms_slope, ci[1] * rms_slope)
    return Prediction(f, xi, ci, how, law.confidence, fitted_f, rms_slope, slope, slope_ci)


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


def read_run_law(run_dir: str | Path) -> tuple[LogFit, tuple[float, float], np.ndarray | None]:
    """The law a run fitted (its summary.json), the range of f it was fitted over, and its
    bootstrap pairs (None without realizations.npz)."""
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
    return LogFit.from_dict(fit), f_range, bootstrap_pairs(run_dir)


def prediction_text(p: Prediction) -> str:
    level = f"{100 * p.confidence:g}%"
    ci = format_interval(p.xi_ci)
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

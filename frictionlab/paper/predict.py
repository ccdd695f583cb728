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

import io
import math
import numbers
import os
import sys
import zipfile
import zlib
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from ..arguments import path_argument
from ..errors import FrictionlabError, RunFolderError, command_word, short_repr, shown_name
from ..compute.fit import LogFit, fit_log_law, format_interval, format_number, percentile_interval, resample_pairs
from ..io.files import npz_unpacked_problem
from ..io.inputs import InputFileProblem
from ..plugin import ForceNormalisation, mdr_length
from ..runs.results import read_curve, read_summary
from ..runs.runfolder import check_searchable, read_member
from ..runs.settled import fit_failed
from ..preset.schema import MAX_REALIZATIONS, MAX_STEPS
from ..preset.seeds import bootstrap_rng

MDR_OF_A_SURFACE = ForceNormalisation(load="force", modulus="E*", extent="mdr length")
"""f of MDR pressing the line that stands for a surface: F / (E* h L), L = 2 sqrt(A / pi)."""


def dimensionless_force_3d(
    force: float, modulus: float, rms_height: float, area: float, names: dict[str, str] | None = None
) -> float:
    """f = sqrt(pi) F / (2 E* h sqrt(A)) (= F / (E* h L) with L = 2 sqrt(A / pi)).

    Where a product on the way under- or overflows (F, E*, h, A far from 1) f is
    formed from logarithms instead; an f that double precision cannot hold
    (beyond about 1e-308 .. 1e308) is a FrictionlabError naming the four inputs (as ``names``
    spells them: ``{"rms_height": "--rms-height"}``)."""
    for name, value in (("force", force), ("modulus", modulus), ("rms_height", rms_height), ("area", area)):
        _check_positive(value, (names or {}).get(name, name))
    force, modulus, rms_height, area = (float(v) for v in (force, modulus, rms_height, area))
    unit = MDR_OF_A_SURFACE.force_unit(modulus, rms_height, mdr_length(area))
    f = force / unit if unit > 0 else math.inf
    if all(_normal(v) for v in (area / math.pi, modulus * rms_height, unit, f)):
        return f
    ln_f = math.log(math.sqrt(math.pi) / 2) + math.log(force) - math.log(modulus) - math.log(rms_height)
    ln_f -= 0.5 * math.log(area)
    f = math.exp(ln_f) if ln_f < math.log(sys.float_info.max) else math.inf
    if not _normal(f):
        raise FrictionlabError(
            f"f = sqrt(pi) F / (2 E* h sqrt(A)) = e^{ln_f:.6g} is beyond double precision (about 1e-308 to 1e308) "
            f"for force {force!r}, modulus {modulus!r}, rms_height {rms_height!r}, area {area!r}: "
            "give them in one consistent system of units"
        )
    return f


def _is_number(value) -> bool:
    """A real number, numpy's scalars too (a value read from a table is np.float64 or np.int64), not a bool."""
    return isinstance(value, numbers.Real) and not isinstance(value, bool | np.bool_)


def _check_positive(value, name: str) -> None:
    if not (_is_number(value) and math.isfinite(value) and value > 0):
        raise FrictionlabError(f"{name} must be a finite number > 0. Got {short_repr(value)} instead.")


def _normal(value: float) -> bool:
    """Finite and at least the smallest normal double (a subnormal has lost digits)."""
    return math.isfinite(value) and value >= sys.float_info.min


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
        # xi = 1 at full contact and the law has no reason to pass it there; a mean xi can
        # exceed 1 a little before full contact (a very rough line), so this says "may"
        return self.xi > 1.0

    def __repr__(self) -> str:  # rounded, as a notebook shows it; the fields keep every digit
        slope = "" if self.slope_contact is None else f", rms slope in contact = {self.slope_contact:.4g}"
        flags = ", extrapolated" * self.extrapolated + ", xi > 1: may be past full contact" * self.beyond_full_contact
        return (f"Prediction(f = {self.f:.6g}, xi = {format_number(self.xi)} {format_interval(self.xi_ci)} "
                f"({100 * self.confidence:g}% CI, {self.interval}){slope}{flags})")  # fmt: skip

    def __str__(self) -> str:  # print(): as ``frictionlab predict`` says it, with its warnings
        return prediction_text(self)


def check_law(
    law: LogFit, names: dict[str, str] | None = None, error: type[FrictionlabError] = FrictionlabError
) -> None:
    """Refuse a law no prediction can come from: a or b not finite, a confidence
    outside (0, 1), an interval half known, not finite or with low > high (both
    unknown, NaN, is fine: no interval). ``names`` says how the caller spells each
    field (``{"a": "--a"}``); the message names it, its value and what is allowed."""
    names = names or {}

    def name(field: str) -> str:
        return names.get(field, field)

    if not isinstance(law, LogFit):  # a run's r.fit is None when no realization finished
        why = " (a run's fit is None when no realization finished)" if law is None else ""
        raise error(f"law must be a frictionlab.compute.fit.LogFit, e.g. LogFit(a, b, a_ci=(lo, hi), "
                    f"b_ci=(lo, hi)). Got {type(law).__name__}{why} instead.")  # fmt: skip
    for field in ("a", "b"):
        value = getattr(law, field)
        if not (_is_number(value) and math.isfinite(value)):
            raise error(f"{name(field)} must be a finite number. Got {value!r} instead.")
    if not (_is_number(law.confidence) and 0 < law.confidence < 1):
        raise error(
            f"{name('confidence')} must be a number between 0 and 1 (exclusive). Got {law.confidence!r} instead."
        )
    for field in ("a_ci", "b_ci"):
        value = getattr(law, field)
        pair = isinstance(value, tuple | list) and len(value) == 2 and all(map(_is_number, value))
        if pair and math.isnan(value[0]) and math.isnan(value[1]):
            continue
        if not (pair and math.isfinite(value[0]) and math.isfinite(value[1]) and value[0] <= value[1]):
            got = f"{value[0]!r}, {value[1]!r}" if pair else short_repr(value)
            raise error(f"{name(field)} must be two finite numbers LO <= HI. Got {got} instead.")


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
    names: dict[str, str] | None = None,
) -> Prediction:
    """xi = a + b ln f of ``law`` at f = sqrt(pi) F / (2 E* h sqrt(A)), with an interval
    (see the module doc): from the bootstrap ``pairs`` if given, else from the corners of
    the law's ``a_ci`` x ``b_ci`` if known. FrictionlabError for a law ``check_law``
    refuses, for numbers that leave double precision (every number returned is finite
    but an unknown interval, NaN), and for an xi <= 0, which no rms slope is."""
    check_law(law)
    if rms_slope is not None:
        _check_positive(rms_slope, (names or {}).get("rms_slope", "rms_slope"))
    f = dimensionless_force_3d(force, modulus, rms_height, area, names)
    pairs = None if pairs is None else _pairs_argument(pairs)
    ln_f = math.log(f)
    with np.errstate(over="ignore", invalid="ignore"):  # an overflow is refused below, by name
        xi = law.a + law.b * ln_f
        if pairs is not None and len(pairs):
            low, high = percentile_interval(pairs[:, 0] + pairs[:, 1] * ln_f, law.confidence)
            ci, how = (float(low), float(high)), "bootstrap pairs"
        elif all(math.isfinite(v) for v in (*law.a_ci, *law.b_ci)):
            corners = [ai + bi * ln_f for ai in law.a_ci for bi in law.b_ci]
            ci, how = (min(corners), max(corners)), "rectangle of a_ci x b_ci"
        else:
            ci, how = (math.nan, math.nan), "none"
    _refuse_overflow("xi = a + b ln f", xi, law, ln_f)
    _refuse_not_positive(xi, law, f, fitted_f, names)
    if how != "none":
        _refuse_overflow(f"the interval of xi ({how})", max(abs(ci[0]), abs(ci[1])), law, ln_f)
    slope = slope_ci = None
    if rms_slope is not None:
        slope, slope_ci = xi * rms_slope, (ci[0] * rms_slope, ci[1] * rms_slope)
        if not math.isfinite(slope) or (how != "none" and not all(map(math.isfinite, slope_ci))):
            raise FrictionlabError(
                f"the rms slope in contact, xi * rms_slope = {xi:.6g} * {rms_slope!r}, is beyond double precision: "
                "rms_slope is too large"
            )
    return Prediction(f, xi, ci, how, law.confidence, fitted_f, rms_slope, slope, slope_ci)


def _pairs_argument(pairs) -> np.ndarray:
    """The bootstrap (a, b) pairs as an (n, 2) array of finite numbers (``bootstrap_pairs`` gives them)."""
    try:
        array = np.asarray(pairs, dtype=float)
    except (TypeError, ValueError):
        array = None
    if array is None:
        got = type(pairs).__name__
    elif array.ndim != 2 or array.shape[1] != 2:
        got = f"shape {array.shape}"
    elif not np.isfinite(array).all():
        got = f"{np.count_nonzero(~np.isfinite(array))} values that are not finite"
    else:
        return array
    raise FrictionlabError(f"pairs must be bootstrap (a, b) pairs: an array of shape (n, 2) of finite numbers, "
                           f"as bootstrap_pairs(run folder) gives. Got {got} instead.")  # fmt: skip


def _refuse_overflow(what: str, value: float, law: LogFit, ln_f: float) -> None:
    if not math.isfinite(value):
        raise FrictionlabError(
            f"{what} is beyond double precision (about 1e308) with a = {law.a!r}, b = {law.b!r}, ln f = {ln_f:.6g}: "
            "the law's coefficients (or their intervals) are too large"
        )


def _refuse_not_positive(xi: float, law: LogFit, f: float, fitted_f, names: dict[str, str] | None) -> None:
    """An xi <= 0 is an rms slope at or below zero: no contact has one, so no prediction is
    printed. It comes of an f far outside the law's range, most often of inputs in mixed units."""
    if xi > 0:
        return
    named = ", ".join((names or {}).get(field, field) for field in ("force", "modulus", "rms_height", "area"))
    fitted = "" if fitted_f is None else f" (the run was fitted over f = {fitted_f[0]:.3g} .. {fitted_f[1]:.3g})"
    raise FrictionlabError(
        f"xi = a + b ln f = {law.a:.6g} + {law.b:.6g} x {math.log(f):.4g} = {xi:.4g} at f = {f:.6g}{fitted}: an rms "
        f"slope in contact must be > 0, so this f lies far outside where the law holds. Check {named}: they must "
        "be in one consistent system of units (F in N with E* in Pa, h and sqrt(A) in m, say); else the force is "
        "too far from the law's range (too few points in contact) for a prediction"
    )


# ------------------------------------------------------------------ a run folder's law



MAX_REALIZATIONS_BYTES = 16 * 1024**3  # realizations.npz: curves of every realization


def read_run_law(
    run_dir: str | Path, name: str = "run folder"
) -> tuple[LogFit, tuple[float, float] | None, np.ndarray | None]:
    """The law a run fitted (its summary.json), the range of f it was fitted over (None when
    unknown), and its bootstrap pairs (None without realizations.npz). RunFolderError, naming
    the file and the field, for a run that did not complete or whose files are damaged;
    ``name`` says how a message names the folder (the command line: ``--from``)."""
    run_dir = path_argument(run_dir, "run_dir", "a run folder")
    check_searchable(run_dir)  # a folder that cannot be looked into is said so, exit 5
    summary = _read_summary(run_dir, name)
    path = run_dir / "summary.json"
    status = summary.get("status", "completed")
    if status != "completed":
        counts = summary.get("realizations")
        count = ""
        if isinstance(counts, dict):
            count = f" ({short_repr(counts.get('done'), 20)} of {short_repr(counts.get('requested'), 20)} realizations)"
        if said := fit_failed(summary):  # no law, with every realization done: resuming it gives none either
            raise RunFolderError(f"{shown_name(path)}: the run failed with all its realizations finished{count}, and holds "
                                 f"no law: {said}; give a law by hand with --a/--b")  # fmt: skip
        raise RunFolderError(
            f"{shown_name(path)}: the run's status is {short_repr(status)}{count}, not 'completed': its law and interval "
            f"would come from fewer realizations than it asked for; finish it with `frictionlab resume {command_word(run_dir)}`, "
            "or give its law by hand with --a/--b"
        )
    law = _fit_of(summary, path)
    arrays = _read_realizations(run_dir / "realizations.npz", summary)
    if arrays is None:  # output.realizations: false; curve.csv has the same loads
        return law, _curve_range(run_dir), None
    xi, f = arrays
    _check_law_refitted(xi, f, law, path)  # before the resamples are redrawn: the cheaper check, and the plainer message
    pairs = _pairs_of(summary, law, xi, f)
    _check_intervals_redrawn(pairs, law, path)
    return law, (float(np.min(f)), float(np.max(f))), pairs


def _curve_range(run_dir: Path) -> tuple[float, float] | None:
    """The range of f of curve.csv (checked as ``read_curve`` reads it); None without one."""
    if not os.path.lexists(run_dir / "curve.csv"):
        return None
    f = read_curve(run_dir)["f"]
    f = f[np.isfinite(f) & (f > 0)]
    return (float(f.min()), float(f.max())) if f.size else None


def _check_intervals_redrawn(pairs: np.ndarray | None, law: LogFit, path: Path) -> None:
    """summary.json's intervals are the percentiles of the very pairs redrawn here: a
    realizations.npz that gives others (one xi forged to 1e308 gave an interval of xi up
    to 1e306, a and b still among the resamples) is not the run's."""
    if pairs is None or not len(pairs):
        return
    low, high = percentile_interval(pairs, law.confidence, axis=0)
    for column, name, stored in ((0, "a", law.a_ci), (1, "b", law.b_ci)):
        redrawn = (float(low[column]), float(high[column]))
        if not np.allclose(stored, redrawn, rtol=1e-6, atol=1e-12):
            raise RunFolderError(
                f"{shown_name(path)}: fit.{name}_ci = [{stored[0]:.6g}, {stored[1]:.6g}] is not the interval of its "
                f"{len(pairs)} bootstrap resamples redrawn from realizations.npz ([{redrawn[0]:.6g}, {redrawn[1]:.6g}]): "
                "the two files disagree (one was edited or damaged); run it again, or give the law by hand with --a/--b"
            )


def _check_law_refitted(xi: np.ndarray, f: np.ndarray, law: LogFit, path: Path) -> None:
    """summary.json's a and b are the fit of realizations.npz's mean curve, refitted here to
    rounding: an edited a or b was taken as the run's (a = 1e30 predicted xi = 1e30 with the
    run's interval beside it), unless it fell outside every one of 100 or more resamples."""
    with np.errstate(over="ignore", invalid="ignore"):
        refit = fit_log_law(f, xi, bootstrap=0)
    scale = max(abs(refit.a), abs(refit.b))
    for name, stored, value in (("a", law.a, refit.a), ("b", law.b, refit.b)):
        if not math.isclose(stored, value, rel_tol=1e-6, abs_tol=1e-9 * scale):
            raise RunFolderError(
                f"{shown_name(path)}: fit.{name} = {stored:.6g} is not the fit of realizations.npz's mean curve "
                f"({name} = {value:.6g}): the two files disagree (one was edited or damaged); run it again, or give "
                "the law by hand with --a/--b"
            )


def bootstrap_pairs(run_dir: str | Path) -> np.ndarray | None:
    """The run's bootstrap (a, b) pairs, redrawn from realizations.npz with the run's
    seed and resample count: the very pairs behind summary.json's intervals."""
    run_dir = path_argument(run_dir, "run_dir", "a run folder")
    summary = _read_summary(run_dir)
    law = _fit_of(summary, run_dir / "summary.json")
    arrays = _read_realizations(run_dir / "realizations.npz", summary)
    return None if arrays is None else _pairs_of(summary, law, *arrays)


def _pairs_of(summary: dict, law: LogFit, xi: np.ndarray, f: np.ndarray) -> np.ndarray | None:
    if not law.bootstrap or xi.shape[0] < 2:
        return None
    with np.errstate(over="ignore", invalid="ignore"):  # a forged xi of 1e308: refused by name once redrawn
        return resample_pairs(f, xi, law.bootstrap, bootstrap_rng(summary["seed"]))


def _read_summary(run_dir: Path, name: str = "run folder") -> dict:
    """summary.json of the run folder, each value checked (``results.read_summary``); ``name``
    says how the caller names it (the command line: ``--from``)."""
    if not run_dir.is_dir():  # a file (its summary.json, say) is named as one, not as missing
        what = "not a folder: give the run's folder" if os.path.lexists(run_dir) else "no such folder"
        raise RunFolderError(f"{name} {shown_name(run_dir)}: no readable summary.json there ({what})")
    if not os.path.lexists(run_dir / "summary.json") and os.path.lexists(run_dir / "sweep.json"):
        raise RunFolderError(  # a law per point: the user names one
            f"{name} {shown_name(run_dir)} is a sweep's folder, which holds a law per point: give one point's run folder, "
            f"{shown_name(run_dir / 'points')}/<NN-label> (frictionlab runs {command_word(run_dir / 'points')} lists them)"
        )
    if not os.path.lexists(run_dir / "summary.json") and os.path.lexists(run_dir / "run.json"):
        raise RunFolderError(  # killed before its end (kill -9, a crash): "no such summary.json" said not why
            f"{name} {shown_name(run_dir)} holds a run that wrote no summary.json: it is still running (`frictionlab "
            f"follow {command_word(run_dir)}` shows it), or it stopped before its end (`frictionlab resume "
            f"{command_word(run_dir)}` finishes it); or give the law by hand with --a/--b"
        )
    return read_summary(run_dir)[0]


def _fit_of(summary: dict, path: Path) -> LogFit:
    """summary.json's ``fit`` (its types checked by the schema) checked as a law (``check_law``)."""
    if summary.get("fit") is None:
        raise RunFolderError(f"{shown_name(path)}: the run has no fit (status {summary.get('status')})")
    law = LogFit.from_dict(summary["fit"])
    names = {field: f"{shown_name(path)}: field 'fit.{field}'" for field in ("a", "b", "a_ci", "b_ci", "confidence")}
    check_law(law, names, RunFolderError)
    if law.bootstrap and summary.get("seed") is None:
        raise RunFolderError(f"{shown_name(path)}: field 'seed' must be a whole number >= 0 (the bootstrap's), not null")
    return law


def _most_array_bytes(summary: dict) -> int:
    """The largest array its run writes in realizations.npz: one float64 per realization done
    and load step (as summary.json says them, each within what a preset allows)."""
    counts, loading = summary.get("realizations"), (summary.get("preset") or {}).get("loading")
    done = counts.get("done") if isinstance(counts, dict) else None
    steps = loading.get("steps") if isinstance(loading, dict) else None
    done = done if isinstance(done, int) and 0 < done <= MAX_REALIZATIONS else MAX_REALIZATIONS
    steps = steps if isinstance(steps, int) and 2 <= steps <= MAX_STEPS else MAX_STEPS
    return done * steps * 8 + 4096


def _read_realizations(path: Path, summary: dict) -> tuple[np.ndarray, np.ndarray] | None:
    """(xi per realization, f) of realizations.npz, checked; None when the run kept no such file."""
    if not os.path.lexists(path):
        return None
    try:
        raw = read_member(path.parent, path.name, MAX_REALIZATIONS_BYTES, "realizations.npz")
        if raw[:2] != b"PK":  # every zip, so every .npz, starts so
            raise RunFolderError(f"{shown_name(path)} is damaged (not an .npz archive: it does not start as a zip file does)")
        with zipfile.ZipFile(io.BytesIO(raw)) as archive:
            problem = npz_unpacked_problem(archive, _most_array_bytes(summary))
        if problem:
            raise RunFolderError(f"{shown_name(path)} is damaged ({problem})")
        with np.load(io.BytesIO(raw), allow_pickle=False) as data:
            missing = [name for name in ("xi", "f") if name not in data.files]
            if missing:
                raise RunFolderError(f"{shown_name(path)} is damaged (no array {missing[0]!r} in it)")
            xi, f = data["xi"], data["f"]
    except InputFileProblem as exc:
        raise RunFolderError(f"{shown_name(path)}: {exc}") from None
    except (ValueError, OSError, EOFError, zipfile.BadZipFile, zlib.error) as exc:  # cut short, pickled, bad header
        reason = str(exc) or type(exc).__name__
        if "allow_pickle" in reason:
            reason = "it holds pickled Python objects, which are never loaded"
        reason = short_repr(reason, 120)[1:-1]
        raise RunFolderError(f"{shown_name(path)} is damaged (not an .npz archive of number arrays: {reason})") from None
    except MemoryError as exc:  # an array's header may claim any shape
        raise RunFolderError(f"{shown_name(path)}: an array in it is larger than this machine's memory ({exc})") from None
    for name, array, ndim in (("xi", xi, 2), ("f", f, 1)):
        if array.dtype.kind not in "fiu" or array.ndim != ndim or not array.size:
            raise RunFolderError(
                f"{shown_name(path)}: array {name!r} must be {ndim}-D numbers, not empty. "
                f"Got shape {array.shape} of {array.dtype} instead."
            )
    if xi.shape[1] != f.size:
        raise RunFolderError(f"{shown_name(path)}: array 'xi' has {xi.shape[1]} columns, one per load step, but 'f' has {f.size}")
    if not np.all(np.isfinite(f) & (f > 0)):
        raise RunFolderError(f"{shown_name(path)}: array 'f' must hold finite numbers > 0 (some are not)")
    defined = f.size - np.isnan(xi).all(axis=0).sum()  # NaN: a line with no xi at that load
    if (bad := np.count_nonzero(np.isinf(xi))) or defined < 2:  # said as it is: infinite, or too few loads
        why = f"{bad} of {xi.size} are infinite" if bad else f"no line has xi at {f.size - defined} of its {f.size} loads"
        raise RunFolderError(f"{shown_name(path)}: array 'xi' must hold finite numbers, or NaN where a line has no xi, with xi "
                             f"defined at two loads or more ({why})")  # fmt: skip
    if negative := np.count_nonzero(xi < 0):  # an rms slope over another: a run writes none below 0
        raise RunFolderError(f"{shown_name(path)}: array 'xi' must hold numbers >= 0, or NaN where a line has no xi "
                             f"({negative} of {xi.size} are negative)")  # fmt: skip
    counts = summary.get("realizations")
    done = counts.get("done") if isinstance(counts, dict) else None
    if isinstance(done, int) and not isinstance(done, bool) and done != xi.shape[0]:
        raise RunFolderError(
            f"{shown_name(path)}: array 'xi' has {xi.shape[0]} realizations but summary.json says {done} were done: "
            "the two files are not of one run"
        )
    return xi.astype(float), f.astype(float)


def prediction_text(p: Prediction) -> str:
    level = f"{100 * p.confidence:g}%"
    ci = format_interval(p.xi_ci)
    lines = [
        f"f = sqrt(pi) F / (2 E* h sqrt(A)) = {p.f:.6g}   (ln f = {math.log(p.f):.4f})",
        f"xi = grad_z_contact / grad_z = {format_number(p.xi)}   {level} interval {ci} ({p.interval})",
    ]
    if p.slope_contact is not None:
        low, high = p.slope_contact_ci
        ci = f"[{low:.4g}, {high:.4g}]" if math.isfinite(low) and math.isfinite(high) else "n/a"
        lines.append(f"rms slope in contact = {p.slope_contact:.4g}   {ci}")
    if p.extrapolated:
        lines.append(f"warning: f is outside the run's fitted range [{p.fitted_f[0]:.3g}, {p.fitted_f[1]:.3g}]: extrapolated")
    if p.beyond_full_contact:
        lines.append("warning: xi > 1, more than the whole surface's rms slope: at full contact xi = 1, so this force "
                     "may be past where the log law holds (see the run's contact fraction)")
    return "\n".join(lines)

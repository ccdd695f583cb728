"""What a plugin hands back, checked where the framework takes it: a profile, its slopes,
a contact curve. The run refuses a broken answer by the plugin's name and distribution,
before any number is computed from it; the conformance kit (``frictionlab.testing``)
states the same problems in the same words."""

from __future__ import annotations

import ctypes
import functools
import json
import math
import sys
from collections.abc import Callable

import numpy as np

from ..errors import PluginError, short_repr
from .data import ContactCurve, Profile
from .kinds import ContactSolver, SlopeEstimator, SpectrumGenerator
from .registry import plugin_label

LEAVE_INPUTS = "a plugin must leave the arrays it is given as they are (heights, slopes, loads): compute into new ones"
SAME_SEED = ("the same seed gave different heights; draw all randomness from the rng argument and keep no "
             "state between calls (realizations run in any order, in other processes)")
OTHER_SEED = ("different seeds gave identical heights; draw all randomness from the rng argument (or declare "
              "deterministic = True, for a generator that ignores randomness by design, e.g. one that reads a measured profile)")
SAMPLE_POINTS = 1024  # heights compared of two profiles of one seed: spread over the whole profile
CURVE_ARRAYS = ("force", "indentation", "contact_count", "contact_fraction", "slope_rms_contact")
DECLARED_ARRAYS = {"real_area_corrected": "corrected_area", "real_gradient_rms": "real_gradient",
                   "contact_spots": "counts_spots"}  # fmt: skip


def array_problem(what: str, value, shape=None, floating: bool = True, nan: bool = False) -> str | None:
    """What is wrong with ``value`` as a plugin's array: not a numpy array, another shape,
    not float64 (``floating``) or not numeric, or not finite (NaN allowed with ``nan``)."""
    if not isinstance(value, np.ndarray):
        return f"{what} must be a numpy array. Got {type(value).__name__} instead."
    if shape is not None and value.shape != tuple(shape):
        return f"{what} must have shape {tuple(shape)}. Got {value.shape} instead."
    if floating and value.dtype != np.float64:  # what the framework computes and stores in: float32 loses digits
        return f"{what} must be float64 (double precision). Got dtype {value.dtype} instead."
    if not np.issubdtype(value.dtype, np.number) or np.issubdtype(value.dtype, np.complexfloating):
        return f"{what} must be real numbers. Got dtype {value.dtype} instead."
    if value.size and not _all_finite(value, nan):
        bad = np.isinf(value) if nan else ~np.isfinite(value)
        first = np.unravel_index(int(np.argmax(bad)), value.shape)  # where to look, in the plugin's own terms
        where = first[0] if value.ndim == 1 else tuple(int(i) for i in first)
        return (f"{what} must be finite. Got {int(np.count_nonzero(bad))} non-finite value(s), the first "
                f"{float(value[first])} at index {where}.")  # fmt: skip
    return None


def _all_finite(value: np.ndarray, nan: bool) -> bool:
    """Whether every entry of a non-empty numeric ``value`` is finite (or NaN, with ``nan``):
    its extremes say it without a mask the size of the array."""
    if not nan:  # max and min carry a NaN through
        return bool(np.isfinite(value.max()) and np.isfinite(value.min()))
    extremes = np.fmax.reduce(value, axis=None), np.fmin.reduce(value, axis=None)  # these pass a NaN by
    return bool(np.isfinite(extremes).all()) or not np.isinf(value).any()  # NaN extremes: every entry is NaN


def whole_problem(what: str, values) -> str | None:
    """``values`` must be whole numbers (counts), of an integer or a float dtype."""
    if not np.array_equal(values, np.round(values)):
        return f"{what} must hold whole numbers. Got {values!r}."
    return None


def profile_problem(generator: SpectrumGenerator, profile) -> str | None:
    """What is wrong with what ``generate()`` returned."""
    if not isinstance(profile, Profile):
        return f"generate() must return a frictionlab.Profile. Got {type(profile).__name__} instead."
    problem = array_problem("Profile.heights", profile.heights)
    if problem:
        return problem
    dimension = generator.dimension
    if profile.heights.ndim != dimension:
        return f"Profile.heights must be {dimension}-D (dimension = {dimension}). Got shape {profile.heights.shape} instead."
    if profile.heights.size < 2:
        return f"Profile.heights must have at least 2 points. Got {profile.heights.size}."
    spacing = profile.spacing
    real = isinstance(spacing, (int, float, np.integer, np.floating)) and not isinstance(spacing, bool)
    if not (real and math.isfinite(spacing) and spacing > 0):
        return f"Profile.spacing must be finite and > 0. Got {spacing!r} instead."
    if not isinstance(profile.periodic, bool):
        return f"Profile.periodic must be True or False. Got {profile.periodic!r} instead."
    if not isinstance(declared := generator.periodic(), bool):  # as answers_problem says it, not as a mismatch
        return f"periodic() must be True or False. Got {declared!r} instead."
    if profile.periodic is not declared:  # the preset's solver and estimator were checked by it
        return f"Profile.periodic must be what periodic() declares, {declared!r}. Got {profile.periodic!r} instead."
    return None


def heights_sample(profile: Profile) -> tuple:
    """Up to ``SAMPLE_POINTS`` heights of ``profile`` spread evenly over it, with its shape and spacing:
    what compares two profiles without keeping both."""
    heights = profile.heights
    spread = np.linspace(0, heights.size - 1, min(heights.size, SAMPLE_POINTS)).astype(np.intp)
    return heights.shape, profile.spacing, heights.flat[spread].tobytes()


def seed_problem(generator: SpectrumGenerator, profile: Profile, generated: Callable[[int], object],
                 others: bool = True) -> str | None:  # fmt: skip
    """What is wrong with a generator whose realization 0 is ``profile``, as ``generated(index)``
    makes realization ``index`` again from a fresh generator of its seed: realization 0 must come
    out the same, and realization 1 other where there are ``others`` (unless ``deterministic``); an
    exception making realization 1 is left to it. Each is sampled and let go before the next is
    made: at most one more profile is held."""
    expected = heights_sample(profile)
    for index, problem in ((0, SAME_SEED), (1, OTHER_SEED)):
        if index and (generator.deterministic or not others):
            break
        try:
            made = generated(index)
        except Exception:  # noqa: BLE001 - realization 1's own failure: it tells it when it runs
            if index:
                break
            raise
        if wrong := profile_problem(generator, made):
            return wrong
        if (heights_sample(made) == expected) != (index == 0):
            return problem
        del made
    return None


def slopes_problem(estimator: SlopeEstimator, slopes, profile: Profile, what: str = "slopes()") -> str | None:
    """What is wrong with what ``slopes(heights, spacing, periodic)`` returned for ``profile``."""
    undefined = estimator.undefined_points(profile.periodic) is True
    problem = array_problem(what, slopes, profile.heights.shape, nan=undefined)
    if problem and not undefined and array_problem(what, slopes, profile.heights.shape, nan=True) is None:  # NaN alone
        problem += f" A NaN (a point without a slope) needs undefined_points({profile.periodic}) to return True."
    if not problem and slopes.ndim == 2 and slopes.size and (least := float(np.fmin.reduce(slopes, axis=None))) < 0:
        problem = f"{what} on a surface must be gradient magnitudes |grad z| >= 0. Got a minimum of {least:.6g}."
    if not problem and slopes.size and not slopes.any() and (span := float(np.ptp(profile.heights))) > 0:
        problem = (f"{what} gave 0 at every point of a {'surface' if slopes.ndim == 2 else 'line'} whose heights span "
                   f"{span:.6g} (in the profile's length unit): no slope of it is 0 everywhere")  # fmt: skip
    return problem


def curve_problem(solver: ContactSolver, curve, loads: int, where: str = "solve()") -> str | None:
    """What is wrong with what ``solve()`` (called as ``where`` says) returned for ``loads`` loads."""
    if not isinstance(curve, ContactCurve):
        return f"{where} must return a frictionlab.ContactCurve. Got {type(curve).__name__} instead."
    for name in CURVE_ARRAYS:
        nan = name == "slope_rms_contact" and solver.undefined_slopes  # NaN where no point in contact has a slope
        value, what = getattr(curve, name), f"{where}.{name}"
        problem = array_problem(what, value, (loads,), floating=name != "contact_count", nan=nan)
        if problem or (name == "contact_count" and (problem := whole_problem(what, value))):
            return problem
    for name, flag in DECLARED_ARRAYS.items():  # contract names: ContactCurve's fields, ContactSolver's flags
        value, declared, what = getattr(curve, name), getattr(solver, flag), f"{where}.{name}"
        if (value is not None) != declared:
            return f"{what} must be given exactly when {flag} is True (it is {declared!r}). Got {value!r}."
        if value is not None and (problem := array_problem(what, value, (loads,), name != "contact_spots")):
            return problem
    half, what = curve.half_load_points, f"{where}.half_load_points"
    if half is not None:  # optional: a solver may not say
        return array_problem(what, half, (loads,), floating=False) or whole_problem(what, half)
    return None


SLOPE_RTOL = 1e-6  # an rms of slopes past the largest by this much: the rounding of sums over a million points, not a bug


def largest_magnitude(values: np.ndarray) -> float:
    """The largest |value|, NaN ones passed by (0 for none; NaN when all are), without a
    temporary the size of ``values``."""
    if not values.size:
        return 0.0
    return float(np.fmax(np.fmax.reduce(values, axis=None), -np.fmin.reduce(values, axis=None)))


def reported_problem(curve: ContactCurve, loads: np.ndarray, control: str, points: int, steepest: float) -> str | None:
    """What is wrong with the numbers of a well-formed ``curve`` solved for ``loads`` under ``control``
    on a profile of ``points`` points whose largest |slope| handed to the solver is ``steepest``: the
    loads not reported as asked (within 1%, as the conformance kit asks), a count or fraction out of
    its range, an rms slope below 0 or (in contact) past ``steepest``, a corrected area out of
    [0, contact_fraction]."""
    reported, what = getattr(curve, control), f"solve(..., control={control!r}).{control}"
    if not np.allclose(reported, loads, rtol=1e-2, atol=0):
        return f"{what} must report the loads asked for: {short_repr(loads, 300)}. Got {short_repr(reported, 300)} instead."
    count, fraction = curve.contact_count, curve.contact_fraction
    if count.size and (count.min() < 0 or count.max() > points):
        return f"solve().contact_count must lie in 0 .. {points} (points of the profile). Got {short_repr(count, 300)}."
    if fraction.size and (fraction.min() < 0 or fraction.max() > 1):
        return f"solve().contact_fraction must lie in [0, 1]. Got {short_repr(fraction, 300)}."
    rms = curve.slope_rms_contact  # NaN (where declared) compares False: passed by
    if np.any(rms < 0) or np.any(rms > steepest * (1 + SLOPE_RTOL)):
        return (f"solve().slope_rms_contact must lie in [0, max |slope| = {steepest:.6g}] (an rms of the slopes "
                f"solve() is given, over the points in contact). Got {short_repr(rms, 300)}.")  # fmt: skip
    if curve.real_gradient_rms is not None and np.any(curve.real_gradient_rms < 0):
        return f"solve().real_gradient_rms is an rms slope and must be >= 0. Got {short_repr(curve.real_gradient_rms, 300)}."
    corrected = curve.real_area_corrected
    if corrected is not None and (np.any(corrected < 0) or np.any(corrected > fraction * (1 + 1e-12))):
        return ("solve().real_area_corrected must lie in [0, contact_fraction]: the correction removes part of the "
                f"pixels counted. Got {short_repr(corrected, 300)}.")  # fmt: skip
    return None


ORDER_RTOL = 1e-3  # a drop an iterative solver's stop may leave (bem's certified indentation: within 1e-4)


def schedule_problem(loads: np.ndarray) -> str | None:
    """Loads handed to a solver must not decrease: every solver sweeps them in order (warm starts)."""
    if loads.size > 1 and np.any(loads[1:] < loads[:-1]):
        return f"the loads handed to the solver must not decrease. Got {short_repr(loads, 300)}."
    return None


def order_problem(solver: ContactSolver, curve: ContactCurve, control: str) -> str | None:
    """What a well-formed ``curve`` solved for non-decreasing loads reports out of order: a force,
    indentation or contact count below one at a smaller load (by more than a relative ``ORDER_RTOL``
    of the largest for an iterative solver, whose stop leaves that much; by nothing for a direct one)."""
    rtol = ORDER_RTOL if solver.tolerance_param is not None else 1e-12
    for name in ("force", "indentation", "contact_count"):
        values = np.asarray(getattr(curve, name), dtype=float)
        if values.size < 2:
            continue
        drops = np.maximum.accumulate(values) - values  # below the largest at a smaller load
        j = int(np.argmax(drops))
        if drops[j] > rtol * float(np.abs(values).max()):
            first = int(np.argmax(values[:j] > values[j]))
            return (f"solve(..., control={control!r}).{name} must not decrease as the load grows. Got {values[j]:.6g} "
                    f"at index {j}, after {values[first]:.6g} at index {first}: {short_repr(values, 300)}.")  # fmt: skip
    return None


_KEY_BYTES = 624 * 4  # MT19937's key; its position (a C int) follows it in the state struct


@functools.cache
def _legacy_state_address() -> int | None:
    """Where the legacy MT19937 state that ``np.random.*`` functions draw from lies in memory (its
    key, then its position), when it reads there as ``np.random.get_state()`` says; None otherwise
    (another numpy's layout: the whole state is then compared)."""
    try:
        address = np.random.mtrand._rand._bit_generator.ctypes.state_address
        _, keys, position, _, _ = np.random.get_state()
        raw = ctypes.string_at(address, _KEY_BYTES + 4)
        same = raw[:_KEY_BYTES] == keys.tobytes() and int.from_bytes(raw[_KEY_BYTES:], sys.byteorder, signed=True) == position
    except (AttributeError, TypeError, ValueError):
        return None
    return address if same else None


def random_state() -> tuple:
    """numpy's global random state (what ``np.random.*`` functions draw from), to compare."""
    _, keys, position, has_gauss, gauss = np.random.get_state()
    return keys.tobytes(), position, has_gauss, gauss


class RandomWatch:
    """numpy's global random state looked at between consecutive plugin calls: ``problem(what)``
    says whether the call since the last look (``what``) drew from it (or seeded it), whose numbers
    would then depend on which realizations ran before it in the process, so on the worker count.

    A look copies the MT19937 key and position (about a microsecond; ``np.random.get_state()``
    takes tens): every draw moves the position or, past the key's end, renews the whole key. Only
    a cached second Gaussian is drawn without either; so the whole state is read as a watch starts,
    unless the key and position are those a watch started at with none cached (nothing drawn
    since: none cached now), and where one is cached every look reads the whole state."""

    clear: bytes | None = None  # the key and position at the last start known to have no Gaussian cached

    def __init__(self):
        address = _legacy_state_address()
        if address is not None and ctypes.string_at(address, _KEY_BYTES + 4) != RandomWatch.clear:
            address = None if np.random.get_state()[3] else address
        self.address = address
        self.last = self._look()
        if address is not None:
            RandomWatch.clear = self.last

    def _look(self):
        return random_state() if self.address is None else ctypes.string_at(self.address, _KEY_BYTES + 4)

    def problem(self, what: str) -> str | None:
        before, self.last = self.last, self._look()
        if self.last == before:
            return None
        return (f"{what} used numpy's global random state (np.random.* functions): draw all randomness from "
                "the rng argument generate() is given, so that a seed gives the same numbers for any worker count")


def read_only(array: np.ndarray) -> np.ndarray:
    """A view of ``array`` that cannot be written: what a plugin is lent, so that changing it in place
    raises in the plugin's own line rather than changing what the run computes next."""
    view = array.view()
    view.flags.writeable = False
    return view


def _positive(what: str, value, none: bool = False) -> str | None:
    if value is None and none:
        return None
    real = isinstance(value, (int, float, np.integer, np.floating)) and not isinstance(value, bool)
    if not (real and math.isfinite(value) and value > 0):
        return f"{what} must be {'None or a number ' if none else ''}finite and > 0. Got {value!r} instead."
    return None


def _whole(value) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, bool)


def answers_problem(plugin) -> str | None:
    """What is wrong with the answers a run reads of ``plugin`` before it starts: a spectrum's
    ``periodic()``, ``grid_shape()`` and ``caveats()`` (``rms_height()``: ``height_problem``, once a measured
    file is read); a solver's ``stiffness()`` and ``tolerance()``; an estimator's
    ``undefined_points(periodic)``."""
    if isinstance(plugin, SpectrumGenerator):
        periodic, shape, dimension = plugin.periodic(), plugin.grid_shape(), plugin.dimension
        if not isinstance(periodic, bool):
            return f"periodic() must be True or False. Got {periodic!r} instead."
        if shape is not None and not (isinstance(shape, (tuple, list)) and len(shape) == dimension
                                      and all(_whole(n) and n >= 1 for n in shape)):  # fmt: skip
            return f"grid_shape() must be None or {dimension} whole number(s) >= 1, the shape generate() makes. Got {shape!r} instead."
        return caveats_problem(plugin.caveats())
    if isinstance(plugin, ContactSolver):
        return _positive("stiffness()", plugin.stiffness()) or _positive("tolerance()", plugin.tolerance(), none=True)
    undefined = (plugin.undefined_points(True), plugin.undefined_points(False))
    if undefined[0] is not False or not isinstance(undefined[1], bool):
        return ("undefined_points(periodic) must be False for a periodic profile, True or False for another. "
                f"Got {undefined[0]!r} and {undefined[1]!r}.")  # fmt: skip
    return None


def caveats_problem(caveats) -> str | None:
    """A spectrum's ``caveats()`` must be a tuple of sentences: a bare string would be told letter by letter."""
    if isinstance(caveats, tuple) and all(isinstance(c, str) and c.strip() for c in caveats):
        return None
    return f"caveats() must be a tuple of non-empty strings (one sentence: (sentence,)). Got {caveats!r} instead."


def input_summary_problem(summary) -> str | None:
    """``input_summary()`` must be None or a JSON-ready mapping (summary.json holds it) giving at
    least file, shape, spacing, unit and rms_height (the progress and validate say them)."""
    if summary is None:
        return None
    try:
        json.dumps(summary, allow_nan=False)
    except (TypeError, ValueError) as exc:  # an object json cannot write, infinity, NaN
        return f"input_summary() must be None or a JSON-ready mapping. Got {short_repr(repr(summary), 300)[1:-1]} ({exc})."
    if not isinstance(summary, dict) or not {"file", "shape", "spacing", "unit", "rms_height"} <= set(summary):
        return f"input_summary() must give at least file, shape, spacing, unit and rms_height. Got {summary!r}."
    return None


def shape_problem(spectrum: SpectrumGenerator, profile: Profile) -> str | None:
    """``grid_shape()`` must be None or the shape of what ``generate()`` made, ``profile``."""
    shape = spectrum.grid_shape()
    if shape is not None and tuple(shape) != profile.heights.shape:
        return f"grid_shape() must be None or the shape generate() makes, {profile.heights.shape}. Got {shape!r}."
    return None


def height_problem(spectrum: SpectrumGenerator) -> str | None:
    """What is wrong with ``rms_height()``, the h of f."""
    return _positive("rms_height()", spectrum.rms_height())


def height_of(spectrum: SpectrumGenerator, profile: Profile) -> tuple[float, float | None]:
    """The h of f for ``profile`` and the profile's own h (None when it is the nominal one), checked."""
    own = spectrum.profile_rms_height(profile)
    if own is None:  # asked once: a measured spectrum may compute it
        nominal = spectrum.rms_height()
        refuse(spectrum, _positive("rms_height()", nominal))
        return nominal, None
    refuse(spectrum, _positive("profile_rms_height(profile)", own))
    return own, own


def full_contact_problem(full, method: str = "full_contact_load") -> str | None:
    """What is wrong with an answer of ``full_contact_load(profile)`` (or of ``method``)."""
    if full is None or (isinstance(full, (int, float, np.integer, np.floating)) and not isinstance(full, bool)
                        and math.isfinite(full) and full >= 0):  # fmt: skip
        return None
    return f"{method}(profile) must be None or a finite number >= 0. Got {full!r}."


def refuse(plugin, problem: str | None) -> None:
    """Raise PluginError naming ``plugin`` (kind, name, class, distribution) and ``problem``, if any."""
    if problem:
        raise PluginError(f"{plugin_label(type(plugin))} broke the plugin contract: {problem}")

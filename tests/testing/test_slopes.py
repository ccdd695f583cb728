"""The slope estimator check fails for estimators broken in one way each."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from frictionlab import testing as fltesting
from frictionlab.plugin import KINDS

from .fakes import fails_naming, forward_differences, slopes_variant

ROOT = Path(__file__).resolve().parents[2]

KIND_HOOKS = {kind: base.register_hook for kind, base in KINDS.items()}


# =========================================================================== fakes


def _demean_in_place(self, heights, spacing, periodic=True):
    heights -= heights.mean()
    return forward_differences(heights, spacing, periodic)


SLOPE_BREAKAGES = [
    ("WrongShape", lambda self, z, dx, periodic=True: np.diff(z) / dx, r"must have shape \(128,\)"),
    ("ForgetsSpacing", lambda self, z, dx, periodic=True: np.roll(z, -1) - z, "order of magnitude"),
    ("SignFlipped", lambda self, z, dx, periodic=True: -forward_differences(z, dx), "order of magnitude and sign"),
    ("Offset", lambda self, z, dx, periodic=True: forward_differences(z, dx) + 1e-3, "constant line must have zero slopes"),
    ("ReturnsList", lambda self, z, dx, periodic=True: list(forward_differences(z, dx)), "must be a numpy array"),
    ("NaN", lambda self, z, dx, periodic=True: np.where(np.arange(z.size) == 0, np.nan, forward_differences(z, dx)), "must be finite"),
    ("Integer", lambda self, z, dx, periodic=True: np.round(forward_differences(z, dx)).astype(int), "must be float64"),
    ("Single", lambda self, z, dx, periodic=True: forward_differences(z, dx).astype(np.float32),
     r"must be float64 \(double precision\). Got dtype float32"),
    ("MutatesInput", _demean_in_place, r"modified its input: a plugin must leave the arrays it is given as they are"),
    ("Random", lambda self, z, dx, periodic=True: forward_differences(z, dx) + 1e-12 * np.random.default_rng().random(z.size),
     "not repeatable"),
    ("WrapsAScan", lambda self, z, dx, periodic=True: forward_differences(z, dx), "a difference across the ends"),
    ("NoPeriodicArgument", lambda self, z, dx: forward_differences(z, dx), "raised TypeError"),
]


@pytest.mark.parametrize("qualname,slopes,match", SLOPE_BREAKAGES, ids=[b[0] for b in SLOPE_BREAKAGES])
def test_slope_check_fails_for_broken_estimators(qualname, slopes, match):
    cls = slopes_variant(qualname, slopes)
    fails_naming(fltesting.check_slope_estimator, cls, match)


def _nan_at(index):
    def slopes(self, z, dx, periodic=True):
        out = forward_differences(z, dx, periodic)
        if not periodic:
            out[index] = np.nan
        return out

    return slopes


@pytest.mark.parametrize(
    "qualname,slopes,undefined,match",
    [
        ("UndeclaredEnd", _nan_at(-1), lambda self, periodic: False,
         r"must be finite\. Got 1 non-finite value\(s\), the first nan at index 127\. A NaN \(a point without a slope\) needs undefined_points\(False\) to return True"),
        ("InnerNaN", _nan_at(5), lambda self, periodic: not periodic, "only in bands at the profile's ends"),
        ("WideBand", _nan_at(slice(0, 40)), lambda self, periodic: not periodic, "at most a quarter of each axis"),
        ("UndefinedWhenPeriodic", _nan_at(-1), lambda self, periodic: True, r"undefined_points\(True\) must be False"),
    ],
)
def test_slope_check_holds_undefined_points_to_the_edge_of_a_scan(qualname, slopes, undefined, match):
    cls = type(qualname, (slopes_variant(qualname, slopes),), {"undefined_points": undefined})
    fails_naming(fltesting.check_slope_estimator, cls, match)
    ends = type("UndefinedEnd", (slopes_variant("UndefinedEnd", _nan_at(-1)),),
                {"undefined_points": lambda self, periodic: not periodic})  # fmt: skip
    fltesting.check_slope_estimator(ends)


def test_a_wide_stencil_may_leave_several_points_at_each_end_without_a_slope():
    """Fourth-order central differences leave two points at each end of a scan without a
    slope (NaN, declared): the check accepts them, the tilt exact at every other point, on
    lines and on surfaces (NaN bands two points deep along both axes)."""

    def fourth_order(self, z, dx, periodic=True):
        ahead = [np.roll(z, -k, axis=0) - np.roll(z, k, axis=0) for k in (1, 2)]
        out = (8 * ahead[0] - ahead[1]) / (12 * dx)
        if not periodic:
            out[:2], out[-2:] = np.nan, np.nan
        return out

    line = type("FourthOrder", (slopes_variant("FourthOrder", fourth_order),),
                {"undefined_points": lambda self, periodic: not periodic})  # fmt: skip
    fltesting.check_slope_estimator(line)


def test_negative_slopes_on_a_surface_fail_in_the_words_of_a_run():
    def slopes(self, z, dx, periodic=True):
        return forward_differences(z, dx, periodic) if z.ndim == 1 else -np.hypot(*np.gradient(z, dx))

    cls = type("NegativeGradient", (slopes_variant("NegativeGradient", slopes),), {"dimensions": (1, 2)})
    fails_naming(fltesting.check_slope_estimator, cls,
                 r"slopes\(random surface\) on a surface must be gradient magnitudes \|grad z\| >= 0. Got a minimum of -")


def test_the_kit_names_a_plugin_as_a_run_does_with_its_distribution():
    """The kit named the class alone (``module.MutatesInput ('broken-slopes')``); a run names the
    kind, the name, the class and the distribution: the kit now says it in the same words."""
    cls = slopes_variant("MutatesInput", _demean_in_place)
    with pytest.raises(AssertionError) as excinfo:
        fltesting.check_slope_estimator(cls)
    assert str(excinfo.value).startswith(f"slope 'broken-slopes' ({cls.__module__}.MutatesInput from {cls.__module__}): ")

"""The spectrum check fails for generators broken in one way each."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from frictionlab import (
    Profile,
)
from frictionlab import testing as fltesting
from frictionlab.plugin import KINDS

from .fakes import GoodSpectrum, fails_naming, spectrum_variant

ROOT = Path(__file__).resolve().parents[2]

KIND_HOOKS = {kind: base.register_hook for kind, base in KINDS.items()}


# =========================================================================== fakes


SPECTRUM_BREAKAGES = [
    ("NonDeterministic", {"generate": lambda self, rng: GoodSpectrum.generate(self, np.random.default_rng())},
     "same seed gave different heights"),
    ("IgnoresSeed", {"generate": lambda self, rng: GoodSpectrum.generate(self, np.random.default_rng(0))},
     "different seeds gave identical heights"),
    ("Stateful", {"generate": lambda self, rng: Profile(  # its rng used, yet each call differs: told to keep no state
        GoodSpectrum.generate(self, rng).heights + 0.01 * next(self.__dict__.setdefault("calls", iter(range(99)))), 1.0)},
     "same seed gave different heights; draw all randomness from the rng argument and keep no state between calls"),
    # seeded from numpy's global state: told as the run tells it, not as a seed that varies
    ("GlobalState", {"generate": lambda self, rng: GoodSpectrum.generate(self, np.random.default_rng(np.random.randint(99)))},
     r"generate\(\) used numpy's global random state \(np.random.\* functions\)"),
    ("NaNHeights", {"generate": lambda self, rng: Profile(np.full(8, np.nan), 1.0)}, "must be finite"),
    ("TwoDimensional", {"generate": lambda self, rng: Profile(rng.random((4, 4)), 1.0)}, "must be 1-D"),
    ("IntegerHeights", {"generate": lambda self, rng: Profile(rng.integers(0, 9, 16), 1.0)}, "must be float64"),
    ("SingleHeights", {"generate": lambda self, rng: Profile(rng.standard_normal(16).astype(np.float32), 1.0)},
     r"Profile\.heights must be float64 \(double precision\). Got dtype float32"),
    ("ZeroSpacing", {"generate": lambda self, rng: Profile(rng.random(16), 0.0)}, r"spacing must be finite and > 0"),
    ("NotAProfile", {"generate": lambda self, rng: rng.random(16)}, "must return a frictionlab.Profile"),
    ("ZeroRms", {"rms_height": lambda self: 0.0}, r"rms_height\(\) must be finite and > 0"),
    ("WrongRms", {"rms_height": lambda self: 10.0}, "within a factor of 3"),
    ("ScalarPsd", {"psd": lambda self, q: 1.0}, r"psd\(q\)"),
    ("NegativePsd", {"psd": lambda self, q: -np.ones_like(q)}, r"psd\(q\) must be >= 0"),
    ("Raises", {"generate": lambda self, rng: 1 / 0}, "raised ZeroDivisionError"),
    ("BadRmsSlope", {"rms_slope": lambda self: float("nan")}, r"rms_slope\(\)"),
    ("NoAdviceWhenNotPeriodic",
     {"generate": lambda self, rng: Profile(rng.standard_normal(64), 1.0, periodic=False), "periodic": lambda self: False,
      "not_periodic_advice": lambda self: ("not periodic", "")}, r"not_periodic_advice\(\) must be a \(why, how\)"),
    ("Trended", {"generate": lambda self, rng: Profile(GoodSpectrum.generate(self, rng).heights + np.linspace(0, 3, 128), 1.0)},
     r"periodic\(\) is True, but the profile does not wrap: the step from its last point back to its first is 2\.9"),
    ("EndPointRepeated", {"generate": lambda self, rng: Profile(np.cos(2 * np.pi * np.linspace(0, 1, 128) + rng.uniform(0, 6)), 1.0)},
     r"the last point repeats the first in every one of 8 seeds: a period of N points is sampled on \[0, L\)"),
    ("TrendedSurface", {"dimension": 2, "generate": lambda self, rng: Profile(
        GoodSpectrum.generate(self, rng).heights[:, None] + np.linspace(0, 3, 64) + np.sin(np.arange(64) / 3), 1.0)},
     r"the profile does not wrap along axis 1"),
    ("PeriodicNotABool", {"periodic": lambda self: "yes"},  # named as a run names it, not as a mismatch with the profile
     r"periodic\(\) must be True or False\. Got 'yes' instead\."),
    ("CaveatsAsOneString", {"caveats": lambda self: "coarse"}, r"caveats\(\) must be a tuple of non-empty strings"),
    ("EmptyCaveat", {"caveats": lambda self: ("",)}, r"caveats\(\) must be a tuple of non-empty strings"),
]


@pytest.mark.parametrize("qualname,methods,match", SPECTRUM_BREAKAGES, ids=[b[0] for b in SPECTRUM_BREAKAGES])
def test_spectrum_check_fails_for_broken_generators(qualname, methods, match):
    cls = spectrum_variant(qualname, **methods)
    fails_naming(fltesting.check_spectrum, cls, match)


def test_a_generator_declared_deterministic_may_ignore_its_seed():
    """The kit reads ``deterministic`` where a run does, on the class: given to the check alone it
    passed a generator every run of more than one realization would refuse."""
    def fixed(self, rng):
        return GoodSpectrum.generate(self, np.random.default_rng(0))

    fltesting.check_spectrum(spectrum_variant("FixedLine", generate=fixed, deterministic=True))
    with pytest.raises(AssertionError, match="deterministic=True was given to the check, but the class does not declare"):
        fltesting.check_spectrum(spectrum_variant("Undeclared", generate=fixed), deterministic=True)
    with pytest.raises(AssertionError, match="the same seed gave different heights"):  # but not a drifting answer
        fltesting.check_spectrum(spectrum_variant(
            "Drifting", generate=lambda self, rng: GoodSpectrum.generate(self, np.random.default_rng()), deterministic=True))


def test_spectrum_check_fails_for_wrong_declarations():
    cls = spectrum_variant("SaysPeriodic", periodic=lambda self: False)
    with pytest.raises(AssertionError, match=r"Profile.periodic must be what periodic\(\) declares, False. Got True instead."):
        fltesting.check_spectrum(cls)
    cls = spectrum_variant("WrongShape", grid_shape=lambda self: (3,))
    with pytest.raises(AssertionError, match=r"grid_shape\(\) must be None or the shape"):
        fltesting.check_spectrum(cls)
    cls = spectrum_variant("LineOfALine", equivalent_line=lambda self: GoodSpectrum())
    with pytest.raises(AssertionError, match=r"equivalent_line\(\) must be None"):
        fltesting.check_spectrum(cls)
    cls = spectrum_variant("MakesNoLineButSaysItsCost", equivalent_line_bytes=lambda self: 1024)  # a line has no line
    with pytest.raises(AssertionError, match=r"equivalent_line_bytes\(\) must be None"):
        fltesting.check_spectrum(cls)
    # GoodSpectrum's lines all have rms 1: an own h that follows each line's first height differs between them
    cls = spectrum_variant("OwnHeightPerLine", profile_rms_height=lambda self, profile: 1.0 + abs(float(profile.heights[0])))
    with pytest.raises(AssertionError, match=r"profile_rms_height\(profile\) must be one h for the ensemble"):
        fltesting.check_spectrum(cls)
    cls = spectrum_variant("NegativeHurst", hurst_exponent=lambda self: -1.0)
    with pytest.raises(AssertionError, match=r"hurst_exponent\(\)"):
        fltesting.check_spectrum(cls)


def _summary(self, **changes):
    made = GoodSpectrum.generate(self, np.random.default_rng(0))
    summary = {"file": "scan.x3p", "shape": list(made.heights.shape), "spacing": made.spacing, "unit": "um",
               "rms_height": self.rms_height()}  # fmt: skip
    return {**summary, **changes}


@pytest.mark.parametrize("qualname,summary,match", [
    ("NotJson", lambda self: {**_summary(self), "shape": np.array([3])}, "JSON-ready"),
    ("NaNInSummary", lambda self: _summary(self, rms_height=float("nan")), "JSON-ready"),
    ("NoUnit", lambda self: {k: v for k, v in _summary(self).items() if k != "unit"}, "at least file, shape"),
    ("WrongSpacing", lambda self: _summary(self, spacing=123.0), "spacing"),
    ("WrongShape", lambda self: _summary(self, shape=[2, 2]), "the shape"),
])  # fmt: skip
def test_spectrum_check_fails_for_a_wrong_input_summary(qualname, summary, match):
    fails_naming(fltesting.check_spectrum, spectrum_variant(qualname, input_summary=summary), match)


def test_spectrum_check_passes_a_true_input_summary():
    fltesting.check_spectrum(spectrum_variant("TrueSummary", input_summary=_summary))


def test_a_non_periodic_spectrum_with_its_own_advice_passes_and_the_default_advice_too():
    line = {"generate": lambda self, rng: Profile(rng.standard_normal(64), 1.0, periodic=False), "periodic": lambda self: False}
    fltesting.check_spectrum(spectrum_variant("PlainScan", **line))
    own = ("spectrum scan is not periodic (closed: false)", "set spectrum.params.closed: true")
    fltesting.check_spectrum(spectrum_variant("OwnScan", **line, not_periodic_advice=lambda self: own))


def test_a_failed_check_shows_the_test_and_the_plugin_not_the_kits_frames():
    """pytest printed every frame of the kit (check_plugin, check_spectrum, fail...) above the
    message; a frame it shows must be the caller's or the plugin's."""
    import os
    import traceback

    def blows_up(self, rng):
        raise RuntimeError("my generator broke")

    for generate, cause in ((lambda self, rng: Profile(np.full(8, np.nan), 1.0), None), (blows_up, "blows_up")):
        with pytest.raises(AssertionError) as excinfo:
            fltesting.check_plugin("spectrum", spectrum_variant("Broken", generate=generate))
        kit = [frame for frame, _ in traceback.walk_tb(excinfo.value.__traceback__)
               if f"frictionlab{os.sep}testing" in frame.f_code.co_filename]
        assert kit and all(frame.f_locals.get("__tracebackhide__") for frame in kit)
        if cause:
            assert excinfo.value.__cause__.__traceback__.tb_frame.f_code.co_name == cause


def test_a_measured_profile_declared_periodic_is_not_held_to_wrapping():
    """deterministic: a file's profile is periodic as its data and its preset say (a plane levelled
    away leaves a step at the wrap); the kit checks the plugin, not the data."""
    scan = np.sin(np.arange(128) / 5) + np.linspace(0, 3, 128)
    fltesting.check_spectrum(spectrum_variant("Scan", generate=lambda self, rng: Profile(scan.copy(), 1.0),
                                              deterministic=True))


def test_deterministic_is_declared_true_or_false():
    from frictionlab.errors import PluginError
    from frictionlab.plugin.registry import validate_plugin_class

    with pytest.raises(PluginError, match=r"deterministic must be True or False\. Got 'yes' instead\."):
        validate_plugin_class("spectrum", spectrum_variant("Vague", deterministic="yes"))

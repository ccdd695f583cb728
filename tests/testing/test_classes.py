"""The class check (what every kind shares) fails for classes broken in one way each."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from pydantic import BaseModel, ConfigDict, Field

from frictionlab import (
    PluginParams,
)
from frictionlab import testing as fltesting
from frictionlab.plugin import KINDS

from .fakes import GoodSlopes, GoodSpectrum, fails_naming, spectrum_variant

ROOT = Path(__file__).resolve().parents[2]

KIND_HOOKS = {kind: base.register_hook for kind, base in KINDS.items()}


# =========================================================================== fakes


# --------------------------------------------------------- class-level failures


class _NoAssignmentParams(BaseModel):
    model_config = ConfigDict(extra="forbid")
    points: int = Field(128, ge=8, description="number of grid points")


class _UnenforcedParams(PluginParams):
    points: int = Field(128, description="number of grid points", json_schema_extra={"minimum": 8})


class _RequiredParams(PluginParams):
    points: int = Field(ge=8, description="number of grid points")
    spacing: float = Field(1.0, gt=0, description="grid spacing")


class _BadDefaultParams(PluginParams):
    points: int = Field(4, ge=8, description="number of grid points")


class _InfiniteDefaultParams(PluginParams):
    depth: float = Field(float("inf"), gt=0, description="deepest indentation")


class _InfiniteAllowedParams(PluginParams):
    depth: float = Field(1.0, gt=0, allow_inf_nan=True, description="deepest indentation")


class _NotStoring(GoodSpectrum):
    name = "not-storing"

    def __init__(self, params=None, **kwargs):
        self.params = None


CLASS_BREAKAGES = [
    ("BadName", {"name": "Bad_Name"}, "name must be kebab-case"),
    ("NoSummary", {"summary": " "}, "summary must be one non-empty line"),
    ("LooseParams", {"Params": type("P", (BaseModel,), {"__annotations__": {"x": int}, "x": Field(1, description="x")})},
     "must forbid unknown keys"),
    ("Undescribed", {"Params": type("P", (PluginParams,), {"__annotations__": {"x": int}, "x": 1})}, "no description"),
    ("StringReferences", {"references": "10.1000/xyz"}, "references must be a tuple of strings"),
    ("NoAssignmentCheck", {"Params": _NoAssignmentParams}, "validate on assignment"),
    ("UnenforcedBound", {"Params": _UnenforcedParams}, r"Params.points = 7 \(past its minimum 8\) was accepted"),
    ("RequiredField", {"Params": _RequiredParams},
     r"Params.points has no default: pass the check a value \(check_plugin\(.spectrum., cls, points=...\)\), or give "),
    ("DefaultOutOfBounds", {"Params": _BadDefaultParams},
     r"Params.points defaults to 4, which its own bounds refuse \(Input should be greater than or equal to 8\)"),
    ("InfiniteDefault", {"Params": _InfiniteDefaultParams},
     r"Params.depth defaults to inf: a parameter must be a finite number \(results are JSON"),
    ("InfiniteAllowed", {"Params": _InfiniteAllowedParams},
     r"Params.depth allows infinity and NaN \(allow_inf_nan=True\): a parameter must be a finite number"),
    ("BuiltinsName", {"name": "power-law"}, r"name 'power-law' is taken by the built-in spectrum "
                                             r"frictionlab_spectra\.power_law\.PowerLaw: .*choose another name"),
]


@pytest.mark.parametrize("qualname,attrs,match", CLASS_BREAKAGES, ids=[b[0] for b in CLASS_BREAKAGES])
def test_class_check_fails_for_broken_classes(qualname, attrs, match):
    cls = type(qualname, (GoodSpectrum,), dict(attrs))
    fails_naming(lambda c: fltesting.check_plugin_class("spectrum", c), cls, match)


def test_class_check_uses_given_params():
    cls = type("NeedsPoints", (GoodSpectrum,), {"Params": _RequiredParams})
    fltesting.check_plugin_class("spectrum", cls, params={"points": 64})
    fltesting.check_plugin("spectrum", cls, points=64)


def test_class_check_fails_when_constructor_drops_params():
    with pytest.raises(AssertionError, match="self.params"):
        fltesting.check_plugin_class("spectrum", _NotStoring)


def test_class_check_rejects_unknown_kind():
    with pytest.raises(ValueError, match="kind must be one of"):
        fltesting.check_plugin_class("surface", GoodSpectrum)


def test_class_check_skips_bounds_when_none():
    fltesting.check_plugin_class("slope", GoodSlopes)  # no fields at all


def test_check_plugin_runs_the_kind_check():
    cls = spectrum_variant("IgnoresSeedAgain", generate=lambda self, rng: GoodSpectrum.generate(self, np.random.default_rng(0)))
    fltesting.check_plugin_class("spectrum", cls)
    with pytest.raises(AssertionError, match="different seeds"):
        fltesting.check_plugin("spectrum", cls)

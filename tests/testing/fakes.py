"""Plugins for the conformance kit's own tests: good ones, and variants each broken in one way."""

from __future__ import annotations

import types

import numpy as np
import pytest
from pydantic import Field

from frictionlab import (
    ContactCurve,
    ContactSolver,
    ForceNormalisation,
    PluginParams,
    Profile,
    SlopeEstimator,
    SpectrumGenerator,
    hookimpl,
)
from frictionlab import testing as fltesting
from frictionlab.plugin import KINDS

KIND_HOOKS = {kind: base.register_hook for kind, base in KINDS.items()}


class GoodSpectrum(SpectrumGenerator):
    name = "good-spectrum"
    summary = "Smooth random line for conformance tests"

    class Params(PluginParams):
        points: int = Field(128, ge=8, le=1 << 20, description="number of grid points")
        spacing: float = Field(1.0, gt=0, description="grid spacing")

    def generate(self, rng):
        n = self.params.points
        spectrum = np.zeros(n // 2 + 1, complex)
        spectrum[1:4] = np.exp(2j * np.pi * rng.random(3)) * n / 2
        z = np.fft.irfft(spectrum, n=n)
        return Profile(heights=z * (1 / np.sqrt(1.5)), spacing=self.params.spacing)

    def rms_height(self):
        return 1.0

    def psd(self, q):
        return np.exp(-np.asarray(q, float))


class GoodSolver(ContactSolver):
    """Springs of stiffness k dx, solved exactly (sort + cumulative sums)."""

    name = "good-solver"
    summary = "Exact spring row for conformance tests"
    normalisations = {1: ForceNormalisation(load="force", modulus="k", extent="length")}
    problem = "Winkler foundation"

    class Params(PluginParams):
        modulus: float = Field(2.0, gt=0, le=1e12, description="spring modulus k")

    def stiffness(self):
        return self.params.modulus

    def solve(self, profile, loads, control, slopes):
        z, dx, k = profile.heights, profile.spacing, self.params.modulus
        top = np.sort(z)[::-1]
        n = top.size
        levels = []
        for load in loads:
            if control == "indentation":
                levels.append(top[0] - load)
                continue
            cum = np.cumsum(top)
            for m in range(1, n + 1):
                c = (cum[m - 1] - load / (k * dx)) / m
                if m == n or c >= top[m]:
                    levels.append(c)
                    break
        levels = np.array(levels)
        inside = z[None, :] > levels[:, None]
        count = inside.sum(axis=1)
        force = k * dx * np.maximum(z[None, :] - levels[:, None], 0).sum(axis=1)
        rms = np.sqrt((inside * slopes[None, :] ** 2).sum(axis=1) / np.maximum(count, 1))
        return ContactCurve(
            force=force,
            indentation=top[0] - levels,
            contact_count=count,
            contact_fraction=count / n,
            slope_rms_contact=rms,
            extras={"levels": levels},
        )


class GoodSlopes(SlopeEstimator):
    name = "good-slopes"
    summary = "Periodic forward differences for conformance tests"

    class Params(PluginParams):
        pass

    def slopes(self, heights, spacing, periodic=True):
        return forward_differences(heights, spacing, periodic)


def replace_curve(curve, **changes):
    fields = {name: getattr(curve, name) for name in ContactCurve.__dataclass_fields__}
    fields.update(changes)
    return ContactCurve(**fields)


def spectrum_variant(qualname, **methods):
    return type(qualname, (GoodSpectrum,), {"name": "broken-spectrum", **methods})


def solver_variant(qualname, change):
    def solve(self, profile, loads, control, slopes):
        return change(GoodSolver.solve(self, profile, loads, control, slopes), profile, loads)

    return type(qualname, (GoodSolver,), {"name": "broken-solver", "solve": solve})


def slopes_variant(qualname, slopes):
    return type(qualname, (GoodSlopes,), {"name": "broken-slopes", "slopes": slopes})


@pytest.mark.parametrize(
    "kind,cls", [("spectrum", GoodSpectrum), ("solver", GoodSolver), ("slope", GoodSlopes)]
)
def test_good_fakes_pass(kind, cls):
    fltesting.check_plugin(kind, cls)


def spectrum_class(name="fake-line", module="acme_one.lines", qualname="FakeLine"):
    class FakeLine(SpectrumGenerator):
        summary = "White-noise line for registry tests"

        class Params(PluginParams):
            points: int = Field(32, ge=8, le=4096, description="number of grid points")

        def generate(self, rng):
            return Profile(heights=rng.standard_normal(self.params.points), spacing=1.0)

        def rms_height(self):
            return 1.0

    FakeLine.name = name
    FakeLine.__module__ = module
    FakeLine.__qualname__ = qualname
    return FakeLine


def provider(*classes, hook_name=None):
    """A hook holder (what an entry point points at) registering ``classes``."""
    holder = types.SimpleNamespace()
    by_hook: dict[str, list] = {}
    for cls in classes:
        by_hook.setdefault(hook_name or KIND_HOOKS[cls.kind], []).append(cls)
    for hook, members in by_hook.items():
        # pluggy reads the argument names: the implementation takes just ``register``
        def make(ms):
            def register_all(register):
                for cls in ms:
                    register(cls)

            return register_all

        setattr(holder, hook, hookimpl(make(tuple(members))))
    return holder


def forward_differences(heights, spacing, periodic=True):
    out = (np.roll(heights, -1) - heights) / spacing
    if not periodic:
        out[-1] = out[-2]
    return out


def fails_naming(check, cls, match: str) -> None:
    """``check(cls)`` fails with a message that matches ``match`` and names the class."""
    with pytest.raises(AssertionError, match=match) as excinfo:
        check(cls)
    assert cls.__qualname__ in str(excinfo.value)

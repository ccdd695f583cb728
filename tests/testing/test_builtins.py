"""Every built-in plugin passes the conformance kit."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from frictionlab import testing as fltesting
from frictionlab.plugin import KINDS
from frictionlab.plugin.registry import Registry

ROOT = Path(__file__).resolve().parents[2]

KIND_HOOKS = {kind: base.register_hook for kind, base in KINDS.items()}


# =========================================================================== fakes


# ================================================ conformance: built-ins pass


def _builtin_cases():
    cases = []
    extra = {
        ("spectrum", "power-law"): [{"hurst": 0.8, "points": 256}, {"hurst": 0.3, "points": 255, "amplitudes": "rayleigh"},
                                    {"hurst": 1.0, "points": 256, "series": "cosine", "height_reference": "measured"}],
        ("slope", "forward-difference"): [{}, {"line_end": "undefined"}],
        ("slope", "central-difference"): [{}, {"line_end": "undefined"}],
        ("spectrum", "rolloff"): [{"hurst": 1.0, "points": 256, "rolloff_wavelength": 64.0}],
        ("spectrum", "profile-file"): [{"path": "<profile>", "spacing": 0.5}],
        ("spectrum", "surface-file"): [{"path": "<surface>", "spacing": 0.5}],
        ("spectrum", "power-law-2d"): [{"hurst": 0.8, "points": 32}, {"hurst": 0.3, "points": 31, "points_y": 40}],
        ("spectrum", "rolloff-2d"): [{"hurst": 1.0, "points": 48, "rolloff_wavelength": 16.0, "amplitudes": "rayleigh"}],
    }
    for info in Registry(discover=False).infos():
        for i, params in enumerate(extra.get((info.kind, info.name), [{}])):
            cases.append(pytest.param(info.kind, info.cls, params, id=f"{info.kind}:{info.name}:{i}"))
    return cases


@pytest.mark.parametrize("kind,cls,params", _builtin_cases())
def test_builtins_pass_the_conformance_checks(kind, cls, params, tmp_path):
    params = dict(params)
    deterministic = False
    if params.get("path") == "<profile>":
        path = tmp_path / "profile.txt"
        np.savetxt(path, np.random.default_rng(3).standard_normal(200).cumsum())
        params["path"] = str(path)
        deterministic = True
    if params.get("path") == "<surface>":
        params["path"] = str(tmp_path / "surface.npy")
        np.save(params["path"], np.random.default_rng(3).standard_normal((16, 24)).cumsum(axis=1))
        deterministic = True
    fltesting.check_plugin(kind, cls, deterministic=deterministic, **params)

"""Three exact scaling laws, each on its own, for every built-in solver and slope estimator.

At the same dimensionless force f the contact set, and so xi, must not move when

* every height is multiplied by c (rms_height x c): the force at the same f is x c;
* the modulus alone is multiplied by m: the force is x m;
* the length unit alone changes (points fixed, spacing, cut-offs and heights x s, moduli
  fixed): the force is x s^2 for a force (h L, or h A for springs on a surface, whose
  foundation modulus is then taken per unit length, x 1/s), x s for a force per unit depth
  (the half-plane: h).

tests/test_units.py changes lengths and moduli together; here each law is alone, so an
error in one cannot be hidden by another. The force factors are written from the physics,
independently of the code; f is checked to come out the same, xi within rounding (springs)
or the CG's tolerance (boundary elements).
"""

from __future__ import annotations

import numpy as np
import pytest

import frictionlab

LINE = {"name": "power-law", "params": {"hurst": 0.7, "points": 256, "spacing": 0.5, "rms_height": 0.2}}
SURFACE = {"name": "power-law-2d",
           "params": {"hurst": 0.7, "points": 32, "spacing": 0.5, "rms_height": 0.2, "short_cutoff": 2.0}}  # fmt: skip
# solver -> (spectrum, forces at partial contact, the load is a force per unit depth)
SOLVERS = {
    "mdr": (LINE, (0.05, 2.0), False),
    "mdr-bisection": (LINE, (0.05, 2.0), False),
    "winkler": (SURFACE, (0.05, 2.0), False),
    "bem-halfplane": (LINE, (0.005, 0.05), True),
    "bem-halfspace": (SURFACE, (0.05, 0.5), False),
    "bem-halfspace-free": (SURFACE, (0.05, 0.5), False),
}
SLOPES = ("forward-difference", "central-difference", "spectral")
LAWS = ("heights", "modulus", "length")
FACTOR = 7.3  # c, m or s: not a power of two, so rounding is exercised


def lengths_scaled(params: dict, factor: float) -> dict:
    """A spectrum's parameters with every length (spacing, heights, cut-off) times ``factor``:
    the same surface in another unit of length."""
    return {k: v * factor if k in ("spacing", "rms_height", "short_cutoff") else v for k, v in params.items()}


def _preset(solver: str, slope: str, law: str | None) -> dict:
    spectrum, (start, stop), per_depth = SOLVERS[solver]
    params = dict(spectrum["params"])
    modulus_key = "modulus" if solver == "winkler" else "youngs_modulus"
    solver_params = {modulus_key: 1.3}
    if solver.startswith("bem"):
        solver_params["tolerance"] = 1e-10
    load = 1.0
    if law == "heights":
        params["rms_height"] *= FACTOR
        load = FACTOR
    elif law == "modulus":
        solver_params[modulus_key] *= FACTOR
        load = FACTOR
    elif law == "length":
        params = lengths_scaled(params, FACTOR)
        load = FACTOR if per_depth else FACTOR**2
        if solver == "winkler":  # a foundation modulus on a surface is a stress per unit length
            solver_params[modulus_key] /= FACTOR
    return {
        "name": f"scaling-{solver}",
        "seed": 7,
        "realizations": 2,
        "spectrum": {"name": spectrum["name"], "params": params},
        "solver": {"name": solver, "params": solver_params},
        "slope": {"name": slope},
        "loading": {"control": "force", "start": start * load, "stop": stop * load, "steps": 4, "spacing": "log"},
        "fit": {"bootstrap": 0},
        "output": {"plot": False},
    }


@pytest.mark.parametrize("law", LAWS)
@pytest.mark.parametrize("slope", SLOPES)
@pytest.mark.parametrize("solver", SOLVERS)
def test_xi_at_equal_f_obeys_each_scaling_law(solver, slope, law, tmp_path):
    base = frictionlab.run(_preset(solver, slope, None), out=tmp_path / "base", plot=False, progress=False)
    scaled = frictionlab.run(_preset(solver, slope, law), out=tmp_path / "scaled", plot=False, progress=False)
    assert base.status == scaled.status == "completed"
    fraction = base.table["contact_fraction"]
    assert base.table["contact_count"].min() >= 1 and fraction.max() < 1, "the test needs partial contact"
    np.testing.assert_allclose(scaled.table["f"], base.table["f"], rtol=1e-12)
    np.testing.assert_array_equal(scaled.table["contact_count"], base.table["contact_count"])
    rtol = 1e-7 if solver.startswith("bem") else 1e-11
    np.testing.assert_allclose(scaled.table["xi"], base.table["xi"], rtol=rtol)
    np.testing.assert_allclose(scaled.table["indentation"], base.table["indentation"]
                               * (FACTOR if law in ("heights", "length") else 1.0), rtol=rtol)  # fmt: skip

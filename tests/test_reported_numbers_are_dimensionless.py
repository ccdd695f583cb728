"""The numbers frictionlab reports as dimensionless (f, xi, and the fit's a, b and their
bootstrap intervals) are the same whether lengths are in metres or nanometres.

Going from m to nm multiplies every length (spacing, rms height, cut-offs) by S = 1e9
and divides every stress (E) by S^2, so a force (stress x area) is unchanged and a
force per unit depth is divided by S. Every built-in slope estimator is covered, with
the line solvers and the two periodic boundary-element ones, through ``frictionlab.run``.
The fit's bootstrap draws from the preset's seed, so its intervals must agree too.
"""

from __future__ import annotations

import numpy as np
import pytest

import frictionlab

from .test_scaling_laws import lengths_scaled

S = 1e9  # m -> nm
SLOPES = ("forward-difference", "central-difference", "spectral")
# solver -> (spectrum params in metres, E in Pa, load unit factor m -> nm, forces in N)
CASES = {
    "mdr": ({"name": "power-law", "params": {"hurst": 0.7, "points": 512, "spacing": 2e-9, "rms_height": 1e-9}},
            1, (2e-10, 2e-8)),
    "mdr-bisection": ({"name": "power-law", "params": {"hurst": 0.7, "points": 256, "spacing": 2e-9,
                                                       "rms_height": 1e-9}}, 1, (2e-10, 2e-8)),
    "bem-halfplane": ({"name": "power-law", "params": {"hurst": 0.7, "points": 256, "spacing": 2e-9,
                                                       "rms_height": 1e-9}}, 1 / S, (2e-3, 5e-2)),
    "bem-halfspace": ({"name": "power-law-2d", "params": {"hurst": 0.7, "points": 32, "spacing": 2e-9,
                                                          "rms_height": 1e-9, "short_cutoff": 8e-9}},
                      1, (4e-10, 4e-9)),
}  # fmt: skip
E = 1e9  # Pa: keeps loads and moduli well inside a preset's ranges in both unit systems


def _preset(solver: str, slope: str, nm: bool) -> dict:
    spectrum, load_factor, (start, stop) = CASES[solver]
    params = dict(spectrum["params"])
    if nm:
        params = lengths_scaled(params, S)
    solver_params = {"youngs_modulus": E / S**2 if nm else E, "poisson_ratio": 0.3}
    if solver.startswith("bem"):
        solver_params["tolerance"] = 1e-10
    factor = load_factor if nm else 1.0
    return {
        "name": f"units-{solver}-{slope}",
        "seed": 3,
        "realizations": 4,
        "spectrum": {"name": spectrum["name"], "params": params},
        "solver": {"name": solver, "params": solver_params},
        "slope": {"name": slope},
        "loading": {"control": "force", "start": start * factor, "stop": stop * factor, "steps": 5, "spacing": "log"},
        "fit": {"bootstrap": 200},
        "output": {"plot": False},
    }


@pytest.mark.parametrize("slope", SLOPES)
@pytest.mark.parametrize("solver", CASES)
def test_f_xi_a_b_and_their_intervals_are_the_same_in_nm_as_in_m(solver, slope, tmp_path):
    metres = frictionlab.run(_preset(solver, slope, False), out=tmp_path / "m", plot=False, progress=False)
    nanometres = frictionlab.run(_preset(solver, slope, True), out=tmp_path / "nm", plot=False, progress=False)
    assert metres.status == nanometres.status == "completed"
    counts = metres.table["contact_count"]
    assert counts.min() >= 1 and metres.table["contact_fraction"].max() < 1, "the test needs partial contact"
    rtol = 1e-7 if solver.startswith("bem") else 1e-9  # the CG's tolerance; springs: rounding
    np.testing.assert_allclose(nanometres.table["f"], metres.table["f"], rtol=1e-12)
    np.testing.assert_array_equal(nanometres.table["contact_count"], counts)
    np.testing.assert_allclose(nanometres.table["xi"], metres.table["xi"], rtol=rtol)
    one, other = metres.fit, nanometres.fit
    for name in ("a", "b", "a_se", "b_se", "a_se_bootstrap", "b_se_bootstrap"):
        assert not np.isnan(getattr(one, name)) and getattr(other, name) == pytest.approx(getattr(one, name), rel=rtol, abs=1e-12), name
    for name in ("a_ci", "b_ci"):
        assert not np.isnan(getattr(one, name)).any()
        np.testing.assert_allclose(getattr(other, name), getattr(one, name), rtol=rtol, atol=1e-12, err_msg=name)

"""Unit invariance: a quantity called dimensionless must not change with the units.

Every solver x every spectrum kind it accepts (lines and surfaces, synthetic and
measured). Multiply every length by S and every modulus (stress) by M; a load
then scales by what its unit is: a force by M S^2, a force per unit depth by
M S, an indentation by S. A Winkler foundation modulus is a stress on a line
(N/m^2: x M) and a stress per unit length on a surface (N/m^3: x M / S).
f, xi and the contact set must not move.

The expected f of each solver is written here from its physics, independently of
the code: MDR F / (E* h L); Winkler on a line F / (k h L), on a surface
F / (k h A); half-plane F' / (E* h); half-space F / (E* h L), L = 2 sqrt(A / pi).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from frictionlab.compute import engine
from frictionlab.preset import build_scene
from frictionlab.preset.seeds import realization_rng
from frictionlab.options import RunOptions

S = 1000.0  # every length
M = 7.0  # every modulus

LINE_SPECTRA = ("power-law", "rolloff", "profile-file")
COSINE = "power-law cosine series"  # the non-periodic series of power-law (series: cosine)
SURFACE_SPECTRA = ("power-law-2d", "rolloff-2d", "surface-file")
# solver -> the spectra it takes (a line solver takes a surface as its MDR-equivalent line;
# the periodic BEM takes the scans declared periodic, not the cosine series)
PAIRS = {
    "mdr": LINE_SPECTRA + (COSINE,) + SURFACE_SPECTRA,
    "mdr-bisection": LINE_SPECTRA + (COSINE,) + SURFACE_SPECTRA,
    "winkler": LINE_SPECTRA + (COSINE,) + SURFACE_SPECTRA,
    "bem-halfplane": LINE_SPECTRA,
    "bem-halfspace": SURFACE_SPECTRA,
    "bem-halfspace-free": SURFACE_SPECTRA,
}
CASES = [(solver, spectrum) for solver, spectra in PAIRS.items() for spectrum in spectra]
PERIODIC_BEM = {"bem-halfplane", "bem-halfspace"}
BEM = PERIODIC_BEM | {"bem-halfspace-free"}

LINE = {"hurst": 0.7, "points": 256, "rms_height": 0.2}
SURFACE = {"hurst": 0.7, "points": 32, "rms_height": 0.2}
SPACING = 0.5


def test_every_builtin_solver_and_spectrum_is_covered(registry):
    covered_spectra = set(LINE_SPECTRA + SURFACE_SPECTRA)
    assert set(registry.names("spectrum")) <= covered_spectra, "a spectrum without a unit-invariance test"
    assert set(registry.names("solver")) <= set(PAIRS), "a solver without a unit-invariance test"


# ------------------------------------------------------------------ scenes


def _write_scan(path, heights):
    np.save(path, heights)
    return str(path)


def spectrum_choice(name: str, tmp_path, length: float = 1.0, tag: str = "", periodic: bool = False) -> dict:
    """The spectrum ``name`` with every length multiplied by ``length`` (a scan declared
    ``periodic`` for the solvers of periodic profiles)."""
    dx = SPACING * length
    if name == COSINE:
        return {"name": "power-law", "params": {**LINE, "rms_height": LINE["rms_height"] * length, "spacing": dx,
                                                "series": "cosine", "short_cutoff": 20 * dx}}  # fmt: skip
    if name in ("power-law", "rolloff"):
        params = {**LINE, "rms_height": LINE["rms_height"] * length, "spacing": dx}
        if name == "rolloff":
            params["rolloff_wavelength"] = 32.0 * length
        return {"name": name, "params": params}
    if name in ("power-law-2d", "rolloff-2d"):
        params = {**SURFACE, "rms_height": SURFACE["rms_height"] * length, "spacing": dx, "short_cutoff": 2.0 * length}
        if name == "rolloff-2d":
            params["rolloff_wavelength"] = 8.0 * length
        return {"name": name, "params": params}
    if name == "profile-file":
        base = build_scene(_preset({"name": "power-law", "params": {**LINE, "spacing": SPACING}}, "mdr"))
        z = base.spectrum.generate(realization_rng(5, 0)).heights
        path = _write_scan(tmp_path / f"scan{tag}.npy", z * length)
        return {"name": name, "params": {"path": path, "spacing": dx, "periodic": periodic}}
    if name == "surface-file":
        base = build_scene(
            _preset({"name": "power-law-2d", "params": {**SURFACE, "spacing": SPACING, "short_cutoff": 2.0}}, "winkler")
        )
        z = base.spectrum.generate(realization_rng(5, 0)).heights
        path = _write_scan(tmp_path / f"map{tag}.npy", z * length)
        return {"name": name, "params": {"path": path, "spacing": dx, "periodic": periodic}}
    raise AssertionError(f"no unit test for spectrum {name!r}")


def solver_choice(name: str, surface: bool, modulus: float = 1.0, length: float = 1.0) -> dict:
    """The solver ``name`` with every modulus x ``modulus`` (lengths x ``length``: a
    Winkler modulus per unit area is a stress per length)."""
    if name == "winkler":
        k = 2.5 * modulus / (length if surface else 1.0)
        return {"name": name, "params": {"modulus": k}}
    params = {"youngs_modulus": 1.3 * modulus, "poisson_ratio": 0.3}
    if name in BEM:
        params["tolerance"] = 1e-10
    return {"name": name, "params": params}


def _preset(spectrum: dict, solver: str | dict, loading: dict | None = None) -> dict:
    return {
        "name": "units",
        "seed": 11,
        "realizations": 2,
        "spectrum": spectrum,
        "solver": solver if isinstance(solver, dict) else {"name": solver},
        "slope": {"name": "forward-difference"},
        "loading": loading or {"control": "force", "start": 1.0, "stop": 2.0, "steps": 2},
        "fit": {"bootstrap": 0},
        "output": {"plot": False},
    }


def expected_force_unit(solver: str, scene) -> float:
    """k h X of f = F / (k h X), from the solver's physics (see the module docstring)."""
    profile = scene.generator.generate(realization_rng(scene.preset.seed, 0))
    h = scene.generator.rms_height()
    k = scene.solver.stiffness()
    area = profile.heights.size * profile.spacing**profile.heights.ndim
    if solver == "bem-halfplane":
        return k * h  # F' / (E* h)
    if solver == "winkler" and profile.heights.ndim == 2:
        return k * h * area  # F / (k h A)
    if profile.heights.ndim == 2:  # the half-space, and MDR on a surface
        return k * h * 2.0 * math.sqrt(area / math.pi)
    if scene.equivalent_line is not None:  # MDR's line of a surface: L = 2 sqrt(A / pi) of the surface
        surface = scene.spectrum.generate(realization_rng(scene.preset.seed, 0))
        return k * h * 2.0 * math.sqrt(surface.heights.size * surface.spacing**2 / math.pi)
    return k * h * profile.heights.size * profile.spacing  # F / (k h L)


F_GRID = {  # dimensionless forces with partial contact for every spectrum of the solver
    "mdr": (0.002, 0.01, 0.05),
    "mdr-bisection": (0.002, 0.01, 0.05),
    "winkler": (0.002, 0.01, 0.05),
    "bem-halfplane": (0.005, 0.02, 0.08),
    "bem-halfspace": (0.005, 0.02, 0.08),
    "bem-halfspace-free": (0.005, 0.02, 0.08),
}


def run(preset: dict):
    scene = build_scene(preset)
    return scene, engine.run(scene, RunOptions(workers=1))


def scene_pair(solver: str, spectrum: str, tmp_path, control: str):
    """(base outcome, scaled outcome, base scene, f asked for)."""
    surface, periodic = spectrum in SURFACE_SPECTRA, solver in PERIODIC_BEM
    base = build_scene(_preset(spectrum_choice(spectrum, tmp_path, periodic=periodic), solver_choice(solver, surface)))
    unit = expected_force_unit(solver, base)
    f = np.array(F_GRID[solver])
    if control == "force":
        loads = f * unit
    else:
        loads = np.array([0.2, 0.6, 1.2]) * base.spectrum.rms_height()
    load_scale = S if control == "indentation" else (M * S if solver == "bem-halfplane" else M * S * S)
    loading = {"control": control, "start": float(loads[0]), "stop": float(loads[-1]), "steps": 3, "spacing": "log"}
    # three log-spaced loads reproduce the grid exactly up to rounding
    scaled_loading = {**loading, "start": loading["start"] * load_scale, "stop": loading["stop"] * load_scale}
    base_scene, base_out = run(
        _preset(spectrum_choice(spectrum, tmp_path, periodic=periodic), solver_choice(solver, surface), loading)
    )
    _, scaled_out = run(
        _preset(
            spectrum_choice(spectrum, tmp_path, length=S, tag="-scaled", periodic=periodic),
            solver_choice(solver, surface, modulus=M, length=S),
            scaled_loading,
        )
    )
    return base_out, scaled_out, base_scene, f


def _tolerance(solver: str) -> float:
    return 1e-7 if solver in BEM else 1e-9


@pytest.mark.parametrize("control", ["force", "indentation"])
@pytest.mark.parametrize("solver,spectrum", CASES, ids=[f"{a}-{b}" for a, b in CASES])
def test_f_xi_and_contact_do_not_depend_on_the_units(solver, spectrum, control, tmp_path):
    base, scaled, scene, f = scene_pair(solver, spectrum, tmp_path, control)
    assert not base.failures and not scaled.failures, (base.failures, scaled.failures)
    counts = base.per_realization["contact_count"]
    points = scene.spectrum.generate(realization_rng(scene.preset.seed, 0)).heights.size
    assert counts.min() >= 1 and counts.max() < points, "the test needs partial contact"
    rtol = _tolerance(solver)
    if control == "force":  # the f asked for, from the solver's physics
        np.testing.assert_allclose(base.f, f, rtol=1e-9)
    np.testing.assert_allclose(scaled.f, base.f, rtol=rtol)
    np.testing.assert_array_equal(scaled.per_realization["contact_count"], counts)
    np.testing.assert_allclose(scaled.per_realization["xi"], base.per_realization["xi"], rtol=rtol)
    if solver in ("bem-halfspace", "bem-halfspace-free"):  # g_r a slope, kappa and kappa_r pure numbers
        for name in ("real_gradient_rms", "kappa", "kappa_r"):
            np.testing.assert_allclose(getattr(scaled, name), getattr(base, name), rtol=rtol)


SPACING_CASES = [(s, p) for s, p in CASES if p in ("power-law", "power-law-2d")]


@pytest.mark.parametrize("solver,spectrum", SPACING_CASES, ids=[f"{a}-{b}" for a, b in SPACING_CASES])
def test_only_the_spacing_changed_at_equal_f_gives_equal_results(solver, spectrum, tmp_path):
    """Same H, N, cut-offs in units of dx, same h and moduli, spacing x 10: at equal f
    the contact sets and xi are those of the original grid."""
    surface = spectrum in SURFACE_SPECTRA
    outcomes = []
    for factor in (1.0, 10.0):
        choice = spectrum_choice(spectrum, tmp_path)
        params = choice["params"]
        params["spacing"] *= factor
        if "short_cutoff" in params:
            params["short_cutoff"] *= factor
        scene = build_scene(_preset(choice, solver_choice(solver, surface)))
        f = np.array(F_GRID[solver])
        loads = f * expected_force_unit(solver, scene)
        loading = {"control": "force", "start": float(loads[0]), "stop": float(loads[-1]), "steps": 3, "spacing": "log"}
        _, outcome = run(_preset(choice, solver_choice(solver, surface), loading))
        np.testing.assert_allclose(outcome.f, f, rtol=1e-9)
        outcomes.append(outcome)
    first, second = outcomes
    np.testing.assert_array_equal(second.per_realization["contact_count"], first.per_realization["contact_count"])
    np.testing.assert_allclose(second.per_realization["xi"], first.per_realization["xi"], rtol=_tolerance(solver))

"""g_r, the rms gradient over the real contact, and kappa_r = (A / A0) E* g_r / p.

Known answers:

* the weights of the contact pixels (1 - c m, m a pixel's free neighbours along its row
  and column) sum to the corrected area N - c M exactly, on periodic maps and on scans
  (whose border is no edge), checked against a pixel-by-pixel count;
* g_r on a small map equals the brute-force weighted rms; with c = 0 it is the plain rms
  over the contact pixels, so g_r / g is xi exactly;
* unit invariance: every length times s (heights, spacing), the force times s^2: the
  contact set, g_r, kappa and kappa_r are unchanged (tests/test_units.py runs it end to end);
* kappa in curve.csv is the per-realization (A / A0) E* g / p averaged, with A0 the surface's
  side squared.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from frictionlab import Profile
from frictionlab_solvers import BEMHalfSpace, contact_area
from frictionlab_solvers.bem_free import BEMHalfSpaceFree
from frictionlab_solvers.contact_area import (
    PERIMETER_COEFFICIENT,
    contact_weights,
    corrected_area_fraction,
    corrected_gradient_rms,
)

from .test_contact_area import resumed_and_whole  # the run cancelled after its first realization, as there


def brute_weights(contact: np.ndarray, periodic: bool) -> np.ndarray:
    ny, nx = contact.shape
    out = np.zeros(contact.shape)
    for i in range(ny):
        for j in range(nx):
            if not contact[i, j]:
                continue
            free = 0
            for di, dj in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                a, b = i + di, j + dj
                if not periodic and not (0 <= a < ny and 0 <= b < nx):
                    continue
                free += not contact[a % ny, b % nx]
            out[i, j] = 1 - PERIMETER_COEFFICIENT * free
    return out


@pytest.mark.parametrize("periodic", [True, False])
@pytest.mark.parametrize("seed", range(4))
def test_the_weights_are_a_pixel_count_and_sum_to_the_corrected_area(periodic, seed):
    rng = np.random.default_rng(seed)
    contact = rng.random((7, 9)) < 0.4
    weights = contact_weights(contact, periodic=periodic)
    np.testing.assert_allclose(weights, brute_weights(contact, periodic), rtol=0, atol=1e-15)
    if periodic:
        np.testing.assert_allclose(weights.sum() / contact.size, corrected_area_fraction(contact), rtol=1e-14)
    slopes = rng.random(contact.shape) * 3
    expected = math.sqrt(np.sum(brute_weights(contact, periodic) * slopes**2) / brute_weights(contact, periodic).sum())
    assert corrected_gradient_rms(contact, slopes, periodic=periodic) == pytest.approx(expected, rel=1e-13)


def test_a_scans_border_is_no_edge_and_full_contact_weighs_every_pixel_whole():
    full = np.ones((4, 5), bool)
    np.testing.assert_array_equal(contact_weights(full, periodic=False), 1.0)
    np.testing.assert_array_equal(contact_weights(full, periodic=True), 1.0)
    column = np.zeros((4, 5), bool)
    column[:, 0] = True  # a column on the scan's left border: its only free neighbours are on the right
    np.testing.assert_allclose(contact_weights(column, periodic=False)[:, 0], 1 - PERIMETER_COEFFICIENT)
    np.testing.assert_allclose(contact_weights(column, periodic=True)[:, 0], 1 - 2 * PERIMETER_COEFFICIENT)
    assert math.isnan(corrected_gradient_rms(np.zeros((3, 3), bool), np.ones((3, 3))))


def _surface(points=48, seed=1):
    rng = np.random.default_rng(seed)
    y, x = np.meshgrid(np.arange(points), np.arange(points), indexing="ij")
    z = sum(rng.normal() * np.cos(2 * np.pi * (kx * x + ky * y) / points + rng.uniform(0, 2 * np.pi))
            for kx, ky in ((1, 0), (0, 1), (1, 1), (2, 1), (1, 3), (3, 2)))  # fmt: skip
    gy, gx = np.roll(z, -1, 0) - z, np.roll(z, -1, 1) - z
    return z, np.hypot(gx, gy)


@pytest.mark.parametrize("solver", [BEMHalfSpace, BEMHalfSpaceFree], ids=["periodic", "free"])
def test_uncorrected_g_r_over_g_is_xi_exactly(solver, monkeypatch):
    z, slopes = _surface()
    loads = np.array([20.0, 80.0, 300.0])
    monkeypatch.setattr(contact_area, "PERIMETER_COEFFICIENT", 0.0)
    curve = solver(tolerance=1e-10).solve(Profile(z, 1.0), loads, "force", slopes)
    assert np.all(curve.contact_fraction < 1) and np.all(curve.contact_count > 0)
    np.testing.assert_allclose(curve.real_gradient_rms, curve.slope_rms_contact, rtol=1e-13)


@pytest.mark.parametrize("solver", [BEMHalfSpace, BEMHalfSpaceFree], ids=["periodic", "free"])
def test_corrected_g_r_is_the_weighted_rms_over_the_contact_set_and_unit_invariant(solver, monkeypatch):
    from frictionlab_solvers import contact_record

    z, slopes = _surface()
    loads = np.array([20.0, 80.0, 300.0])
    seen = []

    def spy(contact, values, *, periodic=True):  # the solver's own contact maps, checked by brute force below
        seen.append((contact.copy(), periodic))
        return corrected_gradient_rms(contact, values, periodic=periodic)

    monkeypatch.setattr(contact_record, "corrected_gradient_rms", spy)  # where both solvers measure it
    curve = solver(tolerance=1e-10).solve(Profile(z, 1.0), loads, "force", slopes)
    assert len(seen) == loads.size
    for j, (contact, periodic) in enumerate(seen):
        assert periodic == (solver is BEMHalfSpace)  # a scan's border is no edge
        assert int(contact.sum()) == curve.contact_count[j]
        w = brute_weights(contact, periodic)
        assert curve.real_gradient_rms[j] == pytest.approx(math.sqrt(np.sum(w * slopes**2) / w.sum()), rel=1e-12)
    # the correction takes weight off the edge pixels: g_r is not the plain rms over the pixels
    assert np.all(np.abs(curve.real_gradient_rms / curve.slope_rms_contact - 1) > 1e-6)
    s = 7.5  # every length x s (heights, spacing; slopes unchanged), a force x s^2 at fixed E*
    scaled = solver(tolerance=1e-10).solve(Profile(z * s, s), loads * s * s, "force", slopes)
    np.testing.assert_array_equal(scaled.contact_count, curve.contact_count)
    np.testing.assert_allclose(scaled.real_gradient_rms, curve.real_gradient_rms, rtol=1e-12)


SURFACE = {"name": "gradient", "seed": 3, "realizations": 3,
           "spectrum": {"name": "power-law-2d", "params": {"hurst": 0.8, "points": 32, "length": 8.0,
                                                           "short_cutoff": 1.0, "rms_height": 0.5}},
           "solver": {"name": "bem-halfspace", "params": {"youngs_modulus": 3.0, "poisson_ratio": 0.3}},
           "slope": {"name": "forward-difference"},
           "loading": {"control": "force", "start": 0.5, "stop": 20.0, "steps": 4, "spacing": "log"},
           "fit": {"bootstrap": 50}}  # fmt: skip


def test_g_r_kappa_and_kappa_r_reach_curve_csv_and_read_back(tmp_path):
    import frictionlab
    from frictionlab.runs.results import read_curve

    result = frictionlab.run(SURFACE, out=tmp_path / "run", workers=1, progress=False, plot=False)
    per = np.load(tmp_path / "run" / "realizations.npz")
    g_r, area, g = per["real_gradient_rms"], per["real_area_corrected"], per["slope_rms_line"]
    assert g_r.shape == (3, 4) and np.all(g_r > 0)
    stiffness = 3.0 / (1 - 0.3**2)
    a0 = 8.0**2  # the surface's side squared
    pressure = result.table["F"] / a0
    kappa = area * stiffness * g[:, None] / pressure
    np.testing.assert_allclose(result.table["real_gradient_rms"], g_r.mean(axis=0), rtol=1e-14)
    np.testing.assert_allclose(result.table["kappa"], kappa.mean(axis=0), rtol=1e-12)
    np.testing.assert_allclose(result.table["kappa_r"], (kappa * g_r / g[:, None]).mean(axis=0), rtol=1e-12)
    # xi is the plain rms over the pixels, g_r the corrected one: close (a few percent), not equal
    xi_times_g = per["xi"] * g[:, None]
    assert np.all(np.abs(g_r / xi_times_g - 1) < 0.1) and np.any(np.abs(g_r / xi_times_g - 1) > 1e-6)
    curve = read_curve(tmp_path / "run")
    for name in ("real_gradient_rms", "kappa", "kappa_r"):
        np.testing.assert_array_equal(curve[name], result.table[name])
    assert frictionlab.load(tmp_path / "run").table["kappa_r"].shape == (4,)
    header = (tmp_path / "run" / "curve.csv").read_text().splitlines()[0]
    assert "kappa_r [" in header and "dimensionless" in header


def test_springs_have_no_g_r_and_a_damaged_header_is_refused(tmp_path):
    import frictionlab
    from frictionlab.errors import RunFolderError
    from frictionlab.runs.results import read_curve

    springs = frictionlab.run({**SURFACE, "solver": {"name": "mdr", "params": {}}}, out=tmp_path / "mdr", workers=1,
                              progress=False, plot=False)  # fmt: skip
    assert "real_gradient_rms" not in springs.table and "kappa_r" not in springs.table
    frictionlab.run(SURFACE, out=tmp_path / "run", workers=1, progress=False, plot=False)
    path = tmp_path / "run" / "curve.csv"
    lines = path.read_text().splitlines()
    names = lines[0].split(",")
    lines[0] = ",".join(names[:-2] + names[-1:] + names[-2:-1])  # kappa_r before kappa
    path.write_text("\n".join(lines) + "\n")
    with pytest.raises(RunFolderError, match="damaged"):
        read_curve(tmp_path / "run")


def test_a_resumed_run_keeps_g_r_and_an_older_chunk_without_it_reads_as_unknown(registry, tmp_path):
    from frictionlab.runs.chunks import chunk_results

    scene, resumed, whole = resumed_and_whole(SURFACE, registry, tmp_path / "run")
    np.testing.assert_array_equal(resumed.real_gradient_rms, whole.table["real_gradient_rms"])
    np.testing.assert_array_equal(resumed.kappa_r, whole.table["kappa_r"])
    chunk = sorted((tmp_path / "run" / "chunks").glob("*.npz"))[0]
    arrays = dict(np.load(chunk))
    del arrays["real_gradient_rms"]  # as a version before g_r wrote it
    results = chunk_results(arrays, 0, 2, scene)
    assert all(np.isnan(r.real_gradient_rms).all() for r in results if r.ok)


def brute_spots(contact: np.ndarray, periodic: bool) -> int:
    """Flood fill, pixel by pixel."""
    ny, nx = contact.shape
    seen = np.zeros(contact.shape, bool)
    spots = 0
    for i in range(ny):
        for j in range(nx):
            if contact[i, j] and not seen[i, j]:
                spots += 1
                stack = [(i, j)]
                seen[i, j] = True
                while stack:
                    a, b = stack.pop()
                    for da, db in ((1, 0), (-1, 0), (0, 1), (0, -1)):
                        c, d = a + da, b + db
                        if not periodic and not (0 <= c < ny and 0 <= d < nx):
                            continue
                        c, d = c % ny, d % nx
                        if contact[c, d] and not seen[c, d]:
                            seen[c, d] = True
                            stack.append((c, d))
    return spots


@pytest.mark.parametrize("periodic", [True, False])
@pytest.mark.parametrize("seed", range(6))
def test_spots_are_counted_as_a_flood_fill_counts_them(periodic, seed):
    from frictionlab_solvers.contact_area import contact_spots

    rng = np.random.default_rng(seed)
    contact = rng.random((9, 11)) < (0.3 + 0.05 * seed)
    assert contact_spots(contact, periodic=periodic) == brute_spots(contact, periodic)


def test_a_band_across_the_periodic_boundary_is_one_spot_and_two_on_a_scan():
    from frictionlab_solvers.contact_area import contact_spots

    contact = np.zeros((6, 6), bool)
    contact[:, 0] = contact[:, -1] = True  # one band wrapping round the boundary
    contact[2, 2:4] = True
    assert contact_spots(contact, periodic=True) == 2
    assert contact_spots(contact, periodic=False) == 3


def test_spots_reach_curve_csv_and_grow_from_a_few(tmp_path):
    import frictionlab

    result = frictionlab.run(SURFACE, out=tmp_path / "run", workers=1, progress=False, plot=False)
    per = np.load(tmp_path / "run" / "realizations.npz")["contact_spots"]
    assert per.shape == (3, 4) and np.all(per >= 1) and np.all(per == np.round(per))
    np.testing.assert_allclose(result.table["contact_spots"], per.mean(axis=0), rtol=1e-15)
    assert np.all(per <= np.load(tmp_path / "run" / "realizations.npz")["contact_count"])


@pytest.mark.parametrize("attr", ["real_gradient", "counts_spots"])
def test_a_declaration_that_is_not_a_bool_is_refused_naming_it(attr):
    from frictionlab.plugin.classcheck import declaration_problems

    broken = type("Broken", (BEMHalfSpace,), {attr: "yes", "name": "broken-bem"})
    assert any(attr in p and "True or False" in p for p in declaration_problems(broken))
    assert not declaration_problems(BEMHalfSpace)

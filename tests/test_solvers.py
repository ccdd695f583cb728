"""Spring contact solvers (exact nested contact sets, scaling laws) against closed forms, a
brute-force force balance and the bisection baseline.

Grid tolerances for the closed forms (Euler-Maclaurin): on a uniform grid the
force is a Riemann sum of g(x) = max(0, z(x) - c), which is smooth except for
kinks at the contact edges x = +-a, where g' jumps by J = |z'(a)|. With
periodic Bernoulli functions |B2| <= 1/6 and |B3| <= 0.0481 the sum differs
from the integral by at most, per contact patch,

    dx^2 / 12 * (J_left + J_right) + dx^3 / 6 * 0.0481 * (|g''(-a)| + |g''(a)|) + ...

which is exact for a parabola (g''' = 0) and, for a cosine, followed by dx^4
terms far below it. The count of grid points strictly inside (-a, a) is within
one of 2a / dx.
"""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from frictionlab import Profile
from frictionlab.plugin.registry import validate_plugin_class
from frictionlab.testing import check_plugin
from frictionlab_slopes import ForwardDifference
from frictionlab_solvers import BisectionSprings, MDRSprings, WinklerSprings

B3 = 0.0481  # max |B3(t)| on [0, 1] is sqrt(3)/36 = 0.04811
MARGIN = 1.05  # room for floating-point rounding on top of the grid bound


def line(points: int, seed: int, *, smooth: int = 10) -> np.ndarray:
    """A band-limited random periodic line (zero mean, unit rms)."""
    rng = np.random.default_rng(seed)
    k = np.arange(1, points // 2 + 1)
    amplitude = k**-1.5 * (k <= points / smooth)
    spectrum = np.zeros(points // 2 + 1, complex)
    spectrum[1:] = amplitude * np.exp(2j * np.pi * rng.random(k.size))
    z = np.fft.irfft(spectrum, n=points)
    return z / z.std()


def forward(z, dx=1.0):
    return ForwardDifference().slopes(z, dx)


def solve(solver, z, loads, control="force", dx=1.0, slopes=None):
    z = np.asarray(z, dtype=float)
    slopes = forward(z, dx) if slopes is None else slopes
    return solver.solve(Profile(z, dx), np.asarray(loads, dtype=float), control, slopes)


# ------------------------------------------------------------------ contract


@pytest.mark.parametrize("cls", [MDRSprings, WinklerSprings, BisectionSprings])
def test_plugin_contract(cls):
    validate_plugin_class("solver", cls)
    for name, info in cls.Params.model_fields.items():
        kinds = {type(m).__name__ for m in info.metadata}
        assert kinds & {"Gt", "Ge", "Lt", "Le", "Interval"}, f"{name} has no bounds"
    with pytest.raises(ValueError):
        cls(not_a_param=1.0)


@pytest.mark.parametrize(
    "cls, params",
    [(MDRSprings, {}), (MDRSprings, {"youngs_modulus": 3.0, "poisson_ratio": 0.5}), (WinklerSprings, {"modulus": 0.2}),
     (BisectionSprings, {})],
)
def test_conformance(cls, params):
    check_plugin("solver", cls, **params)


def test_names_and_references():
    assert (MDRSprings.name, WinklerSprings.name, BisectionSprings.name) == ("mdr", "winkler", "mdr-bisection")
    assert "10.1007/978-3-642-53876-6" in MDRSprings.references
    assert "baseline" in BisectionSprings.summary


def test_stiffness():
    assert MDRSprings(youngs_modulus=2.0, poisson_ratio=0.3).stiffness() == 2.0 / (1 - 0.3**2)
    assert MDRSprings(youngs_modulus=3.0, poisson_ratio=0.5).stiffness() == 3.0 / 0.75
    assert MDRSprings().stiffness() == 1.0
    assert WinklerSprings(modulus=7.5).stiffness() == 7.5
    assert BisectionSprings(youngs_modulus=2.0, poisson_ratio=0.3).stiffness() == MDRSprings(
        youngs_modulus=2.0, poisson_ratio=0.3
    ).stiffness()
    for bad in ({"youngs_modulus": 0.0}, {"youngs_modulus": np.inf}, {"poisson_ratio": 0.6},
                {"poisson_ratio": -1.0}, {"poisson_ratio": np.nan}):
        with pytest.raises(ValueError):
            MDRSprings(**bad)
    for bad in ({"tolerance": 0.0}, {"max_iterations": 0}):
        with pytest.raises(ValueError):
            BisectionSprings(**bad)
    with pytest.raises(ValueError):
        WinklerSprings(modulus=-1.0)


def test_winkler_with_modulus_e_star_is_mdr():
    mdr = MDRSprings(youngs_modulus=2.0, poisson_ratio=0.3)
    winkler = WinklerSprings(modulus=mdr.stiffness())
    z = line(3000, 1)
    for control, loads in (("force", np.geomspace(1e-3, 1e4, 40)), ("indentation", np.geomspace(1e-3, 5, 40))):
        a, b = solve(mdr, z, loads, control, dx=0.5), solve(winkler, z, loads, control, dx=0.5)
        for field in ("force", "indentation", "contact_count", "contact_fraction", "slope_rms_contact"):
            np.testing.assert_array_equal(getattr(a, field), getattr(b, field))


# ------------------------------------------------------------- closed forms


def cosine_line(h0, wavelength, per_period, periods):
    dx = wavelength / per_period
    x = np.arange(per_period * periods) * dx  # a crest sits on the grid point x = 0
    q = 2 * np.pi / wavelength
    return h0 * np.cos(q * x), dx, q


def cosine_force(k, h0, q, d, periods):
    c = h0 - d
    a = np.arccos(c / h0) / q
    return periods * k * 2 * (h0 * np.sin(q * a) / q - c * a), a


def cosine_bound(k, h0, q, a, dx, periods):
    # kinks: J = h0 q sin(q a) at each edge; |g''| <= h0 q^2
    return MARGIN * periods * k * (dx**2 / 6 * h0 * q * np.sin(q * a) + dx**3 / 3 * B3 * h0 * q**2)


@pytest.mark.parametrize("per_period", [100, 400])
def test_cosine_indentation_control(per_period):
    solver = MDRSprings(youngs_modulus=2.0, poisson_ratio=0.3)
    k, h0, periods = solver.stiffness(), 0.01, 3
    z, dx, q = cosine_line(h0, 1.0, per_period, periods)
    d = np.linspace(0.02, 1.95, 150) * h0  # below full contact (d = 2 h0)
    curve = solve(solver, z, d, "indentation", dx=dx)
    exact, a = cosine_force(k, h0, q, d, periods)
    assert np.all(np.abs(curve.force - exact) <= cosine_bound(k, h0, q, a, dx, periods))
    # contact width 2a per period against n dx: within one grid point per patch
    assert np.all(np.abs(curve.contact_count * dx - 2 * a * periods) <= periods * dx * (1 + 1e-9))
    np.testing.assert_array_equal(curve.indentation, d)


def test_cosine_force_control():
    solver = MDRSprings(youngs_modulus=1.5)
    k, h0, periods, per_period = solver.stiffness(), 2.0, 4, 256
    z, dx, q = cosine_line(h0, 3.0, per_period, periods)
    d = np.linspace(0.05, 1.9, 100) * h0
    forces, a = cosine_force(k, h0, q, d, periods)
    curve = solve(solver, z, forces, "force", dx=dx)
    # F_h(d_h) = F(d): |d_h - d| <= (grid force error) / min dF/dd, dF/dd = 2 a k per period,
    # taken at the smaller of the two contact widths (a grows with d)
    a_low = np.arccos(np.clip((h0 - np.minimum(d, curve.indentation)) / h0, -1, 1)) / q
    a_high = np.arccos((h0 - np.maximum(d, curve.indentation)) / h0) / q
    allowed = cosine_bound(k, h0, q, a_high, dx, periods) / (2 * a_low * k * periods)
    assert np.all(np.abs(curve.indentation - d) <= allowed)
    # 1000x looser than allowed would still be a strong check; the bound is the honest one
    assert np.max(np.abs(curve.indentation - d) / d) < 1e-3


def parabola(radius, dx, half_width):
    half = int(round(half_width / dx))
    x = np.arange(-half, half) * dx  # the top (x = 0) is a grid point
    return -(x**2) / (2 * radius)


def parabola_bound(k, radius, a, dx):
    # kinks: J = a / R at each edge; g'' = -1/R; g''' = 0, so this is the whole error
    return MARGIN * k * (dx**2 / 6 * a / radius + dx**3 / 3 * B3 / radius)


def test_parabola_indentation_control_converges():
    solver = MDRSprings(youngs_modulus=2.0, poisson_ratio=0.25)
    k, radius = solver.stiffness(), 10.0
    d = np.linspace(0.05, 1.0, 60)
    a = np.sqrt(2 * radius * d)
    exact = 4 / 3 * k * np.sqrt(2 * radius) * d**1.5
    worst = []
    for dx in (0.1, 0.05, 0.0125):
        curve = solve(solver, parabola(radius, dx, 10.0), d, "indentation", dx=dx)
        error = np.abs(curve.force - exact)
        assert np.all(error <= parabola_bound(k, radius, a, dx))
        assert np.all(np.abs(curve.contact_count * dx - 2 * a) <= dx * (1 + 1e-9))
        worst.append(np.max(error / exact))
    # second order: refining 8x cuts the worst error by ~64 (the constant oscillates)
    assert worst[2] < worst[0] / 16
    assert worst[1] < worst[0]


def test_parabola_force_control():
    solver = WinklerSprings(modulus=3.0)
    k, radius, dx = solver.stiffness(), 4.0, 0.02
    forces = np.geomspace(0.05, 20.0, 50)
    d = (3 * forces / (4 * k * np.sqrt(2 * radius))) ** (2 / 3)
    curve = solve(solver, parabola(radius, dx, 8.0), forces, "force", dx=dx)
    a_low = np.sqrt(2 * radius * np.minimum(d, curve.indentation))
    a_high = np.sqrt(2 * radius * np.maximum(d, curve.indentation))
    allowed = parabola_bound(k, radius, a_high, dx) / (2 * a_low * k)  # dF/dd = 2 a k
    assert np.all(np.abs(curve.indentation - d) <= allowed)
    # width 2 sqrt(2 R d) at the solver's own indentation: within one grid point
    assert np.all(np.abs(curve.contact_count * dx - 2 * np.sqrt(2 * radius * curve.indentation)) <= dx * (1 + 1e-9))
    np.testing.assert_array_equal(curve.force, forces)


def test_mdr_of_a_sphere_is_hertz():
    """Popov's MDR: a sphere of radius R maps to the line g(x) = x^2 / R; pressed into
    springs of stiffness E* dx it carries Hertz's F = 4/3 E* sqrt(R) d^(3/2) with the line's
    contact half-width the sphere's contact radius a = sqrt(R d). E* = E / (1 - nu^2) here,
    not the solver's own stiffness(). Tolerances: the Euler-Maclaurin bound above."""
    youngs, nu, radius, dx = 2.0, 0.25, 5.0, 0.01
    solver = MDRSprings(youngs_modulus=youngs, poisson_ratio=nu)
    e_star = youngs / (1 - nu**2)
    half = int(round(6.0 / dx))
    x = np.arange(-half, half) * dx
    d = np.linspace(0.05, 1.0, 40)
    curve = solve(solver, -(x**2) / radius, d, "indentation", dx=dx)
    a = np.sqrt(radius * d)
    hertz = 4 / 3 * e_star * np.sqrt(radius) * d**1.5
    assert np.all(np.abs(curve.force - hertz) <= parabola_bound(e_star, radius / 2, a, dx))
    assert np.all(np.abs(curve.contact_count * dx - 2 * a) <= dx * (1 + 1e-9))


# --------------------------------------------------------- exactness checks


def test_force_and_indentation_control_are_inverse():
    solver = MDRSprings(youngs_modulus=1.3, poisson_ratio=0.2)
    z = line(2000, 3)
    forces = np.geomspace(1e-6, 1e5, 80)  # one point ... far past full contact
    by_force = solve(solver, z, forces, "force", dx=0.7)
    assert by_force.contact_count[0] == 1 and by_force.contact_fraction[-1] == 1.0
    back = solve(solver, z, by_force.indentation, "indentation", dx=0.7)
    np.testing.assert_allclose(back.force, forces, rtol=1e-12)
    np.testing.assert_array_equal(back.contact_count, by_force.contact_count)
    np.testing.assert_array_equal(back.slope_rms_contact, by_force.slope_rms_contact)
    again = solve(solver, z, back.force, "force", dx=0.7)
    np.testing.assert_allclose(again.indentation, by_force.indentation, rtol=1e-12)
    np.testing.assert_array_equal(again.contact_count, by_force.contact_count)


def test_brute_force_balance_from_the_reported_indentation():
    solver = MDRSprings(youngs_modulus=0.8, poisson_ratio=0.45)
    dx = 0.25
    z = line(5000, 4) + 3.0  # an offset the solver must not care about
    slopes = forward(z, dx)
    forces = np.geomspace(1e-4, 1e3, 30)
    curve = solve(solver, z, forces, "force", dx=dx, slopes=slopes)
    for force, d, n, rms in zip(forces, curve.indentation, curve.contact_count, curve.slope_rms_contact):
        level = z.max() - d
        contact = z > level
        assert solver.stiffness() * dx * np.maximum(z - level, 0.0).sum() == pytest.approx(force, rel=1e-9)
        assert contact.sum() == n
        assert rms == pytest.approx(np.sqrt(np.mean(slopes[contact] ** 2)), rel=1e-12)


def test_plateaus_and_the_strictly_above_rule():
    # depths below the top: 0, 1, 1, 2; K = 1. Onsets: point 2 (and its tie) at F = 1,
    # point 4 at F = 1 + 1*1 + 2*0 + 3*(2 - 1) = 4.
    z = np.array([1.0, 2.0, 1.0, 0.0])
    slopes = np.array([3.0, -1.0, 5.0, 7.0])
    curve = solve(MDRSprings(), z, [0.5, 1.0, 1.5, 4.0, 4.5], "force", slopes=slopes)
    np.testing.assert_array_equal(curve.contact_count, [1, 1, 3, 3, 4])  # ties at the level do not touch
    np.testing.assert_array_equal(curve.indentation, [0.5, 1.0, 3.5 / 3, 2.0, 8.5 / 4])
    assert curve.slope_rms_contact[1] == 1.0
    assert curve.slope_rms_contact[2] == pytest.approx(np.sqrt((1 + 9 + 25) / 3), rel=1e-15)
    by_d = solve(MDRSprings(), z, [1.0, 1.0 + 1e-9, 2.0, 2.5], "indentation", slopes=slopes)
    np.testing.assert_array_equal(by_d.contact_count, [1, 3, 3, 4])
    np.testing.assert_allclose(by_d.force, [1.0, 1.0 + 3e-9, 4.0, 4.0 + 4 * 0.5], rtol=1e-12)
    # a plateau at the top: all of it touches at once
    top = solve(MDRSprings(), [0.0, 1.0, 1.0, 1.0, 0.5], [1e-9, 0.3], "force")
    np.testing.assert_array_equal(top.contact_count, [3, 3])
    np.testing.assert_allclose(top.indentation, [1e-9 / 3, 0.1], rtol=1e-15)


def test_candidate_bound_is_tight():
    # K = 1, depths 0 and 0.8: at F = 1 both touch (d = 0.9 > 0.8), and 0.8 is close to
    # the bound F/K = 1. At F = 0.8 the second point is exactly at the level: not in contact.
    z = np.array([-5.0, 0.0, -0.8, -3.0, -0.99999])
    curve = solve(MDRSprings(), z, [1.0], "force")
    assert curve.contact_count[0] == 2 and curve.indentation[0] == pytest.approx(0.9, rel=1e-15)
    assert curve.extras["candidates"][0] == 3
    curve = solve(MDRSprings(), z, [0.8], "force")
    assert curve.contact_count[0] == 1 and curve.indentation[0] == 0.8
    assert curve.extras["candidates"][0] == 2
    curve = solve(MDRSprings(), z, [0.8000001], "indentation")
    assert curve.contact_count[0] == 2 and curve.extras["candidates"][0] == 2


def test_loads_far_below_the_resolution_of_the_heights():
    # F/K below half an ulp of max z: the level rounds to the top, the top still touches
    z = line(1000, 16) + 1e6
    curve = solve(MDRSprings(), z, [1e-20, 1e-15], "force")
    np.testing.assert_array_equal(curve.contact_count, 1)
    np.testing.assert_allclose(curve.indentation, [1e-20, 1e-15], rtol=1e-15)
    curve = solve(MDRSprings(), z, [1e-20], "indentation")
    assert curve.contact_count[0] == 1 and curve.force[0] == pytest.approx(1e-20, rel=1e-15)


def test_loads_in_any_order():
    z = line(1000, 6)
    loads = np.geomspace(1e-3, 1e3, 25)
    perm = np.random.default_rng(0).permutation(loads.size)
    a, b = solve(MDRSprings(), z, loads, "force"), solve(MDRSprings(), z, loads[perm], "force")
    for field in ("force", "indentation", "contact_count", "slope_rms_contact"):
        np.testing.assert_array_equal(getattr(a, field)[perm], getattr(b, field))


def test_full_contact_gives_xi_one_bitwise():
    z = line(4096, 7)
    slopes = forward(z, 0.5)
    line_rms = float(np.sqrt(np.mean(np.square(slopes))))  # as the engine forms it
    for solver in (MDRSprings(), BisectionSprings()):
        curve = solve(solver, z, [1e4, 1e6, 1e9], "force", dx=0.5, slopes=slopes)
        np.testing.assert_array_equal(curve.contact_fraction, 1.0)
        np.testing.assert_array_equal(curve.contact_count, z.size)
        assert np.all(curve.slope_rms_contact == line_rms)
        assert np.all(curve.slope_rms_contact / line_rms == 1.0)
    deep = solve(MDRSprings(), z, [z.max() - z.min() + 1.0], "indentation", dx=0.5, slopes=slopes)
    assert deep.contact_fraction[0] == 1.0 and deep.slope_rms_contact[0] == line_rms


def test_one_point_in_contact():
    z = line(10_000, 8)
    slopes = forward(z)
    top = int(np.argmax(z))
    for solver in (MDRSprings(youngs_modulus=4.0), BisectionSprings(youngs_modulus=4.0)):
        curve = solve(solver, z, [1e-12, 1e-9], "force", slopes=slopes)
        np.testing.assert_array_equal(curve.contact_count, 1)
        assert np.all(curve.slope_rms_contact == abs(slopes[top]))
        np.testing.assert_allclose(curve.indentation, [1e-12 / 4, 1e-9 / 4], rtol=1e-9)


def test_partial_sort_is_used(monkeypatch):
    """The candidate count is exposed per load in ``extras['candidates']``; a spy
    on ``numpy.argsort`` confirms only that many depths get sorted."""
    z = line(100_000, 9) * 1e4  # study-like: ~a dozen points in contact at F = 20
    slopes = forward(z)
    sizes = []
    real_argsort = np.argsort

    def spy(a, *args, **kwargs):
        sizes.append(np.size(a))
        return real_argsort(a, *args, **kwargs)

    monkeypatch.setattr(np, "argsort", spy)
    curve = solve(MDRSprings(), z, np.linspace(1, 20, 400), "force", slopes=slopes)
    monkeypatch.undo()
    candidates = curve.extras["candidates"]
    assert candidates.shape == (400,) and np.all(candidates == candidates[0])
    assert curve.contact_count.max() <= candidates[0] < 1000
    assert sizes == [candidates[0]]
    # every point a candidate: one full sort
    sizes.clear()
    monkeypatch.setattr(np, "argsort", spy)
    curve = solve(MDRSprings(), z, [1e20], "force", slopes=slopes)
    monkeypatch.undo()
    assert sizes == [z.size] and curve.extras["candidates"][0] == z.size


# ------------------------------------------------------------------ scaling


@pytest.mark.parametrize("control", ["force", "indentation"])
def test_height_scaling_power_of_two_is_exact(control):
    z = line(3000, 10)
    loads = np.geomspace(1e-4, 1e4, 30) if control == "force" else np.geomspace(1e-4, 10, 30)
    base = solve(MDRSprings(), z, loads, control)
    for s in (2.0**-40, 2.0**35):
        scaled = solve(MDRSprings(), s * z, s * loads, control, slopes=s * forward(z))
        np.testing.assert_array_equal(scaled.contact_count, base.contact_count)
        np.testing.assert_array_equal(scaled.slope_rms_contact, s * base.slope_rms_contact)
        np.testing.assert_array_equal(scaled.indentation, s * base.indentation)
        np.testing.assert_array_equal(scaled.force, s * base.force)


@pytest.mark.parametrize("s", [3.7, 1e-12, 1e12])
def test_height_scaling_any_factor(s):
    z = line(3000, 11)
    forces = np.geomspace(1e-4, 1e4, 30)
    base = solve(MDRSprings(), z, forces)
    scaled = solve(MDRSprings(), s * z, s * forces, slopes=forward(s * z))
    np.testing.assert_array_equal(scaled.contact_count, base.contact_count)
    np.testing.assert_allclose(scaled.slope_rms_contact, s * base.slope_rms_contact, rtol=1e-12)
    np.testing.assert_allclose(scaled.indentation, s * base.indentation, rtol=1e-12)


@pytest.mark.parametrize("s", [2.0**20, 2.0**-30, 3.7, 1e-9])
def test_modulus_scaling(s):
    z = line(3000, 12)
    forces = np.geomspace(1e-4, 1e4, 30)
    base = solve(MDRSprings(youngs_modulus=1.7, poisson_ratio=0.3), z, forces)
    scaled = solve(MDRSprings(youngs_modulus=1.7 * s, poisson_ratio=0.3), z, s * forces)
    np.testing.assert_array_equal(scaled.contact_count, base.contact_count)
    if np.log2(s).is_integer():
        np.testing.assert_array_equal(scaled.indentation, base.indentation)
        np.testing.assert_array_equal(scaled.slope_rms_contact, base.slope_rms_contact)
    else:
        np.testing.assert_allclose(scaled.indentation, base.indentation, rtol=1e-12)
        np.testing.assert_allclose(scaled.slope_rms_contact, base.slope_rms_contact, rtol=1e-12)


# ----------------------------------------------------- against the bisection


@st.composite
def rough_lines(draw):
    points = draw(st.integers(8, 200))
    seed = draw(st.integers(0, 2**32 - 1))
    if draw(st.booleans()):  # hypothesis' own values: many repeats and edge values
        base = draw(arrays(np.float64, points, elements=st.floats(-1.0, 1.0, allow_subnormal=False)))
    else:  # generic values, as from a real line
        base = np.random.default_rng(seed).uniform(-1.0, 1.0, points)
    quantum = draw(st.sampled_from([None, 0.5, 0.1, 1 / 64]))  # rounding makes ties and plateaus
    if quantum is not None:
        base = np.round(base / quantum) * quantum
    scale = draw(st.sampled_from([1e-3, 1.0, 7.5, 1e3]))
    # the largest load sets the candidate bound: let it range from one point to far past full contact
    top = draw(st.floats(-8.0, 1.5))
    below = draw(st.lists(st.floats(0.0, 6.0), min_size=0, max_size=11))
    exponents = [top] + [top - b for b in below]
    return base * scale, np.array(exponents), seed


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rough_lines(), st.sampled_from([0.5, 1.0, 3.0]), st.sampled_from([0.0, 0.3]))
def test_sorted_sweep_matches_bisection(case, dx, nu):
    z, exponents, seed = case
    slopes = np.random.default_rng(seed + 1).normal(size=z.size)
    fast, slow = MDRSprings(youngs_modulus=2.0, poisson_ratio=nu), BisectionSprings(youngs_modulus=2.0, poisson_ratio=nu)
    spring = fast.stiffness() * dx
    span = z.max() - z.min()
    # force at full contact is spring * (N max z - sum z); factors 10^1.5 go far past it
    full = spring * (z.size * span + 1e-3 * (span + 1e-3))
    forces = full * 10.0**exponents
    a = solve(fast, z, forces, "force", dx=dx, slopes=slopes)
    b = solve(slow, z, forces, "force", dx=dx, slopes=slopes)
    np.testing.assert_array_equal(a.contact_count, b.contact_count)
    np.testing.assert_array_equal(a.contact_fraction, b.contact_fraction)
    np.testing.assert_allclose(a.slope_rms_contact, b.slope_rms_contact, rtol=1e-12)
    # bisection stops at |F(d) - F| <= tol F; dF/dd >= K n near the root
    tol = slow.params.tolerance
    reach = forces / spring
    allowed = 2 * tol * reach / np.maximum(a.contact_count - 1, 1) + 4e-16 * reach
    assert np.all(np.abs(a.indentation - b.indentation) <= allowed)
    assert np.all((b.extras["residual"] <= tol) | (b.extras["iterations"] > 0))
    # indentation control: direct on both sides
    depths = np.unique(a.indentation)
    c = solve(fast, z, depths, "indentation", dx=dx, slopes=slopes)
    e = solve(slow, z, depths, "indentation", dx=dx, slopes=slopes)
    np.testing.assert_array_equal(c.contact_count, e.contact_count)
    np.testing.assert_allclose(c.force, e.force, rtol=1e-12)
    np.testing.assert_allclose(c.slope_rms_contact, e.slope_rms_contact, rtol=1e-12)


def test_bisection_reports_its_work():
    z = line(500, 13)
    curve = solve(BisectionSprings(tolerance=1e-8), z, np.geomspace(1e-3, 1e3, 10))
    assert np.all(curve.extras["residual"] <= 1e-8)
    assert np.all(curve.extras["iterations"] >= 1)
    by_d = solve(BisectionSprings(), z, [0.1, 1.0], "indentation")
    np.testing.assert_array_equal(by_d.extras["iterations"], 0)


# ------------------------------------------------------------------- errors


@pytest.mark.parametrize("cls", [MDRSprings, WinklerSprings, BisectionSprings])
@pytest.mark.parametrize("control", ["force", "indentation"])
@pytest.mark.parametrize(
    "bad, problem", [(0.0, "not positive"), (-2.0, "not positive"), (np.nan, "not finite"), (np.inf, "not finite")]
)
def test_invalid_loads(cls, control, bad, problem):
    z = line(64, 14)
    with pytest.raises(ValueError, match=rf"load 1 is .*{problem}"):
        solve(cls(), z, [1.0, bad, 2.0], control)


@pytest.mark.parametrize("cls", [MDRSprings, BisectionSprings])
def test_invalid_arguments(cls):
    z = line(64, 15)
    with pytest.raises(ValueError, match="control"):
        solve(cls(), z, [1.0], "pressure")
    with pytest.raises(ValueError, match="empty"):
        solve(cls(), z, [], "force")
    with pytest.raises(ValueError, match="1D"):
        solve(cls(), z, [[1.0]], "force")
    with pytest.raises(ValueError, match="shape"):
        solve(cls(), z, [1.0], "force", slopes=np.zeros(63))
    with pytest.raises(ValueError, match="finite"):
        solve(cls(), np.where(np.arange(64) == 3, np.nan, z), [1.0], "force", slopes=np.zeros(64))
    with pytest.raises(ValueError, match="spacing"):
        cls().solve(Profile(z, 0.0), np.array([1.0]), "force", np.zeros(64))

"""Loads in the user's terms (force, f, p / E*, a contact fraction), what validate says of
them, the refusal of a law where xi does not change, the points carrying half the load,
the spike caveat, the limit of a solver's arithmetic, and the free boundary's corrected area."""

from __future__ import annotations

import json
import math

import numpy as np
import pytest

import frictionlab
from frictionlab import Profile, half_load_points
from frictionlab.errors import PresetError
from frictionlab.preset import build_scene
from frictionlab_solvers import BEMHalfSpaceFree, BisectionSprings, MDRSprings
from frictionlab_solvers.contact_area import PERIMETER_COEFFICIENT, contact_edges, corrected_area_fraction

FAST = {"workers": 1, "progress": False, "plot": False}
LINE = {
    "name": "line", "seed": 3, "realizations": 3,
    "spectrum": {"name": "power-law", "params": {"hurst": 0.8, "points": 512, "spacing": 1.0, "rms_height": 1.0}},
    "solver": {"name": "mdr", "params": {"youngs_modulus": 1.0}},
    "loading": {"start": 0.5, "stop": 20.0, "steps": 8, "spacing": "log"},
    "fit": {"bootstrap": 0},
}  # fmt: skip
SURFACE = {
    "name": "surface", "seed": 5, "realizations": 1,
    "spectrum": {"name": "power-law-2d", "params": {"hurst": 0.8, "points": 24, "spacing": 1.0, "rms_height": 1.0}},
    "solver": {"name": "bem-halfspace", "params": {"tolerance": 1e-10}},
    "loading": {"start": 0.5, "stop": 8.0, "steps": 4, "spacing": "log"},
    "fit": {"bootstrap": 0},
}  # fmt: skip


def with_loading(preset: dict, **loading) -> dict:
    return {**preset, "loading": {**preset["loading"], **loading}}


def test_a_load_given_as_f_or_as_a_pressure_is_the_same_run_as_its_force():
    forced = frictionlab.run(LINE, **FAST)
    unit = build_scene(LINE).load_scales.force_unit
    assert unit == pytest.approx(1.0 * 1.0 * 512)  # E* h L on a line of 512 points of spacing 1
    as_f = frictionlab.run(with_loading(LINE, unit="f", start=0.5 / unit, stop=20.0 / unit), **FAST)
    area = math.pi * 512**2 / 4  # the disc whose MDR line is 512 long
    as_p = frictionlab.run(with_loading(LINE, unit="pressure", start=0.5 / area, stop=20.0 / area), **FAST)
    for other in (as_f, as_p):
        np.testing.assert_allclose(other.table["F"], forced.table["F"], rtol=1e-12)
        np.testing.assert_allclose(other.table["xi"], forced.table["xi"], rtol=1e-9)
        np.testing.assert_array_equal(other.table["contact_count"], forced.table["contact_count"])


@pytest.mark.parametrize("preset", [with_loading(LINE, unit="force"), SURFACE], ids=["winkler", "bem-halfspace"])
def test_a_contact_fraction_is_reached_and_is_the_same_run_as_the_force_found(preset):
    if preset is not SURFACE:
        preset = {**preset, "solver": {"name": "winkler", "params": {}}, "realizations": 1}
    fractions = dict(unit="contact-fraction", start=0.02, stop=0.2, steps=4)
    run = frictionlab.run(with_loading(preset, **fractions), **FAST)
    points = 512 if preset is not SURFACE else 24 * 24
    target = np.ceil(np.geomspace(0.02, 0.2, 4) * points)
    count = run.table["contact_count"]
    assert np.all(count >= target) and np.all(count <= target + 0.02 * points)  # a jump may pass a few points
    for j, force in enumerate(run.table["F"]):  # each force found, as a force (the first of two steps)
        with pytest.warns(UserWarning, match="run failed: no law"):  # two loads a hair apart: no law, said
            again = frictionlab.run(with_loading(preset, unit="force", start=force, stop=force * (1 + 1e-9), steps=2),
                                    **FAST).table  # fmt: skip
        assert again["F"][0] == force and again["contact_count"][0] == count[j]
        assert again["xi"][0] == pytest.approx(run.table["xi"][j], rel=1e-9)


@pytest.mark.parametrize("change, words", [
    ({"loading": {"unit": "contact-fraction", "start": 0.1, "stop": 0.5, "steps": 3}}, "mdr counts mdr springs"),
    ({"solver": {"name": "winkler"}, "loading": {"unit": "pressure", "start": 1e-3, "stop": 1e-2, "steps": 3}},
     "'pressure' needs a solver whose modulus is a stress"),
])  # fmt: skip
def test_a_unit_the_solver_cannot_take_is_refused_before_the_run(tmp_path, change, words):
    preset = {**LINE, **{k: v for k, v in change.items() if k != "loading"}, "loading": change["loading"]}
    with pytest.raises(PresetError, match="loading.unit") as caught:
        frictionlab.run(preset, out=tmp_path / "run", **FAST)
    assert words in str(caught.value) and not (tmp_path / "run").exists()
    with pytest.raises(PresetError, match="loading.unit"):  # a run kept in memory too
        frictionlab.run(preset, **FAST)


@pytest.mark.parametrize("loading, words", [
    ({"unit": "f", "control": "indentation", "start": 0.1, "stop": 1.0, "steps": 3}, "needs control 'force'"),
    ({"unit": "contact-fraction", "start": 0.1, "stop": 1.0, "steps": 3}, "stop must be < 1 under unit contact-fraction .* Got 1.0 instead"),
    ({"unit": "newton", "start": 0.1, "stop": 1.0, "steps": 3}, "loading.unit"),
])  # fmt: skip
def test_bad_units_are_named(loading, words):
    with pytest.raises(PresetError, match=words.replace("(", r"\(")):
        build_scene({**LINE, "loading": loading})


def test_validate_prints_the_force_unit_the_loads_in_every_unit_and_full_contact(cli):
    done = cli("validate", "quickstart", "--set", "loading.unit=f", "--set", "loading.start=0.001", "--set", "loading.stop=0.1")
    assert done.returncode == 0, done.stderr
    out = done.stdout
    assert "force unit E* h L = 4096 (modulus x length^2)" in out
    assert "f = 0.001 .. 0.1" in out and "F = 4.096 .. 409.6 (modulus x length^2)" in out
    assert "p/E* = 3.108e-07 .. 3.108e-05" in out  # 4.096 / (pi 4096^2 / 4)
    record = frictionlab.validate("quickstart")["loads"]
    scene = build_scene(frictionlab.api.read_preset_input("quickstart", {})[0])
    from frictionlab.preset.loads import probe_profile

    z = probe_profile(scene).heights
    assert record["full_contact"]["force"] == pytest.approx(np.sum(z - z.min()), rel=1e-12)  # E* dx sum(z - min z)
    assert record["full_contact"]["how"].startswith("exact")
    # a springs run 1 % past it is in full contact, 1 % short of it is not
    counts = MDRSprings().solve(Profile(z, 1.0), np.array([0.99, 1.01]) * record["full_contact"]["force"], "force",
                                np.ones_like(z)).contact_count  # fmt: skip
    assert counts[0] < z.size == counts[1]


def test_validate_calls_the_free_boundary_s_full_contact_an_estimate():
    record = frictionlab.validate({**SURFACE, "solver": {"name": "bem-halfspace-free"}})["loads"]
    assert record["full_contact"]["how"].startswith("estimate") and record["range"]["pressure"] is not None


def test_a_load_past_the_free_solver_s_arithmetic_is_refused_naming_the_limit(tmp_path, cli):
    preset = with_loading({**SURFACE, "solver": {"name": "bem-halfspace-free"}}, start=1.0, stop=1e39)
    with pytest.raises(PresetError, match=r"f <= 1e\+30") as caught:
        frictionlab.run(preset, out=tmp_path / "run", **FAST)
    assert "loading.stop" in str(caught.value) and not (tmp_path / "run").exists()
    done = cli("validate", "mdr-vs-halfspace", "--set", "solver.name=bem-halfspace-free", "--set", "loading.stop=1e39")
    assert done.returncode != 0 and "f <= 1e+30" in done.stderr and "Traceback" not in done.stderr


def test_an_indentation_no_force_reaches_is_refused_before_the_run(tmp_path, cli):
    """Under indentation control a periodic half-space saturates at max z - mean z (full contact):
    the preset passed validate, and every realization failed at run time."""
    preset = with_loading(SURFACE, control="indentation", start=0.1, stop=50.0)
    with pytest.raises(PresetError, match=r"loading.stop: indentation 50 is at or past [0-9.]+, the full-contact "
                                          r"approach max z - mean z of realization 0") as caught:
        frictionlab.run(preset, out=tmp_path / "run", **FAST)
    assert not (tmp_path / "run").exists() and "loading.control 'force'" in str(caught.value)
    full = float(str(caught.value).split("at or past ")[1].split(",")[0])
    below = frictionlab.run(with_loading(preset, stop=0.9 * full), out=None, **FAST)
    assert below.status == "completed" and below.realizations == (1, 1)
    done = cli("validate", "mdr-vs-halfspace", "--set", "solver.name=bem-halfspace", "--set", "loading.control=indentation",
               "--set", "loading.stop=50", "--set", "loading.start=0.1")  # fmt: skip
    assert done.returncode == 2 and "loading.stop: indentation 50 is at or past" in done.stderr, done.stderr


def test_a_refusal_of_the_loads_names_the_preset_it_is_about(tmp_path, cli):
    """Loads are checked once the preset is built: their refusal names the file (of several
    validated at once, the one at fault) and the built-in with its --set options, as a
    refusal of any other field does."""
    good = tmp_path / "good.yaml"
    good.write_text(json.dumps({**SURFACE, "solver": {"name": "bem-halfspace-free"}}), encoding="utf-8")
    bad = tmp_path / "bad.yaml"
    bad.write_text(json.dumps(with_loading({**SURFACE, "solver": {"name": "bem-halfspace-free"}}, stop=1e39)),
                   encoding="utf-8")  # fmt: skip
    done = cli("validate", str(good), str(bad), cwd=tmp_path)
    assert done.returncode == 2 and f"{bad}: 1 problem in preset" in done.stderr and str(good) not in done.stderr
    done = cli("run", "quickstart", "--set", "loading.unit=contact-fraction", "--set", "loading.start=0.1",
               "--set", "loading.stop=0.2", "--out", str(tmp_path / "run"), cwd=tmp_path)  # fmt: skip
    assert done.returncode == 2 and not (tmp_path / "run").exists()
    assert "error: built-in preset 'quickstart' --set loading.unit=contact-fraction" in done.stderr
    with pytest.raises(PresetError, match=r"f <= 1e\+30") as caught:
        frictionlab.run(bad, out=tmp_path / "api-run", **FAST)
    assert str(caught.value).startswith(f"{bad}: 1 problem in preset")


def test_the_free_solver_itself_refuses_a_load_past_its_arithmetic():
    z = np.random.default_rng(0).standard_normal((8, 8))
    with pytest.raises(ValueError, match=r"f = F / \(E\* h L\) <= 1e\+30"):
        BEMHalfSpaceFree().solve(Profile(z, 1.0, False), np.array([1e39]), "force", np.ones_like(z))
    with pytest.raises(ValueError, match=r"at most 1e\+30 times the height range"):
        BEMHalfSpaceFree().solve(Profile(z, 1.0, False), np.array([1e39]), "indentation", np.ones_like(z))


def test_loads_that_press_the_same_point_fit_no_law(tmp_path):
    preset = with_loading(SURFACE, start=1e-30, stop=1e-25, steps=6)
    with pytest.warns(UserWarning, match="run failed: no law: every load"):
        result = frictionlab.run(preset, out=tmp_path / "run", **FAST)
    assert result.fit is None and result.status == "failed"
    assert result.caveats[0].startswith("no law: every load") and "same points" in result.caveats[0]
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["fit"] is None and summary["caveats"] == result.caveats and summary["error"] == result.caveats[0]
    assert frictionlab.load(tmp_path / "run").fit is None


def test_loads_all_in_full_contact_fit_no_law_and_the_cli_says_so(tmp_path, cli):
    path = tmp_path / "full.yaml"
    path.write_text(json.dumps(with_loading(LINE, start=1e6, stop=1e7)))
    done = cli("run", path, "--out", tmp_path / "o", "--quiet", "--no-plot")
    assert done.returncode != 0 and "no law: the whole profile is in contact at every load" in done.stderr
    assert "R^2" not in done.stdout and "Traceback" not in done.stderr


def test_half_load_points_by_brute_force():
    rng = np.random.default_rng(1)
    for _ in range(50):
        loads = np.where(rng.random(9) < 0.4, 0.0, rng.random(9))
        total = loads.sum()
        best = min((k for k in range(1, 10) if np.sort(loads)[::-1][:k].sum() >= total / 2), default=0)
        assert half_load_points(loads) == (best if total > 0 else 0)


@pytest.mark.parametrize("steps", [15, 300])  # every share at once; a bisection over k (300 x 300 shares)
def test_springs_count_the_points_carrying_half_the_load_as_the_bisection_does(steps):
    z = np.random.default_rng(2).standard_normal(300)
    loads = np.geomspace(1e-3, 100, steps)
    fast = MDRSprings().solve(Profile(z, 1.0), loads, "force", np.ones_like(z))
    slow = BisectionSprings().solve(Profile(z, 1.0), loads, "force", np.ones_like(z))
    np.testing.assert_array_equal(fast.half_load_points, slow.half_load_points)
    assert fast.half_load_points[0] == 1 and np.all(fast.half_load_points <= fast.contact_count)


def test_a_spike_and_few_carriers_are_caveats_in_curve_csv_and_summary(tmp_path):
    z = np.random.default_rng(4).standard_normal((32, 32))
    z[10, 10] = z.mean() + 13 * z.std()  # a one-pixel spike 13 rms high
    np.save(tmp_path / "scan.npy", z)
    preset = {**SURFACE, "spectrum": {"name": "surface-file", "params": {"path": str(tmp_path / "scan.npy"),
              "spacing": 1.0}}, "solver": {"name": "bem-halfspace-free"}}  # fmt: skip
    result = frictionlab.run(with_loading(preset, start=1e-3, stop=30.0, steps=6), out=tmp_path / "run", **FAST)
    caveats = " | ".join(result.caveats)
    assert "stands 1" in caveats and "rms heights above the mean height (more than 8" in caveats
    assert "fewer than 5 points carry half the force" in caveats
    header = (tmp_path / "run" / "curve.csv").read_text().splitlines()[0]
    assert "half_load_points [" in header
    assert result.table["half_load_points"][0] == 1
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["half_load_points_at_first_load"] == 1 and summary["peak_height_rms"] > 8


def brute_edges(contact: np.ndarray, periodic: bool) -> int:
    ny, nx = contact.shape
    edges = 0
    for i in range(ny):
        for j in range(nx):
            for di, dj in ((0, 1), (1, 0)):
                k, m = i + di, j + dj
                if not periodic and (k >= ny or m >= nx):
                    continue
                edges += contact[i, j] != contact[k % ny, m % nx] if (k % ny, m % nx) != (i, j) else 0
    return edges


def test_contact_edges_without_wrapping_by_brute_force():
    rng = np.random.default_rng(6)
    for shape in ((1, 1), (1, 5), (4, 1), (3, 4), (6, 6)):
        for _ in range(10):
            contact = rng.random(shape) < 0.5
            assert contact_edges(contact, periodic=False) == brute_edges(contact, False)
            assert contact_edges(contact, periodic=True) == brute_edges(contact, True)
    contact = np.zeros((4, 4), bool)
    contact[:, 0] = True  # a column on the border: on a free map no edge on the left
    assert contact_edges(contact, periodic=False) == 4 and contact_edges(contact, periodic=True) == 8
    assert corrected_area_fraction(contact, periodic=False) == pytest.approx((4 - PERIMETER_COEFFICIENT * 4) / 16)


def test_the_free_boundary_s_corrected_area_of_a_hertz_contact_is_pi_a_squared():
    n, radius = 96, 400.0
    y, x = np.mgrid[:n, :n] - (n - 1) / 2
    z = -(x**2 + y**2) / (2 * radius)
    a = 16.0  # Hertz: F = 4 E* a^3 / (3 R)
    force = 4 * a**3 / (3 * radius)
    curve = BEMHalfSpaceFree(tolerance=1e-10, stop="tolerance").solve(Profile(z, 1.0, False), np.array([force]), "force",
                                                                       np.ones_like(z))  # fmt: skip
    exact = math.pi * a**2 / z.size
    corrected = float(curve.real_area_corrected[0])
    counted = float(curve.contact_fraction[0])
    assert corrected == pytest.approx(exact, rel=0.02)
    assert abs(corrected - exact) < abs(counted - exact)  # the correction brings the count nearer


@pytest.mark.parametrize("command", [
    "frictionlab validate quickstart --set loading.unit=f --set loading.start=1e-4 --set loading.stop=0.01",
    "frictionlab validate mdr-vs-halfspace --set solver.name=bem-halfspace-free --set loading.unit=contact-fraction "
    "--set loading.start=0.01 --set loading.stop=0.2",
    "frictionlab validate mdr-vs-halfspace --set solver.name=bem-halfspace-free --set loading.stop=1e39",
    "frictionlab run quickstart --set loading.start=1e4 --set loading.stop=1e5 --no-plot",
])  # fmt: skip
def test_the_loads_page_shows_what_the_commands_print(command, tmp_path, cli):
    """docs/how-to/loads.md: each output shown is printed by its command (wall times and folders aside)."""
    from tests.test_docs_outputs import ROOT, _comparable, _shown_block

    argv = command.split()
    done = cli(*argv[1:], cwd=tmp_path)
    printed = {line.strip() for line in (done.stdout + done.stderr).splitlines()}
    shown = [line.strip() for line in _shown_block("docs/how-to/loads.md", f"$ {command}") if _comparable(line)]
    assert ROOT.is_dir() and shown and not [line for line in shown if line not in printed]


def test_a_contact_fraction_search_says_its_load_and_stops_on_cancel(monkeypatch):
    import threading

    from frictionlab.compute import realization
    from frictionlab.plugin import SolveCancelled

    monkeypatch.setattr(realization, "ITERATION_EVENT_SECONDS", 0.0)  # every iteration heard
    scene = build_scene(with_loading(SURFACE, unit="contact-fraction", start=0.05, stop=0.3, steps=3))
    cancel, heard = threading.Event(), []

    def on_iteration(index, load, iteration, residual):
        heard.append(load)
        if load == 2:  # the search for the second load is under way: cancel
            cancel.set()

    with pytest.raises(SolveCancelled):
        realization.compute_realization(scene, 0, realization.SolveListeners(on_iteration=on_iteration), cancel)
    assert heard[0] == 1 and heard[-1] == 2  # the iterations of the search are said as their load's


def test_validate_warns_of_loads_past_full_contact(cli):
    done = cli("validate", "quickstart", "--set", "loading.stop=1e4")
    assert done.returncode == 0 and "caveat: the last loads are past full contact" in done.stdout, done.stderr
    done = cli("validate", "quickstart")
    assert done.returncode == 0 and "past full contact" not in done.stdout, done.stderr
    done = cli("validate", "quickstart", "--set", "loading.start=1e4", "--set", "loading.stop=1e5")
    assert done.returncode == 0 and "caveat: every load is past full contact" in done.stdout, done.stderr
    assert "lower the loads" in done.stdout and "the last loads" not in done.stdout


def test_a_contact_fraction_reached_at_the_first_touch_is_found_not_an_error():
    """A map whose top is a plateau of 128 points: any force touches all of them, so no force
    has exactly 3 in contact; the search shrank the force to 1e-132 and failed the realization
    ('no force found ... within 80 solves'). The first touch is accepted, with the plateau's count."""
    from frictionlab.preset.loads import forces_for_fractions

    heights = np.zeros((16, 16))
    heights[:, :8] = 1.0
    profile = Profile(heights=heights, spacing=1.0, periodic=False)
    solver = BEMHalfSpaceFree(youngs_modulus=1.0, poisson_ratio=0.0)
    forces = forces_for_fractions(solver, profile, np.array([0.01]), np.zeros_like(heights), first_guess=1.0)
    assert 0 < forces[0] <= 1e-9  # far below the first guess, 0.01
    count = solver.solve(profile, forces, "force", np.zeros_like(heights)).contact_count
    assert int(np.asarray(count)[0]) == 128


def test_fractions_a_plateau_covers_share_its_force_and_the_forces_never_decrease():
    """Fractions below a clipped map's plateau (half of its points at the top): each search
    stopped at some force below 1e-9 of its own first guess, and the forces went up and down
    (the run then refused them: 'the loads handed to the solver must not decrease')."""
    from frictionlab.preset.loads import forces_for_fractions

    heights = np.zeros((16, 16))
    heights[:, :8] = 1.0
    heights[:, 8:] = np.linspace(0.0, 0.5, 128).reshape(16, 8)  # below the plateau: distinct heights
    profile = Profile(heights=heights, spacing=1.0, periodic=False)
    solver = BEMHalfSpaceFree(youngs_modulus=1.0, poisson_ratio=0.0)
    fractions = np.array([0.01, 0.05, 0.1, 0.3, 0.45, 0.6])
    forces = forces_for_fractions(solver, profile, fractions, np.zeros_like(heights), first_guess=1.0)
    assert np.all(np.diff(forces) >= 0), forces
    assert np.unique(forces[:5]).size == 1  # the plateau's 128 points cover 1 % to 45 %: one force, its first touch
    assert forces[5] > forces[4]  # 60 % needs more than the plateau
    counts = np.asarray(solver.solve(profile, forces, "force", np.zeros_like(heights)).contact_count)
    assert np.all(counts >= np.ceil(fractions * heights.size - 1e-9)), counts

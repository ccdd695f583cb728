"""What a plugin answers before a run starts (its declarations' values, realization 0's
profile and its slopes, the load of full contact) is checked where it is taken: a broken answer is refused
by the plugin's name, and an exception raised in a third party's plugin code is told as
that plugin's fault, never as frictionlab's internal error."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest
from pydantic import Field

from frictionlab.errors import PluginError
from frictionlab.plugin.outputs import RandomWatch
from frictionlab.preset import build_scene
from frictionlab.preset.loads import load_scales

from .conftest import SMALL_PRESET
from .testing.fakes import GoodSolver, GoodSlopes, GoodSpectrum

BROKEN = {
    "text-rms": (GoodSpectrum, {"rms_height": lambda self: "1.0"}, "rms_height() must be finite and > 0. Got '1.0'"),
    "no-rms": (GoodSpectrum, {"rms_height": lambda self: -1.0}, "rms_height() must be finite and > 0. Got -1.0"),
    "text-grid": (GoodSpectrum, {"grid_shape": lambda self: "big"}, "grid_shape() must be None or 1 whole number(s)"),
    "wrong-grid": (GoodSpectrum, {"grid_shape": lambda self: (7,)},
                   "grid_shape() must be None or the shape generate() makes, (128,). Got (7,)"),
    "text-periodic": (GoodSpectrum, {"periodic": lambda self: "yes"}, "periodic() must be True or False. Got 'yes'"),
    "nan-heights": (GoodSpectrum, {"generate": lambda self, rng: GoodSpectrum.generate(self, rng).__class__(
        np.full(128, np.nan), 1.0)}, "Profile.heights must be finite"),
    "flag-periodic": (GoodSpectrum, {"generate": lambda self, rng: GoodSpectrum.generate(self, rng).__class__(
        np.sin(np.arange(128.0)), 1.0, periodic=False)},
        "Profile.periodic must be what periodic() declares, True. Got False instead."),
    "global-random": (GoodSpectrum, {"generate": lambda self, rng: GoodSpectrum.generate(
        self, np.random.default_rng(np.random.randint(2**31)))}, "generate() used numpy's global random state"),
    "own-seed": (GoodSpectrum, {"generate": lambda self, rng: GoodSpectrum.generate(self, np.random.default_rng(0))},
                 "different seeds gave identical heights"),
    "zero-slopes": (GoodSlopes, {"slopes": lambda self, heights, spacing, periodic=True: np.zeros_like(heights)},
                    "slopes() gave 0 at every point of a line whose heights span "),
    "no-stiffness": (GoodSolver, {"stiffness": lambda self: 0.0}, "stiffness() must be finite and > 0. Got 0.0"),
    "nan-tolerance": (GoodSolver, {"tolerance": lambda self: float("nan")},
                      "tolerance() must be None or a number finite and > 0. Got nan"),
    "text-full": (GoodSolver, {"full_contact_load": lambda self, profile: "lots"},
                  "full_contact_load(profile) must be None or a finite number >= 0. Got 'lots'"),
    "nan-indentation": (GoodSolver, {"full_contact_indentation": lambda self, profile: float("nan")},
                        "full_contact_indentation(profile) must be None or a finite number >= 0. Got nan"),
    "single-slopes": (GoodSlopes, {"slopes": lambda self, heights, spacing, periodic=True: GoodSlopes.slopes(
        self, heights, spacing, periodic).astype(np.float32)}, "slopes() must be float64 (double precision)"),
    "text-undefined": (GoodSlopes, {"undefined_points": lambda self, periodic: "no"},
                       "undefined_points(periodic) must be False for a periodic profile"),
}
SLOTS = {GoodSpectrum: "spectrum", GoodSolver: "solver", GoodSlopes: "slope"}
GOOD = {**{k: v for k, v in SMALL_PRESET.items() if k not in SLOTS.values()},
        "spectrum": {"name": "good-spectrum"}, "solver": {"name": "good-solver"}, "slope": {"name": "good-slopes"}}


def _broken_preset(register_plugin, case: str):
    """(preset data, registry) of BROKEN[case]'s plugin beside good ones of the other kinds."""
    base, methods, _ = BROKEN[case]
    broken = type("Broken", (base,), {"name": f"broken-{SLOTS[base]}", **methods})
    registry = register_plugin(broken)
    for cls in {GoodSpectrum, GoodSolver, GoodSlopes} - {base}:
        register_plugin(cls)
    return {**GOOD, SLOTS[base]: {"name": broken.name}}, registry


@pytest.mark.parametrize("case", BROKEN)
def test_a_broken_answer_is_refused_by_the_plugin_s_name(register_plugin, case):
    """Taken as it came, each was an internal error (grid_shape as text, full contact as text),
    a message about the preset's magnitudes (a negative h), or a scene built on it."""
    base, _, problem = BROKEN[case]
    data, registry = _broken_preset(register_plugin, case)
    with pytest.raises(PluginError) as excinfo:
        load_scales(build_scene(data, registry=registry))
    assert str(excinfo.value) == (f"{SLOTS[base]} 'broken-{SLOTS[base]}' (tests.test_plugin_answers.Broken from "
                                  f"tests.test_plugin_answers) broke the plugin contract: {problem}"
                                  + str(excinfo.value).partition(problem)[2])


@pytest.mark.parametrize("case", BROKEN)
def test_a_run_refuses_before_it_starts_what_validate_refuses(register_plugin, tmp_path, case):
    """Taken as they came, a run of a generator ignoring its rng completed with a fit over copies of
    one line (realization 0 alone failed), one whose grid_shape() was not its shape completed, and
    one whose rms_height() raised failed every realization: validate refused each."""
    from frictionlab.api import run_scene, scene_record
    from frictionlab.options import RunOptions

    problem = BROKEN[case][2]
    data, registry = _broken_preset(register_plugin, case)
    with pytest.raises(PluginError) as validated:
        scene_record(build_scene(data, registry=registry))
    for out in (None, tmp_path / "run"):
        with pytest.raises(PluginError) as ran:
            run_scene(build_scene(data, registry=registry), out, RunOptions(workers=1), plot=False)
        assert str(ran.value) == str(validated.value) and problem in str(ran.value)
    assert not (tmp_path / "run").exists()  # refused before the folder was made


def test_an_exception_in_a_plugin_s_code_is_told_as_its_fault(register_plugin):
    def rms_height(self):
        return 1 / 0

    broken = type("Raising", (GoodSpectrum,), {"name": "raising-spectrum", "rms_height": rms_height})
    registry = register_plugin(broken)
    for cls in (GoodSolver, GoodSlopes):
        register_plugin(cls)
    with pytest.raises(ZeroDivisionError) as excinfo:
        load_scales(build_scene({**GOOD, "spectrum": {"name": "raising-spectrum"}}, registry=registry))
    fault = registry.at_fault(excinfo.value)
    assert isinstance(fault, PluginError)
    assert str(fault).startswith("spectrum 'raising-spectrum' (tests.test_plugin_answers.Raising from "
                                 "tests.test_plugin_answers) raised ZeroDivisionError: division by zero in "
                                 "rms_height() at test_plugin_answers.py:")
    assert "the plugin is at fault" in str(fault)


def test_an_exception_in_frictionlab_or_a_builtin_is_no_plugin_s_fault(frictionlab_registry):
    from frictionlab_solvers.checks import check_control

    with pytest.raises(ValueError) as excinfo:
        check_control("sideways")
    assert frictionlab_registry.at_fault(excinfo.value) is None
    with pytest.raises(ZeroDivisionError) as excinfo:
        1 / 0
    assert frictionlab_registry.at_fault(excinfo.value) is None


def _filled(seed: int, dtype) -> np.ndarray:
    """A small array of ``dtype`` with, for floats, NaN and ±inf strewn at random (or none)."""
    rng = np.random.default_rng(seed)
    size = int(rng.integers(1, 9))
    if not np.issubdtype(dtype, np.floating):
        return rng.integers(-(2**62), 2**62, size=size, dtype=dtype)
    values = rng.normal(size=size) * 10.0 ** rng.integers(-300, 300)
    for special in (np.nan, np.inf, -np.inf):
        values[rng.random(size) < rng.choice([0.0, 0.3, 1.0])] = special
    return values


@pytest.mark.parametrize("nan", [False, True])
@pytest.mark.parametrize("dtype", [np.float64, np.int64])
def test_an_array_is_refused_as_not_finite_exactly_where_an_entry_is(nan, dtype):
    """array_problem's test of finiteness (by the array's extremes) agrees, entry by entry
    brute force, with a mask of every entry, for arrays all NaN, all inf, mixed or clean."""
    from frictionlab.plugin.outputs import array_problem

    for seed in range(300):
        value = _filled(seed, dtype)
        bad = np.isinf(value) if nan else ~np.isfinite(value)
        problem = array_problem("a", value, floating=False, nan=nan)
        assert (problem is not None) == bool(bad.any()), (seed, value)


def test_a_non_finite_array_is_told_with_its_first_bad_entry_and_where():
    """'Got 1 non-finite value(s)' left the plugin's author to search the array."""
    from frictionlab.plugin.outputs import array_problem

    line = np.arange(6.0)
    line[[2, 4]] = np.nan, np.inf
    assert array_problem("Profile.heights", line) == (
        "Profile.heights must be finite. Got 2 non-finite value(s), the first nan at index 2.")
    surface = np.zeros((3, 4))
    surface[1, 2] = -np.inf
    assert array_problem("slopes()", surface, nan=True) == (
        "slopes() must be finite. Got 1 non-finite value(s), the first -inf at index (1, 2).")


def test_the_slope_scale_is_found_past_nan_slopes():
    """slope_scale brings the largest slope in magnitude (NaN ones passed by) near 1 by a power
    of two, and leaves slopes that square safely as they are."""
    from frictionlab.compute.realization import slope_scale

    for largest in (1e300, -1e300, 1e-300, -1e-300, 3.0):
        slopes = np.array([np.nan, 0.5 * largest, largest, np.nan, 0.0])
        scale = slope_scale(slopes)
        expected = 1.0 if abs(largest) == 3.0 else 2.0 ** -np.frexp(abs(largest))[1]
        assert scale == expected, largest
    assert slope_scale(np.full(4, np.nan)) == 1.0 and slope_scale(np.array([1.0, np.inf])) == 1.0


def test_negative_slopes_on_a_surface_are_refused_where_a_run_takes_them():
    """A surface's slopes are |grad z|; a line's keep their sign. A run took negative ones on."""
    from frictionlab.plugin import Profile
    from frictionlab.plugin.outputs import slopes_problem

    z = np.linspace(-1.0, 1.0, 64).reshape(8, 8)
    assert slopes_problem(GoodSlopes(), z, Profile(z, 1.0)) == (
        "slopes() on a surface must be gradient magnitudes |grad z| >= 0. Got a minimum of -1.")
    assert slopes_problem(GoodSlopes(), np.abs(z), Profile(z, 1.0)) is None
    assert slopes_problem(GoodSlopes(), z[0], Profile(z[0], 1.0)) is None


@pytest.mark.parametrize("summary, said", [
    ({"file": "a.csv", "shape": [128], "spacing": 1.0, "unit": None, "rms_height": float("nan")},
     "Out of range float values are not JSON compliant"),
    ({"file": "a.csv", "shape": [128], "spacing": 1.0, "unit": None, "rms_height": 1.0, "when": object()},
     "Object of type object is not JSON serializable"),
    ({"file": "a.csv"}, "input_summary() must give at least file, shape, spacing, unit and rms_height"),
])
def test_an_input_summary_no_json_holds_is_refused_as_the_run_starts_and_by_validate(register_plugin, summary, said):
    """Taken as it came, the run computed every realization, then ended in an internal error
    writing summary.json (and validate --json in one writing its answer)."""
    from frictionlab.api import scene_record
    from frictionlab.runs.inputrecord import what_was_read

    broken = type("Summarised", (GoodSpectrum,), {"name": "broken-spectrum", "input_summary": lambda self: summary})
    registry = register_plugin(broken)
    for cls in (GoodSolver, GoodSlopes):
        register_plugin(cls)
    scene = build_scene({**GOOD, "spectrum": {"name": "broken-spectrum"}}, registry=registry)
    for read in (what_was_read, scene_record):
        with pytest.raises(PluginError, match="broke the plugin contract: input_summary()") as excinfo:
            read(scene)
        assert said in str(excinfo.value)


def _noisy_generate(self, rng):
    np.random.standard_normal()  # numpy's global state: another number for each worker count
    return GoodSpectrum.generate(self, rng)


def _in_place_slopes(self, heights, spacing, periodic=True):
    heights -= heights.mean()  # the profile the solver is given next changes
    return GoodSlopes.slopes(self, heights, spacing, periodic)


def _solved(method, values, source=None):
    """A good solve() whose ``method`` is ``values`` of its own (or of its ``source``: a declared array it gives)."""
    def solve(self, profile, loads, control, slopes):
        curve = GoodSolver.solve(self, profile, loads, control, slopes)
        return replace(curve, **{method: values(getattr(curve, source or method))})

    return solve


def _one_draw(method):
    """``method`` of a good plugin, drawing one number of numpy's global state first."""
    def drawing(self, *args, **kwargs):
        np.random.randint(2)  # one 32-bit word of the key
        return method(self, *args, **kwargs)

    return drawing


RUN_BROKEN = {
    "global-random": (GoodSpectrum, {"generate": _noisy_generate}, "generate() used numpy's global random state"),
    "own-seed": (GoodSpectrum, {"generate": lambda self, rng: GoodSpectrum.generate(self, np.random.default_rng(0))},
                 "different seeds gave identical heights; draw all randomness from the rng argument"),
    "unseeded": (GoodSpectrum, {"generate": lambda self, rng: GoodSpectrum.generate(self, np.random.default_rng())},
                 "the same seed gave different heights; draw all randomness from the rng argument"),
    "one-draw-generate": (GoodSpectrum, {"generate": _one_draw(GoodSpectrum.generate)},
                          "generate() used numpy's global random state"),
    "one-draw-slopes": (GoodSlopes, {"slopes": _one_draw(GoodSlopes.slopes)}, "slopes() used numpy's global random state"),
    "one-draw-solve": (GoodSolver, {"solve": _one_draw(GoodSolver.solve)}, "solve() used numpy's global random state"),
    "one-draw-own-height": (GoodSpectrum, {"profile_rms_height": _one_draw(lambda self, profile: 1.0)},
                            "profile_rms_height() used numpy's global random state"),
    "in-place": (GoodSlopes, {"slopes": _in_place_slopes}, "(a plugin must leave the arrays it is given as they are (heights, slopes, loads): compute into new ones)"),
    "negative-count": (GoodSolver, {"solve": _solved("contact_count", lambda c: c - c.max())},
                       "solve().contact_count must lie in 0 .. 128 (points of the profile). Got array([-"),
    "reversed-force": (GoodSolver, {"solve": _solved("force", lambda f: f[::-1].copy())},
                       "solve(..., control='force').force must report the loads asked for"),
    "reversed-indentation": (GoodSolver, {"solve": _solved("indentation", lambda d: d[::-1].copy())},
                             "solve(..., control='force').indentation must not decrease as the load grows. Got "),
    "reversed-count": (GoodSolver, {"solve": _solved("contact_count", lambda c: c[::-1].copy())},
                       "solve(..., control='force').contact_count must not decrease as the load grows. Got "),
    "negative-rms": (GoodSolver, {"solve": _solved("slope_rms_contact", lambda r: -r)},
                     "solve().slope_rms_contact must lie in [0, max |slope| = "),
    "rms-past-the-steepest": (GoodSolver, {"solve": _solved("slope_rms_contact", lambda r: r * 1e6)},
                              "solve().slope_rms_contact must lie in [0, max |slope| = "),
    "negative-gradient": (GoodSolver, {"real_gradient": True, "solve": _solved("real_gradient_rms", lambda r: -r, "slope_rms_contact")},
                          "solve().real_gradient_rms is an rms slope and must be >= 0. Got array([-"),
    "area-past-the-count": (GoodSolver, {"corrected_area": True,
                                         "solve": _solved("real_area_corrected", lambda a: 2 * a, "contact_fraction")},
                            "solve().real_area_corrected must lie in [0, contact_fraction]"),
}


@pytest.mark.parametrize("case", RUN_BROKEN)
def test_a_plugin_breaking_the_contract_within_a_realization_fails_it_naming_the_plugin(register_plugin, case):
    """Each of these ran to a result: numbers that changed with the worker count (global random
    state), with the loads (a profile changed in place), or counts no profile has."""
    from frictionlab.compute.realization import compute_realization

    base, methods, problem = RUN_BROKEN[case]
    broken = type("Broken", (base,), {"name": f"broken-{SLOTS[base]}", "__module__": "broken_plugin", **methods})
    registry = register_plugin(broken)
    for cls in {GoodSpectrum, GoodSolver, GoodSlopes} - {base}:
        register_plugin(cls)
    scene = build_scene({**GOOD, SLOTS[base]: {"name": broken.name}}, registry=registry)
    error = compute_realization(scene, 0).error
    assert error is not None and problem in error
    assert f"{SLOTS[base]} 'broken-{SLOTS[base]}' (broken_plugin.Broken from " in error



@pytest.mark.parametrize("first", ["nothing", "a Gaussian", "the rest of the key"])
def test_one_draw_is_caught_whatever_numpy_s_global_state_holds(register_plugin, first):
    """A realization looks at numpy's global state between its plugin calls by its key and
    position alone, read in full once: one Gaussian drawn of a pair cached before the realization
    moves neither, and a draw that ends the key renews it (the position as it was)."""
    from frictionlab.compute.realization import compute_realization

    def solve(self, profile, loads, control, slopes):
        if first == "a Gaussian":
            np.random.standard_normal()  # the cached second of the pair: key and position unchanged
        else:
            np.random.randint(2**32, size=624 if first == "the rest of the key" else 1, dtype=np.uint64)
        return GoodSolver.solve(self, profile, loads, control, slopes)

    broken = type("Broken", (GoodSolver,), {"name": "broken-solver", "__module__": "broken_plugin", "solve": solve})
    registry = register_plugin(broken)
    for cls in (GoodSpectrum, GoodSlopes):
        register_plugin(cls)
    scene = build_scene({**GOOD, "solver": {"name": "broken-solver"}}, registry=registry)
    state = np.random.get_state()
    try:
        np.random.seed(5)
        RandomWatch()  # as a realization before this one starts: it finds no Gaussian cached
        if first == "a Gaussian":
            np.random.standard_normal()  # one of a pair: the other is cached
            assert np.random.get_state()[3] == 1
        error = compute_realization(scene, 0).error
    finally:
        np.random.set_state(state)
    assert error is not None and "solve() used numpy's global random state" in error


def test_loads_out_of_order_fail_the_realization_before_the_solver_sees_them(register_plugin):
    """Taken as they came, loads that decrease were solved, and the curve kept in their order."""
    from frictionlab.compute.realization import compute_realization

    registry = register_plugin(GoodSolver)
    for cls in (GoodSpectrum, GoodSlopes):
        register_plugin(cls)
    scene = build_scene(GOOD, registry=registry)
    scene.__dict__["solver_loads"] = scene.solver_loads[::-1].copy()  # as a caller's own scene might hold them
    error = compute_realization(scene, 0).error
    assert error is not None and error.startswith("ValueError: the loads handed to the solver must not decrease. Got ")


@pytest.mark.parametrize("drop, refused", [(1e-5, False), (1e-2, True)])
def test_under_indentation_control_a_force_that_falls_is_refused_past_an_iterative_solver_s_stop(
        register_plugin, drop, refused):
    """Taken as it came, forces out of order under indentation control were kept (the count of
    each load then paired with another's force); an iterative solver's stop may leave a drop of
    a relative 1e-3."""
    from frictionlab.compute.realization import compute_realization

    def solve(self, profile, loads, control, slopes):
        curve = GoodSolver.solve(self, profile, loads, control, slopes)
        force = curve.force.copy()
        force[-1] = force[-2] - drop * force.max()
        return replace(curve, force=force)

    class Params(GoodSolver.Params):
        tolerance: float = Field(1e-6, gt=0, description="relative tolerance")

    broken = type("Iterative", (GoodSolver,), {"name": "iterative-solver", "__module__": "broken_plugin",
                                               "solve": solve, "Params": Params, "tolerance_param": "tolerance"})
    registry = register_plugin(broken)
    for cls in (GoodSpectrum, GoodSlopes):
        register_plugin(cls)
    loading = {**GOOD["loading"], "control": "indentation", "start": 0.1, "stop": 1.0}
    scene = build_scene({**GOOD, "solver": {"name": "iterative-solver"}, "loading": loading}, registry=registry)
    error = compute_realization(scene, 0).error
    if refused:
        assert error is not None and "solve(..., control='indentation').force must not decrease" in error
    else:
        assert error is None


@pytest.mark.parametrize("declared", [False, True])
def test_a_spectrum_ignoring_its_rng_fails_realization_0_alone_unless_declared_deterministic(register_plugin, declared):
    """Once a run: realization 0 is made again, and realization 1's profile once, to be compared;
    the other realizations are not checked again. A spectrum declaring ``deterministic`` may give
    every seed one profile."""
    from frictionlab.compute.realization import compute_realization

    def fixed(self, rng):
        return GoodSpectrum.generate(self, np.random.default_rng(0))

    cls = type("Fixed", (GoodSpectrum,), {"name": "fixed-spectrum", "__module__": "fixed_plugin",
                                          "generate": fixed, "deterministic": declared})
    registry = register_plugin(cls)
    for other in (GoodSolver, GoodSlopes):
        register_plugin(other)
    scene = build_scene({**GOOD, "spectrum": {"name": cls.name}}, registry=registry)
    errors = [compute_realization(scene, i).error for i in range(3)]
    if declared:
        assert errors == [None, None, None]
    else:
        assert errors[0].startswith("PluginError: spectrum 'fixed-spectrum' (fixed_plugin.Fixed from fixed_plugin) "
                                    "broke the plugin contract: different seeds gave identical heights")
        assert errors[1:] == [None, None]


def test_realization_1_s_own_failure_is_not_realization_0_s(register_plugin):
    """Realization 0's check makes realization 1's profile: where that raises, realization 1 says so itself."""
    from frictionlab.compute.realization import compute_realization
    from frictionlab.preset.seeds import realization_rng

    def generate(self, rng):
        if rng.bit_generator.state == realization_rng(GOOD["seed"], 1).bit_generator.state:
            raise RuntimeError("realization 1's own failure")
        return GoodSpectrum.generate(self, rng)

    registry = register_plugin(type("Second", (GoodSpectrum,), {"name": "second-fails", "generate": generate}))
    for cls in (GoodSolver, GoodSlopes):
        register_plugin(cls)
    scene = build_scene({**GOOD, "spectrum": {"name": "second-fails"}}, registry=registry)
    assert compute_realization(scene, 0).error is None
    assert "realization 1's own failure" in compute_realization(scene, 1).error

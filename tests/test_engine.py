"""The ensemble engine: seeding, executors, events, cancellation, scaling laws."""

import threading

import numpy as np
import pytest

from frictionlab import SpectrumGenerator, hookimpl
from frictionlab.compute import engine
from frictionlab.plugin import PluginParams, Profile
from frictionlab.compute.realization import compute_realization
from frictionlab.preset import Scene
from frictionlab.compute.executors import pool_context
from frictionlab.options import RunOptions

from .testing.fakes import replace_curve


def same_outcome(one, two):
    for key in one.per_realization:
        np.testing.assert_array_equal(one.per_realization[key], two.per_realization[key])
    np.testing.assert_array_equal(one.xi, two.xi)
    np.testing.assert_array_equal(one.f, two.f)
    assert one.fit == two.fit


def test_same_seed_same_numbers_for_one_and_two_workers(make_scene):
    scene = make_scene({"realizations": 12})
    serial = engine.run(scene, RunOptions(workers=1))
    pooled = engine.run(scene, RunOptions(workers=2, executor="processes"))  # a pool, however short the run
    assert serial.status == pooled.status == "completed"
    assert serial.done == 12
    same_outcome(serial, pooled)


def test_other_seed_other_numbers(make_scene):
    one = engine.run(make_scene({"seed": 1}), RunOptions(workers=1))
    two = engine.run(make_scene({"seed": 2}), RunOptions(workers=1))
    assert not np.array_equal(one.per_realization["xi"], two.per_realization["xi"])


def test_a_realization_does_not_depend_on_the_others(make_scene):
    """Realization 5 computed alone equals row 5 of a full run: seeds are addressed,
    not drawn in sequence."""
    scene = make_scene({"realizations": 8})
    full = engine.run(scene, RunOptions(workers=1))
    alone = compute_realization(scene, 5)
    np.testing.assert_array_equal(alone.xi, full.per_realization["xi"][5])
    np.testing.assert_array_equal(alone.contact_count, full.per_realization["contact_count"][5])


class Recorder:
    def __init__(self, cancel_after=None, cancel=None):
        self.events = []
        self.cancel_after, self.cancel = cancel_after, cancel

    @hookimpl
    def run_started(self, run):
        self.events.append(("started", run.total))

    @hookimpl
    def realization_done(self, result, done, total):
        self.events.append(("done", result.index, done, total))
        if self.cancel_after is not None and done >= self.cancel_after:
            self.cancel.set()

    @hookimpl
    def realization_failed(self, result, done):
        self.events.append(("failed", result.index, done))

    @hookimpl
    def run_finished(self, outcome):
        self.events.append(("finished", outcome.status, outcome.done))


def test_listeners_see_every_realization_between_start_and_finish(make_scene):
    recorder = Recorder()
    outcome = engine.run(make_scene({"realizations": 6}), RunOptions(workers=2), listeners=[recorder])
    kinds = [e[0] for e in recorder.events]
    assert kinds[0] == "started" and kinds[-1] == "finished"
    assert kinds.count("done") == 6
    assert sorted(e[1] for e in recorder.events if e[0] == "done") == list(range(6))
    assert [e[2] for e in recorder.events if e[0] == "done"] == list(range(1, 7))
    assert recorder.events[-1] == ("finished", "completed", outcome.done)


@pytest.mark.parametrize("workers", [1, 2])
def test_cancel_keeps_what_finished(make_scene, workers):
    cancel = threading.Event()
    recorder = Recorder(cancel_after=3, cancel=cancel)
    scene = make_scene({"realizations": 400, "spectrum": {"params": {"points": 4096}}})
    outcome = engine.run(scene, RunOptions(workers=workers), listeners=[recorder], cancel=cancel)
    assert outcome.status == "cancelled"
    assert 3 <= outcome.done < 400
    assert outcome.fit is not None
    # the kept rows are exactly those realizations, as a full run would give them
    for row, index in enumerate(outcome.indices[:3]):
        np.testing.assert_array_equal(outcome.per_realization["xi"][row], compute_realization(scene, index).xi)


class Flaky(SpectrumGenerator):
    """A spectrum that fails for one in three realizations (decided by its rng)."""

    name = "flaky"
    summary = "test double: fails for some realizations"

    class Params(PluginParams):
        pass

    def generate(self, rng):
        if rng.random() < 1 / 3:
            raise RuntimeError("bad luck")
        x = np.arange(256)
        return Profile(np.sin(2 * np.pi * x / 256) + 0.1 * rng.standard_normal(256), 1.0)

    def rms_height(self):
        return 1.0


def test_failures_are_carried_on_results_and_the_run_goes_on(make_scene):
    base = make_scene({"realizations": 30})
    scene = Scene(preset=base.preset, spectrum=Flaky(), solver=base.solver, slope=base.slope)
    recorder = Recorder()
    outcome = engine.run(scene, RunOptions(workers=2), listeners=[recorder])
    failed = [e[1] for e in recorder.events if e[0] == "failed"]
    assert outcome.status == "completed"
    assert 0 < len(outcome.failures) < 30
    assert sorted(failed) == [index for index, _ in outcome.failures]
    assert all("RuntimeError: bad luck" in error for _, error in outcome.failures)
    assert outcome.done == 30 - len(failed)
    assert set(outcome.indices) == set(range(30)) - set(failed)


def test_a_constant_line_fails_with_a_clear_message(make_scene):
    base = make_scene()

    class Flat(Flaky):
        name = "flat"
        deterministic = True  # one line for every seed, by design

        def generate(self, rng):
            return Profile(np.ones(64), 1.0)

    scene = Scene(preset=base.preset, spectrum=Flat(), solver=base.solver, slope=base.slope)
    result = compute_realization(scene, 0)
    assert not result.ok
    assert "rms slope of the whole line is 0.0" in result.error


def _broken(plugin, kind, method, change):
    """``plugin`` (its class and parameters) whose ``method`` returns its answer passed through ``change``."""
    base = type(plugin)

    def broken(self, *args):
        return change(getattr(base, method)(self, *args))

    return type(f"Broken{kind.title()}", (base,), {"name": f"broken-{kind}", method: broken})(plugin.params)


BROKEN_ANSWERS = {
    "list-heights": ("spectrum", "generate", lambda p: Profile(list(p.heights), p.spacing), "Profile.heights must be a numpy array. Got list"),
    "text-heights": ("spectrum", "generate", lambda p: Profile(p.heights.astype(str), p.spacing), "Profile.heights must be float64"),
    "nan-heights": ("spectrum", "generate", lambda p: Profile(p.heights * np.nan, p.spacing), "Profile.heights must be finite"),
    "column": ("spectrum", "generate", lambda p: Profile(p.heights[:, None], p.spacing), "Profile.heights must be 1-D"),
    "heights-only": ("spectrum", "generate", lambda p: p.heights, "generate() must return a frictionlab.Profile"),
    "no-spacing": ("spectrum", "generate", lambda p: Profile(p.heights, 0.0), "Profile.spacing must be finite and > 0"),
    "short-slopes": ("slope", "slopes", lambda s: s[:-1], "slopes() must have shape (64,). Got (63,)"),
    "nan-slopes": ("slope", "slopes", lambda s: s * np.nan, "slopes() must be finite"),
    # was 'the rms slope of the whole line is 0.0 (is the line constant?)', naming no plugin
    "zero-slopes": ("slope", "slopes", np.zeros_like, "slopes() gave 0 at every point of a line whose heights span "),
    "short-curve": ("solver", "solve", lambda c: replace_curve(c, slope_rms_contact=c.slope_rms_contact[:-1]),
                    "solve().slope_rms_contact must have shape (12,). Got (11,)"),
    "text-counts": ("solver", "solve", lambda c: replace_curve(c, contact_count=c.contact_count.astype(str)),
                    "solve().contact_count must be real numbers"),
    "half-counts": ("solver", "solve", lambda c: replace_curve(c, contact_count=c.contact_count + 0.5),
                    "solve().contact_count must hold whole numbers"),
    "not-a-curve": ("solver", "solve", lambda c: {"force": c.force}, "solve() must return a frictionlab.ContactCurve"),
}


@pytest.mark.parametrize("case", BROKEN_ANSWERS)
def test_a_plugin_answer_that_breaks_the_contract_is_refused_by_the_plugin_s_name(make_scene, case):
    """Taken as it came, such an answer ended the run in an internal error (a curve one load
    short), a message about something else (NaN heights: 'is the line constant?'), or a run
    that completed on nonsense (heights or counts as text)."""
    kind, method, change, problem = BROKEN_ANSWERS[case]
    scene = make_scene({"realizations": 2, "spectrum": {"params": {"points": 64}}, "loading": {"steps": 12}})
    slots = {"spectrum": scene.spectrum, "solver": scene.solver, "slope": scene.slope}
    slots[kind] = _broken(slots[kind], kind, method, change)
    result = compute_realization(Scene(preset=scene.preset, **slots), 0)
    assert not result.ok
    cls = type(slots[kind])
    assert result.error == (f"PluginError: {kind} 'broken-{kind}' (tests.test_engine.{cls.__qualname__} from "
                            f"tests.test_engine) broke the plugin contract: {result.error.split('contract: ')[1]}")
    assert result.error.split("contract: ")[1].startswith(problem)


SCALINGS = {
    # exact scaling laws: z -> s z with F -> s F. s a power of two scales every operation exactly.
    "heights": ({"spectrum": {"params": {"rms_height": 4.0}}}, 4.0, 1e-13),
    # E -> s E with F -> s F.
    "modulus": ({"solver": {"params": {"youngs_modulus": 3.7}}}, 3.7, 1e-12),
    # only f, H, N and the cut-offs in units of dx matter: F = f E* h L with L = N dx.
    "spacing": ({"spectrum": {"params": {"spacing": 0.25}}}, 0.25, 1e-12),
}


@pytest.mark.parametrize("changes, s, rtol", SCALINGS.values(), ids=SCALINGS)
def test_scaling_laws_leave_counts_xi_and_f_unchanged(make_scene, changes, s, rtol):
    base = engine.run(make_scene(), RunOptions(workers=1))
    scaled = engine.run(make_scene({**changes, "loading": {"start": 0.5 * s, "stop": 20.0 * s}}), RunOptions(workers=1))
    np.testing.assert_array_equal(base.per_realization["contact_count"], scaled.per_realization["contact_count"])
    np.testing.assert_allclose(scaled.xi, base.xi, rtol=rtol)
    np.testing.assert_allclose(scaled.f, base.f, rtol=rtol)


def test_full_contact_gives_xi_one(make_scene):
    """Far past full contact every point touches and xi must be exactly 1."""
    outcome = engine.run(make_scene({"loading": {"start": 1e5, "stop": 1e6, "steps": 4}}), RunOptions(workers=1))
    assert np.all(outcome.per_realization["contact_count"] == 1024)
    np.testing.assert_array_equal(outcome.per_realization["xi"], 1.0)


def test_only_what_the_scene_needs_is_kept(make_scene):
    force = engine.run(make_scene({"realizations": 3}), RunOptions(workers=1))
    assert set(force.per_realization) == {"index", "xi", "contact_count", "indentation", "slope_rms_line",
                                           "measured_rms_height", "half_load_points"}
    indentation = engine.run(make_scene({"realizations": 3, "loading": {"control": "indentation", "start": 0.1, "stop": 2.0}}), RunOptions(workers=1))
    assert "force" in indentation.per_realization
    assert indentation.per_realization["force"].shape == (3, 16)
    # forces grow with indentation in every realization
    assert np.all(np.diff(indentation.per_realization["force"], axis=1) > 0)


def test_with_threads_alive_the_pool_uses_forkserver_and_gives_the_same_numbers(make_scene):
    """Forking a threaded process is unsafe (a front end runs the engine in a
    thread): then the pool starts by forkserver, which pickles the scene."""
    scene = make_scene({"realizations": 6})
    serial = engine.run(scene, RunOptions(workers=1))
    release = threading.Event()
    bystander = threading.Thread(target=release.wait)
    bystander.start()
    try:
        assert pool_context().get_start_method() == "forkserver"
        pooled = engine.run(scene, RunOptions(workers=2, executor="processes"))
    finally:
        release.set()
        bystander.join()
    # fork again once the bystander is gone (unless a Dask client left its threads in this process)
    assert pool_context().get_start_method() == ("fork" if threading.active_count() == 1 else "forkserver")
    same_outcome(serial, pooled)


def test_a_run_where_every_realization_failed_is_failed_not_completed(make_scene):
    base = make_scene({"realizations": 4})

    class Broken(Flaky):
        name = "broken"

        def generate(self, rng):
            raise RuntimeError("unreadable scan")

    scene = Scene(preset=base.preset, spectrum=Broken(), solver=base.solver, slope=base.slope)
    outcome = engine.run(scene, RunOptions(workers=1))
    assert outcome.done == 0 and len(outcome.failures) == 4
    assert outcome.status == "failed"
    assert "no realization finished" in outcome.error and "unreadable scan" in outcome.error


def test_ctrl_c_during_the_fit_lets_the_fit_finish_and_the_run_is_summarised(make_scene, monkeypatch):
    import os
    import signal

    import frictionlab.compute.ensemble

    fit = frictionlab.compute.ensemble.fit_log_law

    def fit_while_pressed(*args, **kwargs):  # the user presses Ctrl-C as the fit starts
        os.kill(os.getpid(), signal.SIGINT)
        return fit(*args, **kwargs)

    scene = make_scene({"realizations": 6})
    expected = engine.run(scene, RunOptions(workers=1))
    monkeypatch.setattr(frictionlab.compute.ensemble, "fit_log_law", fit_while_pressed)
    outcome = engine.run(scene, RunOptions(workers=1))  # before, a KeyboardInterrupt left no outcome
    assert outcome.status == "completed" and outcome.extra["signal"] == "SIGINT"
    assert outcome.fit == expected.fit


def test_a_failure_a_plugin_explains_is_its_message_alone(make_scene):
    """A SolveFailed is the plugin's own word to the user: before, a built-in's ended in the
    source line that raised it ('... loosen the tolerance. (contact_cg.py:436)'), and a
    third party's was told as that plugin's fault ('tell its authors')."""
    from frictionlab import SolveFailed

    scene = make_scene({"spectrum": {"params": {"points": 64}},
                        "solver": {"name": "bem-halfplane", "params": {"max_iterations": 1, "tolerance": 1e-12}}})
    error = compute_realization(scene, 0).error
    assert error.startswith("SolveFailed: bem-halfplane did not converge at load 0")
    assert error.endswith("Raise max_iterations or loosen the tolerance.")
    base = type(scene.solver)

    def solve(self, *args):
        raise SolveFailed("gave up: raise max_iterations")

    diverging = type("Diverging", (base,), {"name": "diverging", "solve": solve})(scene.solver.params)
    result = compute_realization(Scene(preset=scene.preset, spectrum=scene.spectrum, solver=diverging, slope=scene.slope), 0)
    assert result.error == "SolveFailed: gave up: raise max_iterations"


def test_an_error_of_a_megabyte_is_recorded_cut_and_its_chunk_resumed_as_it_is(make_scene, tmp_path):
    """A solver failing with a SolveFailed of a million characters (its own words, recorded as
    they are): the error was recorded whole, its chunk grew past what any chunk can hold, and
    every resume refused it as damaged and computed it again. Recorded cut to
    MAX_ERROR_CHARACTERS, saying how much was left out."""
    import warnings

    from frictionlab import SolveFailed
    from frictionlab.compute.realization import MAX_ERROR_CHARACTERS
    from frictionlab.runs.runner import run_to_folder

    scene = make_scene({"realizations": 3, "spectrum": {"params": {"points": 64}}, "fit": {"bootstrap": 0}})

    def solve(self, profile, loads, control, slopes):
        raise SolveFailed("x" * 10**6)

    solver = type("Loud", (type(scene.solver),), {"name": "loud", "solve": solve})(scene.solver.params)
    scene = Scene(preset=scene.preset, spectrum=scene.spectrum, solver=solver, slope=scene.slope)
    outcome, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1, executor="serial"))
    [error, *_] = [e for _, e in outcome.failures]
    kept = MAX_ERROR_CHARACTERS - 40
    assert error == f"SolveFailed: {'x' * (kept - 13)}... ({10**6 + 13 - kept} more characters)"
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a chunk refused as damaged is said with a warning
        again, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1, executor="serial", resume=True))
    assert again.extra["retried"] == 3  # read back as failures, not as damage

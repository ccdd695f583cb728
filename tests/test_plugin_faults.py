"""Mistakes of an installed plugin, as its author makes them: each is told naming the plugin
and its distribution, and none costs a run."""

from __future__ import annotations

import functools
import sys
from typing import Any

import pytest
from pydantic import Field

import frictionlab
from frictionlab import ContactSolver, ForceNormalisation, PluginParams, Profile, SpectrumGenerator
from frictionlab.compute import engine
from frictionlab.errors import PluginError
from frictionlab.options import RunOptions
from frictionlab.plugin.registry import Registry, validate_plugin_class
from frictionlab.preset import build_scene

from .conftest import SMALL_PRESET
from .test_registry import fake_dists  # noqa: F401 - the fixture
from .testing.fakes import GoodSlopes, GoodSolver, GoodSpectrum

RAISING_LOGGER = '''
import frictionlab

heard = []

@frictionlab.hookimpl
def run_started(run):
    raise RuntimeError("log server unreachable")

@frictionlab.hookimpl
def realization_done(run, result, done, total):
    heard.append(done)
'''


def test_a_listener_that_raises_is_told_and_the_run_goes_on(fake_dists, small_preset):  # noqa: F811
    fake_dists("acme-logs", "acme-logger", "acme_logger_plugin", RAISING_LOGGER, "0.2")
    registry = Registry(env={})
    small_preset["realizations"] = 3
    with pytest.warns(RuntimeWarning) as warned:
        outcome = engine.run(build_scene(small_preset, registry=registry), RunOptions(workers=1), registry=registry)
    assert (outcome.status, outcome.done) == ("completed", 3)
    [message] = [str(w.message) for w in warned if "raised" in str(w.message)]  # told once, not per event
    assert "'acme-logger' from acme-logs raised RuntimeError: log server unreachable" in message
    assert "run_started() at acme_logger_plugin.py:8" in message
    assert "FRICTIONLAB_BLOCK_PLUGINS=acme-logger" in message
    import acme_logger_plugin

    assert acme_logger_plugin.heard == []  # heard no more of the run once it failed


ENDING_LOGGER = '''
import sys
import frictionlab

heard = []

@frictionlab.hookimpl
def {hook}(run, **rest):
    heard.append("{hook}")
    {raising}
'''


@pytest.mark.parametrize("hook", ["run_started", "realization_done", "run_finished"])
@pytest.mark.parametrize("raising, said", [("sys.exit('log server unreachable')", "SystemExit: log server unreachable"),
                                           ("raise KeyboardInterrupt", "KeyboardInterrupt in ")])
def test_a_listener_that_exits_or_interrupts_is_told_and_the_run_goes_on(fake_dists, small_preset, monkeypatch,
                                                                         hook, raising, said):  # noqa: F811
    """Taken as they came, a sys.exit() in run_started ended the run (a notebook's script with it),
    told as the fault of another plugin of the package; a KeyboardInterrupt of its own in
    realization_done cancelled the run (exit 130), naming no plugin."""
    from frictionlab.plugin import registry as registry_module

    fake_dists("acme-logs", "acme-ending-logger", "acme_ending_logger", ENDING_LOGGER.format(hook=hook, raising=raising))
    monkeypatch.setattr(registry_module, "default_registry", functools.cache(lambda: Registry(env={})))
    with pytest.warns(RuntimeWarning) as warned:
        result = frictionlab.run({**small_preset, "realizations": 3}, workers=1, progress=False, plot=False)
    assert (result.status, result.realizations) == ("completed", (3, 3))
    [message] = [str(w.message) for w in warned if "raised" in str(w.message)]
    assert f"'acme-ending-logger' from acme-logs raised {said}" in message and f"{hook}() at acme_ending_logger.py:" in message
    assert "it hears no more of this run, which goes on" in message
    import acme_ending_logger

    assert acme_ending_logger.heard == [hook]  # heard no more once it failed


RAISING_SOLVER = '''
import frictionlab
from frictionlab import ContactSolver, ForceNormalisation

class Raising(ContactSolver):
    name = "acme-raising"
    summary = "a solver with a bug"
    normalisations = {1: ForceNormalisation(load="force", modulus="k", extent="length")}
    problem = "Winkler foundation"

    def stiffness(self):
        return 1.0

    def solve(self, profile, loads, control, slopes):
        return {}["missing-key"]

@frictionlab.hookimpl
def register_solvers(register):
    register(Raising)
'''


def test_an_exception_in_a_plugins_solve_names_the_plugin_in_the_realizations_error(fake_dists, small_preset):  # noqa: F811
    fake_dists("acme-solvers", "acme-raising", "acme_raising_plugin", RAISING_SOLVER, "0.3")
    registry = Registry(env={})
    small_preset.update(realizations=2, solver={"name": "acme-raising"})
    outcome = engine.run(build_scene(small_preset, registry=registry), RunOptions(workers=1), registry=registry)
    assert outcome.done == 0
    [(_, error), _] = outcome.failures
    assert "solver 'acme-raising' (acme_raising_plugin.Raising from acme-solvers) raised KeyError" in error
    assert "in solve() at acme_raising_plugin.py:15" in error


MISSING_METHOD = '''
import frictionlab
from frictionlab import Profile, SpectrumGenerator

class Missing(SpectrumGenerator):
    name = "acme-line"
    summary = "forgot rms_height"

    def generate(self, rng):
        return Profile(heights=rng.standard_normal(64), spacing=1.0)

@frictionlab.hookimpl
def register_spectra(register):
    register(Missing)
'''


def test_a_preset_naming_a_plugin_that_failed_to_load_is_told_why_not_a_guess(fake_dists):  # noqa: F811
    fake_dists("acme-lines", "acme", "acme_line_plugin", MISSING_METHOD)  # entry point named otherwise
    with pytest.warns(RuntimeWarning, match="'acme' from acme-lines failed to load"):
        registry = Registry(env={})
    with pytest.raises(PluginError) as refused:
        registry.get("spectrum", "acme-line")
    message = str(refused.value)
    assert message.startswith("spectrum plugin 'acme-line' is installed but failed to load: acme (acme-lines): ")
    assert "implements no rms_height()" in message
    assert "did you mean" not in message
    assert "installed spectrum plugins: " in message and "power-law" in message


class Undescribed(SpectrumGenerator):
    name = "acme-blank"
    summary = "a field described by blanks"

    class Params(PluginParams):
        points: int = Field(64, description="  ")

    def generate(self, rng):
        return Profile(rng.standard_normal(self.params.points), 1.0)

    def rms_height(self):
        return 1.0


def test_a_field_described_by_blanks_is_refused_with_how_to_describe_it():
    with pytest.raises(PluginError, match=r"Params.points has no description; give it one, points: \.\.\. = Field\("):
        validate_plugin_class("spectrum", Undescribed)


def test_the_contract_says_what_the_run_and_the_kit_do():
    """The docstrings an author reads: the rate iteration_done is heard at, the sign of slopes."""
    from pathlib import Path

    from frictionlab import RunListener, SlopeEstimator
    from frictionlab.compute.realization import ITERATION_EVENT_SECONDS

    page = (Path(__file__).parents[1] / "docs" / "reference" / "plugin-contract.md").read_text(encoding="utf-8")
    assert 1 / ITERATION_EVENT_SECONDS == 4
    for text in (page, RunListener.iteration_done.__doc__):
        assert "at most four times a" in " ".join(text.split())
    assert "dz/dx with its sign on a line" in " ".join(SlopeEstimator.__doc__.split())
    assert "the run goes on: a logger's fault never costs results" in " ".join(page.split())
    assert "a `Params` field without a description" in " ".join(page.split())  # refused by the registry


def test_the_kits_register_plugin_says_the_hook_meant_as_discovery_does(register_plugin):
    import pluggy

    from frictionlab import hookimpl

    class Misspelled:
        @hookimpl
        def run_finish(self, run, outcome):
            pass

    with pytest.raises(pluggy.PluginValidationError, match=r"unknown hook 'run_finish'; did you mean 'run_finished'\?"):
        register_plugin(Misspelled())


WRONG_ARGUMENT = '''
import frictionlab

@frictionlab.hookimpl
def realization_done(run, res, done, total):
    pass
'''


def test_a_hook_taking_an_argument_not_passed_is_told_on_one_line_with_those_passed(fake_dists):  # noqa: F811
    fake_dists("acme-args", "acme-args", "acme_args_plugin", WRONG_ARGUMENT)
    with pytest.warns(RuntimeWarning):
        registry = Registry(env={})
    [failure] = registry.failures
    assert "\n" not in failure.error
    assert "{'res'}" in failure.error
    assert failure.error.endswith("realization_done passes (run, result, done, total): take any of them, by these names")


class OneCaveat(SpectrumGenerator):
    name = "acme-one-caveat"
    summary = "a caveat given as a bare string"

    class Params(PluginParams):
        points: int = Field(64, ge=8, le=4096, description="Grid points.")

    def generate(self, rng):
        return Profile(rng.standard_normal(self.params.points), 1.0)

    def rms_height(self):
        return 1.0

    def caveats(self):
        return "for testing only"


def test_caveats_given_as_a_bare_string_are_refused_before_the_run_as_by_the_kit(small_preset, register_plugin):
    from frictionlab.testing import check_spectrum

    registry = register_plugin(OneCaveat)
    small_preset["spectrum"] = {"name": "acme-one-caveat"}
    expected = r"caveats\(\) must be a tuple of non-empty strings \(one sentence: \(sentence,\)\)\. Got 'for testing only'"
    with pytest.raises(PluginError, match=expected):
        build_scene(small_preset, registry=registry)
    with pytest.raises(AssertionError, match=expected):
        check_spectrum(OneCaveat)


def _helper_that_fails():
    return {}["missing-key"]


class HelpedSolver(ContactSolver):
    name = "acme-helped"
    summary = "a solver whose module-level helper raises"
    normalisations = {1: ForceNormalisation(load="force", modulus="k", extent="length")}
    problem = "Winkler foundation"

    def stiffness(self):
        return 1.0

    def solve(self, profile, loads, control, slopes):
        return _helper_that_fails()


def test_a_fault_in_a_helper_is_told_as_the_plugin_whose_method_called_it():
    """The spectrum and the solver share a package: the one whose method was on the stack is at fault."""
    from frictionlab.plugin.registry import plugin_fault

    try:
        HelpedSolver().solve(None, None, "force", None)
    except KeyError as exc:
        fault = plugin_fault(exc, [OneCaveat, HelpedSolver])
    assert str(fault).startswith("solver 'acme-helped' (tests.test_plugin_faults.HelpedSolver from ")
    assert "in _helper_that_fails() at test_plugin_faults.py:" in str(fault)


def test_a_plugin_claiming_a_built_ins_name_fails_to_load_and_the_built_in_keeps_it(fake_dists):  # noqa: F811
    """Installing it must not break every preset naming the built-in (quickstart's power-law)."""
    from tests.test_registry import GOOD_SOURCE

    fake_dists("acme-twin", "acme-twin-ep", "acme_twin", GOOD_SOURCE.format(cls="Twin", name="power-law"))
    with pytest.warns(RuntimeWarning, match="plugin 'acme-twin-ep' from acme-twin failed to load"):
        registry = Registry(env={})
    assert registry.get("spectrum", "power-law").__module__ == "frictionlab_spectra.power_law"
    assert registry.clashes == []
    assert [f.error for f in registry.failures] == [
        "PluginError: Twin: name 'power-law' is taken by the built-in spectrum "
        "frictionlab_spectra.power_law.PowerLaw, which keeps it; choose another name"
    ]


def test_the_kit_names_a_solvers_float32_field_as_an_attribute_of_what_solve_returned():
    import dataclasses

    import numpy as np

    from frictionlab.testing import check_solver
    from frictionlab_solvers.springs import WinklerSprings

    class Single(WinklerSprings):
        name = "acme-single"

        def solve(self, profile, loads, control, slopes):
            curve = super().solve(profile, loads, control, slopes)
            return dataclasses.replace(curve, force=curve.force.astype(np.float32))

    with pytest.raises(AssertionError, match=r"on a line, solve\(\.\.\., control='force'\)\.force must be float64"):
        check_solver(Single)


EXITING = '''
import os
import sys
from typing import Any

import frictionlab
from frictionlab import ContactSolver, ForceNormalisation, Profile, SpectrumGenerator


class ExitingLine(SpectrumGenerator):
    name = "acme-exiting-line"
    summary = "a line whose rms_height() ends the process"

    def generate(self, rng):
        return Profile(heights=rng.standard_normal(64), spacing=1.0)

    def rms_height(self):
        if os.environ.get("ACME_RAISE"):
            raise KeyboardInterrupt  # by no Ctrl-C
        sys.exit(3)


class ExitingSolver(ContactSolver):
    name = "acme-exiting"
    summary = "a solver whose solve() ends the process, with success"
    normalisations = {1: ForceNormalisation(load="force", modulus="k", extent="length")}
    problem = "Winkler foundation"

    def stiffness(self):
        return 1.0

    def solve(self, profile, loads, control, slopes):
        sys.exit(0)


@frictionlab.hookimpl
def register_spectra(register):
    register(ExitingLine)


@frictionlab.hookimpl
def register_solvers(register):
    register(ExitingSolver)
'''


@pytest.fixture
def exiting_plugin(fake_dists):  # noqa: F811
    """The exiting plugin installed, as the ``frictionlab`` command finds it."""
    from frictionlab.plugin import registry as registry_module

    fake_dists("acme-exits", "acme-exits", "acme_exits_plugin", EXITING)
    registry_module.default_registry.cache_clear()
    yield
    registry_module.default_registry.cache_clear()


def test_a_plugin_calling_sys_exit_in_a_realization_fails_it_and_the_run_says_so(exiting_plugin, small_preset,
                                                                                 tmp_path, capsys):  # fmt: skip
    """Taken as it came, the SystemExit ended the command silently with the plugin's code:
    0 here, a run that never solved told as done (3 would have read as an unreadable preset)."""
    import yaml

    from frictionlab.cli.main import main

    small_preset.update(realizations=3, solver={"name": "acme-exiting"})
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(small_preset))
    code = main(["run", str(tmp_path / "p.yaml"), "--out", str(tmp_path / "out"), "--workers", "1", "--quiet", "--no-plot"])
    err = capsys.readouterr().err
    assert code == 1, err
    assert ("solver 'acme-exiting' (acme_exits_plugin.ExitingSolver from acme-exits) raised SystemExit: 0 in "
            "solve() at acme_exits_plugin.py:") in err  # fmt: skip
    assert "no realization finished: 3 failed" in err and "Traceback" not in err


@pytest.mark.parametrize("raising, said", [(False, "SystemExit: 3"), (True, "KeyboardInterrupt")])
def test_a_plugin_ending_the_command_before_the_run_is_told_as_its_fault(exiting_plugin, small_preset, tmp_path, capsys,
                                                                        monkeypatch, raising, said):  # fmt: skip
    """Taken as it came, validate exited 3 without a word (as for a preset file it cannot read),
    or 130, "interrupted", by no Ctrl-C."""
    import yaml

    from frictionlab.cli.main import main

    if raising:
        monkeypatch.setenv("ACME_RAISE", "1")
    small_preset["spectrum"] = {"name": "acme-exiting-line"}
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(small_preset))
    assert main(["validate", str(tmp_path / "p.yaml")]) == 2
    err = capsys.readouterr().err
    assert (f"spectrum 'acme-exiting-line' (acme_exits_plugin.ExitingLine from acme-exits) raised {said} in "
            "rms_height() at acme_exits_plugin.py:") in err  # fmt: skip
    assert "Traceback" not in err


@pytest.mark.parametrize("raising, said", [(False, "SystemExit: 3"), (True, "KeyboardInterrupt")])
@pytest.mark.parametrize("entry", ["validate", "run"])
def test_a_plugin_ending_a_python_call_before_the_run_raises_its_plugin_error(exiting_plugin, small_preset, monkeypatch,
                                                                            raising, said, entry):  # fmt: skip
    """Taken as they came, frictionlab.validate and frictionlab.run let the plugin's SystemExit
    out (a script ended with the plugin's code) or its KeyboardInterrupt, by no Ctrl-C."""
    from frictionlab.errors import PluginError

    if raising:
        monkeypatch.setenv("ACME_RAISE", "1")
    small_preset["spectrum"] = {"name": "acme-exiting-line"}
    keys = {"progress": False, "plot": False} if entry == "run" else {}
    with pytest.raises(PluginError) as told:
        getattr(frictionlab, entry)(small_preset, **keys)
    assert str(told.value).startswith(f"spectrum 'acme-exiting-line' (acme_exits_plugin.ExitingLine from acme-exits) "
                                      f"raised {said} in rms_height() at acme_exits_plugin.py:")  # fmt: skip


def _ending(how):
    def solve(self, profile, loads, control, slopes):
        if how == "exit":
            sys.exit(5)
        raise KeyboardInterrupt  # no Ctrl-C: none reaches a worker, nor the thread solving in this process

    return type(f"Ending{how.title()}", (GoodSolver,), {"name": "acme-ending", "solve": solve})


@pytest.mark.parametrize("how, said", [("exit", "SystemExit: 5"), ("raise", "KeyboardInterrupt")])
@pytest.mark.parametrize("workers", [1, 2])
def test_a_plugin_ending_the_process_in_a_realization_fails_that_realization_alone(register_plugin, how, said, workers):
    """Taken as it came, a worker process died three times over and the run ended on "a worker
    process died", naming neither the plugin nor its line; in this process (one worker) the
    command ended with the plugin's exit code, or as interrupted (exit 130) by no Ctrl-C."""
    broken = _ending(how)
    registry = register_plugin(broken)
    for cls in (GoodSpectrum, GoodSlopes):
        register_plugin(cls)
    preset = {**SMALL_PRESET, "realizations": 4, "spectrum": {"name": "good-spectrum"},
              "solver": {"name": "acme-ending"}, "slope": {"name": "good-slopes"}}  # fmt: skip
    executor = "processes" if workers > 1 else "serial"
    outcome = engine.run(build_scene(preset, registry=registry), RunOptions(workers=workers, executor=executor),
                         registry=registry)  # fmt: skip
    assert outcome.done == 0 and len(outcome.failures) == 4
    for _, error in outcome.failures:
        assert f"solver 'acme-ending' (tests.test_plugin_faults.{broken.__name__} from " in error
        assert f"raised {said} in solve() at test_plugin_faults.py:" in error


VALIDATED = '''
import frictionlab
from pydantic import Field, field_validator
from frictionlab import PluginParams, Profile, SpectrumGenerator


class Alpha(SpectrumGenerator):
    name = "acme-alpha"
    summary = "a good line, listed first"

    def generate(self, rng):
        return Profile(heights=rng.standard_normal(64), spacing=1.0)

    def rms_height(self):
        return 1.0


class Checked(Alpha):
    name = "acme-checked"
    summary = "a line whose Params validator has a bug"

    class Params(PluginParams):
        points: int = Field(64, ge=8, le=4096, description="number of points")

        @field_validator("points")
        @classmethod
        def even(cls, value):
            return value // (1 - value % 2)  # a bug: an odd value divides by zero


@frictionlab.hookimpl
def register_spectra(register):
    register(Alpha)
    register(Checked)
'''


def test_a_bug_in_a_params_validator_names_its_own_plugin_not_the_first_of_its_package(fake_dists, small_preset):  # noqa: F811
    """A validator is a classmethod of Params (no plugin instance on the stack): taken as it came,
    the fault went to the first plugin the package registered, acme-alpha."""
    fake_dists("acme-checked", "acme-checked", "acme_checked_plugin", VALIDATED)
    registry = Registry(env={})
    small_preset["spectrum"] = {"name": "acme-checked", "params": {"points": 65}}
    with pytest.raises(ZeroDivisionError) as excinfo:
        build_scene(small_preset, registry=registry)
    assert str(registry.at_fault(excinfo.value)).startswith(
        "spectrum 'acme-checked' (acme_checked_plugin.Checked from acme-checked) raised ZeroDivisionError: "
        "integer division or modulo by zero in even() at acme_checked_plugin.py:")


class AnyExtra(GoodSpectrum):
    name = "acme-any"
    summary = "a line with a parameter of any type"

    class Params(GoodSpectrum.Params):
        extra: Any = Field(None, description="anything the plugin reads")


def test_infinity_hidden_in_a_parameter_of_any_type_is_refused_as_in_a_number(register_plugin, small_preset):
    """Taken as it came, the run went on and stored the value as null: resumed, it ran with None."""
    from frictionlab.errors import PresetError

    registry = register_plugin(AnyExtra)
    small_preset["spectrum"] = {"name": "acme-any", "params": {"extra": [1.0, {"a": float("inf")}]}}
    with pytest.raises(PresetError) as refused:
        build_scene(small_preset, registry=registry)
    assert refused.value.problems == ["spectrum.params.extra[1].a: must be a finite number, got inf"]
    small_preset["spectrum"]["params"]["extra"] = [1.0, {"a": "text", "b": [2, None]}]
    assert build_scene(small_preset, registry=registry).spectrum.params.extra[1]["b"] == [2, None]


ALLOCATING = '''
import os

import frictionlab
from frictionlab import ContactSolver, ForceNormalisation


class Allocating(ContactSolver):
    name = "acme-allocating"
    summary = "a solver that allocates more than the machine has"
    normalisations = {1: ForceNormalisation(load="force", modulus="k", extent="length")}
    problem = "Winkler foundation"

    def __init__(self, params=None):
        super().__init__(params)
        if os.environ.get("ACME_ALLOCATE_AT_START"):
            raise MemoryError("Unable to allocate 8.00 TiB for an array with shape (1099511627776,)")

    def stiffness(self):
        return 1.0

    def solve(self, profile, loads, control, slopes):
        raise MemoryError("Unable to allocate 16.0 GiB for an array with shape (2147483648,)")


@frictionlab.hookimpl
def register_solvers(register):
    register(Allocating)
'''


@pytest.mark.parametrize("at_start", [True, False])
def test_a_plugin_out_of_memory_is_the_machines_limit_said_where_not_its_fault(fake_dists, small_preset, tmp_path,
                                                                              capsys, monkeypatch, at_start):  # noqa: F811
    """Taken as it came, a MemoryError in a plugin's __init__ was told as "out of memory" with no
    word of where, and one in its solve() as the plugin's fault, without the advice that helps."""
    import yaml

    from frictionlab.cli.main import main
    from frictionlab.plugin import registry as registry_module

    fake_dists("acme-allocates", "acme-allocating", "acme_allocating_plugin", ALLOCATING)
    registry_module.default_registry.cache_clear()
    if at_start:
        monkeypatch.setenv("ACME_ALLOCATE_AT_START", "1")
    small_preset.update(realizations=2, solver={"name": "acme-allocating"})
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(small_preset))
    try:
        code = main(["run", str(tmp_path / "p.yaml"), "--out", str(tmp_path / "out"), "--workers", "1", "--quiet",
                     "--no-plot"])  # fmt: skip
    finally:
        registry_module.default_registry.cache_clear()
    err = capsys.readouterr().err
    assert code == 1, err
    assert "out of memory" in err and "at fault" not in err and "Traceback" not in err
    method = "__init__" if at_start else "solve"
    assert (f"(in solver 'acme-allocating' (acme_allocating_plugin.Allocating from acme-allocates), "
            f"{method}() at acme_allocating_plugin.py:") in err  # fmt: skip
    if not at_start:
        assert "2 realization(s) ran out of memory" in err and "fewer workers" in err

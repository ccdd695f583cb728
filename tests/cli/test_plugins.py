"""The headless CLI as a user meets it: real files, real subprocesses, exit codes."""

import json

import pytest

from frictionlab.cli import main
from frictionlab.errors import ExitCode

from tests.test_registry import fake_dists  # noqa: F401 (a fixture)


def test_plugins_lists_kind_name_provider_and_version(capsys):
    assert main(["plugins"]) == ExitCode.OK
    out = capsys.readouterr().out
    for kind, name in [("spectrum", "power-law"), ("solver", "mdr"), ("slope", "forward-difference")]:
        line = next(line for line in out.splitlines() if line.split()[:2] == [kind, name])
        assert "frictionlab" in line and "0." in line  # provider and its version
    assert main(["plugins", "--json"]) == ExitCode.OK
    rows = json.loads(capsys.readouterr().out)["plugins"]
    assert {r["name"] for r in rows if r["kind"] == "slope"} >= {"forward-difference", "central-difference", "spectral"}



def test_a_name_two_plugins_claim_is_named_and_other_presets_still_validate(capsys, fake_dists):
    from frictionlab.plugin import registry as registry_module
    from tests.test_registry import GOOD_SOURCE

    for dist in ("acme-one", "acme-two"):
        module = dist.replace("-", "_")
        fake_dists(dist, dist, module, GOOD_SOURCE.format(cls="Twin", name="twin-line"))
    registry_module.default_registry.cache_clear()
    try:
        with pytest.warns(RuntimeWarning, match="two spectrum plugins are named 'twin-line'"):
            assert main(["plugins"]) == ExitCode.OK
        captured = capsys.readouterr()
        assert "twin-line" not in captured.out and "power-law" in captured.out
        assert "not listed: two spectrum plugins are named 'twin-line': acme_" in captured.err
        assert main(["plugins", "--json"]) == ExitCode.OK
        assert "two spectrum plugins are named 'twin-line'" in json.loads(capsys.readouterr().out)["clashes"][0]
        assert main(["validate", "quickstart"]) == ExitCode.OK
        twin = ["--set", "spectrum.name=twin-line", "--set", "spectrum.params={}"]
        assert main(["validate", "quickstart", *twin]) == ExitCode.USAGE
        assert "spectrum.name: two spectrum plugins are named 'twin-line'" in capsys.readouterr().err
    finally:
        registry_module.default_registry.cache_clear()


RAISING_SOURCE = '''
import frictionlab
from tests.testing.fakes import GoodSpectrum


class Raising(GoodSpectrum):
    name = "raising-line"

    def rms_height(self):
        return 1 / 0


@frictionlab.hookimpl
def register_spectra(register):
    register(Raising)
'''


def test_a_plugin_that_raises_is_named_with_exit_code_2_not_an_internal_error(capsys, fake_dists):
    from frictionlab.plugin import registry as registry_module

    fake_dists("acme-raising", "raising", "acme_raising", RAISING_SOURCE, "1.2")
    registry_module.default_registry.cache_clear()
    try:
        args = ["validate", "quickstart", "--set", "spectrum.name=raising-line", "--set", "spectrum.params={}"]
        assert main(args) == ExitCode.USAGE
        err = capsys.readouterr().err
        assert err.startswith("error: spectrum 'raising-line' (acme_raising.Raising from acme-raising) raised "
                              "ZeroDivisionError: division by zero in rms_height() at acme_raising.py:")
        assert "internal error" not in err
        assert main(["validate", "quickstart"]) == ExitCode.OK
    finally:
        registry_module.default_registry.cache_clear()


EXPLAINING_SOURCE = '''
import frictionlab
from frictionlab import SolveFailed
from frictionlab_solvers.springs import MDRSprings


class Picky(MDRSprings):
    name = "acme-picky"

    def full_contact_load(self, profile):
        raise SolveFailed("no full contact on a line this rough; use mdr")


@frictionlab.hookimpl
def register_solvers(register):
    register(Picky)
'''


def test_a_solve_failed_before_any_realization_is_the_plugins_word_not_its_fault(tmp_path, capsys, fake_dists):
    """A SolveFailed (a failure the plugin explains) raised as validate takes the load of full
    contact was told "the plugin is at fault: tell its authors", where a realization's tells its
    message alone: said as run says it, naming the plugin, exit 2; validate goes on to the next preset."""
    from frictionlab.plugin import registry as registry_module

    fake_dists("acme-picky", "picky", "acme_picky", EXPLAINING_SOURCE, "1.0")
    registry_module.default_registry.cache_clear()
    try:
        said = ("solver 'acme-picky' (acme_picky.Picky from acme-picky) raised SolveFailed: no full contact on a "
                "line this rough; use mdr")
        picky = ["--set", "solver.name=acme-picky"]
        assert main(["validate", "quickstart", "quickstart", *picky]) == ExitCode.USAGE
        err = capsys.readouterr().err
        assert err.count(f"quickstart: {said}") == 2 and "at fault" not in err and "internal error" not in err
        f_loads = ["--set", "loading.unit=f", "--set", "loading.start=0.01", "--set", "loading.stop=1"]
        run = ["run", "quickstart", *picky, *f_loads, "--out", str(tmp_path / "r"), "--quiet"]
        assert main(run) == ExitCode.USAGE  # its loads in f need the load of full contact
        err = capsys.readouterr().err
        assert err.startswith(f"error: {said}") and "at fault" not in err
    finally:
        registry_module.default_registry.cache_clear()


CHATTY_SOURCE = '''
import frictionlab
from tests.testing.fakes import GoodSpectrum


class Chatty(GoodSpectrum):
    name = "chatty-line"

    def generate(self, rng):
        print("generating, debug")
        return super().generate(rng)


@frictionlab.hookimpl
def register_spectra(register):
    register(Chatty)
'''


@pytest.mark.parametrize("workers", ["1", "2"])
def test_a_plugin_printing_as_it_runs_leaves_json_alone_on_stdout(capsys, fake_dists, tmp_path, workers):
    """A researcher's debug print in generate() went to stdout, before the one JSON object."""
    from frictionlab.plugin import registry as registry_module

    fake_dists("acme-chatty", "chatty", "acme_chatty", CHATTY_SOURCE)
    registry_module.default_registry.cache_clear()
    try:
        args = ["run", "quickstart", "--set", "spectrum.name=chatty-line", "--set", "spectrum.params={}",
                "--set", "realizations=3", "--set", "fit.bootstrap=0", "--out", str(tmp_path / "run"),
                "--no-plot", "--workers", workers, "--json"]
        assert main(args) == ExitCode.OK
        captured = capsys.readouterr()
        assert json.loads(captured.out)["status"] == "completed"
        assert "generating, debug" in captured.err
    finally:
        registry_module.default_registry.cache_clear()

"""The registry: built-ins, names, errors, entry points, environment switches, hook
documentation, and plugins listening to runs."""

from __future__ import annotations

import importlib
import importlib.metadata as md
import inspect
import sys
import textwrap
import warnings

import pluggy
import pytest
from pydantic import BaseModel, Field

from frictionlab import ContactSolver, PluginParams, SpectrumGenerator, hookimpl
from frictionlab.plugin import registry as registry_module
from frictionlab.errors import ExitCode, PluginError
from frictionlab.plugin.hookspecs import PROJECT_NAME, RegistrationSpecs
from frictionlab.plugin.listeners import RunListener as LifecycleSpecs
from frictionlab.options import RunOptions
from frictionlab.plugin import KINDS
from frictionlab.plugin.registry import BUILTIN_MODULES, ENTRY_POINT_GROUP, LoadFailure, Registry, normalize_name, validate_plugin_class

from .conftest import ROOT
from .testing.fakes import KIND_HOOKS, provider, spectrum_class


@pytest.fixture
def reg():
    return Registry(discover=False)


# ======================================================================= built-ins


EXPECTED_BUILTINS = {
    "spectrum": {"power-law", "rolloff", "profile-file"},
    "solver": {"mdr", "winkler", "mdr-bisection"},
    "slope": {"forward-difference", "central-difference", "spectral"},
}


def test_builtins_listed_per_kind_with_provider(reg):
    version = md.version("frictionlab")
    for kind in KINDS:
        infos = reg.infos(kind)
        assert {i.name for i in infos} >= EXPECTED_BUILTINS[kind]
        assert [i.name for i in infos] == sorted(i.name for i in infos) == reg.names(kind)
        for info in infos:
            assert info.kind == kind
            assert info.provider == "frictionlab"
            assert info.version == version
            assert info.cls.__module__.split(".")[0] in BUILTIN_MODULES
            assert info.summary == info.cls.summary
    assert reg.infos() == [i for kind in KINDS for i in reg.infos(kind)]
    assert reg.failures == []


def test_builtins_are_exactly_what_their_hooks_register(reg):
    for module_name in BUILTIN_MODULES:
        module = importlib.import_module(module_name)
        for kind, hook in KIND_HOOKS.items():
            impl = getattr(module, hook, None)
            if impl is None:
                continue
            seen = []
            impl(register=seen.append)
            assert seen, f"{module_name}.{hook} registers nothing"
            for cls in seen:
                assert reg.get(kind, cls.name) is cls


@pytest.mark.parametrize(
    "raw,normal",
    [("Power_Law", "power-law"), (" power law ", "power-law"), ("POWER-LAW", "power-law"), ("mdr", "mdr")],
)
def test_normalize_name(raw, normal):
    assert normalize_name(raw) == normal


def test_lookup_normalises_names(reg):
    cls = reg.get("spectrum", "power-law")
    assert reg.get("spectrum", "Power_Law") is cls
    assert reg.get("spectrum", "  POWER law") is cls
    assert reg.info("spectrum", "Power_Law").name == "power-law"
    assert reg.get("slope", "Forward_Difference").name == "forward-difference"


def test_unknown_name_suggests_close_matches_and_lists_installed(reg):
    with pytest.raises(PluginError) as excinfo:
        reg.get("spectrum", "power-lwa")
    message = str(excinfo.value)
    assert "no spectrum plugin named 'power-lwa'" in message
    assert "did you mean 'power-law'" in message
    for name in reg.names("spectrum"):
        assert name in message
    assert excinfo.value.exit_code == ExitCode.USAGE


def test_unknown_name_without_a_close_one_is_a_sentence_before_the_installed_list(reg):
    """`no spectrum plugin named 'nosuch' Installed spectrum plugins: ...` ran the two together."""
    with pytest.raises(PluginError) as excinfo:
        reg.get("spectrum", "nosuch")
    assert str(excinfo.value).startswith("no spectrum plugin named 'nosuch'. Installed spectrum plugins: ")


def test_unknown_name_without_close_match_still_lists_installed(reg):
    with pytest.raises(PluginError) as excinfo:
        reg.get("solver", "boundary-element-xyz")
    message = str(excinfo.value)
    assert "did you mean" not in message
    assert "Installed solver plugins: " + ", ".join(reg.names("solver")) in message


def test_unknown_kind(reg):
    with pytest.raises(PluginError, match="unknown plugin kind 'surface'.*spectrum, solver, slope"):
        reg.get("surface", "power-law")


# ====================================================================== clashes


def test_two_plugins_with_one_name_name_both_providers(reg):
    first = spectrum_class("twin-line", "acme_one.lines", "TwinLine")
    second = spectrum_class("twin-line", "acme_two.spectra", "OtherTwin")
    reg.register_plugin(provider(first), name="acme-one")
    assert reg.get("spectrum", "twin-line") is first
    with pytest.raises(PluginError) as excinfo:
        reg.register_plugin(provider(second), name="acme-two")
    message = str(excinfo.value)
    assert "two spectrum plugins are named 'twin-line'" in message
    assert "acme_one.lines.TwinLine from acme_one.lines" in message
    assert "acme_two.spectra.OtherTwin from acme_two.spectra" in message
    assert "FRICTIONLAB_BLOCK_PLUGINS" in message
    # the rejected plugin is rolled back: the registry is as before
    assert reg.pm.get_plugin("acme-two") is None
    assert reg.get("spectrum", "twin-line") is first


def test_a_builtins_name_is_refused_as_an_installed_plugin_is_told(reg):
    """The kit's register_plugin said 'two spectrum plugins are named', where an installed
    plugin fails to load and the built-in keeps its name."""
    impostor = spectrum_class("power-law", "acme_three.lines", "Impostor")
    with pytest.raises(PluginError) as excinfo:
        reg.register_plugin(provider(impostor))
    assert str(excinfo.value) == ("Impostor: name 'power-law' is taken by the built-in spectrum "
                                  "frictionlab_spectra.power_law.PowerLaw, which keeps it; choose another name")
    assert reg.get("spectrum", "power-law").__module__ == "frictionlab_spectra.power_law"
    assert reg.clashes == []


def test_one_class_registered_twice_is_not_a_clash(reg):
    cls = spectrum_class("shared-line")
    reg.register_plugin(provider(cls), name="one")
    reg.register_plugin(provider(cls), name="two")
    assert reg.get("spectrum", "shared-line") is cls


# ============================================================== invalid classes


def _broken_variants():
    def with_(name="broken-line", **attrs):
        cls = spectrum_class(name)
        for key, value in attrs.items():
            setattr(cls, key, value)
        return cls

    class LooseParams(BaseModel):
        points: int = Field(32, description="number of points")

    class UndescribedParams(PluginParams):
        points: int = Field(32, ge=8)

    class NotAModel:
        points = 32

    class Solverish(ContactSolver):
        name = "wrong-kind"
        summary = "A solver registered as a spectrum"

    return [
        pytest.param(with_("Bad_Name"), r"name must be kebab-case.*'Bad_Name'", id="underscore-name"),
        pytest.param(with_("bad name"), r"name must be kebab-case", id="space-name"),
        pytest.param(with_("2d-line"), r"name must be kebab-case", id="digit-first"),
        pytest.param(with_(""), r"name must be kebab-case", id="empty-name"),
        pytest.param(with_(summary="two\nlines"), r"summary must be one non-empty line", id="multiline-summary"),
        pytest.param(with_(summary=""), r"summary must be one non-empty line", id="empty-summary"),
        pytest.param(with_(Params=LooseParams), r"Params must forbid unknown keys", id="extra-allowed"),
        pytest.param(with_(Params=UndescribedParams), r"Params\.points has no description", id="undescribed"),
        pytest.param(with_(Params=NotAModel), r"Params must be a pydantic model", id="not-pydantic"),
        pytest.param(Solverish, r"must subclass frictionlab\.SpectrumGenerator", id="wrong-kind"),
        pytest.param(with_(generate=SpectrumGenerator.generate), r"implements no generate\(\): a SpectrumGenerator must",
                     id="no-generate"),
        pytest.param(with_(generate=SpectrumGenerator.generate, rms_height=SpectrumGenerator.rms_height),
                     r"implements no generate\(\) nor rms_height\(\)", id="no-generate-nor-rms-height"),
        pytest.param(with_(generate=lambda self: None), r"generate\(\) must take \(rng\), as frictionlab calls it\. "
                     r"Got generate\(self\) instead\.", id="generate-without-rng"),
        pytest.param(with_(profile_rms_height=lambda self, profile, extra: None),
                     r"profile_rms_height\(\) must take \(profile\)", id="optional-method-with-an-extra-argument"),
    ]


@pytest.mark.parametrize("cls,match", _broken_variants())
def test_invalid_class_is_a_clear_plugin_error(reg, cls, match):
    before = reg.infos()
    with pytest.raises(PluginError, match=match):
        reg.register_plugin(provider(cls, hook_name="register_spectra"), name="acme-broken")
    assert reg.infos() == before
    assert reg.pm.get_plugin("acme-broken") is None
    with pytest.raises(PluginError, match=match):
        validate_plugin_class("spectrum", cls)


def test_valid_fake_passes_validation():
    validate_plugin_class("spectrum", spectrum_class())


# ============================================================ hook validation


def test_misspelled_hook_fails_check_pending(reg):
    class Misspelled:
        @hookimpl
        def register_spectrum(self, register):  # sic: the spec is register_spectra
            register(spectrum_class("never-line"))

    plugin = Misspelled()
    with pytest.raises(pluggy.PluginValidationError, match="register_spectrum"):
        reg.register_plugin(plugin, name="acme-typo")
    assert not reg.pm.is_registered(plugin)
    assert "never-line" not in reg.names("spectrum")
    reg.pm.check_pending()  # nothing left behind


def test_hook_with_wrong_argument_fails_at_registration(reg):
    class WrongArgument:
        @hookimpl
        def register_spectra(self, callback):
            pass

    with pytest.raises(pluggy.PluginValidationError, match="callback"):
        reg.register_plugin(WrongArgument())


def test_hook_may_take_no_arguments(reg):
    """pluggy lets an implementation take a subset of the spec's arguments."""

    class Quiet:
        @hookimpl
        def register_solvers(self):
            pass

    reg.register_plugin(Quiet())
    assert reg.names("solver") == Registry(discover=False).names("solver")


def test_unregister_plugin(reg):
    holder = provider(spectrum_class("temporary-line"))
    reg.register_plugin(holder)
    assert "temporary-line" in reg.names("spectrum")
    reg.unregister_plugin(holder)
    assert "temporary-line" not in reg.names("spectrum")


# ========================================================= entry points (faked)


GOOD_SOURCE = '''
import frictionlab
from tests.testing.fakes import spectrum_class

{cls} = spectrum_class("{name}", __name__, "{cls}")  # a class of this module, as a distribution's


@frictionlab.hookimpl
def register_spectra(register):
    register({cls})
'''

MISSPELLED_SOURCE = '''
import frictionlab


@frictionlab.hookimpl
def register_spectrum(register):
    pass
'''


@pytest.fixture
def fake_dists(tmp_path, monkeypatch):
    """``add(dist, ep_name, module, source, version="1.0", target=None)``: a fake
    installed distribution in tmp_path with one ``frictionlab`` entry point, and
    ``importlib.metadata.entry_points`` (as the registry calls it) seeing only these."""
    site = tmp_path / "site"
    site.mkdir()
    modules: list[str] = []

    def add(dist, ep_name, module, source, version="1.0", target=None):
        (site / f"{module}.py").write_text(textwrap.dedent(source))
        info = site / f"{dist.replace('-', '_')}-{version}.dist-info"
        info.mkdir()
        (info / "METADATA").write_text(f"Metadata-Version: 2.1\nName: {dist}\nVersion: {version}\n")
        (info / "entry_points.txt").write_text(f"[{ENTRY_POINT_GROUP}]\n{ep_name} = {target or module}\n")
        (info / "top_level.txt").write_text(f"{module}\n")
        modules.append(module)
        importlib.invalidate_caches()
        registry_module._module_distributions.cache_clear()

    def entry_points(**selection):
        found = [ep for dist in md.distributions(path=[str(site)]) for ep in dist.entry_points]
        return md.EntryPoints(found).select(**selection)

    monkeypatch.syspath_prepend(str(site))
    monkeypatch.setattr(registry_module.md, "entry_points", entry_points)
    registry_module._module_distributions.cache_clear()
    yield add
    registry_module._module_distributions.cache_clear()
    for module in modules:
        sys.modules.pop(module, None)


@pytest.fixture
def two_good(fake_dists):
    fake_dists("acme-good", "good", "acme_good_plugin", GOOD_SOURCE.format(cls="GoodLine", name="good-line"), "2.3.4")
    fake_dists("acme-other", "other", "acme_other_plugin", GOOD_SOURCE.format(cls="OtherLine", name="other-line"))
    return fake_dists


def test_entry_points_are_discovered_with_provider_and_version(two_good):
    reg = Registry(env={})
    good = reg.info("spectrum", "good-line")
    assert (good.provider, good.version) == ("acme-good", "2.3.4")
    assert good.cls.__module__ == "acme_good_plugin"
    assert reg.info("spectrum", "other-line").provider == "acme-other"
    assert {"power-law", "good-line", "other-line"} <= set(reg.names("spectrum"))
    assert reg.failures == []


@pytest.mark.parametrize("value", ["1", "true", "YES", "on"])
def test_disable_discovery(two_good, value):
    reg = Registry(env={"FRICTIONLAB_DISABLE_DISCOVERY": value})
    assert "good-line" not in reg.names("spectrum")
    assert "power-law" in reg.names("spectrum")  # built-ins stay


def test_discovery_switch_off_values_keep_discovery(two_good):
    reg = Registry(env={"FRICTIONLAB_DISABLE_DISCOVERY": "0"})
    assert "good-line" in reg.names("spectrum")


def test_discover_false_never_reads_entry_points(monkeypatch):
    def explode(**_):
        raise AssertionError("entry points were read")

    monkeypatch.setattr(registry_module.md, "entry_points", explode)
    assert "power-law" in Registry(discover=False, env={}).names("spectrum")


def test_only_listed_plugins(two_good):
    with pytest.warns(RuntimeWarning, match=r"FRICTIONLAB_PLUGINS names 'nonexistent', which is no installed plugin's "
                                            r"entry point \(installed: good, other;"):  # fmt: skip
        reg = Registry(env={"FRICTIONLAB_PLUGINS": " other , nonexistent"})
    assert "other-line" in reg.names("spectrum")
    assert "good-line" not in reg.names("spectrum")
    assert "power-law" in reg.names("spectrum")


def test_blocked_plugins(two_good, recwarn):
    reg = Registry(env={"FRICTIONLAB_BLOCK_PLUGINS": "good,not-installed"})  # blocked all the same: no warning
    assert not [w for w in recwarn if "FRICTIONLAB" in str(w.message)]
    assert "good-line" not in reg.names("spectrum")
    assert "other-line" in reg.names("spectrum")
    both = Registry(env={"FRICTIONLAB_BLOCK_PLUGINS": "good,other"})
    assert not {"good-line", "other-line"} & set(both.names("spectrum"))


def test_trace_hooks_writes_to_stderr(capsys):
    Registry(discover=False, env={})
    assert capsys.readouterr().err == ""
    Registry(discover=False, env={"FRICTIONLAB_TRACE_HOOKS": "1"})
    err = capsys.readouterr().err
    for hook in KIND_HOOKS.values():
        assert hook in err


def test_trace_hooks_through_file_descriptor(capfd):
    Registry(discover=False, env={"FRICTIONLAB_TRACE_HOOKS": "yes"})
    captured = capfd.readouterr()
    assert "register_spectra" in captured.err
    assert captured.out == ""


BROKEN_SOURCES = {
    "raises": ('raise RuntimeError("boom: broken on import")', None, "RuntimeError: boom: broken on import"),
    "missing-dependency": ("import acme_dependency_that_is_not_installed", None, "ModuleNotFoundError"),
    "missing-attribute": ("x = 1", "acme_broken_plugin:nothing_here", "AttributeError"),
    "syntax-error": ("def broken(:\n    pass", None, "SyntaxError: invalid syntax ("),
    "no-module-name": ("x = 1", "acme-broken-plugin:plugin", "PluginError: the entry point's value "
                       "'acme-broken-plugin:plugin' names no module: it must be module or module:attribute, of "
                       "letters, digits, _ and dots"),
}


@pytest.mark.parametrize("case", sorted(BROKEN_SOURCES))
def test_failing_entry_point_warns_and_is_recorded(two_good, case):
    source, target, error = BROKEN_SOURCES[case]
    two_good("acme-broken", "broken", "acme_broken_plugin", source, "0.9", target=target)
    with pytest.warns(RuntimeWarning, match=r"plugin 'broken' from acme-broken failed to load .*skipped"):
        reg = Registry(env={})
    assert len(reg.failures) == 1
    failure = reg.failures[0]
    assert isinstance(failure, LoadFailure)
    assert (failure.entry_point, failure.distribution) == ("broken", "acme-broken")
    assert error in failure.error
    if case == "syntax-error":  # the file in full: which of the installed copies
        assert f"{sys.modules['acme_good_plugin'].__file__.rpartition('/')[0]}/acme_broken_plugin.py, line 1)" in failure.error
    # the others still load
    assert {"good-line", "other-line", "power-law"} <= set(reg.names("spectrum"))
    # only when a plugin is asked for and missing does the failure become an error
    message = reg.not_found_message("spectrum", "broken-line")
    assert "Plugins that failed to load: broken (acme-broken): " in message
    assert error in message
    with pytest.raises(PluginError, match="failed to load.*acme-broken"):
        reg.get("spectrum", "broken-line")


def test_blocking_a_broken_plugin_silences_it(two_good):
    two_good("acme-broken", "broken", "acme_broken_plugin", 'raise RuntimeError("boom")')
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        reg = Registry(env={"FRICTIONLAB_BLOCK_PLUGINS": "broken"})
    assert reg.failures == []


HOOK_RAISES_SOURCE = '''
import frictionlab


@frictionlab.hookimpl
def register_solvers(register):
    raise RuntimeError("boom: broken in its hook")
'''

INVALID_CLASS_SOURCE = '''
import frictionlab
from tests.testing.fakes import spectrum_class

Loose = spectrum_class("loose-line", __name__, "Loose")
Loose.Params = dict


@frictionlab.hookimpl
def register_spectra(register):
    register(Loose)
'''

PARAMS_SOURCE = '''
import numpy as np
from pydantic import ConfigDict, Field
import frictionlab
from tests.testing.fakes import spectrum_class

Loose = spectrum_class("loose-line", __name__, "Loose")


class Params(frictionlab.PluginParams):
    model_config = ConfigDict(extra="forbid", arbitrary_types_allowed=True)
    {field}


Loose.Params = Params


@frictionlab.hookimpl
def register_spectra(register):
    register(Loose)
'''

BROKEN_AT_REGISTRATION = {
    "misspelled-hook": (MISSPELLED_SOURCE, "PluginError: unknown hook 'register_spectrum'; did you mean 'register_spectra'?"),
    "hook-raises": (HOOK_RAISES_SOURCE,
                    "RuntimeError: boom: broken in its hook (in register_solvers() at acme_typo_plugin.py:7)"),
    "import-fails": ("import json\nimport no_such_module_for_acme\n",
                     "ModuleNotFoundError: No module named 'no_such_module_for_acme' (as it imports, "
                     "acme_typo_plugin.py:2)"),
    "invalid-class": (INVALID_CLASS_SOURCE, "PluginError: Loose: Params must be a pydantic model"),
    "exits-at-import": ("import argparse\nargparse.ArgumentParser(prog='acme').parse_args(['--no-such-option'])\n",
                        "SystemExit(2): it exits as it loads (parsing arguments at import?)"),
    "no-mark": ("def register_spectra(register):\n    pass\n",
                "PluginError: it implements no hook: register_spectra lacks the @frictionlab.hookimpl mark"),
    "no-schema": (PARAMS_SOURCE.replace("{field}", 'window: np.ndarray = Field(None, description="a window")'),
                  "PluginError: Loose: Params has no JSON Schema (PydanticInvalidForJsonSchema: Cannot generate a "
                  "JsonSchema for core_schema.IsInstanceSchema (<class 'numpy.ndarray'>)): give every field a type "
                  "pydantic can describe (numbers, strings, lists of them)"),
    "default-out-of-bounds": (PARAMS_SOURCE.replace("{field}", 'points: int = Field(4, ge=8, description="points")'),
                              "PluginError: Loose: Params.points defaults to 4, which its own bounds refuse (Input "
                              "should be greater than or equal to 8): a preset leaving it out would run with it"),
}


@pytest.mark.parametrize("case", sorted(BROKEN_AT_REGISTRATION))
def test_an_entry_point_broken_at_registration_is_skipped_by_name(two_good, case):
    """A misspelled hook, a hook that raises or a class breaking the contract is that plugin's
    failure, named with its distribution: every other plugin (and every command) still works."""
    source, error = BROKEN_AT_REGISTRATION[case]
    two_good("acme-typo", "typo", "acme_typo_plugin", source)
    with pytest.warns(RuntimeWarning, match=r"plugin 'typo' from acme-typo failed to load .*skipped"):
        reg = Registry(env={})
    assert [(f.entry_point, f.distribution, f.error) for f in reg.failures] == [("typo", "acme-typo", error)]
    assert reg.pm.get_plugin("typo") is None
    assert {"good-line", "other-line", "power-law"} <= set(reg.names("spectrum"))
    assert reg.names("solver") == Registry(discover=False).names("solver")
    assert "good-line" in Registry(env={"FRICTIONLAB_BLOCK_PLUGINS": "typo"}).names("spectrum")


def test_an_entry_point_naming_the_class_not_the_module_is_told_so(two_good):
    """It registered nothing without a word: the plugin was looked for in vain."""
    two_good("acme-named", "named", "acme_named_plugin", GOOD_SOURCE.format(cls="Named", name="named-line"),
             target="acme_named_plugin:Named")
    with pytest.warns(RuntimeWarning, match="plugin 'named' from acme-named failed to load"):
        reg = Registry(env={})
    assert [f.error for f in reg.failures] == [
        "PluginError: it implements no hook: the entry point's value must be the module holding its "
        "@frictionlab.hookimpl functions (acme_named_plugin), not the class Named"]


def test_what_a_plugin_prints_as_it_loads_goes_to_stderr(two_good, capsys):
    """stdout may be JSON (frictionlab schema, --json): a plugin's debug print corrupted it."""
    two_good("acme-chatty", "chatty", "acme_chatty_plugin",
             "print('loading chatty')\n" + GOOD_SOURCE.format(cls="Chatty", name="chatty-line"))
    assert "chatty-line" in Registry(env={}).names("spectrum")
    out, err = capsys.readouterr()
    assert (out, err) == ("", "loading chatty\n")


def test_a_name_two_installed_plugins_claim_is_an_error_only_where_used(two_good):
    """Two installed plugins: neither's. An installed plugin claiming a built-in's name fails to
    load instead, and the built-in keeps it (test_plugin_faults)."""
    two_good("acme-twin", "twin", "acme_twin_plugin", GOOD_SOURCE.format(cls="Twin", name="good-line"))
    two_good("acme-fake", "fake", "acme_fake_plugin", GOOD_SOURCE.format(cls="PowerLaw", name="power-law"))
    with pytest.warns(RuntimeWarning) as warned:
        reg = Registry(env={})
    said = [str(w.message) for w in warned]
    assert any("two spectrum plugins are named 'good-line'" in m for m in said), said
    assert len(reg.clashes) == 1
    assert "good-line" not in reg.names("spectrum")
    with pytest.raises(PluginError, match="two spectrum plugins are named 'good-line'") as excinfo:
        reg.get("spectrum", "good-line")
    assert all(f" from {p}" in str(excinfo.value) for p in ("acme-good", "acme-twin"))
    assert "other-line" in reg.names("spectrum") and "rolloff" in reg.names("spectrum")
    assert reg.get("spectrum", "power-law").__module__ == "frictionlab_spectra.power_law"
    assert [f.entry_point for f in reg.failures] == ["fake"]


def test_default_registry_is_cached():
    assert registry_module.default_registry() is registry_module.default_registry()


# ====================================================== hookspecs are documented


def _hookspecs():
    marker = f"{PROJECT_NAME}_spec"
    return [
        pytest.param(holder, name, id=name)
        for holder in (RegistrationSpecs, LifecycleSpecs)
        for name, fn in vars(holder).items()
        if callable(fn) and hasattr(fn, marker)
    ]


def test_hookspecs_found():
    names = {p.values[1] for p in _hookspecs()}
    assert set(KIND_HOOKS.values()) <= names
    assert {"run_started", "realization_done", "realization_failed", "run_finished"} <= names
    assert set(KIND_HOOKS) == set(KINDS)


@pytest.mark.parametrize("holder,name", _hookspecs())
def test_every_hookspec_has_a_docstring(holder, name):
    doc = inspect.getdoc(getattr(holder, name))
    assert doc and len(doc.split()) >= 5, f"hookspec {name} needs a docstring"


@pytest.mark.parametrize("holder,name", _hookspecs())
def test_every_hookspec_is_documented_in_the_plugin_contract_page(holder, name):
    page = ROOT / "docs" / "reference" / "plugin-contract.md"
    assert page.is_file(), f"{page} is missing"
    assert f"`{name}(" in page.read_text(encoding="utf-8"), f"{page.name} does not document the hook {name}"


def test_registration_hooks_take_only_register():
    for name in KIND_HOOKS.values():
        params = list(inspect.signature(getattr(RegistrationSpecs, name)).parameters)
        assert params == ["self", "register"]


def test_an_installed_plugin_can_listen_to_every_run(register_plugin, small_preset):
    """Lifecycle hooks are registry hooks too: a plugin implementing one is accepted (a misspelled
    one is not) and hears the runs made with its registry."""
    from frictionlab.compute import engine
    from frictionlab.preset import build_scene

    heard = []

    class RunLog:
        @hookimpl
        def run_finished(self, run, outcome):
            heard.append((run.scene.preset.name, outcome.done))

    registry = register_plugin(RunLog())
    assert len(registry.run_listeners()) == 1
    small_preset["realizations"] = 2
    engine.run(build_scene(small_preset, registry=registry), RunOptions(workers=1), registry=registry)
    assert heard == [("small", 2)]

    class Misspelled:
        @hookimpl
        def run_finnished(self, run, outcome):
            pass

    with pytest.raises(pluggy.PluginValidationError):
        register_plugin(Misspelled())

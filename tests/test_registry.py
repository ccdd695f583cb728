"""The registry and the plugin contract: built-ins, names, errors, entry points,
environment switches, hook documentation, and the conformance checks of
``frictionlab.testing`` (which must pass for every built-in and fail for broken
plugins)."""

from __future__ import annotations

import importlib
import importlib.metadata as md
import inspect
import os
import subprocess
import sys
import textwrap
import types
import warnings
from pathlib import Path

import numpy as np
import pluggy
import pytest
from pydantic import BaseModel, ConfigDict, Field

from frictionlab import (
    ContactCurve,
    ContactSolver,
    ForceNormalisation,
    PluginParams,
    Profile,
    SlopeEstimator,
    SpectrumGenerator,
    hookimpl,
)
from frictionlab import registry as registry_module
from frictionlab import testing as fltesting
from frictionlab.errors import ExitCode, PluginError
from frictionlab.hookspecs import PROJECT_NAME, LifecycleSpecs, RegistrationSpecs
from frictionlab.plugin import KINDS
from frictionlab.registry import (
    BUILTIN_MODULES,
    ENTRY_POINT_GROUP,
    KIND_HOOKS,
    LoadFailure,
    Registry,
    normalize_name,
    validate_plugin_class,
)

ROOT = Path(__file__).resolve().parents[1]


# =========================================================================== fakes


def _spectrum_class(name="fake-line", module="acme_one.lines", qualname="FakeLine"):
    class FakeLine(SpectrumGenerator):
        summary = "White-noise line for registry tests"

        class Params(PluginParams):
            points: int = Field(32, ge=8, le=4096, description="number of grid points")

        def generate(self, rng):
            return Profile(heights=rng.standard_normal(self.params.points), spacing=1.0)

        def rms_height(self):
            return 1.0

    FakeLine.name = name
    FakeLine.__module__ = module
    FakeLine.__qualname__ = qualname
    return FakeLine


def _provider(*classes, hook_name=None):
    """A hook holder (what an entry point points at) registering ``classes``."""
    holder = types.SimpleNamespace()
    by_hook: dict[str, list] = {}
    for cls in classes:
        by_hook.setdefault(hook_name or KIND_HOOKS[cls.kind], []).append(cls)
    for hook, members in by_hook.items():
        # pluggy reads the argument names: the implementation takes just ``register``
        def make(ms):
            def register_all(register):
                for cls in ms:
                    register(cls)

            return register_all

        setattr(holder, hook, hookimpl(make(tuple(members))))
    return holder


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
    first = _spectrum_class("twin-line", "acme_one.lines", "TwinLine")
    second = _spectrum_class("twin-line", "acme_two.spectra", "OtherTwin")
    reg.register_plugin(_provider(first), name="acme-one")
    assert reg.get("spectrum", "twin-line") is first
    with pytest.raises(PluginError) as excinfo:
        reg.register_plugin(_provider(second), name="acme-two")
    message = str(excinfo.value)
    assert "two spectrum plugins are named 'twin-line'" in message
    assert "acme_one.lines.TwinLine from acme_one.lines" in message
    assert "acme_two.spectra.OtherTwin from acme_two.spectra" in message
    assert "FRICTIONLAB_BLOCK_PLUGINS" in message
    # the rejected plugin is rolled back: the registry is as before
    assert reg.pm.get_plugin("acme-two") is None
    assert reg.get("spectrum", "twin-line") is first


def test_clash_with_a_builtin_names_frictionlab(reg):
    impostor = _spectrum_class("power-law", "acme_three.lines", "Impostor")
    with pytest.raises(PluginError) as excinfo:
        reg.register_plugin(_provider(impostor))
    message = str(excinfo.value)
    assert "frictionlab_spectra.power_law.PowerLaw from frictionlab" in message
    assert "acme_three.lines.Impostor from acme_three.lines" in message
    assert reg.get("spectrum", "power-law").__module__ == "frictionlab_spectra.power_law"


def test_one_class_registered_twice_is_not_a_clash(reg):
    cls = _spectrum_class("shared-line")
    reg.register_plugin(_provider(cls), name="one")
    reg.register_plugin(_provider(cls), name="two")
    assert reg.get("spectrum", "shared-line") is cls


# ============================================================== invalid classes


def _broken_variants():
    def with_(name="broken-line", **attrs):
        cls = _spectrum_class(name)
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
    ]


@pytest.mark.parametrize("cls,match", _broken_variants())
def test_invalid_class_is_a_clear_plugin_error(reg, cls, match):
    before = reg.infos()
    with pytest.raises(PluginError, match=match):
        reg.register_plugin(_provider(cls, hook_name="register_spectra"), name="acme-broken")
    assert reg.infos() == before
    assert reg.pm.get_plugin("acme-broken") is None
    with pytest.raises(PluginError, match=match):
        validate_plugin_class("spectrum", cls)


def test_valid_fake_passes_validation():
    validate_plugin_class("spectrum", _spectrum_class())


# ============================================================ hook validation


def test_misspelled_hook_fails_check_pending(reg):
    class Misspelled:
        @hookimpl
        def register_spectrum(self, register):  # sic: the spec is register_spectra
            register(_spectrum_class("never-line"))

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
    holder = _provider(_spectrum_class("temporary-line"))
    reg.register_plugin(holder)
    assert "temporary-line" in reg.names("spectrum")
    reg.unregister_plugin(holder)
    assert "temporary-line" not in reg.names("spectrum")


# ========================================================= entry points (faked)


GOOD_SOURCE = '''
import numpy as np
from pydantic import Field

import frictionlab
from frictionlab import PluginParams, Profile, SpectrumGenerator


class {cls}(SpectrumGenerator):
    name = "{name}"
    summary = "White-noise line from a fake distribution"

    class Params(PluginParams):
        points: int = Field(32, ge=8, le=4096, description="number of grid points")

    def generate(self, rng):
        return Profile(heights=rng.standard_normal(self.params.points), spacing=1.0)

    def rms_height(self):
        return 1.0


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
    reg = Registry(env={"FRICTIONLAB_PLUGINS": " other , nonexistent"})
    assert "other-line" in reg.names("spectrum")
    assert "good-line" not in reg.names("spectrum")
    assert "power-law" in reg.names("spectrum")


def test_blocked_plugins(two_good):
    reg = Registry(env={"FRICTIONLAB_BLOCK_PLUGINS": "good"})
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


def test_misspelled_hook_in_an_entry_point_fails_loudly(two_good):
    two_good("acme-typo", "typo", "acme_typo_plugin", MISSPELLED_SOURCE)
    with pytest.raises(pluggy.PluginValidationError, match="register_spectrum"):
        Registry(env={})
    assert "good-line" in Registry(env={"FRICTIONLAB_BLOCK_PLUGINS": "typo"}).names("spectrum")


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
def test_every_hookspec_is_mentioned_in_the_readme(holder, name):
    readme = ROOT / "README.md"
    assert readme.is_file(), "README.md is missing"
    assert name in readme.read_text(encoding="utf-8"), f"README.md does not mention the hook {name}"


def test_registration_hooks_take_only_register():
    for name in KIND_HOOKS.values():
        params = list(inspect.signature(getattr(RegistrationSpecs, name)).parameters)
        assert params == ["self", "register"]


# ================================================ conformance: built-ins pass


def _builtin_cases():
    cases = []
    extra = {
        ("spectrum", "power-law"): [{"hurst": 0.8, "points": 256}, {"hurst": 0.3, "points": 255, "amplitudes": "rayleigh"}],
        ("spectrum", "rolloff"): [{"hurst": 1.0, "points": 256, "rolloff_wavelength": 64.0}],
        ("spectrum", "profile-file"): [{"path": "<profile>", "spacing": 0.5}],
        ("spectrum", "surface-file"): [{"path": "<surface>", "spacing": 0.5}],
        ("spectrum", "power-law-2d"): [{"hurst": 0.8, "points": 32}, {"hurst": 0.3, "points": 31, "points_y": 40}],
        ("spectrum", "rolloff-2d"): [{"hurst": 1.0, "points": 48, "rolloff_wavelength": 16.0, "amplitudes": "rayleigh"}],
    }
    for info in Registry(discover=False).infos():
        for i, params in enumerate(extra.get((info.kind, info.name), [{}])):
            cases.append(pytest.param(info.kind, info.cls, params, id=f"{info.kind}:{info.name}:{i}"))
    return cases


@pytest.mark.parametrize("kind,cls,params", _builtin_cases())
def test_builtins_pass_the_conformance_checks(kind, cls, params, tmp_path):
    params = dict(params)
    deterministic = False
    if params.get("path") == "<profile>":
        path = tmp_path / "profile.txt"
        np.savetxt(path, np.random.default_rng(3).standard_normal(200).cumsum())
        params["path"] = str(path)
        deterministic = True
    if params.get("path") == "<surface>":
        params["path"] = str(tmp_path / "surface.npy")
        np.save(params["path"], np.random.default_rng(3).standard_normal((16, 24)).cumsum(axis=1))
        deterministic = True
    fltesting.check_plugin(kind, cls, deterministic=deterministic, **params)


# ========================================= conformance: broken plugins fail


class GoodSpectrum(SpectrumGenerator):
    name = "good-spectrum"
    summary = "Smooth random line for conformance tests"

    class Params(PluginParams):
        points: int = Field(128, ge=8, le=1 << 20, description="number of grid points")
        spacing: float = Field(1.0, gt=0, description="grid spacing")

    def generate(self, rng):
        n = self.params.points
        spectrum = np.zeros(n // 2 + 1, complex)
        spectrum[1:4] = np.exp(2j * np.pi * rng.random(3)) * n / 2
        z = np.fft.irfft(spectrum, n=n)
        return Profile(heights=z * (1 / np.sqrt(1.5)), spacing=self.params.spacing)

    def rms_height(self):
        return 1.0

    def psd(self, q):
        return np.exp(-np.asarray(q, float))


class GoodSolver(ContactSolver):
    """Springs of stiffness k dx, solved exactly (sort + cumulative sums)."""

    name = "good-solver"
    summary = "Exact spring row for conformance tests"
    normalisations = {1: ForceNormalisation(load="force", modulus="k", extent="length")}
    problem = "Winkler foundation"

    class Params(PluginParams):
        modulus: float = Field(2.0, gt=0, le=1e12, description="spring modulus k")

    def stiffness(self):
        return self.params.modulus

    def solve(self, profile, loads, control, slopes):
        z, dx, k = profile.heights, profile.spacing, self.params.modulus
        top = np.sort(z)[::-1]
        n = top.size
        levels = []
        for load in loads:
            if control == "indentation":
                levels.append(top[0] - load)
                continue
            cum = np.cumsum(top)
            for m in range(1, n + 1):
                c = (cum[m - 1] - load / (k * dx)) / m
                if m == n or c >= top[m]:
                    levels.append(c)
                    break
        levels = np.array(levels)
        inside = z[None, :] > levels[:, None]
        count = inside.sum(axis=1)
        force = k * dx * np.maximum(z[None, :] - levels[:, None], 0).sum(axis=1)
        rms = np.sqrt((inside * slopes[None, :] ** 2).sum(axis=1) / np.maximum(count, 1))
        return ContactCurve(
            force=force,
            indentation=top[0] - levels,
            contact_count=count,
            contact_fraction=count / n,
            slope_rms_contact=rms,
            extras={"levels": levels},
        )


class GoodSlopes(SlopeEstimator):
    name = "good-slopes"
    summary = "Periodic forward differences for conformance tests"

    class Params(PluginParams):
        pass

    def slopes(self, heights, spacing, periodic=True):
        return _fd(heights, spacing, periodic)


def _replace_curve(curve, **changes):
    fields = {name: getattr(curve, name) for name in ContactCurve.__dataclass_fields__}
    fields.update(changes)
    return ContactCurve(**fields)


def _spectrum_variant(qualname, **methods):
    return type(qualname, (GoodSpectrum,), {"name": "broken-spectrum", **methods})


def _solver_variant(qualname, change):
    def solve(self, profile, loads, control, slopes):
        return change(GoodSolver.solve(self, profile, loads, control, slopes), profile, loads)

    return type(qualname, (GoodSolver,), {"name": "broken-solver", "solve": solve})


def _slopes_variant(qualname, slopes):
    return type(qualname, (GoodSlopes,), {"name": "broken-slopes", "slopes": slopes})


@pytest.mark.parametrize(
    "kind,cls", [("spectrum", GoodSpectrum), ("solver", GoodSolver), ("slope", GoodSlopes)]
)
def test_good_fakes_pass(kind, cls):
    fltesting.check_plugin(kind, cls)


SPECTRUM_BREAKAGES = [
    ("NonDeterministic", {"generate": lambda self, rng: GoodSpectrum.generate(self, np.random.default_rng())},
     "same seed gave different heights"),
    ("IgnoresSeed", {"generate": lambda self, rng: GoodSpectrum.generate(self, np.random.default_rng(0))},
     "different seeds gave identical heights"),
    ("NaNHeights", {"generate": lambda self, rng: Profile(np.full(8, np.nan), 1.0)}, "must be finite"),
    ("TwoDimensional", {"generate": lambda self, rng: Profile(rng.random((4, 4)), 1.0)}, "must be 1-D"),
    ("IntegerHeights", {"generate": lambda self, rng: Profile(rng.integers(0, 9, 16), 1.0)}, "floating point"),
    ("ZeroSpacing", {"generate": lambda self, rng: Profile(rng.random(16), 0.0)}, r"spacing must be finite and > 0"),
    ("NotAProfile", {"generate": lambda self, rng: rng.random(16)}, "must return a frictionlab.Profile"),
    ("ZeroRms", {"rms_height": lambda self: 0.0}, r"rms_height\(\) must be finite and > 0"),
    ("WrongRms", {"rms_height": lambda self: 10.0}, "within a factor of 3"),
    ("ScalarPsd", {"psd": lambda self, q: 1.0}, r"psd\(q\)"),
    ("NegativePsd", {"psd": lambda self, q: -np.ones_like(q)}, r"psd\(q\) must be >= 0"),
    ("Raises", {"generate": lambda self, rng: 1 / 0}, "raised ZeroDivisionError"),
    ("BadRmsSlope", {"rms_slope": lambda self: float("nan")}, r"rms_slope\(\)"),
]


@pytest.mark.parametrize("qualname,methods,match", SPECTRUM_BREAKAGES, ids=[b[0] for b in SPECTRUM_BREAKAGES])
def test_spectrum_check_fails_for_broken_generators(qualname, methods, match):
    cls = _spectrum_variant(qualname, **methods)
    with pytest.raises(AssertionError, match=match) as excinfo:
        fltesting.check_spectrum(cls)
    assert qualname in str(excinfo.value)


def test_deterministic_flag_allows_seed_independence():
    cls = _spectrum_variant("FixedLine", generate=lambda self, rng: GoodSpectrum.generate(self, np.random.default_rng(0)))
    fltesting.check_spectrum(cls, deterministic=True)
    with pytest.raises(AssertionError):  # but not a different answer for the same seed
        fltesting.check_spectrum(
            _spectrum_variant("Drifting", generate=lambda self, rng: GoodSpectrum.generate(self, np.random.default_rng())),
            deterministic=True,
        )


def _noisy(curve, profile, loads):
    return _replace_curve(curve, force=curve.force * (1 + 1e-9 * np.random.default_rng().random(loads.size)))


def _sorts_in_place(curve, profile, loads):
    profile.heights.sort()
    return curve


SOLVER_BREAKAGES = [
    ("WrongShape", lambda c, p, l: _replace_curve(c, contact_count=c.contact_count[:-1]), r"must have shape \(5,\)"),
    ("Decreasing", lambda c, p, l: _replace_curve(c, contact_count=c.contact_count[::-1],
                                                   contact_fraction=c.contact_fraction[::-1]), "must not decrease"),
    ("NoContact", lambda c, p, l: _replace_curve(c, contact_count=c.contact_count * 0,
                                                  contact_fraction=c.contact_fraction * 0), r"must lie in 1 \.\. 64"),
    ("TooMany", lambda c, p, l: _replace_curve(c, contact_count=c.contact_count + 64,
                                                contact_fraction=(c.contact_count + 64) / 64), r"must lie in 1 \.\. 64"),
    ("WrongFraction", lambda c, p, l: _replace_curve(c, contact_fraction=c.contact_fraction / 2), "contact_count / N"),
    ("FractionalCount", lambda c, p, l: _replace_curve(c, contact_count=c.contact_count + 0.5,
                                                        contact_fraction=(c.contact_count + 0.5) / 64), "whole numbers"),
    ("DimensionlessForce", lambda c, p, l: _replace_curve(c, force=c.force / 1000), "must report the loads"),
    ("NaNSlope", lambda c, p, l: _replace_curve(c, slope_rms_contact=c.slope_rms_contact * np.nan), "must be finite"),
    ("HugeSlope", lambda c, p, l: _replace_curve(c, slope_rms_contact=c.slope_rms_contact + 100), r"max \|slope\|"),
    ("ShortExtras", lambda c, p, l: _replace_curve(c, extras={"iterations": np.ones(2)}), "one entry per load"),
    ("NotRepeatable", _noisy, "not repeatable"),
    ("MutatesInput", _sorts_in_place, "modified its inputs"),
    ("NotACurve", lambda c, p, l: {"force": c.force}, "must return a frictionlab.ContactCurve"),
]


@pytest.mark.parametrize("qualname,change,match", SOLVER_BREAKAGES, ids=[b[0] for b in SOLVER_BREAKAGES])
def test_solver_check_fails_for_broken_solvers(qualname, change, match):
    cls = _solver_variant(qualname, change)
    with pytest.raises(AssertionError, match=match) as excinfo:
        fltesting.check_solver(cls)
    assert qualname in str(excinfo.value)


def test_solver_check_fails_for_bad_stiffness():
    cls = type("Soft", (GoodSolver,), {"name": "soft", "stiffness": lambda self: -1.0})
    with pytest.raises(AssertionError, match=r"stiffness\(\) must be finite and > 0"):
        fltesting.check_solver(cls)


WRONG_NORMALISATIONS = [
    ("PerUnitDepth", ForceNormalisation(load="force per unit depth", modulus="k", extent="length")),
    ("NoLength", ForceNormalisation(load="force", modulus="k", extent="one")),
]


@pytest.mark.parametrize("qualname,normalisation", WRONG_NORMALISATIONS, ids=[w[0] for w in WRONG_NORMALISATIONS])
def test_solver_check_fails_for_a_wrong_normalisation(qualname, normalisation):
    """Springs of stiffness k dx under a force: any other declared meaning of f is not dimensionless."""
    cls = type(qualname, (GoodSolver,), {"name": "wrong-f", "normalisations": {1: normalisation}})
    with pytest.raises(AssertionError, match="is not dimensionless as declared"):
        fltesting.check_solver(cls)


def test_the_half_plane_with_the_old_f_fails_the_kit():
    """f = F' / (E* h L) for a force per unit depth (the half-plane's f before) fails the unit check."""
    from frictionlab_solvers import BEMHalfPlane

    old = ForceNormalisation(load="force per unit depth", modulus="E*", extent="length")
    cls = type("OldHalfPlane", (BEMHalfPlane,), {"name": "old-halfplane", "normalisations": {1: old}})
    with pytest.raises(AssertionError, match="is not dimensionless as declared"):
        fltesting.check_solver(cls)
    fltesting.check_solver(BEMHalfPlane)


def test_solver_check_fails_when_periodic_only_is_not_kept():
    cls = type("Loose", (GoodSolver,), {"name": "loose", "periodic_only": True})
    with pytest.raises(AssertionError, match="periodic_only is True, but a non-periodic profile was accepted"):
        fltesting.check_solver(cls)


@pytest.mark.parametrize(
    "attributes,match",
    [
        ({"normalisations": {}}, "normalisations must map each of its dimensions"),
        ({"dimensions": (1, 2)}, "normalisations must map each of its dimensions"),
        ({"problem": ""}, "problem must name the physical problem"),
        ({"contact_measure": "area"}, "contact_measure must be one of"),
        ({"body_params": ("youngs_modulus",)}, "body_params names 'youngs_modulus', not fields of Params"),
        ({"tolerance_param": "tol"}, "tolerance_param names 'tol'"),
        ({"normalisations": {1: ForceNormalisation(load="force", modulus="k", extent="area")}}, "not defined for a 1D"),
    ],
)
def test_solver_declarations_are_checked_at_registration(attributes, match):
    cls = type("Undeclared", (GoodSolver,), {"name": "undeclared", **attributes})
    with pytest.raises(PluginError, match=match):
        registry_module.validate_plugin_class("solver", cls)


def test_spectrum_check_fails_for_wrong_declarations():
    cls = _spectrum_variant("SaysPeriodic", periodic=lambda self: False)
    with pytest.raises(AssertionError, match=r"periodic\(\) must be True or False and equal Profile.periodic"):
        fltesting.check_spectrum(cls)
    cls = _spectrum_variant("WrongShape", grid_shape=lambda self: (3,))
    with pytest.raises(AssertionError, match=r"grid_shape\(\) must be None or the shape"):
        fltesting.check_spectrum(cls)
    cls = _spectrum_variant("LineOfALine", equivalent_line=lambda self: GoodSpectrum())
    with pytest.raises(AssertionError, match=r"equivalent_line\(\) must be None"):
        fltesting.check_spectrum(cls)
    cls = _spectrum_variant("NegativeHurst", hurst_exponent=lambda self: -1.0)
    with pytest.raises(AssertionError, match=r"hurst_exponent\(\)"):
        fltesting.check_spectrum(cls)


def _fd(heights, spacing, periodic=True):
    out = (np.roll(heights, -1) - heights) / spacing
    if not periodic:
        out[-1] = out[-2]
    return out


def _demean_in_place(self, heights, spacing, periodic=True):
    heights -= heights.mean()
    return _fd(heights, spacing, periodic)


SLOPE_BREAKAGES = [
    ("WrongShape", lambda self, z, dx, periodic=True: np.diff(z) / dx, r"must have shape \(128,\)"),
    ("ForgetsSpacing", lambda self, z, dx, periodic=True: np.roll(z, -1) - z, "order of magnitude"),
    ("SignFlipped", lambda self, z, dx, periodic=True: -_fd(z, dx), "order of magnitude and sign"),
    ("Offset", lambda self, z, dx, periodic=True: _fd(z, dx) + 1e-3, "constant line must have zero slopes"),
    ("ReturnsList", lambda self, z, dx, periodic=True: list(_fd(z, dx)), "must be a numpy array"),
    ("NaN", lambda self, z, dx, periodic=True: np.where(np.arange(z.size) == 0, np.nan, _fd(z, dx)), "must be finite"),
    ("Integer", lambda self, z, dx, periodic=True: np.round(_fd(z, dx)).astype(int), "floating point"),
    ("MutatesInput", _demean_in_place, "modified its input"),
    ("Random", lambda self, z, dx, periodic=True: _fd(z, dx) + 1e-12 * np.random.default_rng().random(z.size),
     "not repeatable"),
    ("WrapsAScan", lambda self, z, dx, periodic=True: _fd(z, dx), "a difference across the ends"),
    ("NoPeriodicArgument", lambda self, z, dx: _fd(z, dx), "raised TypeError"),
]


@pytest.mark.parametrize("qualname,slopes,match", SLOPE_BREAKAGES, ids=[b[0] for b in SLOPE_BREAKAGES])
def test_slope_check_fails_for_broken_estimators(qualname, slopes, match):
    cls = _slopes_variant(qualname, slopes)
    with pytest.raises(AssertionError, match=match) as excinfo:
        fltesting.check_slope_estimator(cls)
    assert qualname in str(excinfo.value)


# --------------------------------------------------------- class-level failures


class _NoAssignmentParams(BaseModel):
    model_config = ConfigDict(extra="forbid")
    points: int = Field(128, ge=8, description="number of grid points")


class _UnenforcedParams(PluginParams):
    points: int = Field(128, description="number of grid points", json_schema_extra={"minimum": 8})


class _RequiredParams(PluginParams):
    points: int = Field(ge=8, description="number of grid points")
    spacing: float = Field(1.0, gt=0, description="grid spacing")


class _NotStoring(GoodSpectrum):
    name = "not-storing"

    def __init__(self, params=None, **kwargs):
        self.params = None


CLASS_BREAKAGES = [
    ("BadName", {"name": "Bad_Name"}, "name must be kebab-case"),
    ("NoSummary", {"summary": " "}, "summary must be one non-empty line"),
    ("LooseParams", {"Params": type("P", (BaseModel,), {"__annotations__": {"x": int}, "x": Field(1, description="x")})},
     "must forbid unknown keys"),
    ("Undescribed", {"Params": type("P", (PluginParams,), {"__annotations__": {"x": int}, "x": 1})}, "no description"),
    ("StringReferences", {"references": "10.1000/xyz"}, "references must be a tuple of strings"),
    ("NoAssignmentCheck", {"Params": _NoAssignmentParams}, "validate on assignment"),
    ("UnenforcedBound", {"Params": _UnenforcedParams}, r"Params.points = 7 \(past its minimum 8\) was accepted"),
    ("RequiredField", {"Params": _RequiredParams}, r"Params\(\*\*\{\}\) is invalid \(pass the required values"),
]


@pytest.mark.parametrize("qualname,attrs,match", CLASS_BREAKAGES, ids=[b[0] for b in CLASS_BREAKAGES])
def test_class_check_fails_for_broken_classes(qualname, attrs, match):
    cls = type(qualname, (GoodSpectrum,), dict(attrs))
    with pytest.raises(AssertionError, match=match) as excinfo:
        fltesting.check_plugin_class("spectrum", cls)
    assert qualname in str(excinfo.value)


def test_class_check_uses_given_params():
    cls = type("NeedsPoints", (GoodSpectrum,), {"Params": _RequiredParams})
    fltesting.check_plugin_class("spectrum", cls, params={"points": 64})
    fltesting.check_plugin("spectrum", cls, points=64)


def test_class_check_fails_when_constructor_drops_params():
    with pytest.raises(AssertionError, match="self.params"):
        fltesting.check_plugin_class("spectrum", _NotStoring)


def test_class_check_rejects_unknown_kind():
    with pytest.raises(ValueError, match="kind must be one of"):
        fltesting.check_plugin_class("surface", GoodSpectrum)


def test_class_check_skips_bounds_when_none():
    fltesting.check_plugin_class("slope", GoodSlopes)  # no fields at all


def test_check_plugin_runs_the_kind_check():
    cls = _spectrum_variant("IgnoresSeedAgain", generate=lambda self, rng: GoodSpectrum.generate(self, np.random.default_rng(0)))
    fltesting.check_plugin_class("spectrum", cls)
    with pytest.raises(AssertionError, match="different seeds"):
        fltesting.check_plugin("spectrum", cls)


# ==================================================== the pytest plugin itself


def test_frictionlab_registry_fixture(frictionlab_registry):
    assert isinstance(frictionlab_registry, Registry)
    assert "power-law" in frictionlab_registry.names("spectrum")


def test_register_plugin_fixture_accepts_modules_holders_and_classes(register_plugin, frictionlab_registry):
    module = types.ModuleType("acme_module_plugin")
    module.register_solvers = hookimpl(lambda register: register(GoodSolver))
    assert register_plugin(module) is frictionlab_registry
    assert frictionlab_registry.get("solver", "Good_Solver") is GoodSolver
    register_plugin(GoodSlopes)  # a plugin class: registered through its kind's hook
    assert frictionlab_registry.get("slope", "good-slopes") is GoodSlopes
    register_plugin(_provider(GoodSpectrum), name="acme-holder")
    assert frictionlab_registry.pm.get_plugin("acme-holder") is not None


def test_register_plugin_fixture_propagates_errors(register_plugin, frictionlab_registry):
    class Typo:
        @hookimpl
        def register_solver(self, register):
            pass

    with pytest.raises(pluggy.PluginValidationError):
        register_plugin(Typo())
    with pytest.raises(PluginError, match="kebab-case"):
        register_plugin(_provider(_spectrum_class("Not_Kebab")))
    assert frictionlab_registry.names("spectrum") == Registry(discover=False).names("spectrum")


def test_pytest_plugin_autoloads_and_unregisters_after_each_test(tmp_path):
    """In a separate pytest run: the fixtures exist without any import (pytest11
    entry point), and a plugin registered in one test is gone in the next even
    when the registry fixture is overridden with a wider scope."""
    (tmp_path / "test_fixture_scope.py").write_text(
        textwrap.dedent(
            '''
            import pytest

            import frictionlab
            from frictionlab.registry import Registry

            SHARED = Registry(discover=False)

            @pytest.fixture
            def frictionlab_registry():
                return SHARED

            class Holder:
                @staticmethod
                @frictionlab.hookimpl
                def register_slope_estimators(register):
                    pass

            def test_first(register_plugin):
                register_plugin(Holder, name="acme-holder")
                assert SHARED.pm.get_plugin("acme-holder") is Holder

            def test_second():
                assert SHARED.pm.get_plugin("acme-holder") is None
            '''
        )
    )
    env = {k: v for k, v in os.environ.items() if k not in ("PYTEST_DISABLE_PLUGIN_AUTOLOAD", "PYTEST_ADDOPTS")}
    result = subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--rootdir", str(tmp_path), str(tmp_path)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=env,
        timeout=120,
    )
    assert result.returncode == 0, result.stdout + result.stderr
    assert "2 passed" in result.stdout


def test_testing_module_import_is_cheap():
    """Loaded in every pytest session: importing it adds nothing to what
    ``import frictionlab`` and ``import pytest`` already import (no registry, no
    plugin discovery, no built-in physics)."""
    code = (
        "import sys, frictionlab, pytest; before = set(sys.modules); "
        "import frictionlab.testing; print(sorted(set(sys.modules) - before))"
    )
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=True)
    assert out.stdout.strip() == "['frictionlab.testing']", out.stdout


def test_an_installed_plugin_can_listen_to_every_run(register_plugin, small_preset):
    """Lifecycle hooks are registry hooks too: a plugin implementing one is accepted (a misspelled
    one is not) and hears the runs made with its registry."""
    from frictionlab import engine
    from frictionlab.preset import build_scene

    heard = []

    class RunLog:
        @hookimpl
        def run_finished(self, run, outcome):
            heard.append((run.scene.preset.name, outcome.done))

    registry = register_plugin(RunLog())
    assert len(registry.run_listeners()) == 1
    small_preset["realizations"] = 2
    engine.run(build_scene(small_preset, registry=registry), workers=1, registry=registry)
    assert heard == [("small", 2)]

    class Misspelled:
        @hookimpl
        def run_finnished(self, run, outcome):
            pass

    with pytest.raises(pluggy.PluginValidationError):
        register_plugin(Misspelled())

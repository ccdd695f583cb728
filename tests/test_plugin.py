"""The plugin base contract: constructors only store validated parameters."""

import re

import pytest
from pydantic import ValidationError

from frictionlab_solvers import MDRSprings
from frictionlab_spectra import PowerLaw


def test_constructor_stores_validated_params_from_kwargs_or_a_params_instance():
    by_kwargs = PowerLaw(hurst=0.7, points=512)
    by_params = PowerLaw(PowerLaw.Params(hurst=0.7, points=512))
    assert by_kwargs.params == by_params.params
    assert "hurst=0.7" in repr(by_kwargs)
    with pytest.raises(ValidationError, match="hurst"):
        PowerLaw(hurst=7.0, points=512)
    with pytest.raises(TypeError, match="either a Params instance or keyword arguments"):
        PowerLaw(PowerLaw.Params(hurst=0.7, points=512), hurst=0.5)
    with pytest.raises(TypeError, match="must be an instance of MDRSprings.Params. Got Params instead."):
        MDRSprings(PowerLaw.Params(hurst=0.7, points=512))


def test_a_rejected_edit_leaves_the_old_value():
    """Editing params in place (the TUI does) must never leave an invalid value,
    also when a check across fields (not the field's own bound) rejects it."""
    params = PowerLaw.Params(hurst=0.8, points=1024)
    with pytest.raises(ValidationError):
        params.short_cutoff = 1.0  # below the Nyquist limit of 2 dx: a model-level check
    assert params.short_cutoff is None
    with pytest.raises(ValidationError):
        params.hurst = 5.0  # the field's own bound
    assert params.hurst == 0.8
    params.short_cutoff = 20.0
    assert params.short_cutoff == 20.0


# ------------------------------------------------------------------ the contract, all of it


def test_the_conformance_kit_covers_every_declared_item():
    """Whatever a kind's base class declares (``plugin.contract``), its check says how it is
    checked: a new declaration without a check fails here."""
    import re

    from frictionlab import testing
    from frictionlab.plugin import KINDS, contract

    checks = {"spectrum": testing.check_spectrum, "solver": testing.check_solver, "slope": testing.check_slope_estimator}
    assert set(checks) == set(KINDS)
    for kind, check in checks.items():
        documented = testing.check_plugin_class.__doc__ + check.__doc__
        missing = [name for name in sorted(contract(kind)) if not re.search(rf"\b{re.escape(name)}\b", documented)]
        assert not missing, f"the {kind} check does not say how it checks {missing}"


def _strict(cls):
    """``cls`` under another name, whose instances refuse the framework (any module of the
    ``frictionlab`` package) every attribute its contract does not declare."""
    import sys

    from frictionlab.plugin import contract

    allowed = contract(cls.kind)

    def __getattribute__(self, name):
        if not name.startswith("__") and name not in allowed:
            caller = sys._getframe(1).f_globals.get("__name__", "")
            if caller == "frictionlab" or caller.startswith("frictionlab."):
                raise AssertionError(f"{caller} read {name!r} of a {cls.kind} plugin: not in its contract")
        return object.__getattribute__(self, name)

    return type(cls.__name__, (cls,), {"name": f"strict-{cls.name}", "__getattribute__": __getattribute__})


def test_the_framework_uses_nothing_of_a_plugin_beyond_the_contract(tmp_path, register_plugin, monkeypatch):
    """Runs, sweeps, result files, the memory check and its advice, and the trade-off study,
    on plugins that refuse the framework anything undeclared."""
    import math

    from frictionlab.compute import memory
    from frictionlab.errors import RunError
    from frictionlab.options import RunOptions
    from frictionlab.preset import build_scene
    from frictionlab.runs.runner import run_to_folder
    from frictionlab.runs.sweep import plan_sweep, run_sweep
    from frictionlab.tradeoff.axes import Study
    from frictionlab.tradeoff.options import StudyOptions
    from frictionlab.tradeoff.scenes import SceneFactory
    from frictionlab_slopes import ForwardDifference
    from frictionlab_solvers import BEMHalfSpace, WinklerSprings
    from frictionlab_spectra import PowerLawSurface

    for plugin in (PowerLaw, PowerLawSurface, MDRSprings, WinklerSprings, BEMHalfSpace, ForwardDifference):
        registry = register_plugin(_strict(plugin))
    line = {
        "name": "strict", "seed": 3, "realizations": 3, "fit": {"bootstrap": 20},
        "spectrum": {"name": "strict-power-law", "params": {"hurst": 0.8, "points": 256, "rms_height": 1.0}},
        "solver": {"name": "strict-mdr"}, "slope": {"name": "strict-forward-difference"},
        "loading": {"start": 0.5, "stop": 5.0, "steps": 5, "spacing": "log"},
    }  # fmt: skip
    surface = {**line, "spectrum": {"name": "strict-power-law-2d", "params": {"hurst": 0.8, "points": 16}}}
    one = RunOptions(workers=1)
    # plot.png (a second of drawing each) for the line and the half-space: the figure reads the same
    # plugin attributes whatever the solver, so the other two runs leave it out
    for data, solver, plot in ((line, "strict-mdr", True), (surface, "strict-mdr", False),
                               (surface, "strict-winkler", False), (surface, "strict-bem-halfspace", True)):  # fmt: skip
        scene = build_scene({**data, "solver": {"name": solver}, "output": {"plot": plot}}, registry=registry)
        outcome, _ = run_to_folder(scene, tmp_path / f"{solver}-{scene.geometry}", one)
        assert outcome.status == "completed" and not outcome.failures, outcome.failures
    # its points' plot.png left out (the line's figure again, drawn above); sweep.png is drawn
    sweep = plan_sweep({**line, "output": {"plot": False}, "sweep": {"parameters": {"seed": {"values": [1, 2]}}}},
                       registry=registry)  # fmt: skip
    assert run_sweep(sweep, tmp_path / "sweep", one).status == "completed"
    monkeypatch.setattr(memory, "available_memory", lambda: (200 * 2**20, "a test"))
    with pytest.raises(RunError, match="spectrum.params.points <= "):  # the advice names points_param
        memory.check_fits(build_scene({**line, "realizations": 1, "spectrum": {**line["spectrum"], "params": {
            "hurst": 0.8, "points": 10_000_000}}}, registry=registry), workers=1, executor="serial")  # fmt: skip
    study = Study(SceneFactory(surface, registry, "strict"), StudyOptions(
        axes=("grid", "solver", "tolerance"), grid_factors=(0.5, 1.0), grid_realizations=2, compare_realizations=2,
        compare_steps=3, compare_points_surface=16, tolerances=(1e-3, 1e-6), reference="strict-bem-halfspace"))  # fmt: skip
    rows = study.run()
    assert {row.axis for row in rows} == {"grid", "solver", "tolerance"}
    assert all(math.isfinite(row.b) for row in rows)


@pytest.mark.parametrize("value", ["maybe", "2", "ture", "\x1b[2J"])
def test_a_yes_no_variable_set_to_another_value_is_said(value):
    """FRICTIONLAB_DISABLE_DISCOVERY=maybe (or a typo of true) was read as off without a word:
    the entry points it was meant to keep out loaded all the same."""
    from frictionlab.plugin.registry import Registry

    for key in ("FRICTIONLAB_DISABLE_DISCOVERY", "FRICTIONLAB_TRACE_HOOKS"):
        with pytest.warns(RuntimeWarning, match=re.escape(f"{key}={value!r}") + r" is not one of 1, true, yes, on \(on\) or 0, .* read as off"):
            Registry(env={key: value})


def test_a_yes_no_variable_of_a_known_spelling_is_read_without_a_word(recwarn):
    from frictionlab.plugin.registry import Registry

    for value in ("", "0", "off", "No", " TRUE "):
        Registry(discover=False, env={"FRICTIONLAB_TRACE_HOOKS": value.replace("TRUE", "false")})
    assert not [w for w in recwarn if "FRICTIONLAB" in str(w.message)]

"""The solver check fails for solvers broken in one way each, and for a wrong meaning of f."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from frictionlab import (
    ForceNormalisation,
)
from frictionlab.plugin import registry as registry_module
from frictionlab import testing as fltesting
from frictionlab.errors import PluginError
from frictionlab.plugin import KINDS

from .fakes import GoodSolver, fails_naming, replace_curve, solver_variant

ROOT = Path(__file__).resolve().parents[2]

KIND_HOOKS = {kind: base.register_hook for kind, base in KINDS.items()}


# =========================================================================== fakes


def _noisy(curve, profile, loads):
    return replace_curve(curve, force=curve.force * (1 + 1e-9 * np.random.default_rng().random(loads.size)))


def _sorts_in_place(curve, profile, loads):
    profile.heights.sort()
    return curve


SOLVER_BREAKAGES = [
    ("WrongShape", lambda c, p, l: replace_curve(c, contact_count=c.contact_count[:-1]), r"must have shape \(5,\)"),
    ("Decreasing", lambda c, p, l: replace_curve(c, contact_count=c.contact_count[::-1],
                                                   contact_fraction=c.contact_fraction[::-1]), "must not decrease"),
    ("NoContact", lambda c, p, l: replace_curve(c, contact_count=c.contact_count * 0,
                                                  contact_fraction=c.contact_fraction * 0), r"must lie in 1 \.\. 64"),
    ("TooMany", lambda c, p, l: replace_curve(c, contact_count=c.contact_count + 64,
                                                contact_fraction=(c.contact_count + 64) / 64), r"must lie in 1 \.\. 64"),
    ("WrongFraction", lambda c, p, l: replace_curve(c, contact_fraction=c.contact_fraction / 2), "contact_count / N"),
    ("FractionalCount", lambda c, p, l: replace_curve(c, contact_count=c.contact_count + 0.5,
                                                        contact_fraction=(c.contact_count + 0.5) / 64), "whole numbers"),
    ("DimensionlessForce", lambda c, p, l: replace_curve(c, force=c.force / 1000), "must report the loads"),
    ("SingleSlope", lambda c, p, l: replace_curve(c, slope_rms_contact=c.slope_rms_contact.astype(np.float32)),
     r"slope_rms_contact must be float64 \(double precision\)"),
    ("NaNSlope", lambda c, p, l: replace_curve(c, slope_rms_contact=c.slope_rms_contact * np.nan), "must be finite"),
    ("HugeSlope", lambda c, p, l: replace_curve(c, slope_rms_contact=c.slope_rms_contact + 100), r"max \|slope\|"),
    ("ShortExtras", lambda c, p, l: replace_curve(c, extras={"iterations": np.ones(2)}), "one entry per load"),
    ("NotRepeatable", _noisy, "not repeatable"),
    ("MutatesInput", _sorts_in_place, "modified its inputs"),
    ("NotACurve", lambda c, p, l: {"force": c.force}, "must return a frictionlab.ContactCurve"),
]


@pytest.mark.parametrize("qualname,change,match", SOLVER_BREAKAGES, ids=[b[0] for b in SOLVER_BREAKAGES])
def test_solver_check_fails_for_broken_solvers(qualname, change, match):
    cls = solver_variant(qualname, change)
    fails_naming(fltesting.check_solver, cls, match)


def test_solver_check_fails_for_bad_stiffness():
    cls = type("Soft", (GoodSolver,), {"name": "soft", "stiffness": lambda self: -1.0})
    with pytest.raises(AssertionError, match=r"stiffness\(\) must be finite and > 0"):
        fltesting.check_solver(cls)


def _ends(how):
    def stiffness(self):
        if how == "exit":
            import sys

            sys.exit("bye from stiffness")
        raise KeyboardInterrupt("by no Ctrl-C")

    return stiffness


@pytest.mark.parametrize("how, said", [("exit", "SystemExit: bye from stiffness"),
                                       ("interrupt", "KeyboardInterrupt: by no Ctrl-C")])
@pytest.mark.parametrize("check", ["check_solver", "check_plugin"])
def test_a_solver_that_exits_or_interrupts_fails_the_check_and_the_tests_go_on(how, said, check):
    """Taken as they came, the kit let a plugin's sys.exit() out, and its KeyboardInterrupt ended
    the whole pytest session ("no tests ran")."""
    cls = type("Ending", (GoodSolver,), {"name": "ending", "stiffness": _ends(how)})
    arguments = (cls,) if check == "check_solver" else ("solver", cls)
    with pytest.raises(AssertionError) as failed:
        getattr(fltesting, check)(*arguments)
    assert said in str(failed.value) and "Ending" in str(failed.value)


def test_solver_check_fails_for_a_wrong_normalisation():
    """Springs of stiffness k dx under a force, declared as a force per unit depth over k h:
    the load scales as k h L, not as k h, so f is not dimensionless."""
    wrong = ForceNormalisation(load="force per unit depth", modulus="k", extent="one")
    cls = type("PerUnitDepth", (GoodSolver,), {"name": "wrong-f", "normalisations": {1: wrong}})
    with pytest.raises(AssertionError, match="is not dimensionless as declared"):
        fltesting.check_solver(cls)


@pytest.mark.parametrize("load,extent", [("force per unit depth", "length"), ("force", "one"),
                                         ("force per unit depth", "area")])  # fmt: skip
def test_a_load_that_does_not_match_its_extent_is_refused(load, extent):
    """k h X has the unit of the load only as the contract pairs them (k a stress, or a stress
    per length over an area): any other pairing could never give a dimensionless f."""
    with pytest.raises(ValueError, match=f"not a {load}: f would not be dimensionless"):
        ForceNormalisation(load=load, modulus="k", extent=extent)


def test_the_half_plane_with_the_old_f_fails_the_kit():
    """f = F' / (E* h L) for a force per unit depth (the half-plane's f before) fails the unit check."""
    from frictionlab_solvers import BEMHalfPlane

    with pytest.raises(ValueError, match="not a force per unit depth"):  # refused as declared then
        ForceNormalisation(load="force per unit depth", modulus="E*", extent="length")
    old = ForceNormalisation(load="force", modulus="E*", extent="length")  # its load taken for a force
    cls = type("OldHalfPlane", (BEMHalfPlane,), {"name": "old-halfplane", "normalisations": {1: old}})
    with pytest.raises(AssertionError, match="is not dimensionless as declared"):
        fltesting.check_solver(cls)
    fltesting.check_solver(BEMHalfPlane)


@pytest.mark.parametrize(
    "attributes,match",
    [
        ({"mean_displacement_known": False, "mean_displacement": lambda self, f, h: 0.1 * np.asarray(f)},
         "mean_displacement_known is False, so mean_displacement\\(f, h\\) must stay zero"),
        ({"mean_displacement_known": False, "indentation_reference": "mean surface"},
         "indentation_reference is the mean surface, so its mean displacement is known"),
    ],
)
def test_solver_check_fails_for_an_unknown_mean_displacement_declared_wrongly(attributes, match):
    cls = type("Unplaced", (GoodSolver,), {"name": "unplaced", **attributes})
    with pytest.raises(AssertionError, match=match):
        fltesting.check_solver(cls)


def test_solver_check_fails_when_the_corrected_area_and_its_declaration_differ():
    """A solver that declares corrected_area must give real_area_corrected, one that does not must not."""
    from frictionlab_solvers import BEMHalfSpace

    undeclared = solver_variant("Undeclared", lambda c, p, loads: replace_curve(c, real_area_corrected=c.contact_fraction))
    missing = type("Missing", (GoodSolver,), {"name": "missing", "corrected_area": True})
    for cls in (undeclared, missing):
        with pytest.raises(AssertionError, match="real_area_corrected must be given exactly when corrected_area is True"):
            fltesting.check_solver(cls)
    too_large = type("TooLarge", (solver_variant("Large", lambda c, p, loads: replace_curve(
        c, real_area_corrected=c.contact_fraction * 1.01)),), {"corrected_area": True})  # fmt: skip
    with pytest.raises(AssertionError, match=r"real_area_corrected must lie in \(0, contact_fraction\]"):
        fltesting.check_solver(too_large)
    fltesting.check_solver(BEMHalfSpace)


def test_solver_check_fails_when_periodic_only_is_not_kept():
    cls = type("Loose", (GoodSolver,), {"name": "loose", "periodic_only": True})
    with pytest.raises(AssertionError, match="periodic_only is True, but a non-periodic profile was accepted"):
        fltesting.check_solver(cls)


def test_solver_check_fails_when_undefined_slopes_are_not_left_out():
    """GoodSolver's rms takes NaN slopes in, and NaN out at every load: it may not declare them."""
    cls = type("NaNPropagating", (GoodSolver,), {"name": "nan-propagating", "undefined_slopes": True})
    with pytest.raises(AssertionError, match="undefined_slopes: with slopes 1 and NaN at the top point"):
        fltesting.check_solver(cls)


@pytest.mark.parametrize(
    "attributes,match",
    [
        ({"undefined_slopes": "yes"}, "undefined_slopes must be True or False. Got 'yes'"),
        ({"mean_displacement_known": None}, "mean_displacement_known must be True or False. Got None"),
        ({"normalisations": {}}, "normalisations must map each of its dimensions"),
        ({"dimensions": (1, 2)}, "normalisations must map each of its dimensions"),
        ({"problem": ""}, "problem must name the physical problem"),
        ({"contact_measure": "area"}, "contact_measure must be one of"),
        ({"corrected_area": "yes"}, "corrected_area must be True or False. Got 'yes'"),
        ({"body_params": ("youngs_modulus",)}, "body_params names 'youngs_modulus', not fields of Params"),
        ({"tolerance_param": "tol"}, "tolerance_param names 'tol'"),
        ({"mdr_lines": 1}, "mdr_lines must be True or False. Got 1"),
        ({"mdr_lines": True, "dimensions": (1, 2), "normalisations": {
            1: ForceNormalisation(load="force", modulus="k", extent="length"),
            2: ForceNormalisation(load="force", modulus="k", extent="area")}},
         r"mdr_lines is for a solver of lines alone \(dimensions \(1,\)\)"),
        ({"bytes_per_point": 0}, "bytes_per_point must be None or a whole number > 0. Got 0"),
        ({"bytes_per_point": 12.5}, "bytes_per_point must be None or a whole number > 0. Got 12.5"),
        ({"normalisations": {1: ForceNormalisation(load="force", modulus="k", extent="area")}}, "not defined for a 1D"),
    ],
)
def test_solver_declarations_are_checked_at_registration(attributes, match):
    cls = type("Undeclared", (GoodSolver,), {"name": "undeclared", **attributes})
    with pytest.raises(PluginError, match=match):
        registry_module.validate_plugin_class("solver", cls)


# ====================================================== progress and cancel


def _iterating(qualname, on_step, tolerance_param="modulus"):
    """GoodSolver reporting one step per load through ``on_step(load_index)``, declared iterative."""

    def solve(self, profile, loads, control, slopes):
        for index in range(len(loads)):
            on_step(index)
        return GoodSolver.solve(self, profile, loads, control, slopes)

    return type(qualname, (GoodSolver,), {"name": "iterating", "solve": solve, "tolerance_param": tolerance_param})


def _swallows(index):
    from frictionlab import SolveCancelled, iteration_done

    try:
        iteration_done(index, 0.5)
    except SolveCancelled:
        pass


def _wraps(index):
    from frictionlab import iteration_done

    try:
        iteration_done(index, 0.5)
    except Exception as exc:
        raise RuntimeError("the solve failed") from exc


CANCEL_BREAKAGES = [
    ("Deaf", lambda index: None, r"tolerance_param is 'modulus' \(an iterative solver\), but solve\(\) never called "
                                 r"frictionlab\.iteration_done"),
    ("Swallows", _swallows, "swallowed the frictionlab.SolveCancelled raised by iteration_done"),
    ("Wraps", _wraps, "raised RuntimeError: the solve failed; let the frictionlab.SolveCancelled"),
    ("NegativeStep", lambda index: __import__("frictionlab").iteration_done(-1, 0.5), r"Got \(-1, 0\.5\)"),
    ("NaNResidual", lambda index: __import__("frictionlab").iteration_done(index, float("nan")), r"Got \(0, nan\)"),
]


@pytest.mark.parametrize("qualname,on_step,match", CANCEL_BREAKAGES, ids=[b[0] for b in CANCEL_BREAKAGES])
def test_solver_check_fails_for_a_solver_that_a_cancel_cannot_stop(qualname, on_step, match):
    fails_naming(fltesting.check_solver, _iterating(qualname, on_step), match)


def test_solver_check_passes_a_solver_that_reports_its_steps_and_stops_on_cancel():
    from frictionlab import iteration_done

    fltesting.check_solver(_iterating("Reports", lambda index: iteration_done(index, 0.5)))
    fltesting.check_solver(_iterating("DirectAndQuiet", lambda index: None, tolerance_param=None))


@pytest.mark.parametrize("deepest, match", [
    (lambda self, profile: "deep", r"full_contact_indentation\(profile\) must be None or a finite number >= 0"),
    (lambda self, profile: 1e-3, r"full_contact_indentation\(profile\) = 0.001, but an indentation 1 % past it was solved"),
])  # fmt: skip
def test_solver_check_fails_for_a_wrong_full_contact_indentation(deepest, match):
    """GoodSolver's springs take any indentation: one claimed unreachable must be refused by solve."""
    cls = type("Shallow", (GoodSolver,), {"name": "shallow", "full_contact_indentation": deepest})
    with pytest.raises(AssertionError, match=match):
        fltesting.check_solver(cls)

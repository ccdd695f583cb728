"""Loads in the user's terms, turned into the solver's loads in one place.

A preset's ``loading.unit`` says what its numbers are: ``force`` (the solver's load:
a force in E* x length^2, or a force per unit depth), ``f`` (the dimensionless force
F / (k h X), ``plugin.ForceNormalisation``), ``pressure`` (the nominal pressure over
the modulus, p / k = F / (k A), A the apparent area: ``ForceNormalisation.nominal_area``)
or ``contact-fraction`` (a target real-contact fraction, found per profile by solving).

The scales are those of the profiles pressed: every profile of an ensemble shares its
grid and its h (``ensemble`` checks it), so realization 0's profile gives them.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass, replace

import numpy as np

from ..plugin import ContactSolver, Profile, force_unit, listening_to_loads
from ..plugin.outputs import (
    RandomWatch, full_contact_problem, height_of, profile_problem, read_only, refuse, seed_problem, shape_problem,
    slopes_problem,
)  # fmt: skip

LOAD_UNITS = {
    "force": "the solver's load (a force in E* x length^2, or a force per unit depth)",
    "f": "the dimensionless force f = F / (k h X)",
    "pressure": "the nominal pressure over the modulus, p / E* = F / (E* A), A the apparent area",
    "contact-fraction": "a target real-contact fraction, in (0, 1): the force reaching it is found per profile",
}
SEARCH_STEPS = 80  # solves allowed to find one contact fraction's force
SEARCH_PRECISION = 1e-6  # relative width of the bracket at which a jump in the count is accepted
FIRST_TOUCH = 1e-9  # a force this far below the first guess, still past the target, is the first touch


@dataclass(frozen=True)
class LoadScales:
    """The force at which each unit's value is 1, for the profiles a scene presses; and where
    full contact starts (``full_contact``, exact when ``full_contact_exact``, else an estimate)."""

    force_unit: float  # k h X: F at f = 1
    pressure_unit: float | None  # k A: F at p / k = 1; None where p / k is not dimensionless
    full_contact: float | None
    full_contact_exact: bool
    points: int
    full_indentation: float | None = None  # the indentation no finite load reaches (the solver's), if any

    def to_forces(self, values: np.ndarray, unit: str) -> np.ndarray:
        """``values`` in ``unit`` (force, f or pressure) as the solver's loads."""
        values = np.asarray(values, dtype=float)
        if unit == "force":
            return values.copy()
        if unit == "f":
            return values * self.force_unit
        if unit == "pressure" and self.pressure_unit is not None:
            return values * self.pressure_unit
        raise ValueError(f"a load in {unit!r} has no equivalent force here")

    def in_units(self, forces: np.ndarray) -> dict[str, np.ndarray | None]:
        """``forces`` in every unit: force, f, and pressure (None where undefined)."""
        forces = np.asarray(forces, dtype=float)
        return {
            "force": forces,
            "f": forces / self.force_unit,
            "pressure": None if self.pressure_unit is None else forces / self.pressure_unit,
        }


def probe_profile(scene) -> Profile:
    """Realization 0's profile: the grid and h every profile of the scene shares."""
    profile = _generated(scene)
    return replace(profile, heights=read_only(profile.heights))  # lent as every realization's is


def _generated(scene) -> Profile:
    from .seeds import realization_rng

    watch = RandomWatch()
    profile = scene.generator.generate(realization_rng(scene.preset.seed, 0))
    refuse(scene.generator, watch.problem("generate()") or profile_problem(scene.generator, profile)
           or shape_problem(scene.generator, profile))  # fmt: skip
    # a generator ignoring its rng (every realization one line) is refused here, before the run
    refuse(scene.generator, rng_problem(scene, profile) or watch.problem("generate()"))
    return profile


def rng_problem(scene, profile: Profile) -> str | None:
    """``seed_problem`` of ``scene``'s generator, whose realization 0 is ``profile``: made again
    from fresh generators of realization 0's seed and (where the run has more) realization 1's."""
    from .seeds import realization_rng

    def again(index: int) -> Profile:  # realization index's profile, from a fresh generator of its seed
        return scene.generator.generate(realization_rng(scene.preset.seed, index))

    return seed_problem(scene.generator, profile, again, scene.preset.realizations > 1)


def load_scales(scene, profile: Profile | None = None) -> LoadScales:
    """The scales of ``scene``'s loads, from ``profile`` (realization 0's when None)."""
    profile = probe_profile(scene) if profile is None else profile
    solver, generator = scene.solver, scene.generator
    h, _ = height_of(generator, profile)
    unit = force_unit(solver, h, profile)
    area = scene.normalisation.nominal_area(profile)
    pressure_unit = None if area is None else float(solver.stiffness()) * area
    full, exact = solver.full_contact_load(profile), True
    refuse(solver, full_contact_problem(full))
    full_indentation = solver.full_contact_indentation(profile)
    refuse(solver, full_contact_problem(full_indentation, "full_contact_indentation"))
    # the estimator's answer too, as every realization takes it: a broken one is refused before the run
    watch = RandomWatch()
    slopes = scene.slope.slopes(profile.heights, profile.spacing, profile.periodic)
    refuse(scene.slope, watch.problem("slopes()") or slopes_problem(scene.slope, slopes, profile))
    if full is None and pressure_unit is not None:
        full, exact = estimated_full_contact(slopes, pressure_unit), False
    return LoadScales(unit, pressure_unit, full, exact, profile.points, full_indentation)


def estimated_full_contact(slopes: np.ndarray, pressure_unit: float) -> float | None:
    """An estimate of the force of full contact: the nominal pressure p = E* g, g the profile's
    rms slope (``slopes``, of the scene's slope estimator), which presses a surface flat to within a
    few per cent of its area (Persson's theory gives erf(sqrt 2) = 95 % in contact there)."""
    with np.errstate(invalid="ignore", over="ignore"):
        squares = np.square(slopes[np.isfinite(slopes)])
        g = math.sqrt(float(np.mean(squares))) if squares.size else math.nan
    return g * pressure_unit if math.isfinite(g) and g > 0 else None


def solver_loads(scene) -> np.ndarray | None:
    """The loads the solver is given for ``scene``: the preset's under ``force`` (or indentation)
    control, converted from f or a pressure; None for contact fractions (found per profile)."""
    loading = scene.preset.loading
    values = loading.values()
    if loading.unit == "force":
        return values
    if loading.unit == "contact-fraction":
        return None
    return scene.load_scales.to_forces(values, loading.unit)


def check_loads(scene) -> None:
    """Refuse, before a run, loads ``scene``'s solver cannot take (``load_problems``): a PresetError;
    and a plugin's broken answer on realization 0's profile (``Scene.load_scales`` makes it and
    checks every answer a run reads: its shape, seeds, slopes, h, full contact): a PluginError."""
    scene.load_scales  # noqa: B018 - made once (cached): the run and validate check the same answers
    from ..errors import PresetError

    problems = load_problems(scene)
    if problems:
        raise PresetError(problems, source=scene.source)


def load_problems(scene) -> list[str]:
    """What keeps ``scene``'s loads from running: a unit the solver cannot take, a load past the
    solver's ``max_f``. Each names the field, the value and what is allowed."""
    loading, solver, problems = scene.preset.loading, scene.solver, []
    if loading.unit == "pressure" and scene.normalisation.pressure_area == "":
        problems.append(
            f"loading.unit: 'pressure' needs a solver whose modulus is a stress over a known area; {solver.name}'s "
            f"f is {scene.normalisation.formula}: give the loads as 'force' or 'f'"
        )
    if loading.unit == "contact-fraction" and solver.contact_measure != "real contact":
        problems.append(
            f"loading.unit: 'contact-fraction' is a real-contact fraction, but {solver.name} counts "
            f"{solver.contact_measure}, not the real contact: give the loads as 'force', 'f' or 'pressure'"
        )
    if loading.control == "indentation" and not problems:
        problems += _indentation_problems(scene)
    if problems or loading.unit == "contact-fraction" or solver.max_f is None or loading.control != "force":
        return problems
    scales = scene.load_scales
    f = scales.in_units(scene.solver_loads)["f"]
    if float(f.max()) > solver.max_f:
        problems.append(
            f"loading.stop: {loading.stop:g} is f = {float(f.max()):.4g}, past what {solver.name}'s arithmetic holds: "
            f"f <= {solver.max_f:g} ({scene.normalisation.load_symbol} <= {solver.max_f * scales.force_unit:.6g} "
            f"{scene.normalisation.load_unit}); full contact comes long before"
        )
    return problems


def forces_for_fractions(
    solver: ContactSolver, profile: Profile, fractions: np.ndarray, slopes: np.ndarray, *,
    first_guess: float, on_load: Callable[[int], None] | None = None,
) -> np.ndarray:  # fmt: skip
    """Per target real-contact fraction, the smallest force at which at least ``ceil(fraction N)``
    points of ``profile`` touch: found by solving (a secant in log-log, kept inside a bisection
    bracket), to the force at which the count is exactly reached, or to a relative 1e-6 where
    several points enter at once. ``first_guess``: a force to start from (f = the fraction).
    ``on_load(j)`` hears which load is sought; a cancelled run stops inside the solver."""
    points = profile.points
    forces = np.empty(np.size(fractions))
    low = (0.0, 0)  # (force, count) known short of the target
    reached = (0.0, 0)  # (force, count) of the last load found
    for j, fraction in enumerate(np.asarray(fractions, dtype=float)):
        if on_load is not None:
            on_load(j)
        target = min(points, max(1, math.ceil(fraction * points - 1e-9)))
        if j and reached[1] >= target:  # the last load's contact covers this one (a plateau, a jump): its force
            forces[j] = reached[0]
            continue
        reached, low = _search(solver, profile, slopes, target, low, max(first_guess * fraction, low[0] * 2))
        forces[j] = reached[0]
    return forces


def _search(solver, profile, slopes, target: int, low: tuple[float, int], guess: float):
    """((force, count) found, the bracket's low end for the next target) of one target count."""
    high = None
    force = guess
    with listening_to_loads(None):  # the search's solves are not the run's loads
        for _ in range(SEARCH_STEPS):
            curve = solver.solve(profile, np.array([force]), "force", slopes)
            count = int(np.asarray(curve.contact_count)[0])
            if count >= target:
                high = (force, count)
            else:
                low = (force, count)
            if high is not None and (high[1] == target or (low[0] > 0 and high[0] <= low[0] * (1 + SEARCH_PRECISION))):
                return high, low
            if high is not None and low[0] == 0.0 and high[0] <= guess * FIRST_TOUCH:
                return high, low  # more than the target touch at first contact: points of equal height (a plateau)
            force = _next_force(low, high, target)
    raise ValueError(
        f"no force found at which {target} of {profile.points} points touch within {SEARCH_STEPS} solves "
        f"(last tried: {force:g})"
    )


def _next_force(low: tuple[float, int], high: tuple[float, int] | None, target: int) -> float:
    """The next force: the count taken as proportional to the force from the nearest end (the
    real contact grows about linearly with the load), kept strictly inside the bracket."""
    if high is None:  # not bracketed yet: grow, by at most 100 times
        return low[0] * min(100.0, max(2.0, target / max(low[1], 1)))
    if low[0] == 0.0:  # nothing below yet: shrink, by at most 100 times
        return high[0] * max(0.01, min(0.5, target / high[1]))
    guess = low[0] * target / max(low[1], 1)
    lo, hi = math.log(low[0]), math.log(high[0])
    inside = lo + 0.05 * (hi - lo) < math.log(guess) < hi - 0.05 * (hi - lo) if guess > 0 else False
    return guess if inside else math.exp(0.5 * (lo + hi))


def _indentation_problems(scene) -> list[str]:
    """An indentation at or past the one no finite load reaches (realization 0's surface)."""
    full = scene.load_scales.full_indentation
    deepest = float(np.max(scene.preset.loading.values()))
    if full is None or deepest < full:
        return []
    return [f"loading.stop: indentation {deepest:g} is at or past {full:.6g}, the full-contact approach max z - "
            f"mean z of realization 0's surface (in its length unit): on a periodic elastic body no finite force "
            f"reaches it, and {scene.solver.name} would fail there. Use loading.control 'force', or indentations "
            f"below {full:.4g}"]  # fmt: skip


def describe_loads(scene) -> dict:
    """What ``frictionlab validate`` shows of the loads, JSON-ready: the force unit k h X (f = 1)
    with its unit, the load range in every unit (force, f, p / E*; None where one does not
    apply), and where full contact starts (exact, or an estimate said as such, or None)."""
    loading, normalisation = scene.preset.loading, scene.normalisation
    scales = scene.load_scales
    record = {
        "unit": loading.unit,
        "force_unit": scales.force_unit,
        "force_unit_formula": f"{normalisation.modulus} h{normalisation.formula.split('h', 1)[1].rstrip(')')}",
        "force_unit_unit": normalisation.load_unit,
        "pressure_unit": scales.pressure_unit,
        "range": None,
        "full_contact": None,
    }
    if loading.control == "force" and loading.unit != "contact-fraction":
        ends = scales.in_units(scene.solver_loads[[0, -1]])
        record["range"] = {unit: None if v is None else [float(v[0]), float(v[1])] for unit, v in ends.items()}
    if scales.full_contact is not None:
        full = scales.in_units(np.array([scales.full_contact]))
        record["full_contact"] = {
            "how": "exact (the solver's own, from the heights)" if scales.full_contact_exact else "estimate: the nominal pressure "
            "p = E* g that flattens the surface, g its rms slope (about 95 % in contact there)",
            **{unit: None if v is None else float(v[0]) for unit, v in full.items()},
        }
    return record


def loads_lines(record: dict, symbol: str) -> list[str]:
    """``describe_loads`` in words, a line each: force unit, the range in every unit, full contact."""
    lines = [f"force unit {record['force_unit_formula']} = {record['force_unit']:.6g} ({record['force_unit_unit']}): "
             f"the load at f = 1"]  # fmt: skip
    span = record["range"]
    if span is not None:
        parts = [f"{symbol} = {span['force'][0]:.4g} .. {span['force'][1]:.4g} ({record['force_unit_unit']})", f"f = {span['f'][0]:.4g} .. {span['f'][1]:.4g}"]
        if span["pressure"] is not None:
            parts.append(f"p/E* = {span['pressure'][0]:.4g} .. {span['pressure'][1]:.4g}")
        lines.append("loads: " + ", ".join(parts))
    elif record["unit"] == "contact-fraction":
        lines.append("loads: real-contact fractions; each surface's forces are found by solving")
    full = record["full_contact"]
    if full is None:
        lines.append("full contact: not known short of a solve (this solver gives no full-contact load, and p / E* "
                     "is not defined for it)")  # fmt: skip
    else:
        pressure = f", p/E* = {full['pressure']:.4g}" if full["pressure"] is not None else ""
        lines.append(f"full contact from {symbol} = {full['force']:.4g} ({record['force_unit_unit']}), "
                     f"f = {full['f']:.4g}{pressure}: {full['how']}")  # fmt: skip
        if span is not None and span["force"][1] > full["force"]:
            every = span["force"][0] >= full["force"]  # no load measures roughness: the run finds no law
            lines.append(f"caveat: {'every load is' if every else 'the last loads are'} past full contact"
                         f"{'' if full['how'].startswith('exact') else ' (estimated)'}: xi is 1 there by definition and "
                         f"they measure no roughness; lower {'the loads' if every else 'loading.stop'}")  # fmt: skip
    return lines

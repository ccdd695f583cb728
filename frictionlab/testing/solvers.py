"""The check of a contact solver."""

from __future__ import annotations

from .common import call, check_positive_number, fail, instantiate, must_refuse, reported


def _test_line(points: int = 64, seed: int = 20240613):
    """A smooth random periodic line with rms 1 and its forward-difference slopes."""
    import numpy as np

    rng = np.random.default_rng(seed)
    k = np.arange(points // 2 + 1)
    amplitude = np.zeros(k.size)
    amplitude[1:-1] = k[1:-1] ** -1.5
    spectrum = amplitude * np.exp(2j * np.pi * rng.random(k.size))
    heights = np.fft.irfft(spectrum, n=points)
    heights = (heights - heights.mean()) / heights.std()
    spacing = 1.0
    slopes = (np.roll(heights, -1) - heights) / spacing
    return heights, spacing, slopes


def _test_surface(points: int = 16, seed: int = 20240613):
    """A smooth random periodic surface with rms 1 and its forward-difference gradient magnitude."""
    import numpy as np

    rng = np.random.default_rng(seed)
    k = np.hypot(*np.meshgrid(np.fft.fftfreq(points, 1 / points), np.arange(points // 2 + 1), indexing="ij"))
    amplitude = np.where(k > 0, k, np.inf) ** -2.0
    heights = np.fft.irfft2(amplitude * np.exp(2j * np.pi * rng.random(k.shape)), s=(points, points))
    heights = (heights - heights.mean()) / heights.std()
    spacing = 1.0
    slopes = np.hypot(np.roll(heights, -1, axis=0) - heights, np.roll(heights, -1, axis=1) - heights) / spacing
    return heights, spacing, slopes


@reported
def check_solver(cls, **params) -> None:
    """``cls(**params).solve(profile, loads, control, slopes)``, for each of the
    solver's ``dimensions``, on a small smooth random periodic line (64 points)
    with forward-difference slopes, or a 16 x 16 surface with forward-difference
    gradient magnitudes, under force
    control (forces F = f k h L, L = ``Profile.length``, f from 0.005 to 1, k = ``stiffness()``) and
    under indentation control (2.5 % to 95 % of max z - mean z, the approach at
    which a periodic elastic half-space reaches full contact): it returns a ``ContactCurve``
    whose arrays all have the shape of ``loads`` and are finite, float64 but for the counts; the controlled
    quantity is reported back (``force`` resp. ``indentation`` equal to the
    loads within 1 %); force and indentation do not decrease with load (an iterative solver's
    stop may leave a drop of 1e-3 of the largest, as a run allows); contact
    counts are whole numbers, do not decrease with load, and lie in 1 .. N;
    ``contact_fraction == contact_count / N`` (the fraction of points, of the
    real contact or of MDR springs as ``contact_measure`` says); ``real_area_corrected`` is
    given exactly when ``corrected_area`` is True, and then lies in (0, contact_fraction];
    ``real_gradient_rms`` is given exactly when ``real_gradient`` is True, and is then finite and >= 0;
    ``contact_spots`` is given exactly when ``counts_spots`` is True, whole numbers in 1 .. contact_count;
    ``half_load_points``, where given, holds whole numbers in 1 .. contact_count;
    ``slope_rms_contact`` is >= 0 and
    no larger than the largest |slope| (to a relative 1e-6: a sum's rounding); every ``extras`` array has one entry per
    load; the inputs are not modified; the same input gives the same output.
    ``stiffness()`` is finite and > 0. The declarations: the forces come from
    ``frictionlab.force_unit``, the solver's ``normalisation`` of the profile;
    f is dimensionless as declared: every length x 1000 with each load scaled as
    its declared unit k h X scales (k fixed: a force x 1000^2 against a stress, a
    force per unit depth x 1000, an indentation x 1000), and the spacing alone x 10
    at equal f, leave the contact counts and the rms slope in contact unchanged; ``mean_displacement(f, h)`` has the shape
    of f, and is zero where the ``indentation_reference`` is the mean surface, and where
    ``mean_displacement_known`` is False (which the mean surface never is); ``tolerance()``
    is None exactly when ``tolerance_param`` is; ``bytes_per_point``
    (memory estimates) is None or a whole number > 0 (registration checks it; that it
    bounds the solver's peak is for the plugin's own tests, measured on a large grid); a
    ``periodic_only`` solver raises ValueError on a non-periodic profile, any
    other solves it. ``max_f`` is None or a number > 0, and a force of 10 ``max_f`` k h X
    raises ValueError naming the limit (before any overflow); ``full_contact_load(profile)``
    is None or a finite number >= 0, and the load 1 % above it puts every point in
    contact; ``full_contact_indentation(profile)`` is None or a finite number >= 0, and an
    indentation 1 % past it raises ValueError. A solver declaring ``undefined_slopes`` is given NaN slopes
    too: with every slope NaN, ``slope_rms_contact`` is NaN at every load; with
    slopes 1 but a NaN at the top point, it is 1 wherever it is finite, and finite
    at every load with 2 or more points in contact (the rms over the defined ones).
    A solver declaring no ``undefined_slopes`` is never given NaN. An iterative solver
    (``tolerance_param``) calls ``frictionlab.iteration_done(iteration, residual)`` in its loop
    (a whole number >= 0, a finite residual >= 0), and any solver that calls it lets the
    ``SolveCancelled`` it raises in a cancelled run propagate, neither swallowed nor wrapped:
    so a run shows a long load's progress and stops on Ctrl-C. (Registration itself checks that every declaration is
    well formed: ``classcheck.declaration_problems``.)
    """
    solver = instantiate(cls, params)
    from frictionlab.plugin.outputs import answers_problem

    if problem := call(cls, "stiffness() or tolerance()", answers_problem, solver):  # as a run takes them
        fail(cls, problem)
    for dimension in cls.dimensions:
        heights, spacing, slopes = _test_line() if dimension == 1 else _test_surface()
        _check_solves(cls, solver, heights, spacing, slopes)


def _check_solves(cls, solver, heights, spacing, slopes) -> None:
    """Everything ``check_solver`` says, on one profile."""
    import numpy as np

    from frictionlab.plugin import Profile, force_unit
    from frictionlab.plugin.outputs import LEAVE_INPUTS, curve_problem, order_problem, reported_problem

    n = heights.size
    shape = "line" if heights.ndim == 1 else "surface"
    h = float(heights.std())
    unit = call(cls, "force_unit() (from normalisations)", force_unit, solver, h, Profile(heights, spacing))
    cases = {
        "force": np.array([0.005, 0.02, 0.1, 0.4, 1.0]) * unit,
        # below max z - mean z: past it an elastic half-space would need an infinite force
        "indentation": np.array([0.025, 0.1, 0.25, 0.5, 0.95]) * float(heights.max() - heights.mean()),
    }
    names = ("force", "indentation", "contact_count", "contact_fraction", "slope_rms_contact")

    for control, loads in cases.items():
        where = f"on a {shape}, solve(..., control={control!r})"  # its fields read as solve(...).force

        def run():
            profile = Profile(heights=heights.copy(), spacing=spacing)
            args = (profile, loads.copy(), control, slopes.copy())
            curve = call(cls, where, solver.solve, *args)
            if not (
                np.array_equal(args[0].heights, heights)
                and np.array_equal(args[1], loads)
                and np.array_equal(args[3], slopes)
            ):
                fail(cls, f"{where} modified its inputs: {LEAVE_INPUTS}")
            return curve

        curve = run()
        problem = curve_problem(solver, curve, loads.size, where)  # as a run takes it
        if problem:
            fail(cls, problem)
        arrays = {name: getattr(curve, name) for name in names}
        if not np.all(np.isfinite(arrays["slope_rms_contact"])):  # every slope defined here: every rms too
            fail(cls, f"{where}.slope_rms_contact must be finite. Got {arrays['slope_rms_contact']!r}.")
        corrected = curve.real_area_corrected
        if corrected is not None and (np.any(corrected <= 0) or np.any(corrected > arrays["contact_fraction"] * (1 + 1e-12))):
            fail(cls, f"{where}.real_area_corrected must lie in (0, contact_fraction]: the correction "
                      f"removes part of the pixels counted. Got {corrected!r}.")  # fmt: skip
        _whole_counts(cls, where, curve, "contact_spots", curve.contact_spots)
        _whole_counts(cls, where, curve, "half_load_points", curve.half_load_points)
        for name, value in curve.extras.items():
            if np.shape(value)[:1] != loads.shape:
                fail(cls, f"{where}.extras[{name!r}] must have one entry per load. Got shape {np.shape(value)}.")

        count = arrays["contact_count"]  # every load here has a point in contact: stricter than a run's range
        if np.any(count < 1) or np.any(count > n):
            fail(cls, f"{where}.contact_count must lie in 1 .. {n} (points of the {shape}). Got {count!r}.")
        if not np.allclose(arrays["contact_fraction"], count / n, rtol=1e-12, atol=1e-12):
            fail(
                cls,
                f"{where}.contact_fraction must equal contact_count / N = {count / n!r}. "
                f"Got {arrays['contact_fraction']!r} instead.",
            )
        # then the numbers as a run checks them: the loads reported as asked, the ranges, the order
        if problem := reported_problem(curve, loads, control, n, float(np.abs(slopes).max())) or order_problem(solver, curve, control):
            fail(cls, f"on a {shape}, {problem}")

        again = run()
        for name in names:
            if not np.array_equal(np.asarray(getattr(again, name)), arrays[name]):
                fail(cls, f"{where} is not repeatable: {name} differs between two identical calls")
    _check_solver_declarations(cls, solver, heights, spacing, slopes, cases["force"])
    _check_cancel(cls, solver, heights, spacing, slopes, cases["force"])
    _check_load_limits(cls, solver, heights, spacing, slopes, unit)
    _check_solver_units(cls, solver, heights, spacing, slopes)



def _whole_counts(cls, where: str, curve, name: str, values) -> None:
    """``values`` (None: nothing to check) must be whole numbers in 1 .. contact_count."""
    import numpy as np

    if values is not None and (not np.array_equal(values, np.round(values)) or np.any(values < 1)
                               or np.any(values > count_of(curve))):  # fmt: skip
        fail(cls, f"{where}.{name} must be whole numbers in 1 .. contact_count. Got {values!r}.")

def count_of(curve):
    import numpy as np

    return np.asarray(curve.contact_count)


def _check_cancel(cls, solver, heights, spacing, slopes, forces) -> None:
    """An iterative solver (``tolerance_param``) calls ``iteration_done(iteration, residual)`` in
    its loop, a whole number >= 0 and a finite residual >= 0; any solver that calls it lets the
    ``SolveCancelled`` it raises on a cancelled run propagate: that is how Ctrl-C stops a long solve."""
    import math

    import numpy as np

    from frictionlab.plugin import Profile, SolveCancelled, listening_to_iterations

    heard = []

    def cancel(iteration, residual):
        heard.append((iteration, residual))
        raise SolveCancelled("the conformance kit cancels the solve")

    where = "solve(..., control='force') in a cancelled run"
    try:
        with listening_to_iterations(cancel):
            solver.solve(Profile(heights.copy(), spacing), forces.copy(), "force", slopes.copy())
    except SolveCancelled:
        pass
    except Exception as exc:
        fail(cls, f"{where} raised {type(exc).__name__}: {exc}; let the frictionlab.SolveCancelled raised by "
                  "iteration_done() propagate as it is, so the run stops", exc)  # fmt: skip
    else:
        if heard:
            fail(cls, f"{where} returned: it swallowed the frictionlab.SolveCancelled raised by iteration_done(); "
                      "let it propagate, so the run stops")  # fmt: skip
        if cls.tolerance_param is not None:
            fail(cls, f"tolerance_param is {cls.tolerance_param!r} (an iterative solver), but solve() never called "
                      "frictionlab.iteration_done(iteration, residual): a run could not show its progress within a "
                      "load nor stop it on Ctrl-C")  # fmt: skip
    if heard:
        iteration, residual = heard[0]
        whole = isinstance(iteration, (int, np.integer)) and not isinstance(iteration, bool) and iteration >= 0
        real = isinstance(residual, (int, float, np.floating)) and math.isfinite(residual) and residual >= 0
        if not (whole and real):
            fail(cls, "iteration_done(iteration, residual) takes the steps done, a whole number >= 0, and the relative "
                      f"residual, a finite number >= 0. Got ({iteration!r}, {residual!r}).")  # fmt: skip


def _check_load_limits(cls, solver, heights, spacing, slopes, unit: float) -> None:
    """``max_f`` refused past it; ``full_contact_load`` puts every point in contact; an indentation
    past ``full_contact_indentation`` is refused."""
    import numpy as np

    from frictionlab.plugin import Profile
    from frictionlab.plugin.outputs import full_contact_problem

    limit = cls.max_f
    if limit is not None:
        if isinstance(limit, bool) or not isinstance(limit, (int, float)) or not limit > 0:
            fail(cls, f"max_f must be None or a number > 0. Got {limit!r}.")
        try:
            solver.solve(Profile(heights.copy(), spacing), np.array([10 * limit * unit]), "force", slopes.copy())
        except ValueError as exc:
            if f"{limit:g}" not in str(exc):
                fail(cls, f"the refusal of a force at f = 10 max_f must name the limit {limit:g}. Got: {exc}")
        except Exception as exc:
            fail(cls, f"a force at f = 10 max_f must raise ValueError. Got {type(exc).__name__}: {exc}", exc)
        else:
            fail(cls, f"max_f is {limit:g}, but a force at f = 10 max_f was accepted; it must raise ValueError")
    deepest = call(cls, "full_contact_indentation(profile)", solver.full_contact_indentation,
                   Profile(heights.copy(), spacing))  # fmt: skip
    if problem := full_contact_problem(deepest, "full_contact_indentation"):
        fail(cls, problem)
    if deepest:
        try:
            solver.solve(Profile(heights.copy(), spacing), np.array([1.01 * deepest]), "indentation", slopes.copy())
        except ValueError:
            pass
        except Exception as exc:
            fail(cls, f"an indentation past full_contact_indentation(profile) must raise ValueError. Got "
                      f"{type(exc).__name__}: {exc}", exc)  # fmt: skip
        else:
            fail(cls, f"full_contact_indentation(profile) = {deepest:g}, but an indentation 1 % past it was solved; "
                      "no load reaches it, so it must raise ValueError")  # fmt: skip
    full = call(cls, "full_contact_load(profile)", solver.full_contact_load, Profile(heights.copy(), spacing))
    if full is None:
        return
    if problem := full_contact_problem(full):
        fail(cls, problem)
    curve = _solve(cls, solver, heights, spacing, slopes, np.array([1.01 * full or unit]))
    if int(count_of(curve)[0]) != heights.size:
        fail(cls, f"full_contact_load(profile) = {full:g}, but 1.01 times it puts {int(count_of(curve)[0])} of "
                  f"{heights.size} points in contact, not all")  # fmt: skip


def _solve(cls, solver, heights, spacing, slopes, loads, control="force", periodic=True):
    from frictionlab.plugin import Profile

    where = f"solve(..., control={control!r}) on a profile of spacing {spacing:g}" + ("" if periodic else ", not periodic")
    return call(cls, where, solver.solve, Profile(heights.copy(), spacing, periodic), loads.copy(), control, slopes.copy())


def _check_solver_declarations(cls, solver, heights, spacing, slopes, forces) -> None:
    """mean_displacement(), tolerance(), and periodic_only against a non-periodic profile."""
    import numpy as np

    f = np.array([0.01, 0.1])
    shift = np.asarray(call(cls, "mean_displacement(f, h)", solver.mean_displacement, f, 1.0))
    if shift.shape != f.shape or not np.all(np.isfinite(shift)):
        fail(cls, f"mean_displacement(f, h) must return a finite array of the shape of f. Got {shift!r}.")
    if cls.indentation_reference == "mean surface" and np.any(shift != 0):
        fail(cls, "indentation_reference is the mean surface, so mean_displacement(f, h) must be zero "
                  f"(the indentation is already measured from it). Got {shift!r}.")  # fmt: skip
    if cls.indentation_reference == "mean surface" and not cls.mean_displacement_known:
        fail(cls, "indentation_reference is the mean surface, so its mean displacement is known (zero): "
                  "mean_displacement_known must be True")  # fmt: skip
    if not cls.mean_displacement_known and np.any(shift != 0):
        fail(cls, "mean_displacement_known is False, so mean_displacement(f, h) must stay zero, not a guess. "
                  f"Got {shift!r}.")  # fmt: skip
    tolerance = call(cls, "tolerance()", solver.tolerance)
    if (tolerance is None) != (cls.tolerance_param is None):
        fail(cls, f"tolerance() must be None exactly when tolerance_param is None. Got {tolerance!r}.")
    if tolerance is not None:
        check_positive_number(cls, "tolerance()", tolerance)
    if cls.periodic_only:
        from frictionlab.plugin import Profile

        profile = Profile(heights.copy(), spacing, periodic=False)
        must_refuse(cls, "a non-periodic profile", lambda: solver.solve(profile, forces.copy(), "force", slopes.copy()))
    else:
        _solve(cls, solver, heights, spacing, slopes, forces, periodic=False)
    if cls.undefined_slopes:
        _check_undefined_slopes(cls, solver, heights, spacing, forces)


def _check_undefined_slopes(cls, solver, heights, spacing, forces) -> None:
    """NaN slopes count in no rms: none defined gives NaN, the rest defined gives their rms."""
    import numpy as np

    curve = _solve(cls, solver, heights, spacing, np.full(heights.shape, np.nan), forces)
    if not np.all(np.isnan(np.asarray(curve.slope_rms_contact, float))):
        fail(cls, f"undefined_slopes: with every slope NaN, slope_rms_contact must be NaN at every load. "
                  f"Got {curve.slope_rms_contact!r}.")  # fmt: skip
    ones = np.ones(heights.shape)
    ones[np.unravel_index(int(np.argmax(heights)), heights.shape)] = np.nan  # the first point to touch
    curve = _solve(cls, solver, heights, spacing, ones, forces)
    rms, count = np.asarray(curve.slope_rms_contact, float), np.asarray(curve.contact_count)
    finite = np.isfinite(rms)
    if not np.allclose(rms[finite], 1.0, rtol=1e-12) or not np.all(finite[count >= 2]):
        fail(cls, "undefined_slopes: with slopes 1 and NaN at the top point, slope_rms_contact must be 1 at every "
                  f"load with 2 or more points in contact (the rms of the defined slopes). Got {rms!r} "
                  f"with contact counts {count!r}.")  # fmt: skip


def _check_solver_units(cls, solver, heights, spacing, slopes) -> None:
    """f is dimensionless as declared: every length x 1000 with each load scaled as its
    declared unit k h X scales (the moduli are the solver's own, only lengths change: a
    force x 1000^2 against a stress E*, x 1000^3 against a foundation modulus per area; a
    force per unit depth x 1000; an indentation x 1000), and the spacing alone x 10 at equal
    f, leave the contact counts and the rms slope in contact as they were."""
    import numpy as np

    from frictionlab.plugin import Profile, force_unit

    h = float(heights.std())
    f = np.array([0.01, 0.05, 0.2])
    base = _solve(cls, solver, heights, spacing, slopes, f * force_unit(solver, h, Profile(heights, spacing)))
    s = 1000.0
    normalisation = solver.normalisation(heights.ndim)
    scaled = _solve(cls, solver, heights * s, spacing * s, slopes, f * force_unit(solver, h * s, Profile(heights * s, spacing * s)))
    refined = _solve(cls, solver, heights, spacing * 10, slopes / 10,
                     f * force_unit(solver, h, Profile(heights, spacing * 10)))  # fmt: skip

    def compare(what, other, slope_factor=1.0):
        counts, expected = np.asarray(other.contact_count), np.asarray(base.contact_count)
        slope = np.asarray(other.slope_rms_contact) * slope_factor
        if not np.array_equal(counts, expected) or not np.allclose(slope, base.slope_rms_contact, rtol=1e-6, atol=0):
            fail(
                cls,
                f"f = {normalisation.formula} is not dimensionless as declared ({normalisation.definition}): with "
                f"{what} the contact counts went from {expected.tolist()} to {counts.tolist()}, the rms slope in "
                f"contact from {np.asarray(base.slope_rms_contact).tolist()} to {slope.tolist()}",
            )

    compare(f"every length x {s:g}, each load by its unit ({normalisation.load})", scaled)
    compare("only the spacing x 10 at equal f", refined, 10.0)
    depth = _solve(cls, solver, heights * s, spacing * s, slopes, np.asarray(base.indentation) * s, "indentation")
    compare(f"every length x {s:g} under indentation control", depth)

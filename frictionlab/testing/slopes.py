"""The check of a slope estimator."""

from __future__ import annotations

from .common import call, check_array, fail, instantiate, must_refuse, reported


@reported
def check_slope_estimator(cls, **params) -> None:
    """``cls(**params).slopes(heights, spacing, periodic)`` on a random periodic line returns
    a finite float64 array of the same shape, does not modify its input
    and is repeatable; a constant line gives zero slopes; on a periodic sine
    (3 periods over 128 points, spacing 0.1) the slopes match the exact
    derivative in order of magnitude and sign (rms within a factor of 2,
    relative rms error below 0.5). An estimator whose ``dimensions`` include 2
    gets the same checks on a 24 x 40 surface, with a plane wave across both
    axes whose exact slope is |grad z| (so its slopes must be >= 0); lines are
    checked only if ``dimensions`` include 1. ``slopes(..., periodic=False)``
    on a tilted plane gives the tilt at every point (no difference across the
    ends), or, for a ``periodic_only`` estimator, raises ValueError; there
    ``undefined_points(False)`` says whether some points may have no slope (NaN):
    if True, NaN appears only in bands at the profile's ends (a wide stencil leaves
    several points without a slope; at most a quarter of each axis at either end)
    and every other slope is the tilt; if False, none is NaN. On a periodic
    profile every slope is finite, and ``undefined_points(True)`` is False.
    """
    import numpy as np

    from frictionlab.plugin import Profile
    from frictionlab.plugin.outputs import LEAVE_INPUTS, slopes_problem

    estimator = instantiate(cls, params)
    spacing = 0.1
    dimensions = cls.dimensions

    if call(cls, "undefined_points(True)", estimator.undefined_points, True) is not False:
        fail(cls, "undefined_points(True) must be False: a periodic profile has no end, every point a slope")
    undefined_ends = call(cls, "undefined_points(False)", estimator.undefined_points, False)
    if not isinstance(undefined_ends, bool):
        fail(cls, f"undefined_points(False) must be True or False. Got {undefined_ends!r} instead.")

    def run(what, heights, periodic=True):
        original = heights.copy()
        where = f"slopes({what}, spacing={spacing}, periodic={periodic})"
        slopes = call(cls, where, estimator.slopes, heights, spacing, periodic)
        if not np.array_equal(heights, original):
            fail(cls, f"slopes({what}) modified its input: {LEAVE_INPUTS}")
        if not periodic and undefined_ends and isinstance(slopes, np.ndarray) and slopes.shape == heights.shape:
            core = _defined_core(slopes)
            if core is None:
                fail(cls, f"slopes({what}): NaN (no slope) is allowed only in bands at the profile's ends, at most "
                          "a quarter of each axis at either end, around a block where every point has a slope")  # fmt: skip
            check_array(cls, f"slopes({what}) inside the edge", slopes[core])
            return slopes
        problem = slopes_problem(estimator, slopes, Profile(heights, spacing, periodic), f"slopes({what})")
        if problem:
            fail(cls, problem)
        return slopes

    rng = np.random.default_rng(7)
    for shape in [s for d, s in ((1, (128,)), (2, (24, 40))) if d in dimensions]:
        kind = "line" if len(shape) == 1 else "surface"
        noisy = rng.standard_normal(shape)
        first = run(f"random {kind}", noisy)
        if not np.array_equal(run(f"random {kind}", noisy), first):
            fail(cls, "slopes() is not repeatable: two identical calls differ")

        flat = run(f"constant {kind}", np.full(shape, 3.7))
        if np.max(np.abs(flat)) > 1e-9:
            fail(cls, f"a constant {kind} must have zero slopes. Got max |slope| = {np.max(np.abs(flat)):.3g}.")

        # a sine along x (a line), a plane wave across both axes (a surface: |grad z|)
        grids = np.meshgrid(*(np.arange(n) * spacing for n in shape), indexing="ij")
        q = [2 * np.pi * k / (n * spacing) for k, n in zip((3, 2)[: len(shape)], shape)]
        amplitude = 0.8
        phase = sum(qi * xi for qi, xi in zip(q, grids))
        sine = amplitude * np.sin(phase)
        exact = amplitude * np.cos(phase) * (q[0] if kind == "line" else np.hypot(*q))
        estimate = run("sine" if kind == "line" else "plane wave", sine)
        if kind == "surface":  # slopes_problem refused a negative one
            exact = np.abs(exact)
        rms_exact = float(np.sqrt(np.mean(exact**2)))
        rms_estimate = float(np.sqrt(np.mean(estimate**2)))
        error = float(np.sqrt(np.mean((estimate - exact) ** 2))) / rms_exact
        if not (0.5 <= rms_estimate / rms_exact <= 2.0) or error > 0.5:
            fail(
                cls,
                f"on A sin(q . x) (A = {amplitude}, q = {np.round(q, 4).tolist()}, spacing = {spacing}, shape {shape}) "
                f"the slopes have rms {rms_estimate:.4g} and relative rms error {error:.3g} against the exact "
                f"derivative (rms {rms_exact:.4g}); expected the same order of magnitude and sign (divide by spacing?)",
            )

        # a scan whose ends do not meet: a plane, tilted along every axis; no slope may cross the ends
        grade = np.array([0.3, -0.2])[: len(shape)]
        ramp = sum(g * x for g, x in zip(grade, grids))
        if cls.periodic_only:
            must_refuse(cls, "a non-periodic profile", lambda ramp=ramp: estimator.slopes(ramp, spacing, False))
            continue
        tilted = run(f"non-periodic tilted {kind}", ramp, periodic=False)
        exact = grade[0] if kind == "line" else float(np.hypot(*grade))
        tilted = np.where(np.isnan(tilted), exact, tilted)  # points without a slope (undefined_points)
        if not np.allclose(tilted, exact, rtol=1e-9, atol=1e-12):
            worst = np.unravel_index(int(np.argmax(np.abs(tilted - exact))), shape)
            fail(
                cls,
                f"on a non-periodic {kind} tilted by {grade.tolist()} every slope must be {exact:.6g}; "
                f"point {tuple(int(i) for i in worst)} has {tilted[worst]:.6g} (a difference across the ends?)",
            )


def _defined_core(slopes):
    """The block of points with a slope, as slices, when the NaN (points without one) only
    fill bands at the profile's ends, each at most a quarter of its axis; else None."""
    import numpy as np

    defined = ~np.isnan(slopes)
    core = []
    for axis, size in enumerate(slopes.shape):
        found = np.flatnonzero(defined.any(axis=tuple(a for a in range(slopes.ndim) if a != axis)))
        if found.size == 0 or found[0] > size // 4 or size - 1 - found[-1] > size // 4:
            return None
        core.append(slice(int(found[0]), int(found[-1]) + 1))
    core = tuple(core)
    return core if defined[core].all() and np.count_nonzero(defined) == defined[core].size else None

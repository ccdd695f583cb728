"""The check of a spectrum generator."""

from __future__ import annotations

import math

from .common import call, check_array, check_positive_number, fail, instantiate, is_not_implemented, reported


@reported
def check_spectrum(cls, *, deterministic: bool = False, **params) -> None:
    """``cls(**params).generate(rng)`` returns a ``Profile`` with finite,
    float64 heights of ``cls.dimension`` dimensions (1: a line, 2: a surface) and a finite ``spacing > 0``; the same seed gives
    identical heights; a different seed gives different heights (unless the class declares
    ``deterministic = True``, a generator that ignores randomness by design, e.g. one that
    reads a measured profile: a run reads the declaration, so ``deterministic=True`` given
    here alone fails); ``rms_height()`` is finite and
    > 0 and agrees within a factor of 3 with the rms (about the mean) of the
    generated lines, pooled over 8 seeds. If ``psd`` is implemented it is
    vectorised (array in, array of the same shape out), finite and >= 0; if
    ``rms_slope`` is implemented it is finite and > 0. The declarations:
    ``periodic()`` is a bool equal to ``Profile.periodic`` of what it makes, and when
    it is False ``not_periodic_advice()`` gives two sentences (why, how to change it); when it is
    True, and randomness makes the profiles (not ``deterministic``), they wrap: along each axis,
    the step from the last point back to the first is neither more than twice the largest step
    between neighbours (a trend) nor zero (a period sampled with its end point) in every one of
    the 8 seeds;
    ``points_param``, if not None, names the field whose value is the points (per
    side) that ``generate()`` makes;
    ``grid_shape()`` is None or the generated shape; ``refined(2 N)``, if not
    None, gives 2 N points (per side) over the same length; ``equivalent_line()``
    is None or, for a surface, a spectrum of lines 2 sqrt(A / pi) long with the
    surface's rms height, itself checked; ``equivalent_line_bytes()`` is None or, for a
    spectrum with such a line, a whole number >= 0; ``c0()`` is NotImplementedError or
    finite > 0; ``hurst_exponent()`` is None or finite >= 0; ``input_summary()`` is None or
    a JSON-ready mapping whose ``shape``, ``spacing`` and ``rms_height`` are those of what
    ``generate()`` makes and ``rms_height()``, with ``file`` and ``unit``;
    ``profile_rms_height(profile)`` is None or finite > 0 for the generated
    profiles, and the same for two of them within a relative 1e-9 (f needs one h);
    ``caveats()`` is a tuple of non-empty sentences (strings).
    """
    import numpy as np

    from frictionlab.plugin.outputs import OTHER_SEED, SAME_SEED, RandomWatch, height_problem, profile_problem

    if deterministic and cls.deterministic is not True:
        fail(cls, "deterministic=True was given to the check, but the class does not declare deterministic = True: "
                  "a run reads the declaration, and refuses a generator whose seeds all give one profile")  # fmt: skip
    deterministic = cls.deterministic is True
    gen = instantiate(cls, params)

    def generate(seed: int):
        watch = RandomWatch()
        profile = call(cls, f"generate(default_rng({seed}))", gen.generate, np.random.default_rng(seed))
        problem = watch.problem("generate()") or profile_problem(gen, profile)  # as a run takes it
        if problem:
            fail(cls, problem)
        return profile

    first = generate(1234)
    second = generate(1234)
    if first.heights.shape != second.heights.shape or not np.array_equal(first.heights, second.heights):
        fail(cls, SAME_SEED)
    if first.spacing != second.spacing:
        fail(cls, "the same seed gave different spacings")
    other = generate(4321)
    if not deterministic and other.heights.shape == first.heights.shape:
        if np.array_equal(other.heights, first.heights):
            fail(cls, OTHER_SEED)

    if problem := call(cls, "rms_height()", height_problem, gen):
        fail(cls, problem)
    h = gen.rms_height()
    profiles = [first, other, *(generate(seed) for seed in range(6))]
    variances = [np.var(profile.heights) for profile in profiles]
    measured = float(np.sqrt(np.mean(variances)))
    if not (h / 3 <= measured <= 3 * h):
        fail(
            cls,
            f"rms_height() = {h:.6g} but the generated lines have rms {measured:.6g} "
            "(pooled over 8 seeds); they should agree within a factor of 3",
        )

    q = 2 * np.pi / (first.heights.size * first.spacing) * np.array([1.0, 2.0, 4.0, 8.0])
    missing, psd = is_not_implemented(cls, "psd(q)", gen.psd, q)
    if not missing:
        psd = np.asarray(psd)
        check_array(cls, "psd(q) for q of shape (4,)", psd, shape=q.shape)
        if np.any(psd < 0):
            fail(cls, f"psd(q) must be >= 0. Got {psd!r}.")
    missing, slope = is_not_implemented(cls, "rms_slope()", gen.rms_slope)
    if not missing:
        check_positive_number(cls, "rms_slope()", slope)
    _check_spectrum_declarations(cls, gen, first, params, deterministic)
    if first.periodic and not deterministic:  # a measured profile is periodic as its data and its preset say
        _check_wraps(cls, profiles)


def _check_wraps(cls, profiles) -> None:
    """A periodic profile's last point leads back to its first as any point leads to the next, along
    each axis: in every one of ``profiles``, a step back more than twice the largest step between
    neighbours is a trend or a window across the profile; none at all, a period sampled with its
    end point ([0, L] rather than [0, L)). Steps are rms over the other axis of a surface."""
    import numpy as np

    for axis in range(profiles[0].heights.ndim):
        along = "" if profiles[0].heights.ndim == 1 else f" along axis {axis}"
        wraps, largest, typical = [], [], []
        for profile in profiles:
            z = profile.heights
            steps = np.diff(z, axis=axis, append=np.take(z, [0], axis=axis))  # the last: back to the first
            rms = np.sqrt(np.mean(np.square(np.moveaxis(steps, axis, 0)).reshape(z.shape[axis], -1), axis=1))
            wraps.append(rms[-1]), largest.append(rms[:-1].max()), typical.append(np.median(rms[:-1]))
        if all(w > 2 * m for w, m in zip(wraps, largest)):
            fail(cls, f"periodic() is True, but the profile does not wrap{along}: the step from its last point back "
                      f"to its first is {wraps[0]:.4g}, more than twice the largest step between neighbours "
                      f"({largest[0]:.4g}), in every one of {len(profiles)} seeds (a trend across it?); make it "
                      "periodic, or declare periodic() False")  # fmt: skip
        if all(w <= 1e-9 * t for w, t in zip(wraps, typical)) and min(typical) > 0:
            fail(cls, f"periodic() is True, but the last point repeats the first{along} in every one of "
                      f"{len(profiles)} seeds: a period of N points is sampled on [0, L) (x = arange(N) * dx), "
                      "not on [0, L] (linspace(0, L, N))")  # fmt: skip


def _check_spectrum_declarations(cls, gen, profile, params, deterministic: bool) -> None:
    """periodic(), points_param, grid_shape(), refined(), equivalent_line(), equivalent_line_bytes(), c0(),
    hurst_exponent(), input_summary(), caveats()."""
    import numpy as np

    from frictionlab.plugin import SpectrumGenerator, mdr_length
    from frictionlab.plugin.outputs import answers_problem, shape_problem

    periodic = call(cls, "periodic()", gen.periodic)
    if not isinstance(periodic, bool) or profile.periodic is not periodic:
        fail(cls, f"periodic() must be True or False and equal Profile.periodic of what generate() makes "
                   f"({profile.periodic!r}). Got {periodic!r} instead.")  # fmt: skip
    if periodic is False:
        advice = call(cls, "not_periodic_advice()", gen.not_periodic_advice)
        if not (isinstance(advice, tuple) and len(advice) == 2 and all(isinstance(t, str) and t.strip() for t in advice)):
            fail(cls, f"not_periodic_advice() must be a (why, how) pair of sentences. Got {advice!r} instead.")
    if cls.points_param is not None:
        points = gen.params.model_dump()[cls.points_param]
        if points != profile.heights.shape[-1]:
            fail(cls, f"points_param names {cls.points_param!r} = {points!r}, but generate() makes "
                      f"{profile.heights.shape[-1]} points (per side)")  # fmt: skip
    answers = call(cls, "periodic(), grid_shape() or caveats()", answers_problem, gen)
    if problem := answers or call(cls, "grid_shape()", shape_problem, gen, profile):
        fail(cls, problem)

    finer_points = 2 * profile.heights.shape[-1]
    changes = call(cls, f"refined({finer_points})", gen.refined, finer_points)
    if changes is not None:
        finer = instantiate(cls, {**params, **changes})
        made = call(cls, f"generate() with refined({finer_points})", finer.generate, np.random.default_rng(1))
        extent = profile.heights.shape[-1] * profile.spacing
        if made.heights.shape[-1] != finer_points or not math.isclose(
            made.heights.shape[-1] * made.spacing, extent, rel_tol=1e-9
        ):
            fail(cls, f"refined({finer_points}) must give {finer_points} points (per side) over the same length "
                       f"{extent:g}. Got shape {made.heights.shape}, spacing {made.spacing!r}.")  # fmt: skip

    line = call(cls, "equivalent_line()", gen.equivalent_line)
    making = call(cls, "equivalent_line_bytes()", gen.equivalent_line_bytes)
    if making is not None and (line is None or not isinstance(making, int) or isinstance(making, bool) or making < 0):
        fail(cls, f"equivalent_line_bytes() must be None, or for a spectrum with an equivalent_line() a whole number "
                  f"of bytes >= 0. Got {making!r} instead.")  # fmt: skip
    if line is not None:
        if cls.dimension != 2 or not isinstance(line, SpectrumGenerator) or line.dimension != 1:
            fail(cls, "equivalent_line() must be None, or (for a surface) a SpectrumGenerator of lines. "
                       f"Got {line!r} instead.")  # fmt: skip
        made = call(cls, "equivalent_line().generate()", line.generate, np.random.default_rng(3))
        length, wanted = made.heights.size * made.spacing, mdr_length(profile.area)
        if not math.isclose(length, wanted, rel_tol=1e-9):
            fail(cls, f"the MDR-equivalent line must be 2 sqrt(A / pi) = {wanted:.9g} long. Got {length:.9g}.")
        line_h, h = call(cls, "equivalent_line().rms_height()", line.rms_height), gen.rms_height()
        if not math.isclose(line_h, h, rel_tol=1e-9):
            fail(cls, f"the MDR-equivalent line must have the surface's rms height {h:.9g}. Got {line_h:.9g}.")
        check_spectrum(type(line), **line.params.model_dump())

    missing, c0 = is_not_implemented(cls, "c0()", gen.c0)
    if not missing:
        check_positive_number(cls, "c0()", c0)
    own = [call(cls, "profile_rms_height(profile)", gen.profile_rms_height, p)
           for p in (profile, gen.generate(np.random.default_rng(11)))]  # fmt: skip
    if own[0] is not None or own[1] is not None:
        if own[0] is None or own[1] is None:
            fail(cls, f"profile_rms_height(profile) must be None for every profile, or a number for every one. Got {own!r}.")
        first, second = (check_positive_number(cls, "profile_rms_height(profile)", h) for h in own)
        if not math.isclose(first, second, rel_tol=1e-9):
            fail(cls, f"profile_rms_height(profile) must be one h for the ensemble's profiles (f is one axis): "
                      f"two profiles gave {first!r} and {second!r}")  # fmt: skip
    hurst = call(cls, "hurst_exponent()", gen.hurst_exponent)
    if hurst is not None and not (isinstance(hurst, float | int) and math.isfinite(hurst) and hurst >= 0):
        fail(cls, f"hurst_exponent() must be None or a finite number >= 0. Got {hurst!r}.")
    _check_input_summary(cls, gen, profile)


def _check_input_summary(cls, gen, profile) -> None:
    from frictionlab.plugin.outputs import input_summary_problem

    summary = call(cls, "input_summary()", gen.input_summary)
    if summary is None:
        return
    if problem := input_summary_problem(summary):  # as a run takes it
        fail(cls, problem)
    if (tuple(summary["shape"]) != profile.heights.shape or summary["spacing"] != profile.spacing
            or summary["rms_height"] != gen.rms_height()):
        fail(cls, f"input_summary() must give the shape {profile.heights.shape}, spacing {profile.spacing!r} and "
                  f"rms height {gen.rms_height()!r} of what generate() makes. Got {summary!r}.")  # fmt: skip

"""pytest helpers for frictionlab plugin authors.

This module is a pytest plugin. It is declared as the ``pytest11`` entry point
``frictionlab``, so it is active in every pytest session of an environment where
frictionlab is installed: you do not import anything to get the fixtures. The
check functions are plain functions; import them::

    from frictionlab.testing import check_plugin

Importing this module is cheap and has no side effects: frictionlab, numpy and
pydantic are imported only when a fixture or a check runs.

Fixtures
========

``frictionlab_registry``
    A fresh ``frictionlab.registry.Registry(discover=False)`` for one test: the
    built-in plugins are loaded, entry-point discovery is blocked (so what other
    distributions happen to be installed cannot change your test).

``register_plugin``
    A function ``register_plugin(obj, name=None)`` that registers ``obj`` on
    ``frictionlab_registry`` for the duration of one test and unregisters it
    afterwards; it returns the registry. ``obj`` is what an entry point would
    point at: a module, or a class or instance carrying ``@frictionlab.hookimpl``
    functions. As a shortcut, a plugin class itself (a ``SpectrumGenerator``,
    ``ContactSolver`` or ``SlopeEstimator`` subclass) is accepted too and is
    registered through the hook of its kind::

        def test_my_plugin_is_found(register_plugin):
            import frictionlab_gaussian

            registry = register_plugin(frictionlab_gaussian)
            assert registry.get("spectrum", "gaussian") is frictionlab_gaussian.Gaussian

    Registration runs pluggy's ``check_pending()``, so a misspelled hook name
    fails here with ``pluggy.PluginValidationError``; a class that breaks the
    contract fails with ``frictionlab.errors.PluginError``.

Conformance checks
==================

Each check raises ``AssertionError`` with a readable message naming the class
and what is wrong (an exception raised by your plugin's code is turned into an
``AssertionError`` too, chained to the original). Parametrise them over your own
classes::

    import pytest
    from frictionlab.testing import check_plugin

    @pytest.mark.parametrize("params", [{}, {"correlation_length": 3.0}])
    def test_conformance(params):
        check_plugin("spectrum", Gaussian, **params)

``check_plugin_class(kind, cls, params=None)``
    The contract every kind shares (``kind`` is ``"spectrum"``, ``"solver"`` or
    ``"slope"``): ``frictionlab.registry.validate_plugin_class`` passes (right
    base class, kebab-case ``name``, one-line ``summary``, pydantic ``Params``
    forbidding unknown keys, every field described); ``references`` is a tuple
    of strings; ``Params`` has a JSON Schema; ``Params(**params)`` and
    ``cls(**params)`` construct (``params`` defaults to ``{}``: give it when a
    field has no default); an unknown key raises ``pydantic.ValidationError``
    naming it; the parameters survive a JSON round trip (presets are YAML);
    and, for every bounded numeric field (bounds read from the JSON Schema, or
    from the field's ``ge``/``gt``/``le``/``lt`` metadata), a value just past
    each bound is rejected, at construction and on assignment, with a message
    naming the field. That last part is skipped only when no field is bounded.

``check_spectrum(cls, *, deterministic=False, **params)``
    ``cls(**params).generate(rng)`` returns a ``Profile`` with finite,
    floating-point heights of ``cls.dimension`` dimensions (1: a line, 2: a surface) and a finite ``spacing > 0``; the same seed gives
    identical heights; a different seed gives different heights (pass
    ``deterministic=True`` for a generator that ignores randomness by design,
    e.g. one that reads a measured profile); ``rms_height()`` is finite and
    > 0 and agrees within a factor of 3 with the rms (about the mean) of the
    generated lines, pooled over 8 seeds. If ``psd`` is implemented it is
    vectorised (array in, array of the same shape out), finite and >= 0; if
    ``rms_slope`` is implemented it is finite and > 0. The declarations:
    ``periodic()`` is a bool equal to ``Profile.periodic`` of what it makes;
    ``grid_shape()`` is None or the generated shape; ``refined(2 N)``, if not
    None, gives 2 N points (per side) over the same length; ``equivalent_line()``
    is None or, for a surface, a spectrum of lines 2 sqrt(A / pi) long with the
    surface's rms height, itself checked; ``c0()`` is NotImplementedError or
    finite > 0; ``hurst_exponent()`` is None or finite >= 0.

``check_solver(cls, **params)``
    ``cls(**params).solve(profile, loads, control, slopes)`` on a small smooth
    random periodic line (64 points) with forward-difference slopes (a solver
    whose ``dimensions`` lack 1 gets a 16 x 16 surface with forward-difference
    gradient magnitudes instead), under force
    control (forces F = f k h L, L = ``Profile.length``, f from 0.005 to 1, k = ``stiffness()``) and
    under indentation control (2.5 % to 95 % of max z - mean z, the approach at
    which a periodic elastic half-space reaches full contact): it returns a ``ContactCurve``
    whose arrays all have the shape of ``loads`` and are finite; the controlled
    quantity is reported back (``force`` resp. ``indentation`` equal to the
    loads within 1 %); force and indentation do not decrease with load; contact
    counts are whole numbers, do not decrease with load, and lie in 1 .. N;
    ``contact_fraction == contact_count / N``; ``slope_rms_contact`` is >= 0 and
    no larger than the largest |slope|; every ``extras`` array has one entry per
    load; the inputs are not modified; the same input gives the same output.
    ``stiffness()`` is finite and > 0. The declarations: the forces come from
    ``frictionlab.force_unit``, so ``normalisations`` must cover the profile;
    f is dimensionless as declared: every length x 1000 with each load scaled by
    its unit (a force x 1000^2, a force per unit depth x 1000, an indentation x
    1000), and the spacing alone x 10 at equal f, leave the contact counts and
    the rms slope in contact unchanged; ``mean_displacement(f, h)`` has the shape
    of f; ``tolerance()`` is None exactly when ``tolerance_param`` is; a
    ``periodic_only`` solver raises ValueError on a non-periodic profile, any
    other solves it. (Registration itself checks that every declaration is
    well formed: ``registry.declaration_problems``.)

``check_slope_estimator(cls, **params)``
    ``cls(**params).slopes(heights, spacing, periodic)`` on a random periodic line returns
    a finite floating-point array of the same shape, does not modify its input
    and is repeatable; a constant line gives zero slopes; on a periodic sine
    (3 periods over 128 points, spacing 0.1) the slopes match the exact
    derivative in order of magnitude and sign (rms within a factor of 2,
    relative rms error below 0.5). An estimator whose ``dimensions`` include 2
    gets the same checks on a 24 x 40 surface, with a plane wave across both
    axes whose exact slope is |grad z| (so its slopes must be >= 0); lines are
    checked only if ``dimensions`` include 1. ``slopes(..., periodic=False)``
    on a tilted plane gives the tilt at every point (no difference across the
    ends), or, for a ``periodic_only`` estimator, raises ValueError.

``check_plugin(kind, cls, *, deterministic=False, **params)``
    ``check_plugin_class`` followed by the check of ``kind``
    (``deterministic`` is passed on to ``check_spectrum`` only).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Mapping
from typing import Any

import pytest

__all__ = [
    "check_plugin",
    "check_plugin_class",
    "check_slope_estimator",
    "check_solver",
    "check_spectrum",
    "frictionlab_registry",
    "register_plugin",
]

KIND_CHOICES = ("spectrum", "solver", "slope")

# ------------------------------------------------------------------ fixtures


@pytest.fixture
def frictionlab_registry():
    """A fresh registry: built-ins loaded, entry-point discovery blocked."""
    from frictionlab.registry import Registry

    return Registry(discover=False)


@pytest.fixture
def register_plugin(frictionlab_registry):
    """``register_plugin(obj, name=None) -> registry``: register ``obj`` on
    ``frictionlab_registry`` for this test only."""
    registered: list[object] = []

    def register(obj, name: str | None = None):
        plugin = _as_hook_plugin(obj)
        if name is None and plugin is not obj:
            name = f"{obj.__module__}.{obj.__qualname__}"
        frictionlab_registry.register_plugin(plugin, name=name)
        registered.append(plugin)
        return frictionlab_registry

    yield register

    for plugin in reversed(registered):
        if frictionlab_registry.pm.is_registered(plugin):
            frictionlab_registry.unregister_plugin(plugin)


def _as_hook_plugin(obj):
    """A plugin class (not a hook holder) becomes a namespace with one hookimpl."""
    from frictionlab.plugin import Plugin

    if isinstance(obj, type) and issubclass(obj, Plugin) and obj.kind:
        import types

        from frictionlab.hookspecs import hookimpl
        from frictionlab.registry import KIND_HOOKS

        def _register(register):
            register(obj)

        return types.SimpleNamespace(**{KIND_HOOKS[obj.kind]: hookimpl(_register)})
    return obj


# ------------------------------------------------------------------ helpers


def _label(cls) -> str:
    from frictionlab.plugin import Plugin

    if not isinstance(cls, type):
        return repr(cls)
    name = cls.name if issubclass(cls, Plugin) else None
    return f"{cls.__module__}.{cls.__qualname__}" + (f" ({name!r})" if name else "")


def _fail(cls, message: str, cause: BaseException | None = None):
    error = AssertionError(f"{_label(cls)}: {message}")
    if cause is not None:
        raise error from cause
    raise error


def _call(cls, what: str, fn: Callable[..., Any], *args, **kwargs):
    """Run plugin code; any exception becomes an AssertionError naming the call."""
    try:
        return fn(*args, **kwargs)
    except AssertionError:
        raise
    except Exception as exc:
        _fail(cls, f"{what} raised {type(exc).__name__}: {exc}", exc)


def _instantiate(cls, params: Mapping[str, Any]):
    return _call(
        cls,
        f"{cls.__qualname__}(**{dict(params)!r}) (give the check the parameters it needs)",
        cls,
        **params,
    )


def _check_array(cls, what: str, value, shape=None, floating=True):
    import numpy as np

    if not isinstance(value, np.ndarray):
        _fail(cls, f"{what} must be a numpy array. Got {type(value).__name__} instead.")
    if shape is not None and value.shape != tuple(shape):
        _fail(cls, f"{what} must have shape {tuple(shape)}. Got {value.shape} instead.")
    if floating and not np.issubdtype(value.dtype, np.floating):
        _fail(cls, f"{what} must be floating point. Got dtype {value.dtype} instead.")
    if not np.issubdtype(value.dtype, np.number):
        _fail(cls, f"{what} must be numeric. Got dtype {value.dtype} instead.")
    if not np.all(np.isfinite(value)):
        bad = int(np.size(value) - np.count_nonzero(np.isfinite(value)))
        _fail(cls, f"{what} must be finite. Got {bad} non-finite value(s).")
    return value


def _check_positive_number(cls, what: str, value) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        _fail(cls, f"{what} must be a number. Got {value!r} instead.")
    if not math.isfinite(number) or number <= 0:
        _fail(cls, f"{what} must be finite and > 0. Got {number!r} instead.")
    return number


def _is_not_implemented(cls, what: str, fn, *args):
    """Call an optional method: (True, None) if it raises NotImplementedError."""
    try:
        return False, fn(*args)
    except NotImplementedError:
        return True, None
    except Exception as exc:
        _fail(cls, f"{what} raised {type(exc).__name__}: {exc}", exc)


# ------------------------------------------------------------------ Params bounds


def _schema_bounds(prop: Mapping[str, Any]) -> list[tuple[str, float, bool]]:
    """(keyword, bound, is_integer) for a property of a JSON Schema (anyOf too)."""
    bounds = []
    alternatives = [prop]
    for key in ("anyOf", "oneOf", "allOf"):
        alternatives.extend(prop.get(key, []))
    for alt in alternatives:
        if not isinstance(alt, Mapping) or alt.get("type") not in ("number", "integer"):
            continue
        for keyword in ("minimum", "exclusiveMinimum", "maximum", "exclusiveMaximum"):
            value = alt.get(keyword)
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                bounds.append((keyword, float(value), alt.get("type") == "integer"))
    return bounds


def _metadata_bounds(info) -> list[tuple[str, float, bool]]:
    keywords = {"ge": "minimum", "gt": "exclusiveMinimum", "le": "maximum", "lt": "exclusiveMaximum"}
    is_int = info.annotation is int
    bounds = []
    for item in info.metadata:
        for attr, keyword in keywords.items():
            value = getattr(item, attr, None)
            if isinstance(value, (int, float)) and not isinstance(value, bool):
                bounds.append((keyword, float(value), is_int))
    return bounds


def _past(keyword: str, bound: float, is_int: bool):
    """A value just on the wrong side of a bound."""
    step = max(1.0, abs(bound))
    if keyword == "minimum":
        value = math.ceil(bound) - 1 if is_int else bound - step
    elif keyword == "exclusiveMinimum":
        value = math.floor(bound) if is_int else bound
    elif keyword == "maximum":
        value = math.floor(bound) + 1 if is_int else bound + step
    else:  # exclusiveMaximum
        value = math.ceil(bound) if is_int else bound
    return int(value) if is_int else float(value)


def _bounded_fields(cls, schema) -> list[tuple[str, str, float, bool]]:
    found = []
    props = (schema or {}).get("properties", {})
    for field_name, info in cls.Params.model_fields.items():
        key = info.alias or field_name
        bounds = _schema_bounds(props.get(key, {})) or _metadata_bounds(info)
        seen = set()
        for keyword, bound, is_int in bounds:
            if keyword not in seen:
                seen.add(keyword)
                found.append((key, keyword, bound, is_int))
    return found


# ------------------------------------------------------------------ generic check


def check_plugin_class(kind: str, cls, params: Mapping[str, Any] | None = None) -> None:
    """Check the contract shared by every plugin kind (see the module docstring).

    ``params`` are keyword arguments that construct a valid instance (default:
    none, i.e. every field has a default).
    """
    from pydantic import ValidationError

    from frictionlab.errors import PluginError
    from frictionlab.registry import normalize_name, validate_plugin_class

    if kind not in KIND_CHOICES:
        raise ValueError(f"kind must be one of {', '.join(KIND_CHOICES)}. Got {kind!r} instead.")
    params = dict(params or {})

    try:
        validate_plugin_class(kind, cls)
    except PluginError as exc:
        _fail(cls, f"breaks the {kind} plugin contract: {exc}", exc)
    if normalize_name(cls.name) != cls.name:
        _fail(cls, f"name must be in normalised kebab-case. Got {cls.name!r} instead.")
    refs = cls.references
    if not isinstance(refs, (tuple, list)) or not all(isinstance(r, str) and r.strip() for r in refs):
        _fail(cls, f"references must be a tuple of strings (DOIs). Got {refs!r} instead.")

    Params = cls.Params
    undescribed = [n for n, info in Params.model_fields.items() if not (info.description or "").strip()]
    if undescribed:
        _fail(cls, f"Params fields without a description: {', '.join(undescribed)}")
    try:
        schema = Params.model_json_schema()
    except Exception as exc:  # editors and the CLI need it
        _fail(cls, f"Params.model_json_schema() raised {type(exc).__name__}: {exc}", exc)

    # defaults (or the given params) construct
    try:
        model = Params(**params)
    except ValidationError as exc:
        hint = "" if params else " (pass the required values: check_plugin_class(kind, cls, params={...}))"
        _fail(cls, f"Params(**{params!r}) is invalid{hint}: {exc}", exc)
    instance = _instantiate(cls, params)
    if instance.__dict__.get("params") != model:
        _fail(cls, "the constructor must store its validated Params as self.params")

    # unknown keys are rejected
    unknown = "frictionlab_conformance_unknown_key"
    try:
        Params(**params, **{unknown: 1})
    except ValidationError as exc:
        if unknown not in str(exc):
            _fail(cls, f"the error for an unknown key does not name it: {exc}")
    else:
        _fail(cls, f"Params accepted the unknown key {unknown!r}; unknown keys must be rejected")

    # JSON round trip (presets and result files store params as YAML/JSON)
    try:
        again = Params.model_validate(model.model_dump(mode="json"))
    except Exception as exc:
        _fail(cls, f"Params do not survive a JSON round trip: {type(exc).__name__}: {exc}", exc)
    if again != model:
        _fail(cls, f"Params change in a JSON round trip: {model!r} -> {again!r}")

    # bounds are enforced, with messages naming the field
    for key, keyword, bound, is_int in _bounded_fields(cls, schema):
        bad = _past(keyword, bound, is_int)
        what = f"Params.{key} = {bad!r} (past its {keyword} {bound:g})"
        try:
            Params(**{**params, key: bad})
        except ValidationError as exc:
            if key not in str(exc):
                _fail(cls, f"the error for {what} does not name the field: {exc}")
        else:
            _fail(cls, f"{what} was accepted; out-of-range values must be rejected")
        fresh = Params(**params)
        try:
            setattr(fresh, key, bad)
        except ValidationError:
            pass
        except Exception as exc:
            _fail(cls, f"assigning {what} raised {type(exc).__name__} instead of ValidationError", exc)
        else:
            _fail(
                cls,
                f"assigning {what} was accepted; Params must validate on assignment "
                "(derive from frictionlab.PluginParams)",
            )


# ------------------------------------------------------------------ kind checks


def check_spectrum(cls, *, deterministic: bool = False, **params) -> None:
    """Check a spectrum generator class (see the module docstring)."""
    import numpy as np

    from frictionlab.plugin import Profile

    gen = _instantiate(cls, params)

    def generate(seed: int):
        profile = _call(cls, f"generate(default_rng({seed}))", gen.generate, np.random.default_rng(seed))
        if not isinstance(profile, Profile):
            _fail(cls, f"generate() must return a frictionlab.Profile. Got {type(profile).__name__} instead.")
        heights = _check_array(cls, "Profile.heights", profile.heights)
        dimension = cls.dimension
        if heights.ndim != dimension:
            _fail(cls, f"Profile.heights must be {dimension}-D (dimension = {dimension}). Got shape {heights.shape} instead.")
        if heights.size < 2:
            _fail(cls, f"Profile.heights must have at least 2 points. Got {heights.size}.")
        _check_positive_number(cls, "Profile.spacing", profile.spacing)
        return profile

    first = generate(1234)
    second = generate(1234)
    if first.heights.shape != second.heights.shape or not np.array_equal(first.heights, second.heights):
        _fail(cls, "the same seed gave different heights; draw all randomness from the rng argument")
    if first.spacing != second.spacing:
        _fail(cls, "the same seed gave different spacings")
    other = generate(4321)
    if not deterministic and other.heights.shape == first.heights.shape:
        if np.array_equal(other.heights, first.heights):
            _fail(
                cls,
                "different seeds gave identical heights; use the rng argument "
                "(or pass deterministic=True if the generator is deterministic by design)",
            )

    h = _check_positive_number(cls, "rms_height()", _call(cls, "rms_height()", gen.rms_height))
    variances = [np.var(first.heights), np.var(other.heights)]
    variances += [np.var(generate(seed).heights) for seed in range(6)]
    measured = float(np.sqrt(np.mean(variances)))
    if not (h / 3 <= measured <= 3 * h):
        _fail(
            cls,
            f"rms_height() = {h:.6g} but the generated lines have rms {measured:.6g} "
            "(pooled over 8 seeds); they should agree within a factor of 3",
        )

    q = 2 * np.pi / (first.heights.size * first.spacing) * np.array([1.0, 2.0, 4.0, 8.0])
    missing, psd = _is_not_implemented(cls, "psd(q)", gen.psd, q)
    if not missing:
        psd = np.asarray(psd)
        _check_array(cls, "psd(q) for q of shape (4,)", psd, shape=q.shape)
        if np.any(psd < 0):
            _fail(cls, f"psd(q) must be >= 0. Got {psd!r}.")
    missing, slope = _is_not_implemented(cls, "rms_slope()", gen.rms_slope)
    if not missing:
        _check_positive_number(cls, "rms_slope()", slope)
    _check_spectrum_declarations(cls, gen, first, params, deterministic)


def _check_spectrum_declarations(cls, gen, profile, params, deterministic: bool) -> None:
    """periodic(), grid_shape(), refined(), equivalent_line(), c0(), hurst_exponent()."""
    import numpy as np

    from frictionlab.plugin import SpectrumGenerator, mdr_length

    periodic = _call(cls, "periodic()", gen.periodic)
    if not isinstance(periodic, bool) or profile.periodic is not periodic:
        _fail(cls, f"periodic() must be True or False and equal Profile.periodic of what generate() makes "
                   f"({profile.periodic!r}). Got {periodic!r} instead.")  # fmt: skip
    shape = _call(cls, "grid_shape()", gen.grid_shape)
    if shape is not None and tuple(shape) != profile.heights.shape:
        _fail(cls, f"grid_shape() must be None or the shape generate() makes, {profile.heights.shape}. Got {shape!r}.")

    finer_points = 2 * profile.heights.shape[-1]
    changes = _call(cls, f"refined({finer_points})", gen.refined, finer_points)
    if changes is not None:
        finer = _instantiate(cls, {**params, **changes})
        made = _call(cls, f"generate() with refined({finer_points})", finer.generate, np.random.default_rng(1))
        extent = profile.heights.shape[-1] * profile.spacing
        if made.heights.shape[-1] != finer_points or not math.isclose(
            made.heights.shape[-1] * made.spacing, extent, rel_tol=1e-9
        ):
            _fail(cls, f"refined({finer_points}) must give {finer_points} points (per side) over the same length "
                       f"{extent:g}. Got shape {made.heights.shape}, spacing {made.spacing!r}.")  # fmt: skip

    line = _call(cls, "equivalent_line()", gen.equivalent_line)
    if line is not None:
        if cls.dimension != 2 or not isinstance(line, SpectrumGenerator) or line.dimension != 1:
            _fail(cls, "equivalent_line() must be None, or (for a surface) a SpectrumGenerator of lines. "
                       f"Got {line!r} instead.")  # fmt: skip
        made = _call(cls, "equivalent_line().generate()", line.generate, np.random.default_rng(3))
        length, wanted = made.heights.size * made.spacing, mdr_length(profile.area)
        if not math.isclose(length, wanted, rel_tol=1e-9):
            _fail(cls, f"the MDR-equivalent line must be 2 sqrt(A / pi) = {wanted:.9g} long. Got {length:.9g}.")
        line_h, h = _call(cls, "equivalent_line().rms_height()", line.rms_height), gen.rms_height()
        if not math.isclose(line_h, h, rel_tol=1e-9):
            _fail(cls, f"the MDR-equivalent line must have the surface's rms height {h:.9g}. Got {line_h:.9g}.")
        check_spectrum(type(line), **line.params.model_dump())

    missing, c0 = _is_not_implemented(cls, "c0()", gen.c0)
    if not missing:
        _check_positive_number(cls, "c0()", c0)
    hurst = _call(cls, "hurst_exponent()", gen.hurst_exponent)
    if hurst is not None and not (isinstance(hurst, float | int) and math.isfinite(hurst) and hurst >= 0):
        _fail(cls, f"hurst_exponent() must be None or a finite number >= 0. Got {hurst!r}.")


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


def check_solver(cls, **params) -> None:
    """Check a contact solver class (see the module docstring)."""
    import numpy as np

    from frictionlab.plugin import ContactCurve, Profile, force_unit

    solver = _instantiate(cls, params)
    _check_positive_number(cls, "stiffness()", _call(cls, "stiffness()", solver.stiffness))
    if 1 in cls.dimensions:
        heights, spacing, slopes = _test_line()
    else:  # a solver of surfaces only
        heights, spacing, slopes = _test_surface()
    n = heights.size
    h = float(heights.std())
    unit = _call(cls, "force_unit() (from normalisations)", force_unit, solver, h, Profile(heights, spacing))
    cases = {
        "force": np.array([0.005, 0.02, 0.1, 0.4, 1.0]) * unit,
        # below max z - mean z: past it an elastic half-space would need an infinite force
        "indentation": np.array([0.025, 0.1, 0.25, 0.5, 0.95]) * float(heights.max() - heights.mean()),
    }
    names = ("force", "indentation", "contact_count", "contact_fraction", "slope_rms_contact")

    for control, loads in cases.items():
        where = f"solve(..., control={control!r})"

        def run():
            profile = Profile(heights=heights.copy(), spacing=spacing)
            args = (profile, loads.copy(), control, slopes.copy())
            curve = _call(cls, where, solver.solve, *args)
            if not (
                np.array_equal(args[0].heights, heights)
                and np.array_equal(args[1], loads)
                and np.array_equal(args[3], slopes)
            ):
                _fail(cls, f"{where} modified its inputs")
            return curve

        curve = run()
        if not isinstance(curve, ContactCurve):
            _fail(cls, f"{where} must return a frictionlab.ContactCurve. Got {type(curve).__name__} instead.")
        arrays = {}
        for name in names:
            value = getattr(curve, name)
            floating = name != "contact_count"
            arrays[name] = _check_array(cls, f"{where}.{name}", np.asarray(value), loads.shape, floating)
        for name, value in curve.extras.items():
            if np.shape(value)[:1] != loads.shape:
                _fail(cls, f"{where}.extras[{name!r}] must have one entry per load. Got shape {np.shape(value)}.")

        reported = arrays[control]
        if not np.allclose(reported, loads, rtol=1e-2, atol=0):
            _fail(cls, f"{where}.{control} must report the loads asked for: {loads!r}. Got {reported!r} instead.")
        for name in ("force", "indentation", "contact_count"):
            if np.any(np.diff(arrays[name]) < 0):
                _fail(cls, f"{where}.{name} must not decrease as the load grows. Got {arrays[name]!r}.")
        count = arrays["contact_count"]
        if not np.array_equal(count, np.round(count)):
            _fail(cls, f"{where}.contact_count must hold whole numbers. Got {count!r}.")
        if np.any(count < 1) or np.any(count > n):
            _fail(cls, f"{where}.contact_count must lie in 1 .. {n} (points in the line). Got {count!r}.")
        if not np.allclose(arrays["contact_fraction"], count / n, rtol=1e-12, atol=1e-12):
            _fail(
                cls,
                f"{where}.contact_fraction must equal contact_count / N = {count / n!r}. "
                f"Got {arrays['contact_fraction']!r} instead.",
            )
        rms = arrays["slope_rms_contact"]
        if np.any(rms < 0) or np.any(rms > np.abs(slopes).max() * (1 + 1e-12)):
            _fail(
                cls,
                f"{where}.slope_rms_contact must lie in [0, max |slope| = {np.abs(slopes).max():.6g}]. "
                f"Got {rms!r}.",
            )

        again = run()
        for name in names:
            if not np.array_equal(np.asarray(getattr(again, name)), arrays[name]):
                _fail(cls, f"{where} is not repeatable: {name} differs between two identical calls")
    _check_solver_declarations(cls, solver, heights, spacing, slopes, cases["force"])
    _check_solver_units(cls, solver, heights, spacing, slopes)


def _must_refuse(cls, what: str, call: Callable[[], Any]) -> None:
    """A ``periodic_only`` plugin must refuse ``what`` with a ValueError."""
    try:
        call()
    except ValueError:
        return
    except Exception as exc:
        _fail(cls, f"periodic_only: {what} must raise ValueError. Got {type(exc).__name__}: {exc}", exc)
    _fail(cls, f"periodic_only is True, but {what} was accepted; it must raise ValueError")


def _solve(cls, solver, heights, spacing, slopes, loads, control="force", periodic=True):
    from frictionlab.plugin import Profile

    where = f"solve(..., control={control!r}) on a profile of spacing {spacing:g}" + ("" if periodic else ", not periodic")
    return _call(cls, where, solver.solve, Profile(heights.copy(), spacing, periodic), loads.copy(), control, slopes.copy())


def _check_solver_declarations(cls, solver, heights, spacing, slopes, forces) -> None:
    """mean_displacement(), tolerance(), and periodic_only against a non-periodic profile."""
    import numpy as np

    f = np.array([0.01, 0.1])
    shift = np.asarray(_call(cls, "mean_displacement(f, h)", solver.mean_displacement, f, 1.0))
    if shift.shape != f.shape or not np.all(np.isfinite(shift)):
        _fail(cls, f"mean_displacement(f, h) must return a finite array of the shape of f. Got {shift!r}.")
    tolerance = _call(cls, "tolerance()", solver.tolerance)
    if (tolerance is None) != (cls.tolerance_param is None):
        _fail(cls, f"tolerance() must be None exactly when tolerance_param is None. Got {tolerance!r}.")
    if tolerance is not None:
        _check_positive_number(cls, "tolerance()", tolerance)
    if cls.periodic_only:
        from frictionlab.plugin import Profile

        profile = Profile(heights.copy(), spacing, periodic=False)
        _must_refuse(cls, "a non-periodic profile", lambda: solver.solve(profile, forces.copy(), "force", slopes.copy()))
    else:
        _solve(cls, solver, heights, spacing, slopes, forces, periodic=False)


def _check_solver_units(cls, solver, heights, spacing, slopes) -> None:
    """f is dimensionless as declared: every length x 1000 with each load scaled by its unit
    (a force by 1000^2, a force per unit depth by 1000, an indentation by 1000), and the
    spacing alone x 10 at equal f, leave the contact counts and the rms slope in contact as
    they were (the moduli are the solver's own; only lengths change)."""
    import numpy as np

    from frictionlab.plugin import Profile, force_unit

    h = float(heights.std())
    f = np.array([0.01, 0.05, 0.2])
    base = _solve(cls, solver, heights, spacing, slopes, f * force_unit(solver, h, Profile(heights, spacing)))
    s = 1000.0
    normalisation = solver.normalisation(heights.ndim)
    load_scale = s * s if normalisation.load == "force" else s
    scaled = _solve(cls, solver, heights * s, spacing * s, slopes, f * force_unit(solver, h, Profile(heights, spacing)) * load_scale)
    refined = _solve(cls, solver, heights, spacing * 10, slopes / 10,
                     f * force_unit(solver, h, Profile(heights, spacing * 10)))  # fmt: skip

    def compare(what, other, slope_factor=1.0):
        counts, expected = np.asarray(other.contact_count), np.asarray(base.contact_count)
        slope = np.asarray(other.slope_rms_contact) * slope_factor
        if not np.array_equal(counts, expected) or not np.allclose(slope, base.slope_rms_contact, rtol=1e-6, atol=0):
            _fail(
                cls,
                f"f = {normalisation.formula} is not dimensionless as declared ({normalisation.definition}): with "
                f"{what} the contact counts went from {expected.tolist()} to {counts.tolist()}, the rms slope in "
                f"contact from {np.asarray(base.slope_rms_contact).tolist()} to {slope.tolist()}",
            )

    compare(f"every length x {s:g}, each load by its unit ({normalisation.load})", scaled)
    compare("only the spacing x 10 at equal f", refined, 10.0)
    depth = _solve(cls, solver, heights * s, spacing * s, slopes, np.asarray(base.indentation) * s, "indentation")
    compare(f"every length x {s:g} under indentation control", depth)


def check_slope_estimator(cls, **params) -> None:
    """Check a slope estimator class (see the module docstring)."""
    import numpy as np

    estimator = _instantiate(cls, params)
    spacing = 0.1
    dimensions = cls.dimensions

    def run(what, heights, periodic=True):
        original = heights.copy()
        call = f"slopes({what}, spacing={spacing}, periodic={periodic})"
        slopes = _call(cls, call, estimator.slopes, heights, spacing, periodic)
        if not np.array_equal(heights, original):
            _fail(cls, f"slopes({what}) modified its input")
        _check_array(cls, f"slopes({what})", slopes, heights.shape)
        return slopes

    rng = np.random.default_rng(7)
    for shape in [s for d, s in ((1, (128,)), (2, (24, 40))) if d in dimensions]:
        kind = "line" if len(shape) == 1 else "surface"
        noisy = rng.standard_normal(shape)
        first = run(f"random {kind}", noisy)
        if not np.array_equal(run(f"random {kind}", noisy), first):
            _fail(cls, "slopes() is not repeatable: two identical calls differ")

        flat = run(f"constant {kind}", np.full(shape, 3.7))
        if np.max(np.abs(flat)) > 1e-9:
            _fail(cls, f"a constant {kind} must have zero slopes. Got max |slope| = {np.max(np.abs(flat)):.3g}.")

        # a sine along x (a line), a plane wave across both axes (a surface: |grad z|)
        grids = np.meshgrid(*(np.arange(n) * spacing for n in shape), indexing="ij")
        q = [2 * np.pi * k / (n * spacing) for k, n in zip((3, 2)[: len(shape)], shape)]
        amplitude = 0.8
        phase = sum(qi * xi for qi, xi in zip(q, grids))
        sine = amplitude * np.sin(phase)
        exact = amplitude * np.cos(phase) * (q[0] if kind == "line" else np.hypot(*q))
        estimate = run("sine" if kind == "line" else "plane wave", sine)
        if kind == "surface":
            if np.any(estimate < 0):
                _fail(cls, "on a surface the slopes must be gradient magnitudes |grad z| >= 0")
            exact = np.abs(exact)
        rms_exact = float(np.sqrt(np.mean(exact**2)))
        rms_estimate = float(np.sqrt(np.mean(estimate**2)))
        error = float(np.sqrt(np.mean((estimate - exact) ** 2))) / rms_exact
        if not (0.5 <= rms_estimate / rms_exact <= 2.0) or error > 0.5:
            _fail(
                cls,
                f"on A sin(q . x) (A = {amplitude}, q = {np.round(q, 4).tolist()}, spacing = {spacing}, shape {shape}) "
                f"the slopes have rms {rms_estimate:.4g} and relative rms error {error:.3g} against the exact "
                f"derivative (rms {rms_exact:.4g}); expected the same order of magnitude and sign (divide by spacing?)",
            )

        # a scan whose ends do not meet: a plane, tilted along every axis; no slope may cross the ends
        grade = np.array([0.3, -0.2])[: len(shape)]
        ramp = sum(g * x for g, x in zip(grade, grids))
        if cls.periodic_only:
            _must_refuse(cls, "a non-periodic profile", lambda ramp=ramp: estimator.slopes(ramp, spacing, False))
            continue
        tilted = run(f"non-periodic tilted {kind}", ramp, periodic=False)
        exact = grade[0] if kind == "line" else float(np.hypot(*grade))
        if not np.allclose(tilted, exact, rtol=1e-9, atol=1e-12):
            worst = np.unravel_index(int(np.argmax(np.abs(tilted - exact))), shape)
            _fail(
                cls,
                f"on a non-periodic {kind} tilted by {grade.tolist()} every slope must be {exact:.6g}; "
                f"point {tuple(int(i) for i in worst)} has {tilted[worst]:.6g} (a difference across the ends?)",
            )


_KIND_CHECKS = {
    "spectrum": check_spectrum,
    "solver": check_solver,
    "slope": check_slope_estimator,
}


def check_plugin(kind: str, cls, *, deterministic: bool = False, **params) -> None:
    """``check_plugin_class(kind, cls, params)`` and then the check of ``kind``."""
    check_plugin_class(kind, cls, params)
    if kind == "spectrum":
        check_spectrum(cls, deterministic=deterministic, **params)
    else:
        _KIND_CHECKS[kind](cls, **params)

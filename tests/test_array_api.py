"""The exact solvers' operators and contact CG on a strict array API namespace
(``array_api_strict``): nothing numpy-only (``out=``, fancy scatter, methods of
ndarray) may remain on the path a GPU's CuPy arrays take. Each answer is checked
against the numpy path's, which the rest of the solver tests check against physics.
And ``device: gpu`` is refused, naming what is missing, where CuPy is not installed."""


import numpy as np
import pytest

from frictionlab import Profile
from frictionlab_solvers import arrays, bem, bem_free
from frictionlab_solvers.bem import BEMHalfSpace
from frictionlab_solvers.bem_free import BEMHalfSpaceFree, FreeHalfSpace
from frictionlab_solvers.contact_cg import ProjectedCG, cold_start
from frictionlab_solvers.elastic import PeriodicHalfSpace

xp = pytest.importorskip("array_api_strict")


def surface(side: int, seed: int) -> np.ndarray:
    """A smooth random surface (a few long waves): a partial contact of a few patches."""
    rng = np.random.default_rng(seed)
    y, x = np.meshgrid(np.arange(side), np.arange(side), indexing="ij")
    z = np.zeros((side, side))
    for kx, ky in [(1, 0), (0, 1), (1, 1), (2, 1), (1, 3), (3, 2)]:
        z += rng.normal() / np.hypot(kx, ky) ** 1.8 * np.cos(2 * np.pi * (kx * x + ky * y) / side + rng.uniform(0, 6.3))
    return z


def strict(array: np.ndarray):
    return xp.asarray(array)


@pytest.mark.parametrize("operator_of", [PeriodicHalfSpace, FreeHalfSpace], ids=["periodic", "free"])
def test_the_operators_give_numpys_answers_on_strict_arrays(operator_of):
    shape = (24, 20)
    field = np.random.default_rng(1).normal(size=shape)
    on_numpy, on_strict = operator_of(shape), operator_of(shape, xp)
    for method, close in [("displacement", 1e-13), ("displacement_estimate", 1e-6), ("precondition", 1e-6)]:
        expected = getattr(on_numpy, method)(field, np.empty(shape))
        out = xp.empty(shape, dtype=xp.float64)
        got = getattr(on_strict, method)(strict(field), out)
        assert got is out and isinstance(got, type(xp.asarray(0.0)))
        scale = np.abs(expected).max()
        assert np.abs(arrays.host(got) - expected).max() <= close * scale, method
    assert on_strict.point_stiffness == pytest.approx(on_numpy.point_stiffness, rel=1e-12)


@pytest.mark.parametrize("control", ["force", "indentation"])
@pytest.mark.parametrize("operator_of", [PeriodicHalfSpace, FreeHalfSpace], ids=["periodic", "free"])
def test_the_contact_cg_solves_strict_arrays_as_it_solves_numpy_ones(operator_of, control):
    z = surface(32, 3)
    depth = (z.max() - z) / (z.max() - z.min())
    shape = depth.shape
    answers = []
    for namespace in (None, xp):
        operator = operator_of(shape) if namespace is None else operator_of(shape, namespace)
        cg = ProjectedCG(operator, depth if namespace is None else strict(depth))
        start = cold_start(depth, 0.002) if control == "force" else np.maximum(0.3 - depth, 0.0)
        pressure = start if namespace is None else strict(start)
        given = {"mean_pressure": 0.002} if control == "force" else {"approach": 0.3}
        p, level, iterations, residual = cg.solve(pressure, tolerance=1e-11, max_iterations=2000, **given)
        assert residual <= 1e-11
        answers.append((arrays.host(p), level, iterations))
    (p_np, level_np, _), (p_strict, level_strict, _) = answers
    assert 0 < np.count_nonzero(p_np) < p_np.size  # a partial contact: clipping, penetration and the sets exercised
    assert np.array_equal(p_np > 0, p_strict > 0)
    assert level_strict == pytest.approx(level_np, rel=1e-9, abs=1e-12)
    assert np.abs(p_strict - p_np).max() <= 1e-7 * p_np.max()


@pytest.mark.parametrize("solver", [BEMHalfSpace(), BEMHalfSpace(stop="tolerance"), BEMHalfSpaceFree()], ids=["certified", "tolerance", "free"])
def test_a_whole_sweep_of_the_plugins_on_strict_arrays(monkeypatch, solver):
    """The plugins' solve, its device copies and its results, with the namespace of
    ``device`` replaced by the strict one: the same contact counts, forces and
    indentations as on numpy."""
    profile = Profile(surface(32, 5), 1.0)
    slopes = np.ones_like(profile.heights)
    loads = np.geomspace(0.5, 30.0, 4)
    expected = solver.solve(profile, loads, "force", slopes)
    for module in (bem, bem_free):
        monkeypatch.setattr(module, "namespace", lambda device: xp)
    got = solver.solve(profile, loads, "force", slopes)
    assert np.array_equal(got.contact_count, expected.contact_count)
    assert np.allclose(got.indentation, expected.indentation, rtol=1e-6)
    assert np.array_equal(got.force, expected.force)


def test_host_and_device_copies():
    a = np.arange(6.0)
    assert arrays.on_device(arrays.namespace("cpu"), a) is a  # no copy on the CPU
    assert arrays.host(a) is a
    back = arrays.host(arrays.on_device(xp, a))
    assert isinstance(back, np.ndarray) and np.array_equal(back, a)


def _cupy_importable() -> bool:
    try:
        import cupy  # noqa: F401
    except ImportError:
        return False
    return True


@pytest.mark.skipif(_cupy_importable(), reason="CuPy is installed: the refusal of a missing one cannot be seen")
def test_device_gpu_without_cupy_is_refused_naming_the_parameter_and_what_is_missing(tmp_path, cli):
    with pytest.raises(ValueError, match=r"device 'gpu' needs CuPy, which is not installed \(pip install cupy"):
        arrays.namespace("gpu")
    with pytest.raises(ValueError, match="device") as refused:
        BEMHalfSpace(device="gpu")
    assert "CuPy" in str(refused.value)
    preset = tmp_path / "gpu.yaml"
    preset.write_text(
        "name: g\nseed: 1\nrealizations: 1\nspectrum: {name: power-law-2d, params: {hurst: 0.8, points: 32}}\n"
        "solver: {name: bem-halfspace-free, params: {device: gpu}}\nslope: {name: forward-difference}\n"
        "loading: {control: force, start: 1.0, stop: 2.0, steps: 2, spacing: log}\n"
    )
    done = cli("validate", preset)
    assert done.returncode != 0
    assert "solver.params.device" in done.stderr + done.stdout and "needs CuPy" in done.stderr + done.stdout
    assert "Traceback" not in done.stderr


def test_a_device_that_is_neither_is_refused_with_the_choices():
    with pytest.raises(ValueError, match="device must be one of cpu, gpu. Got 'tpu' instead"):
        arrays.namespace("tpu")
    with pytest.raises(ValueError, match="'cpu' or 'gpu'"):
        BEMHalfSpace(device="tpu")


def test_fft_workers_give_the_one_thread_answer():
    """scipy.fft on two threads against numpy's FFTs on one: the same displacement to
    rounding, and a sweep with the same contact counts."""
    shape = (64, 48)
    field = np.random.default_rng(2).normal(size=shape)
    one = PeriodicHalfSpace(shape).displacement(field, np.empty(shape))
    two = PeriodicHalfSpace(shape, workers=2).displacement(field, np.empty(shape))
    assert np.abs(two - one).max() <= 1e-13 * np.abs(one).max()
    profile = Profile(surface(32, 7), 1.0)
    slopes = np.ones_like(profile.heights)
    loads = np.geomspace(0.5, 30.0, 4)
    for cls in (BEMHalfSpace, BEMHalfSpaceFree):
        a = cls().solve(profile, loads, "force", slopes)
        b = cls(fft_workers=2).solve(profile, loads, "force", slopes)
        assert np.array_equal(a.contact_count, b.contact_count)
        assert np.allclose(a.indentation, b.indentation, rtol=1e-6)

"""Executors: the same numbers whatever runs them, chunks sized by cost, a
worker that dies costs only a retry. Dask tests share one 2-worker LocalCluster
on loopback (started once: it costs seconds) and come last, since its threads
switch the process pool to forkserver."""

from __future__ import annotations

import os
import sys

import numpy as np
import pytest

from frictionlab import engine
from frictionlab.errors import FrictionlabError
from frictionlab.executors import DASK_MISSING, make_executor, plan_chunks
from frictionlab.plugin import PluginParams
from frictionlab.preset import Scene
from frictionlab_spectra.power_law import PowerLaw

from .conftest import loopback_cluster


def same_numbers(one, two):
    assert one.per_realization.keys() == two.per_realization.keys()
    for key in one.per_realization:
        np.testing.assert_array_equal(one.per_realization[key], two.per_realization[key], err_msg=key)
    np.testing.assert_array_equal(one.xi, two.xi)
    np.testing.assert_array_equal(one.f, two.f)
    assert one.fit == two.fit


class CrashingPowerLaw(PowerLaw):
    """The power-law line, but a worker process (never the test's own) that
    generates one dies on the spot: once per run (the first to create ``flag``),
    or every time (``always``)."""

    name = "crashing-power-law"

    class Params(PowerLaw.Params):
        flag: str
        parent: int
        always: bool = False

    def generate(self, rng):
        p = self.params
        if os.getpid() != p.parent:
            if p.always:
                os._exit(3)
            try:
                os.close(os.open(p.flag, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
            except FileExistsError:
                pass
            else:
                os._exit(3)  # a killed worker: no exception, no cleanup
        return super().generate(rng)


def crashing(scene: Scene, flag, always: bool = False) -> Scene:
    params = scene.spectrum.params.model_dump()
    spectrum = CrashingPowerLaw(**params, flag=str(flag), parent=os.getpid(), always=always)
    return Scene(preset=scene.preset, spectrum=spectrum, solver=scene.solver, slope=scene.slope)


@pytest.fixture(scope="module")
def scene_24(registry):
    from frictionlab.preset import build_scene

    from .conftest import SMALL_PRESET, merge

    return build_scene(merge(SMALL_PRESET, {"realizations": 24}), registry=registry)


@pytest.fixture(scope="module")
def serial_24(scene_24):
    return engine.run(scene_24, workers=1, executor="serial")


# ------------------------------------------------------------------ chunking


def test_chunks_cover_every_index_once_in_order():
    indices = list(range(3, 1000, 3))
    for seconds in (0.0, 1e-4, 0.01, 5.0):
        chunks = plan_chunks(indices, workers=2, seconds_each=seconds)
        assert [i for c in chunks for i in c] == indices


def test_chunks_are_sized_by_cost_and_keep_every_worker_busy():
    indices = list(range(10_000))
    # 1 ms each: 0.5 s is 500 realizations, and 2 workers x 4 chunks leave room for that
    assert {len(c) for c in plan_chunks(indices, workers=2, seconds_each=1e-3)[:-1]} == {500}
    # 0.1 s each: 5 per chunk
    assert len(plan_chunks(indices, workers=2, seconds_each=0.1)[0]) == 5
    # cheap realizations, few of them: at least 4 chunks per worker
    assert len(plan_chunks(list(range(80)), workers=2, seconds_each=1e-6)) == 8
    # very slow ones: one per chunk
    assert len(plan_chunks(list(range(7)), workers=2, seconds_each=30.0)) == 7


# ------------------------------------------------------------------ same numbers


@pytest.mark.parametrize("executor, workers", [("processes", 1), ("processes", 2)])
def test_process_pool_gives_the_serial_numbers_bitwise(scene_24, serial_24, executor, workers):
    outcome = engine.run(scene_24, workers=workers, executor=executor)
    assert outcome.status == "completed" and outcome.done == 24
    assert outcome.extra["executor"] == "processes"
    same_numbers(serial_24, outcome)


def test_a_worker_killed_mid_chunk_is_retried_with_the_same_numbers(scene_24, serial_24, tmp_path):
    flag = tmp_path / "crashed"
    outcome = engine.run(crashing(scene_24, flag), workers=2, executor="processes")
    assert flag.exists(), "no worker died: the test did not test anything"
    assert outcome.status == "completed" and outcome.done == 24
    same_numbers(serial_24, outcome)


def test_a_worker_that_always_dies_fails_the_run_after_bounded_retries(scene_24, tmp_path):
    outcome = engine.run(crashing(scene_24, tmp_path / "x", always=True), workers=2, executor="processes", retries=1)
    assert outcome.status == "failed"
    assert "a worker process died 2 times" in outcome.error
    assert outcome.done == 1  # only the realization measured in the main process


def test_unknown_executor_and_scheduler_without_dask_are_refused():
    with pytest.raises(FrictionlabError, match="executor must be one of serial, processes, dask. Got 'mpi'"):
        make_executor("mpi", 2)
    with pytest.raises(FrictionlabError, match="needs the dask executor"):
        make_executor("processes", 2, scheduler="tcp://127.0.0.1:1")


def test_missing_dask_names_the_extra_to_install(monkeypatch, scene_24):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    with pytest.raises(FrictionlabError) as caught:
        engine.run(scene_24, executor="dask")
    assert str(caught.value) == DASK_MISSING
    assert 'pip install "frictionlab[dask]"' in DASK_MISSING


# ------------------------------------------------------------------ dask (last)

try:
    import distributed
except ImportError:  # the optional extra; installed with frictionlab[test] and in CI
    distributed = None
needs_dask = pytest.mark.skipif(distributed is None, reason='dask is not installed: pip install "frictionlab[dask]"')


@pytest.fixture(scope="module")
def dask_scheduler():
    with loopback_cluster(2) as cluster:
        yield cluster.scheduler_address


@needs_dask
def test_dask_on_an_existing_two_worker_cluster_gives_the_serial_numbers(scene_24, serial_24, dask_scheduler):
    outcome = engine.run(scene_24, executor="dask", scheduler=dask_scheduler)
    assert outcome.status == "completed" and outcome.workers == 2
    same_numbers(serial_24, outcome)


@needs_dask
def test_dask_killed_worker_is_rescheduled_with_the_same_numbers(scene_24, serial_24, dask_scheduler, tmp_path):
    flag = tmp_path / "crashed"
    outcome = engine.run(crashing(scene_24, flag), executor="dask", scheduler=dask_scheduler)
    assert flag.exists(), "no worker died: the test did not test anything"
    assert outcome.status == "completed"
    same_numbers(serial_24, outcome)


@needs_dask
def test_dask_own_local_cluster_of_one_worker_gives_the_serial_numbers(scene_24, serial_24):
    outcome = engine.run(scene_24, workers=1, executor="dask")
    assert outcome.status == "completed" and outcome.workers == 1
    same_numbers(serial_24, outcome)


@needs_dask
def test_dask_memory_limits_foresee_those_of_the_local_cluster(dask_scheduler):
    from frictionlab.executors import dask_memory_limits

    # the fixture's cluster is built like the executor's own LocalCluster: what
    # the memory check expects without starting one is what Dask then gives
    reported, usable = dask_memory_limits(dask_scheduler)
    foreseen, _ = dask_memory_limits(None, 2)
    assert len(reported) == 2 and all(address.startswith("tcp://127.0.0.1:") for address in reported)
    assert sorted(foreseen.values()) == sorted(reported.values())
    assert all(limit > 0 for limit in reported.values())
    assert 0 < usable <= 1

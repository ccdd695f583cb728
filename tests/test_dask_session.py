"""Dask, a command at a time: a sweep on Dask starts one LocalCluster (a real one, on
loopback) for all its points, closes it at the end, and gives the numbers of serial runs;
a cancelled run's running tasks stop within their solve."""

import pickle
import time

import numpy as np
import pytest

from frictionlab.compute import engine
from frictionlab import hookimpl
from frictionlab.compute.dask_session import one_dask_cluster
from frictionlab.compute.executors import _packed_chunk
from frictionlab.compute.realization import compute_realization
from frictionlab.options import RunOptions
from frictionlab.preset import build_scene
from frictionlab.runs.sweep import plan_sweep, run_sweep

from .conftest import loopback_cluster, merge
from .test_load_progress import LONG_LOADS
from .test_sweep import sweep_preset

try:
    import distributed
except ImportError:  # the optional extra; installed with frictionlab[test] and in CI
    distributed = None
needs_dask = pytest.mark.skipif(distributed is None, reason='dask is not installed: pip install "frictionlab[dask]"')


@pytest.fixture
def clusters_started(monkeypatch):
    """Every LocalCluster started from now on (the executor's own, on 127.0.0.1)."""
    started = []

    class Counted(distributed.LocalCluster):
        def __init__(self, *args, **kwargs):
            super().__init__(*args, **kwargs)
            started.append(self)

    monkeypatch.setattr(distributed, "LocalCluster", Counted)
    return started


@pytest.mark.long
@needs_dask
def test_a_sweep_on_dask_starts_one_cluster_for_all_its_points(tmp_path, registry, clusters_started):
    sweep = plan_sweep(sweep_preset({"spectrum.params.hurst": {"values": [0.5, 0.7, 0.9]}}), registry=registry)
    outcome = run_sweep(sweep, tmp_path / "out", RunOptions(workers=2, executor="dask"), plot=False)
    assert outcome.status == "completed" and len(outcome.results) == 3
    assert len(clusters_started) == 1
    assert clusters_started[0].status.name == "closed"  # closed when the sweep ended
    for result in outcome.results:
        serial = engine.run(result.point.scene, RunOptions(workers=1))
        assert np.array_equal(np.load(result.folder / "realizations.npz")["xi"], serial.per_realization["xi"])


@pytest.mark.long
@needs_dask
def test_runs_outside_a_session_start_a_cluster_each_and_inside_one_share_it(make_scene, clusters_started):
    scene = make_scene({"realizations": 4})
    options = RunOptions(workers=2, executor="dask")
    engine.run(scene, options)
    engine.run(scene, options)
    assert len(clusters_started) == 2
    with one_dask_cluster(options):
        with one_dask_cluster(options):  # a command within a command: the outer one's
            engine.run(scene, options)
        engine.run(scene, options)
        assert len(clusters_started) == 3 and clusters_started[2].status.name == "running"
    assert clusters_started[2].status.name == "closed"
    with one_dask_cluster(options):  # a command that runs nothing on Dask starts nothing
        engine.run(scene, RunOptions(workers=1))
    assert len(clusters_started) == 3


@pytest.mark.long
@needs_dask
def test_a_task_stops_within_its_solve_once_the_run_s_stop_event_is_set(registry):
    scene = build_scene(LONG_LOADS, registry=registry)  # about a second a realization
    with loopback_cluster(1) as cluster, distributed.Client(cluster) as client:
        task = client.submit(_packed_chunk, scene, [1, 2], "frictionlab-test-stop", pure=False)
        while not any(client.processing().values()):  # until it runs
            time.sleep(0.05)
        time.sleep(0.3)
        distributed.Event("frictionlab-test-stop", client=client).set()
        # the chunk ends with what finished, realization 1 abandoned within its solve
        assert pickle.loads(task.result(timeout=60)) == []
        whole = client.submit(_packed_chunk, scene, [1], "frictionlab-test-other", pure=False)
        assert [r.index for r in pickle.loads(whole.result(timeout=60))] == [1]


@pytest.mark.long
@needs_dask
def test_a_dask_run_cancelled_while_it_waits_returns_at_once_with_what_finished(registry):
    import threading

    scene = build_scene(merge(LONG_LOADS, {"realizations": 6, "spectrum": {"params": {"points": 512}}}), registry=registry)
    cancel, cancelled_at = threading.Event(), []  # a realization lasts seconds

    def cancel_now():
        cancelled_at.append(time.monotonic())
        cancel.set()

    class CancelSoonAfterTheFirst:  # the first runs in this process; then the run waits for Dask's tasks
        @hookimpl
        def realization_done(self, run, result, done, total):
            if done == 1:
                threading.Timer(0.3, cancel_now).start()

    with loopback_cluster(2) as cluster:
        options = RunOptions(executor="dask", scheduler=cluster.scheduler_address)
        with one_dask_cluster(options) as session:
            session.connect()  # connected before: the tasks are submitted at once, and run when the cancel comes
            outcome = engine.run(scene, options, cancel=cancel, listeners=[CancelSoonAfterTheFirst()])
            returned = time.monotonic()
    assert outcome.status == "cancelled" and 1 <= outcome.indices.size < 6, (outcome.status, outcome.indices)
    # the workers were within their solves: the run did not wait for one to finish
    assert returned - cancelled_at[0] < 0.5 * outcome.compute_seconds / outcome.indices.size
    alone = [compute_realization(scene, int(i)).xi for i in outcome.indices]  # the same, solved in this process
    assert np.array_equal(outcome.per_realization["xi"], np.vstack(alone))

"""Executors: the same numbers whatever runs them, chunks sized by cost, a
worker that dies costs only a retry. Dask tests share one 2-worker LocalCluster
on loopback (started once: it costs seconds; they are marked long) and come last, since its threads
switch the process pool to forkserver."""

from __future__ import annotations

import logging
import os
import subprocess
import sys

import numpy as np
import pytest

from frictionlab.compute import engine
from frictionlab.errors import FrictionlabError
from frictionlab.compute import executors
from frictionlab.compute.executors import DASK_MISSING, ProcessExecutor, SerialExecutor, plan_chunks, sized_executor
from frictionlab.preset import Scene
from frictionlab.options import RunOptions

from .conftest import loopback_cluster
from .faults import CrashingPowerLaw, with_spectrum


def same_numbers(one, two):
    assert one.per_realization.keys() == two.per_realization.keys()
    for key in one.per_realization:
        np.testing.assert_array_equal(one.per_realization[key], two.per_realization[key], err_msg=key)
    np.testing.assert_array_equal(one.xi, two.xi)
    np.testing.assert_array_equal(one.f, two.f)
    assert one.fit == two.fit


def crashing(scene: Scene, flag, always: bool = False) -> Scene:
    return with_spectrum(scene, CrashingPowerLaw, flag=str(flag), parent=os.getpid(), always=always)


@pytest.fixture(scope="module")
def scene_24(registry):
    from frictionlab.preset import build_scene

    from .conftest import SMALL_PRESET, merge

    return build_scene(merge(SMALL_PRESET, {"realizations": 24}), registry=registry)


@pytest.fixture(scope="module")
def serial_24(scene_24):
    return engine.run(scene_24, RunOptions(workers=1, executor="serial"))


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


def test_short_runs_get_fewer_longer_chunks_where_tasks_cost_more():
    fig2 = list(range(300))  # the Fig. 2 scene: 300 realizations of about 1.6 ms
    # on 2 Dask workers (5 ms a task) 8 chunks of 60 ms would lose 6 %: one chunk per worker
    assert [len(c) for c in plan_chunks(fig2, workers=2, seconds_each=1.6e-3, overhead=5e-3)] == [150, 150]
    # on a process pool (0.5 ms a task) 4 per worker still cost under 1 %
    assert len(plan_chunks(fig2, workers=2, seconds_each=1.6e-3, overhead=0.5e-3)) == 8
    for each in (1e-5, 1e-4, 1e-3, 1e-2, 1.0, 30.0):
        for count in (7, 300, 5000):
            chunks = plan_chunks(list(range(count)), workers=2, seconds_each=each, overhead=5e-3)
            assert [i for c in chunks for i in c] == list(range(count))
            # a task lasts at least 50 overheads, unless the run is too short for two of that length
            assert min(len(c) for c in chunks[:-1] or chunks) * each >= 50 * 5e-3 or len(chunks) <= 2


# ------------------------------------------------------------------ executor sized to the work


def test_the_default_pool_is_started_only_when_the_work_repays_its_start():
    pool, default = ProcessExecutor(2), RunOptions(workers=2)
    start = executors.POOL_START_SECONDS
    # shared by 2 workers, the work saves half of itself: twice the start is the threshold
    assert isinstance(sized_executor(pool, default, 100, 3.9 * start / 100), SerialExecutor)
    assert sized_executor(pool, default, 100, 4.1 * start / 100) is pool
    assert isinstance(sized_executor(pool, default, 0, 10.0), SerialExecutor)  # one realization: nothing left
    four = ProcessExecutor(4)  # saves three quarters of the work
    assert sized_executor(four, default, 100, 2.7 * start / 100) is four
    assert isinstance(sized_executor(four, default, 100, 2.6 * start / 100), SerialExecutor)
    named = RunOptions(workers=2, executor="processes")  # asked for by name: kept, whatever the work
    assert sized_executor(pool, named, 1, 1e-9) is pool


def test_a_run_too_short_for_a_pool_runs_here_with_the_numbers_of_any_worker_count(scene_24, serial_24, monkeypatch):
    # 24 tiny lines: far less than a pool's start, here a minute, so that on a loaded machine a
    # slow first realization (over the 9 ms that repay the real 0.05 s) cannot tip the choice
    monkeypatch.setattr(executors, "POOL_START_SECONDS", 60.0)
    short = engine.run(scene_24, RunOptions(workers=2))
    assert (short.extra["executor"], short.workers) == ("serial", 1)
    same_numbers(serial_24, short)
    monkeypatch.setattr(executors, "POOL_START_SECONDS", 0.0)  # any work repays a free start
    pooled = engine.run(scene_24, RunOptions(workers=2))
    assert (pooled.extra["executor"], pooled.workers) == ("processes", 2)
    same_numbers(serial_24, pooled)


# ------------------------------------------------------------------ same numbers


@pytest.mark.parametrize("executor, workers", [("processes", 1), ("processes", 2)])
def test_process_pool_gives_the_serial_numbers_bitwise(scene_24, serial_24, executor, workers):
    outcome = engine.run(scene_24, RunOptions(workers=workers, executor=executor))
    assert outcome.status == "completed" and outcome.done == 24
    assert outcome.extra["executor"] == "processes"
    same_numbers(serial_24, outcome)


def test_a_worker_killed_mid_chunk_is_retried_with_the_same_numbers(scene_24, serial_24, tmp_path):
    flag = tmp_path / "crashed"
    outcome = engine.run(crashing(scene_24, flag), RunOptions(workers=2, executor="processes"))
    assert flag.exists(), "no worker died: the test did not test anything"
    assert outcome.status == "completed" and outcome.done == 24
    same_numbers(serial_24, outcome)


def test_a_worker_that_always_dies_fails_the_run_after_bounded_retries(scene_24, tmp_path):
    outcome = engine.run(crashing(scene_24, tmp_path / "x", always=True), RunOptions(workers=2, executor="processes", retries=1))
    assert outcome.status == "failed"
    assert "a worker process died 2 times" in outcome.error
    assert outcome.done == 1  # only the realization measured in the main process


UNGUARDED = """
import threading, time
import frictionlab

threading.Thread(target=time.sleep, args=(60,), daemon=True).start()  # as a notebook's or a GUI's thread
result = frictionlab.run("quickstart", realizations=6, workers=2, executor="processes", progress=False, plot=False)
print(result.status, result.error)
"""


@pytest.mark.parametrize("guarded", [False, True])
def test_a_script_whose_run_is_not_under_a_main_guard_is_told_to_put_it_there(tmp_path, guarded):
    """A thread running beside the run has its workers started by forkserver, which imports the
    script again: unguarded, each ran the run again and died starting a pool, and the run failed
    on "a worker process died 3 times (exit code 1)", saying nothing of the script."""
    source = UNGUARDED.replace("result =", 'if __name__ == "__main__":\n    result =').replace(
        "\nprint", "\n    print") if guarded else UNGUARDED  # fmt: skip
    (tmp_path / "script.py").write_text(source, encoding="utf-8")
    done = subprocess.run([sys.executable, str(tmp_path / "script.py")], capture_output=True, text=True, timeout=120,
                          cwd=tmp_path)  # fmt: skip
    last = done.stdout.strip().splitlines()[-1]
    if guarded:
        assert last == "completed None", done.stderr[-2000:]
    else:
        assert last.startswith("failed a worker process died "), done.stderr[-2000:]
        assert last.endswith(f"the workers start by importing {tmp_path / 'script.py'} again (a thread of its own runs "
                             "beside the run, so they are not forked) and run what its top level does: put the run "
                             'under `if __name__ == "__main__":`')  # fmt: skip


def test_unknown_executor_and_scheduler_without_dask_are_refused():
    with pytest.raises(FrictionlabError, match="executor must be one of serial, processes, dask. Got 'mpi'"):
        RunOptions(executor="mpi", workers=2)
    with pytest.raises(FrictionlabError, match="needs the dask executor"):
        RunOptions(executor="processes", workers=2, scheduler="tcp://127.0.0.1:1")



@pytest.mark.parametrize("options", [{"workers": "8" * 10000}, {"executor": "x" * 10000},
                                     {"executor": "serial", "scheduler": "tcp://" + "h" * 10000 + ":1"},
                                     {"retries": [1] * 10000}])  # fmt: skip
def test_a_refused_run_option_is_quoted_cut_short(options):
    """frictionlab.run(workers='888...') (10,000 characters) was refused with the whole value
    quoted, 10 kB of message; executor, scheduler and retries the same."""
    with pytest.raises(FrictionlabError) as refused:
        RunOptions(**options)
    assert len(str(refused.value)) < 300
    assert next(iter(options)) in str(refused.value)

def test_missing_dask_names_the_extra_to_install(monkeypatch, scene_24):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed -> ImportError
    with pytest.raises(FrictionlabError) as caught:
        engine.run(scene_24, RunOptions(executor="dask"))
    assert str(caught.value) == DASK_MISSING
    assert 'pip install "frictionlab[dask]"' in DASK_MISSING


# ------------------------------------------------------------------ dask (last)

try:
    import distributed
except ImportError:  # the optional extra; installed with frictionlab[test] and in CI
    distributed = None
needs_dask = pytest.mark.skipif(distributed is None, reason='dask is not installed: pip install "frictionlab[dask]"')


@pytest.fixture(scope="module")
def two_worker_cluster():
    with loopback_cluster(2) as cluster:
        yield cluster


@pytest.fixture
def dask_scheduler(two_worker_cluster):
    """The module's cluster with both its workers: a test that kills one leaves it to
    its nanny, which restarts it in the background; the next test waits for it
    (reading the cluster at once would see one worker, now and then)."""
    with distributed.Client(two_worker_cluster.scheduler_address, timeout="30s") as client:
        client.wait_for_workers(2, timeout=120)
    return two_worker_cluster.scheduler_address


@pytest.mark.long
@needs_dask
def test_dask_on_an_existing_two_worker_cluster_gives_the_serial_numbers(scene_24, serial_24, dask_scheduler):
    outcome = engine.run(scene_24, RunOptions(executor="dask", scheduler=dask_scheduler))
    assert outcome.status == "completed" and outcome.workers == 2
    same_numbers(serial_24, outcome)


@pytest.mark.long
@needs_dask
def test_a_scene_too_large_to_travel_in_each_task_is_broadcast_with_the_same_numbers(
    monkeypatch, scene_24, serial_24, dask_scheduler
):
    from frictionlab.compute import executors

    scattered = []
    real_scatter = distributed.Client.scatter

    def counted(self, *args, **kwargs):
        scattered.append(args[0])
        return real_scatter(self, *args, **kwargs)

    monkeypatch.setattr(distributed.Client, "scatter", counted)
    engine.run(scene_24, RunOptions(executor="dask", scheduler=dask_scheduler))
    assert scattered == []  # a preset's scene is small: it goes with each task
    monkeypatch.setattr(executors, "INLINE_SCENE_BYTES", 0)
    outcome = engine.run(scene_24, RunOptions(executor="dask", scheduler=dask_scheduler))
    assert len(scattered) == 1 and scattered[0] is scene_24
    same_numbers(serial_24, outcome)


def test_the_size_of_a_scene_s_pickle_is_counted_without_copying_a_large_one():
    import pickle
    import tracemalloc

    from frictionlab.compute.executors import _pickles_within

    small = {"hurst": 0.8, "points": 1024}
    size = len(pickle.dumps(small, protocol=pickle.HIGHEST_PROTOCOL))
    assert _pickles_within(small, size) and not _pickles_within(small, size - 1)
    heights = np.zeros(20_000_000)  # 160 MB
    tracemalloc.start()
    try:
        assert not _pickles_within(heights, 64 * 1024)
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    assert peak < 1_000_000  # given up at the limit, nothing copied


def test_results_come_straight_from_the_workers_only_of_a_scheduler_on_this_machine():
    from frictionlab.compute.dask_security import _on_this_machine

    assert _on_this_machine("tcp://127.0.0.1:8786") and _on_this_machine("tls://localhost:8786")
    assert _on_this_machine("tcp://[::1]:8786")
    assert not _on_this_machine("tls://10.0.0.5:8786") and not _on_this_machine("tcp://cluster.example.org:8786")


@pytest.mark.long
@needs_dask
@pytest.mark.parametrize("size", [1, 5, 23])
def test_numbers_do_not_depend_on_the_chunk_size(monkeypatch, scene_24, serial_24, dask_scheduler, size):
    def fixed(indices, *args, **kwargs):
        indices = list(indices)
        return [indices[i : i + size] for i in range(0, len(indices), size)]

    monkeypatch.setattr(engine, "plan_chunks", fixed)
    for options in (RunOptions(executor="dask", scheduler=dask_scheduler), RunOptions(workers=2, executor="processes")):
        outcome = engine.run(scene_24, options)
        assert outcome.status == "completed"
        same_numbers(serial_24, outcome)


@pytest.mark.long
@needs_dask
def test_dask_killed_worker_is_rescheduled_with_the_same_numbers(scene_24, serial_24, dask_scheduler, tmp_path):
    flag = tmp_path / "crashed"
    outcome = engine.run(crashing(scene_24, flag), RunOptions(executor="dask", scheduler=dask_scheduler))
    assert flag.exists(), "no worker died: the test did not test anything"
    assert outcome.status == "completed"
    same_numbers(serial_24, outcome)


@pytest.mark.long
@needs_dask
def test_dask_own_local_cluster_of_one_worker_gives_the_serial_numbers(scene_24, serial_24):
    outcome = engine.run(scene_24, RunOptions(workers=1, executor="dask"))
    assert outcome.status == "completed" and outcome.workers == 1
    same_numbers(serial_24, outcome)


@pytest.mark.long
@needs_dask
def test_the_own_cluster_s_workers_keep_the_adaptive_malloc_thresholds_and_log_no_errors():
    """Dask's default MALLOC_TRIM_THRESHOLD_ made every large array a fresh mapping in its
    workers (the half-space solver 1.5x slower): the executor's own cluster unsets it. In a
    fresh process: a nanny started here before (another test's cluster) leaves Dask's value
    in this process's environment, which a worker inherits.
    Its workers log only what is critical: on a loaded machine a worker's heartbeat, racing
    the cluster's close at the end of a run, printed an ERROR with three tracebacks under a
    run that had finished (a task's failure is said by the run)."""
    script = (
        "from frictionlab.compute.dask_security import start_local_cluster\n"
        "import logging, os\n"
        "client, cluster = start_local_cluster(1)\n"
        "print(list(client.run(os.environ.get, 'MALLOC_TRIM_THRESHOLD_').values()))\n"
        "print(*client.run(lambda: logging.getLogger('distributed').level).values())\n"
        "client.close(); cluster.close()\n"
    )
    env = {k: v for k, v in os.environ.items() if k != "MALLOC_TRIM_THRESHOLD_"}
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, timeout=120)
    assert done.returncode == 0, done.stderr
    thresholds, levels = done.stdout.strip().splitlines()[-2:]
    assert thresholds == "[None]"
    assert levels.split() == [str(logging.CRITICAL)]


@pytest.mark.long
@needs_dask
def test_dask_memory_limits_foresee_those_of_the_local_cluster(dask_scheduler):
    from frictionlab.compute.executors import dask_memory_limits

    # the fixture's cluster is built like the executor's own LocalCluster: what
    # the memory check expects without starting one is what Dask then gives
    reported, usable = dask_memory_limits(dask_scheduler)
    foreseen, _ = dask_memory_limits(None, 2)
    assert len(reported) == 2 and all(address.startswith("tcp://127.0.0.1:") for address in reported)
    assert sorted(foreseen.values()) == sorted(reported.values())
    assert all(limit > 0 for limit in reported.values())
    assert 0 < usable <= 1


# ------------------------------------------------------------------ dask security (last: they start clusters)


def _http_status(address: str, path: str) -> int:
    import urllib.error
    import urllib.request

    try:
        return urllib.request.urlopen(f"{address}{path}", timeout=5).status
    except urllib.error.HTTPError as exc:
        return exc.code


def _http_address(cluster) -> str:
    port = next(iter(cluster.scheduler.http_server._sockets.values())).getsockname()[1]
    return f"http://127.0.0.1:{port}"


INTRUDER = """
import sys
from distributed import Client, Security
address, how = sys.argv[1:]
where = address.replace("tls://", "tcp://") if how == "plain tcp" else address
security = Security.temporary() if how == "its own credentials" else None
try:
    Client(where, timeout="3s", security=security).close()
    print("got in")
except Exception as exc:
    print("refused", type(exc).__name__)
"""


@needs_dask
@pytest.mark.long
def test_the_executors_own_cluster_admits_only_this_runs_credentials():
    import subprocess

    from frictionlab.compute.executors import DaskExecutor

    client, cluster = DaskExecutor(1)._connect()  # what `--executor dask` without --scheduler starts
    try:
        address = cluster.scheduler_address
        assert address.startswith("tls://127.0.0.1:")
        assert client.submit(sum, [1, 2]).result() == 3  # the run's own client gets in
        # another local process (another user's, as far as the cluster can tell) tries to connect:
        # without credentials, with credentials of its own, in plain TCP (one process each:
        # a failed distributed.Client can leave its process unable to try again)
        for how in ("no credentials", "its own credentials", "plain tcp"):
            intruder = subprocess.run([sys.executable, "-c", INTRUDER, address, how], capture_output=True, text=True,
                                      timeout=60)  # fmt: skip
            assert intruder.stdout.startswith("refused "), (how, intruder.stdout, intruder.stderr[-2000:])
        assert _http_status(_http_address(cluster), "/health") == 404  # no dashboard, no routes at all
    finally:
        client.close()
        cluster.close()


@pytest.mark.long
@needs_dask
def test_the_dashboard_is_served_on_loopback_only_when_asked(capsys):
    from frictionlab.compute.dask_security import start_local_cluster

    client, cluster = start_local_cluster(1, dashboard=True)
    try:
        http = _http_address(cluster)
        assert http.startswith("http://127.0.0.1:") and _http_status(http, "/health") == 200
        assert _http_status(http, "/status") == 200  # the dashboard itself (bokeh's pages), not only the server
        assert "Dask dashboard: http://127.0.0.1:" in capsys.readouterr().err
    finally:
        client.close()
        cluster.close()


def test_scheduler_addresses_neither_loopback_nor_tls_get_a_warning():
    import warnings

    from frictionlab.compute.dask_security import check_address

    with pytest.warns(UserWarning, match="reached without TLS: anyone who can reach that address can run code"):
        check_address("tcp://10.1.2.3:8786")
    with warnings.catch_warnings(record=True) as again:  # checked again on connecting: said once
        warnings.simplefilter("always")
        check_address("tcp://10.1.2.3:8786")
    assert again == []
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        for quiet in ("tls://10.1.2.3:8786", "tcp://127.0.0.1:8786", "localhost:8786", "tcp://[::1]:8786"):
            check_address(quiet)
    for wrong in ("ftp://host:1", "garbage", "tcp://host", "tcp://host:port", "tcp://host:99999"):
        with pytest.raises(FrictionlabError, match="--scheduler must be an address like"):
            check_address(wrong)


@pytest.mark.long
@needs_dask
def test_a_tls_scheduler_is_reached_with_certificate_files(tmp_path, scene_24, serial_24):
    import json
    import logging
    import subprocess

    import yaml
    from distributed import LocalCluster, Security

    from .conftest import ROOT, SMALL_PRESET, merge

    security = Security.temporary()
    files = {}
    for name, pem in (("ca", security.tls_ca_file), ("cert", security.tls_client_cert), ("key", security.tls_client_key)):
        files[name] = tmp_path / f"{name}.pem"
        files[name].write_text(pem)
    preset = tmp_path / "p.yaml"
    preset.write_text(yaml.safe_dump(merge(SMALL_PRESET, {"realizations": 24, "output": {"plot": False}})))
    with LocalCluster(n_workers=2, threads_per_worker=1, host="127.0.0.1", protocol="tls://", security=security,
                      dashboard_address=None, scheduler_kwargs={"dashboard_address": "127.0.0.1:0"},  # no fixed port
                      silence_logs=logging.ERROR) as cluster:  # fmt: skip
        command = [sys.executable, "-m", "frictionlab", "run", str(preset), "--executor", "dask",
                   "--scheduler", cluster.scheduler_address, "--quiet"]  # fmt: skip
        bare = subprocess.run([*command, "--out", str(tmp_path / "bare")], capture_output=True, text=True, cwd=ROOT,
                              timeout=120)  # fmt: skip
        assert bare.returncode == 2 and "a tls:// scheduler needs TLS certificates" in bare.stderr, bare.stderr
        tls = ["--tls-ca-file", str(files["ca"]), "--tls-cert", str(files["cert"]), "--tls-key", str(files["key"])]
        done = subprocess.run([*command, *tls, "--out", str(tmp_path / "o"), "--json"], capture_output=True,
                              text=True, cwd=ROOT, timeout=120)  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "warning" not in done.stderr
    summary = json.loads(done.stdout)
    assert summary["executor"] == "dask" and summary["workers"] == 2
    assert (summary["fit"]["a"], summary["fit"]["b"]) == (serial_24.fit.a, serial_24.fit.b)


@pytest.mark.long
@needs_dask
@pytest.mark.parametrize("server", ["http", "silent"])
def test_an_address_that_answers_but_not_as_a_scheduler_is_refused_within_the_connect_timeout(server, monkeypatch):
    """An HTTP server (the dashboard's port, say), or one that accepts and never answers,
    is refused with a message within the connect timeout: a Client would wait for minutes."""
    import http.server
    import socket
    import threading
    import time

    from frictionlab.compute import dask_security
    from frictionlab.compute.dask_security import connect_scheduler
    from frictionlab.errors import RunError

    CONNECT_SECONDS = 2  # the timeout shortened from its 10 s: the test waits it out
    monkeypatch.setattr(dask_security, "CONNECT_SECONDS", CONNECT_SECONDS)

    class Quiet(http.server.SimpleHTTPRequestHandler):
        def log_message(self, *args):
            pass

    if server == "http":
        listener = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Quiet)
        threading.Thread(target=listener.serve_forever, daemon=True).start()
        port = listener.server_address[1]
    else:
        listener = socket.socket()
        listener.bind(("127.0.0.1", 0))
        listener.listen()
        port = listener.getsockname()[1]
    started = time.monotonic()
    try:
        with pytest.raises(RunError, match=rf"did not answer as a Dask scheduler within {CONNECT_SECONDS} s"):
            connect_scheduler(f"tcp://127.0.0.1:{port}")
    finally:
        (listener.shutdown if server == "http" else listener.close)()
    assert time.monotonic() - started < 3 * CONNECT_SECONDS  # a bound against a hang (it was minutes), not a speed test


@needs_dask
def test_a_scheduler_address_where_nothing_listens_is_said_so():
    """A port where nothing listens (the connection refused) was said, after Dask's connect had
    retried it for the whole timeout, to 'not answer as a Dask scheduler (is it another service,
    such as the dashboard's HTTP port?)': a question about a service that is not there."""
    import socket

    import distributed

    from frictionlab.compute.dask_security import _check_answers_as_scheduler
    from frictionlab.errors import RunError

    with socket.socket() as taken:  # a port of this machine, free once closed
        taken.bind(("127.0.0.1", 0))
        port = taken.getsockname()[1]
    with pytest.raises(RunError) as refused:
        _check_answers_as_scheduler(f"tcp://127.0.0.1:{port}", distributed.Security(), seconds=1)
    assert str(refused.value) == (f"--scheduler tcp://127.0.0.1:{port}: nothing listens there (the connection was "
                                  "refused): start the scheduler first (dask scheduler), or give the address it listens on")  # fmt: skip

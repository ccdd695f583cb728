"""The peak-memory estimate: an upper bound of what a run really takes, and a
refusal that names the estimate, the limit and a setting that fits."""

from __future__ import annotations

import re
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import yaml

from frictionlab.compute import memory
from frictionlab.cli import main
from frictionlab.errors import RunError
from frictionlab.preset import build_scene
from frictionlab.options import RunOptions

from .conftest import SMALL_PRESET, loopback_cluster, merge


def offered_points(message: str) -> int:
    """The grid a memory refusal offers instead ("... points <= 1,234,567 ...")."""
    return int(re.search(r"points <= ([\d,]+)", message).group(1).replace(",", ""))


GiB = 2**30

PEAK_OF_CHILD = """
import os, subprocess, sys
child = subprocess.Popen(sys.argv[1:], stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
_, status, usage = os.wait4(child.pid, 0)
if status:
    sys.exit(child.stderr.read().decode() or f"exit status {status}")
print(usage.ru_maxrss)
"""


def line_of(points: int, **changes) -> dict:
    return merge(SMALL_PRESET, {"realizations": 2, "spectrum": {"params": {"points": points}}, **changes})


# Full contact at the largest force: every point is sorted, the costliest case of the spring sweep
# (from a load that is not: a run in full contact at every load fits no law).
FULL_CONTACT = {"loading": {"start": 1.0, "stop": 1e10, "steps": 16, "spacing": "log"}}


@pytest.mark.parametrize(
    "points, changes",
    [
        (300_000, FULL_CONTACT),
        (2_000_000, {**FULL_CONTACT, "output": {"plot": False}}),
        # a length whose prime factor passes its root: numpy's FFT takes 128 B a point more (Bluestein)
        (2 * 1_000_003, {**FULL_CONTACT, "output": {"plot": False}}),
        # the large grid of the docs' memory example (1e7 points, about 1 GiB at full contact)
        pytest.param(10_000_000, {**FULL_CONTACT, "output": {"plot": False}}, marks=pytest.mark.slow),
    ],
    ids=["3e5-with-plot", "2e6", "2e6-prime-factor", "1e7"],
)
@pytest.mark.long  # a process of its own, seconds end to end: pytest -m long
def test_the_estimate_bounds_the_measured_peak_of_a_real_run(registry, tmp_path, points, changes):
    preset = line_of(points, **changes)
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump(preset))
    command = [sys.executable, "-m", "frictionlab", "run", str(path), "--out", str(tmp_path / "out"), "--workers", "1", "--quiet"]
    # A child forked from this (large) pytest process is charged the parent's RSS
    # before it execs; a small wrapper forks the run instead and reports its peak.
    done = subprocess.run([sys.executable, "-c", PEAK_OF_CHILD, *command], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    peak = int(done.stdout) * 1024  # ru_maxrss is in kB on Linux
    estimate = memory.estimate(build_scene(preset, registry=registry), workers=1, executor="serial")
    assert peak <= estimate.total, f"measured {peak / 2**20:.0f} MiB > estimated {estimate.total / 2**20:.0f} MiB"
    # and not uselessly loose: within a factor 4 of the truth
    assert estimate.total < 4 * peak


def surface_of(points: int, solver: str = "bem-halfspace", **changes) -> dict:
    return merge(SMALL_PRESET, {
        "realizations": 1,
        "spectrum": {"name": "power-law-2d", "params": {"hurst": 0.8, "points": points, "length": 128.0, "short_cutoff": 4.0}},
        "solver": {"name": solver, "params": {}}, "slope": {"name": "forward-difference"},
        # up to 99.7 % contact: the contact set's index arrays are largest there
        "loading": {"control": "force", "start": 1.5, "stop": 3000.0, "steps": 6, "spacing": "log"}, **changes,
    })  # fmt: skip


@pytest.mark.long
def test_the_half_space_declares_what_its_realization_allocates(registry):
    """tracemalloc sees numpy's buffers: the peak of one realization (synthesis, slopes,
    the solve) per point lies under the declared estimate, and not far under it."""
    import tracemalloc

    from frictionlab.compute.realization import compute_realization

    scene = build_scene(surface_of(256), registry=registry)
    compute_realization(scene, 0)  # caches (the synthesis, FFT plans) are not per realization
    tracemalloc.start()
    try:
        floor = tracemalloc.get_traced_memory()[0]
        result = compute_realization(scene, 1)
        peak = tracemalloc.get_traced_memory()[1] - floor
    finally:
        tracemalloc.stop()
    assert result.ok and result.contact_count[-1] > 0.99 * 256**2
    estimate = memory.estimate(scene, workers=1, executor="serial")
    assert estimate.points == 256**2
    assert peak <= estimate.per_realization
    assert estimate.per_realization < 1.6 * peak
    # the line pipeline's figure would not have covered it
    assert peak > 256**2 * memory.BYTES_PER_POINT


def test_a_solver_declaring_more_bytes_per_point_raises_the_estimate(registry):
    surface = build_scene(surface_of(256), registry=registry)
    declared = type(surface.solver).bytes_per_point
    assert declared is not None
    line = build_scene(surface_of(256, solver="mdr"), registry=registry)  # presses the equivalent line
    assert type(line.solver).bytes_per_point is None
    assert memory.bytes_per_point(line) == memory.BYTES_PER_POINT
    assert memory.bytes_per_point(surface) == declared + memory.PROFILE_BYTES_PER_POINT


def assert_offer_is_the_most_that_fits(scene, message: str, points=lambda offered: offered) -> None:
    """The points a refusal offers fit in the 1 GiB limit on one worker with 2 % to spare (an offer
    at the very edge was refused when run), and one more would not."""
    offered = offered_points(message)
    fits = memory.estimate(scene, workers=1, executor="processes", points=points(offered)).total
    too_many = memory.estimate(scene, workers=1, executor="processes", points=points(offered + 1)).total
    assert fits <= 0.98 * GiB < too_many


def test_a_surface_too_large_for_the_half_space_is_refused_with_the_side_that_fits(registry, monkeypatch):
    scene = build_scene(surface_of(4096), registry=registry)
    monkeypatch.setattr(memory, "available_memory", lambda: (1 * GiB, "a test limit"))
    with pytest.raises(RunError, match=r"spectrum.params.points <= ([\d,]+)\.") as caught:
        memory.check_fits(scene, workers=2, executor="processes")
    assert_offer_is_the_most_that_fits(scene, caught.value.args[0], points=lambda side: side**2)


def test_an_absurd_grid_is_refused_in_numbers_a_person_reads(registry, monkeypatch):
    """10**99 points: the refusal printed the points and the GiB in full, about 200 digits."""
    scene = build_scene(line_of(10**99), registry=registry)
    monkeypatch.setattr(memory, "available_memory", lambda: (1 * GiB, "a test limit"))
    with pytest.raises(RunError) as caught:
        memory.check_fits(scene, workers=1, executor="processes")
    message = caught.value.args[0]
    assert "1e+99 points" in message and re.search(r"about \d\.\d\de\+\d+ GiB", message)
    assert max(len(word) for word in message.split()) < 30, message
    assert memory.gib(2.5 * GiB) == "2.50 GiB" and memory.points_text(1_234_567) == "1,234,567"


def test_estimate_grows_with_points_workers_and_kept_rows(registry):
    small = build_scene(line_of(10_000), registry=registry)
    large = build_scene(line_of(1_000_000), registry=registry)
    many = build_scene(merge(line_of(10_000), {"realizations": 100_000}), registry=registry)
    one = memory.estimate(large, workers=1, executor="processes")
    two = memory.estimate(large, workers=2, executor="processes")
    assert two.total - one.total == one.per_worker
    assert memory.estimate(large, workers=1, executor="serial").total > memory.estimate(small, workers=1, executor="serial").total
    # 100 000 realizations x 16 steps x 3 arrays x 8 bytes, kept in the main process
    assert memory.estimate(many, workers=1, executor="serial").main - memory.estimate(small, workers=1, executor="serial").main > 100_000 * 16 * 3 * 8


def test_refusal_names_estimate_limit_and_fewer_workers(registry, monkeypatch):
    scene = build_scene(line_of(4_000_000), registry=registry)
    monkeypatch.setattr(memory, "available_memory", lambda: (1 * GiB, "a test limit"))
    with pytest.raises(RunError) as caught:
        memory.check_fits(scene, workers=2, executor="processes")
    message = str(caught.value)
    needed = memory.estimate(scene, workers=2, executor="processes").total
    assert needed > GiB
    assert message.startswith(f"this run would need about {needed / GiB:.2f} GiB (2 worker(s) x ")
    assert "but 1.00 GiB is available (a test limit). It would fit with --workers 1." in message
    memory.check_fits(scene, workers=1, executor="processes")  # the advice is right


def test_refusal_offers_fewer_points_when_one_worker_is_too_many(registry, monkeypatch):
    scene = build_scene(line_of(20_000_000), registry=registry)
    monkeypatch.setattr(memory, "available_memory", lambda: (1 * GiB, "a test limit"))
    with pytest.raises(RunError, match=r"It would fit with --workers 1 and spectrum.params.points <= ([\d,]+)\.") as caught:
        memory.check_fits(scene, workers=2, executor="processes")
    assert_offer_is_the_most_that_fits(scene, caught.value.args[0])


def test_a_notebooks_refusal_names_the_argument_of_frictionlab_run(registry, monkeypatch, tmp_path):
    """The advice reaches frictionlab.run too, where workers=1 is what to type (--workers 1 is not)."""
    import frictionlab

    monkeypatch.setattr(memory, "available_memory", lambda: (1 * GiB, "a test limit"))
    with pytest.raises(RunError, match=r"It would fit with workers=1\.") as caught:
        frictionlab.run(line_of(4_000_000), workers=2, progress=False, out=tmp_path / "out")
    assert "(memory_check=False skips this estimate" in str(caught.value) and "--" not in str(caught.value)
    assert not (tmp_path / "out").exists()


def test_cli_refuses_before_writing_anything(tmp_path, monkeypatch, capsys):
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump(line_of(4_000_000)))
    monkeypatch.setattr(memory, "available_memory", lambda: (GiB // 4, "a test limit"))
    code = main(["run", str(path), "--out", str(tmp_path / "out"), "--workers", "2"])
    err = capsys.readouterr().err
    assert code == 1
    assert err.startswith("error: this run would need about ") and "Traceback" not in err
    assert not (tmp_path / "out").exists()
    # --no-memory-check takes the user's word for it (a tiny run, so it really runs)
    path.write_text(yaml.safe_dump(line_of(1024)))
    monkeypatch.setattr(memory, "available_memory", lambda: (1, "a test limit"))
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--workers", "1", "--quiet", "--no-memory-check",
                 "--no-plot"]) == 0  # fmt: skip


def test_available_memory_is_positive_and_below_the_machine_total():
    available, source = memory.available_memory()
    total = next(int(line.split()[1]) * 1024 for line in Path("/proc/meminfo").read_text().splitlines() if line.startswith("MemTotal:"))
    assert 0 < available <= total
    assert source


# ------------------------------------------------------------------ Dask workers' memory limits

MiB = 2**20


def test_worker_check_takes_the_smallest_limit_and_skips_workers_without_one(registry):
    scene = build_scene(line_of(1_000_000), registry=registry)  # 1e6 x 112 B = 107 MiB, plus the worker
    need = memory.DASK_WORKER_PROCESS + memory.estimate(scene, workers=1, executor="dask").per_realization
    # no limit (0, None) is never the smallest; a roomy limit passes
    memory.check_worker_limits(scene, {"tcp://a:1": 0, "tcp://b:2": None, "tcp://c:3": need}, usable=1.0)
    # the margin: Dask kills a worker at a fraction of its limit
    with pytest.raises(RunError, match=r"worker tcp://c:3 has a memory limit of 0\.\d\d GiB \(Dask kills a worker at 95% of its limit\)"):
        memory.check_worker_limits(scene, {"tcp://c:3": need}, usable=0.95)
    with pytest.raises(RunError) as caught:
        memory.check_worker_limits(scene, {"tcp://big:1": 4 * GiB, "tcp://small:2": 200 * MiB, "tcp://none:3": 0}, usable=0.95)
    message = str(caught.value)
    assert "Dask worker tcp://small:2 has a memory limit of 0.20 GiB (the smallest of 2 workers with a limit;" in message
    assert message.startswith(f"one realization of 1,000,000 points would need about {need / GiB:.2f} GiB in a Dask worker")
    offered = offered_points(message)
    room = 0.98 * int(200 * MiB * 0.95)  # 2 % to spare
    larger = min(m for m in range(offered + 1, 2 * offered) if memory.smooth_at_most(m) == m)  # the next FFT length
    assert memory.smooth_at_most(offered) == offered  # a line's length its FFT takes without more memory
    assert memory.DASK_WORKER_PROCESS + offered * memory.BYTES_PER_POINT + 16 * memory.BYTES_PER_STEP <= room
    assert memory.DASK_WORKER_PROCESS + larger * memory.BYTES_PER_POINT + 16 * memory.BYTES_PER_STEP > room
    # when even the worker process alone does not fit, only a larger limit helps
    with pytest.raises(RunError, match=r"It would fit with workers with a memory limit of at least 0\.\d\d GiB\."):
        memory.check_worker_limits(scene, {"tcp://tiny:1": 100 * MiB}, usable=0.95)


try:
    import distributed
except ImportError:
    distributed = None


@pytest.fixture(scope="module")
def small_worker_cluster():
    """One worker process on loopback whose nanny kills it above 95% of 200 MiB."""
    with loopback_cluster(1, memory_limit="200MiB") as cluster:
        yield cluster.scheduler_address, next(iter(cluster.scheduler_info["workers"]))


needs_dask = pytest.mark.skipif(distributed is None, reason='dask is not installed: pip install "frictionlab[dask]"')


@needs_dask
@pytest.mark.long  # a Dask cluster of its own (seconds); the refusal's arithmetic is checked above without one
def test_cli_refuses_a_grid_too_large_for_the_dask_worker_before_submitting_anything(tmp_path, capsys, small_worker_cluster):
    scheduler, worker = small_worker_cluster
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump(line_of(1_000_000, realizations=4)))
    out = tmp_path / "out"
    code = main(["run", str(path), "--out", str(out), "--executor", "dask", "--scheduler", scheduler, "--quiet"])
    err = capsys.readouterr().err
    assert code == 1 and "Traceback" not in err
    assert err.startswith("error: one realization of 1,000,000 points would need about ")
    assert f"Dask worker {worker} has a memory limit of 0.20 GiB" in err
    assert not out.exists()  # no run directory, no chunk
    # the grid it offers really runs on that worker (a wrong bound would get it killed)
    offered = offered_points(err)
    assert 300_000 < offered < 1_000_000
    path.write_text(yaml.safe_dump(line_of(offered, realizations=2, **FULL_CONTACT)))
    code = main(["run", str(path), "--out", str(out), "--executor", "dask", "--scheduler", scheduler, "--quiet", "--json"])
    assert code == 0, capsys.readouterr().err


@needs_dask
@pytest.mark.long  # the same cluster
def test_a_grid_that_fits_gives_the_serial_numbers_and_no_memory_check_skips_the_refusal(registry, tmp_path, small_worker_cluster):
    import threading

    from frictionlab.compute import engine
    from frictionlab.runs.runner import run_to_folder

    from .test_executors import same_numbers

    scheduler, _ = small_worker_cluster
    scene = build_scene(merge(SMALL_PRESET, {"realizations": 12}), registry=registry)
    outcome, _ = run_to_folder(scene, tmp_path / "small", RunOptions(executor="dask", scheduler=scheduler))
    assert outcome.status == "completed" and outcome.extra["executor"] == "dask"
    same_numbers(engine.run(scene, RunOptions(workers=1, executor="serial")), outcome)

    # too large: refused by the check, not by the cluster; skipped with the check off
    # (cancelled before the first realization, so nothing large ever runs)
    large = build_scene(line_of(1_000_000, realizations=4), registry=registry)
    cancelled = threading.Event()
    cancelled.set()
    with pytest.raises(RunError, match="has a memory limit of 0.20 GiB"):
        run_to_folder(large, tmp_path / "large", RunOptions(executor="dask", scheduler=scheduler), cancel=cancelled)
    outcome, _ = run_to_folder(large, tmp_path / "large", RunOptions(executor="dask", scheduler=scheduler, memory_check=False), cancel=cancelled)
    assert outcome.status == "cancelled" and outcome.done == 0


@needs_dask
def test_own_local_cluster_is_checked_before_it_starts(registry, tmp_path, monkeypatch):
    from distributed import worker_memory

    from frictionlab.runs.runner import run_to_folder

    # as on a many-core machine, where "auto" gives each worker memory/cores
    monkeypatch.setattr(worker_memory, "parse_memory_limit", lambda *args, **kwargs: 200 * MiB)
    large = build_scene(line_of(1_000_000, realizations=4), registry=registry)
    with pytest.raises(RunError, match=r"Dask worker 1 of the LocalCluster on 127\.0\.0\.1 has a memory limit of 0\.20 GiB"):
        run_to_folder(large, tmp_path / "out", RunOptions(workers=2, executor="dask"))
    assert not (tmp_path / "out").exists()


_UNDER_A_LIMIT = """
import resource, sys
import frictionlab
from frictionlab.errors import FrictionlabError
from frictionlab.compute.memory import available_memory
limit = int(sys.argv[1])
resource.setrlimit(resource.RLIMIT_AS, (limit, limit))
room, source = available_memory()
print("ROOM", room, source)
try:
    frictionlab.run("quickstart", {"spectrum.params.points": int(sys.argv[2])}, realizations=2, workers=1, progress=False)
    print("RAN")
except FrictionlabError as exc:
    print("REFUSED", exc)
    sys.exit(exc.exit_code)
"""


@pytest.mark.long  # two processes under ulimit -v
def test_a_process_limit_on_address_space_is_part_of_the_check(tmp_path):
    """Under ``ulimit -v``, a run whose estimate passes the limit is refused at once with
    the limit named (it would otherwise die of MemoryError in every realization); the room
    reported lies below the limit, and a small run still runs."""
    vms = __import__("psutil").Process().memory_info().vms
    limit = vms + 1536 * MiB  # this test's own process plus 1.5 GiB: the child imports less
    script = tmp_path / "limited.py"
    script.write_text(_UNDER_A_LIMIT)
    big = subprocess.run([sys.executable, str(script), str(limit), str(2**25)], capture_output=True, text=True,
                         timeout=300, cwd=tmp_path)  # fmt: skip
    assert big.returncode == 1, big.stdout + big.stderr
    room = int(big.stdout.split("ROOM ")[1].split()[0])
    assert 0 < room < limit and "RLIMIT_AS" in big.stdout.split("ROOM ")[1].splitlines()[0]
    assert "REFUSED this run would need about" in big.stdout and "RLIMIT_AS (ulimit -v)" in big.stdout
    small = subprocess.run([sys.executable, str(script), str(limit), "1024"], capture_output=True, text=True,
                           timeout=300, cwd=tmp_path)  # fmt: skip
    assert small.returncode == 0 and "RAN" in small.stdout, small.stdout + small.stderr


def test_the_check_of_a_huge_surface_allocates_nothing_in_proportion_to_it(registry, tmp_path):
    """The estimate is arithmetic: refusing a 65536² half-space (4.3e9 points, 800 GiB)
    costs the memory of a small run, measured as the growth of ru_maxrss in a fresh process
    (the surface's synthesis, which the check once ran to learn the grid's shape, grows
    by 170 MiB at 16384² and 2.7 GiB at 65536²)."""
    script = tmp_path / "huge.py"
    script.write_text(
        "import resource, yaml, frictionlab\n"
        "from frictionlab.errors import RunError\n"
        f"data = yaml.safe_load(open({str(Path(__file__).parents[1] / 'presets' / 'exact3d-h08-rolloff.yaml')!r}))\n"
        "data['spectrum']['params']['points'] = 65536\n"
        "del data['spectrum']['params']['short_cutoff']\n"  # the default, a few pixels: every mode in the band
        "before = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss\n"
        "try:\n    frictionlab.run(data, workers=1, progress=False)\nexcept RunError as exc:\n    print('REFUSED', exc)\n"
        "print('GROWTH_KIB', resource.getrusage(resource.RUSAGE_SELF).ru_maxrss - before)\n"
    )
    done = subprocess.run([sys.executable, str(script)], capture_output=True, text=True, timeout=300)
    assert "REFUSED this run would need about" in done.stdout and "4,294,967,296 points" in done.stdout, done.stderr
    growth = int(done.stdout.split("GROWTH_KIB ")[1])
    assert growth < 200 * 1024  # KiB: a 65536² array of float64 alone is 32 GiB


# ------------------------------------------------------------------ a process limit is each process's


def _under_a_process_limit(monkeypatch, room: int, machine: int = 64 * GiB) -> None:
    source = "the process limit RLIMIT_AS (ulimit -v) less what this process uses"
    monkeypatch.setattr(memory, "_process_limits", lambda: [(room, source)])
    monkeypatch.setattr(memory, "_machine_rooms", lambda: [(machine, "a test machine")])


def test_workers_under_ulimit_v_each_have_the_limit_to_themselves(registry, monkeypatch):
    """Under ``ulimit -v`` each worker process has the whole limit: 16 workers of 0.2 GiB
    realizations fit under a 1 GiB limit (the sum, 4.7 GiB, is the machine's to bound),
    where they were refused as if the workers shared it ('It would fit with --workers 3')."""
    scene = build_scene(line_of(2_000_000), registry=registry)
    guess = memory.estimate(scene, workers=16, executor="processes")
    assert guess.total > 4 * GiB and memory._largest_process(guess) < GiB
    _under_a_process_limit(monkeypatch, 1 * GiB)
    assert memory.check_fits(scene, workers=16, executor="processes") == guess
    _under_a_process_limit(monkeypatch, 1 * GiB, machine=2 * GiB)  # the machine still bounds the sum
    with pytest.raises(RunError, match=r"but 2\.00 GiB is available \(a test machine\)\. It would fit with --workers (\d+)\."):
        memory.check_fits(scene, workers=16, executor="processes")


def _bytes(text: str) -> float:
    number, unit = text.split()
    return float(number) * (GiB if unit == "GiB" else 2**20)


@pytest.mark.parametrize("points, executor", [(1000, "processes"), (5_000_000, "processes")])
def test_a_refusal_by_the_process_limit_names_every_part_of_the_need(registry, monkeypatch, points, executor):
    """A small run refused under a small limit once read 'would need 0.16 GiB (a realization: 0 MiB)':
    the process's own share, Python and its libraries, was left unsaid. The parts now add up to the need."""
    scene = build_scene(line_of(points), registry=registry)
    _under_a_process_limit(monkeypatch, 20 * 2**20)
    with pytest.raises(RunError) as caught:
        memory.check_fits(scene, workers=2, executor=executor)
    amount = r"(\d+(?:\.\d+)? (?:GiB|MiB))"
    found = re.search(rf"would need about {amount} at its peak \(a realization of [\d,]+ points: {amount}, the process "
                      rf"itself with Python, its libraries and what it keeps: {amount}\)", str(caught.value))
    assert found, str(caught.value)
    need, realization, own = (_bytes(found.group(i)) for i in (1, 2, 3))
    assert own >= 64 * 2**20  # at least what the base of a worker process is
    assert realization + own == pytest.approx(need, abs=0.011 * GiB)  # each shown to 0.01 GiB or 1 MiB


def test_a_realization_past_the_process_limit_is_refused_naming_it_and_a_grid_that_fits(registry, monkeypatch):
    scene = build_scene(line_of(20_000_000), registry=registry)  # 2.1 GiB a realization
    _under_a_process_limit(monkeypatch, 1 * GiB)
    with pytest.raises(RunError) as caught:
        memory.check_fits(scene, workers=4, executor="processes")
    message = str(caught.value)
    assert message.startswith("one process of this run would need about 2.") and "RLIMIT_AS (ulimit -v)" in message
    assert "each worker process has the limit to itself" in message
    offered = offered_points(message)
    fits = memory.estimate(scene, workers=1, executor="processes", points=offered)
    too_many = memory.estimate(scene, workers=1, executor="processes", points=offered + 1)
    assert memory._largest_process(fits) <= GiB < memory._largest_process(too_many)


def test_a_serial_run_under_a_process_limit_counts_its_whole_peak_against_it(registry, monkeypatch):
    scene = build_scene(line_of(8_000_000), registry=registry)  # one process: the limit bounds the whole run
    _under_a_process_limit(monkeypatch, memory.estimate(scene, workers=1, executor="serial").total - 1)
    with pytest.raises(RunError, match=r"RLIMIT_AS \(ulimit -v\) less what this process uses\)\. It would fit with"):
        memory.check_fits(scene, workers=1, executor="serial")


@pytest.mark.skipif(not Path("/proc/self/statm").exists(), reason="reads /proc directly on Linux only")
def test_the_memory_read_from_proc_is_psutils(monkeypatch):
    psutil = pytest.importorskip("psutil")
    vms, data = memory._address_space()
    used = psutil.Process().memory_info()
    assert vms == pytest.approx(used.vms, abs=64 * 2**20) and data == pytest.approx(used.data, abs=64 * 2**20)
    assert memory._system_available() == pytest.approx(psutil.virtual_memory().available, rel=0.05, abs=256 * 2**20)
    # without /proc, psutil's figures
    monkeypatch.setattr(memory, "PROC_MEMINFO", "/nonexistent/meminfo")
    monkeypatch.setattr(memory, "PROC_STATM", "/nonexistent/statm")
    assert memory._address_space()[0] == pytest.approx(psutil.Process().memory_info().vms, abs=64 * 2**20)
    assert memory._system_available() == pytest.approx(psutil.virtual_memory().available, rel=0.05, abs=256 * 2**20)


def test_a_grid_too_large_for_one_realization_is_not_offered_no_realizations(tmp_path, monkeypatch):
    """A measured map has no points parameter to offer: with one realization already too large,
    the advice was 'It would fit with --workers 1 and realizations <= 0'. It names the points."""
    np.save(tmp_path / "map.npy", np.random.default_rng(np.random.SeedSequence(3)).normal(size=(512, 512)))
    scene = build_scene({
        "name": "scan", "seed": 1, "realizations": 1,
        "spectrum": {"name": "surface-file", "params": {"path": str(tmp_path / "map.npy"), "spacing": 1.0}},
        "solver": {"name": "bem-halfspace-free"}, "loading": {"start": 0.01, "stop": 0.1, "steps": 3},
    })  # fmt: skip
    one = memory.estimate(scene, workers=1, executor="serial")
    room = memory.PROCESS_BASE + one.per_realization // 2  # frictionlab itself fits, the realization does not
    monkeypatch.setattr(memory, "available_memory", lambda: (room, "a test limit"))
    with pytest.raises(RunError) as caught:
        memory.check_fits(scene, workers=1, executor="serial")
    message = str(caught.value)
    assert "realizations <= 0" not in message
    assert "It would fit with fewer points: one realization of 262,144 points alone needs" in message


def test_a_resume_refused_for_memory_says_only_the_worker_count_can_change(registry, monkeypatch):
    """A resume keeps its stored preset, yet its refusal offered 'spectrum.params.points <= N'
    as for a new run: it now says that of the advice only --workers applies."""
    from frictionlab.runs.runner import check_memory

    scene = build_scene(line_of(8_000_000), registry=registry)
    monkeypatch.setattr(memory, "available_memory", lambda: (GiB // 2, "a test limit"))
    with pytest.raises(RunError, match=r"spectrum\.params\.points <= [\d,]+\.") as fresh:
        check_memory(scene, RunOptions(workers=1))
    assert "A resume" not in str(fresh.value)
    with pytest.raises(RunError) as resumed:
        check_memory(scene, RunOptions(workers=1, resume=True))
    assert str(resumed.value).startswith(str(fresh.value))
    assert str(resumed.value).endswith("A resume keeps the preset the run was started with: of that advice only the worker "
                                       "count applies; otherwise resume it where more memory is available.")  # fmt: skip


def test_a_run_on_one_worker_is_not_advised_one_worker(registry, monkeypatch):
    """A run already on one worker was told 'It would fit with --workers 1 and
    spectrum.params.points <= N'; the advice is the points alone, the most that fit."""
    scene = build_scene(line_of(20_000_000), registry=registry)
    monkeypatch.setattr(memory, "available_memory", lambda: (1 * GiB, "a test limit"))
    with pytest.raises(RunError, match=r"It would fit with spectrum.params.points <= ([\d,]+)\.") as caught:
        memory.check_fits(scene, workers=1, executor="processes")
    assert "--workers" not in caught.value.args[0]
    assert_offer_is_the_most_that_fits(scene, caught.value.args[0])


def test_a_refusal_in_python_names_the_keyword_that_skips_it():
    import frictionlab

    with pytest.raises(RunError) as caught:
        frictionlab.run(SMALL_PRESET, spectrum__params__points=2**40, workers=1, progress=False)
    assert "(memory_check=False skips this estimate, an upper bound.)" in str(caught.value)
    assert frictionlab.run(SMALL_PRESET, workers=1, progress=False, memory_check=False).status == "completed"


def test_the_largest_7_smooth_length_is_found_as_brute_force_finds_it():
    """The advice offers a length numpy's FFT takes without Bluestein's extra memory: 2,814,498
    (2 x 3^2 x 156,361) was offered under 600 MB and every realization ran out of memory."""
    def smooth(n):
        for p in (2, 3, 5, 7):
            while n % p == 0:
                n //= p
        return n == 1

    for n in [*range(1, 3000), 2_814_498, 15_614_498, 2**31 - 1]:
        best = memory.smooth_at_most(n)
        assert smooth(best) and best <= n, n
        assert n > 5000 or not any(smooth(m) for m in range(best + 1, n + 1)), n  # the largest (brute force)
    for n, extra in ((2_814_498, True), (2 * 1_000_003, True), (2**21, False), (2_799_360, False), (1_654_784, False)):
        assert (memory.fft_extra_bytes(n) > 0) is extra, n  # 1,654,784 = 2^14 x 101: numpy's own passes

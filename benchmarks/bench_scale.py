"""Benchmark: large grids, cost against N and force steps, executors.

Every figure is printed with the baseline it is compared with, measured in the
same process (or, for peak memory, in a fresh one per size):

* large lines: peak memory (ru_maxrss of a fresh process) and seconds per
  realization of the Fig. 2 line with N points (1e6, 1e7; 1e8 with --huge);
* cost per realization against N (1e3..1e7, at 400 steps) and against the
  number of force steps (10..1e4, at N = 1e5): time / (N log2 N) should stay
  flat in N, and the time flat in steps;
* the Fig. 2 scene and an exact 3D ensemble (exact3d-h08 on 128^2 pixels, 32 surfaces) with each
  executor (serial; processes 1, 2; Dask LocalCluster of 2, cluster start and the
  workers' first import excluded, with a client per run and with one client for every run
  as a sweep has; the Fig. 2 scene on a LocalCluster of 1 too), efficiency = serial /
  (workers x time); serial and Dask also in back-to-back rounds, each round's efficiency;
* overhead per task of each executor (tiny realizations, one per task);
* the Fig. 2 scene end to end (run + chunk files + result files and plot) with
  the default executor.

    python benchmarks/bench_scale.py [--huge] [--skip-dask] [--repeat 3]
"""

from __future__ import annotations

import argparse
import logging
import math
import os
import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from frictionlab.compute import engine
from frictionlab.compute.dask_security import PROFILE_OFF, WORKER_CONFIG
from frictionlab.compute.dask_session import one_dask_cluster
from frictionlab.compute.executors import make_executor
from frictionlab.options import RunOptions
from frictionlab.preset import load_scene
from frictionlab.compute.realization import compute_realization
from frictionlab.runs.runner import run_to_folder
from bench_fig2 import best_of  # the same timing rule in every benchmark (run as a script: its folder is on sys.path)

PRESET = Path(__file__).resolve().parents[1] / "presets" / "benad2012-fig2.yaml"

PEAK_SCRIPT = """
import sys, time
from frictionlab.preset import load_scene
from frictionlab.compute.realization import compute_realization
from frictionlab.compute.realization import compute_realization
from frictionlab.options import RunOptions
n = int(float(sys.argv[2]))
scene = load_scene(sys.argv[1], [f"spectrum.params.points={n}", f"spectrum.params.length={float(n)}"])
times = []
for i in range(int(sys.argv[3])):
    start = time.perf_counter(); result = compute_realization(scene, i); times.append(time.perf_counter() - start)
    assert result.ok, result.error
print(min(times))
"""


def line_scene(points: int, steps: int = 400):
    return load_scene(
        PRESET, [f"spectrum.params.points={points}", f"spectrum.params.length={float(points)}", f"loading.steps={steps}"]
    )


def per_realization(scene, count: int, repeat: int) -> float:
    compute_realization(scene, 0)  # warm: synthesis cache, FFT plan
    return best_of(repeat, lambda: [compute_realization(scene, i) for i in range(count)]) / count


def large_lines(sizes: list[float]) -> None:
    print("Large lines (Fig. 2 line, 400 forces), one fresh process per size, serial:")
    print(f"  {'N':>8}  {'s/realization':>13}  {'peak RSS':>9}  {'bytes/point':>11}")
    for n in sizes:
        count = 1 if n >= 1e8 else 2
        process = subprocess.Popen(
            [sys.executable, "-c", PEAK_SCRIPT, str(PRESET), str(n), str(count)], stdout=subprocess.PIPE, text=True
        )
        out = process.stdout.read()
        _, status, usage = os.wait4(process.pid, 0)
        if status:
            print(f"  {n:8.0e}  failed (status {status})")
            continue
        peak = usage.ru_maxrss * 1024
        print(f"  {n:8.0e}  {float(out):13.3f}  {peak / 2**20:7.0f} MiB  {peak / n:11.1f}")


def cost_against_n_and_steps(repeat: int) -> None:
    print("Cost per realization against N (400 forces); time / (N log2 N) flat means N log N:")
    base = None
    for n in (1_000, 10_000, 100_000, 1_000_000, 10_000_000):
        count = max(1, int(2e6 // n))
        seconds = per_realization(line_scene(n), count, repeat if n < 1e7 else 1)
        norm = seconds / (n * math.log2(n))
        base = base or norm
        print(f"  N = {n:>10,}: {seconds * 1e3:9.3f} ms   per N log2 N: {norm * 1e9:6.2f} ns  ({norm / base:5.2f} x N = 1e3)")
    print("Cost per realization against force steps (N = 1e5):")
    base = None
    for steps in (10, 100, 1_000, 10_000):
        seconds = per_realization(line_scene(100_000, steps), 20, repeat)
        base = base or seconds
        print(f"  {steps:>6} steps: {seconds * 1e3:7.3f} ms  ({seconds / base:5.2f} x 10 steps)")


SURFACE_PRESET = PRESET.parent / "exact3d-h08.yaml"


def efficiency_rows(scene, repeat: int) -> list[tuple[str, int, float]]:
    """(executor, workers, best seconds) of ``scene`` run serially and on 1 and 2 processes
    (before any Dask cluster starts: its threads would make the pool use forkserver)."""
    rows = [("serial", 1, best_of(repeat, lambda: engine.run(scene, RunOptions(workers=1, executor="serial"))))]
    for workers in (1, 2):
        rows.append(("processes", workers, best_of(repeat, lambda: engine.run(scene, RunOptions(workers=workers, executor="processes")))))
    return rows


def timed(work) -> float:
    start = time.perf_counter()
    work()
    return time.perf_counter() - start


def dask_rows(scene, repeat: int, address: str) -> tuple[list[tuple[str, int, float]], list[float]]:
    """A client per run (a single ``frictionlab run``), and one client for every run (a sweep
    or a study: ``one_dask_cluster``), connected before the timing as a command's first run does.

    Rounds of (serial, Dask one client, Dask own client), back to back: the speed of a shared
    machine drifts between rounds, so each round's efficiency compares runs seconds apart.
    Returns the best times, and the efficiency of the one-client run of every round."""
    options = RunOptions(executor="dask", scheduler=address)
    serial_options = RunOptions(workers=1, executor="serial")
    serial, own, one, rounds = [], [], [], []
    with one_dask_cluster(options):
        engine.run(scene, options)
        for _ in range(repeat):
            serial.append(timed(lambda: engine.run(scene, serial_options)))
            one.append(timed(lambda: engine.run(scene, options)))
            rounds.append(serial[-1] / (2 * one[-1]))
    for _ in range(repeat):  # outside the session: a client per run
        own.append(timed(lambda: engine.run(scene, options)))
    rows = [("serial (rounds)", 1, min(serial)), ("dask, own client", 2, min(own)), ("dask, one client", 2, min(one))]
    return rows, rounds


def print_rounds(rounds: list[float]) -> None:
    ordered = sorted(rounds)
    print(
        f"  dask, one client, round by round (serial / (2 x dask), each pair seconds apart): median {ordered[len(ordered) // 2]:.2f}, "
        f"range {ordered[0]:.2f} .. {ordered[-1]:.2f} over {len(ordered)} rounds"
    )


def print_efficiencies(title: str, rows) -> None:
    serial = rows[0][2]
    print(f"{title} (efficiency = serial / (workers x time)):")
    for name, workers, seconds in rows:
        print(f"  {name:18} {workers} worker(s): {seconds:7.3f} s   speed-up {serial / seconds:5.2f}   efficiency {serial / (workers * seconds):5.2f}")


def executors(repeat: int, skip_dask: bool) -> None:
    scene = load_scene(PRESET)
    m = scene.preset.realizations
    # exact 3D ensembles: the family's preset on 128^2 pixels, 32 surfaces (about 0.15 s each)
    surface = load_scene(SURFACE_PRESET, ["spectrum.params.points=128", "realizations=32"])
    tiny = load_scene(PRESET, ["spectrum.params.points=64", "spectrum.params.length=64.0", "loading.steps=2"])
    tasks = [[i] for i in range(400)]
    never = threading.Event()

    def overhead(pool) -> float:
        compute = best_of(repeat, lambda: [compute_realization(tiny, i) for i in range(len(tasks))])
        wall = best_of(repeat, lambda: list(pool.map_chunks(tiny, tasks, never)))
        return (wall - compute) / len(tasks)

    overheads = [("serial", overhead(make_executor(RunOptions(executor="serial"), 1))), ("processes (2, pool start included)", overhead(make_executor(RunOptions(executor="processes"), 2)))]
    rows, rows_3d = efficiency_rows(scene, repeat), efficiency_rows(surface, min(repeat, 2))
    if not skip_dask:
        import dask
        import distributed

        with dask.config.set({**WORKER_CONFIG, **PROFILE_OFF}), distributed.LocalCluster(  # the workers frictionlab's own cluster has
            n_workers=2, threads_per_worker=1, host="127.0.0.1", dashboard_address=None, silence_logs=logging.ERROR
        ) as cluster:
            address = cluster.scheduler_address
            engine.run(scene, RunOptions(executor="dask", scheduler=address))  # the workers import frictionlab once
            dask_2d, rounds = dask_rows(scene, repeat, address)
            dask_3d, rounds_3d = dask_rows(surface, min(repeat, 2), address)
            rows.extend(dask_2d)
            rows_3d.extend(dask_3d)
            overheads.append(("dask (2, connect included)", overhead(make_executor(RunOptions(executor="dask", scheduler=address), 2))))
        # one worker on a machine of two cores: the client and the scheduler have a core of their own
        with dask.config.set({**WORKER_CONFIG, **PROFILE_OFF}), distributed.LocalCluster(
            n_workers=1, threads_per_worker=1, host="127.0.0.1", dashboard_address=None, silence_logs=logging.ERROR
        ) as cluster:
            options = RunOptions(executor="dask", scheduler=cluster.scheduler_address)
            with one_dask_cluster(options):
                engine.run(scene, options)
                rows.append(("dask, one client", 1, best_of(repeat, lambda: engine.run(scene, options))))
    print_efficiencies(f"Fig. 2 scene ({m} realizations), executors", rows)
    if not skip_dask:
        print_rounds(rounds)
    print_efficiencies(f"Exact 3D ensemble ({SURFACE_PRESET.name} on 128^2 pixels, 32 surfaces), executors", rows_3d)
    if not skip_dask:
        print_rounds(rounds_3d)
    # the engine runs the first realization alone (its time sizes the chunks): with M equal
    # realizations on W workers the efficiency is at most M / (W (1 + ceil((M - 1) / W)))
    bound = 32 / (2 * (1 + math.ceil(31 / 2)))
    print(f"  (bound for 32 equal realizations on 2 workers, the first run alone: {bound:.2f})")
    print("Overhead per task (400 one-realization tasks of a 64-point line):")
    for name, seconds in overheads:
        print(f"  {name:36} {seconds * 1e3:8.3f} ms")


def end_to_end(repeat: int) -> None:
    scene = load_scene(PRESET)
    with tempfile.TemporaryDirectory() as tmp:
        counter = iter(range(1000))
        warm = best_of(repeat, lambda: run_to_folder(scene, Path(tmp) / str(next(counter))))
        start = time.perf_counter()
        subprocess.run(
            [sys.executable, "-m", "frictionlab", "run", str(PRESET), "--out", str(Path(tmp) / "cold"), "--quiet"],
            check=True,
            stdout=subprocess.DEVNULL,
        )
        cold = time.perf_counter() - start
    print("Fig. 2 scene end to end, default executor:")
    print(f"  run_to_folder (run, chunk files, results and plot), warm process: {warm:6.3f} s  (target < 1 s)")
    print(f"  `frictionlab run` in a new process (start-up and imports included): {cold:6.3f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--huge", action="store_true", help="also N = 1e8 (about 3 GiB; run it alone)")
    parser.add_argument("--skip-dask", action="store_true")
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--only", choices=("large", "cost", "executors", "end-to-end"))
    args = parser.parse_args()
    sections = {
        "large": lambda: large_lines([1e6, 1e7] + ([1e8] if args.huge else [])),
        "cost": lambda: cost_against_n_and_steps(args.repeat),
        "executors": lambda: executors(args.repeat, args.skip_dask),
        "end-to-end": lambda: end_to_end(args.repeat),
    }
    for name, section in sections.items():
        if args.only in (None, name):
            section()


if __name__ == "__main__":
    main()

"""The user's path under a virtual-memory limit of 2 GiB (``ulimit -v 2097152``), as on a
login node or in a container where the kernel does not overcommit.

Each command runs in a process of its own whose RLIMIT_AS is set before it starts: a run
(serial and on worker processes), a resume, ``frictionlab.load``, ``runs``, ``follow``,
``report --figures`` (the paper's presets shrunk), ``validate`` of an instrument file, a
sweep and a 256 x 256 exact half-space run. Each must end with exit 0 and the numbers of
the same work done without the limit (in this process); a run that truly needs more is
refused before it starts, naming the limit (an MDR run of a surface too large to make its
line from included, which died of MemoryError once). A buffer sized by a cap instead of by the data
(16 GiB for a chunk of a few kB) failed every one of them.
"""

from __future__ import annotations

import json
import os
import re
import resource
import subprocess
import sys
import threading

import numpy as np
import pytest
import yaml

from frictionlab.options import RunOptions
from frictionlab.preset import apply_overrides, build_scene, load_preset_file
from frictionlab.runs.runner import run_to_folder

from .conftest import PRESETS
from .test_resume import CancelAfter, same_files

pytestmark = pytest.mark.long  # about twenty processes, each importing numpy, scipy and matplotlib

LIMIT = 2 * 1024**3  # bytes of address space: ulimit -v 2097152

SMALL = {
    "name": "small", "seed": 3, "realizations": 8, "fit": {"bootstrap": 50},
    "spectrum": {"name": "power-law", "params": {"hurst": 0.8, "points": 4096, "spacing": 1.0, "rms_height": 1.0}},
    "solver": {"name": "mdr"}, "loading": {"start": 0.5, "stop": 50.0, "steps": 12, "spacing": "log"},
}  # fmt: skip
SWEEP = {**SMALL, "name": "sweep", "realizations": 4, "output": {"plot": False},
         "sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.6, 0.9]}}}}  # fmt: skip
HALF_SPACE = {
    "name": "half-space", "seed": 5, "realizations": 2, "fit": {"bootstrap": 20}, "output": {"plot": False},
    "spectrum": {"name": "power-law-2d", "params": {"hurst": 0.8, "points": 256, "length": 32.0, "long_cutoff": 16.0,
                                                    "short_cutoff": 2.0, "rms_height": 1.0}},
    "solver": {"name": "bem-halfspace"}, "loading": {"start": 1.5, "stop": 30.0, "steps": 4, "spacing": "log"},
}  # fmt: skip
REPORT_SMALL = ["spectrum.params.points=1024", "spectrum.params.length=1024.0", "spectrum.params.rms_height=300.0",
                "loading.steps=12", "fit.bootstrap=20", "realizations=4"]  # fmt: skip


def _limit_address_space():
    resource.setrlimit(resource.RLIMIT_AS, (LIMIT, LIMIT))


def limited(*args, cwd, python: str | None = None) -> subprocess.CompletedProcess:
    """``frictionlab ARGS`` (or ``python -c PYTHON``) in a process whose address space is limited to 2 GiB."""
    command = [sys.executable, "-c", python] if python else [sys.executable, "-m", "frictionlab", *args]
    return subprocess.run(command, capture_output=True, text=True, cwd=cwd, timeout=300, preexec_fn=_limit_address_space)


def ok(done: subprocess.CompletedProcess) -> subprocess.CompletedProcess:
    assert done.returncode == 0, (done.returncode, done.stderr[-3000:])
    assert "Traceback" not in done.stderr and "out of memory" not in done.stderr
    return done


def write(folder, name: str, data: dict) -> str:
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return str(path)


@pytest.fixture(scope="module")
def reference(tmp_path_factory):
    """The small run done without a limit, in this process."""
    folder = tmp_path_factory.mktemp("reference") / "run"
    run_to_folder(build_scene(SMALL), folder, RunOptions(workers=1))
    return folder


@pytest.mark.parametrize("workers", [["--workers", "1"], ["--workers", "2", "--executor", "processes"]], ids=["serial", "processes"])
def test_a_run_ends_with_exit_0_and_the_numbers_of_an_unlimited_run(tmp_path, reference, workers):
    ok(limited("run", write(tmp_path, "small", SMALL), "--out", str(tmp_path / "run"), *workers, cwd=tmp_path))
    same_files(tmp_path / "run", reference)
    assert (tmp_path / "run" / "plot.png").stat().st_size > 0


def test_a_resume_ends_where_the_unlimited_run_ends(tmp_path, reference):
    cancel = threading.Event()
    first, _ = run_to_folder(build_scene(SMALL), tmp_path / "run", RunOptions(workers=1), listeners=[CancelAfter(3, cancel)],
                             cancel=cancel)  # fmt: skip
    assert first.status == "cancelled" and first.done < SMALL["realizations"]
    ok(limited("resume", str(tmp_path / "run"), "--workers", "1", cwd=tmp_path))
    same_files(tmp_path / "run", reference)


def test_a_resume_recomputes_a_chunk_grown_past_what_it_can_hold_without_reading_it(tmp_path, reference):
    """A chunk of a few realizations grown to 3 GiB was read whole: "out of memory", and the
    resume it said to run failed the same way. It is refused by its size, and recomputed."""
    cancel = threading.Event()
    run_to_folder(build_scene(SMALL), tmp_path / "run", RunOptions(workers=1), listeners=[CancelAfter(3, cancel)],
                  cancel=cancel)  # fmt: skip
    chunk = tmp_path / "run" / "chunks" / min(json.loads((tmp_path / "run" / "run.json").read_text())["chunks"])
    os.truncate(chunk, 3 * 1024**3)  # sparse: past LIMIT, no disk
    done = ok(limited("resume", str(tmp_path / "run"), "--workers", "1", cwd=tmp_path))
    assert f"'{chunk.name}': file of {3 * 1024**3:,} bytes, more than the limit of " in done.stderr, done.stderr
    same_files(tmp_path / "run", reference)


def test_load_runs_and_follow_read_a_finished_run(tmp_path, reference):
    import frictionlab

    code = ("import json, sys, frictionlab\nr = frictionlab.load(sys.argv[1])\n"
            "print(json.dumps({'a': r.fit.a, 'b': r.fit.b, 'xi': [float(x) for x in r.table['xi']]}))\n")  # fmt: skip
    done = ok(subprocess.run([sys.executable, "-c", code, str(reference)], capture_output=True, text=True, timeout=120,
                             preexec_fn=_limit_address_space))  # fmt: skip
    here = frictionlab.load(reference)
    assert json.loads(done.stdout) == {"a": here.fit.a, "b": here.fit.b, "xi": [float(x) for x in here.table["xi"]]}
    listed = json.loads(ok(limited("runs", str(reference.parent), "--json", cwd=tmp_path)).stdout)
    assert "completed" in json.dumps(listed)
    ok(limited("follow", str(reference), cwd=tmp_path))


def test_report_with_figures_of_the_shrunk_paper_presets(tmp_path):
    from frictionlab.paper.figures import FIGURES

    presets = tmp_path / "presets"
    presets.mkdir()
    for fig in FIGURES:
        data = apply_overrides(load_preset_file(PRESETS / fig.preset), REPORT_SMALL)
        (presets / fig.preset).write_text(yaml.safe_dump(data, sort_keys=False))
    out, figures = tmp_path / "report", tmp_path / "figures"
    ok(limited("report", "--presets", str(presets), "--out", str(out), "--figures", str(figures), "--workers", "1", "--quiet",
               cwd=tmp_path))  # fmt: skip
    assert (out / "REPRODUCTION.md").is_file() and sorted(p.suffix for p in figures.iterdir()) == [".png"] * len(
        list(figures.iterdir())
    ) and any(figures.iterdir())
    fig2 = next(fig for fig in FIGURES if fig.key == "fig2")
    data = apply_overrides(load_preset_file(presets / fig2.preset), ["output.plot=false"])
    run_to_folder(build_scene(data), tmp_path / "fig2", RunOptions(workers=1))
    with np.load(out / "fig2" / "realizations.npz") as limited_run, np.load(tmp_path / "fig2" / "realizations.npz") as free:
        for name in free.files:
            np.testing.assert_array_equal(limited_run[name], free[name], err_msg=name)


def test_validate_of_an_instrument_file_says_what_an_unlimited_process_says(tmp_path):
    from SurfaceTopography import Topography

    z = np.random.default_rng(4).standard_normal((64, 64))
    Topography(z, (16.0, 16.0), unit="um").to_netcdf(str(tmp_path / "scan.nc"))
    preset = write(tmp_path, "scan", {**SMALL, "spectrum": {"name": "surface-file", "params": {"path": "scan.nc", "unit": "um"}}})
    under = ok(limited("validate", preset, cwd=tmp_path))
    free = subprocess.run([sys.executable, "-m", "frictionlab", "validate", preset], capture_output=True, text=True, cwd=tmp_path,
                          timeout=120)  # fmt: skip
    assert free.returncode == 0 and under.stdout == free.stdout and "scan.nc" in under.stdout


def test_a_sweep_gives_the_numbers_of_an_unlimited_sweep(tmp_path):
    from frictionlab.runs.sweep import plan_sweep, run_sweep

    ok(limited("run", write(tmp_path, "sweep", SWEEP), "--out", str(tmp_path / "sweep"), "--workers", "1", cwd=tmp_path))
    run_sweep(plan_sweep(SWEEP), tmp_path / "free", RunOptions(workers=1), plot=False)
    points = sorted(p.name for p in (tmp_path / "free" / "points").iterdir())
    assert len(points) == 2 and points == sorted(p.name for p in (tmp_path / "sweep" / "points").iterdir())
    for point in points:
        same_files(tmp_path / "sweep" / "points" / point, tmp_path / "free" / "points" / point)
    under, free = (_untimed_rows(tmp_path / folder / "sweep.csv") for folder in ("sweep", "free"))
    assert under == free and len(under) == 2


def _untimed_rows(path) -> list[dict]:
    """sweep.csv's rows without the time each point took."""
    import csv

    with open(path, newline="") as fh:
        return [{k: v for k, v in row.items() if k != "elapsed_s"} for row in csv.DictReader(fh)]


def test_an_exact_half_space_run_of_256_by_256_pixels(tmp_path):
    ok(limited("run", write(tmp_path, "half-space", HALF_SPACE), "--out", str(tmp_path / "run"), "--workers", "1", cwd=tmp_path))
    run_to_folder(build_scene(HALF_SPACE), tmp_path / "free", RunOptions(workers=1))
    same_files(tmp_path / "run", tmp_path / "free")


def test_a_run_that_needs_more_is_refused_before_it_starts_naming_the_limit(tmp_path):
    preset = write(tmp_path, "large", {**SMALL, "spectrum": {**SMALL["spectrum"], "params": {
        **SMALL["spectrum"]["params"], "points": 30_000_000}}})  # fmt: skip
    done = limited("run", preset, "--out", str(tmp_path / "run"), "--workers", "1", cwd=tmp_path)
    assert done.returncode == 1, done.stderr[-3000:]
    assert "the process limit RLIMIT_AS (ulimit -v)" in done.stderr and "spectrum.params.points <=" in done.stderr
    assert "Traceback" not in done.stderr and not (tmp_path / "run").exists()


def test_the_exact_3d_study_whose_finest_grid_does_not_fit_starts_nothing(tmp_path):
    """Under ulimit -v 1048576 the full study ran its 256² to 1024² grids for hours, then its
    2048² grid was refused. Every ensemble left to run is checked first: it ends at once."""
    def one_gib():
        resource.setrlimit(resource.RLIMIT_AS, (2**30, 2**30))

    command = [sys.executable, "-m", "frictionlab", "exact3d", "--runs", "runs", "--out", "page", "--workers", "1", "--quiet"]
    done = subprocess.run(command, capture_output=True, text=True, cwd=tmp_path, timeout=300, preexec_fn=one_gib)
    assert done.returncode == 1, done.stderr[-3000:]
    assert done.stderr.startswith("error: the exact 3D study starts nothing: its ensemble H = 0.8, 2048² px, exact")
    assert "RLIMIT_AS (ulimit -v)" in done.stderr and "--quick" in done.stderr and "Traceback" not in done.stderr
    assert not (tmp_path / "runs").exists() and not (tmp_path / "page").exists()


@pytest.mark.parametrize("workers", ["1", "2"])
def test_an_mdr_surface_whose_line_cannot_be_made_is_refused_and_the_side_offered_runs(tmp_path, workers):
    """An MDR run of a 16384^2 surface with every mode in its band: the check counted the
    line alone (18,488 points) and passed, then the surface's synthesis died of MemoryError
    ('out of memory: Unable to allocate 1.00 GiB ...'). It is refused before it is made,
    naming the making and a side, whose neighbourhood runs under the same limit."""
    surface = {**SMALL, "realizations": 2, "spectrum": {"name": "power-law-2d", "params": {
        "hurst": 0.8, "points": 16384, "spacing": 1.0, "short_cutoff": 2.0, "rms_height": 1.0}}}  # fmt: skip
    done = limited("run", write(tmp_path, "surface", surface), "--out", str(tmp_path / "run"), "--workers", workers,
                   cwd=tmp_path)  # fmt: skip
    assert done.returncode == 1, done.stderr[-3000:]
    assert "making the MDR-equivalent line of a surface of 268,435,456 points" in done.stderr, done.stderr[-3000:]
    assert "RLIMIT_AS (ulimit -v)" in done.stderr and "out of memory" not in done.stderr and "Traceback" not in done.stderr
    assert not (tmp_path / "run").exists()
    side = int(re.search(r"spectrum\.params\.points <= ([\d,]+)", done.stderr).group(1).replace(",", ""))
    assert 4000 < side < 16384
    # the room is the limit less the address space this process holds, which moves by a few MiB
    # from one process to the next: a side 16 under the offer (9 MiB less to make the line)
    fits = side - 16
    offered = {**surface, "spectrum": {**surface["spectrum"], "params": {**surface["spectrum"]["params"], "points": fits}}}
    ok(limited("run", write(tmp_path, "offered", offered), "--out", str(tmp_path / "fits"), "--workers", workers,
               "--no-plot", cwd=tmp_path))  # fmt: skip


@pytest.mark.parametrize("limit_mib", [60, 80, 100, 250])
@pytest.mark.parametrize("command", [["run", "quickstart", "--out", "run"], ["exact3d", "--quick", "--runs", "runs", "--workers", "1"]])
def test_a_limit_too_small_to_load_or_run_is_said_and_never_hangs(tmp_path, command, limit_mib):
    """Under ulimit -v 250000 OpenBLAS's import reserved a buffer per core, found no room and spun
    for ever inside the import, deaf to SIGTERM (exact3d); or exited with 'OpenBLAS error: Memory
    allocation still failed' (run; under 80 MiB on one thread, its one buffer); under 60000 a
    library that could not be mapped was an 'internal error ... (this is a bug)'. Each ends at
    once, saying the limit."""
    tight_run(command, limit_mib, tmp_path)


def tight_run(command, limit_mib, cwd) -> subprocess.CompletedProcess:
    """``frictionlab COMMAND --quiet`` under ``ulimit -v`` of ``limit_mib``: it must end at once,
    exit 1, saying the limit, in no words of a library's or a traceback."""
    def tight():
        resource.setrlimit(resource.RLIMIT_AS, (limit_mib * 2**20,) * 2)

    env = {name: value for name, value in os.environ.items() if not name.endswith("_NUM_THREADS")}
    done = subprocess.run([sys.executable, "-m", "frictionlab", *command, "--quiet"], capture_output=True, text=True,
                          cwd=cwd, timeout=60, preexec_fn=tight, env=env)  # fmt: skip
    assert done.returncode == 1, (done.returncode, done.stderr[-3000:])
    assert done.stderr.startswith("error: ") and "ulimit -v" in done.stderr, done.stderr[-3000:]
    assert not any(word in done.stderr for word in ("OpenBLAS", "internal error", "Traceback", "not installed"))
    return done


@pytest.mark.parametrize("limit_mib", [130, 160])
def test_an_instrument_file_whose_reader_cannot_load_is_said_as_the_limit_not_a_hang(tmp_path, limit_mib):
    """Reading a NetCDF scan loads SurfaceTopography and with it scipy's OpenBLAS, whose work
    buffer (32 MiB) is reserved as it loads. Under ulimit -v 163840 it found no room and spun
    for ever inside the import; under 133120 a library of it that could not be mapped (scipy
    raises it again as 'the install seems to be broken') was said 'instrument files are read by
    the optional extra topography: pip install', exit 2, with the extra installed."""
    from SurfaceTopography import Topography

    z = np.random.default_rng(4).standard_normal((64, 64))
    Topography(z, (16.0, 16.0), unit="um").to_netcdf(str(tmp_path / "scan.nc"))
    preset = write(tmp_path, "scan", {**SMALL, "spectrum": {"name": "surface-file", "params": {"path": "scan.nc", "unit": "um"}}})
    done = tight_run(["run", preset, "--no-plot", "--out", "run", "--workers", "1"], limit_mib, tmp_path)
    assert "out of memory loading " in done.stderr and not (tmp_path / "run").exists()


@pytest.mark.parametrize("workers", ["1", "2"])
def test_a_sweep_on_dask_runs_without_tracebacks_or_a_hang(tmp_path, workers):
    """Under ulimit -v 700000 the Dask cluster's threads (glibc's 64 MiB malloc arena each) took
    the main process's address space: 'RuntimeError: can't start new thread' tracebacks from
    tornado, then a hang. Each point now ends with its numbers, or refused before it starts."""
    def tight():
        resource.setrlimit(resource.RLIMIT_AS, (700_000 * 1024,) * 2)

    env = {name: value for name, value in os.environ.items() if not name.startswith("MALLOC_")}
    command = [sys.executable, "-m", "frictionlab", "run", write(tmp_path, "sweep", SWEEP), "--out", "out",
               "--executor", "dask", "--workers", workers, "--quiet"]  # fmt: skip
    done = subprocess.run(command, capture_output=True, text=True, cwd=tmp_path, timeout=120, preexec_fn=tight, env=env)
    assert done.returncode in (0, 1) and not any(word in done.stderr for word in ("Traceback", "OpenBLAS")), done.stderr[-3000:]
    rows = json.loads((tmp_path / "out" / "sweep.json").read_text())["points"]
    assert all(row["status"] == "completed" or "would need about" in row["error"] for row in rows), rows


def test_malloc_arenas_are_held_back_under_a_process_limit_unless_told(monkeypatch):
    from frictionlab.compute import heap

    monkeypatch.setenv("MALLOC_ARENA_MAX", "")  # set, then removed: given back as it was after the test
    monkeypatch.delenv("MALLOC_ARENA_MAX")
    monkeypatch.setattr(heap, "process_limit", lambda: None)
    heap.spare_address_space_under_a_limit()
    assert "MALLOC_ARENA_MAX" not in os.environ  # no limit
    monkeypatch.setattr(heap, "process_limit", lambda: (2**30, "-v"))
    monkeypatch.setenv("MALLOC_ARENA_MAX", "8")
    heap.spare_address_space_under_a_limit()
    assert os.environ["MALLOC_ARENA_MAX"] == "8"  # the user's count stands
    monkeypatch.delenv("MALLOC_ARENA_MAX")
    heap.spare_address_space_under_a_limit()
    assert os.environ["MALLOC_ARENA_MAX"] == "2"


@pytest.mark.parametrize("chosen", [None, "OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS"])
def test_the_command_runs_openblas_on_one_thread_unless_the_user_chose_a_count(chosen):
    """Set before numpy is imported (OpenBLAS reads it as it loads), in the command's process
    whatever its memory limit: what the command's own code then finds, and what numpy's
    OpenBLAS runs with."""
    script = (
        "import importlib, json, sys\n"
        "command = importlib.import_module('frictionlab.cli.main')  # the package names its function main too\n"
        "def main(argv=None):\n"
        "    before = 'numpy' in sys.modules\n"
        "    import os, numpy, threadpoolctl\n"
        "    blas = [lib['num_threads'] for lib in threadpoolctl.threadpool_info() if lib['internal_api'] == 'openblas']\n"
        "    print(json.dumps([before, os.environ.get('OPENBLAS_NUM_THREADS'), blas]))\n"
        "    return 0\n"
        "command.main = main\n"
        "sys.argv = ['frictionlab', 'validate', 'quickstart']\n"
        "command.program()\n"
    )
    env = {k: v for k, v in os.environ.items() if k not in ("OPENBLAS_NUM_THREADS", "GOTO_NUM_THREADS", "OMP_NUM_THREADS")}
    if chosen:
        env[chosen] = "2"
    done = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, env=env, check=True)
    numpy_before, told, blas = json.loads(done.stdout.strip().splitlines()[-1])
    assert not numpy_before and blas
    if chosen is None:
        assert told == "1" and blas == [1] * len(blas)
    else:
        assert told == (None if chosen != "OPENBLAS_NUM_THREADS" else "2")  # left as the user set it

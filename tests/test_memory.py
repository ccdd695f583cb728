"""The peak-memory estimate: an upper bound of what a run really takes, and a
refusal that names the estimate, the limit and a setting that fits."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from frictionlab import memory
from frictionlab.cli import main
from frictionlab.errors import RunError
from frictionlab.preset import build_scene

from .conftest import SMALL_PRESET, merge

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


# Full contact at the largest force: every point is sorted, the costliest case of the spring sweep.
FULL_CONTACT = {"loading": {"start": 1e9, "stop": 1e10, "steps": 16}}


@pytest.mark.parametrize(
    "points, changes",
    [
        (300_000, FULL_CONTACT),
        (2_000_000, {**FULL_CONTACT, "output": {"plot": False}}),
        # the large grid of the README (1e7 points, about 1 GiB at full contact)
        pytest.param(10_000_000, {**FULL_CONTACT, "output": {"plot": False}}, marks=pytest.mark.slow),
    ],
    ids=["3e5-with-plot", "2e6", "1e7"],
)
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
    offered = int(caught.value.args[0].split("points <= ")[1].split(".")[0].replace(",", ""))
    fits = memory.estimate(scene, workers=1, executor="processes", points=offered).total
    too_many = memory.estimate(scene, workers=1, executor="processes", points=offered + 1).total
    assert fits <= GiB < too_many


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
    assert main(["run", str(path), "--out", str(tmp_path / "out"), "--workers", "1", "--quiet", "--no-memory-check"]) == 0


def test_available_memory_is_positive_and_below_the_machine_total():
    available, source = memory.available_memory()
    total = next(int(line.split()[1]) * 1024 for line in Path("/proc/meminfo").read_text().splitlines() if line.startswith("MemTotal:"))
    assert 0 < available <= total
    assert source

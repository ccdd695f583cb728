"""The advice of a memory refusal under a process limit (``ulimit -v``): a limit too small
for frictionlab itself is said so with the limit that fits, a grid too large is offered the
smaller grid or the higher limit, and the limit offered runs."""

from __future__ import annotations

import re
import subprocess
import sys

import pytest

from frictionlab.compute import memory
from frictionlab.errors import RunError
from frictionlab.preset import build_scene

from .conftest import merge
from .test_memory import GiB, MiB, _under_a_process_limit, line_of


@pytest.mark.parametrize("workers, executor", [(1, "serial"), (2, "processes")])
@pytest.mark.parametrize("points", [4096, 2**20])  # a line of the quickstart's, a surface of the exact runs'
def test_a_limit_too_small_for_frictionlab_itself_is_said_with_the_limit_that_fits(registry, monkeypatch, workers, executor, points):
    """Under a limit that leaves less than frictionlab itself needs, the advice was 'fewer points: making
    the MDR-equivalent line of a surface of 4,096 points alone needs 0 MiB (a measured map: crop it...)'
    for a line, or for a surface on the half-space; no setting of the preset helps, a higher limit does."""
    two_d = {"spectrum": {"name": "power-law-2d", "params": {"points": 1024, "length": 128.0, "hurst": 0.8}},
             "solver": {"name": "bem-halfspace"}}  # fmt: skip
    scene = build_scene(line_of(points) if points == 4096 else merge(line_of(4), two_d), registry=registry)
    room = 30 * MiB
    _under_a_process_limit(monkeypatch, room)
    monkeypatch.setattr("resource.getrlimit", lambda which: (200 * MiB, -1))
    with pytest.raises(RunError) as caught:
        memory.check_fits(scene, workers=workers, executor=executor)
    message = str(caught.value)
    assert "measured" not in message and "0 MiB (" not in message
    limit = int(re.search(r"It would fit with a higher limit: ulimit -v (\d+) or more\.", message).group(1))
    guess = memory.estimate(scene, workers=workers, executor=executor)
    need = guess.total if executor == "serial" else memory._largest_process(guess)
    assert 200 * MiB - room + need <= limit * 1024 <= (200 * MiB - room + need) * 1.03 + MiB


def test_a_grid_too_large_for_the_limit_offers_the_grid_or_the_limit_that_fits(registry, monkeypatch):
    scene = build_scene(line_of(20_000_000), registry=registry)  # 2.1 GiB a realization
    _under_a_process_limit(monkeypatch, 1 * GiB)
    monkeypatch.setattr("resource.getrlimit", lambda which: (GiB + 200 * MiB, -1))
    for workers, executor in ((1, "serial"), (4, "processes")):
        with pytest.raises(RunError, match=r"It would fit with spectrum\.params\.points <= [\d,]+, or with a higher "
                                           r"limit: ulimit -v \d+ or more\."):  # fmt: skip
            memory.check_fits(scene, workers=workers, executor=executor)


@pytest.mark.long  # two processes of seconds each
def test_the_limit_a_refusal_offers_runs(tmp_path):
    """The ulimit -v a refusal names is enough for the run it refused (what the process
    holds once loaded is counted, with the kB it differs by from one start to the next)."""
    run = [sys.executable, "-m", "frictionlab", "run", "quickstart", "--set", f"spectrum.params.points={2**23}",
           "--set", "realizations=1", "--no-plot", "--quiet", "--workers", "1", "--out"]  # fmt: skip

    def under(limit_kib: int, out: str) -> subprocess.CompletedProcess:
        limited = lambda: __import__("resource").setrlimit(__import__("resource").RLIMIT_AS, (limit_kib * 1024,) * 2)
        return subprocess.run([*run, out], capture_output=True, text=True, cwd=tmp_path, timeout=300, preexec_fn=limited)

    refused = under(1024 * 1024, "refused")
    assert refused.returncode == 1 and not (tmp_path / "refused").exists(), refused.stderr
    limit = int(re.search(r"ulimit -v (\d+) or more", refused.stderr).group(1))
    done = under(limit, "done")
    assert done.returncode == 0 and "Traceback" not in done.stderr, done.stderr

"""Under a limit on memory the run's work is on disk before its fit: OpenBLAS ends a process
it cannot give its buffer (at the fit's first call, after every realization), past Python's
reach, and a short run's one chunk was written only after the fit, so nothing was kept."""

from __future__ import annotations

import json
import subprocess
import sys

import pytest

from .conftest import PRESETS

RUN = f"""
import os, resource, sys
if sys.argv[1] == "limit":
    resource.setrlimit(resource.RLIMIT_AS, (64 * 2**30, resource.RLIM_INFINITY))  # a limit, far above the run's need
from frictionlab.compute import ensemble
def fit_ends_the_process(*args, **keys):
    os._exit(9)  # as OpenBLAS does where the limit leaves no room for its buffer
ensemble.fit_log_law = fit_ends_the_process
from frictionlab.cli import main
main(["run", {str(PRESETS / "quickstart.yaml")!r}, "--out", "run", "--quiet", "--no-plot", "--workers", "1",
      "--set", "realizations=6"])
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="a process limit on address space")
@pytest.mark.parametrize("limit", ["limit", "none"])
def test_a_process_ended_at_the_fit_keeps_its_realizations_under_a_memory_limit(tmp_path, limit):
    ended = subprocess.run([sys.executable, "-c", RUN, limit], capture_output=True, text=True, cwd=tmp_path)
    assert ended.returncode == 9, ended.stderr
    chunks = sorted(path.name for path in (tmp_path / "run" / "chunks").glob("*.npz"))
    # without a limit OpenBLAS has its buffer already: the run keeps its one write, after the fit
    assert chunks == (["00000000-00000005.npz"] if limit == "limit" else [])
    if limit == "limit":
        resumed = subprocess.run([sys.executable, "-m", "frictionlab", "resume", "run", "--quiet", "--no-plot"],
                                 capture_output=True, text=True, cwd=tmp_path)  # fmt: skip
        assert resumed.returncode == 0, resumed.stderr
        summary = json.loads((tmp_path / "run" / "summary.json").read_text())
        assert summary["resumed_realizations"] == 6 and summary["realizations"]["done"] == 6

"""Under a process limit on memory, OpenBLAS's work buffer is mapped as a command starts:
mapped at the fit (after the realizations) it could exit the process with nothing
written. Here the limit leaves less room than the buffer once reserved, and the fit's
least squares still runs."""

from __future__ import annotations

import subprocess
import sys

import pytest

CODE = """
import os, resource
os.environ["OPENBLAS_NUM_THREADS"] = "1"
resource.setrlimit(resource.RLIMIT_AS, (8 * 2**30, resource.RLIM_INFINITY))  # a limit: the buffer is reserved
from frictionlab.compute.heap import reserve_blas_buffer
reserve_blas_buffer()
import numpy as np
pages = int(open("/proc/self/statm").read().split()[0]) * resource.getpagesize()
resource.setrlimit(resource.RLIMIT_AS, (pages + 16 * 2**20, resource.RLIM_INFINITY))  # less than OpenBLAS's buffer
coef = np.linalg.lstsq(np.vander(np.arange(40.0), 2), np.arange(40.0), rcond=None)[0]
print(round(float(coef[0]), 6))
"""


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="a process limit on address space, /proc")
def test_the_fit_finds_the_blas_buffer_reserved_under_a_tight_limit():
    done = subprocess.run([sys.executable, "-c", CODE], capture_output=True, text=True, timeout=120)
    assert done.returncode == 0, done.stderr
    assert abs(float(done.stdout) - 1.0) < 1e-9

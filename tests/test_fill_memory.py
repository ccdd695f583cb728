"""The memory of filling a map's points not measured (``undefined: harmonic``, a sparse Laplace
solve) is estimated before the fill starts: the estimate bounds the fill's real peak (the growth
of the peak resident memory of a fresh process: the solve's LU factors are allocated where
Python's tracing does not see them), and a fill that does not fit is refused by name before it
takes the memory. Linux only (the peak is read from /proc)."""

from __future__ import annotations

import subprocess
import sys

import numpy as np
import pytest

from frictionlab_spectra import SurfaceFile, instrument_reader
from frictionlab_spectra.scan_shaping import filling
from frictionlab_spectra.scan_shaping.filling import harmonic_fill_bytes

pytestmark = pytest.mark.skipif(not sys.platform.startswith("linux"), reason="the peak is read from /proc")

# A fresh process fills a map of N x N with a square hole (the worst shape for the fill) or
# scattered ones, and prints the holes and the growth of its peak memory over the fill: resident,
# and in address space (what ulimit -v limits; the peak before it, of the imports, may be higher).
_FILL = """
import sys
import numpy as np, scipy.sparse.linalg
from frictionlab_spectra.scan_shaping.filling import fill_harmonic
n, shape = int(sys.argv[1]), sys.argv[2]
z = np.random.default_rng(0).normal(size=(n, n))
if shape == "square":
    z[n // 4 : 3 * n // 4, n // 4 : 3 * n // 4] = np.nan
else:
    z.ravel()[np.random.default_rng(1).choice(n * n, n * n // 3, replace=False)] = np.nan
holes = int(np.count_nonzero(np.isnan(z)))
def status_kib(field):
    for line in open("/proc/self/status"):
        if line.startswith(field + ":"):
            return int(line.split()[1])
with open("/proc/self/clear_refs", "w") as fh:  # the peak from here on
    fh.write("5")
before, reserved = status_kib("VmRSS"), status_kib("VmSize")
fill_harmonic(z)
assert not np.isnan(z).any()
print(holes, (status_kib("VmHWM") - before) * 1024, (status_kib("VmPeak") - reserved) * 1024)
"""


@pytest.mark.parametrize("shape", ["square", "scattered"])
def test_the_estimate_bounds_the_fills_real_peak(tmp_path, shape):
    script = tmp_path / "fill.py"
    script.write_text(_FILL)
    done = subprocess.run([sys.executable, str(script), "256", shape], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0, done.stderr
    holes, resident, reserved = map(int, done.stdout.split())
    for peak, estimate in ((resident, harmonic_fill_bytes((256, 256), holes)),
                           (reserved, harmonic_fill_bytes((256, 256), holes, reserved=True))):  # fmt: skip
        assert peak <= estimate, (holes, peak, estimate)
        if shape == "square":  # the shape it is made for: not far above it either
            assert estimate <= 1.6 * peak, (holes, peak, estimate)


def test_a_fill_that_does_not_fit_is_refused_before_it_starts(tmp_path, monkeypatch):
    z = np.random.default_rng(2).normal(size=(32, 32))
    z[8:24, 8:24] = np.nan
    np.save(tmp_path / "holes.npy", z)

    def must_not_fill(*args, **kwargs):
        raise AssertionError("the fill started")

    monkeypatch.setattr(filling, "fill_harmonic", must_not_fill)
    for address_space in (False, True):  # the memory in use, or ulimit -v: what the fill keeps, or reserves
        need = harmonic_fill_bytes(z.shape, 256, reserved=address_space)
        monkeypatch.setattr(instrument_reader, "memory_rooms", lambda: [(need - 1, "a test limit", address_space)])
        with pytest.raises(ValueError, match=r"filling its 256 points not measured \(undefined: harmonic\) takes about "
                                             r"[\d.e-]+ GiB, more than the [\d.e-]+ GiB this process may use \(a test limit\)"):
            SurfaceFile(path=str(tmp_path / "holes.npy"), spacing=1.0, undefined="harmonic").rms_height()
    monkeypatch.undo()
    monkeypatch.setattr(instrument_reader, "memory_rooms", lambda: [(need, "a test limit", True)])
    assert SurfaceFile(path=str(tmp_path / "holes.npy"), spacing=1.0, undefined="harmonic").rms_height() > 0

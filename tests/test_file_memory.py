"""The memory check sees a measured file's grid from its header (a .npy's, an instrument
file's metadata) and refuses an oversize map before the file is read: the growth of the
peak memory over ``frictionlab run`` / ``validate`` in a fresh process stays far below the
file's size, while the same command given room to read it grows by at least the file.
Linux only (the peak is read from /proc)."""

from __future__ import annotations

import subprocess
import sys
import warnings

import numpy as np
import pytest
import yaml

from frictionlab.errors import ExitCode

MiB = 2**20

# A fresh process: imports everything a command needs, lowers the memory the check sees,
# then runs the command and reports its exit code and the growth of its peak memory.
_MEASURE = """
import sys
import numpy, scipy.fft, yaml
import frictionlab.runs.runner, frictionlab.compute.engine, frictionlab_spectra, frictionlab_solvers
from frictionlab import memory
from frictionlab.cli.main import main
try:
    import SurfaceTopography.IO, SurfaceTopography.Support.UnitConversion
except ImportError:
    pass
available = int(sys.argv[1])
memory.available_memory = lambda: (available, "a test limit")
def status_kib(field):
    for line in open("/proc/self/status"):
        if line.startswith(field + ":"):
            return int(line.split()[1])
# the peak from here on: the imports' own high-water mark (higher than the memory in use now
# on some runs) would hide a read of the file; clear_refs 5 resets it to what is in use now
with open("/proc/self/clear_refs", "w") as fh:
    fh.write("5")
before = status_kib("VmRSS")
code = main(sys.argv[2:])
print("EXIT", int(code), "GROWTH_KIB", status_kib("VmHWM") - before)
"""


def preset(path, **params) -> dict:
    return {
        "name": "big-scan", "seed": 1, "realizations": 1, "fit": {"bootstrap": 0},
        "spectrum": {"name": "surface-file", "params": {"path": str(path), **params}},
        "solver": {"name": "winkler"}, "slope": {"name": "central-difference"},
        "loading": {"start": 0.01, "stop": 0.2, "steps": 4, "spacing": "log"},
    }  # fmt: skip


def measure(tmp_path, available: int, *command: str) -> tuple[int, int, str]:
    """Exit code, growth of peak memory in bytes, stderr of ``frictionlab COMMAND`` in a fresh process."""
    script = tmp_path / "measure.py"
    script.write_text(_MEASURE)
    done = subprocess.run([sys.executable, str(script), str(available), *command], capture_output=True, text=True,
                          timeout=300, cwd=tmp_path)  # fmt: skip
    assert "EXIT" in done.stdout, done.stdout + done.stderr
    fields = done.stdout.split("EXIT ")[1].split()
    return int(fields[0]), int(fields[2]) * 1024, done.stderr


def check_refused_unread(tmp_path, data: dict, size: int, available: int) -> None:
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(data))
    for command in (["run", "p.yaml", "--out", "out", "--workers", "1", "--quiet"], ["validate", "p.yaml"]):
        code, growth, err = measure(tmp_path, available, *command)
        assert code == ExitCode.RUNTIME_FAILURE, err
        assert "this run would need about " in err and "a test limit" in err, err
        assert "Traceback" not in err
        assert growth < size / 4, (command, growth, size)
    assert not (tmp_path / "out").exists()
    # given room, validate reads the file: the measurement sees a read
    code, growth, err = measure(tmp_path, 2**50, "validate", "p.yaml")
    assert growth > size / 2, (growth, size, err)


def rough_npy(path, side: int) -> int:
    """A .npy of ``side``^2 float64 heights that vary (a constant map is refused once read,
    ); its size in bytes."""
    x = np.sin(np.arange(side) * 0.37)
    heights = np.lib.format.open_memmap(path, mode="w+", dtype=np.float64, shape=(side, side))
    for row in range(0, side, 256):
        heights[row : row + 256] = x[row : row + 256, None] * x[None, :]
    heights.flush()
    del heights
    return path.stat().st_size


@pytest.mark.long
def test_an_npy_map_too_large_is_refused_from_its_header_before_it_is_read(tmp_path):
    size = rough_npy(tmp_path / "big.npy", 4096)  # 128 MiB
    check_refused_unread(tmp_path, preset(tmp_path / "big.npy", spacing=1.0), size, available=1024 * MiB)


@pytest.mark.long
def test_an_instrument_map_too_large_is_refused_from_its_metadata_before_it_is_read(tmp_path):
    topography_module = pytest.importorskip("SurfaceTopography")  # the optional extra topography
    side = 4096
    x = np.arange(side) / side
    z = np.sin(2 * np.pi * 3 * x)[:, None] * np.cos(2 * np.pi * 5 * x)[None, :]
    topography = topography_module.Topography(z, (1.0, 1.0), unit="um")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        topography.to_netcdf(str(tmp_path / "big.nc"))
    size = z.nbytes  # 128 MiB of heights; the file holds them as float64 too
    assert (tmp_path / "big.nc").stat().st_size >= size
    check_refused_unread(tmp_path, preset(tmp_path / "big.nc"), size, available=256 * MiB)


def test_a_file_spectrum_knows_its_shape_and_periodicity_from_the_header(tmp_path):
    from frictionlab_spectra import ProfileFile, SurfaceFile

    np.save(tmp_path / "map.npy", np.arange(12 * 20, dtype=np.float64).reshape(12, 20) % 7)
    surface = SurfaceFile(path=str(tmp_path / "map.npy"), spacing=1.0)
    assert surface.grid_shape() == (12, 20) and surface.periodic() is False
    assert "_cached__map" not in surface.__dict__  # the map itself was not read
    assert surface.generate(None).heights.shape == (12, 20)
    for stored in (np.arange(30.0) % 4, np.stack([np.arange(30.0), np.arange(30.0) % 4]),
                   np.stack([np.arange(30.0), np.arange(30.0) % 4], axis=1), (np.arange(30.0) % 4)[None, :]):  # fmt: skip
        np.save(tmp_path / "line.npy", stored)
        line = ProfileFile(path=str(tmp_path / "line.npy"), **({} if stored.ndim == 2 and 2 in stored.shape else
                                                                {"spacing": 1.0}))  # fmt: skip
        assert line.grid_shape() == (30,) == line.generate(None).heights.shape

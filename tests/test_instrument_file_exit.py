"""Reading an instrument file ends the command with its documented exit code, never a
signal.

An HDF5 file with two data sets and no physical size is refused (exit 2) by
SurfaceTopography's HDF5 reader, which opens the file through h5py on the Python file
object it is given. A reader left open held that h5py file until libhdf5's own exit
handler closed it, after the interpreter had finalized: h5py's close callback then took
the GIL of an interpreter that was gone (SIGSEGV, exit 139, after the right message).
Each case runs the ``frictionlab`` command in a process of its own, as a user does.
"""

from __future__ import annotations

import re
import subprocess
import sys

import h5py
import numpy as np
import pytest
import yaml

from frictionlab.errors import ExitCode


def write_two_data_sets(path):
    rng = np.random.default_rng(7)
    with h5py.File(path, "w") as h5:
        h5["first"] = rng.standard_normal((16, 16))
        h5["second"] = rng.standard_normal((16, 16))


def write_netcdf(path):
    from SurfaceTopography import Topography  # here, not at the top: its import takes seconds, paid only where a test writes such a file

    z = np.random.default_rng(8).standard_normal((16, 16))
    Topography(z, (4.0, 4.0), unit="um").to_netcdf(str(path))


def preset(folder, name, spectrum, file_name):
    path = folder / f"{name}.yaml"
    path.write_text(yaml.safe_dump({
        "name": name, "seed": 1, "realizations": 1, "fit": {"bootstrap": 0},
        "spectrum": {"name": spectrum, "params": {"path": file_name, "unit": "um"}},
        "solver": {"name": "mdr"}, "loading": {"start": 0.1, "stop": 3.0, "steps": 3},  # from a few points to most: a law
    }))  # fmt: skip
    return str(path)


def frictionlab(*args, cwd):
    return subprocess.run([sys.executable, "-m", "frictionlab", *args], capture_output=True, text=True, cwd=cwd, timeout=120)


@pytest.fixture
def files(tmp_path):
    write_two_data_sets(tmp_path / "two.h5")
    write_netcdf(tmp_path / "scan.nc")
    return {
        "h5 surface": preset(tmp_path, "h5-surface", "surface-file", "two.h5"),
        "h5 profile": preset(tmp_path, "h5-profile", "profile-file", "two.h5"),
        "nc": preset(tmp_path, "nc", "surface-file", "scan.nc"),
    }


@pytest.mark.long  # a process of its own for each command: SurfaceTopography's import takes seconds
@pytest.mark.parametrize("order", [("h5 surface", "h5 profile", "nc"), ("nc", "h5 profile", "h5 surface")])
def test_hdf5_files_without_physical_size_and_a_netcdf_file_read_back_to_back_in_one_process(tmp_path, files, order):
    done = frictionlab("validate", *(files[which] for which in order), cwd=tmp_path)
    assert done.returncode == ExitCode.USAGE, (done.returncode, done.stderr[-2000:])  # not -11 (SIGSEGV)
    assert "nc.yaml: ok" in done.stdout
    for name in ("h5-surface.yaml", "h5-profile.yaml"):
        assert f"{name}: 1 problem in preset" in done.stderr, done.stderr
    assert len(re.findall(r"two\.h5': the [^']+? file does not state its physical size", done.stderr)) == 2, done.stderr


@pytest.mark.long
def test_a_netcdf_file_alone_validates_and_runs_with_exit_0(tmp_path, files):
    for command in (["validate", files["nc"]], ["run", files["nc"], "--out", str(tmp_path / "out"), "--no-plot"]):
        done = frictionlab(*command, cwd=tmp_path)
        assert done.returncode == 0, (command, done.returncode, done.stderr[-2000:])

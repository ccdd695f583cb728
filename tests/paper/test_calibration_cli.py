"""`python -m frictionlab.paper.calibration`: usage and input errors in a line, no traceback."""

import subprocess
import sys

import pytest

from frictionlab.paper import calibration


def calibrate(*args: str, cwd=None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "frictionlab.paper.calibration", *args],
        capture_output=True, text=True, timeout=60, cwd=cwd,
    )  # fmt: skip


def test_no_preset_prints_the_usage_and_exits_2():
    done = calibrate()
    assert done.returncode == 2
    assert "usage: python -m frictionlab.paper.calibration" in done.stderr and "preset" in done.stderr
    assert "Traceback" not in done.stderr


def test_a_missing_preset_is_named_with_the_preset_file_exit_code(tmp_path):
    missing = tmp_path / "nowhere.yaml"
    done = calibrate(str(missing))
    assert done.returncode == 3
    assert str(missing) in done.stderr and "no such preset file" in done.stderr
    assert "Traceback" not in done.stderr


class Stop(Exception):
    pass


def test_a_built_in_name_is_calibrated_from_any_folder(tmp_path, monkeypatch):
    """As frictionlab run takes it: the built-in's name where no such file is (the ensemble itself not run here)."""
    monkeypatch.chdir(tmp_path)
    read = []

    def stop(data, *args, **kwargs):
        read.append(data)
        raise Stop

    monkeypatch.setattr(calibration, "count_curve", stop)
    with pytest.raises(Stop):
        calibration.main("benad2012-fig2")
    assert read[0]["name"] == "benad2012-fig2" and read[0]["realizations"] == 300


def test_the_clone_s_path_outside_the_clone_names_the_built_in(tmp_path):
    done = calibrate("presets/benad2012-fig2.yaml", cwd=tmp_path)
    assert done.returncode == 3 and "Traceback" not in done.stderr
    assert "the built-in preset of that name is 'benad2012-fig2'" in done.stderr

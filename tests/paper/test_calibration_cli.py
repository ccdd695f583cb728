"""`python -m frictionlab.paper.calibration`: usage and input errors in a line, no traceback."""

import subprocess
import sys


def calibrate(*args: str) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "frictionlab.paper.calibration", *args], capture_output=True, text=True, timeout=60
    )


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

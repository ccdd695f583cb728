"""`python -m frictionlab.paper.calibration`: usage and input errors in a line, no traceback."""

import os
import signal
import subprocess
import sys

import pytest

from frictionlab import hookimpl
from frictionlab.compute import signals
from frictionlab.compute.signals import WorkInterrupted
from frictionlab.options import RunOptions
from frictionlab.paper import calibration
from frictionlab.preset import load_preset_file
from frictionlab.preset.builtin import resolve_preset_path


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


class InterruptAtFirstRealization:
    """Ctrl-C as the first line finishes: the run's own handler cancels the rest."""

    @hookimpl
    def realization_done(self, done):
        if done == 1:
            os.kill(os.getpid(), signal.SIGINT)


def test_an_interrupted_calibration_gives_no_h_from_part_of_its_ensemble():
    """Ctrl-C ended the calibration's ensemble early, and the h of the lines that had finished
    was printed as the answer, with exit code 0."""
    data = load_preset_file(resolve_preset_path("quickstart"))
    data["realizations"] = 6
    with pytest.raises(WorkInterrupted, match=r"ended interrupted after 1 of 6 realizations; no h from a part of it"):
        calibration.count_curve(data, RunOptions(workers=1, executor="serial"), [InterruptAtFirstRealization()])


def test_an_interrupted_calibration_is_said_in_a_line_with_the_signal_s_exit_code(monkeypatch, capsys):
    def interrupted(*args, **kwargs):
        signals.received.append(signal.SIGINT)
        raise WorkInterrupted("the calibration's ensemble ended interrupted after 1 of 6 realizations")

    monkeypatch.setattr(signals, "received", [])
    monkeypatch.setattr(calibration, "count_curve", interrupted)
    try:
        code = calibration.cli(["quickstart"])
    except KeyboardInterrupt:
        pytest.fail("the interrupt escaped as a traceback")
    assert code == 130
    out, err = capsys.readouterr()
    assert out == "" and err == "frictionlab: interrupted: the calibration's ensemble ended interrupted after 1 of 6 realizations\n"


def test_a_closed_pipe_ends_the_calibration_quietly(tmp_path):
    """`python -m frictionlab.paper.calibration PRESET | head -0`: no traceback, the closed
    pipe's exit code, as every frictionlab command ends on one."""
    from frictionlab.errors import ExitCode

    preset = tmp_path / "small.yaml"
    preset.write_text(resolve_preset_path("benad2012-fig2").read_text().replace("realizations: 300", "realizations: 4")
                      .replace("points: 100000", "points: 2000").replace("length: 100000.0", "length: 2000.0"))  # fmt: skip
    read_end, write_end = os.pipe()
    os.close(read_end)
    try:
        done = subprocess.run([sys.executable, "-m", "frictionlab.paper.calibration", str(preset)], stdout=write_end,
                              stderr=subprocess.PIPE, timeout=120)  # fmt: skip
    finally:
        os.close(write_end)
    assert done.stderr == b"" and done.returncode == ExitCode.BROKEN_PIPE

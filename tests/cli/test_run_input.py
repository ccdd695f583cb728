"""``frictionlab run`` of a measured file says what it read, as ``validate`` does: once,
under the progress's first line; nothing under ``--quiet``, nothing for a generated surface."""

import numpy as np
import pytest

import frictionlab
from frictionlab.cli import main
from frictionlab.errors import ExitCode

from ..conftest import SMALL_PRESET, merge
from .conftest import write_preset


def _measured(tmp_path, **changes) -> dict:
    x = np.arange(1024)
    heights = 3.0 * np.cos(2 * np.pi * x / 256) + 0.05 * np.sin(2 * np.pi * x / 16) + 0.002 * x
    np.savetxt(tmp_path / "scan.csv", heights)
    spectrum = {"name": "profile-file", "params": {"path": str(tmp_path / "scan.csv"), "spacing": 0.5, "detrend": "tilt"}}
    return merge({**SMALL_PRESET, "name": "scan", "realizations": 1, "spectrum": spectrum}, changes)


def _read_lines(text: str) -> list[str]:
    return [line for line in text.splitlines() if line.lstrip().startswith("read ")]


def test_a_run_of_a_measured_file_says_what_validate_says_it_read(tmp_path, capsys):
    preset = write_preset(tmp_path, _measured(tmp_path))
    assert main(["validate", str(preset)]) == ExitCode.OK
    validated = _read_lines(capsys.readouterr().out)
    assert len(validated) == 1 and "scan.csv" in validated[0] and "detrend tilt (preset)" in validated[0]
    assert main(["run", str(preset), "--out", str(tmp_path / "o"), "--workers", "1", "--no-plot"]) == ExitCode.OK
    captured = capsys.readouterr()
    assert _read_lines(captured.err) == validated and not _read_lines(captured.out)  # stdout: the table alone
    first, read = captured.err.splitlines()[:2]
    assert first.startswith("scan: 1 realization of ") and read == validated[0]  # before any progress
    assert main(["run", str(preset), "--out", str(tmp_path / "q"), "--quiet", "--no-plot"]) == ExitCode.OK
    assert capsys.readouterr().err == ""


def test_a_generated_surface_prints_no_read_line(tmp_path, capsys):
    preset = write_preset(tmp_path, SMALL_PRESET)
    assert main(["run", str(preset), "--out", str(tmp_path / "o"), "--workers", "1", "--no-plot"]) == ExitCode.OK
    err = capsys.readouterr().err
    assert err.startswith("small: 8 realizations of power-law lines, 16 force steps, 1 worker(s)\n")
    assert not _read_lines(err)


def test_a_sweep_says_a_file_read_alike_once_and_each_reading_that_differs(tmp_path, capsys):
    same = _measured(tmp_path, sweep={"parameters": {"solver.params.youngs_modulus": {"values": [1.0, 2.0]}}})
    assert main(["run", str(write_preset(tmp_path, same)), "--out", str(tmp_path / "a"), "--workers", "1",
                 "--no-plot"]) == ExitCode.OK  # fmt: skip
    assert len(_read_lines(capsys.readouterr().err)) == 1
    levelled = _measured(tmp_path, sweep={"parameters": {"spectrum.params.detrend": {"values": ["mean", "tilt"]}}})
    assert main(["run", str(write_preset(tmp_path, levelled)), "--out", str(tmp_path / "b"), "--workers", "1",
                 "--no-plot"]) == ExitCode.OK  # fmt: skip
    said = _read_lines(capsys.readouterr().err)
    assert len(said) == 2 and "detrend mean" in said[0] and "detrend tilt" in said[1]


def test_the_python_api_says_it_with_its_progress_and_keeps_it_on_the_result(tmp_path, capsys):
    data = _measured(tmp_path)
    result = frictionlab.run(data, workers=1, plot=False, out=tmp_path / "o")
    said = _read_lines(capsys.readouterr().err)
    assert len(said) == 1 and "scan.csv" in said[0]
    assert result.input["detrend"] == "tilt" and frictionlab.load(tmp_path / "o").input == result.input
    frictionlab.run(data, workers=1, plot=False, progress=False)
    assert not _read_lines(capsys.readouterr().err)


@pytest.mark.parametrize("scan_name, preset_name", [("curve.csv", "mine.yaml"), ("scan.csv", "preset.yaml")])
def test_force_into_the_folder_of_its_own_scan_or_preset_replaces_neither(tmp_path, capsys, scan_name, preset_name):
    """Found by a hostile-input audit: ``run preset.yaml --out . --force`` in the folder of a scan
    named curve.csv replaced the scan by the results table (and the preset by the run's copy):
    the run then could not even be resumed. Refused before anything is computed (exit 4)."""
    data = _measured(tmp_path)
    (tmp_path / "scan.csv").rename(tmp_path / scan_name)
    data["spectrum"]["params"]["path"] = scan_name  # beside the preset, as a user keeps them
    preset = write_preset(tmp_path, data, preset_name)
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()}
    assert main(["run", str(preset), "--out", str(tmp_path), "--force", "--quiet", "--no-plot"]) == ExitCode.OUTPUT_REFUSED
    err = capsys.readouterr().err
    assert ("is this run's input" in err) if scan_name == "curve.csv" else ("is the preset being run" in err), err
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir() if p.is_file()} == before  # nothing written over

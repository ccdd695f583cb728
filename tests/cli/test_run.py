"""The headless CLI as a user meets it: real files, real subprocesses, exit codes."""

import csv
import json
import signal
import subprocess
import sys
import time

import numpy as np
import pytest

from frictionlab.cli import main
from frictionlab.errors import ExitCode
from frictionlab.runs.results import column_name

from ..conftest import SMALL_PRESET, merge
from .conftest import RUN_DIRECTORY, write_preset


def test_run_writes_every_output_file_with_the_documented_contents(tmp_path, capsys):
    preset = write_preset(tmp_path, SMALL_PRESET)
    out = tmp_path / "out"
    code = main(["run", str(preset), "--out", str(out), "--workers", "1"])
    captured = capsys.readouterr()
    assert code == ExitCode.OK
    assert {p.name for p in out.iterdir()} == {
        "summary.json",
        "curve.csv",
        "realizations.npz",
        "preset.yaml",
        "plot.png",
        *RUN_DIRECTORY,
    }
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "completed"
    assert summary["realizations"] == {"requested": 8, "done": 8, "failed": 0, "failures": []}
    assert summary["seed"] == 7
    assert summary["preset"]["spectrum"]["params"]["hurst"] == 0.8
    assert summary["preset"]["spectrum"]["params"]["amplitudes"] == "fixed"  # defaults resolved
    fit = summary["fit"]
    assert fit["a_ci"][0] < fit["a"] < fit["a_ci"][1]
    assert fit["b_ci"][0] < fit["b"] < fit["b_ci"][1]
    assert 0 < fit["r2"] <= 1
    with open(out / "curve.csv") as fh:
        rows = [{column_name(k): v for k, v in row.items()} for row in csv.DictReader(fh)]
    assert list(rows[0]) == ["F", "f", "xi", "xi_sem", "lines_used", "contact_count", "contact_fraction", "indentation",
                            "half_load_points"]
    assert len(rows) == 16
    # the load and f say what they are: MDR's load is a force, f = F / (E* h L)
    header = (out / "curve.csv").read_text().splitlines()[0]
    assert header.startswith("F [force: modulus x length^2],f [F / (E* h L); F the force; E* = E / (1 - nu^2) the contact modulus; h the rms height; L the line's length]")
    assert "contact_fraction [fraction of MDR springs in contact; not the real area]" in header
    normalisation = summary["normalisation"]
    assert normalisation["f"] == "f = F / (E* h L), F the force, E* = E / (1 - nu^2) the contact modulus, h the rms height, L the line's length"
    assert normalisation["load"] == "force" and normalisation["extent"] == "length"
    assert normalisation["extent_value"] == 1024.0 and normalisation["rms_height"] == 1.0
    np.testing.assert_allclose(
        [float(r["f"]) for r in rows], [float(r["F"]) / normalisation["force_unit"] for r in rows], rtol=1e-15
    )
    assert "f = F / (E* h L)" in captured.out
    arrays = np.load(out / "realizations.npz")
    assert arrays["xi"].shape == (8, 16)
    # the curve is the mean of the per-realization rows
    np.testing.assert_allclose([float(r["xi"]) for r in rows], arrays["xi"].mean(axis=0), rtol=1e-15)
    assert (out / "plot.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the table on stdout carries the same fit; stdout has no progress in it
    assert f"{fit['a']:10.4f}" in captured.out
    assert "realizations," not in captured.out
    # its std.err is the bootstrap's spread over the lines, beside the interval it draws, not the
    # least-squares error over the forces (several times smaller: neighbouring forces correlate)
    for name in ("a", "b"):
        [row] = [line.split() for line in captured.out.splitlines() if line.split()[:1] == [name]]
        assert float(row[2]) == pytest.approx(fit[f"{name}_se_bootstrap"], abs=5e-5)
        assert fit[f"{name}_se_bootstrap"] > 2 * fit[f"{name}_se"] > 0


def test_resolved_preset_reruns_to_the_same_numbers(tmp_path, capsys):
    preset = write_preset(tmp_path, SMALL_PRESET)
    main(["run", str(preset), "--out", str(tmp_path / "one"), "--workers", "1", "--quiet", "--no-plot"])  # numbers only
    main(["run", str(tmp_path / "one" / "preset.yaml"), "--out", str(tmp_path / "two"), "--workers", "2", "--quiet"])
    one = json.loads((tmp_path / "one" / "summary.json").read_text())
    two = json.loads((tmp_path / "two" / "summary.json").read_text())
    assert one["fit"] == two["fit"]
    assert (tmp_path / "one" / "curve.csv").read_text() == (tmp_path / "two" / "curve.csv").read_text()


def test_json_summary_on_stdout_and_set_and_seed_overrides(tmp_path, cli):
    preset = write_preset(tmp_path, SMALL_PRESET)
    result = cli(
        "run", preset, "--out", tmp_path / "o", "--json", "--quiet", "--workers", "1", "--no-plot",
        "--set", "spectrum.params.hurst=0.5", "--set", "realizations=5", "--seed", "99",
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    summary = json.loads(result.stdout)  # stdout is only the JSON
    assert summary["preset"]["spectrum"]["params"]["hurst"] == 0.5
    assert summary["realizations"]["done"] == 5
    assert summary["seed"] == 99
    assert result.stderr == ""  # --quiet


@pytest.mark.parametrize("command", ["run", "study"])
def test_a_seed_given_twice_with_two_values_is_refused_before_any_work(tmp_path, cli, command):
    """--seed 99 with --set seed=5 (either order) named a seed the run did not take: --seed won, without a word."""
    preset = write_preset(tmp_path, SMALL_PRESET)
    for order in (("--seed", "99", "--set", "seed=5"), ("--set", "seed=5", "--seed", "99")):
        result = cli(command, preset, "--out", tmp_path / "o", "--quiet", *order)
        assert result.returncode == ExitCode.USAGE, result.stderr
        assert "--seed 99 and --set 'seed=5' both give the root seed: give it once" in result.stderr
        assert "Traceback" not in result.stderr and not (tmp_path / "o").exists()
    same = cli("run", preset, "--out", tmp_path / "o", "--json", "--quiet", "--workers", "1", "--no-plot",
               "--set", "seed=99", "--seed", "99")  # fmt: skip
    assert same.returncode == 0, same.stderr
    assert json.loads(same.stdout)["seed"] == 99


@pytest.mark.parametrize("command, option", [("run", ["--seed", "9"]), ("run", ["--set", "seed=9"]),
                                             ("validate", ["--set", "seed=9"])])  # fmt: skip
def test_a_swept_path_given_on_the_command_line_is_refused(tmp_path, cli, command, option):
    """--seed 9 beside a sweep over seed ran seeds 1 and 2, the option ignored without a word."""
    preset = write_preset(tmp_path, merge(SMALL_PRESET, {"sweep": {"parameters": {"seed": {"values": [1, 2]}}}}))
    out = ["--out", tmp_path / "o", "--quiet"] if command == "run" else []
    result = cli(command, preset, *out, *option)
    assert result.returncode == ExitCode.USAGE, result.stderr
    said = "--seed 9" if option[0] == "--seed" else "--set 'seed=9'"
    assert f"{said}: seed is swept by the preset's sweep, which sets it at each point: it would be ignored" in result.stderr
    assert not (tmp_path / "o").exists()
    assert cli("validate", preset, "--set", "sweep=null", "--set", "seed=9").returncode == 0  # the preset once


def test_progress_lines_on_stderr_when_not_a_terminal(tmp_path, cli):
    preset = write_preset(tmp_path, merge(SMALL_PRESET, {"realizations": 40}))
    result = cli("run", preset, "--out", tmp_path / "o", "--workers", "2", "--no-plot")
    assert result.returncode == 0
    lines = result.stderr.strip().splitlines()
    assert lines[0].startswith("small: 40 realizations")
    progress = [line for line in lines if "/40 realizations" in line]
    assert 1 <= len(progress) <= 11  # one line per tenth once past 2 s (the last always), not one per realization
    assert progress[-1].startswith("40/40 realizations")
    assert "\r" not in result.stderr


BAD_PRESETS = [
    ({"spectrum": {"params": {"hurst": 2.0}}}, "spectrum.params.hurst: must be <= 1.5, got 2.0"),
    ({"spectrum": {"params": {"hurts": 0.5}}}, "spectrum.params.hurts: is not a known field; did you mean 'hurst'? allowed:"),
    ({"spectrum": {"name": "power-lw"}}, "spectrum.name: no spectrum plugin named 'power-lw'; did you mean 'power-law'"),
    ({"solver": {"name": "bem"}}, "solver.name: no solver plugin named 'bem'"),
    ({"realizations": 0}, "realizations: must be >= 1, got 0"),
    ({"realizations": "many"}, "realizations: must be a whole number, got 'many'"),
    ({"loading": {"start": -1.0}}, "loading.start: must be > 0.0, got -1.0"),
    ({"loading": {"start": 5.0, "stop": 1.0}}, "loading: stop must be > start (5.0). Got 1.0 instead."),
    ({"loading": {"control": "pressure"}}, "loading.control: must be one of 'force' or 'indentation'"),
    ({"seeds": 3}, "seeds: is not a known field; did you mean 'seed'? allowed: description, fit, loading"),
    ({"solver": {"params": {"poisson_ratio": 0.7}}}, "solver.params.poisson_ratio: must be <= 0.5, got 0.7"),
]


@pytest.mark.parametrize("changes, message", BAD_PRESETS, ids=[m.split(":")[0] for _, m in BAD_PRESETS])
def test_bad_presets_give_their_message_and_exit_code(tmp_path, capsys, changes, message):
    preset = write_preset(tmp_path, merge(SMALL_PRESET, changes))
    for command in (["validate", str(preset)], ["run", str(preset), "--out", str(tmp_path / "o")]):
        assert main(command) == ExitCode.USAGE
        err = capsys.readouterr().err
        assert message in err
        assert "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_missing_required_and_file_errors(tmp_path, capsys):
    data = dict(SMALL_PRESET)
    del data["loading"]
    assert main(["validate", str(write_preset(tmp_path, data))]) == ExitCode.USAGE
    assert "loading: is required" in capsys.readouterr().err
    assert main(["validate", str(tmp_path / "nope.yaml")]) == ExitCode.INPUT_FILE
    assert "no such preset file" in capsys.readouterr().err
    broken = tmp_path / "broken.yaml"
    broken.write_text("name: x\nspectrum: [unclosed\n")
    assert main(["validate", str(broken)]) == ExitCode.USAGE
    assert "not valid YAML at line" in capsys.readouterr().err
    listing = tmp_path / "list.yaml"
    listing.write_text("- 1\n- 2\n")
    assert main(["validate", str(listing)]) == ExitCode.USAGE
    assert "must be a mapping" in capsys.readouterr().err


@pytest.mark.long
def test_ctrl_c_keeps_finished_realizations_and_exits_130(tmp_path):
    """A real SIGINT to a running pool run: everything finished is written."""
    data = merge(SMALL_PRESET, {"realizations": 100000, "spectrum": {"params": {"points": 2048}}})
    preset = write_preset(tmp_path, data)
    out = tmp_path / "o"
    proc = subprocess.Popen(
        [sys.executable, "-m", "frictionlab", "run", str(preset), "--out", str(out), "--workers", "2"],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    line = ""
    deadline = time.monotonic() + 60
    while "/100000 realizations" not in line and time.monotonic() < deadline:
        line = proc.stderr.readline()
    proc.send_signal(signal.SIGINT)
    stdout, stderr = proc.communicate(timeout=60)
    assert proc.returncode == ExitCode.INTERRUPTED, stderr
    assert "Traceback" not in stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["status"] == "interrupted"
    assert 0 < summary["realizations"]["done"] < 100000
    assert summary["realizations"]["failed"] == 0
    arrays = np.load(out / "realizations.npz")
    assert arrays["xi"].shape[0] == summary["realizations"]["done"]


def test_a_measured_profile_runs_end_to_end_with_its_own_rms_height(tmp_path, capsys):
    x = np.arange(2048)
    heights = 3.0 * np.cos(2 * np.pi * x / 512) + 0.05 * np.sin(2 * np.pi * x / 16) + 7.0
    np.savetxt(tmp_path / "scan.csv", heights)
    preset = write_preset(
        tmp_path,
        {
            "name": "scan",
            "realizations": 1,
            "spectrum": {"name": "profile-file", "params": {"path": str(tmp_path / "scan.csv"), "spacing": 0.5}},
            "loading": {"start": 0.1, "stop": 50.0, "steps": 12, "spacing": "log"},
        },
    )
    assert main(["run", str(preset), "--out", str(tmp_path / "o"), "--quiet", "--no-plot"]) == ExitCode.OK
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["workers"] == 1  # one realization runs in-process, and says so
    assert summary["normalisation"]["rms_height"] == pytest.approx(np.std(heights), rel=1e-12)
    assert summary["normalisation"]["extent_value"] == 1024.0


def test_a_run_whose_every_realization_fails_still_writes_and_exits_1(tmp_path, capsys):
    data = {**SMALL_PRESET, "realizations": 2}  # a solver that cannot converge in one iteration: each fails
    data["solver"] = {"name": "bem-halfplane", "params": {"max_iterations": 1, "tolerance": 1e-12}}
    preset = write_preset(tmp_path, data)
    assert main(["run", str(preset), "--out", str(tmp_path / "o"), "--quiet"]) == ExitCode.RUNTIME_FAILURE
    out = capsys.readouterr().out
    assert "2 realization(s) failed; first: #0: SolveFailed: bem-halfplane did not converge" in out
    assert ".py:" not in out  # a failure the solver explains carries no source line
    summary = json.loads((tmp_path / "o" / "summary.json").read_text())
    assert summary["realizations"]["done"] == 0 and summary["fit"] is None
    assert summary["realizations"]["failures"][1]["index"] == 1


def test_output_switches_leave_out_the_per_realization_file_and_the_plot(tmp_path, capsys):
    preset = write_preset(tmp_path, merge(SMALL_PRESET, {"output": {"realizations": False, "plot": False}}))
    assert main(["run", str(preset), "--out", str(tmp_path / "o"), "--quiet"]) == ExitCode.OK
    assert {p.name for p in (tmp_path / "o").iterdir()} == {"summary.json", "curve.csv", "preset.yaml", *RUN_DIRECTORY}
    files = json.loads((tmp_path / "o" / "summary.json").read_text())["files"]
    assert set(files) == {"curve", "preset"}


@pytest.mark.parametrize("address", ["", "   "])
def test_an_empty_scheduler_address_is_refused_not_taken_for_a_local_cluster(tmp_path, address, cli):
    preset = write_preset(tmp_path, SMALL_PRESET)
    result = cli("run", preset, "--out", tmp_path / "o", "--executor", "dask", "--scheduler", address)
    assert result.returncode == ExitCode.USAGE, result.stderr
    assert "--scheduler: the address is empty" in result.stderr
    assert not (tmp_path / "o").exists()

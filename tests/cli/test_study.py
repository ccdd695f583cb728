"""``frictionlab study``: the command line of the trade-off study."""



import pytest
import yaml

from frictionlab.cli import main
from frictionlab.errors import ExitCode

from ..tradeoff.conftest import TINY

# ------------------------------------------------------------------ CLI


def write(tmp_path, data):
    path = tmp_path / "preset.yaml"
    path.write_text(yaml.safe_dump(data))
    return path


def test_cli_runs_a_study_and_prints_the_recommendation(tmp_path, capsys):
    preset = write(tmp_path, TINY)
    out = tmp_path / "study"
    code = main([
        "study", str(preset), "--out", str(out), "--reference", "mdr-bisection", "--points", "128",
        "--compare-realizations", "3", "--compare-steps", "5", "--grid-realizations", "3",
        "--grid-factors", "1,2", "--tolerances", "1e-3,1e-9", "--axes", "grid,solver,tolerance",
    ])
    captured = capsys.readouterr()
    assert code == ExitCode.OK, captured.err
    assert captured.out.startswith("for 2% error in b at H = 0.8: mdr needs N = 256")
    assert "study: grid" in captured.err and "study: solver" in captured.err
    assert {p.name for p in out.iterdir()} == {"study.csv", "study.md", "study.png"}
    assert "--reference mdr-bisection" in (out / "study.md").read_text()


@pytest.mark.parametrize(
    "args, message",
    [
        (["--reference", "bem-nowhere"], "--reference: no solver plugin named 'bem-nowhere'"),
        (["--axes", "grid,speed"], "--axes must name some of grid, realizations, steps, solver, tolerance"),
        (["--target", "2"], "--target must be > 0 and < 1"),
        (["--tolerances", "1e-3,abc"], "--tolerances must be a comma-separated list of numbers"),
        (["--grid-factors", "1,-2"], "--grid-factors values must be > 0. Got -2.0 instead."),
        (["--points", "4"], "--points must be >= 8. Got 4 instead."),
        (["--set", "spectrum.params.hurst=7"], "spectrum.params.hurst: must be <= 1.5"),
    ],
)
def test_cli_usage_errors_name_the_option(tmp_path, capsys, args, message):
    code = main(["study", str(write(tmp_path, TINY)), "--out", str(tmp_path / "o"), *args])
    err = capsys.readouterr().err
    assert code == ExitCode.USAGE
    assert message in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_cli_bad_preset_file(tmp_path, capsys):
    (tmp_path / "bad.yaml").write_text("name: [unclosed\n")
    assert main(["study", str(tmp_path / "bad.yaml")]) == ExitCode.USAGE
    assert "not valid YAML" in capsys.readouterr().err
    assert main(["study", str(tmp_path / "missing.yaml")]) == ExitCode.INPUT_FILE
    assert "no such preset file" in capsys.readouterr().err

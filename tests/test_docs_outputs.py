"""The outputs the README and the docs show are what the commands beside them print
today: each is rerun here (serially: the numbers do not depend on the workers) and
every line shown must be printed, but for wall times and output paths. When the
physics or the output changes, these fail until the pages show the new output."""

from __future__ import annotations

import contextlib
import io
import re

import pytest

from frictionlab.cli.main import main
from frictionlab.paper import calibration

from .conftest import ROOT


def _shown_block(page: str, first_line: str) -> list[str]:
    """The lines of the fenced block of ``page`` that starts with ``first_line``."""
    text = (ROOT / page).read_text(encoding="utf-8")
    for block in re.findall(r"^```text\n(.*?)^```", text, flags=re.S | re.M):
        lines = block.splitlines()
        if lines and lines[0].startswith(first_line):
            return lines
    raise AssertionError(f"{page} shows no output starting with {first_line!r}")


def _comparable(line: str) -> bool:
    """Output lines that hold no wall time and no output folder (those differ run to run)."""
    return not re.search(r" in \d+\.\d+ s\b|^results in |^\.\.\.$|^\$ ", line.strip())


def _check(page: str, first_line: str, printed: str):
    shown = [line.strip() for line in _shown_block(page, first_line) if _comparable(line)]
    printed_lines = {line.strip() for line in printed.splitlines()}
    stale = [line for line in shown if line not in printed_lines]
    assert len(shown) >= 3
    assert not stale, f"{page} shows output the command no longer prints:\n" + "\n".join(stale) + "\n--- printed:\n" + printed


def _printed_run(out, preset: str, *options: str) -> tuple:
    """``frictionlab run PRESET --out OUT --workers 1 --quiet OPTIONS``: (out, what it printed)."""
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout):
        code = main(["run", str(ROOT / "presets" / preset), "--out", str(out), "--workers", "1", "--quiet", *options])
    assert code == 0
    return out, stdout.getvalue()


@pytest.fixture(scope="module")
def fig2_run(tmp_path_factory):
    # its figure left out: it prints the same without (the quickstart's run below draws one)
    return _printed_run(tmp_path_factory.mktemp("fig2") / "fig2", "benad2012-fig2.yaml", "--no-plot")


@pytest.fixture(scope="module")
def quickstart_printed(tmp_path_factory):
    """The README's quickstart run, once for the three pages that show its output."""
    return _printed_run(tmp_path_factory.mktemp("qs") / "qs", "quickstart.yaml")[1]


@pytest.mark.parametrize("page", ["README.md", "docs/getting-started.md", "docs/tutorials/dask-cluster.md"])
def test_the_quickstart_output_shown_is_what_it_prints(page, quickstart_printed):
    _check(page, "quickstart: 50/50", quickstart_printed)


def test_the_fig2_output_shown_is_what_it_prints(fig2_run):
    _check("docs/tutorials/reproduce-fig2.md", "benad2012-fig2: 300/300", fig2_run[1])


def test_the_predictions_shown_are_what_predict_prints(fig2_run, capsys):
    folder = str(fig2_run[0])
    args = ["--area", "1e10", "--modulus", "1", "--rms-height", "1e4", "--force", "5"]
    assert main(["predict", "--from", folder, *args]) == 0
    _check("docs/how-to/predict.md", "law: xi = 1.6059", capsys.readouterr().out)
    given = ["--a", "2.9", "--b", "0.14", "--a-ci", "2.8", "3.0", "--b-ci", "0.13", "0.15"]
    given += ["--area", "1e-4", "--modulus", "1e6", "--rms-height", "1e-6", "--force", "1e-9"]
    assert main(["predict", *given]) == 0
    _check("docs/how-to/predict.md", "law: xi = 2.9000", capsys.readouterr().out)


@pytest.mark.long  # the fig2 calibration, solved in full
def test_the_calibration_shown_is_what_it_prints(capsys):
    calibration.main(str(ROOT / "presets" / "benad2012-fig2.yaml"))
    _check("docs/tutorials/reproduce-fig2.md", "least-squares (in log) h =", capsys.readouterr().out)


def test_the_validation_errors_shown_are_what_validate_prints(tmp_path, monkeypatch, capsys):
    quickstart = (ROOT / "presets" / "quickstart.yaml").read_text(encoding="utf-8")
    bad = quickstart.replace("hurst: 0.8", "hurst: 2.0").replace("steps: 40", "steps: abc")
    bad = re.sub(r"(?m)^  name: mdr$", "  name: mdrr", bad)
    assert bad.count("2.0") and "abc" in bad and "mdrr" in bad, "the quickstart preset changed: update the page's bad.yaml"
    (tmp_path / "bad.yaml").write_text(bad, encoding="utf-8")
    monkeypatch.chdir(tmp_path)
    assert main(["validate", "bad.yaml"]) == 2
    captured = capsys.readouterr()
    _check("docs/how-to/presets.md", "$ frictionlab validate bad.yaml", captured.out + captured.err)


def test_the_built_in_presets_listing_shown_is_what_it_prints(capsys):
    assert main(["presets"]) == 0
    _check("docs/getting-started.md", "NAME", capsys.readouterr().out)


@pytest.mark.long  # the tutorial's X3P file written, validated and run twice (one a half-space): seconds
def test_the_instrument_file_tutorial_shows_what_its_commands_print(tmp_path, monkeypatch, capsys):
    """docs/tutorials/instrument-file.md, rerun in a copy of the example's folder: the X3P
    file written by the example's script, validated and run by MDR and by the free half-space."""
    import runpy
    import shutil

    page, folder = "docs/tutorials/instrument-file.md", tmp_path / "examples" / "instrument-scan"
    shutil.copytree(ROOT / "examples" / "instrument-scan", folder)
    monkeypatch.chdir(tmp_path)
    runpy.run_path(str(folder / "make_scan.py"))["main"](folder)
    preset = "examples/instrument-scan/scan.yaml"
    assert main(["validate", preset]) == 0
    _check(page, "wrote scan.x3p", capsys.readouterr().out)
    assert main(["run", preset, "--out", "runs/scan-mdr", "--workers", "1"]) == 0  # what it read, on stderr
    captured = capsys.readouterr()
    _check(page, "scan: 10 realizations", captured.err + captured.out)
    exact = ["--set", "solver.name=bem-halfspace-free", "--set", "realizations=1"]  # printed alike without its figure
    assert main(["run", preset, *exact, "--out", "runs/scan-exact", "--workers", "1", "--quiet", "--no-plot"]) == 0
    _check(page, "scan: 1/1", capsys.readouterr().out)


@pytest.mark.long  # the AFM file written, validated three times and run four times: seconds
def test_the_scan_as_the_microscope_leaves_it_shows_what_its_commands_print(tmp_path, monkeypatch, capsys):
    """docs/tutorials/instrument-file.md, its second half: the AFM file written by the
    example's script (tilt, holes, a spike, 2.5:1 pixels, four channels), refused, validated,
    run with and without each default, exactly as the page shows."""
    import runpy
    import shutil

    page, folder = "docs/tutorials/instrument-file.md", tmp_path / "examples" / "instrument-scan"
    shutil.copytree(ROOT / "examples" / "instrument-scan", folder)
    monkeypatch.chdir(tmp_path)
    runpy.run_path(str(folder / "make_afm_scan.py"))["main"](folder)
    preset, filled = "examples/instrument-scan/afm.yaml", ["--set", "spectrum.params.undefined=harmonic"]
    despiked = [*filled, "--set", "spectrum.params.despike=6"]
    assert main(["validate", preset]) == 2
    captured = capsys.readouterr()
    _check(page, "$ python examples/instrument-scan/make_afm_scan.py",
           (captured.out + captured.err).replace(str(tmp_path), "/home/me"))  # fmt: skip
    assert main(["validate", preset, *filled]) == 0
    _check(page, "$ frictionlab validate examples/instrument-scan/afm.yaml --set spectrum.params.undefined=harmonic\n"
           .strip(), capsys.readouterr().out)  # fmt: skip
    runs = {
        "afm-mdr": filled, "afm-despiked": despiked, "afm-mean": [*despiked, "--set", "spectrum.params.detrend=mean"],
        "afm-exact": [*despiked, "--set", "solver.name=bem-halfspace-free", "--set", "realizations=1"],
    }  # fmt: skip
    for out, extra in runs.items():
        assert main(["run", preset, *extra, "--out", f"runs/{out}", "--workers", "1", "--no-plot"]) == 0
        shown, captured = f"$ frictionlab run {preset} {' '.join(extra)} --out runs/{out}", capsys.readouterr()
        _check(page, shown, captured.err + captured.out)  # what it read, on stderr
    region = ["--set", "spectrum.params.region={x: [0, 80], y: [0, 32]}", "--set", "spectrum.params.downsample={factor: 2}"]
    assert main(["validate", preset, *filled, *region]) == 0
    _check(page, f"$ frictionlab validate {preset} {' '.join(filled)} --set 'spectrum.params.region=",
           capsys.readouterr().out)  # fmt: skip

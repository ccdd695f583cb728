"""Start-up costs nothing it need not: what a command imports, checked in a fresh process
(the times themselves are measured by benchmarks/bench_startup.py, not asserted here)."""

import subprocess
import sys

import pytest

from ..conftest import PRESETS

# a measured file's readers: imported where a file is read, never by a preset of a generated surface
READERS = tuple(f"frictionlab_spectra.{m}" for m in ("instrument_file", "instrument_reader", "header_units", "text_table"))
HEAVY = ("numpy", "numpy.ma", "pydantic", "scipy", "matplotlib", "rich", "textual", "importlib.metadata", "dask",
         "distributed", "pandas", "SurfaceTopography", *READERS)
# what no command of a line preset needs before its figure: none is on the path of validate or run --no-plot
NOT_FOR_A_LINE = {"scipy", "matplotlib", "numpy.ma", "rich", "textual", "dask", "distributed", "pandas",
                  "SurfaceTopography", *READERS}


def imported_after(code: str) -> set[str]:
    probe = f"import sys\n{code}\nprint(sorted(m for m in {HEAVY!r} if m in sys.modules))"
    result = subprocess.run([sys.executable, "-c", probe], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    return set(eval(result.stdout.strip().splitlines()[-1]))


def test_help_imports_nothing_heavy():
    code = "from frictionlab.cli import main\ntry:\n    main(['--help'])\nexcept SystemExit:\n    pass"
    assert imported_after(code) == set()


def test_a_line_run_without_plot_imports_neither_scipy_nor_matplotlib(tmp_path):
    quickstart = PRESETS / "quickstart.yaml"
    code = f"from frictionlab.cli import main\nmain(['run', {str(quickstart)!r}, '--out', {str(tmp_path / 'o')!r}, '--quiet', '--no-plot'])"
    assert imported_after(code) & NOT_FOR_A_LINE == set()  # numpy.ma: np.percentile, np.unique
    assert (tmp_path / "o" / "summary.json").is_file() and not (tmp_path / "o" / "plot.png").exists()


def test_validate_imports_only_what_validating_needs():
    fig2 = PRESETS / "benad2012-fig2.yaml"
    code = f"from frictionlab.cli import main\nassert main(['validate', {str(fig2)!r}]) == 0"
    assert imported_after(code) & NOT_FOR_A_LINE == set()


@pytest.mark.long  # a process of its own, seconds end to end: pytest -m long
@pytest.mark.parametrize("drawing_process", [True, False])
def test_the_figure_imports_matplotlib_only_when_drawn(tmp_path, drawing_process):
    """``frictionlab run`` draws plot.png in a process forked as it starts (matplotlib never
    comes into the command's own); where none can be had, it imports matplotlib to draw it."""
    quickstart = PRESETS / "quickstart.yaml"
    refuse = "" if drawing_process else (
        "import frictionlab.runs.figures as figures\nfigures.DrawingProcess.start = classmethod(lambda cls: None)\n")
    code = (f"{refuse}from frictionlab.cli import main\n"
            f"main(['run', {str(quickstart)!r}, '--out', {str(tmp_path / 'o')!r}, '--quiet'])")
    assert ("matplotlib" in imported_after(code)) is not drawing_process
    assert (tmp_path / "o" / "plot.png").is_file()

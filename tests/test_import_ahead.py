"""The plotting module is imported while the ensemble computes, never under a fork."""

from __future__ import annotations

import subprocess
import sys
import textwrap

import pytest

from frictionlab.runs import import_ahead
from frictionlab.runs.runner import run_to_folder

from .conftest import PRESETS


def _in_a_fresh_process(code: str, tmp_path) -> str:
    return subprocess.run(
        [sys.executable, "-c", textwrap.dedent(code)], capture_output=True, text=True, check=True, cwd=tmp_path
    ).stdout


@pytest.mark.skipif(not hasattr(__import__("os"), "fork"), reason="os.fork: POSIX only")
def test_a_fork_waits_for_the_import_under_way(tmp_path):
    """A module that takes 0.5 s to import, imported ahead: a fork at once gets it whole
    in the child (the fork waited), never half imported with its lock held by no thread."""
    (tmp_path / "slow_module.py").write_text("import time\ntime.sleep(0.5)\nDONE = True\n")
    out = _in_a_fresh_process(
        """
        import os, sys, time
        sys.path.insert(0, os.getcwd())
        from frictionlab.runs.import_ahead import import_ahead
        thread = import_ahead("slow_module")
        started = time.monotonic()
        pid = os.fork()
        if pid == 0:
            os._exit(0 if getattr(sys.modules.get("slow_module"), "DONE", False) else 3)
        _, status = os.waitpid(pid, 0)
        print(os.waitstatus_to_exitcode(status), round(time.monotonic() - started, 2), thread is not None)
        """,
        tmp_path,
    ).split()
    assert out[2] == "True"
    assert out[0] == "0", "the child was forked with the module half imported"
    assert float(out[1]) >= 0.3, "the fork did not wait for the import"


def test_a_module_imported_already_is_not_imported_again():
    assert import_ahead.import_ahead("json") is None


def test_a_failing_import_is_left_for_the_drawing_to_report(tmp_path):
    """The thread swallows the failure; importing the module again raises it as usual."""
    (tmp_path / "broken_module.py").write_text("raise RuntimeError('broken on purpose')\n")
    out = _in_a_fresh_process(
        """
        import os, sys
        sys.path.insert(0, os.getcwd())
        from frictionlab.runs.import_ahead import import_ahead
        import_ahead("broken_module").join()
        try:
            import broken_module
        except RuntimeError as exc:
            print("raised:", exc)
        """,
        tmp_path,
    )
    assert out.strip() == "raised: broken on purpose"


@pytest.mark.parametrize("realizations, ahead", [(1, False), (4, True)])
def test_a_run_that_draws_imports_the_plot_module_from_its_second_realization(
    make_scene, tmp_path, monkeypatch, realizations, ahead
):
    """Heard at the second realization (the first runs before any pool starts); a
    one-realization run imports it as it draws. plot.png is drawn either way."""
    asked = []
    monkeypatch.setattr(import_ahead, "import_ahead", lambda name: asked.append(name))
    scene = make_scene({"realizations": realizations})
    _, files = run_to_folder(scene, tmp_path / "run")
    assert asked == ([import_ahead.PLOT_MODULE] if ahead else [])
    assert files["plot"].read_bytes().startswith(b"\x89PNG")


def test_a_run_that_does_not_draw_imports_nothing_ahead(make_scene, tmp_path, monkeypatch):
    asked = []
    monkeypatch.setattr(import_ahead, "import_ahead", lambda name: asked.append(name))
    _, files = run_to_folder(make_scene({"realizations": 4}), tmp_path / "run", plot=False)
    assert asked == [] and "plot" not in files


def test_a_module_asked_for_while_its_import_ahead_fails_raises_that_failure(tmp_path):
    """Asked for during the failing import, the module is not handed over half made: its
    own error is raised (plot.png's failure names what is wrong with matplotlib)."""
    (tmp_path / "slowly_broken.py").write_text("import time\ntime.sleep(0.4)\nraise RuntimeError('broken on purpose')\n")
    out = _in_a_fresh_process(
        """
        import os, sys
        sys.path.insert(0, os.getcwd())
        from frictionlab.runs.import_ahead import import_ahead, imported
        import_ahead("slowly_broken")
        while "slowly_broken" not in sys.modules:  # its import under way in the thread
            pass
        try:
            module = imported("slowly_broken")
        except RuntimeError as exc:
            print("raised:", exc)
        else:
            print("handed over:", module)
        """,
        tmp_path,
    )
    assert out.strip() == "raised: broken on purpose"


def test_drawing_plot_png_imports_nothing_the_plot_module_did_not(tmp_path):
    """The PNG canvas and PIL's format drivers come with the plotting module (imported
    ahead), not with the first figure saved, after the fit is printed."""
    out = _in_a_fresh_process(
        f"""
        import io, sys
        from frictionlab.compute import engine
        from frictionlab.options import RunOptions
        from frictionlab.preset import load_scene
        scene = load_scene({str(PRESETS / "benad2012-fig2.yaml")!r}, ["realizations=2", "spectrum.params.points=1024",
                           "spectrum.params.length=1024", "loading.steps=8", "fit.bootstrap=10"])
        outcome = engine.run(scene, RunOptions(workers=1))
        import frictionlab.plot
        from frictionlab.runs.figures import CurveFigure
        before = set(sys.modules)
        frictionlab.plot.plot_curve(CurveFigure.of(scene, outcome), io.BytesIO())
        print(sorted(set(sys.modules) - before))
        """,
        tmp_path,
    )
    assert out.strip() == "[]"

"""``frictionlab plot DIR``: the figure of a run (or sweep) made without one, drawn from its folder
as the run draws it; an existing figure kept unless --force; a folder that is no run refused."""

import threading

import numpy as np

from frictionlab.errors import ExitCode
from frictionlab.options import RunOptions
from frictionlab.runs.runner import run_to_folder
from frictionlab.runs.sweep import plan_sweep, run_sweep

from ..conftest import SMALL_PRESET, merge
from ..test_sweep import sweep_preset
from .conftest import write_preset

TINY = {"realizations": 3, "spectrum": {"params": {"points": 256}}, "loading": {"steps": 6}, "fit": {"bootstrap": 20}}


def pixels(path):
    from PIL import Image

    with Image.open(path) as image:
        return np.asarray(image.convert("RGBA"))


def test_a_no_plot_runs_figure_is_the_one_the_run_draws_and_is_replaced_only_with_force(tmp_path, cli):
    preset = write_preset(tmp_path, merge(SMALL_PRESET, TINY))
    drawn, bare = tmp_path / "drawn", tmp_path / "bare"
    assert cli("run", preset, "--out", drawn, "--workers", "1", "--quiet").returncode == ExitCode.OK
    assert cli("run", preset, "--out", bare, "--workers", "1", "--quiet", "--no-plot").returncode == ExitCode.OK
    figure = bare / "plot.png"
    assert not figure.exists()
    done = cli("plot", bare)
    assert (done.returncode, done.stdout, done.stderr) == (ExitCode.OK, f"wrote {figure}\n", "")
    np.testing.assert_array_equal(pixels(figure), pixels(drawn / "plot.png"))  # title, labels, fit, caveats alike

    figure.write_bytes(b"my own figure")
    refused = cli("plot", bare)
    assert refused.returncode == ExitCode.OUTPUT_REFUSED and refused.stdout == ""
    assert f"{figure} exists" in refused.stderr and "--force" in refused.stderr and "Traceback" not in refused.stderr
    assert figure.read_bytes() == b"my own figure"  # kept, byte for byte
    forced = cli("plot", bare, "--force", "--quiet")
    assert (forced.returncode, forced.stdout, forced.stderr) == (ExitCode.OK, "", "")
    np.testing.assert_array_equal(pixels(figure), pixels(drawn / "plot.png"))


def test_a_sweeps_figure_is_the_one_the_sweep_draws(tmp_path, cli, registry):
    data = merge(sweep_preset({"spectrum.params.hurst": {"values": [0.6, 0.9]}}), TINY)  # its points draw no plot.png
    run_sweep(plan_sweep(data, registry=registry), tmp_path / "sweep", RunOptions(workers=1))  # sweep.png drawn
    out = tmp_path / "again.png"
    done = cli("plot", tmp_path / "sweep", "--out", out)
    assert (done.returncode, done.stdout) == (ExitCode.OK, f"wrote {out}\n"), done.stderr
    np.testing.assert_array_equal(pixels(out), pixels(tmp_path / "sweep" / "sweep.png"))

    import json

    from frictionlab.runs.figures import SHOWN_LABEL_CHARS
    from frictionlab.runs.sweep import Sweep

    record = json.loads((tmp_path / "sweep" / "sweep.json").read_text())
    record["name"] = "s" * 300_000  # a damaged sweep.json: its title took 40 s to draw, the axes squeezed out
    (tmp_path / "sweep" / "sweep.json").write_text(json.dumps(record))
    assert Sweep.recorded(tmp_path / "sweep").name == "s" * SHOWN_LABEL_CHARS + "..."


def test_a_folder_that_holds_no_run_or_nothing_to_draw_is_refused_by_name(tmp_path, cli, make_scene):
    empty, linked, nothing = tmp_path / "empty", tmp_path / "linked", tmp_path / "nothing"
    empty.mkdir()
    linked.mkdir()
    (tmp_path / "elsewhere.json").write_text("{}")
    (linked / "summary.json").symlink_to(tmp_path / "elsewhere.json")
    cancelled = threading.Event()
    cancelled.set()  # before the first realization: a run folder with none done
    run_to_folder(make_scene(TINY), nothing, RunOptions(workers=1), cancel=cancelled)
    for folder, said in ((empty, "no summary.json"), (linked, "summary.json is a symbolic link"),
                         (nothing, "no realization finished (0 of 3, run cancelled): nothing to draw")):  # fmt: skip
        before = sorted(folder.iterdir())
        done = cli("plot", folder)
        assert done.returncode == ExitCode.RUN_FOLDER and done.stdout == "", (folder, done.stderr)
        assert said in done.stderr and str(folder) in done.stderr and "Traceback" not in done.stderr, done.stderr
        assert sorted(folder.iterdir()) == before  # nothing written
    wrong = cli("plot", empty, "--out", tmp_path / "figure.jpg")
    assert wrong.returncode == ExitCode.USAGE and f"--out {tmp_path / 'figure.jpg'}" in wrong.stderr
    assert "ends in .png" in wrong.stderr and not (tmp_path / "figure.jpg").exists()


def test_a_figure_that_cannot_be_written_is_said_so_in_the_commands_terms(tmp_path, cli):
    """plot computes nothing: its failure to write ended '; the numbers are written', as a run's does."""
    import os

    preset = write_preset(tmp_path, merge(SMALL_PRESET, TINY))
    bare = tmp_path / "bare"
    assert cli("run", preset, "--out", bare, "--workers", "1", "--quiet", "--no-plot").returncode == ExitCode.OK
    before = sorted(p.name for p in bare.iterdir())
    os.symlink("/dev/full", tmp_path / "full.png")  # a device the user names is written into: no space left on it
    done = cli("plot", bare, "--out", tmp_path / "full.png")
    assert done.returncode == ExitCode.RUNTIME_FAILURE and "Traceback" not in done.stderr, done.stderr
    assert done.stderr.rstrip().endswith("No space left on device; the run folder is as it was"), done.stderr
    assert sorted(p.name for p in bare.iterdir()) == before

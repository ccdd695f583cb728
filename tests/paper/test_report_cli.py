"""``frictionlab report`` as a user meets it: Ctrl-C and SIGTERM stop the report with 130
and 143, keeping the finished runs and publishing no report; an output that cannot be
what its option says is refused naming the option (exit 4)."""

import json
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import yaml

from frictionlab.cli import main
from frictionlab.errors import ExitCode, OutputRefused
from frictionlab.paper.figures import FIGURES
from frictionlab.paper.reproduce import report_paths
from frictionlab.preset import apply_overrides, load_preset_file

from ..conftest import PRESETS

SMALL = ["spectrum.params.points=1024", "spectrum.params.length=1024.0", "output.plot=false",
         "spectrum.params.rms_height=300.0", "loading.steps=12", "fit.bootstrap=20"]  # fmt: skip


def _ctrl_c_as_in_a_terminal():
    signal.signal(signal.SIGINT, signal.SIG_DFL)  # a shell's background job would inherit it ignored


def _listed_chunks(run_dir) -> int:
    try:
        return len(json.loads((run_dir / "run.json").read_text())["chunks"])
    except (OSError, ValueError, KeyError):  # not written yet, or being replaced
        return 0


@pytest.mark.long
@pytest.mark.parametrize("signum, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)])
def test_a_signal_stops_the_report_keeping_the_runs_and_writing_no_report(tmp_path, signum, code):
    presets = tmp_path / "presets"
    presets.mkdir()
    for fig in FIGURES:  # Fig. 2 long enough to be interrupted, the others small
        many = ["realizations=20000"] if fig.key == "fig2" else ["realizations=4"]
        data = apply_overrides(load_preset_file(PRESETS / fig.preset), [*SMALL, *many])
        (presets / fig.preset).write_text(yaml.safe_dump(data, sort_keys=False))
    out = tmp_path / "r"
    command = [sys.executable, "-m", "frictionlab", "report", "--presets", str(presets), "--out", str(out),
               "--workers", "1", "--quiet"]  # fmt: skip
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
                               preexec_fn=_ctrl_c_as_in_a_terminal)
    deadline = time.monotonic() + 60
    while _listed_chunks(out / "fig2") < 1:
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, "no chunk written in 60 s"
        time.sleep(0.01)
    process.send_signal(signum)
    stdout, err = process.communicate(timeout=120)
    assert process.returncode == code, err
    assert f"the runs that finished are kept in {out}" in err and f"frictionlab resume {out / 'fig2'}" in err
    assert "Traceback" not in err and stdout == ""
    assert not (out / "REPRODUCTION.md").exists() and not (out / "fig3").exists()
    state = json.loads((out / "fig2" / "run.json").read_text())
    assert state["status"] == "interrupted" and state["chunks"]


def test_figures_or_out_that_is_a_file_and_markdown_that_is_a_folder_are_refused(tmp_path, capsys):
    afile, folder = tmp_path / "my.md", tmp_path / "folder"
    afile.write_text("mine")
    folder.mkdir()
    for args, said in ((["--figures", afile], f"--figures: {afile} is a file, not a folder"),
                       (["--out", afile], f"--out: {afile} is a file, not a folder"),
                       (["--markdown", folder], f"--markdown {folder} is a folder")):  # fmt: skip
        code = main(["report", "--presets", str(PRESETS), "--out", str(tmp_path / "r"), *map(str, args), "--quiet"])
        assert code == ExitCode.OUTPUT_REFUSED
        assert said in capsys.readouterr().err
    assert afile.read_text() == "mine" and sorted(p.name for p in tmp_path.iterdir()) == ["folder", "my.md"]


@pytest.mark.parametrize("option, inside", [("--markdown", "fig2/summary.json"), ("--markdown", "fig5/sweep.json"),
                                            ("--figures", "fig3"), ("--figures", "readings/figures"),
                                            ("--markdown", "fig5-calibrated/REPRODUCTION.md")])  # fmt: skip
def test_a_markdown_or_figures_in_a_folder_of_the_reports_runs_is_refused(tmp_path, capsys, option, inside):
    """--markdown OUT/fig2/summary.json wrote the report over Fig. 2's summary, its run then damaged
    (`frictionlab runs` said so): refused before any run (exit 4), and nothing made."""
    out = tmp_path / "r"
    code = main(["report", "--presets", str(PRESETS), "--out", str(out), option, str(out / inside), "--quiet"])
    assert code == ExitCode.OUTPUT_REFUSED
    folder = out / inside.split("/")[0]
    assert f"{option} {out / inside} is in {folder}, where the report keeps its runs" in capsys.readouterr().err
    assert not out.exists()


@pytest.mark.parametrize("inside", ["fig2/summary.json", "fig5/sweep.csv"])
def test_a_markdown_over_a_file_of_an_earlier_reports_run_is_refused_without_advising_force(tmp_path, capsys, inside):
    """Over a run's file that exists, it said 'the report would overwrite it: ... or --force';
    --force then met the refusal that no --force lifts."""
    out = tmp_path / "r"
    (out / inside).parent.mkdir(parents=True)
    (out / inside).write_text("the run's")
    code = main(["report", "--presets", str(PRESETS), "--out", str(out), "--markdown", str(out / inside), "--quiet"])
    err = capsys.readouterr().err
    assert code == ExitCode.OUTPUT_REFUSED and "--force" not in err
    assert f"--markdown {out / inside} is in {out / inside.split('/')[0]}, where the report keeps its runs" in err
    assert (out / inside).read_text() == "the run's"


def test_a_bad_preset_among_the_figures_is_refused_before_any_figure_runs(tmp_path, capsys, monkeypatch):
    """Fig. 5's preset is the last to run: its mistake is named (exit 2) before Figs. 2 to 4
    spend their minutes, and no run folder is made."""
    presets = tmp_path / "presets"
    presets.mkdir()
    for fig in FIGURES:
        data = load_preset_file(PRESETS / fig.preset)
        if fig.key == "fig5":
            data = apply_overrides(data, ["seed=-4"])
        (presets / fig.preset).write_text(yaml.safe_dump(data, sort_keys=False))

    def must_not_run(*args, **kwargs):
        raise AssertionError("a figure ran before every preset was checked")

    monkeypatch.setattr("frictionlab.paper.figures.run_to_folder", must_not_run)
    monkeypatch.setattr("frictionlab.paper.figures.run_sweep", must_not_run)
    code = main(["report", "--presets", str(presets), "--out", str(tmp_path / "r"), "--quiet"])
    assert code == ExitCode.USAGE
    assert "benad2012-fig5.yaml" in (err := capsys.readouterr().err) and "seed: must be >= 0, got -4" in err
    assert not (tmp_path / "r" / "fig2").exists()


@pytest.mark.parametrize(("key", "assignment", "said"), [
    ("fig2", "spectrum.params.hurst=0.5", "spectrum.params.hurst is 0.5, but the report shows this preset as 'Fig. 2: H = 1"),
    ("fig3", "loading.stop=20", "loading.stop is 20.0, but the report shows this preset as 'Fig. 3: H = 1, F = 1..500'"),
    ("fig5", "loading.start=2", "loading.start is 2.0, but the report shows this preset as 'Fig. 5: a and b against H"),
    ("fig2", "sweep={parameters: {seed: {values: [1, 2]}}}", "sweep: the preset sweeps seed, but the report shows it as "
     "'Fig. 2: H = 1, F = 1..20', a single run (no sweep)"),  # reported as 'Fig. 5 at H = 1', its seeds as H
    ("fig5", "sweep=null", "sweep: the preset has no sweep (a single run), but the report shows it as 'Fig. 5: a and b "
     "against H, each point as Fig. 2', a sweep of spectrum.params.hurst alone"),
    ("fig5", "sweep.parameters={seed: {values: [1, 2]}}", "sweep: the preset sweeps seed, but"),
])  # fmt: skip
def test_a_preset_that_is_not_its_figure_is_refused_before_any_figure_runs(tmp_path, capsys, monkeypatch, key, assignment, said):
    """benad2012-fig2.yaml of H = 0.5 ran and was reported as 'Fig. 2: H = 1' beside the paper's a and b;
    a preset's other values (its realizations, say) are still its own to choose."""
    presets = tmp_path / "presets"
    presets.mkdir()
    for fig in FIGURES:
        data = load_preset_file(PRESETS / fig.preset)
        data = apply_overrides(data, [assignment] if fig.key == key else ["realizations=20"])
        (presets / fig.preset).write_text(yaml.safe_dump(data, sort_keys=False))

    def must_not_run(*args, **kwargs):
        raise AssertionError("a figure ran before every preset was checked")

    monkeypatch.setattr("frictionlab.paper.figures.run_to_folder", must_not_run)
    monkeypatch.setattr("frictionlab.paper.figures.run_sweep", must_not_run)
    assert main(["report", "--presets", str(presets), "--out", str(tmp_path / "r"), "--quiet"]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert f"{presets / f'benad2012-{key}.yaml'}: {said}" in err and "frictionlab presets copy" in err


def test_a_full_disk_says_which_file_and_that_the_runs_that_finished_are_kept(tmp_path, capsys, monkeypatch):
    """A full disk in a figure's run said 'No space left on device: FILE' and nothing of the runs
    that finished nor of how to go on (they are kept: the report run again continues them)."""
    import errno

    from frictionlab.io.files import atomic_write
    from frictionlab.paper import reproduce

    def chunk_that_does_not_fit(presets, out_dir, options, **how):
        def full(fh):
            raise OSError(errno.ENOSPC, "No space left on device")  # as a write says it: no file named

        atomic_write(out_dir / "fig3" / "chunks" / "00000000-00000009.npz", full, binary=True)

    monkeypatch.setattr(reproduce, "run_figures", chunk_that_does_not_fit)
    out = tmp_path / "report"
    assert main(["report", "--out", str(out), "--quiet"]) == ExitCode.RUNTIME_FAILURE
    err = capsys.readouterr().err
    assert err == (f"error: cannot write {out}/fig3/chunks/00000000-00000009.npz: No space left on device; the runs that "
                   f"finished are kept in {out}: the report run again with the same --out continues them; "
                   f"no {out}/REPRODUCTION.md written\n")  # fmt: skip


def test_a_figure_that_does_not_fit_in_memory_is_refused_before_any_figure_runs(tmp_path, capsys, monkeypatch):
    """Under `ulimit -v`, Fig. 4 too large was refused only once Figs. 2 and 3 had run."""
    from frictionlab.errors import RunError
    from frictionlab.paper import figures
    from frictionlab.runs import runner

    def refuse_fig4(scene, options):
        if scene.preset.name == "benad2012-fig4":
            raise RunError("this run would need about 9 GiB at its peak, but 1 GiB is available.")

    monkeypatch.setattr(runner, "check_memory", refuse_fig4)
    monkeypatch.setattr(figures, "check_memory", refuse_fig4, raising=False)
    out = tmp_path / "report"
    assert main(["report", "--out", str(out), "--quiet"]) == ExitCode.RUNTIME_FAILURE
    err = capsys.readouterr().err
    assert err.startswith("error: the report starts nothing: fig4 does not fit: this run would need about 9 GiB")
    assert "--workers and a higher limit do" in err and err.count("\n") == 1
    assert not (out / "fig2").exists()


def test_a_figure_refused_as_it_starts_says_that_the_runs_before_it_are_kept(tmp_path, capsys, monkeypatch):
    """Refused by its own memory check (this process grew meanwhile), a figure said nothing of
    the runs before it, kept and continued by the report run again."""
    from frictionlab.errors import RunError
    from frictionlab.runs import runner

    def refuse(scene, options):
        raise RunError("one process of this run would need about 0.18 GiB at its peak, but 101 MiB is available.")

    monkeypatch.setattr(runner, "check_memory", refuse)  # the run's own check, not the report's ahead of it
    out = tmp_path / "report"
    assert main(["report", "--out", str(out), "--quiet"]) == ExitCode.RUNTIME_FAILURE
    assert capsys.readouterr().err == (
        "error: one process of this run would need about 0.18 GiB at its peak, but 101 MiB is available; the runs that "
        f"finished are kept in {out}: the report run again with the same --out continues them\n")  # fmt: skip


def test_a_report_that_cannot_be_written_says_that_the_runs_are_kept(tmp_path, capsys, monkeypatch):
    """`--markdown /dev/full` (or a disk full at the last file) said only 'No space left on
    device: /dev/full', nothing of the runs, all finished, which the report run again reads back."""
    import errno

    from frictionlab.paper import reproduce

    monkeypatch.setattr(reproduce, "run_figures", lambda *args, **keys: [])
    monkeypatch.setattr(reproduce, "markdown", lambda *args, **keys: "# report\n")

    def full(path, write, *args, **keys):
        raise OSError(errno.ENOSPC, "No space left on device", str(path))

    monkeypatch.setattr(reproduce, "atomic_write", full)
    out = tmp_path / "report"
    assert main(["report", "--out", str(out), "--quiet"]) == ExitCode.RUNTIME_FAILURE
    assert capsys.readouterr().err == (
        f"error: cannot write {out}/REPRODUCTION.md: No space left on device; the runs that finished are kept in "
        f"{out}: the report run again with the same --out continues them (reading them back)\n")  # fmt: skip


def test_an_out_that_holds_other_files_is_refused_before_anything_runs(tmp_path, capsys):
    """--out naming a folder of the user's (not empty, not a report's) was filled with the report's runs,
    figures and REPRODUCTION.md: refused (exit 4) naming what it holds, and nothing is written there."""
    out = tmp_path / "mine"
    (out / "data").mkdir(parents=True)
    (out / "notes.txt").write_text("mine")
    code = main(["report", "--presets", str(PRESETS), "--out", str(out), "--quiet"])
    assert code == ExitCode.OUTPUT_REFUSED
    err = capsys.readouterr().err
    assert f"--out {out} is not empty and is not the folder of an earlier report (it holds 'data', 'notes.txt')" in err
    assert "--force or not" in err and "Traceback" not in err
    assert sorted(p.name for p in out.iterdir()) == ["data", "notes.txt"] and not any((out / "data").iterdir())


@pytest.mark.parametrize("mine", ["notes.txt", "REPRODUCTION.md", "fig2/summary.json"])
def test_force_never_writes_over_files_the_report_did_not_write(tmp_path, capsys, mine):
    """--force wrote the report into a folder of the user's: over a REPRODUCTION.md of theirs, and a figure's run
    over the summary.json and curve.csv in a fig2/ of theirs. Refused before any run (exit 4), --force or not."""
    out = tmp_path / "mine"
    (out / mine).parent.mkdir(parents=True)
    (out / mine).write_text("mine")
    said = {"notes.txt": f"--out {out} is not empty and is not the folder of an earlier report (it holds 'notes.txt')",
            "REPRODUCTION.md": f"{out}/REPRODUCTION.md was not written by frictionlab report: the report never replaces it",
            "fig2/summary.json": f"{out}/fig2 holds files that no frictionlab run wrote"}[mine]  # fmt: skip
    for force in ([], ["--force"]):
        assert main(["report", "--presets", str(PRESETS), "--out", str(out), "--quiet", *force]) == ExitCode.OUTPUT_REFUSED
        err = capsys.readouterr().err
        assert said in err and "--force or not" in err and "Traceback" not in err
        assert [p.relative_to(out) for p in out.rglob("*") if p.is_file()] == [Path(mine)]
        assert (out / mine).read_text() == "mine"


def test_an_out_of_an_earlier_report_is_taken(tmp_path):
    """What an earlier report left in its --out (its runs, figures/, REPRODUCTION.md, a temporary
    file of it), and the figures folder asked for in it, are not the user's files."""
    out = tmp_path / "out"
    for name in ("fig2", "fig5", "readings", "fig5-calibrated", "figures", "pngs"):
        (out / name).mkdir(parents=True)
    for name in ("REPRODUCTION.md", ".REPRODUCTION.md.x1y2.tmp"):
        (out / name).write_text("")
    assert report_paths(out, tmp_path / "other.md", out / "pngs")[0] == out
    (out / "mine.md").write_text("")
    with pytest.raises(OutputRefused, match="it holds 'mine.md', 'pngs'"):
        report_paths(out, tmp_path / "other.md", tmp_path / "figs")
    with pytest.raises(OutputRefused, match="it holds 'mine.md'"):  # --force wrote into it
        report_paths(out, out / "new.md", tmp_path / "figs", force=True)


@pytest.mark.parametrize("markdown", ["out/figures/fig2.png", "figs/fig5-calibrated.png"])
def test_a_markdown_that_is_one_of_the_reports_figures_is_refused(tmp_path, capsys, markdown):
    """--markdown OUT/figures/fig2.png: Fig. 2 was drawn, then the report written over it, linking to
    itself as the figure. Refused before any run (exit 4)."""
    out = tmp_path / "out"
    figures = ["--figures", str(tmp_path / "figs")] if markdown.startswith("figs/") else []
    code = main(["report", "--presets", str(PRESETS), "--out", str(out), *figures, "--markdown", str(tmp_path / markdown),
                 "--quiet"])  # fmt: skip
    assert code == ExitCode.OUTPUT_REFUSED
    assert f"--markdown {tmp_path / markdown} is a figure the report draws in" in capsys.readouterr().err
    assert not out.exists()


def no_figure_may_run(monkeypatch, why: str) -> None:
    """Any figure's run fails the test, saying ``why``."""
    def must_not_run(*args, **kwargs):
        raise AssertionError(why)

    monkeypatch.setattr("frictionlab.paper.figures.run_to_folder", must_not_run)
    monkeypatch.setattr("frictionlab.paper.figures.run_sweep", must_not_run)


@pytest.mark.parametrize("key", ["fig4", "fig5"])
def test_a_figures_folder_its_run_refuses_is_refused_before_any_figure_runs(tmp_path, capsys, monkeypatch, key):
    """--out of an earlier report whose fig4 (or fig5) holds files of the user's: Figs. 2 and 3 ran
    for minutes, then Fig. 4's run refused its folder. Refused before any figure runs (exit 4)."""
    out = tmp_path / "r"
    (out / key).mkdir(parents=True)
    (out / key / "notes.txt").write_text("mine")

    no_figure_may_run(monkeypatch, "a figure ran before every figure's folder was checked")
    code = main(["report", "--presets", str(PRESETS), "--out", str(out), "--quiet"])
    assert code == ExitCode.OUTPUT_REFUSED
    assert f"{out / key} holds files that no frictionlab run wrote ('notes.txt'): " in capsys.readouterr().err
    assert sorted(p.name for p in out.iterdir()) == [key] and (out / key / "notes.txt").read_text() == "mine"


@pytest.mark.parametrize("markdown, figures", [("out/figures", None), ("R.md", "R.md"), ("R.md", "R.md/figs")])
def test_a_markdown_that_is_the_figures_folder_is_refused(tmp_path, capsys, markdown, figures):
    """--markdown OUT/figures (the figures' folder): every figure ran, then the markdown could not be
    written, a folder (exit 1). Refused before any run (exit 4)."""
    out = tmp_path / "out"
    given = ["--figures", str(tmp_path / figures)] if figures else []
    code = main(["report", "--presets", str(PRESETS), "--out", str(out), *given, "--markdown", str(tmp_path / markdown),
                 "--quiet"])  # fmt: skip
    assert code == ExitCode.OUTPUT_REFUSED
    assert f"--markdown {tmp_path / markdown} is the figures' folder" in capsys.readouterr().err
    assert not out.exists() and not (tmp_path / markdown).exists()


@pytest.mark.parametrize("folder", ["readings/02-fig2", "fig5-calibrated/01-fig5"])
def test_a_readings_folder_of_other_files_is_refused_before_any_figure_runs(tmp_path, capsys, monkeypatch, folder):
    """--out of an earlier report whose readings/02-fig2 holds files of the user's: Figs. 2 to 5 ran,
    then the reading's run refused its folder advising --force, which the report never applies
    there. Refused before any figure runs (exit 4), saying what helps."""
    out = tmp_path / "r"
    (out / folder).mkdir(parents=True)
    (out / folder / "notes.txt").write_text("mine")

    no_figure_may_run(monkeypatch, "a figure ran before the readings' folders were checked")
    for force in ([], ["--force"]):
        code = main(["report", "--presets", str(PRESETS), "--out", str(out), "--readings", "--quiet", *force])
        assert code == ExitCode.OUTPUT_REFUSED
        err = capsys.readouterr().err
        assert f"{out / folder} holds files that no frictionlab run wrote ('notes.txt'): " in err
        assert "--force or not; move them aside, or give another --out" in err and "force it (--force" not in err
    assert (out / folder / "notes.txt").read_text() == "mine" and [p.name for p in out.iterdir()] == [folder.split("/")[0]]

"""``frictionlab study``: the command line of the trade-off study."""

import json



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
        # the preset's own solver compared with itself: every error 0, said as a result
        (["--reference", "MDR"], "--reference MDR: mdr is the preset's own solver, and the solver axis would compare "
                                 "it with itself (every error 0); give another solver of the elastic half-space"),
        (["--axes", "grid,speed"], "--axes must name some of grid, realizations, steps, solver, tolerance"),
        (["--axes", "grid,steps,grid"], "--axes names grid more than once; each axis runs once: name it once. "
                                         "Got 'grid,steps,grid' instead."),  # the grid axis ran twice, its rows too
        (["--target", "2"], "--target must be > 0 and < 1"),
        (["--tolerances", "1e-3,abc"], "--tolerances must be a comma-separated list of numbers"),
        (["--grid-factors", "1,-2"], "--grid-factors values must be finite numbers > 0. Got '-2' instead."),
        (["--grid-factors", "1,inf"], "--grid-factors values must be finite numbers > 0. Got 'inf' instead."),  # was exit 70
        (["--reference-grid", "Infinity"], "--reference-grid values must be finite numbers > 0. Got 'Infinity' instead."),
        (["--tolerances", "1e-400"], "--tolerances values must be finite numbers > 0. Got '1e-400' instead."),  # was 0.0
        (["--grid-factors", ",,"], "--grid-factors names no value"),  # the grid axis was left out without a word
        (["--tolerances", ","], "--tolerances names no value"),  # the tolerance axis ran the default instead
        (["--points", "4"], "--points must be >= 8. Got 4 instead."),
        # one value is the axis's reference alone, measured against nothing
        (["--grid-factors", "2"], "--grid-factors must give two different values at least (the axis measures the "
                                  "others against the largest). Got '2' instead."),
        (["--grid-factors", "1,1"], "--grid-factors must give two different values at least"),
        (["--tolerances", "1e-6", "--axes", "tolerance"], "--tolerances must give two different values at least "
                                                          "(the axis measures the others against the tightest)"),
        (["--grid-factors", "1,1e300"], "--grid-factors values must be at most 1e+06. Got '1e300' instead."),
        (["--reference-grid", "2e6"], "--reference-grid values must be at most 1e+06. Got '2e6' instead."),
        (["--repeats", "1000000000"], "--repeats must be a whole number from 1 to 100. Got 1000000000 instead."),
        (["--repeats", "0"], "--repeats must be a whole number from 1 to 100. Got 0 instead."),
        (["--set", "spectrum.params.hurst=7"], "spectrum.params.hurst: must be <= 1.5"),
        # an option whose axes are left out did nothing, unsaid
        (["--axes", "grid", "--tolerances", "1e-4"], "--tolerances changes the solver and tolerance axes, which --axes "
                                                     "grid leaves out: add solver or tolerance to --axes, or drop --tolerances"),
        (["--axes", "realizations", "--grid-factors", "1,2"], "--grid-factors changes the grid axis, which --axes "
                                                               "realizations leaves out: add grid to --axes"),
        (["--axes", "realizations", "--grid-realizations", "5"], "--grid-realizations changes the grid and steps axes"),
        (["--axes", "steps", "--points", "64"], "--points changes the solver and tolerance axes"),
        (["--axes", "grid", "--compare-realizations", "3"], "--compare-realizations changes the solver and tolerance"),
        # above the preset's own it ran with the preset's, unsaid
        (["--compare-realizations", "1000"], "--compare-realizations 1000 is more than the preset's 8 realizations: the "
                                             "study takes at most the preset's; give --compare-realizations 8 or less"),
        (["--grid-realizations", "9"], "--grid-realizations 9 is more than the preset's 8 realizations"),
        (["--compare-steps", "41"], "--compare-steps 41 is more than the preset's 12 load steps"),
        (["--points", "99999999"], "--points 99999999 is more than the preset's 256 points: the study takes at most"),
    ],
)
def test_cli_usage_errors_name_the_option(tmp_path, capsys, args, message):
    code = main(["study", str(write(tmp_path, TINY)), "--out", str(tmp_path / "o"), *args])
    err = capsys.readouterr().err
    assert code == ExitCode.USAGE
    assert message in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


@pytest.mark.parametrize("args, message", [
    (["--grid-factors", "a," * 5000], "--grid-factors must be a comma-separated list of numbers. Got 'a,a,a"),
    (["--axes", "a," * 5000], "--axes must name some of grid"),
    (["--reference", "a" * 5000], "--reference: no solver plugin named 'aaa"),
])  # fmt: skip
def test_a_long_value_is_quoted_cut_short(tmp_path, capsys, args, message):
    """A 10000-character --grid-factors, --axes or --reference was quoted whole in its refusal."""
    assert main(["study", str(write(tmp_path, TINY)), "--out", str(tmp_path / "o"), *args]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert message in err and "..." in err and len(err) < 500


def test_cli_bad_preset_file(tmp_path, capsys):
    (tmp_path / "bad.yaml").write_text("name: [unclosed\n")
    assert main(["study", str(tmp_path / "bad.yaml")]) == ExitCode.USAGE
    assert "not valid YAML" in capsys.readouterr().err
    assert main(["study", str(tmp_path / "missing.yaml")]) == ExitCode.INPUT_FILE
    assert "no such preset file" in capsys.readouterr().err


# ------------------------------------------------------------------ where the study writes

QUICK = ["--axes", "realizations", "--quiet"]


def test_study_out_keeps_the_users_files_unless_force(tmp_path, capsys, users_folders, figure_stubbed):
    (mine, _), (other, _) = folders = users_folders("study.md")
    for folder, held in folders:
        assert main(["study", "quickstart", *QUICK, "--out", str(folder)]) == ExitCode.OUTPUT_REFUSED
        err = capsys.readouterr().err
        assert f"--out {folder} holds '{held}'" in err and "--force" in err
    assert (mine / "study.md").read_text() == "my own notes"
    assert main(["study", "quickstart", *QUICK, "--out", str(other), "--force"]) == ExitCode.OK
    assert (other / "notes.txt").read_text() == "keep me"
    assert (other / "study.md").read_text().startswith("# Trade-off study: quickstart")
    # its own study folder: the same preset's study is run again there, without --force
    (other / "notes.txt").unlink()
    assert main(["study", "quickstart", *QUICK, "--out", str(other)]) == ExitCode.OK
    # another preset's study folder is not its own
    code = main(["study", str(write(tmp_path, TINY)), *QUICK, "--out", str(other)])
    assert code == ExitCode.OUTPUT_REFUSED and "not a study of tiny" in capsys.readouterr().err


def test_a_study_folder_with_other_files_beside_it_is_said_to_be_that_study(tmp_path, capsys):
    """A study of the same preset with the user's notes beside it was refused as 'holds
    'notes.txt', 'study.md', ..., not a study of quickstart': it is one; the notes are the matter."""
    out = tmp_path / "out"
    out.mkdir()
    (out / "study.md").write_text("# Trade-off study: quickstart\n")
    (out / "notes.txt").write_text("keep me")
    assert main(["study", "quickstart", *QUICK, "--out", str(out)]) == ExitCode.OUTPUT_REFUSED
    assert capsys.readouterr().err == (f"error: --out {out} holds a study of quickstart and also 'notes.txt': give another "
                                       "folder, or --force to write study.csv, study.md and study.png into it (nothing "
                                       "else is touched)\n")  # fmt: skip
    assert (out / "notes.txt").read_text() == "keep me" and sorted(p.name for p in out.iterdir()) == ["notes.txt", "study.md"]


@pytest.mark.parametrize("force", [False, True])
def test_a_study_file_that_is_a_folder_is_refused_before_the_work_not_after(tmp_path, capsys, force):
    """A study folder whose study.csv is a folder (its study.md headed as the study's) was taken
    as the study's own: the study ran, then failed to write ('[Errno 21] ...', exit code 1),
    its work lost; with --force, a study.md folder too. Refused at once, naming the file."""
    out = tmp_path / "out"
    (out / "study.csv").mkdir(parents=True)
    (out / "study.csv" / "mine.txt").write_text("keep me")
    (out / "study.md").write_text("# Trade-off study: quickstart\n")
    code = main(["study", "quickstart", *QUICK, "--out", str(out), *(["--force"] if force else [])])
    err = capsys.readouterr().err
    assert code == ExitCode.OUTPUT_REFUSED, err
    assert f"{out / 'study.csv'} is a folder, not a file: the study writes its study.csv there; move it aside" in err
    assert sorted(p.name for p in out.rglob("*")) == ["mine.txt", "study.csv", "study.md"]


@pytest.mark.long
def test_two_studies_started_together_get_two_default_folders(tmp_path):
    import subprocess
    import sys

    command = [sys.executable, "-m", "frictionlab", "study", "quickstart", *QUICK]
    procs = [subprocess.Popen([*command, "--seed", str(seed)], cwd=tmp_path, stdout=subprocess.PIPE, text=True)
             for seed in (1, 2)]  # fmt: skip
    outs = [p.communicate(timeout=120)[0] for p in procs]
    assert [p.returncode for p in procs] == [0, 0]
    folders = sorted((tmp_path / "runs").iterdir())
    assert len(folders) == 2 and all((f / "study.md").is_file() for f in folders)
    assert {out.split(" in ")[-1].strip().rstrip("/") for out in outs} == {f"runs/{f.name}" for f in folders}


def test_study_refuses_a_grid_beyond_the_memory_before_starting(tmp_path, capsys):
    out = tmp_path / "big"
    code = main(["study", "quickstart", "--axes", "grid", "--grid-factors", "1e6,1", "--quiet", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == ExitCode.RUNTIME_FAILURE, err
    assert "--grid-factors 1e+06" in err and "GiB is available" in err and "internal error" not in err
    assert not out.exists()


@pytest.mark.parametrize("axes", ["solver", "tolerance", "solver,tolerance"])
def test_axes_that_all_need_a_reference_where_there_is_none_are_refused(tmp_path, capsys, axes):
    """A line preset of mdr has no exact solver to compare with: --axes solver ran nothing, wrote a
    study.md of notes and said 'no axis measured enough to recommend anything' with exit code 0."""
    out = tmp_path / "study"
    code = main(["study", "quickstart", "--axes", axes, "--quiet", "--out", str(out)])
    err = capsys.readouterr().err
    assert code == ExitCode.USAGE, err
    assert f"--axes {axes}: nothing would run" in err and "no installed solver solves the elastic half-space" in err
    assert not out.exists()


def test_study_out_may_be_a_folder_name_that_is_not_utf8(tmp_path, capsys, figure_stubbed):
    import os

    out = tmp_path / os.fsdecode(b"st\xff")
    assert main(["study", "quickstart", *QUICK, "--out", str(out)]) == ExitCode.OK
    assert "st\\xff/" in capsys.readouterr().out
    assert "st\\xff" in (out / "study.md").read_text(encoding="utf-8")


def test_a_sweep_preset_is_studied_at_its_base_values_and_the_user_told(tmp_path, capsys, figure_stubbed):
    swept = {**TINY, "sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.9]}}}}
    for data, warned in ((swept, True), ({**swept, "sweep": None}, False)):
        preset, out = write(tmp_path, data), tmp_path / f"study-{warned}"
        assert main(["study", str(preset), "--axes", "realizations", "--out", str(out)]) == 0
        err = capsys.readouterr().err
        assert ("the preset's sweep is not studied" in err) is warned
        assert "H = 0.8" in (out / "study.md").read_text()  # the base value, not a point of the sweep


MDR_SURFACE = {
    "name": "mdr-surface", "seed": 3, "realizations": 2, "fit": {"bootstrap": 20},
    "spectrum": {"name": "power-law-2d", "params": {"hurst": 0.8, "points": 2048, "spacing": 1.0, "short_cutoff": 2.0,
                                                     "rms_height": 1.0}},
    "solver": {"name": "mdr"}, "loading": {"start": 0.5, "stop": 20.0, "steps": 8, "spacing": "log"},
}  # fmt: skip


def test_study_refuses_an_mdr_surface_whose_line_cannot_be_made_before_it_is_made(tmp_path, capsys, monkeypatch):
    """The study made the MDR-equivalent line of the preset's surface (the whole surface's
    synthesis) before it checked the memory, which counted the line alone: a surface too
    large to synthesise died of MemoryError ('out of memory: Unable to allocate ...'). It is
    refused first, naming the making. (The grid axis's surfaces are checked the same way;
    a refined surface keeps its band, so its making hardly grows.)"""
    import tracemalloc

    from frictionlab.compute import memory

    monkeypatch.setattr(memory, "available_memory", lambda: (256 * 2**20, "a test limit"))
    monkeypatch.setattr("frictionlab.tradeoff.axes.available_memory", memory.available_memory)
    preset, out = write(tmp_path, MDR_SURFACE), tmp_path / "study"
    tracemalloc.start()
    try:
        code = main(["study", str(preset), "--axes", "realizations", "--quiet", "--out", str(out)])
        peak = tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    err = capsys.readouterr().err
    assert code == ExitCode.RUNTIME_FAILURE, err
    assert "the study would need about" in err and "making the MDR-equivalent line of a surface of 4,194,304 points" in err
    assert "for the preset's grid" in err and "Traceback" not in err
    assert peak < 2048**2 * 8  # not one array of the 2048^2 surface: refused before its synthesis
    assert not out.exists()


def test_each_comparison_count_says_it_is_at_most_the_presets(capsys):
    """--points above the preset's N was capped to it without a word in the help, as
    --compare-realizations, --compare-steps and --grid-realizations once were."""
    assert main(["study", "--help"]) == 0
    help_text = " ".join(capsys.readouterr().out.split())
    for option in ("--points N", "--compare-realizations M", "--compare-steps K", "--grid-realizations M"):
        said = help_text.split(option, 2)[-1].split(" --", 1)[0]  # the option's own help (after the usage line)
        assert "at most the preset's" in said, (option, said)


def test_a_full_disk_says_so_plainly_and_how_to_write_the_study_once_there_is_room(tmp_path, capsys, monkeypatch):
    """A full disk after study.csv said '[Errno 28] No space left on device' and nothing more;
    the same command then refused the folder (its study.csv with no study.md) without --force."""
    import errno

    from frictionlab.tradeoff import outputs

    write_file = outputs.atomic_write

    def md_does_not_fit(path, write, *args, **keys):
        if path.name == "study.md":
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        write_file(path, write, *args, **keys)

    monkeypatch.setattr(outputs, "atomic_write", md_does_not_fit)
    out = tmp_path / "o"
    args = ["study", str(write(tmp_path, TINY)), "--out", str(out), "--axes", "steps",
            "--quiet"]  # fmt: skip
    assert main([*args, "--json"]) == ExitCode.RUNTIME_FAILURE
    captured = capsys.readouterr()
    said = (f"cannot write the study to {out}: No space left on device, nor to a temporary folder (No space left on "
            "device): its rows (study.csv) and recommendation are printed above; free some space and run the study "
            "again with --force (it replaces only study.csv, study.md and study.png)")  # fmt: skip
    assert captured.err.endswith(f"error: {said}\n")
    assert "\nstudy.csv:\naxis," in captured.err  # what was measured, kept where a person sees it
    assert json.loads(captured.out)["error"] == said  # the error object, as for every failure under --json
    monkeypatch.undo()
    assert main(args) == ExitCode.OUTPUT_REFUSED  # as said: without --force, the folder is not a study's
    assert main([*args, "--force"]) == ExitCode.OK
    assert {p.name for p in out.iterdir()} == {"study.csv", "study.md", "study.png"}


def test_a_study_whose_folder_cannot_be_written_keeps_its_files_elsewhere_and_says_how_to_move_them(tmp_path, capsys,
                                                                                                  monkeypatch):
    """A full disk (or a folder that refuses writes) lost every number measured: the study had to
    run again. Its files go to a temporary folder (TMPDIR, often another disk), and the message
    says the command that moves them, nothing measured again."""
    import errno
    import subprocess
    import tempfile

    from frictionlab.tradeoff import outputs

    out, spare_disk = tmp_path / "o", tmp_path / "spare-disk"
    spare_disk.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(spare_disk))
    write_file = outputs.atomic_write

    def out_is_full(path, write, *args, **keys):
        if path.parent == out:
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        write_file(path, write, *args, **keys)

    monkeypatch.setattr(outputs, "atomic_write", out_is_full)
    args = ["study", str(write(tmp_path, TINY)), "--out", str(out), "--axes", "steps", "--quiet"]
    assert main(args) == ExitCode.RUNTIME_FAILURE
    err = capsys.readouterr().err
    [spare] = spare_disk.iterdir()
    assert {p.name for p in spare.iterdir()} == {"study.csv", "study.md", "study.png"}
    assert f"cannot write the study to {out}: No space left on device; it was written to {spare}/ instead" in err
    move = err.split("can be written, ", 1)[1].strip()
    assert move == f"mkdir -p {out} && mv {spare}/study.* {out}/"
    kept = (spare / "study.csv").read_text()
    subprocess.run(["bash", "-c", move], check=True)
    assert (out / "study.csv").read_text() == kept and {p.name for p in out.iterdir()} == {"study.csv", "study.md", "study.png"}
    monkeypatch.undo()
    assert main(args) == ExitCode.OK  # the folder moved into is a study of the preset: written again without --force

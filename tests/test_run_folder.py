"""The run folder keeps its promises: nothing of the user's is deleted or
overwritten without --force, the manifest lists every chunk and input file
with its SHA-256, failed realizations are retried on resume, relative input
files are the preset's neighbours whatever the current folder, a changed
input file stops a resume, and a finished folder has no lock and one chunk."""

from __future__ import annotations

import hashlib
import json
import os
import subprocess
import sys
import threading
from pathlib import Path

import numpy as np
import pytest
import yaml

from frictionlab.runs import runner
from frictionlab.cli import main
from frictionlab.errors import ExitCode, OutputRefused
from frictionlab.preset import build_scene
from frictionlab.runs.rundir import RunDirectory
from frictionlab.runs.runner import run_to_folder
from frictionlab.options import RunOptions

from .conftest import SMALL_PRESET, merge
from .faults import FlakyPowerLaw, with_spectrum
from .test_resume import NO_PLOT, CancelAfter, same_files


def write(path: Path, data: dict) -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    path.write_text(yaml.safe_dump(data, sort_keys=False))
    return path


def tree(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


QUICK = merge(SMALL_PRESET, NO_PLOT)


# ------------------------------------------------------------------ never delete or overwrite


def test_a_folder_left_by_a_run_killed_as_it_started_is_started_afresh_and_nothing_else_is(tmp_path):
    """Killed between making its folder and writing its manifest, a run leaves an empty chunks/
    folder and maybe a temporary file of its preset: a sweep resumed then refused that point
    as "not empty". Such a folder starts afresh; one more file of anyone's is still refused."""
    scene = build_scene(merge(SMALL_PRESET, {"realizations": 3, **NO_PLOT}))
    folder = tmp_path / "point"
    (folder / "chunks").mkdir(parents=True)
    (folder / ".preset.yaml.t5cpv2ct.tmp").write_text("half a preset")
    outcome, _ = run_to_folder(scene, folder, RunOptions(workers=1))
    assert outcome.status == "completed" and outcome.done == 3
    later = tmp_path / "later"  # killed after its preset.yaml, before its manifest took its name
    with RunDirectory(later) as run_dir:
        run_dir.start(scene, resume=False)
    (later / "run.json").rename(later / ".run.json.qhyeg728.tmp")
    outcome, _ = run_to_folder(scene, later, RunOptions(workers=1))
    assert outcome.status == "completed" and outcome.done == 3
    edited = tmp_path / "edited"  # a preset.yaml that is not this run's to the byte: someone's
    with RunDirectory(edited) as run_dir:
        run_dir.start(scene, resume=False)
    (edited / "run.json").unlink()
    (edited / "preset.yaml").write_text((edited / "preset.yaml").read_text() + "# my note\n")
    with pytest.raises(OutputRefused, match="it holds 'preset.yaml'"):
        run_to_folder(scene, edited, RunOptions(workers=1))
    assert (edited / "preset.yaml").read_text().endswith("# my note\n")
    other = tmp_path / "other"
    (other / "chunks").mkdir(parents=True)
    (other / "chunks" / "mine.txt").write_text("not frictionlab's")  # a chunks/ folder that is not empty
    with pytest.raises(OutputRefused, match="is not empty and is not a frictionlab run folder"):
        run_to_folder(scene, other, RunOptions(workers=1))
    assert (other / "chunks" / "mine.txt").read_text() == "not frictionlab's"


def test_out_into_a_folder_that_is_not_a_run_is_refused_and_force_deletes_nothing(tmp_path, capsys):
    preset = write(tmp_path / "p.yaml", QUICK)
    folder = tmp_path / "thesis"
    (folder / "chunks").mkdir(parents=True)
    (folder / "notes.txt").write_text("three years of notes")
    (folder / "chunks" / "00000000-00000003.npz").write_bytes(b"my own file, named like a chunk")
    (folder / "summary.json").write_text("{}")
    before = tree(folder)

    assert main(["run", str(preset), "--out", str(folder), "--quiet"]) == ExitCode.OUTPUT_REFUSED
    err = capsys.readouterr().err
    assert f"{folder} is not empty and is not a frictionlab run folder" in err and "--force" in err
    assert tree(folder) == before

    assert main(["run", str(preset), "--out", str(folder), "--quiet", "--force"]) == ExitCode.OK
    after = tree(folder)
    assert after["notes.txt"] == before["notes.txt"]  # never touched
    assert after["chunks/00000000-00000003.npz"] == before["chunks/00000000-00000003.npz"]  # not ours: kept
    assert json.loads(after["summary.json"])["status"] == "completed"  # --force: our file replaces theirs


def test_a_finished_run_of_another_preset_is_refused_and_the_same_preset_reruns(tmp_path, capsys):
    first = write(tmp_path / "a.yaml", QUICK)
    other = write(tmp_path / "b.yaml", merge(QUICK, {"seed": 8, "spectrum": {"params": {"hurst": 0.7}}}))
    out = tmp_path / "run"
    assert main(["run", str(first), "--out", str(out), "--quiet"]) == ExitCode.OK
    before = tree(out)
    assert main(["run", str(other), "--out", str(out), "--quiet"]) == ExitCode.OUTPUT_REFUSED
    err = capsys.readouterr().err
    assert "holds a finished run of another preset (it differs in seed, spectrum.params.hurst)" in err
    assert tree(out) == before
    with pytest.warns(UserWarning, match="holds a completed run of this preset: it runs again"):
        assert main(["run", str(first), "--out", str(out), "--quiet"]) == ExitCode.OK  # the same preset: rerun
    assert main(["run", str(other), "--out", str(out), "--quiet", "--force"]) == ExitCode.OK
    assert json.loads((out / "summary.json").read_text())["seed"] == 8


@pytest.mark.parametrize("first, then", [("run", "sweep"), ("sweep", "run")])
@pytest.mark.parametrize("detach", [False, True])
def test_a_sweep_forced_into_a_runs_folder_or_a_run_into_a_sweeps_is_refused(tmp_path, capsys, first, then, detach):
    """--force wrote a sweep beside a run (or a run beside a sweep): both manifests stayed, and the
    folder was read as the run (runs, load, resume), the sweep out of sight. Refused, forced or
    not, before anything is written, saying what the folder holds and what to do."""
    presets = {"run": write(tmp_path / "run.yaml", QUICK),
               "sweep": write(tmp_path / "sweep.yaml", {**QUICK, "sweep": {"parameters": {"seed": {"values": [1, 2]}}}})}
    out = tmp_path / "out"
    assert main(["run", str(presets[first]), "--out", str(out), "--quiet", "--no-plot"]) == ExitCode.OK
    before, held = tree(out), "run.json" if first == "run" else "sweep.json"
    capsys.readouterr()
    for force in ([], ["--force"]):
        command = ["run", str(presets[then]), "--out", str(out), "--quiet", "--no-plot", *force, *(["--detach"] * detach)]
        assert main(command) == ExitCode.OUTPUT_REFUSED
        err = capsys.readouterr().err
        assert f"error: {out} holds a frictionlab {first} ({held}), not a {then}: a {then} is not written into a {first}'s " \
               "folder, even forced (--force; force=True in Python)" in err, err
        assert f"move the {first} aside (mv {out} NEW_NAME)" in err and "Traceback" not in err
        assert tree(out) == before


def test_force_over_an_unfinished_run_deletes_only_the_chunks_its_manifest_lists(make_scene, tmp_path):
    scene = make_scene({"realizations": 30, **NO_PLOT})
    cancel = threading.Event()
    run_to_folder(scene, tmp_path / "run", RunOptions(workers=1), listeners=[CancelAfter(12, cancel)], cancel=cancel)
    chunks = tmp_path / "run" / "chunks"
    listed = set(json.loads((tmp_path / "run" / "run.json").read_text())["chunks"])
    (chunks / "mine.npz").write_bytes(b"user data")
    with pytest.raises(OutputRefused, match="holds an unfinished run"):
        run_to_folder(scene, tmp_path / "run", RunOptions(workers=1))
    outcome, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1, force=True))
    assert outcome.status == "completed" and outcome.extra["resumed"] == 0
    assert (chunks / "mine.npz").read_bytes() == b"user data"
    now = set(json.loads((tmp_path / "run" / "run.json").read_text())["chunks"])
    assert {p.name for p in chunks.iterdir()} == now | {"mine.npz"}  # the old chunks went, the user's stayed
    assert listed


@pytest.mark.filterwarnings("ignore:resume of .* not in the manifest")  # the folder left in chunks/: said, kept
@pytest.mark.parametrize("how", ["run --force", "resume of an unfinished compaction"])
def test_a_folder_named_as_a_listed_chunk_is_kept_and_the_run_goes_on(make_scene, tmp_path, how):
    """A listed (or retired) chunk that is a folder is no chunk frictionlab wrote: unlinking it
    failed, and the forced run or the resume ended in 'cannot write results' (exit code 1)."""
    scene = make_scene({"realizations": 30, **NO_PLOT})
    cancel = threading.Event()
    run_to_folder(scene, tmp_path / "run", RunOptions(workers=1), listeners=[CancelAfter(12, cancel)], cancel=cancel)
    manifest = json.loads((tmp_path / "run" / "run.json").read_text())
    name = "00000029-00000029.npz" if how.startswith("resume") else sorted(manifest["chunks"])[0]
    if how.startswith("resume"):
        manifest["retired"] = [name]
        (tmp_path / "run" / "run.json").write_text(json.dumps(manifest))
    else:
        (tmp_path / "run" / "chunks" / name).unlink()
    (tmp_path / "run" / "chunks" / name).mkdir()
    (tmp_path / "run" / "chunks" / name / "mine.txt").write_text("user data")
    outcome, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1, force=True, resume=how.startswith("resume")))
    assert outcome.status == "completed" and outcome.done == 30
    assert (tmp_path / "run" / "chunks" / name / "mine.txt").read_text() == "user data"


def test_the_manifest_lists_every_chunk_with_its_sha256_as_it_is_written(make_scene, tmp_path, monkeypatch):
    monkeypatch.setattr(runner, "UNSAVED_WORK_SECONDS", 0.0)  # each chunk written as it finishes
    scene = make_scene({"realizations": 30, **NO_PLOT})
    seen = []

    class Check:
        from frictionlab import hookimpl

        @hookimpl
        def realization_done(self, done):  # the chunk holding it is already written and listed
            manifest = json.loads((tmp_path / "run" / "run.json").read_text())
            for name, digest in manifest["chunks"].items():
                assert hashlib.sha256((tmp_path / "run" / "chunks" / name).read_bytes()).hexdigest() == digest
            seen.append(len(manifest["chunks"]))

    cancel = threading.Event()
    run_to_folder(scene, tmp_path / "run", RunOptions(workers=1), listeners=[Check(), CancelAfter(25, cancel)], cancel=cancel)
    assert seen and seen[-1] >= 3 and seen == sorted(seen)
    manifest = json.loads((tmp_path / "run" / "run.json").read_text())
    assert manifest["status"] == "cancelled" and manifest["fingerprint"] and manifest["preset"]["seed"] == 7


def test_a_short_run_writes_its_chunks_once_and_the_same_files_as_a_chunk_at_a_time(
    make_scene, tmp_path, monkeypatch, run_folder_writes
):
    """Bookkeeping sized to the run: a sub-second run keeps its finished chunks until the
    end and writes them as one file (no compaction, a third of the writes); the folder
    holds what a run writing each chunk as it finished leaves, to the bit but for the
    realizations' own times."""
    scene = make_scene({"realizations": 30, **NO_PLOT})
    written = run_folder_writes
    run_to_folder(scene, tmp_path / "batched", RunOptions(workers=1))
    batched = list(written)
    monkeypatch.setattr(runner, "UNSAVED_WORK_SECONDS", 0.0)
    written.clear()
    run_to_folder(scene, tmp_path / "each", RunOptions(workers=1))
    assert batched.count("00000000-00000029.npz") == 1 and len([n for n in batched if n.endswith(".npz")]) == 1
    assert batched.count("run.json") <= 3 and len(written) >= 3 * len(batched)  # each chunk, its manifest, compaction
    same_files(tmp_path / "batched", tmp_path / "each")
    for folder in ("batched", "each"):
        assert sorted(p.name for p in (tmp_path / folder / "chunks").iterdir()) == ["00000000-00000029.npz"]
    with np.load(tmp_path / "batched" / "chunks" / "00000000-00000029.npz") as one, np.load(
        tmp_path / "each" / "chunks" / "00000000-00000029.npz"
    ) as other:
        assert one.files == other.files
        for name in one.files:
            if name != "seconds":
                np.testing.assert_array_equal(one[name], other[name], err_msg=name)
    manifests = [json.loads((tmp_path / d / "run.json").read_text()) for d in ("batched", "each")]
    for manifest in manifests:
        manifest.pop("chunks")  # their SHA-256 covers the times
        assert manifest.pop("elapsed_seconds") > 0  # the run's wall time, its own in each
    assert manifests[0] == manifests[1]


def test_a_finished_run_leaves_no_lock_and_its_chunks_compacted_into_one(make_scene, tmp_path):
    scene = make_scene({"realizations": 30, **NO_PLOT})
    outcome, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=2))
    assert outcome.status == "completed"
    assert not (tmp_path / "run" / "run.lock").exists()
    files = [p.name for p in (tmp_path / "run" / "chunks").iterdir()]
    manifest = json.loads((tmp_path / "run" / "run.json").read_text())
    assert files == list(manifest["chunks"]) == ["00000000-00000029.npz"]
    again, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1, resume=True))  # verified, nothing recomputed
    assert again.extra["resumed"] == 30
    with RunDirectory(tmp_path / "run"):  # the lock is free and taken anew
        assert (tmp_path / "run" / "run.lock").exists()
    assert not (tmp_path / "run" / "run.lock").exists()


def test_failed_realizations_are_retried_on_resume(make_scene, tmp_path, capsys):
    flag = tmp_path / "flaky"
    flag.touch()
    scene = with_spectrum(make_scene({"realizations": 20, **NO_PLOT}), FlakyPowerLaw, flag=str(flag))
    first, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1))
    assert first.status == "completed" and 3 <= len(first.failures) <= 15
    flag.unlink()
    from frictionlab.progress import ProgressReporter

    second, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=2, resume=True), listeners=[ProgressReporter()])
    assert second.failures == [] and second.done == 20
    assert second.extra["retried"] == len(first.failures) and second.extra["resumed"] == first.done
    assert f"{len(first.failures)} failed ones retried" in capsys.readouterr().err
    summary = json.loads((tmp_path / "run" / "summary.json").read_text())
    assert summary["retried_realizations"] == len(first.failures)
    run_to_folder(scene, tmp_path / "clean", RunOptions(workers=1))
    same_files(tmp_path / "run", tmp_path / "clean")


# ------------------------------------------------------------------ input files


PROFILE = {**QUICK, "realizations": 2, "spectrum": {"name": "profile-file", "params": {"path": "scan.csv", "spacing": 0.5}}}


def _scan(path: Path, wiggle: float = 0.05) -> None:
    x = np.arange(512)
    np.savetxt(path, 3.0 * np.cos(2 * np.pi * x / 128) + wiggle * np.sin(2 * np.pi * x / 16))


def test_a_relative_profile_path_is_the_preset_files_neighbour_whatever_the_current_folder(tmp_path, monkeypatch):
    preset = write(tmp_path / "study" / "scan.yaml", PROFILE)
    _scan(tmp_path / "study" / "scan.csv")
    (tmp_path / "elsewhere").mkdir()
    _scan(tmp_path / "elsewhere" / "scan.csv", wiggle=0.5)  # another line of the same name: must not be read
    results = {}
    for cwd in ("study", "elsewhere"):
        monkeypatch.chdir(tmp_path / cwd)
        assert main(["run", str(preset), "--out", str(tmp_path / f"from-{cwd}"), "--quiet"]) == ExitCode.OK
        results[cwd] = (tmp_path / f"from-{cwd}" / "curve.csv").read_text()
    assert results["study"] == results["elsewhere"]
    manifest = json.loads((tmp_path / "from-elsewhere" / "run.json").read_text())
    recorded = manifest["inputs"]["spectrum.params.path"]
    assert recorded["path"] == str(tmp_path / "study" / "scan.csv")
    assert recorded["sha256"] == hashlib.sha256((tmp_path / "study" / "scan.csv").read_bytes()).hexdigest()
    assert manifest["preset"]["spectrum"]["params"]["path"] == recorded["path"]


def test_resume_refuses_an_input_file_that_changed(tmp_path, monkeypatch, capsys):
    preset = write(tmp_path / "scan.yaml", merge(PROFILE, {"realizations": 6}))
    _scan(tmp_path / "scan.csv")
    out = tmp_path / "run"
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(preset), "--out", str(out), "--quiet"]) == ExitCode.OK
    assert main(["resume", str(out), "--quiet"]) == ExitCode.OK  # unchanged: fine
    _scan(tmp_path / "scan.csv", wiggle=0.06)
    capsys.readouterr()
    assert main(["resume", str(out), "--quiet"]) == ExitCode.RUN_FOLDER
    err = capsys.readouterr().err
    assert f"the input file spectrum.params.path ({tmp_path / 'scan.csv'}) changed since the run started" in err


def test_a_sweep_into_a_folder_that_is_not_its_own_is_refused(tmp_path, capsys):
    preset = write(tmp_path / "s.yaml", merge(QUICK, {"realizations": 2, "sweep": {"parameters": {
        "spectrum.params.hurst": {"values": [0.6, 0.9]}}}}))  # fmt: skip
    folder = tmp_path / "out"
    folder.mkdir()
    (folder / "notes.txt").write_text("mine")
    assert main(["run", str(preset), "--out", str(folder), "--quiet"]) == ExitCode.OUTPUT_REFUSED
    assert "is not empty and is not the folder of a frictionlab sweep" in capsys.readouterr().err
    assert [p.name for p in folder.iterdir()] == ["notes.txt"]
    assert main(["run", str(preset), "--out", str(tmp_path / "sweep"), "--quiet"]) == ExitCode.OK
    with pytest.warns(UserWarning, match="holds a completed run of this preset: it runs again"):  # each point of its own
        assert main(["run", str(preset), "--out", str(tmp_path / "sweep"), "--quiet", "--no-plot"]) == ExitCode.OK  # its own: rerun
    other = write(tmp_path / "t.yaml", merge(QUICK, {"realizations": 2, "sweep": {"parameters": {
        "spectrum.params.hurst": {"values": [0.5]}}}}))  # fmt: skip
    assert main(["run", str(other), "--out", str(tmp_path / "sweep"), "--quiet"]) == ExitCode.OUTPUT_REFUSED
    err = capsys.readouterr().err
    assert "holds another sweep" in err
    # it named no field: which values differ, stored and given
    assert "\n  sweep.parameters.spectrum.params.hurst.values: [0.6, 0.9] in the run directory, [0.5] given" in err
    assert main(["run", str(preset), "--out", str(tmp_path / "sweep"), "--resume", "--quiet",
                 "--set", "realizations=3"]) == ExitCode.OUTPUT_REFUSED  # fmt: skip
    assert capsys.readouterr().err.endswith("\n  realizations: 2 in the run directory, 3 given\n")


def _status(folder: Path) -> str:
    return json.loads((folder / "run.json").read_text())["status"]


def test_a_figure_that_cannot_be_written_fails_the_command_but_the_run_is_finished(tmp_path, capsys):
    preset = write(tmp_path / "p.yaml", merge(SMALL_PRESET, {"output": {"plot": True}}))
    out = tmp_path / "run"
    (out / "plot.png").mkdir(parents=True)  # plot.png cannot be written: it is a folder
    assert main(["run", str(preset), "--out", str(out), "--quiet", "--force"]) == ExitCode.RUNTIME_FAILURE
    err = capsys.readouterr().err
    assert "cannot write" in err and "plot.png" in err and "the numbers are written" in err
    assert _status(out) == "completed" and json.loads((out / "summary.json").read_text())["status"] == "completed"
    with pytest.warns(UserWarning, match="holds a completed run of this preset: it runs again"):
        assert main(["run", str(preset), "--out", str(out), "--quiet", "--no-plot"]) == ExitCode.OK  # not "unfinished"


@pytest.mark.parametrize(
    "damage, said",
    [
        (lambda d: {**d, "chunks": "abc"}, "chunks is not a mapping"),
        (lambda d: {**d, "chunks": ["a"]}, "chunks is not a mapping"),
        (lambda d: {**d, "chunks": {"00000000-00000005.npz": 5}}, "chunks is not a mapping"),
        (lambda d: {**d, "status": 5}, "status is not a word"),
        (lambda d: {**d, "format": "2"}, "format is not a whole number, but a string"),  # was: every chunk
        (lambda d: {**d, "format": 2.0}, "format is not a whole number, but a number"),  # ignored and computed again
        (lambda d: {**d, "format": 0}, "(format 0: the first is 1)"),  # no frictionlab wrote it: as "2" was
        (lambda d: {**d, "format": -10**30}, "(format of more than 9 digits: the first is 1)"),
        (lambda d: {**d, "preset": "x"}, "preset is not a mapping"),
        (lambda d: {**d, "inputs": [1]}, "inputs is not a mapping"),
        (lambda d: "[" * 100_000 + "]" * 100_000, "nested too deep"),
    ],
)
def test_a_damaged_manifest_is_a_run_folder_error_naming_what_is_wrong(tmp_path, capsys, damage, said):
    preset = write(tmp_path / "p.yaml", QUICK)
    out = tmp_path / "run"
    assert main(["run", str(preset), "--out", str(out), "--quiet"]) == ExitCode.OK
    damaged = damage(json.loads((out / "run.json").read_text()))
    (out / "run.json").write_text(damaged if isinstance(damaged, str) else json.dumps(damaged))
    capsys.readouterr()
    for argv in (["resume", str(out)], ["run", str(preset), "--out", str(out), "--quiet"]):
        assert main(argv) == ExitCode.RUN_FOLDER
        err = capsys.readouterr().err
        assert "run.json is damaged" in err and said in err


@pytest.mark.long  # processes started together
def test_runs_started_together_without_out_each_get_a_folder_of_their_own(tmp_path):
    preset = write(tmp_path / "p.yaml", QUICK)
    command = [sys.executable, "-m", "frictionlab", "run", str(preset), "--quiet", "--workers", "1"]
    runs = [subprocess.Popen([*command, "--seed", str(seed)], cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE)
            for seed in range(4)]  # fmt: skip
    errors = [run.communicate(timeout=120)[1].decode() for run in runs]
    assert [run.returncode for run in runs] == [0] * 4, errors
    folders = sorted((tmp_path / "runs").iterdir())
    assert len(folders) == 4 and all((f / "summary.json").is_file() for f in folders)
    seeds = {json.loads((f / "summary.json").read_text())["seed"] for f in folders}
    assert seeds == {0, 1, 2, 3}


def test_a_run_refused_before_it_starts_leaves_no_empty_folder_behind(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    preset = write(tmp_path / "p.yaml", merge(QUICK, {"spectrum": {"params": {"points": 10**9}}}))
    assert main(["run", str(preset), "--quiet"]) == ExitCode.RUNTIME_FAILURE
    assert "would need about" in capsys.readouterr().err
    assert not (tmp_path / "runs").exists() or list((tmp_path / "runs").iterdir()) == []  # refused before any folder is made


def test_what_cannot_be_resumed_is_said_and_nothing_is_made(tmp_path, capsys):
    preset = write(tmp_path / "p.yaml", QUICK)
    (tmp_path / "afile").write_text("mine")
    for argv, said in (
        (["resume", str(tmp_path / "missing")], "missing does not exist: there is no run to resume there"),
        (["resume", str(tmp_path / "afile")], "afile is not a folder: there is no run to resume there"),
        (["run", str(preset), "--resume", "--out", str(tmp_path / "new")], "new is not a run folder to resume"),
    ):
        assert main(argv) == ExitCode.RUN_FOLDER
        assert said in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["afile", "p.yaml"]  # no folder made
    assert (tmp_path / "afile").read_text() == "mine"
    assert main(["run", str(preset), "--out", "", "--quiet"]) == ExitCode.USAGE
    assert "--out names no folder" in capsys.readouterr().err


def test_a_lock_that_is_not_a_file_is_named(tmp_path, capsys):
    preset = write(tmp_path / "p.yaml", QUICK)
    (tmp_path / "run" / "run.lock").mkdir(parents=True)
    assert main(["run", str(preset), "--out", str(tmp_path / "run"), "--quiet"]) == ExitCode.RUN_FOLDER
    assert "run.lock is not a regular file" in capsys.readouterr().err
    assert (tmp_path / "run" / "run.lock").is_dir()  # left as it was


def test_results_keep_the_preset_the_start_wrote_and_restore_one_changed_or_linked(tmp_path, registry, monkeypatch):
    from frictionlab.runs import results

    scene = build_scene(merge(SMALL_PRESET, {"realizations": 4}), registry=registry)
    written = []
    real_write = results.atomic_write
    monkeypatch.setattr(results, "atomic_write", lambda path, *a, **k: (written.append(Path(path).name), real_write(path, *a, **k)))
    out = tmp_path / "run"
    outcome, _ = run_to_folder(scene, out, RunOptions(workers=1), plot=False)
    expected = yaml.safe_dump(scene.resolved(), sort_keys=False)
    assert (out / "preset.yaml").read_text() == expected
    assert "preset.yaml" not in written  # the run's start wrote these bytes: not written (and synced) again
    (out / "preset.yaml").write_text("name: edited by hand\n")
    results.write_results(out, scene, outcome)
    assert (out / "preset.yaml").read_text() == expected  # restored
    mine = tmp_path / "mine.yaml"
    mine.write_text(expected)
    (out / "preset.yaml").unlink()
    (out / "preset.yaml").symlink_to(mine)  # the same bytes, through a link: replaced, never written through
    results.write_results(out, scene, outcome)
    assert not (out / "preset.yaml").is_symlink() and (out / "preset.yaml").read_text() == expected
    assert mine.read_text() == expected and written.count("preset.yaml") == 2


def test_a_disk_too_full_to_say_who_holds_the_lock_does_not_stop_the_run_nor_leave_the_lock(tmp_path, monkeypatch):
    """A full disk as run.lock was given its holder's pid ended the run at once ('nothing was
    kept') and left run.lock behind, never removed, though the lock itself holds."""
    import errno

    from frictionlab.cli import main

    def full(*args):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(os, "pwrite", full)
    out = tmp_path / "run"
    assert main(["run", "quickstart", "--out", str(out), "--workers", "1", "--quiet", "--no-plot"]) == 0
    assert (out / "summary.json").is_file() and not (out / "run.lock").exists()


def test_resume_refuses_a_file_now_read_otherwise_and_resumes_an_older_folder(tmp_path, monkeypatch, capsys):
    """The same bytes read otherwise by another version (another channel, another levelling) would
    mix realizations of two surfaces: the manifest records what was read (in a run folder of an
    older version it is absent, and the resume goes on)."""
    preset = write(tmp_path / "scan.yaml", merge(PROFILE, {"realizations": 6}))
    _scan(tmp_path / "scan.csv")
    out = tmp_path / "run"
    monkeypatch.chdir(tmp_path)
    assert main(["run", str(preset), "--out", str(out), "--quiet"]) == ExitCode.OK
    manifest = json.loads((out / "run.json").read_text())
    read = manifest["read"]
    assert read["shape"] == [len((tmp_path / "scan.csv").read_text().split())] and "caveats" not in read
    manifest["read"] = {**read, "rms_height": read["rms_height"] * 1.5, "detrend": "quadratic"}
    (out / "run.json").write_text(json.dumps(manifest))
    capsys.readouterr()
    assert main(["resume", str(out), "--quiet"]) == ExitCode.RUN_FOLDER
    err = capsys.readouterr().err
    assert "is read otherwise than when the run started" in err and "detrend: 'quadratic' then, 'mean' now" in err
    assert "rms_height:" in err and "SHA-256" not in err
    del manifest["read"]
    (out / "run.json").write_text(json.dumps(manifest))
    assert main(["resume", str(out), "--quiet"]) == ExitCode.OK
    assert json.loads((out / "run.json").read_text())["read"] == read  # recorded from now on


def test_a_run_that_draws_no_figure_says_the_one_in_its_folder_is_an_earlier_run_s(tmp_path, capsys):
    """`run B --out DIR_of_A --force --no-plot` left A's plot.png beside B's numbers without a word."""
    preset = write(tmp_path / "p.yaml", merge(SMALL_PRESET, {"output": {"plot": True}}))
    other = write(tmp_path / "q.yaml", merge(SMALL_PRESET, {"output": {"plot": True}, "seed": 8}))
    out = tmp_path / "run"
    assert main(["run", str(preset), "--out", str(out), "--quiet"]) == ExitCode.OK
    drawn = (out / "plot.png").read_bytes()
    capsys.readouterr()
    with pytest.warns(UserWarning, match=r"plot.png is an earlier run's figure, not this one's \(none was drawn\): "
                                         r"`frictionlab plot .* --force` draws this run's"):  # fmt: skip
        assert main(["run", str(other), "--out", str(out), "--quiet", "--force", "--no-plot"]) == ExitCode.OK
    assert (out / "plot.png").read_bytes() == drawn  # the user's folder: nothing deleted
    with pytest.warns(UserWarning, match="holds a completed run of this preset") as said:
        assert main(["run", str(other), "--out", str(out), "--quiet", "--force"]) == ExitCode.OK
    assert not any("earlier run" in str(w.message) for w in said)  # drawn: nothing said of it

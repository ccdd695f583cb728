"""``frictionlab runs`` and the listing under it: a damaged run folder is listed as damaged
with its reason (never hidden, never shown as completed), and a run whose progress file
cannot be read is counted from its chunks."""

import json
import os

import pytest

from frictionlab.cli import main
from frictionlab.runs.detached import list_run_states, run_state
from frictionlab.options import RunOptions
from frictionlab.preset import build_scene
from frictionlab.runs.runner import run_to_folder

from .conftest import SMALL_PRESET, merge

TINY = merge(SMALL_PRESET, {"realizations": 4, "spectrum": {"params": {"points": 256}}, "fit": {"bootstrap": 20}})


def _run(folder, registry, seed=1):
    run_to_folder(build_scene(merge(TINY, {"seed": seed}), registry=registry), folder, RunOptions(workers=1), plot=False)


def _damage(runs, registry, tmp_path):
    """Three damaged folders next to a sound one: a junk summary.json, one that is a
    link (to the sound one's), a junk sweep.json."""
    _run(runs / "sound", registry)
    _run(runs / "junk", registry, seed=2)
    (runs / "junk" / "summary.json").write_text("{not json")
    _run(runs / "linked", registry, seed=3)
    (runs / "linked" / "summary.json").unlink()
    (runs / "linked" / "summary.json").symlink_to(runs / "sound" / "summary.json")
    (runs / "sweep").mkdir()
    (runs / "sweep" / "sweep.json").write_text("[1, 2")


def test_damaged_folders_are_listed_as_damaged_with_their_reason(tmp_path, registry, capsys):
    runs = tmp_path / "runs"
    _damage(runs, registry, tmp_path)
    states = {s.folder.name: s for s in list_run_states(runs)}
    assert set(states) == {"sound", "junk", "linked", "sweep"}
    assert (states["sound"].status, states["sound"].reason) == ("completed", None)
    for name in ("junk", "linked", "sweep"):
        assert states[name].status == "damaged", name
    assert "summary.json" in states["junk"].reason and "not valid JSON" in states["junk"].reason
    assert "summary.json" in states["linked"].reason and "link" in states["linked"].reason
    assert "sweep.json" in states["sweep"].reason and states["sweep"].kind == "sweep"

    assert main(["runs", str(runs), "--json"]) == 0
    listed = {os.path.basename(r["folder"]): r for r in json.loads(capsys.readouterr().out)["runs"]}
    assert {name: (r["status"], r["reason"] is None) for name, r in listed.items()} == {
        "sound": ("completed", True), "junk": ("damaged", False), "linked": ("damaged", False), "sweep": ("damaged", False)}
    assert main(["runs", str(runs)]) == 0
    out = capsys.readouterr().out
    for name in ("junk", "linked", "sweep"):
        line = next(line for line in out.splitlines() if line.startswith(str(runs / name) + " is damaged: "))
        assert line.endswith(states[name].reason)
    assert not any("completed" in line for line in out.splitlines() if "/junk " in line or "/linked " in line)


def test_a_run_whose_progress_file_is_a_link_is_counted_from_its_chunks(tmp_path, registry, capsys):
    out = tmp_path / "runs" / "run"
    _run(out, registry)
    (out / "summary.json").unlink()  # ended before its summary: the count must come from somewhere else
    manifest = json.loads((out / "run.json").read_text())
    (out / "run.json").write_text(json.dumps({**manifest, "status": "interrupted"}))
    (out / "progress.jsonl").unlink(missing_ok=True)
    (tmp_path / "elsewhere.jsonl").write_text("")
    (out / "progress.jsonl").symlink_to(tmp_path / "elsewhere.jsonl")
    state = run_state(out)
    assert (state.status, state.done, state.total) == ("interrupted", 4, 4)
    assert main(["runs", str(tmp_path / "runs")]) == 0
    assert "4/4" in capsys.readouterr().out


def test_a_run_that_ended_unfinished_counts_what_its_chunks_hold_not_what_its_log_heard(tmp_path, registry, capsys):
    """A kill -9 loses the realizations done but not yet stored: `runs` said 3253 done where
    the resume restored 3097. An ended run counts what a resume restores."""
    out = tmp_path / "runs" / "run"
    _run(out, registry)
    (out / "summary.json").unlink()
    manifest = json.loads((out / "run.json").read_text())
    kept = _stored_only(out, [0, 1])  # two realizations stored, the rest lost with the process
    (out / "run.json").write_text(json.dumps({**manifest, "status": "interrupted", "chunks": kept}))
    with (out / "progress.jsonl").open("a") as log:  # the log heard all 4 done
        log.write(json.dumps({"event": "realization", "index": 3, "done": 4, "total": 4, "ok": True}) + "\n")
    state = run_state(out)
    assert (state.status, state.done, state.total) == ("interrupted", 2, 4)
    assert main(["runs", str(tmp_path / "runs")]) == 0
    assert "2/4" in capsys.readouterr().out


def _stored_only(out, indices, name=None):
    """The run's chunks replaced by one chunk holding only the realizations ``indices`` (named
    by their range, or ``name``): what a run killed with those stored leaves; its manifest entry."""
    import numpy as np

    chunks = out / "chunks"
    arrays = {}
    for path in sorted(chunks.glob("*.npz")):
        with np.load(path) as data:
            keep = np.isin(data["index"], indices)
            for key in data.files:
                value = data[key][keep] if key not in ("failed_index", "failed_seconds", "failed_error") else data[key]
                arrays[key] = np.concatenate([arrays[key], value]) if key in arrays else value
        path.unlink()
    name = name or f"{min(indices):08d}-{max(indices):08d}.npz"
    np.savez(chunks / name, **arrays)
    return {name: "0" * 64}  # the checksum is a resume's to verify, not a count's


def _interrupted_with(out, chunks):
    (out / "summary.json").unlink(missing_ok=True)
    manifest = json.loads((out / "run.json").read_text())
    (out / "run.json").write_text(json.dumps({**manifest, "status": "interrupted", "chunks": chunks}))


def test_a_chunk_whose_range_has_gaps_counts_the_realizations_it_holds(tmp_path, registry, capsys):
    """Realizations finish out of order on several workers, so a chunk named 0..3 may hold
    0, 1 and 3: the count is what it holds (a resume restores 3), not its name's range (4)."""
    out = tmp_path / "runs" / "run"
    _run(out, registry)
    _interrupted_with(out, _stored_only(out, [0, 1, 3]))
    state = run_state(out)
    assert (state.status, state.done, state.total) == ("interrupted", 3, 4)
    assert main(["runs", str(tmp_path / "runs")]) == 0
    assert "3/4" in capsys.readouterr().out


def test_a_forged_chunk_counts_nothing_and_sizes_no_buffer(tmp_path, registry):
    """A chunk whose index array's header claims 10^12 values, one whose indices lie outside
    its name's range, one that is not a zip, one that is a link to a sound chunk: each holds
    none of the count, and none makes the count allocate what a header claims."""
    import io
    import zipfile

    import numpy as np

    def npy(value):
        buffer = io.BytesIO()
        np.lib.format.write_array(buffer, np.asarray(value, np.int64))
        return buffer.getvalue()

    def chunk(path, index):
        with zipfile.ZipFile(path, "w") as archive:
            archive.writestr("index.npy", index)
            archive.writestr("failed_index.npy", npy([]))

    out = tmp_path / "runs" / "run"
    _run(out, registry)
    entries = _stored_only(out, [0])  # one sound chunk: 1 stored
    huge = io.BytesIO()
    np.lib.format.write_array_header_1_0(huge, {"descr": "<i8", "fortran_order": False, "shape": (10**12,)})
    chunk(out / "chunks" / "00000001-00000001.npz", huge.getvalue())
    claims = io.BytesIO()  # a name whose range allows 10^8 indices, a header claiming them, a file of bytes
    np.lib.format.write_array_header_1_0(claims, {"descr": "<i8", "fortran_order": False, "shape": (10**8,)})
    chunk(out / "chunks" / "00000001-99999999.npz", claims.getvalue())
    chunk(out / "chunks" / "00000002-00000002.npz", npy([3]))  # outside 2..2
    (out / "chunks" / "00000003-00000003.npz").write_bytes(b"not a zip")
    chunk(tmp_path / "elsewhere.npz", npy([2]))  # sound, but reached only through a link
    (out / "chunks" / "00000002-00000003.npz").symlink_to(tmp_path / "elsewhere.npz")
    for name in ("00000001-00000001.npz", "00000001-99999999.npz", "00000002-00000002.npz", "00000003-00000003.npz",
                 "00000002-00000003.npz"):  # fmt: skip
        entries[name] = "0" * 64
    _interrupted_with(out, entries)
    state = run_state(out)
    assert (state.done, state.total) == (1, 4)


def test_a_chunk_with_a_forged_central_directory_is_not_parsed(tmp_path, registry):
    """zipfile parses a zip's whole central directory at once, some 600 bytes of memory for each
    90-byte entry: a chunk padded with 30000 empty entries beside a sound index array (a few MB
    here, gigabytes in a file of a few hundred MB) holds none of the count, read with no more
    memory than its size, and a resume counts it damaged the same way."""
    import hashlib
    import tracemalloc
    import zipfile

    import numpy as np

    from frictionlab.runs.chunks import ChunkDamage, chunk_indices, read_chunk

    out = tmp_path / "runs" / "run"
    _run(out, registry)
    entries = _stored_only(out, [0])
    forged = out / "chunks" / "00000001-00000001.npz"
    with zipfile.ZipFile(forged, "w") as archive:
        for key, value in (("index", [1]), ("failed_index", [])):
            with archive.open(f"{key}.npy", "w") as fh:
                np.lib.format.write_array(fh, np.asarray(value, np.int64))
        for i in range(30000):
            archive.writestr(f"{i}", b"")
    entries[forged.name] = hashlib.sha256(forged.read_bytes()).hexdigest()
    _interrupted_with(out, entries)
    tracemalloc.start()
    try:
        assert chunk_indices(out, forged.name) == set()
        assert tracemalloc.get_traced_memory()[1] < forged.stat().st_size
    finally:
        tracemalloc.stop()
    assert run_state(out).done == 1
    scene = build_scene(TINY, registry=registry)
    try:
        read_chunk(out, forged.name, entries[forged.name], scene)
    except ChunkDamage as exc:  # by its size first: more than a chunk of one realization can be
        assert "more than the limit of" in str(exc) or "unreadable" in str(exc), str(exc)
    else:
        raise AssertionError("a forged central directory was read as a chunk")


def test_a_run_that_ends_between_the_two_looks_is_its_ending_not_interrupted(tmp_path, registry, monkeypatch):
    """A follower read run.json ("running"), then found the lock free: the run had ended in
    between (it writes its ending, then lets the lock go), and was called interrupted (a
    `follow` right after a short resume exited 1 once in CI). The manifest is read again."""
    import frictionlab.runs.detached as detached

    folder = tmp_path / "run"
    _run(folder, registry)
    manifest = folder / "run.json"
    ended = manifest.read_text()
    manifest.write_text(json.dumps({**json.loads(ended), "status": "running"}))

    def ends_now(path) -> bool:  # the run writes its ending and lets the lock go as it is looked at
        manifest.write_text(ended)
        return False

    monkeypatch.setattr(detached, "lock_held", ends_now)
    assert run_state(folder).status == "completed"
    manifest.write_text(json.dumps({**json.loads(ended), "status": "running"}))
    monkeypatch.setattr(detached, "lock_held", lambda path: False)  # gone, still saying running
    assert run_state(folder).status == "interrupted"


def _edit_manifest(folder, edit):
    manifest = json.loads((folder / "run.json").read_text())
    edit(manifest)
    (folder / "run.json").write_text(json.dumps(manifest))


def test_a_run_whose_count_cannot_be_told_is_damaged_with_the_reason_never_a_question_mark(tmp_path, registry, capsys):
    """A run.json whose realizations was not a count was listed '4/?', one without its chunks'
    list (and no summary) '?/4': each is now damaged, saying why; a count its preset still
    tells is used."""
    runs = tmp_path / "runs"
    for name in ("no-total", "preset-total", "no-chunks"):
        _run(runs / name, registry)
    _edit_manifest(runs / "no-total", lambda m: m.update(realizations="x", preset={**m["preset"], "realizations": None}))
    _edit_manifest(runs / "preset-total", lambda m: m.update(realizations="x"))
    _edit_manifest(runs / "no-chunks", lambda m: m.pop("chunks"))
    (runs / "no-chunks" / "summary.json").unlink()
    states = {s.folder.name: s for s in list_run_states(runs)}
    assert (states["preset-total"].status, states["preset-total"].done, states["preset-total"].total) == ("completed", 4, 4)
    assert states["no-total"].status == states["no-chunks"].status == "damaged"
    assert states["no-total"].reason == ("run.json does not say how many realizations the run has "
                                         "(its realizations is 'x', its preset's None)")  # fmt: skip
    assert states["no-chunks"].reason == "run.json does not list its chunks: what finished cannot be counted"
    assert main(["runs", str(runs)]) == 0
    out = capsys.readouterr().out
    assert "?" not in out and f"{runs / 'no-total'} is damaged: run.json does not say" in out
    assert main(["follow", str(runs / "no-chunks")]) == 1
    assert capsys.readouterr().out == f"small: damaged, in {runs / 'no-chunks'}/: {states['no-chunks'].reason}\n"


def test_a_resume_writes_the_count_of_realizations_its_preset_asks(tmp_path, registry, capsys):
    """A manifest whose realizations was damaged ("4" as text) kept it through a resume: the run
    completed, and was listed with 4/? done for ever after (now listed by its preset's count, but
    its run.json stays mended)."""
    folder = tmp_path / "run"
    _run(folder, registry)
    manifest = json.loads((folder / "run.json").read_text())
    manifest.update(status="interrupted", realizations="4")
    (folder / "run.json").write_text(json.dumps(manifest))
    for name in ("summary.json", "curve.csv", "realizations.npz"):
        (folder / name).unlink()
    assert (run_state(folder).status, run_state(folder).total) == ("interrupted", 4)  # listed by its preset's count
    assert main(["resume", str(folder), "--quiet", "--no-plot", "--workers", "1"]) == 0
    assert json.loads((folder / "run.json").read_text())["realizations"] == 4
    assert (run_state(folder).status, run_state(folder).total) == ("completed", 4)


def test_a_summary_whose_values_its_schema_refuses_is_damaged_as_load_says_not_completed(tmp_path, registry, capsys):
    """A summary.json that parses but holds a value its schema refuses (a fit's a that is NaN,
    a count below 0) was listed as completed, and `follow` ended with 0, while
    frictionlab.load and predict --from refused the folder: all now say damaged, and why."""
    from frictionlab import load
    from frictionlab.errors import RunFolderError

    runs = tmp_path / "runs"
    edits = {"nan-a": ('"a": ', '"a": NaN, "was": '), "negative": ('"done": ', '"done": -1, "was": ')}
    for name, (old, new) in edits.items():
        _run(runs / name, registry)
        path = runs / name / "summary.json"
        path.write_text(path.read_text().replace(old, new, 1))
    states = {s.folder.name: s for s in list_run_states(runs)}
    for name, field in (("nan-a", "'fit.a'"), ("negative", "'realizations.done'")):
        with pytest.raises(RunFolderError) as refused:
            load(runs / name)
        assert states[name].status == "damaged" and field in states[name].reason, states[name]
        assert states[name].reason in str(refused.value)
        assert main(["follow", "--quiet", str(runs / name)]) == 1
        assert capsys.readouterr().out.startswith(f"{TINY['name']}: damaged, in {runs / name}/: summary.json")


def test_a_run_folder_that_cannot_be_looked_into_is_said_so_not_taken_for_no_run(tmp_path, registry):
    """A run folder the user may not search (mode 000, or 0666: no x): load said 'no summary.json',
    follow 'holds no run', runs left it out, and resume ended with 'error: Permission denied:
    .../sweep.json' (exit code 1). Each now names the folder and the permission, as a run
    folder that cannot be read (exit code 5; listed as damaged). Run as a process without the
    privilege to read past permissions, which root has."""
    import subprocess
    import sys

    runs = tmp_path / "runs"
    _run(runs / "locked", registry)
    held = sorted(p.relative_to(runs) for p in runs.rglob("*"))
    drop = ["setpriv", "--bounding-set=-dac_override,-dac_read_search"] if os.geteuid() == 0 else []
    said = f"{runs / 'locked'} cannot be read (permission denied): its files cannot be looked at"
    for mode in (0o000, 0o666):
        (runs / "locked").chmod(mode)
        try:
            for args, code in ((["resume", "--quiet"], 5), (["follow", "--quiet"], 5), (["runs"], 0)):
                folder = runs if args == ["runs"] else runs / "locked"
                done = subprocess.run([*drop, sys.executable, "-m", "frictionlab", *args, str(folder)],
                                      capture_output=True, text=True, timeout=120)  # fmt: skip
                assert done.returncode == code, done.stderr
                shown = done.stdout if args == ["runs"] else done.stderr
                assert (f"{runs / 'locked'} is damaged: " + said.split(" ", 1)[1] if args == ["runs"] else said) in shown
            load = f"import frictionlab\ntry:\n frictionlab.load({str(runs / 'locked')!r})\nexcept Exception as e: print(e)"
            done = subprocess.run([*drop, sys.executable, "-c", load], capture_output=True, text=True, timeout=120)
            assert done.stdout.strip() == said, done.stdout + done.stderr
        finally:
            (runs / "locked").chmod(0o755)
    assert sorted(p.relative_to(runs) for p in runs.rglob("*")) == held


def test_a_run_folder_inside_one_that_cannot_be_searched_is_said_so_by_every_command(tmp_path, registry):
    """A run folder whose parent the user may not search: follow, runs and predict --from said
    'error: Permission denied: q/run' with exit code 1 (follow's "the run ended other than
    completed"), where plot and resume named the folder and the permission, exit code 5."""
    import subprocess
    import sys

    _run(tmp_path / "q" / "run", registry)
    drop = ["setpriv", "--bounding-set=-dac_override,-dac_read_search"] if os.geteuid() == 0 else []
    predict = ["predict", "--area", "1e-4", "--modulus", "1e9", "--rms-height", "1e-6", "--force", "1e-5", "--from"]
    (tmp_path / "q").chmod(0o000)
    try:
        for args, folder in ((["follow", "--quiet"], "q/run"), (["runs"], "q"), (predict, "q/run"),
                             (["plot", "--out", str(tmp_path / "x.png")], "q/run")):  # fmt: skip
            done = subprocess.run([*drop, sys.executable, "-m", "frictionlab", *args, str(tmp_path / folder)],
                                  capture_output=True, text=True, timeout=120)  # fmt: skip
            assert done.returncode == 5, (args, done.stderr)
            assert done.stderr == f"error: {tmp_path / folder} cannot be read (permission denied): its files cannot be looked at\n"
    finally:
        (tmp_path / "q").chmod(0o755)


def test_follow_of_a_link_the_user_named_follows_the_folder_as_resume_does(tmp_path, registry, capsys):
    """`follow LINK` of a link to a run folder was refused ('not a run folder (not a folder, or a
    link to one)') while resume, predict --from and load take the folder named, link or not."""
    _run(tmp_path / "run", registry)
    (tmp_path / "link").symlink_to(tmp_path / "run")
    capsys.readouterr()
    assert main(["follow", "--quiet", str(tmp_path / "link")]) == 0
    assert capsys.readouterr().out == f"{TINY['name']}: completed, 4/4 realizations, in {tmp_path / 'run'}/\n"
    (tmp_path / "file-link").symlink_to(tmp_path / "run" / "summary.json")  # a link to a file is still no run folder
    assert main(["follow", "--quiet", str(tmp_path / "file-link")]) == 5
    assert "is not a run folder" in capsys.readouterr().err


def test_runs_of_a_folder_that_does_not_exist_is_a_usage_error(tmp_path, capsys):
    """`frictionlab runs /missing/dir` exited 5, the code of a run folder that cannot be used: a
    folder named on the command line that does not exist is a bad argument (2), as exact3d's --runs."""
    (tmp_path / "file").write_text("")
    for name, what in (("missing", "does not exist"), ("file", "is not a folder")):
        assert main(["runs", str(tmp_path / name)]) == 2
        assert capsys.readouterr().err == f"error: DIR: {tmp_path / name} {what}: give the folder that holds run folders\n"


@pytest.mark.parametrize("command", ["follow", "resume"])
@pytest.mark.parametrize("inside", ["summary.json", "chunks"])
def test_a_file_or_folder_inside_a_run_folder_names_the_folder_to_give(tmp_path, registry, capsys, command, inside):
    """`resume run/summary.json` (`follow run/chunks`) was 'is not a folder: there is no run to
    resume there' ('holds no run (no run.json)'), without the folder the user meant."""
    _run(tmp_path / "run", registry)
    capsys.readouterr()
    before = sorted(p.name for p in (tmp_path / "run").iterdir())
    assert main([command, "--quiet", str(tmp_path / "run" / inside)]) == 5
    assert capsys.readouterr().err == (f"error: {tmp_path / 'run' / inside} is inside the run folder {tmp_path / 'run'}, not "
                                       f"one itself: give that folder (frictionlab {command} {tmp_path / 'run'})\n")  # fmt: skip
    assert sorted(p.name for p in (tmp_path / "run").iterdir()) == before


@pytest.mark.parametrize("command", ["follow", "resume"])
def test_a_sweep_folder_whose_sweep_json_is_gone_is_said_so_not_a_missing_preset_yaml(tmp_path, capsys, command):
    """`resume SWEEP` with sweep.json deleted said 'holds no run to resume (no preset.yaml)' (`follow`:
    'no run.json'), files no sweep has: it names the missing sweep.json and how to reach the points."""
    sweep = tmp_path / "sweep"
    (sweep / "points" / "01-seed-1").mkdir(parents=True)
    (sweep / "sweep.csv").write_text("point,label\n1,01-seed-1\n")
    before = sorted(p.name for p in sweep.rglob("*"))
    assert main([command, "--quiet", str(sweep)]) == 5
    err = capsys.readouterr().err
    assert err.startswith(f"error: {sweep} is a sweep's folder (it holds sweep.csv and points/) but its sweep.json")
    assert f"frictionlab {command} POINT_FOLDER" in err and "Traceback" not in err
    assert sorted(p.name for p in sweep.rglob("*")) == before  # nothing written or deleted


def test_a_damaged_folders_huge_name_is_listed_cut_on_one_short_row(tmp_path, registry, capsys):
    runs = tmp_path / "runs"
    _run(runs / "long", registry)
    state_file = runs / "long" / "run.json"
    manifest = json.loads(state_file.read_text())
    manifest["preset"]["name"] = "n" * 300_000
    state_file.write_text(json.dumps(manifest))
    (state,) = list_run_states(runs)
    assert state.name == "n" * 100 + "..."
    assert main(["runs", str(runs)]) == 0
    row = next(line for line in capsys.readouterr().out.splitlines() if "long" in line)
    assert len(row) < 100 + len(str(runs / "long")) + 40, len(row)

"""Fault injection: a pool worker killed while it sends its result, SIGTERM or SIGHUP in
the middle of a run, and chunk files damaged in every way we could think of.
Each time the run ends (or resumes) to exactly the numbers of an
uninterrupted run, bit for bit, and never counts a realization twice."""

from __future__ import annotations

import hashlib
import io
import json
import math
import shutil
import signal
import subprocess
import sys
import threading
import time
import zipfile
from pathlib import Path

import numpy as np
import pytest
import yaml

from frictionlab.cli import main
from frictionlab.compute import engine
from frictionlab.errors import ExitCode
from frictionlab.runs import runner
from frictionlab.options import RunOptions
from frictionlab.preset import build_scene
from frictionlab.runs.runner import run_to_folder

from .conftest import ROOT, SMALL_PRESET, merge
from .test_resume import KILL_PRESET, NO_PLOT, CancelAfter, kill_preset_whole, same_files  # noqa: F401 (a fixture)

# ------------------------------------------------------------------ a worker killed mid-send

MID_SEND_SCRIPT = """
import json, os, sys
import numpy as np
from frictionlab import engine
from frictionlab.preset import build_scene
from frictionlab.plugin.registry import Registry
from frictionlab.options import RunOptions
from tests.conftest import SMALL_PRESET, merge
from tests.faults import MidSendKiller, with_spectrum

scene = build_scene(merge(SMALL_PRESET, {"realizations": 24}), registry=Registry(discover=False))
killer = with_spectrum(scene, MidSendKiller, flag=sys.argv[1], parent=os.getpid())
outcome = engine.run(killer, RunOptions(workers=2, executor="processes"))
np.save(sys.argv[2], outcome.per_realization["xi"])
print(json.dumps({"status": outcome.status, "done": outcome.done, "a": outcome.fit.a, "b": outcome.fit.b}))
"""


@pytest.mark.long
def test_a_worker_killed_while_sending_its_result_is_retried_and_the_run_finishes_bitwise(registry, tmp_path):
    flag, xi_file = tmp_path / "died", tmp_path / "xi.npy"
    try:  # in a subprocess with a deadline: a pool that hangs here fails the test instead of the suite
        done = subprocess.run(
            [sys.executable, "-c", MID_SEND_SCRIPT, str(flag), str(xi_file)],
            cwd=ROOT, capture_output=True, text=True, timeout=90,
        )  # fmt: skip
    except subprocess.TimeoutExpired:
        pytest.fail("the run hung after a worker died while sending its result")
    assert done.returncode == 0, done.stderr
    sent, size = map(int, flag.read_text().split())
    assert 0 < sent < size, "the worker did not die in the middle of its message"
    summary = json.loads(done.stdout)
    assert summary["status"] == "completed" and summary["done"] == 24

    serial = engine.run(build_scene(merge(SMALL_PRESET, {"realizations": 24}), registry=registry), RunOptions(workers=1))
    np.testing.assert_array_equal(np.load(xi_file), serial.per_realization["xi"])
    assert (summary["a"], summary["b"]) == (serial.fit.a, serial.fit.b)


# ------------------------------------------------------------------ SIGTERM


def _listed_chunks(run_dir: Path) -> int:
    try:
        return len(json.loads((run_dir / "run.json").read_text())["chunks"])
    except (OSError, ValueError, KeyError):  # not written yet, or being replaced
        return 0


def _signalled_mid_run(tmp_path, signum, preexec_fn=None) -> tuple[subprocess.Popen, str, str, Path]:
    """``frictionlab run`` of KILL_PRESET sent ``signum`` once two chunks are written."""
    preset = tmp_path / "long.yaml"
    preset.write_text(yaml.safe_dump(KILL_PRESET))
    run_dir = tmp_path / "run"
    command = [sys.executable, "-m", "frictionlab", "run", str(preset), "--out", str(run_dir), "--workers", "2"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, preexec_fn=preexec_fn)
    deadline = time.monotonic() + 60
    while _listed_chunks(run_dir) < 2:
        assert process.poll() is None, process.communicate()
        assert time.monotonic() < deadline, "no chunk written in 60 s"
        time.sleep(0.01)
    process.send_signal(signum)
    out, err = process.communicate(timeout=120)
    return process, out, err, run_dir


@pytest.mark.long
@pytest.mark.parametrize("signum, code", [(signal.SIGTERM, 143), (signal.SIGHUP, 129)])  # SIGHUP: the terminal closed
def test_sigterm_or_a_hangup_mid_run_ends_interrupted_and_resumes_bitwise(registry, tmp_path, signum, code, kill_preset_whole):
    process, out, err, run_dir = _signalled_mid_run(tmp_path, signum)
    assert process.returncode == code, err
    assert "status interrupted" in out and "Traceback" not in err
    assert f"what finished is kept in {run_dir}/: `frictionlab resume {run_dir}`" in err
    state = json.loads((run_dir / "run.json").read_text())
    assert state["status"] == "interrupted"
    kept = len(state["chunks"])
    assert 2 <= kept and not (run_dir / "run.lock").exists()

    resumed = subprocess.run(
        [sys.executable, "-m", "frictionlab", "resume", str(run_dir), "--workers", "2", "--json"],
        capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    assert resumed.returncode == 0, resumed.stderr
    assert 0 < json.loads(resumed.stdout)["resumed_realizations"] < KILL_PRESET["realizations"]
    same_files(run_dir, kill_preset_whole)


@pytest.mark.long
def test_a_hangup_ignored_as_nohup_ignores_it_leaves_the_run_going(tmp_path):
    process, out, err, run_dir = _signalled_mid_run(tmp_path, signal.SIGHUP, lambda: signal.signal(signal.SIGHUP, signal.SIG_IGN))
    assert process.returncode == 0, err
    assert json.loads((run_dir / "run.json").read_text())["status"] == "completed"


# ------------------------------------------------------------------ damaged chunks

DAMAGE_PRESET = merge(SMALL_PRESET, {"realizations": 40, **NO_PLOT})


@pytest.fixture(scope="module")
def partial_and_whole(registry, tmp_path_factory):
    """A run cancelled after 30 of 40 realizations (several chunk files), and the uninterrupted run."""
    scene = build_scene(DAMAGE_PRESET, registry=registry)
    root = tmp_path_factory.mktemp("damage")
    cancel = threading.Event()
    with pytest.MonkeyPatch.context() as patch:
        patch.setattr(runner, "UNSAVED_WORK_SECONDS", 0.0)  # each chunk written as it finishes
        first, _ = run_to_folder(scene, root / "partial", RunOptions(workers=1), listeners=[CancelAfter(30, cancel)], cancel=cancel)
    assert first.status == "cancelled" and len(json.loads((root / "partial" / "run.json").read_text())["chunks"]) >= 3
    run_to_folder(scene, root / "whole", RunOptions(workers=1))
    return scene, root / "partial", root / "whole"


def _manifest(folder: Path) -> dict:
    return json.loads((folder / "run.json").read_text())


def _rewrite(folder: Path, name: str, change, update_checksum: bool) -> None:
    """Rewrite chunk ``name`` with ``change(arrays)`` applied; list its new
    checksum in the manifest when ``update_checksum`` (as a careful hand would)."""
    path = folder / "chunks" / name
    with np.load(path) as data:
        arrays = {key: data[key].copy() for key in data.files}
    change(arrays)
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    path.write_bytes(buffer.getvalue())
    if update_checksum:
        manifest = _manifest(folder)
        manifest["chunks"][name] = hashlib.sha256(buffer.getvalue()).hexdigest()
        (folder / "run.json").write_text(json.dumps(manifest))


def _second(folder: Path) -> str:
    return list(_manifest(folder)["chunks"])[1]  # realizations 1..10: the first chunk is realization 0 alone


def truncated(folder):
    path = folder / "chunks" / _second(folder)
    path.write_bytes(path.read_bytes()[: path.stat().st_size // 2])


def grown(folder):  # past what a chunk of 10 realizations can hold: refused by its size, never read (sparse: no disk)
    with (folder / "chunks" / _second(folder)).open("r+b") as fh:
        fh.truncate(GROWN_BYTES)


GROWN_BYTES = 64 * 1024**2


def emptied(folder):
    (folder / "chunks" / _second(folder)).write_bytes(b"")


def deleted(folder):
    (folder / "chunks" / _second(folder)).unlink()


def edited_value(folder):
    _rewrite(folder, _second(folder), lambda a: a["xi"].__setitem__((0, 3), a["xi"][0, 3] * 1.001), False)


def nan_row(folder):
    _rewrite(folder, _second(folder), lambda a: a["xi"].__setitem__(2, np.nan), False)


def missing_array(folder):
    _rewrite(folder, _second(folder), lambda a: a.pop("xi"), True)


def index_out_of_range(folder):
    _rewrite(folder, _second(folder), lambda a: a["index"].__setitem__(0, 3000), True)


def negative_index(folder):
    _rewrite(folder, _second(folder), lambda a: a["index"].__setitem__(0, -1), True)


def repeated_index(folder):
    _rewrite(folder, _second(folder), lambda a: a["index"].__setitem__(1, a["index"][0]), True)


def forged_header(folder):  # xi's header claims 7 TiB over 64 bytes: numpy tried to allocate them ('unreadable')
    path = folder / "chunks" / _second(folder)
    with np.load(path) as data:
        arrays = {key: data[key] for key in data.files if key != "xi"}
    header = io.BytesIO()
    np.lib.format.write_array_header_1_0(header, {"descr": "<f8", "fortran_order": False, "shape": (10**6, 10**6)})
    buffer = io.BytesIO()
    np.savez(buffer, **arrays)
    with zipfile.ZipFile(buffer, "a") as archive:
        archive.writestr("xi.npy", header.getvalue() + bytes(64))
    path.write_bytes(buffer.getvalue())
    manifest = _manifest(folder)
    manifest["chunks"][path.name] = hashlib.sha256(buffer.getvalue()).hexdigest()
    (folder / "run.json").write_text(json.dumps(manifest))


def misshapen_rows(folder):
    _rewrite(folder, _second(folder), lambda a: a.__setitem__("xi", a["xi"][:, :-1]), True)


def text_xi(folder):
    _rewrite(folder, _second(folder), lambda a: a.__setitem__("xi", a["xi"].astype(str)), True)


def negative_count(folder):
    _rewrite(folder, _second(folder), lambda a: a["contact_count"].__setitem__((0, 0), -1), True)


def count_above_points(folder):
    _rewrite(folder, _second(folder), lambda a: a["contact_count"].__setitem__((0, 0), a["points"][0] + 1), True)


def huge_xi(folder):  # finite and >= 0: the fit overflowed, a printed in 300 digits
    _rewrite(folder, _second(folder), lambda a: a["xi"].__setitem__((0, 0), 1e308), True)


def infinite_peak(folder):  # the run's caveat said its highest point stood inf rms heights above the mean
    _rewrite(folder, _second(folder), lambda a: a["peak_rms"].__setitem__(0, math.inf), True)


def negative_seconds(folder):
    _rewrite(folder, _second(folder), lambda a: a["seconds"].__setitem__(0, -1e308), True)


def huge_seconds(folder):  # summed into the run's compute time: inf
    _rewrite(folder, _second(folder), lambda a: a["seconds"].__setitem__(0, 1e300), True)


def huge_indentation(folder):  # finite: its mean over the realizations overflowed (a warning, an empty cell)
    _rewrite(folder, _second(folder), lambda a: a["indentation"].__setitem__((0, 3), 1e308), True)


def nan_indentation(folder):  # no solver's: its curve must be finite
    _rewrite(folder, _second(folder), lambda a: a["indentation"].__setitem__((0, 3), math.nan), True)


def huge_rms_height(folder):
    _rewrite(folder, _second(folder), lambda a: a["measured_rms_height"].__setitem__(0, 1e308), True)


def huge_slope(folder):
    _rewrite(folder, _second(folder), lambda a: a["slope_rms_line"].__setitem__(0, 1e308), True)


def no_points(folder):
    _rewrite(folder, _second(folder), lambda a: a["points"].__setitem__(0, 0), True)


def nan_points(folder):  # int(NaN) failed the resume as an internal error
    _rewrite(folder, _second(folder), lambda a: a.update(points=np.where(a["points"] == a["points"][0], np.nan, 1.0)), True)


def fractional_points(folder):
    _rewrite(folder, _second(folder), lambda a: a.update(points=a["points"] + 0.5), True)


def nan_force_unit(folder):  # the run failed as 'the preset's magnitudes leave double precision'
    _rewrite(folder, _second(folder), lambda a: a["force_unit"].__setitem__(0, math.nan), True)


def other_force_unit(folder):  # a unit not the run's moved f, and so the fitted law
    _rewrite(folder, _second(folder), lambda a: a["force_unit"].__setitem__(0, a["force_unit"][0] * 2), True)


def zero_slope(folder):
    _rewrite(folder, _second(folder), lambda a: a["slope_rms_line"].__setitem__(0, 0.0), True)


def unlisted_overlapping_copy(folder):
    """A copy of one chunk under a name that overlaps another, not in the manifest."""
    chunks = folder / "chunks"
    shutil.copy(chunks / _second(folder), chunks / "00000005-00000014.npz")


def listed_twice(folder):
    """The same chunk listed under two names: its realizations must count once."""
    chunks, name = folder / "chunks", _second(folder)
    shutil.copy(chunks / name, chunks / name.replace(".npz", ".1.npz"))
    manifest = _manifest(folder)
    manifest["chunks"][name.replace(".npz", ".1.npz")] = manifest["chunks"][name]
    (folder / "run.json").write_text(json.dumps(manifest))


DAMAGE = {
    truncated: "'00000001-00000010.npz': checksum mismatch",
    emptied: "checksum mismatch",
    grown: f"'00000001-00000010.npz': file of {GROWN_BYTES:,} bytes, more than the limit of ",
    deleted: "'00000001-00000010.npz': missing",
    edited_value: "checksum mismatch",
    nan_row: "checksum mismatch",
    missing_array: "no array xi",
    index_out_of_range: "indices outside",
    negative_index: "indices outside",
    repeated_index: "or repeated",
    misshapen_rows: "array xi of shape",
    forged_header: "'00000001-00000010.npz': array 'xi': its header claims shape (1000000, 1000000) of float64",
    text_xi: "array xi of type <U32, not real numbers",
    negative_count: "contact_count below 0 or above the profile's points",
    count_above_points: "contact_count below 0 or above the profile's points",
    huge_xi: "xi above what an rms over some of a profile's slopes can be",
    infinite_peak: "peak_rms inf, not from 0 to 1e+300 (or NaN)",
    negative_seconds: "seconds -1e+308, not from 0 to 1e+09 (or NaN)",
    huge_seconds: "seconds 1e+300, not from 0 to 1e+09 (or NaN)",
    huge_indentation: "'00000001-00000010.npz': indentation 1e+308, not from -1e+300 to 1e+300",
    nan_indentation: "indentation nan, not from -1e+300 to 1e+300",
    huge_rms_height: "measured_rms_height 1e+308, not from 0 to 1e+300 (or NaN)",
    huge_slope: "slope_rms_line 1e+308, not from 0 to 1e+300",
    no_points: "a profile's points not a whole number >= 1",
    nan_points: "a profile's points not a whole number >= 1",
    fractional_points: "a profile's points not a whole number >= 1",
    nan_force_unit: "a force unit k h X not > 0",
    other_force_unit: "force_unit 2048, not from 1023.99999898 to 1024.00000102",
    zero_slope: "a line's rms slope not a finite number > 0",
    unlisted_overlapping_copy: "1 file(s) in chunks/ are not in the manifest and are ignored",
    listed_twice: None,  # nothing is damaged: no warning
}


def test_a_forged_force_unit_of_realization_0_does_not_move_the_law(partial_and_whole, tmp_path, recwarn):
    """The ensemble forms f with realization 0's force unit: a chunk forged with another one (its
    checksum listed) changed a on resume, with no word; it is recomputed as any forged chunk is."""
    _, partial, whole = partial_and_whole
    folder = tmp_path / "run"
    shutil.copytree(partial, folder)
    first = list(_manifest(folder)["chunks"])[0]
    _rewrite(folder, first, lambda a: a["force_unit"].__setitem__(0, a["force_unit"][0] * 3), True)
    assert main(["resume", str(folder), "--workers", "1", "--quiet", "--no-plot"]) == ExitCode.OK
    err = "\n".join(str(w.message) for w in recwarn)
    assert f"'{first}': force_unit 3072, not from 1023.99999898 to 1024.00000102" in err, err
    assert "1 realization(s) they held are recomputed" in err
    same_files(folder, whole)


@pytest.mark.parametrize("damage", list(DAMAGE), ids=[f.__name__ for f in DAMAGE])
def test_resume_recomputes_damaged_chunks_and_ends_bitwise_whole(partial_and_whole, tmp_path, damage, recwarn):
    scene, partial, whole = partial_and_whole
    folder = tmp_path / "run"
    shutil.copytree(partial, folder)
    damage(folder)
    workers = 2 if damage is truncated else 1  # one case through a real process pool
    outcome, _ = run_to_folder(scene, folder, RunOptions(workers=workers, resume=True))
    messages = [str(w.message) for w in recwarn if "resume of" in str(w.message)]
    expected = DAMAGE[damage]
    if expected is None:
        assert messages == []
    else:
        assert len(messages) == 1 and expected in messages[0], messages
        if damage is not unlisted_overlapping_copy:
            assert "1 chunk file(s) failed verification" in messages[0]
            assert "10 realization(s) they held are recomputed" in messages[0]
    assert outcome.status == "completed" and outcome.done == 40 and len(outcome.failures) == 0
    same_files(folder, whole)

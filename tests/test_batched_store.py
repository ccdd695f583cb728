"""Bookkeeping sized to the run: finished realizations are written in batches of about
half a second of the run's time (its work shared among its workers), and a completed
run's last batch is written only inside its one merged chunk, never apart first."""

from __future__ import annotations

import dataclasses
import json
import math

import numpy as np

from frictionlab.compute import engine
from frictionlab.options import RunOptions
from frictionlab.runs.rundir import RunDirectory
from frictionlab.runs.runner import BatchedStore

from .test_resume import NO_PLOT


class Kept:
    """A store that only keeps what the engine hands it."""

    def __init__(self):
        self.results = []

    def save_chunk(self, results):
        self.results.extend(results)


def results_of(scene) -> list:
    kept = Kept()
    engine.run(scene, RunOptions(workers=1), store=kept)
    return sorted(kept.results, key=lambda r: r.index)


def two_batches(run_dir, scene, first, last, unsaved=0.0) -> BatchedStore:
    """A fresh run in ``run_dir`` whose store has written ``first`` and holds ``last`` pending."""
    run_dir.start(scene, resume=False)
    store = BatchedStore(run_dir, unsaved=unsaved)
    store.save_chunk(first)
    store.unsaved = math.inf
    store.save_chunk(last)
    return store


def test_a_batch_is_half_a_second_of_the_run_s_time_whatever_its_workers(make_scene, tmp_path, run_folder_writes):
    scene = make_scene({"realizations": 4, **NO_PLOT})
    results = [dataclasses.replace(r, seconds=0.3) for r in results_of(scene)]
    written = run_folder_writes
    for workers, first_write in ((1, 2), (2, 4)):  # 0.6 s of work is 0.6 s of one worker's time, 0.3 s of two's
        with RunDirectory(tmp_path / f"w{workers}") as run_dir:
            run_dir.start(scene, resume=False)
            store = BatchedStore(run_dir, unsaved=0.5, workers=workers)
            for done, result in enumerate(results, start=1):
                written.clear()
                store.save_chunk([result])
                assert any(name.endswith(".npz") for name in written) == (done % first_write == 0), (workers, done)


def test_a_completed_run_s_last_batch_is_written_only_in_its_merged_chunk(make_scene, tmp_path, run_folder_writes):
    scene = make_scene({"realizations": 6, **NO_PLOT})
    results = results_of(scene)
    written = run_folder_writes
    with RunDirectory(tmp_path / "run") as run_dir:
        store = two_batches(run_dir, scene, results[0:4], results[4:6])  # the last two pending at the end
        written.clear()
        store.flush(merge=True)
        run_dir.finish(scene, "completed")
    chunks = [name for name in written if name.endswith(".npz")]
    assert chunks == ["00000000-00000005.npz"]  # 00000004-00000005.npz is never written
    assert written.count("run.json") == 2  # the merged chunk listed, then the status
    assert sorted(p.name for p in (tmp_path / "run" / "chunks").iterdir()) == chunks
    manifest = json.loads((tmp_path / "run" / "run.json").read_text())
    assert list(manifest["chunks"]) == chunks and manifest["status"] == "completed" and "retired" not in manifest
    stored = RunDirectory(tmp_path / "run").completed_results(scene)
    assert [r.index for r in stored] == list(range(6))
    for mine, theirs in zip(stored, results):
        np.testing.assert_array_equal(mine.xi, theirs.xi)
        np.testing.assert_array_equal(mine.contact_count, theirs.contact_count)


def test_a_cancelled_run_s_last_batch_is_a_chunk_of_its_own(make_scene, tmp_path):
    scene = make_scene({"realizations": 4, **NO_PLOT})
    results = results_of(scene)
    with RunDirectory(tmp_path / "run") as run_dir:
        store = two_batches(run_dir, scene, results[0:2], results[2:3])
        store.flush(merge=False)
        run_dir.finish(scene, "cancelled")
    manifest = json.loads((tmp_path / "run" / "run.json").read_text())
    assert list(manifest["chunks"]) == ["00000000-00000001.npz", "00000002-00000002.npz"]


def test_a_run_killed_after_its_merge_resumes_from_the_merged_chunk_alone(make_scene, tmp_path):
    """Killed between the merge and the status (writing results.npz, drawing plot.png): the
    manifest lists the merged chunk and the old ones as retired, gone already; a resume
    reads the merged chunk, computes nothing and leaves one chunk and no retired names."""
    from frictionlab.runs.runner import run_to_folder

    scene = make_scene({"realizations": 4, **NO_PLOT})
    results = results_of(scene)
    with RunDirectory(tmp_path / "run") as run_dir:
        store = two_batches(run_dir, scene, results[0:2], results[2:4])
        store.flush(merge=True)  # no finish: killed here
    manifest = json.loads((tmp_path / "run" / "run.json").read_text())
    assert manifest["status"] == "running" and manifest["retired"] == ["00000000-00000001.npz"]
    outcome, _ = run_to_folder(scene, tmp_path / "run", RunOptions(workers=1, resume=True))
    assert outcome.status == "completed" and outcome.extra["resumed"] == 4
    manifest = json.loads((tmp_path / "run" / "run.json").read_text())
    assert list(manifest["chunks"]) == ["00000000-00000003.npz"] and "retired" not in manifest
    assert [p.name for p in (tmp_path / "run" / "chunks").iterdir()] == ["00000000-00000003.npz"]


def test_a_merge_that_does_not_fit_on_the_disk_loses_no_result(make_scene, tmp_path, monkeypatch):
    """The merged chunk of a completed run is larger than its last batch: where the disk has no
    room for it (ENOSPC), the last batch is written apart and the old chunks stay listed, none
    retired, so the error is raised with every result on disk and a resume restores them all."""
    import errno

    from frictionlab.io import files

    scene = make_scene({"realizations": 6, **NO_PLOT})
    results = results_of(scene)

    def full_for_the_merge(path, *args, **kwargs):
        if path.name == "00000000-00000005.npz":
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return files.atomic_write(path, *args, **kwargs)

    with RunDirectory(tmp_path / "run") as run_dir:
        store = two_batches(run_dir, scene, results[0:4], results[4:6])
        monkeypatch.setattr("frictionlab.runs.rundir.atomic_write", full_for_the_merge)
        try:
            store.flush(merge=True)
        except OSError as exc:
            assert exc.errno == errno.ENOSPC
        else:
            raise AssertionError("the merge's ENOSPC was not raised")
    monkeypatch.undo()
    manifest = json.loads((tmp_path / "run" / "run.json").read_text())
    assert list(manifest["chunks"]) == ["00000000-00000003.npz", "00000004-00000005.npz"] and "retired" not in manifest
    with RunDirectory(tmp_path / "run") as run_dir:
        assert [r.index for r in run_dir.start(scene, resume=True)] == list(range(6))

"""A sweep folder read back is untrusted: its sweep.json checked against its points' folders
before a resume runs or writes anything, and a finished row never erased by a point in error."""

import json

import pytest

from frictionlab.cli import main
from frictionlab.runs.sweepfiles import read_table

from .test_sweep import sweep_preset, write

RESUME = ["--workers", "1", "--quiet", "--no-plot"]


@pytest.fixture
def finished(tmp_path, capsys):
    """A completed sweep of two points in tmp_path/out (realizations 6, seed swept: 1, 2)."""
    out = tmp_path / "out"
    assert main(["run", str(write(tmp_path, sweep_preset({"seed": {"values": [1, 2]}}))), "--out", str(out), *RESUME]) == 0
    capsys.readouterr()
    return out


def _edit(out, change) -> None:
    record = json.loads((out / "sweep.json").read_text())
    change(record)
    (out / "sweep.json").write_text(json.dumps(record))


def _files(out) -> dict:
    return {p.relative_to(out): p.read_bytes() for p in sorted(out.rglob("*")) if p.is_file() and p.name != "run.lock"}


@pytest.mark.parametrize("detach", [False, True])
def test_a_sweep_whose_base_preset_was_edited_is_refused_before_anything_runs_or_is_written(finished, capsys, detach):
    """realizations 6 -> 9 in sweep.json: each point's resume was refused, exit 1, and sweep.json and
    sweep.csv rewritten with both finished rows as errors, their fits gone, advising to move them aside."""
    _edit(finished, lambda record: record["base_preset"].update(realizations=9))
    before = _files(finished)
    assert main(["resume", str(finished), *RESUME, *(["--detach"] if detach else [])]) == 5
    err = capsys.readouterr().err
    assert f"cannot resume {finished}: {finished / 'sweep.json'} (its base_preset and sweep) differs" in err
    assert "points 1, 2: realizations: 6 in the run directory, 9 given" in err
    assert "nothing was run or written" in err
    assert _files(finished) == before
    assert [row["status"] for row in read_table(finished / "sweep.csv")] == ["completed", "completed"]


def test_a_point_whose_own_folder_holds_another_run_keeps_its_finished_row_and_the_sweep_goes_on(finished, capsys):
    """Point 1's folder replaced by point 2's run (only it differs: not sweep.json's doing): its row was
    rewritten as an error, its fit gone; it stays completed, its error beside it, till it is recomputed."""
    import shutil

    rows = read_table(finished / "sweep.csv")
    first, second = (finished / "points" / row["label"] for row in rows)
    shutil.rmtree(first)
    shutil.copytree(second, first)
    assert main(["resume", str(finished), *RESUME]) == 1
    assert "seed: 2 in the run directory, 1 given" in capsys.readouterr().err
    assert read_table(finished / "sweep.csv") == rows
    shutil.move(first, finished.parent / "aside")  # what it advises: the point computed afresh
    assert main(["resume", str(finished), *RESUME]) == 0
    timeless = lambda rows: [{**row, "elapsed_s": None} for row in rows]  # noqa: E731
    assert timeless(read_table(finished / "sweep.csv")) == timeless(rows)  # the same seed: the same numbers


def test_a_finished_row_stays_completed_where_its_point_cannot_be_read_back(finished, capsys):
    """A point whose run.json is damaged (its fingerprint not its preset's) is refused by its own
    resume: the sweep said so, and wrote the point's finished row as an error, its fit gone."""
    rows = read_table(finished / "sweep.csv")
    manifest = finished / "points" / rows[0]["label"] / "run.json"
    state = json.loads(manifest.read_text())
    manifest.write_text(json.dumps({**state, "fingerprint": "0" * len(state["fingerprint"])}))
    assert main(["resume", str(finished), *RESUME]) == 1
    printed, err = capsys.readouterr()
    assert "1 of 2 points failed; first: point 1: cannot resume" in err and "fingerprint" in err
    assert "seed=1: a = " in printed and "; error: cannot resume" in printed  # its fit, and why it failed
    assert read_table(finished / "sweep.csv") == rows  # both rows as they were: completed, with their fits
    record = json.loads((finished / "sweep.json").read_text())
    assert record["status"] == "failed" and record["points"][0]["status"] == "completed"
    assert "fingerprint" in record["points"][0]["error"] and record["points"][0]["a"] == float(rows[0]["a"])


@pytest.mark.parametrize("change, field, said", [
    (lambda r: r["sweep"]["parameters"]["seed"].update(values=[1, 3]), "points.1.seed", "is 2, but point 2 of its sweep.parameters has 3"),
    (lambda r: r.update(points=[r["points"][0]] * 2), "points.1.point", "is 1, but point 2 of its sweep.parameters has 2"),
    (lambda r: r.update(points=r["points"][::-1]), "points.0.point", "is 2, but point 1 of its sweep.parameters has 1"),
    (lambda r: r["points"][1].update(folder="points/01-seed-1"), "points.1.folder",
     "is 'points/01-seed-1', but point 2 of its sweep.parameters has 'points/02-seed-2'"),
    (lambda r: r["points"][0].update(seed=True), "points.0.seed", "is True, but point 1 of its sweep.parameters has 1"),
])  # fmt: skip
def test_rows_that_are_not_the_plans_points_are_a_damaged_sweep_json_to_every_reader(finished, capsys, change, field, said):
    """sweep.json's rows were never held to its plan: values [1, 3] showed point 2's fit (seed 2) as seed 3 in
    follow, plot and runs (completed 2/2), and a resume computed 02-seed-3 beside 02-seed-2; a row repeated
    showed point 1's fit twice."""
    import frictionlab
    from frictionlab.errors import RunFolderError

    _edit(finished, change)
    before = _files(finished)
    damaged = f"{finished / 'sweep.json'} is damaged: field '{field}' {said}"
    for command in (["follow", str(finished)], ["plot", str(finished), "--out", str(finished.parent / "x.png")],
                    ["resume", str(finished), *RESUME]):  # fmt: skip
        assert main(command) == 5, command
        assert damaged in capsys.readouterr().err, command
    main(["runs", str(finished.parent)])  # a listing: the folder said damaged, not completed 2/2
    assert damaged.replace(f"{finished / 'sweep.json'}", "sweep.json") in capsys.readouterr().out
    with pytest.raises(RunFolderError, match="its rows are not those of its sweep"):
        frictionlab.load(finished)
    assert _files(finished) == before and not (finished.parent / "x.png").exists()  # nothing computed or rewritten

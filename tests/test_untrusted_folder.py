"""A run folder is untrusted input: load(), predict --from, resume, sweeps and the TUI's
list read only regular files inside it, never through a link, never a FIFO; every
damaged value ends in a frictionlab error naming the file, never a Python exception
and never a line of a file outside the folder; nothing is written through a link."""

from __future__ import annotations

import csv
import hashlib
import json
import os
import re
import shutil
import threading
from pathlib import Path

import pytest

import frictionlab
from frictionlab.cli import main
from frictionlab.errors import ExitCode, FrictionlabError, RunFolderError
from frictionlab.tui.folders import list_runs

from .conftest import SMALL_PRESET, merge
from .test_resume import NO_PLOT

SECRET = "SECRET-LINE-OF-AN-OUTSIDE-FILE"
QUICK = merge(SMALL_PRESET, {**NO_PLOT, "realizations": 4, "fit": {"bootstrap": 0}})
PREDICT = ["predict", "--area", "1e10", "--modulus", "1", "--rms-height", "1e4", "--force", "5"]


@pytest.fixture(scope="module")
def finished(tmp_path_factory) -> Path:
    folder = tmp_path_factory.mktemp("finished") / "run"
    frictionlab.run(QUICK, out=folder, workers=1, progress=False, plot=False)
    return folder


@pytest.fixture
def run_copy(finished, tmp_path) -> Path:
    copy = tmp_path / "run"
    shutil.copytree(finished, copy)
    outside = tmp_path / "elsewhere"
    outside.mkdir()
    for name in ("curve.csv", "summary.json", "secret.txt"):
        (outside / name).write_text(f"{SECRET}\n{SECRET},1,2\n")
    return copy


def with_timeout(call, seconds: float = 20.0):
    """``call()``'s exception (None if it returned): a read that blocks fails the test."""
    box = []

    def target():
        try:
            call()
            box.append(None)
        except BaseException as exc:  # noqa: BLE001 - the test inspects it
            box.append(exc)

    thread = threading.Thread(target=target, daemon=True)
    thread.start()
    thread.join(seconds)
    assert box, f"blocked for more than {seconds} s"
    return box[0]


def edit_summary(folder: Path, change) -> None:
    data = json.loads((folder / "summary.json").read_text())
    change(data)
    (folder / "summary.json").write_text(json.dumps(data))


def set_in(data: dict, dotted: str, value) -> None:
    *parents, last = dotted.split(".")
    for key in parents:
        data = data[key]
    data[last] = value


def link(path: Path, target: Path) -> None:
    path.unlink()
    path.symlink_to(target)


def link_to_a_copy(path: Path) -> None:  # even a link to a file inside the folder is refused
    shutil.copy(path, path.with_name("copy"))
    link(path, path.with_name("copy"))


def edit_cell(folder: Path, column: str, value: str) -> None:
    """Set ``column`` (its short name) of curve.csv's first row to ``value``."""
    lines = (folder / "curve.csv").read_text().splitlines()
    index = [name.split(" [")[0] for name in next(csv.reader([lines[0]]))].index(column)
    cells = lines[1].split(",")  # numbers only: no quoted cells in a data row
    cells[index] = value
    lines[1] = ",".join(cells)
    (folder / "curve.csv").write_text("\n".join(lines) + "\n")


def fifo(path: Path) -> None:
    path.unlink()
    os.mkfifo(path)


# ------------------------------------------------------------------ each kind of hostile folder

HOSTILE = {
    # reads that would leave the folder
    "curve entry ../": lambda f: edit_summary(f, lambda d: set_in(d, "files.curve", "../elsewhere/curve.csv")),
    "curve entry absolute": lambda f: edit_summary(f, lambda d: set_in(d, "files.curve", str(f.parent / "elsewhere/curve.csv"))),
    "curve entry a/../../": lambda f: edit_summary(f, lambda d: set_in(d, "files.curve", "x/../../elsewhere/curve.csv")),
    "curve entry not a str": lambda f: edit_summary(f, lambda d: set_in(d, "files.curve", 5)),
    "curve.csv a link out": lambda f: link(f / "curve.csv", f.parent / "elsewhere" / "curve.csv"),
    "curve.csv a link in": lambda f: link_to_a_copy(f / "curve.csv"),
    "summary.json a link out": lambda f: link(f / "summary.json", f.parent / "elsewhere" / "summary.json"),
    "summary.json a dangling link": lambda f: link(f / "summary.json", f.parent / "nothing"),
    "summary.json a FIFO": lambda f: fifo(f / "summary.json"),
    "curve.csv a FIFO": lambda f: fifo(f / "curve.csv"),
    "summary.json a folder": lambda f: (f / "summary.json").unlink() or (f / "summary.json").mkdir(),
    # JSON of the wrong shape
    "summary a list": lambda f: (f / "summary.json").write_text("[1, 2]"),
    "summary not JSON": lambda f: (f / "summary.json").write_bytes(b"\xff\xfe{"),
    "summary nested deep": lambda f: (f / "summary.json").write_text("[" * 50_000 + "]" * 50_000),
    "no realizations": lambda f: edit_summary(f, lambda d: d.pop("realizations")),
    "no preset name": lambda f: edit_summary(f, lambda d: d["preset"].pop("name")),
    "preset a list": lambda f: edit_summary(f, lambda d: set_in(d, "preset", [1])),
    "fit.a a string": lambda f: edit_summary(f, lambda d: set_in(d, "fit.a", "0.5")),
    "fit.b NaN": lambda f: (f / "summary.json").write_text((f / "summary.json").read_text().replace('"b": ', '"b": NaN, "_b": ', 1)),
    "fit.r2 Infinity": lambda f: edit_summary(f, lambda d: set_in(d, "fit.r2", float("inf"))),
    "fit.b_se negative": lambda f: edit_summary(f, lambda d: set_in(d, "fit.b_se", -0.01)),  # a std.err, an rms: never
    "fit.residual_rms negative": lambda f: edit_summary(f, lambda d: set_in(d, "fit.residual_rms", -1)),  # below 0
    "fit a number": lambda f: edit_summary(f, lambda d: set_in(d, "fit", 3)),
    # values of the right type that no run writes (each was read, plotted and predicted from)
    "fit.a_ci reversed": lambda f: edit_summary(f, lambda d: set_in(d, "fit.a_ci", [2.0, 0.5])),
    "fit.a past 1e100": lambda f: edit_summary(f, lambda d: set_in(d, "fit.a", 1e308)),  # plot: 'overflow in multiply'
    "fit.points past the steps": lambda f: edit_summary(f, lambda d: set_in(d, "fit.points", 10**15)),
    "workers a string": lambda f: edit_summary(f, lambda d: set_in(d, "workers", "many")),
    "failures not failures": lambda f: edit_summary(f, lambda d: set_in(d, "realizations.failures", [{"x": 1}] * 3)),
    "preset.realizations negative": lambda f: edit_summary(f, lambda d: set_in(d, "preset.realizations", -3)),
    "curve entry run.json": lambda f: edit_summary(f, lambda d: set_in(d, "files.curve", "run.json")),  # blamed run.json
    "done a float": lambda f: edit_summary(f, lambda d: set_in(d, "realizations.done", 2.5)),
    "done negative": lambda f: edit_summary(f, lambda d: set_in(d, "realizations.done", -1)),
    "done true": lambda f: edit_summary(f, lambda d: set_in(d, "realizations.done", True)),
    "status unknown": lambda f: edit_summary(f, lambda d: set_in(d, "status", SECRET)),
    "caveats a string": lambda f: edit_summary(f, lambda d: set_in(d, "caveats", SECRET)),
    "elapsed a string": lambda f: edit_summary(f, lambda d: set_in(d, "elapsed_seconds", "1")),
    "elapsed past 30 years": lambda f: edit_summary(f, lambda d: set_in(d, "elapsed_seconds", 1e300)),  # 300 digits shown
    "future schema": lambda f: edit_summary(f, lambda d: set_in(d, "schema_version", 99)),
    "input rms NaN": lambda f: edit_summary(f, lambda d: set_in(d, "input", {"file": "scan.x3p", "rms_height": float("nan")})),
    "input a list": lambda f: edit_summary(f, lambda d: set_in(d, "input", [1, 2])),
    # values of the right kind that contradict each other: no silent wrong or empty fit
    "fit null though done": lambda f: edit_summary(f, lambda d: set_in(d, "fit", None)),
    "fit though none done": lambda f: edit_summary(f, lambda d: set_in(d, "realizations.done", 0)),
    "done above requested": lambda f: edit_summary(f, lambda d: set_in(d, "realizations.done", 99)),
    "failed above requested": lambda f: edit_summary(f, lambda d: set_in(d, "realizations.failed", 99)),
    "completed short of requested": lambda f: edit_summary(f, lambda d: set_in(d, "realizations.requested", 2**70)),
    "curve short a row": lambda f: (f / "curve.csv").write_text("".join((f / "curve.csv").read_text().splitlines(True)[:-1])),
    # CSV that is not frictionlab's
    "curve binary": lambda f: (f / "curve.csv").write_bytes(b"\x89PNG\r\n\x1a\n\x00\x00" + os.urandom(64)),
    "curve NUL": lambda f: (f / "curve.csv").write_bytes((f / "curve.csv").read_bytes() + b"\x00\n"),
    "curve non-numeric cell": lambda f: (f / "curve.csv").write_text((f / "curve.csv").read_text().replace("\n", f"\n{SECRET},", 1).replace(",", "", 1)),
    "curve ragged row": lambda f: (f / "curve.csv").write_text((f / "curve.csv").read_text() + "1,2\n"),
    "curve inf cell": lambda f: (f / "curve.csv").write_text((f / "curve.csv").read_text() + "inf,1,1,1,1,1,1\n"),
    "curve empty": lambda f: (f / "curve.csv").write_text(""),
    # counts that cannot be counts
    "lines_used negative": lambda f: edit_cell(f, "lines_used", "-3"),
    "lines_used fractional": lambda f: edit_cell(f, "lines_used", "2.5"),
    "lines_used empty": lambda f: edit_cell(f, "lines_used", ""),
    "lines_used above done": lambda f: edit_cell(f, "lines_used", "5"),
    "contact_count negative": lambda f: edit_cell(f, "contact_count", "-1"),
    "contact_fraction above 1": lambda f: edit_cell(f, "contact_fraction", "1.5"),
    # values no run writes: a force or xi below 0, an f of 0 beside a law in ln f (plot() failed on it)
    "F negative": lambda f: edit_cell(f, "F", "-0.5"),
    "xi negative": lambda f: edit_cell(f, "xi", "-0.5"),
    "xi_sem negative": lambda f: edit_cell(f, "xi_sem", "-1"),
    "f zero beside a fit": lambda f: edit_cell(f, "f", "0"),
    "f empty beside a fit": lambda f: edit_cell(f, "f", ""),
    "curve missing": lambda f: (f / "curve.csv").unlink(),
    "curve huge": lambda f: (f / "curve.csv").write_bytes(b"1" * (17 * 1024 * 1024)),
}


@pytest.mark.parametrize("case", sorted(HOSTILE))
def test_load_refuses_each_kind_of_hostile_folder_naming_the_file(run_copy, case):
    HOSTILE[case](run_copy)
    raised = with_timeout(lambda: frictionlab.load(run_copy))
    assert isinstance(raised, RunFolderError), f"{case}: {type(raised).__name__}: {raised}"
    message = str(raised)
    assert "summary.json" in message or "curve.csv" in message, message
    assert SECRET not in message, message


@pytest.mark.parametrize("case", ["summary.json a link out", "summary.json a FIFO", "fit.a a string", "fit.b NaN",
                                  "future schema", "summary a list", "status unknown"])  # fmt: skip
def test_predict_from_a_hostile_folder_exits_5(run_copy, case, capsys):
    HOSTILE[case](run_copy)
    codes = []
    assert with_timeout(lambda: codes.append(main([*PREDICT, "--from", str(run_copy)]))) is None
    err = capsys.readouterr().err
    assert codes == [ExitCode.RUN_FOLDER] and "summary.json" in err and SECRET not in err, err


def test_a_curve_with_a_column_of_another_s_is_refused_by_its_header_not_its_first_cell(run_copy):
    """An added column of text was told as 'line 2, column 10: not a finite number'."""
    lines = (run_copy / "curve.csv").read_text().splitlines()
    (run_copy / "curve.csv").write_text("\n".join([lines[0] + ",note", *(line + ",ok" for line in lines[1:])]) + "\n")
    with pytest.raises(RunFolderError, match=r"curve.csv is damaged \(its header does not name the \d+ columns frictionlab "
                                             r"writes: F, f, xi"):  # fmt: skip
        frictionlab.load(run_copy)


def test_a_future_schema_is_refused_naming_its_version(run_copy):
    edit_summary(run_copy, lambda d: set_in(d, "schema_version", 99))
    with pytest.raises(RunFolderError, match=r"newer frictionlab \(schema_version 99; this one reads up to 2\)"):
        frictionlab.load(run_copy)


def test_a_schema_below_the_first_is_refused_as_damaged(run_copy):
    """schema_version 0 or -3 was read as the oldest; no frictionlab wrote it."""
    edit_summary(run_copy, lambda d: set_in(d, "schema_version", 0))
    with pytest.raises(RunFolderError, match=r"summary.json is damaged \(schema_version 0: the first is 1\)"):
        frictionlab.load(run_copy)


def test_a_link_out_of_the_folder_is_named_as_a_link(run_copy):
    link(run_copy / "curve.csv", run_copy.parent / "elsewhere" / "curve.csv")
    with pytest.raises(RunFolderError, match=r"curve.csv: curve.csv is a symbolic link, which is never followed"):
        frictionlab.load(run_copy)


def test_an_intact_copy_loads_the_same_numbers(run_copy, finished):
    assert frictionlab.load(run_copy).fit == frictionlab.load(finished).fit


# ------------------------------------------------------------------ sweeps and the TUI's list


def test_a_sweep_json_without_a_row_for_every_point_is_damaged(tmp_path):
    """Its points cut short (or one row too many) loaded as a smaller sweep without a word."""
    folder = tmp_path / "sweep"
    preset = merge(QUICK, {"sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.6, 0.8]}}}})
    frictionlab.run(preset, out=folder, workers=1, progress=False, plot=False)
    data = json.loads((folder / "sweep.json").read_text())
    for points, said in ((data["points"][:1], "1 rows for a sweep of 2 points"),
                         (data["points"] * 2, "4 rows for a sweep of 2 points")):  # fmt: skip
        (folder / "sweep.json").write_text(json.dumps({**data, "points": points}))
        with pytest.raises(RunFolderError, match=f"sweep.json is damaged \\(points: {said}\\)"):
            frictionlab.load(folder)
    bad_section = {**data["sweep"], "mode": "diagonal"}
    (folder / "sweep.json").write_text(json.dumps({**data, "sweep": bad_section}))
    with pytest.raises(RunFolderError, match=r"sweep.json is damaged \(sweep: not a sweep section"):
        frictionlab.load(folder)
    (folder / "sweep.json").write_text(json.dumps(data))
    assert len(frictionlab.load(folder).points) == 2


def test_a_sweep_json_whose_range_ends_past_a_floats_range_is_damaged(tmp_path):
    """JSON holds integers of any length: a range end of 310 digits reached pydantic's finite
    check (math.isfinite), an OverflowError, exit 70, wherever the folder was read."""
    folder = tmp_path / "sweep"
    preset = merge(QUICK, {"sweep": {"parameters": {"seed": {"start": 1, "stop": 2, "num": 2}}}})
    frictionlab.run(preset, out=folder, workers=1, progress=False, plot=False)
    data = json.loads((folder / "sweep.json").read_text())
    data["sweep"]["parameters"]["seed"]["stop"] = 10**309
    (folder / "sweep.json").write_text(json.dumps(data))
    with pytest.raises(RunFolderError, match=r"sweep.json is damaged \(sweep: not a sweep section a preset can hold\)"):
        frictionlab.load(folder)


def test_a_sweep_json_row_without_its_swept_value_is_damaged(tmp_path):
    """A row without the value its point gave the swept parameter, or a mapping there, was shown
    (and compared with its point's run) as that value."""
    folder = tmp_path / "sweep"
    preset = merge(QUICK, {"sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.6, 0.8]}}}})
    frictionlab.run(preset, out=folder, workers=1, progress=False, plot=False)
    data = json.loads((folder / "sweep.json").read_text())
    for value, said in ((None, "missing"), ({"x": 1}, "a dict, not text, a number, true, false or null")):
        row = {k: v for k, v in data["points"][1].items() if k != "spectrum.params.hurst"}
        if value is not None:
            row["spectrum.params.hurst"] = value
        (folder / "sweep.json").write_text(json.dumps({**data, "points": [data["points"][0], row]}))
        with pytest.raises(RunFolderError, match=r"sweep.json is damaged: field 'points.1.spectrum.params.hurst' "
                                                 rf"\(the swept value of point 2\) is {re.escape(said)}$"):
            frictionlab.load(folder)


def test_a_sweep_json_row_edited_is_refused_or_shown_never_an_internal_error(tmp_path, capsys):
    """A row's elapsed_s, point number or swept value of NaN or infinity (json reads them) made
    follow --json fail as an internal error (exit 70), and a row without its contact_last follow
    itself: each refused naming the field (exit 5), the row without the count shown without it."""
    folder = tmp_path / "sweep"
    preset = merge(QUICK, {"sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.6, 0.8]}}}})
    frictionlab.run(preset, out=folder, workers=1, progress=False, plot=False)
    data = json.loads((folder / "sweep.json").read_text())
    for key, value in (("elapsed_s", float("inf")), ("elapsed_s", 1e300), ("point", float("nan")), ("spectrum.params.hurst", float("nan")),
                       ("set", [float("nan")])):  # fmt: skip
        (folder / "sweep.json").write_text(json.dumps({**data, "points": [{**data["points"][0], key: value}, data["points"][1]]}))
        code = main(["follow", str(folder), "--json"])
        out, err = capsys.readouterr()
        assert code == ExitCode.RUN_FOLDER, err
        assert "sweep.json is damaged: field 'points.0" in err and key in err and "internal error" not in err
    row = {k: v for k, v in data["points"][0].items() if k != "contact_last"}
    (folder / "sweep.json").write_text(json.dumps({**data, "points": [row, data["points"][1]]}))
    assert main(["follow", str(folder), "--quiet"]) == 0
    out = capsys.readouterr().out
    assert "hurst=0.6: a = " in out and "contacts" in out.splitlines()[-1] and "internal error" not in out


def test_resume_of_a_sweep_whose_sweep_json_is_a_folder_or_a_fifo_says_so(tmp_path, capsys):
    """resume of a sweep's folder whose sweep.json is not a regular file said 'holds no run to resume
    (no preset.yaml)', as if it were no sweep: the file is named, and what it is (exit 5)."""
    folder = tmp_path / "sweep"
    preset = merge(QUICK, {"sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.6, 0.8]}}}})
    frictionlab.run(preset, out=folder, workers=1, progress=False, plot=False)
    (folder / "sweep.json").unlink()
    for make, what in ((os.mkdir, "a folder"), (os.mkfifo, "a FIFO (named pipe)")):
        make(folder / "sweep.json")
        codes = []
        assert with_timeout(lambda: codes.append(main(["resume", str(folder), "--quiet"]))) is None
        assert codes == [ExitCode.RUN_FOLDER] and f"sweep.json is {what}, not a regular file" in capsys.readouterr().err
        (os.rmdir if what == "a folder" else os.unlink)(folder / "sweep.json")


def test_a_sweep_json_naming_a_folder_outside_is_refused(tmp_path):
    folder = tmp_path / "sweep"
    preset = merge(QUICK, {"sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.6, 0.8]}}}})
    frictionlab.run(preset, out=folder, workers=1, progress=False, plot=False)
    assert len(frictionlab.load(folder).points) == 2
    data = json.loads((folder / "sweep.json").read_text())
    data["points"][0]["folder"] = "../../elsewhere"
    (folder / "sweep.json").write_text(json.dumps(data))
    with pytest.raises(RunFolderError, match=r"sweep.json is damaged: field 'points.0.folder'"):
        frictionlab.load(folder)
    data["points"][0]["folder"] = "points/" + sorted(p.name for p in (folder / "points").iterdir())[0]
    (folder / "sweep.json").write_text(json.dumps(data))
    points = folder / "points"
    shutil.move(points, tmp_path / "moved")
    points.symlink_to(tmp_path / "moved")  # the point folders now lie outside, through a link
    with pytest.raises(RunFolderError, match=r"points is a symbolic link or not a folder"):
        frictionlab.load(folder).points
    data["schema_version"] = 7
    (folder / "sweep.json").write_text(json.dumps(data))
    with pytest.raises(RunFolderError, match=r"schema_version 7"):
        frictionlab.load(folder)



def test_a_sweep_json_status_no_sweep_writes_is_refused(tmp_path):
    """A sweep.json's status and its points' were any text: load() gave a SweepResult of status
    'done' (or of an escape sequence) and points of status 'ok', as summary.json's status, a
    choice of four, is not."""
    folder = tmp_path / "sweep"
    preset = merge(QUICK, {"sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.6, 0.8]}}}})
    frictionlab.run(preset, out=folder, workers=1, progress=False, plot=False)
    data = json.loads((folder / "sweep.json").read_text())
    for where, field, first in ((data, "status", "running"), (data["points"][1], "points.1.status", "completed")):
        saved, where["status"] = where["status"], "done"
        (folder / "sweep.json").write_text(json.dumps(data))
        with pytest.raises(RunFolderError, match=rf"sweep.json is damaged: field '{field}': input should be '{first}'"):
            frictionlab.load(folder)
        where["status"] = saved

def test_the_tui_list_names_fifos_and_links_damaged_without_blocking(run_copy, tmp_path):
    runs = run_copy.parent
    for name, damage in (("fifo", "summary.json a FIFO"), ("linked", "summary.json a link out")):
        shutil.copytree(run_copy, runs / name)
        HOSTILE[damage](runs / name)
    listed = []
    assert with_timeout(lambda: listed.extend(list_runs(runs))) is None
    entries = {entry.path.name: entry for entry in listed}
    assert entries["run"].status == "completed"
    for name in ("fifo", "linked"):  # listed, never read through, never shown as completed
        assert entries[name].status == "damaged" and "summary.json" in entries[name].reason


# ------------------------------------------------------------------ resume


def test_resume_never_reads_a_chunk_through_a_link(tmp_path):
    folder = tmp_path / "run"
    preset = tmp_path / "p.yaml"
    preset.write_text(json.dumps(merge(QUICK, {"realizations": 8})))
    assert main(["run", str(preset), "--out", str(folder), "--quiet"]) == ExitCode.OK
    expected = frictionlab.load(folder).fit
    (chunk,) = (folder / "chunks").iterdir()
    outside = tmp_path / "outside.npz"
    shutil.copy(chunk, outside)  # the very bytes: its checksum matches the manifest's
    chunk.unlink()
    chunk.symlink_to(outside)
    manifest = json.loads((folder / "run.json").read_text())
    manifest["status"] = "interrupted"
    (folder / "run.json").write_text(json.dumps(manifest))
    with pytest.warns(UserWarning, match=r"1 chunk file\(s\) failed verification \('\d{8}-\d{8}\.npz': file is a symbolic link"):
        assert main(["resume", str(folder), "--quiet"]) == ExitCode.OK
    assert frictionlab.load(folder).fit == expected  # recomputed, bitwise


def _move_out(folder: Path, name: str, user: Path) -> None:
    shutil.move(folder / name, user / name)
    (folder / name).symlink_to(user / name)


RESUME_REFUSALS = {  # damage -> what the message says
    "chunks a link": (lambda f, u: _move_out(f, "chunks", u), "chunks is not a folder"),
    "run.json a link": (lambda f, u: _move_out(f, "run.json", u), "run.json: manifest is a symbolic link"),
    "run.json a FIFO": (lambda f, u: fifo(f / "run.json"), "run.json: manifest is a FIFO"),
    "preset.yaml a link": (lambda f, u: link(f / "preset.yaml", u / "notes.txt"), "preset file is a symbolic link"),
    "preset.yaml a FIFO": (lambda f, u: fifo(f / "preset.yaml"), "preset file is a FIFO"),
    "run.lock a link": (lambda f, u: (f / "run.lock").symlink_to(u / "notes.txt"), "run.lock is not a regular file"),
    "run.lock a FIFO": (lambda f, u: os.mkfifo(f / "run.lock"), "run.lock is not a regular file"),
    # a hard link is no link to refuse when opened, and who holds the lock was written into the user's file
    "run.lock a hard link": (lambda f, u: hard_link(f / "run.lock", u / "notes.txt"), "run.lock is a hard link"),
    "future manifest": (lambda f, u: _edit_manifest(f, format=9), "format 9; this one reads up to 2"),
    "status NaN": (lambda f, u: (f / "run.json").write_text('{"status": NaN}'), "status is not a word, but a number"),
    "status the secret": (lambda f, u: _edit_manifest(f, status=[SECRET]), "status is not a word, but an array"),
    "status no run writes": (lambda f, u: _edit_manifest(f, status="done"),
                             "status is 'done', not one of running, completed, interrupted, cancelled, failed"),
    "chunks a list": (lambda f, u: _edit_manifest(f, chunks=[SECRET]), "chunks is not a mapping"),
}


def hard_link(name: Path, target: Path) -> None:
    """``name`` made another name of the user's file ``target``."""
    name.unlink(missing_ok=True)
    os.link(target, name)


@pytest.mark.parametrize("make", [hard_link, lambda name, target: name.symlink_to(target)], ids=["hard link", "link"])
def test_a_detached_run_is_refused_a_progress_file_that_is_a_users_file_which_stays_unchanged(run_copy, tmp_path, make):
    """A hard-linked progress.jsonl was emptied and written through by ``resume --detach``; a
    symbolic one made the run go on unseen, said to have ended at once."""
    from frictionlab.runs.detached import start_detached
    from frictionlab.runs.progresslog import ProgressLog

    user = tmp_path / "notes.txt"
    user.write_text(SECRET)
    make(run_copy / "progress.jsonl", user)
    with pytest.raises(RunFolderError, match=r"progress\.jsonl in .* is a (hard|symbolic) link.*, never written through"):
        start_detached({}, run_copy)
    log = ProgressLog(run_copy)  # a run begun in the folder all the same writes no progress, and empties nothing
    log._open(truncate=True)
    log.write({"event": "started"})
    log.close()
    assert user.read_text() == SECRET


def _edit_manifest(folder: Path, **changes) -> None:
    manifest = json.loads((folder / "run.json").read_text())
    (folder / "run.json").write_text(json.dumps({**manifest, **changes}))


@pytest.mark.parametrize("damage", sorted(RESUME_REFUSALS))
def test_resume_refuses_a_folder_whose_own_files_are_links_fifos_or_damaged(tmp_path, capsys, damage):
    folder = tmp_path / "run"
    preset = tmp_path / "p.yaml"
    preset.write_text(json.dumps(QUICK))
    assert main(["run", str(preset), "--out", str(folder), "--quiet"]) == ExitCode.OK
    user = tmp_path / "user"
    user.mkdir()
    (user / "notes.txt").write_text(SECRET)
    make, said = RESUME_REFUSALS[damage]
    make(folder, user)
    before = {p.name: p.read_bytes() for p in user.rglob("*") if p.is_file()}
    codes = []
    assert with_timeout(lambda: codes.append(main(["resume", str(folder), "--quiet"]))) is None
    err = capsys.readouterr().err
    assert codes == [ExitCode.RUN_FOLDER] and said in err, err
    assert SECRET not in err and "Traceback" not in err
    assert {p.name: p.read_bytes() for p in user.rglob("*") if p.is_file()} == before


def test_resume_recomputes_a_chunk_that_is_a_fifo_without_blocking(tmp_path):
    folder = tmp_path / "run"
    frictionlab.run(QUICK, out=folder, workers=1, progress=False, plot=False)
    expected = frictionlab.load(folder).fit
    (chunk,) = (folder / "chunks").iterdir()
    fifo(chunk)
    with pytest.warns(UserWarning, match=r"\.npz': file is a FIFO \(named pipe\), not a regular file"):
        assert with_timeout(lambda: frictionlab.run(QUICK, out=folder, resume=True, workers=1, progress=False,
                                                    plot=False)) is None  # fmt: skip
    assert frictionlab.load(folder).fit == expected


# ------------------------------------------------------------------ writing


def test_a_summary_that_is_a_link_to_a_user_file_is_replaced_not_written_through(tmp_path):
    folder = tmp_path / "run"
    frictionlab.run(QUICK, out=folder, workers=1, progress=False, plot=False)
    user = tmp_path / "thesis.tex"
    user.write_text(SECRET)
    for name in ("summary.json", "curve.csv", "preset.yaml"):
        (folder / name).unlink()
        (folder / name).symlink_to(user)
    with pytest.warns(UserWarning, match="holds a completed run of this preset: it runs again"):
        frictionlab.run(QUICK, out=folder, workers=1, progress=False, plot=False)  # the same preset: rerun in place
    assert user.read_text() == SECRET
    assert not any((folder / name).is_symlink() for name in ("summary.json", "curve.csv", "preset.yaml"))
    assert frictionlab.load(folder).status == "completed"


def test_an_output_file_that_is_a_link_needs_force_and_then_replaces_the_link(tmp_path, capsys):
    user = tmp_path / "user.json"
    user.write_text(SECRET)
    out = tmp_path / "schema.json"
    out.symlink_to(user)
    assert main(["schema", "--out", str(out)]) == ExitCode.OUTPUT_REFUSED
    assert "is a symbolic link" in capsys.readouterr().err
    assert main(["schema", "--out", str(out), "--force"]) == ExitCode.OK
    assert user.read_text() == SECRET and not out.is_symlink() and json.loads(out.read_text())
    assert main(["presets", "copy", "quickstart", str(tmp_path / "q.yaml")]) == ExitCode.OK
    (tmp_path / "q.yaml").unlink()
    (tmp_path / "q.yaml").symlink_to(user)
    assert main(["presets", "copy", "quickstart", str(tmp_path / "q.yaml"), "--force"]) == ExitCode.OK
    assert user.read_text() == SECRET and not (tmp_path / "q.yaml").is_symlink()


def test_no_python_exception_reaches_the_user_from_load(tmp_path):
    for argument in (None, 3, b"", "", "a\0b", tmp_path / "missing", [tmp_path]):
        raised = with_timeout(lambda argument=argument: frictionlab.load(argument))
        assert isinstance(raised, FrictionlabError), (argument, raised)


def test_the_tui_preset_list_shows_a_fifo_as_unreadable_without_blocking(tmp_path):
    from frictionlab.tui.folders import list_presets

    (tmp_path / "good.yaml").write_text("name: good\ndescription: a preset\n")
    os.mkfifo(tmp_path / "pipe.yaml")
    listed = []
    assert with_timeout(lambda: listed.extend(list_presets([("presets", tmp_path)]))) is None
    assert [(e.name, bool(e.error)) for e in listed] == [("good", False), ("pipe", True)]


@pytest.mark.parametrize("kind", ["run", "sweep"])
def test_resume_of_a_folder_whose_stored_preset_is_not_valid_is_a_run_folder_error(tmp_path, capsys, kind):
    """A value edited in the preset stored in a run folder (preset.yaml, or a sweep.json's base preset)
    ended a resume as a command-line error (exit code 2); it is the folder that cannot be resumed (5)."""
    folder = tmp_path / "run"
    data = QUICK if kind == "run" else {**QUICK, "sweep": {"parameters": {"seed": {"values": [1, 2]}}}}
    preset = tmp_path / "p.yaml"
    preset.write_text(json.dumps(data))
    assert main(["run", str(preset), "--out", str(folder), "--quiet", "--workers", "1"]) == ExitCode.OK
    if kind == "run":
        stored = folder / "preset.yaml"
        stored.write_text(stored.read_text().replace("realizations: 4", "realizations: -4"))
    else:
        stored = folder / "sweep.json"
        record = json.loads(stored.read_text())
        record["base_preset"]["realizations"] = -4
        stored.write_text(json.dumps(record))
    capsys.readouterr()
    assert main(["resume", str(folder), "--quiet", "--json"]) == ExitCode.RUN_FOLDER
    captured = capsys.readouterr()
    assert "realizations: must be >= 1, got -4" in captured.err
    assert f"{folder} cannot be resumed: the preset stored there is not valid here" in captured.err
    assert json.loads(captured.out)["field"] == "realizations"
    if kind == "sweep":  # following it plans its points from the same stored preset
        assert main(["follow", str(folder), "--quiet"]) == ExitCode.RUN_FOLDER
        assert f"{folder} cannot be followed: the preset stored there is not valid here" in capsys.readouterr().err


@pytest.mark.parametrize("name", ["summary.json", "curve.csv", "realizations.npz"])
def test_a_result_file_that_is_a_folder_refuses_the_run_before_any_work(tmp_path, capsys, name):
    """The run computed every realization, then failed to write over the folder (exit code 1, the status
    left 'running'); it is refused before anything runs, naming the folder: exit code 5 for a resume,
    4 for a run into the folder."""
    folder = tmp_path / "run"
    preset = tmp_path / "p.yaml"
    preset.write_text(json.dumps(QUICK))
    assert main(["run", str(preset), "--out", str(folder), "--quiet", "--workers", "1"]) == ExitCode.OK
    (folder / name).unlink()
    (folder / name).mkdir()
    (folder / name / "mine.txt").write_text(SECRET)
    manifest = (folder / "run.json").read_bytes()
    capsys.readouterr()
    assert main(["resume", str(folder), "--quiet", "--workers", "1"]) == ExitCode.RUN_FOLDER
    assert f"{folder / name} is a folder, not a file: the run writes its {name} there" in capsys.readouterr().err
    assert main(["run", str(preset), "--out", str(folder), "--quiet", "--workers", "1"]) == ExitCode.OUTPUT_REFUSED
    assert f"{folder / name} is a folder, not a file" in capsys.readouterr().err
    assert (folder / "run.json").read_bytes() == manifest  # nothing started: the status is still 'completed'
    assert (folder / name / "mine.txt").read_text() == SECRET


@pytest.mark.parametrize("detach", [False, True])
def test_resume_of_a_sweep_whose_sweep_json_disagrees_with_itself_is_a_run_folder_error(tmp_path, capsys, detach):
    """Its name edited: the resume was refused as 'another sweep' with exit code 4 and the advice to
    force it, which resume has no option for; the folder is what cannot be resumed (5)."""
    folder = tmp_path / "sweep"
    preset = tmp_path / "p.yaml"
    preset.write_text(json.dumps({**QUICK, "sweep": {"parameters": {"seed": {"values": [1, 2]}}}}))
    assert main(["run", str(preset), "--out", str(folder), "--quiet", "--workers", "1"]) == ExitCode.OK
    record = json.loads((folder / "sweep.json").read_text())
    (folder / "sweep.json").write_text(json.dumps({**record, "name": "another-name"}))
    capsys.readouterr()
    assert main(["resume", str(folder), "--quiet", *(["--detach"] if detach else [])]) == ExitCode.RUN_FOLDER
    err = capsys.readouterr().err
    assert f"{folder / 'sweep.json'} is damaged: its name, sweep and base preset are not those of one sweep" in err
    assert "--force" not in err


def test_predict_from_a_sweeps_folder_names_it_as_one_and_where_its_points_laws_are(tmp_path, capsys):
    """It said only 'no such summary.json', of a folder the user had just run; a sweep's folder holds a law
    per point, and the message says where they are."""
    folder = tmp_path / "sweep"
    preset = tmp_path / "p.yaml"
    preset.write_text(json.dumps({**QUICK, "sweep": {"parameters": {"seed": {"values": [1, 2]}}}}))
    assert main(["run", str(preset), "--out", str(folder), "--quiet", "--workers", "1"]) == ExitCode.OK
    capsys.readouterr()
    assert main([*PREDICT, "--from", str(folder)]) == ExitCode.RUN_FOLDER
    err = capsys.readouterr().err
    assert f"--from {folder} is a sweep's folder, which holds a law per point" in err
    assert f"frictionlab runs {folder / 'points'} lists them" in err
    assert main([*PREDICT, "--from", str(folder / "points" / "01-seed-1")]) == ExitCode.OK


def loop(path: Path) -> None:
    """A symbolic link that points at itself: any open of it fails with ELOOP."""
    path.unlink(missing_ok=True)
    path.symlink_to(path.name)


@pytest.mark.parametrize("name", ["run.json", "summary.json", "curve.csv"])
def test_resume_of_a_folder_holding_a_link_to_itself_is_said_never_an_internal_error(run_copy, name, capsys):
    """Path.resolve raised RuntimeError('Symlink loop') on such a link: exit 70, 'internal error'."""
    loop(run_copy / name)
    code = main(["resume", str(run_copy), "--quiet", "--workers", "1"])
    err = capsys.readouterr().err
    assert "internal error" not in err and "Traceback" not in err
    if name == "run.json":  # the manifest is read: a link is refused, naming it
        assert code == ExitCode.RUN_FOLDER and "symbolic link" in err
    else:  # a result file is written anew: the link is replaced by the file, never followed
        assert code == ExitCode.OK
        assert not (run_copy / name).is_symlink() and (run_copy / name).is_file()


def test_a_run_into_a_folder_holding_a_link_to_itself_is_refused_or_forced_never_an_internal_error(tmp_path, capsys):
    preset = tmp_path / "p.yaml"
    preset.write_text(json.dumps(QUICK))
    out = tmp_path / "out"
    out.mkdir()
    loop(out / "summary.json")
    assert main(["run", str(preset), "--out", str(out), "--quiet"]) == ExitCode.OUTPUT_REFUSED
    assert "summary.json" in capsys.readouterr().err
    assert main(["run", str(preset), "--out", str(out), "--quiet", "--force"]) == ExitCode.OK
    assert (out / "summary.json").is_file() and not (out / "summary.json").is_symlink()


def test_an_out_folder_that_is_a_link_to_itself_is_named(tmp_path, capsys):
    preset = tmp_path / "p.yaml"
    preset.write_text(json.dumps(QUICK))
    loop(tmp_path / "out")
    assert main(["run", str(preset), "--out", str(tmp_path / "out"), "--quiet"]) == ExitCode.OUTPUT_REFUSED
    err = capsys.readouterr().err
    assert "out is a symbolic link to nothing" in err and "internal error" not in err


@pytest.mark.parametrize("command", [["schema"], ["plot", "RUN"]])
def test_an_output_file_that_is_a_link_to_itself_is_refused_as_a_link_and_forced_replaced(run_copy, tmp_path, command, capsys):
    """It was 'error: Too many levels of symbolic links' with exit 1 (a run failed)."""
    target = tmp_path / "looped.png"
    loop(target)
    args = [str(run_copy) if word == "RUN" else word for word in command]
    assert main([*args, "--out", str(target)]) == ExitCode.OUTPUT_REFUSED
    assert "is a symbolic link: give another file, or --force" in capsys.readouterr().err
    assert main([*args, "--out", str(target), "--force"]) == ExitCode.OK
    assert target.is_file() and not target.is_symlink()


@pytest.mark.parametrize("written, said", [
    ("null", "(null, not a JSON object)"),  # was 'a JSON NoneType'
    ('{"preset": "quick"}', "field 'preset': input should be a JSON object"),  # was 'instance of _PresetName'
    ('{"seed": ' + "7" * 5000 + "}", "a number of more digits than are read"),  # was 'not valid JSON'
], ids=["null", "preset a string", "a 5000-digit number"])  # fmt: skip
def test_a_damaged_summary_is_said_in_the_file_s_terms_never_python_s(run_copy, written, said):
    (run_copy / "summary.json").write_text(written)
    raised = with_timeout(lambda: frictionlab.load(run_copy))
    assert isinstance(raised, RunFolderError) and said in str(raised), str(raised)
    assert "NoneType" not in str(raised) and "_PresetName" not in str(raised)


def deflated_zeros(path: Path, arrays: dict, rows: int, columns: int) -> None:
    """An .npz whose array 'xi' is ``rows`` x ``columns`` zeros, deflated (megabytes in a few kB),
    written a block at a time (the test never holds it unpacked); ``arrays`` beside it as they are."""
    import zipfile

    import numpy as np

    with zipfile.ZipFile(path, "w", zipfile.ZIP_DEFLATED) as archive:
        for name, array in arrays.items():
            if name != "xi":
                with archive.open(f"{name}.npy", "w") as member:
                    np.lib.format.write_array(member, array)
        with archive.open("xi.npy", "w", force_zip64=True) as member:
            np.lib.format.write_array_header_1_0(member, {"descr": "<f8", "fortran_order": False, "shape": (rows, columns)})
            block = bytes(8 * columns * 256)
            for _ in range(rows // 256):
                member.write(block)


def test_an_archive_that_unpacks_past_what_its_run_writes_is_refused_before_it_is_unpacked(run_copy, capsys):
    """A realizations.npz (or a chunk) of deflated zeros: 1 MB on disk unpacked to 1 GB in memory
    before its shape was checked. The sizes its directory declares are checked first."""
    import numpy as np

    from frictionlab.preset import build_scene
    from frictionlab.runs.chunks import ChunkDamage, read_chunk

    steps = QUICK["loading"]["steps"]
    with np.load(run_copy / "realizations.npz") as data:
        kept = {name: data[name] for name in data.files}
    deflated_zeros(run_copy / "realizations.npz", kept, rows=4096, columns=steps)  # 4 were done
    assert (run_copy / "realizations.npz").stat().st_size < 200_000
    assert main([*PREDICT, "--from", str(run_copy)]) == ExitCode.RUN_FOLDER
    assert "array 'xi' unpacks to" in capsys.readouterr().err
    scene = build_scene(QUICK)
    bomb = run_copy / "chunks" / "00000000-00000003.npz"
    bomb.parent.mkdir(exist_ok=True)
    deflated_zeros(bomb, {}, rows=65536, columns=steps)  # 8 MB: past its errors' room too
    digest = hashlib.sha256(bomb.read_bytes()).hexdigest()
    with pytest.raises(ChunkDamage, match="array 'xi' unpacks to"):
        read_chunk(run_copy, bomb.name, digest, scene)


def test_the_curve_of_the_most_load_steps_a_preset_may_ask_is_read_back(tmp_path):
    """A preset of 200,000 steps (the limit was 10^6) ran to completion, and its curve.csv of 26 MB
    was refused by every reader (16 MiB at most): the TUI said the run had failed. The longest rows
    any solver writes, at the most steps a preset may ask, fit what the readers take."""
    from frictionlab.preset import build_scene
    from frictionlab.preset.schema import MAX_STEPS
    from frictionlab.runs.results import curve_headers
    from frictionlab.runs.runfolder import MAX_CSV_BYTES

    widest = build_scene(merge(SMALL_PRESET, {"spectrum": {"name": "power-law-2d", "params": {"points": 16}},
                                              "solver": {"name": "bem-halfspace"}}))  # fmt: skip
    header = curve_headers(widest)
    assert len(header) == 14  # every column a solver adds
    longest = ",".join([repr(-1.2345678901234567e-123)] * len(header)) + "\r\n"  # as csv writes a row
    assert len((",".join(header) + "\r\n").encode()) + MAX_STEPS * len(longest) <= MAX_CSV_BYTES
    with pytest.raises(frictionlab.errors.PresetError, match=f"loading.steps: .*{MAX_STEPS}"):
        frictionlab.validate(merge(SMALL_PRESET, {"loading": {"steps": MAX_STEPS + 1}}))

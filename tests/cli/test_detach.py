"""``run --detach``, ``runs`` and ``follow``: one JSON object each, the exit codes of errors.ExitCode."""

import json
import os
import re
import signal
import subprocess
import sys
import time

import pytest

from frictionlab.runs.detached import run_state

from ..conftest import SMALL_PRESET, merge
from .conftest import InTerminal, write_preset


@pytest.mark.long
def test_run_detach_then_runs_and_follow_see_it_to_the_end(tmp_path, cli):
    preset = write_preset(tmp_path, merge(SMALL_PRESET, {"realizations": 40}))
    out = tmp_path / "runs" / "one"
    started = cli("run", preset, "--detach", "--json", "--workers", "1", "--out", out)
    assert started.returncode == 0, started.stderr
    told = json.loads(started.stdout)  # one JSON object
    assert told["folder"] == str(out) and told["status"] == "running" and told["pid"] > 0
    listed = cli("runs", tmp_path / "runs", "--json")
    runs = json.loads(listed.stdout)["runs"]
    assert [r["folder"] for r in runs] == [str(out)] and runs[0]["status"] in ("running", "completed")
    followed = cli("follow", out, "--json")
    assert followed.returncode == 0, followed.stderr
    end = json.loads(followed.stdout)
    assert (end["status"], end["done"], end["total"], end["pid"]) == ("completed", 40, 40, None)
    assert json.loads((out / "summary.json").read_text())["realizations"]["done"] == 40
    table = cli("runs", tmp_path / "runs")
    assert "completed" in table.stdout and "40/40" in table.stdout


@pytest.mark.long
def test_follow_prints_progress_until_a_cancelled_run_ends_and_exits_1(tmp_path, cli):
    preset = write_preset(tmp_path, merge(SMALL_PRESET, {"realizations": 100_000}))
    out = tmp_path / "long"
    told = json.loads(cli("run", preset, "--detach", "--json", "--workers", "1", "--no-plot", "--out", out).stdout)
    follow = subprocess.Popen([sys.executable, "-m", "frictionlab", "follow", str(out)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)  # fmt: skip
    heading = follow.stderr.readline()  # the progress it follows (then a line a tenth, in a pipe)
    assert "100000 realizations of" in heading
    deadline = time.monotonic() + 60
    while (run_state(out).done or 0) < 3 and time.monotonic() < deadline:
        time.sleep(0.05)
    os.kill(told["pid"], signal.SIGTERM)
    stdout, _ = follow.communicate(timeout=60)
    assert follow.returncode == 1
    assert "interrupted" in stdout and f"frictionlab resume {out} continues it" in stdout


def follow_a_terminal_run(preset, out, begun) -> tuple[str, str, str]:
    """``frictionlab run PRESET --out OUT`` as typed in a terminal (no progress file), followed once
    ``begun()``: follow's first two lines on stderr, then its stdout once the run is ended (SIGTERM)."""
    run = subprocess.Popen([sys.executable, "-m", "frictionlab", "run", str(preset), "--quiet", "--no-plot", "--workers",
                            "1", "--out", str(out)], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)  # fmt: skip
    try:
        deadline = time.monotonic() + 60
        while not begun():
            assert run.poll() is None and time.monotonic() < deadline, "the run did not start"
            time.sleep(0.05)
        follow = subprocess.Popen([sys.executable, "-m", "frictionlab", "follow", str(out)], stdout=subprocess.PIPE,
                                  stderr=subprocess.PIPE, text=True)  # fmt: skip
        why, count = follow.stderr.readline(), follow.stderr.readline()
        run.terminate()
        stdout, _ = follow.communicate(timeout=60)
    finally:
        run.kill()
        run.wait()
    return why, count, stdout


@pytest.mark.long
def test_follow_counts_a_terminal_runs_chunks_which_writes_no_progress_file(tmp_path, cli):
    """Found by a newcomer: ``frictionlab run`` in a terminal writes no progress.jsonl, and follow
    showed nothing at all until the run ended. It says why, and the count its chunks hold."""
    preset = write_preset(tmp_path, merge(SMALL_PRESET, {"realizations": 100_000}))
    out = tmp_path / "long"

    def begun() -> bool:
        return (out / "run.json").exists() and (run_state(out).done or 0) > 0

    why, count, stdout = follow_a_terminal_run(preset, out, begun)
    assert why.startswith(f"the run in {out} writes no progress.jsonl") and "its count comes from its chunks" in why
    done, total = (int(n) for n in count.removeprefix("small: ").split(" ")[0].split("/"))
    assert count.endswith(" realizations stored\n") and 0 < done < total == 100_000
    assert "interrupted" in stdout
    assert not (out / "progress.jsonl").exists()


@pytest.mark.long
def test_follow_counts_a_terminal_sweeps_points_and_the_chunks_of_the_one_going_on(tmp_path, cli):
    sweep = {"sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.7]}}}, "realizations": 100_000}
    preset = write_preset(tmp_path, merge(SMALL_PRESET, sweep), "sweep.yaml")
    out = tmp_path / "sweep"
    why, count, _ = follow_a_terminal_run(preset, out, lambda: list(out.glob("points/01-*/chunks/*")))
    assert "writes no progress.jsonl" in why
    assert re.fullmatch(r"small: 0/2 points done; point 1: [1-9]\d*/100000 realizations stored\n", count), count


def test_detach_refuses_what_the_run_would_refuse_before_starting_it(tmp_path, cli):
    preset = write_preset(tmp_path, SMALL_PRESET)
    mine = tmp_path / "mine"
    mine.mkdir()
    (mine / "notes.txt").write_text("keep")
    refused = cli("run", preset, "--detach", "--out", mine)
    assert refused.returncode == 4 and "not empty" in refused.stderr
    assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"]  # nothing written into the user's folder
    sweep = write_preset(tmp_path, merge(SMALL_PRESET, {"sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.7]}}}}), "sweep.yaml")
    refused = cli("run", sweep, "--detach", "--out", mine)  # a sweep too
    assert refused.returncode == 4 and "not empty" in refused.stderr and "Traceback" not in refused.stderr
    assert sorted(p.name for p in mine.iterdir()) == ["notes.txt"]


@pytest.mark.parametrize("out", ["afile", "afile/sub", "/dev/null"])
@pytest.mark.parametrize("sweep", [False, True])
def test_detach_refuses_a_file_for_the_folder_as_the_run_does(tmp_path, cli, out, sweep):
    """A file given as --out was refused with 'Not a directory: afile/progress.jsonl', exit 1 (a
    run that failed), naming a file the user never gave; the run itself refuses it as output, exit 4."""
    data = merge(SMALL_PRESET, {"sweep": {"parameters": {"seed": {"values": [1, 2]}}}} if sweep else {})
    preset = write_preset(tmp_path, data)
    (tmp_path / "afile").write_text("keep")
    given = out if out.startswith("/") else tmp_path / out
    detached, attached = (cli("run", preset, *extra, "--out", given) for extra in (["--detach"], ["--no-plot"]))
    assert detached.returncode == attached.returncode == 4, detached.stderr
    assert detached.stderr.splitlines()[-1] == attached.stderr.splitlines()[-1], (detached.stderr, attached.stderr)
    assert "progress.jsonl" not in detached.stderr and (tmp_path / "afile").read_text() == "keep"


@pytest.mark.long
def test_a_detached_sweep_is_one_entry_of_runs_and_follow_shows_each_point_and_its_fit(tmp_path, cli):
    data = merge(SMALL_PRESET, {"realizations": 20, "sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.7]}}}})
    preset = write_preset(tmp_path, data, "sweep.yaml")
    out = tmp_path / "runs" / "sw"
    started = cli("run", preset, "--detach", "--json", "--workers", "1", "--no-plot", "--out", out)
    assert started.returncode == 0, started.stderr
    told = json.loads(started.stdout)
    assert (told["folder"], told["kind"], told["status"]) == (str(out), "sweep", "running") and told["pid"] > 0
    followed = cli("follow", out)
    assert followed.returncode == 0, followed.stderr
    rows = json.loads((out / "sweep.json").read_text())["points"]
    assert followed.stdout.startswith(f"small: completed, 2/2 points, in {out}/")
    for number, row in enumerate(rows, start=1):  # each point and its fit, as sweep.json has it
        assert f"{number}  hurst={row['spectrum.params.hurst']}: a = {row['a']:.4f}" in followed.stdout
    end = json.loads(cli("follow", out, "--json").stdout)
    assert (end["kind"], end["status"], end["done"], end["total"], end["pid"]) == ("sweep", "completed", 2, 2, None)
    assert [p["a"] for p in end["points"]] == [row["a"] for row in rows]
    listed = json.loads(cli("runs", tmp_path / "runs", "--json").stdout)["runs"]
    assert [(r["folder"], r["kind"], r["status"], r["done"], r["total"]) for r in listed] == [(str(out), "sweep", "completed", 2, 2)]
    table = cli("runs", tmp_path / "runs").stdout
    assert "completed" in table and "2/2 points" in table


def test_runs_and_follow_on_a_sweep_folder_whose_sweep_json_is_a_link_say_so_without_a_traceback(tmp_path, cli):
    (tmp_path / "runs" / "bad").mkdir(parents=True)
    (tmp_path / "elsewhere.json").write_text("{}")
    (tmp_path / "runs" / "bad" / "sweep.json").symlink_to(tmp_path / "elsewhere.json")
    listed = cli("runs", tmp_path / "runs")
    assert listed.returncode == 0 and "damaged" in listed.stdout  # listed, never hidden
    assert f"{tmp_path / 'runs' / 'bad'} is damaged: sweep.json is a symbolic link" in listed.stdout
    followed = cli("follow", tmp_path / "runs" / "bad")
    assert followed.returncode == 5 and "sweep.json" in followed.stderr and "Traceback" not in followed.stderr


def test_runs_and_follow_name_a_folder_that_is_not_a_run(tmp_path, cli):
    missing = cli("runs", tmp_path / "nowhere")
    assert missing.returncode == 2 and "DIR:" in missing.stderr and "does not exist" in missing.stderr  # a bad argument
    (tmp_path / "plain").mkdir()
    followed = cli("follow", tmp_path / "plain")
    assert followed.returncode == 5 and "holds no run" in followed.stderr and "Traceback" not in followed.stderr


def test_follow_of_a_run_that_ended_failed_says_why_and_advises_no_resume_that_cannot_mend_it(tmp_path, cli):
    """A run whose every realization finished but whose law could not be fitted (its loads all
    past full contact): follow, after it ended, said only 'failed, 8/8 realizations ...;
    frictionlab resume DIR continues it', its error null under --json, though the run's
    summary.json says why and no resume changes it."""
    preset = write_preset(tmp_path, merge(SMALL_PRESET, {"loading": {"start": 1e90, "stop": 1e99}, "output": {"plot": False}}))
    out = tmp_path / "runs" / "flat"
    assert cli("run", preset, "--workers", "1", "--quiet", "--out", out).returncode == 1
    followed = cli("follow", out)
    assert followed.returncode == 1, followed.stderr
    assert "small: failed, 8/8 realizations" in followed.stdout and "resume" not in followed.stdout
    assert "error: no law: the whole profile is in contact at every load" in followed.stderr
    told = json.loads(cli("follow", out, "--json").stdout)
    assert told["status"] == "failed" and told["error"].startswith("no law: the whole profile is in contact")


@pytest.mark.long
def test_follow_shows_a_running_sweeps_points_until_it_is_cancelled_and_exits_1(tmp_path, cli):
    data = merge(SMALL_PRESET, {"sweep": {"parameters": {"realizations": {"values": [4, 100_000]}}}})
    preset = write_preset(tmp_path, data, "sweep.yaml")
    out = tmp_path / "sw"
    told = json.loads(cli("run", preset, "--detach", "--json", "--workers", "1", "--no-plot", "--out", out).stdout)
    follow = subprocess.Popen([sys.executable, "-m", "frictionlab", "follow", str(out)], stdout=subprocess.PIPE,
                              stderr=subprocess.PIPE, text=True)  # fmt: skip
    heard = [follow.stderr.readline()]
    while "100000 realizations of" not in heard[-1]:  # up to the second point's run, followed live
        heard.append(follow.stderr.readline())
        assert heard[-1], "follow ended before the second point's run"
    os.kill(told["pid"], signal.SIGTERM)
    stdout, _ = follow.communicate(timeout=60)
    row = json.loads((out / "sweep.json").read_text())["points"][0]
    assert heard[0].startswith("small: sweep of 2 points") and heard[1].startswith("point 1/2: realizations=4")
    assert any(f"1  realizations=4: a = {row['a']:.4f}" in line for line in heard)  # how the first point ended
    assert follow.returncode == 1
    assert stdout.startswith(f"small: interrupted, 1/2 points, in {out}/; frictionlab resume {out} continues it")


@pytest.mark.long
@pytest.mark.parametrize("signum, code", [(signal.SIGINT, 130), (signal.SIGTERM, 143)], ids=["ctrl-c", "sigterm"])
def test_follow_in_a_terminal_ends_its_bar_on_its_own_line_when_stopped_with_ctrl_c(tmp_path, signum, code, cli):
    preset = write_preset(tmp_path, merge(SMALL_PRESET, {"realizations": 100_000}))
    out = tmp_path / "long"
    told = json.loads(cli("run", preset, "--detach", "--json", "--workers", "1", "--no-plot", "--out", out).stdout)
    try:
        follow = InTerminal("follow", out)
        deadline = time.monotonic() + 60
        while b"/100000" not in follow.raw and time.monotonic() < deadline:  # its bar shows
            assert follow.process.poll() is None, f"follow ended by itself: {follow.raw[-600:]!r}"
            time.sleep(0.05)
        assert b"/100000" in follow.raw, f"no bar in 60 s: {follow.raw[-600:]!r}"
        time.sleep(0.5)
        follow.process.send_signal(signum)
        ended = follow.wait()
    finally:
        os.kill(told["pid"], signal.SIGTERM)
    lines, column = follow.screen()
    shown = [line for line in lines if line]
    assert ended == code
    assert shown[-1] == f"stopped following; the run goes on (pid {told['pid']})" and column == 0  # the prompt's line is free
    assert "/100000" in shown[-2]  # the bar, as it was left, above


@pytest.mark.long
def test_follow_in_a_terminal_prints_a_sweeps_fits_on_lines_of_their_own_and_no_bar_after_its_summary(tmp_path, cli):
    # some 10 s of sweep (a follow attaches within 1 to 3 s); a point's fit shows wherever it attaches
    data = merge(SMALL_PRESET, {"realizations": 6_000, "sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.7]}}}})
    preset = write_preset(tmp_path, data, "sweep.yaml")
    out = tmp_path / "sw"
    assert cli("run", preset, "--detach", "--workers", "1", "--no-plot", "--out", out).returncode == 0
    follow = InTerminal("follow", out)
    assert follow.wait() == 0
    lines, column = follow.screen()
    shown = [line for line in lines if line]
    summary = shown.index(next(line for line in shown if line.startswith("small: completed, 2/2 points")))
    assert shown[summary + 1].startswith("    1  hurst=0.5: a = ") and shown[summary + 2].startswith("    2  hurst=0.7: a = ")
    assert len(shown) == summary + 3 and column == 0  # nothing drawn after the summary
    fits = [line for line in shown[:summary] if ": a = " in line]
    assert fits and all(line.startswith(("    1  hurst=0.5: a = ", "    2  hurst=0.7: a = ")) for line in fits)
    assert all("6000/6000" in shown[shown.index(line) - 1] for line in fits)  # each below its point's finished bar


@pytest.mark.long
def test_run_detach_quiet_prints_only_the_folder_on_one_line(tmp_path, cli):
    preset = write_preset(tmp_path, SMALL_PRESET)
    out = tmp_path / "runs" / "quiet"
    started = cli("run", preset, "--detach", "--quiet", "--workers", "1", "--no-plot", "--out", out)
    assert started.returncode == 0, started.stderr
    assert started.stdout == f"{out}\n" and started.stderr == ""  # what a script captures: $(frictionlab run ...)
    assert cli("follow", out, "--quiet").returncode == 0
    resumed = cli("resume", out, "--detach", "--quiet")  # resume --detach too
    assert resumed.returncode == 0 and resumed.stdout == f"{out}\n" and resumed.stderr == ""
    assert cli("follow", out, "--quiet").returncode == 0


@pytest.mark.parametrize(("marker", "hint"), [("run.json", "a run folder itself"), ("sweep.json", "a sweep's folder")])
def test_runs_given_a_run_or_sweep_folder_says_what_it_is(marker, hint, tmp_path, capsys):
    from frictionlab.cli import main

    folder = tmp_path / "runs" / "one"
    folder.mkdir(parents=True)
    (folder / marker).write_text("{}")
    assert main(["runs", str(folder)]) == 0
    out = capsys.readouterr().out
    assert out.startswith(f"no run folders in {folder}/: it is {hint}")
    wanted = folder / "points" if marker == "sweep.json" else folder.parent
    assert out.rstrip().endswith(f"frictionlab runs {wanted}")
    capsys.readouterr()
    assert main(["runs", str(tmp_path)]) == 0  # a folder of run folders' folders: no hint
    assert capsys.readouterr().out == f"no run folders in {tmp_path}/\n"
    assert main(["runs", f"{tmp_path}/"]) == 0  # given with its slash: one slash (`runs /` said "//")
    assert capsys.readouterr().out == f"no run folders in {tmp_path}/\n"

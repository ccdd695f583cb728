"""The headless CLI as a user meets it: real files, real subprocesses, exit codes."""

import json
import math
import os
import subprocess
import sys

import pytest

from frictionlab.errors import MEMORY_ADVICE, ExitCode

from ..conftest import PRESETS


def test_bad_command_line_is_a_usage_error_without_traceback(cli):
    result = cli("run")
    assert result.returncode == ExitCode.USAGE
    assert "usage:" in result.stderr and "Traceback" not in result.stderr
    result = cli("run", PRESETS / "quickstart.yaml", "--workers", "0")
    assert result.returncode == ExitCode.USAGE
    assert "--workers must be >= 1. Got 0 instead." in result.stderr


@pytest.mark.long  # a process of its own, seconds end to end: pytest -m long
def test_headless_run_never_imports_textual(tmp_path):
    code = (
        "import sys; from frictionlab.cli import main; "
        f"rc = main(['run', {str(PRESETS / 'quickstart.yaml')!r}, '--out', {str(tmp_path / 'o')!r}, '--quiet']); "
        "bad = sorted(m for m in sys.modules if m.split('.')[0] in {'textual', 'rich'}); "
        "print(rc, bad)"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.stdout.strip().splitlines()[-1] == "0 []", result.stderr


def test_running_out_of_memory_is_said_as_such_not_as_a_bug(monkeypatch, capsys):
    import frictionlab.cli.validate
    from frictionlab.cli import main

    def allocate(args):
        raise MemoryError("Unable to allocate 29.8 TiB for an array with shape (1000000000, 4096)")

    monkeypatch.setattr(frictionlab.cli.validate, "run", allocate)  # the handler the parser is built with
    assert main(["validate", "quickstart"]) == ExitCode.RUNTIME_FAILURE
    err = capsys.readouterr().err
    assert err.startswith("error: out of memory: Unable to allocate 29.8 TiB") and "internal error" not in err


def test_the_dashboard_without_frictionlabs_own_dask_cluster_is_refused_not_ignored(capsys):
    from frictionlab.cli import main

    for extra in ([], ["--executor", "processes"], ["--executor", "dask", "--scheduler", "tcp://127.0.0.1:1"]):
        assert main(["run", "quickstart", "--dashboard", "--quiet", *extra]) == ExitCode.USAGE
        assert "--dashboard serves the dashboard of frictionlab's own Dask cluster" in capsys.readouterr().err


def test_workers_with_the_serial_executor_are_refused_not_ignored(tmp_path, capsys):
    """--executor serial --workers 4 ran on one worker, the 4 ignored but for '1 worker(s)' in the progress."""
    from frictionlab.cli import main

    out = tmp_path / "out"
    assert main(["run", "quickstart", "--out", str(out), "--executor", "serial", "--workers", "4", "--quiet"]) == ExitCode.USAGE
    assert "--workers 4 with --executor serial" in capsys.readouterr().err and not out.exists()
    assert main(["run", "quickstart", "--executor", "serial", "--workers", "1", "--out", str(out), "--quiet"]) == ExitCode.OK
    assert main(["resume", str(out), "--executor", "serial", "--workers", "4", "--quiet"]) == ExitCode.USAGE
    assert "--workers 4 with --executor serial" in capsys.readouterr().err


def test_a_value_argparse_cannot_read_is_said_cut_short_and_a_too_long_number_as_such(capsys):
    """--seed of 5000 digits was 'invalid int value' (Python reads at most 4300), quoted in full,
    and a 500-character --workers too."""
    from frictionlab.cli import main

    with pytest.raises(SystemExit) as exit_:
        main(["run", "quickstart", "--seed", "9" * 5000])
    err = capsys.readouterr().err
    assert exit_.value.code == ExitCode.USAGE and len(err.splitlines()[-1]) < 300
    assert "argument --seed: invalid int value: '999" in err and "a whole number of 5000 digits, too long" in err
    with pytest.raises(SystemExit):
        main(["run", "quickstart", "--workers", "x" * 500])
    last = capsys.readouterr().err.splitlines()[-1]
    assert "argument --workers: invalid int value: 'xxx" in last and "..." in last and len(last) < 300


def test_tls_files_without_a_tls_scheduler_are_refused_not_ignored(tmp_path, capsys):
    """--tls-* only ever reach a tls:// scheduler: given without one, the run went on, unencrypted or on
    frictionlab's own cluster, as if they had been used."""
    from frictionlab.cli import main

    cert = tmp_path / "cert.pem"
    cert.write_text("not read\n")
    out = tmp_path / "out"
    for extra, said in (([], "there is no --scheduler"), (["--scheduler", "tcp://127.0.0.1:1"], "tcp://127.0.0.1:1, which is not encrypted")):
        code = main(["run", "quickstart", "--tls-cert", str(cert), "--out", str(out), "--quiet", *extra])
        err = capsys.readouterr().err
        assert code == ExitCode.USAGE, err
        assert "--tls-cert is for a tls:// Dask scheduler" in err and said in err
        assert not out.exists()
    assert main(["run", "quickstart", "--tls-ca-file", str(cert), "--tls-key", str(cert), "--out", str(out), "--quiet"]) == ExitCode.USAGE
    assert "--tls-ca-file and --tls-key are for a tls:// Dask scheduler" in capsys.readouterr().err

def test_a_negative_number_in_any_notation_is_an_options_value(capsys):
    """argparse itself takes only -1 and -0.5 as values; -1e-2 was refused as an unknown option."""
    from frictionlab.cli import main

    contact = ["predict", "--area", "1", "--modulus", "1", "--rms-height", "1", "--force", "1"]
    assert main([*contact, "--a", "1", "--b", "-1E-2", "--a-ci", "-1e+1", "2", "--b-ci", "-.5e-1", "0"]) == ExitCode.OK
    f = 0.5 * math.sqrt(math.pi)  # sqrt(pi) F / (2 E* h sqrt(A)) with every number 1
    assert f"xi = grad_z_contact / grad_z = {1 - 1e-2 * math.log(f):.4f}" in capsys.readouterr().out
    assert main([*contact, "--a", "-inf", "--b", "1"]) == ExitCode.USAGE  # checked as a number: named, not unknown
    assert "--a must be a finite number. Got -inf instead." in capsys.readouterr().err
    assert main(["study", str(PRESETS / "quickstart.yaml"), "--tolerances", "-1e-3,1e-6"]) == ExitCode.USAGE
    assert "--tolerances values must be finite numbers > 0. Got '-1e-3' instead." in capsys.readouterr().err
    with pytest.raises(SystemExit) as refused:  # an option still is one (argparse's usage error)
        main(["run", str(PRESETS / "quickstart.yaml"), "-x1"])
    assert refused.value.code == ExitCode.USAGE and "unrecognized arguments: -x1" in capsys.readouterr().err


def test_a_long_word_after_a_dash_that_is_no_number_is_refused_at_once(tmp_path):
    """A word of '-' and 100,000 digits ending in a letter took the negative-number pattern
    (\\d+\\.?\\d*: digits that split many ways) a time quadratic in its length: 20,000 digits a
    minute, 100,000 half an hour, before argparse could say it expected a value. The numbers
    it must know are still values."""
    from frictionlab.cli.main import NEGATIVE_NUMBER

    numbers = ["-1", "-1.", "-.5", "-1.5e-3", "-1E+5", "-inf", "-nan", "-1,2,-3", "-1.5,+2e3,-.5"]
    assert all(NEGATIVE_NUMBER.match(word) for word in numbers)
    assert not any(NEGATIVE_NUMBER.match(word) for word in ["-1e", "-1.2.3", "-x1", "-", "-1,", "-,1", "-.", "-e5"])
    try:
        done = subprocess.run([sys.executable, "-m", "frictionlab", "run", str(PRESETS / "quickstart.yaml"), "--seed",
                               "-" + "1" * 100_000 + "x"], capture_output=True, text=True, timeout=60, cwd=tmp_path)  # fmt: skip
    except subprocess.TimeoutExpired:
        pytest.fail("a word of 100,000 digits was still being parsed after 60 s")
    assert done.returncode == ExitCode.USAGE and "argument --seed: expected one argument" in done.stderr


@pytest.mark.parametrize(
    "command", [["validate"], ["resume"], ["runs"], ["schema", "--out"], ["run", str(PRESETS / "quickstart.yaml"), "--out"]]
)
def test_a_path_longer_than_the_file_system_allows_is_a_usage_error(command, tmp_path, capsys):
    """ENAMETOOLONG from the first look at the path: the argument is wrong, not the run (exit 1)."""
    from frictionlab.cli import main

    long = str(tmp_path / ("a" * 300))  # one name past any Linux or macOS file system's 255 bytes
    assert main([*command, long]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "a file name too long for this file system (at most a name 255 bytes" in err and "Traceback" not in err


def test_a_refusal_names_the_first_overrides_only(capsys):
    from frictionlab.cli import main

    overrides = [arg for i in range(2_000) for arg in ("--set", f"seed={i}")]
    assert main(["validate", "quickstart", *overrides, "--set", "realizations=-1"]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "--set seed=0 --set seed=1" in err and "(and 1996 more --set)" in err
    assert "realizations: must be >= 1, got -1" in err and len(err) < 2000


@pytest.mark.parametrize(
    "command, code, said",
    [
        (["validate", ""], ExitCode.INPUT_FILE, "the preset is named by an empty string"),
        (["run", ""], ExitCode.INPUT_FILE, "the preset is named by an empty string"),
        (["schema", "--out", ""], ExitCode.USAGE, "--out names no file (it is empty)"),
        (["presets", "copy", "quickstart", ""], ExitCode.USAGE, "DEST names no file or folder (it is empty)"),
        (["resume", ""], ExitCode.USAGE, "DIR names no folder (it is empty)"),
        (["follow", ""], ExitCode.USAGE, "DIR names no folder (it is empty)"),
        (["runs", ""], ExitCode.USAGE, "DIR names no folder (it is empty)"),
        (["report", "--out", ""], ExitCode.USAGE, "--out names no folder (it is empty)"),
        (["report", "--presets", ""], ExitCode.USAGE, "--presets names no folder (it is empty)"),
        (["report", "--figures", ""], ExitCode.USAGE, "--figures names no folder (it is empty)"),
        (["report", "--markdown", ""], ExitCode.USAGE, "--markdown names no file (it is empty)"),
        (["run", "quickstart", "--out", "  "], ExitCode.USAGE, "--out names no folder (it is only spaces)"),
    ],
)
def test_an_empty_path_is_refused_naming_it_never_read_as_this_folder(command, code, said, tmp_path, monkeypatch, capsys):
    from frictionlab.cli import main

    monkeypatch.chdir(tmp_path)
    assert main(command) == code
    captured = capsys.readouterr()
    assert said in captured.err and "Traceback" not in captured.err and captured.out == ""
    assert list(tmp_path.iterdir()) == []  # nothing written in this folder


@pytest.mark.parametrize("command", [["validate"], ["run"], ["study"]])
def test_a_preset_given_as_an_address_is_named_as_one_as_typed(command, tmp_path, monkeypatch, capsys):
    """A preset named by its address was 'http:/example.com/p.yaml: no such preset file': not
    the value typed (its // made one /), nor what is wrong with it."""
    from frictionlab.cli import main

    monkeypatch.chdir(tmp_path)
    assert main([*command, "https://example.com/p.yaml"]) == ExitCode.INPUT_FILE
    err = capsys.readouterr().err
    assert "https://example.com/p.yaml: 1 problem in preset" in err, err
    assert "(file): https://example.com/p.yaml is an address; a preset is read from a file here, never fetched: " \
           "download it (curl -O ADDRESS), then give the file" in err, err
    assert list(tmp_path.iterdir()) == []


PATH_METAVARS = ("DIR", "RUN_DIR", "FILE", "DEST")


def _path_arguments():
    """(command words up to the path argument, the argument's name) for every path argument of
    every command: an option or a positional whose metavar names a file or a folder."""
    from frictionlab.cli.main import build_parser

    def walk(parser, words):
        for action in parser._actions:
            if action.choices and isinstance(action.choices, dict):  # a command's own commands (presets copy)
                for name, child in action.choices.items():
                    yield from walk(child, [*words, name])
            elif action.metavar in PATH_METAVARS:
                yield words, action

    yield from walk(build_parser(), [])


def _filled(words: list[str], path, parser) -> list[str]:
    """``words`` with every other required argument given a value argparse takes."""
    argv = list(words)
    for action in parser._actions:
        if action is path or not (action.required or (not action.option_strings and action.nargs is None)):
            continue
        value = next(iter(action.choices)) if action.choices else "1"
        argv += [action.option_strings[0], value] if action.option_strings else [value]
    return argv


@pytest.mark.parametrize("words, name", [
    pytest.param(words, name, id=" ".join([*words, name]))
    for words, action in _path_arguments() for name in [action.option_strings[-1] if action.option_strings else action.metavar]
])
def test_every_path_argument_given_empty_is_refused_before_the_command_runs(words, name, tmp_path, monkeypatch, capsys):
    """study --out "" and exact3d --out/--runs/--presets "" were taken as not given: a study
    into a new folder of runs/, hours of exact 3D runs; every path argument is refused alike."""
    import importlib

    from frictionlab.cli import main
    from frictionlab.cli.main import build_parser

    module = importlib.import_module(f"frictionlab.cli.{words[0]}")
    monkeypatch.setattr(module, "run", lambda args: pytest.fail(f"{' '.join(words)} ran with {name} empty"))
    monkeypatch.chdir(tmp_path)
    parser = build_parser()
    for word in words:
        parser = next(a for a in parser._actions if isinstance(a.choices, dict)).choices[word]
    path = next(a for a in parser._actions if (a.option_strings[-1] if a.option_strings else a.metavar) == name)
    argv = _filled(words, path, parser)
    argv += [name, ""] if path.option_strings else [""]
    assert main(argv) == ExitCode.USAGE
    assert f"{name} names no " in capsys.readouterr().err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.skipif(not os.path.isdir("/proc/self"), reason="needs Linux's /proc, a folder no file can be made in")
def test_presets_copy_into_a_folder_no_file_can_be_made_in_is_refused_naming_it(capsys):
    """DEST /proc/self/x was 'No such file or directory: /proc/self/x' with exit code 1; the folder
    is tried first, as schema --out's is."""
    from frictionlab.cli import main

    assert main(["presets", "copy", "quickstart", "/proc/self/q.yaml"]) == ExitCode.OUTPUT_REFUSED
    err = capsys.readouterr().err
    assert "DEST /proc/self/q.yaml: /proc/self cannot be written in" in err and "a folder you can write to" in err


def test_presets_copy_into_a_missing_folder_or_under_a_file_is_refused_naming_it(tmp_path, capsys):
    """open() of DEST in a folder that does not exist said only "No such file or directory"
    with exit code 1; the folder is named, with exit code 4, and nothing is made."""
    from frictionlab.cli import main

    (tmp_path / "file.txt").write_text("mine")
    assert main(["presets", "copy", "quickstart", str(tmp_path / "missing" / "q.yaml")]) == ExitCode.OUTPUT_REFUSED
    assert f"the folder {tmp_path / 'missing'} does not exist; make the folder first" in capsys.readouterr().err
    assert main(["presets", "copy", "quickstart", str(tmp_path / "file.txt" / "q.yaml")]) == ExitCode.OUTPUT_REFUSED
    assert f"{tmp_path / 'file.txt'} is a file, not a folder" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file.txt"] and (tmp_path / "file.txt").read_text() == "mine"


CTRL_C_WHILE_LOADING = """
import sys
loading = sys.argv[1]
class CtrlC:  # Ctrl-C arriving while the command's modules load
    def find_spec(self, name, path=None, target=None):
        if name == loading:
            raise KeyboardInterrupt
sys.meta_path.insert(0, CtrlC())
from frictionlab.__main__ import program
sys.argv = ["frictionlab", "runs", sys.argv[2]]
program()
"""


@pytest.mark.parametrize("module", ["frictionlab.cli.main", "frictionlab.runs.detached"])
def test_ctrl_c_while_the_command_loads_ends_with_130_and_a_line_not_a_traceback(tmp_path, module):
    done = subprocess.run([sys.executable, "-c", CTRL_C_WHILE_LOADING, module, str(tmp_path)],
                          capture_output=True, text=True, timeout=60)  # fmt: skip
    assert done.returncode == 130, done.stderr
    assert done.stderr == "interrupted\n"


def test_realizations_out_of_memory_say_how_to_resume_and_the_resume_finishes(tmp_path, monkeypatch, capsys):
    """A realization that ran out of memory was told as any failure ('1 realization(s) failed; first:
    #1: MemoryError...'), with nothing on what was kept nor how to go on; the TUI called it an internal error."""
    from frictionlab.cli import main
    from frictionlab.tui.text import failure_message
    from frictionlab_spectra.power_law import PowerLaw

    from frictionlab.preset import load_scene
    from frictionlab.preset.seeds import realization_rng

    made, original = [], PowerLaw.generate
    third = realization_rng(load_scene("quickstart").preset.seed, 2).bit_generator.state  # realization 2's, made in the run

    def second_one_short(self, rng):
        if rng.bit_generator.state == third and not made:
            made.append(1)
            raise MemoryError("Unable to allocate 16.0 MiB for an array with shape (2097152,) and data type float64")
        return original(self, rng)

    monkeypatch.setattr(PowerLaw, "generate", second_one_short)
    out = tmp_path / "run"
    args = ["--out", str(out), "--workers", "1", "--quiet", "--no-plot", "--set", "realizations=4"]
    assert main(["run", "quickstart", *args]) == ExitCode.RUNTIME_FAILURE
    err = capsys.readouterr().err
    assert f"1 realization(s) ran out of memory; what finished is kept in {out}/: `frictionlab resume {out}`" in err
    assert "internal error" not in err
    reason = "MemoryError: Unable to allocate 16.0 MiB (springs.py:174)"
    assert failure_message(reason) == f"out of memory (Unable to allocate 16.0 MiB): run it again with {MEMORY_ADVICE}"
    monkeypatch.setattr(PowerLaw, "generate", original)
    assert main(["resume", str(out), "--workers", "1", "--quiet", "--no-plot"]) == ExitCode.OK
    summary = json.loads((out / "summary.json").read_text())
    assert (summary["status"], summary["resumed_realizations"], summary["retried_realizations"]) == ("completed", 3, 1)


@pytest.mark.parametrize("said", ["No space left on device", "out of memory: Unable to allocate 2.0 GiB"])
def test_a_full_disk_or_memory_at_the_end_says_what_is_kept_and_how_to_resume(tmp_path, monkeypatch, capsys, said):
    """'error: cannot write results to DIR: No space left on device' (or 'error: out of memory;
    ask for fewer points...') said nothing of the chunks kept there."""
    import errno

    from frictionlab.cli import main
    from frictionlab.runs import runner

    def full(out_dir, *args):
        if said.startswith("out of memory"):
            raise MemoryError(said.removeprefix("out of memory: "))
        raise OSError(errno.ENOSPC, said, str(out_dir / "summary.json"))

    monkeypatch.setattr(runner, "write_results", full)
    out = tmp_path / "run"
    assert main(["run", "quickstart", "--out", str(out), "--workers", "1", "--quiet"]) == ExitCode.RUNTIME_FAILURE
    err = capsys.readouterr().err
    assert f"{said}" in err and f"; what finished is kept in {out}/: `frictionlab resume {out}`" in err
    assert "internal error" not in err
    monkeypatch.undo()
    assert main(["resume", str(out), "--workers", "1", "--quiet", "--no-plot"]) == ExitCode.OK


def test_a_full_disk_under_json_prints_the_error_object(tmp_path, monkeypatch, capsys):
    """`run --json` stopped by a full disk printed nothing on stdout: a script found no JSON
    where every other refusal or failure gives the error object."""
    import errno

    from frictionlab.cli import main
    from frictionlab.runs import runner

    def full(out_dir, *args):
        raise OSError(errno.ENOSPC, "No space left on device", str(out_dir / "summary.json"))

    monkeypatch.setattr(runner, "write_results", full)
    out = tmp_path / "run"
    assert main(["run", "quickstart", "--out", str(out), "--workers", "1", "--quiet", "--json"]) == ExitCode.RUNTIME_FAILURE
    captured = capsys.readouterr()
    said = (f"cannot write {out}/summary.json: No space left on device; what finished is kept in {out}/: "
            f"`frictionlab resume {out}` computes the rest")  # fmt: skip
    assert captured.err == f"error: {said}\n"
    error = json.loads(captured.out)
    assert (error["schema"], error["command"], error["error"], error["exit_code"]) == ("frictionlab/error/1", "run", said, 1)

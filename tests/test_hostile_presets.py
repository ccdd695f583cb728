"""Hostile and malformed input, as an attacker or a careless user would give
it: each is refused fast with a message that names the field or the file
(never quoting the file's content) and its own exit code, never the
catch-all internal error. Cases that could hang or exhaust memory run in a
subprocess with a deadline and a memory limit, so a regression fails the
test instead of the machine."""

from __future__ import annotations

import json
import math
import os
import re
import resource
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from frictionlab.cli import main
from frictionlab.errors import ExitCode

from .conftest import ROOT, SMALL_PRESET, merge

BASE = yaml.safe_dump(merge(SMALL_PRESET, {"output": {"plot": False}}), sort_keys=False)


def preset_text(**changes) -> str:
    return yaml.safe_dump(merge(SMALL_PRESET, {"output": {"plot": False}, **changes}), sort_keys=False)


def replace(old: str, new: str) -> str:
    assert old in BASE
    return BASE.replace(old, new, 1)


def _limit_memory() -> None:  # pragma: no cover - runs in the child
    resource.setrlimit(resource.RLIMIT_AS, (3 << 30, 3 << 30))


def guarded_validate(folder: Path, *presets: str, timeout: float = 30) -> dict[str, dict]:
    """``frictionlab validate --json PRESETS`` in a process with a deadline and a memory
    limit: each preset's record (its problems and exit code), by the name it was given."""
    try:
        done = subprocess.run(
            [sys.executable, "-m", "frictionlab", "validate", "--json", *presets], capture_output=True, text=True,
            timeout=timeout, cwd=folder, preexec_fn=_limit_memory, env={**os.environ, "PYTHONPATH": str(ROOT)},
        )  # fmt: skip
    except subprocess.TimeoutExpired:
        pytest.fail(f"frictionlab validate {' '.join(presets)} still ran after {timeout} s")
    assert "Traceback" not in done.stderr, done.stderr[-2000:]
    return {record["preset"]: record for record in json.loads(done.stdout)["presets"]}


ALIAS_BOMB = (
    'a: &a ["lol","lol","lol","lol","lol","lol","lol","lol","lol"]\n'
    + "".join(f"{chr(98 + i)}: &{chr(98 + i)} [" + ",".join([f"*{chr(97 + i)}"] * 9) + "]\n" for i in range(8))
)

# id: (preset text, exit code, what the message says); each validated by `frictionlab validate`
IN_PROCESS = {
    "recursive alias": ("description: &d [*d]\n" + BASE, ExitCode.INPUT_FILE, "refers to a value that contains it"),
    "not UTF-8": (b"\xff\xfe".decode("latin-1") + BASE, ExitCode.INPUT_FILE, "not UTF-8 text (byte 1, line 1)"),
    "duplicate key": (BASE + "seed: 8\n", ExitCode.USAGE, "duplicate key 'seed' at lines 2 and"),
    "duplicate nested key": (replace("hurst: 0.8", "hurst: 0.8\n    hurst: 0.9"), ExitCode.USAGE,
                             "spectrum.params: duplicate key 'hurst'"),
    "NUL name": (replace("name: small", 'name: "a\\0b"'), ExitCode.USAGE, "got 'a\\x00b'"),
    "NUL byte in the file": (BASE + "description: a\x00b\n", ExitCode.USAGE, "character #x0000 is not allowed"),
    "int past the digit limit": (replace("seed: 7", "seed: " + "1" * 5000), ExitCode.USAGE,
                                 "seed: the whole number at line 2 has 5000 digits: a number must be 0 or between 1e-100 "
                                 "and 1e+100 in magnitude"),  # not Python's own words ('Exceeds the limit (4300 digits)')
    "a date for a key": (BASE + "2001-01-01: 2\n", ExitCode.USAGE,  # not 'datetime.date(2001, 1, 1): keys should be strings'
                         "(preset): the key 2001-01-01 must be text, and YAML reads it as a date: quote it ('2001-01-01')"),
    "a number for a key of params": (replace("hurst: 0.8", "hurst: 0.8\n    3: 4"), ExitCode.USAGE,
                                     "spectrum.params: the key 3 must be text, and YAML reads it as a whole number"),
    "a key past 1024 characters": (BASE + "k" * 1100 + ": 1\n", ExitCode.USAGE,  # was 'neither key: value nor ...'
                                   "a key of 1100 characters, where YAML takes at most 1024; shorten it"),
    "a nested key past 1024 characters": (replace("hurst: 0.8", "hurst: 0.8\n    " + "k" * 2000 + ": 1"),
                                          ExitCode.USAGE, "a key of 2000 characters, where YAML takes at most 1024"),
    "impossible date": (replace("name: small", "name: 2020-13-45"), ExitCode.USAGE,
                        "name: the value at line 1 cannot be converted (ValueError: month must be in 1..12)"),
    "control char in a file path": (replace("name: power-law", "name: profile-file").replace(
        "hurst: 0.8\n    points: 1024\n    rms_height: 1.0", 'path: "scan\\n.csv"\n    spacing: 1.0'),
        ExitCode.USAGE, "spectrum.params.path: must not contain control characters"),
    "a number for a section": (replace("loading:\n", "loading: 3\nx:\n"), ExitCode.USAGE,
                               "loading: must be a mapping of keys to values (keys: control, spacing, start, steps, stop, "
                               "unit), got 3"),  # it named no key
}


# id: (a line of the preset, what replaces it, what the message says): numbers pydantic alone would take
NUMBERS = {
    "bool realizations": ("realizations: 8", "realizations: true", "realizations: must be a number, not true or false, got true"),
    "bool hurst": ("hurst: 0.8", "hurst: true", "spectrum.params.hurst: must be a number, not true or false"),
    "bool seed": ("seed: 7", "seed: false", "seed: must be a number, not true or false"),
    "inf stop": ("stop: 20.0", "stop: .inf", "loading.stop: must be a finite number, got inf"),
    "nan rms height": ("rms_height: 1.0", "rms_height: .nan", "spectrum.params.rms_height: must be a finite number"),
    "inf c0": ("rms_height: 1.0", "rms_height: null\n    c0: .inf", "spectrum.params.c0: must be a finite number"),
    "1e308 modulus": ("youngs_modulus: 1.0", "youngs_modulus: 1e308", "solver.params.youngs_modulus: must be between 1e-100 and 1e+100, got"),
    "1e308 height": ("rms_height: 1.0", "rms_height: 1.0e+308", "spectrum.params.rms_height: must be between 1e-100 and 1e+100"),
    # and the mirror: pydantic alone takes 0, 1 and the text 'yes' or 'off' as true or false
    "0 plot": ("plot: false", "plot: 0", "output.plot: must be true or false, got 0"),
    "text plot": ("plot: false", "plot: 'yes'", "output.plot: must be true or false, got 'yes'"),
    "1.0 realizations file": ("plot: false", "plot: false\n  realizations: 1.0",
                              "output.realizations: must be true or false, got 1.0"),
}  # fmt: skip
# names that would take the output folder elsewhere, or are no folder name at all
FOLDER_ESCAPES = ("/tmp/escape", "../../escape", '"a\\nb"')
IN_PROCESS.update({case: (replace(old, new), ExitCode.USAGE, message) for case, (old, new, message) in NUMBERS.items()})
IN_PROCESS.update({f"name {name}": (replace("name: small", f"name: {name}"), ExitCode.USAGE,
                                    "name: must be 1 to 100 of a-z, A-Z, 0-9") for name in FOLDER_ESCAPES})  # fmt: skip


@pytest.mark.parametrize("case", list(IN_PROCESS))
def test_malformed_presets_are_refused_naming_the_field(case, tmp_path, capsys):
    text, code, message = IN_PROCESS[case]
    path = tmp_path / "p.yaml"
    path.write_bytes(text.encode("latin-1") if case == "not UTF-8" else text.encode())
    assert main(["validate", str(path)]) == code
    err = capsys.readouterr().err
    assert message in err, err
    assert "internal error" not in err and len(err) < 2000


def test_a_folder_given_as_preset_is_refused(tmp_path, capsys):
    assert main(["validate", str(tmp_path)]) == ExitCode.INPUT_FILE
    assert "preset file is a folder, not a regular file" in capsys.readouterr().err


def test_a_bad_name_writes_nothing_outside_the_runs_folder(tmp_path, monkeypatch, capsys):
    (tmp_path / "work").mkdir()
    monkeypatch.chdir(tmp_path / "work")
    path = tmp_path / "work" / "p.yaml"
    path.write_text(replace("name: small", "name: ../../escape"))
    assert main(["run", str(path), "--quiet"]) == ExitCode.USAGE
    assert sorted(p.name for p in tmp_path.rglob("*")) == ["p.yaml", "work"]


def test_a_bool_given_with_set_is_refused(tmp_path, capsys):
    path = tmp_path / "p.yaml"
    path.write_text(BASE)
    assert main(["validate", str(path), "--set", "realizations=true"]) == ExitCode.USAGE
    assert "realizations: must be a number, not true or false" in capsys.readouterr().err


def test_binary_text_that_is_not_utf8_is_said_so(tmp_path, capsys):
    path = tmp_path / "p.yaml"
    path.write_text(BASE + "description: !!binary /w==\n")  # the byte 0xff
    assert main(["validate", str(path)]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "description: must be UTF-8 text, got b'\\xff'" in err and "raw data" not in err, err


@pytest.mark.parametrize("assignment", ["name=\udcff\udcfe", "\udcff=1", "spectrum.params.hurst=0.5\udcff"])
def test_a_set_in_bytes_that_are_not_utf8_is_refused_as_such(capsys, assignment):
    """A --set typed in Latin-1 (Python reads its bytes as lone surrogates) was told pydantic's 'unable
    to parse raw data as a unicode string', of '\\udcff', or of the field '(preset)' for a key."""
    assert main(["validate", "quickstart", "--set", assignment]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "not UTF-8 text" in err and "\\xff" in err and "udcff" not in err and "raw data" not in err, err


@pytest.mark.parametrize("assignments, said", [
    (["loading.start=true", "loading.stop=0.5"], "loading.start: must be a number, not true or false"),
    (["spectrum.params.length=true"], "spectrum.params.length: must be a number, not true or false"),
    (["spectrum.params.short_cutoff=true"], "spectrum.params.short_cutoff: must be a number, not true or false"),
])  # fmt: skip
def test_a_bool_refused_is_not_also_checked_against_other_fields_as_one(capsys, assignments, said):
    """true passes pydantic as 1: a check across the section's fields then said 'stop must be > start
    (1.0)' or 'length=1.0 disagree', of a value no one wrote."""
    args = ["validate", "quickstart"] + [word for a in assignments for word in ("--set", a)]
    assert main(args) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "1 problem in preset" in err and said in err and "1.0" not in err, err



def test_an_unknown_key_of_any_length_is_named_cut_in_the_middle(tmp_path, capsys):
    key = "q" + "x" * 10_000 + "z"
    path = tmp_path / "p.yaml"
    path.write_text(BASE + f"? {key}\n: 1\n")  # an explicit key: an implicit one is at most 1024 characters
    for args in (["validate", str(path)], ["validate", "quickstart", "--set", f"spectrum.params.{key}=1"]):
        assert main(args) == ExitCode.USAGE
        err = capsys.readouterr().err
        assert "is not a known field" in err and "qxxx" in err and "xxxz" in err
        assert max(map(len, err.splitlines())) < 500

# ------------------------------------------------------------------ cases that hang or eat memory on their own


def write_hostile(folder: Path) -> None:
    (folder / "bomb.yaml").write_text(BASE + ALIAS_BOMB + "description: *i\n")
    (folder / "huge.yaml").write_text(BASE)
    os.truncate(folder / "huge.yaml", 50 * 1024 * 1024)  # 50 MB (sparse: cheap to make)
    (folder / "deep.yaml").write_text(BASE + "description: " + "[" * 5000 + "]" * 5000 + "\n")
    os.mkfifo(folder / "fifo.yaml")
    axes = {"spectrum.params.hurst": {"start": 0.1, "stop": 1.0, "num": 1000}, "seed": {"start": 0, "stop": 999, "num": 1000}}
    (folder / "grid.yaml").write_text(preset_text(sweep={"parameters": axes}))


# preset: (exit code, what its one problem says); all validated by one guarded process
HOSTILE = {
    "bomb.yaml": (ExitCode.INPUT_FILE, "expands to more than 20,000 values (aliases repeat what they refer to)"),
    "huge.yaml": (ExitCode.INPUT_FILE, "preset file of 52,428,800 bytes, more than the limit of 262,144 bytes"),
    "deep.yaml": (ExitCode.INPUT_FILE, "nested more than 64 levels deep at line"),
    "fifo.yaml": (ExitCode.INPUT_FILE, "preset file is a FIFO (named pipe), not a regular file"),
    "/dev/zero": (ExitCode.INPUT_FILE, "preset file is a character device, not a regular file"),
    "grid.yaml": (ExitCode.USAGE, "the sweep has 1,000,000 points (grid of 1000 x 1000); at most 1,000 are allowed"),
}
if os.path.exists("/proc/self/fd"):  # a kernel's /proc is Linux's; /proc's files say they are regular, some block for ever
    HOSTILE["/proc/self/status"] = (ExitCode.INPUT_FILE, "preset file is in the kernel's /proc or /sys (a read may block), not a data file")


@pytest.fixture(scope="module")
def hostile_records(tmp_path_factory) -> dict[str, dict]:
    folder = tmp_path_factory.mktemp("hostile")
    write_hostile(folder)
    return guarded_validate(folder, *HOSTILE)


@pytest.mark.parametrize("preset", list(HOSTILE))
def test_a_preset_that_could_hang_or_eat_memory_is_refused_at_once_with_a_short_message(preset, hostile_records):
    code, message = HOSTILE[preset]
    record = hostile_records[preset]
    assert record["exit_code"] == code and not record["ok"], record
    assert len(record["problems"]) == 1 and message in record["problems"][0], record
    assert len(record["problems"][0]) < 1000


def test_a_closed_stdout_ends_the_command_quietly(tmp_path):
    read_end, write_end = os.pipe()
    os.close(read_end)  # the reader is gone before anything is written (as `| head -c 10` once it has its bytes)
    try:
        done = subprocess.run(
            [sys.executable, "-m", "frictionlab", "plugins", "--json"], stdout=write_end, stderr=subprocess.PIPE,
            cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(ROOT)}, timeout=30,
        )  # fmt: skip
    finally:
        os.close(write_end)
    assert done.returncode == ExitCode.BROKEN_PIPE
    assert done.stderr == b""


# ------------------------------------------------------------------ data files and run folders


SECRET = "root:x:0:0:the-secret-line-of-a-system-file"


def profile_preset(tmp_path: Path, path: str) -> Path:
    data = {**merge(SMALL_PRESET, {"output": {"plot": False}}), "realizations": 2,
            "spectrum": {"name": "profile-file", "params": {"path": path, "spacing": 1.0}}}  # fmt: skip
    preset = tmp_path / "p.yaml"
    preset.write_text(yaml.safe_dump(data))
    return preset


def test_a_profile_file_that_is_not_numbers_is_named_never_quoted(tmp_path, capsys):
    (tmp_path / "passwd.txt").write_text(f"{SECRET}\n" * 20)
    preset = profile_preset(tmp_path, "passwd.txt")
    # refused when the preset is validated, before any run folder is made
    assert main(["run", str(preset), "--out", str(tmp_path / "o"), "--quiet", "--json"]) == ExitCode.USAGE
    captured = capsys.readouterr()
    assert "non-numeric content at line 2" in captured.err  # line 1 is taken for a header
    assert str(tmp_path / "passwd.txt") in captured.err and not (tmp_path / "o").exists()
    for text in (captured.out, captured.err):
        assert "the-secret-line" not in text


def test_a_fifo_as_profile_file_is_refused_when_the_preset_is_validated(tmp_path, capsys):
    os.mkfifo(tmp_path / "scan.csv")
    assert main(["validate", str(profile_preset(tmp_path, "scan.csv"))]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "spectrum.params.path: is a FIFO (named pipe), not a regular file" in err


@pytest.mark.skipif(not os.path.exists("/proc/self/fd"), reason="a kernel's /proc is Linux's")
def test_a_file_of_the_kernel_s_proc_is_refused_as_data(tmp_path, capsys):
    """As a preset: ``HOSTILE`` above."""
    assert main(["validate", str(profile_preset(tmp_path, "/proc/cpuinfo"))]) == ExitCode.USAGE
    assert "profile-file '/proc/cpuinfo': file is in the kernel's /proc or /sys" in capsys.readouterr().err


def test_a_missing_profile_file_is_refused_when_the_preset_is_validated(tmp_path, capsys):
    assert main(["validate", str(profile_preset(tmp_path, "gone.csv"))]) == ExitCode.USAGE
    assert f"spectrum.params.path: no such file, got '{tmp_path / 'gone.csv'}'" in capsys.readouterr().err


def test_a_damaged_preset_in_a_run_folder_is_named(tmp_path, capsys):
    path = tmp_path / "p.yaml"
    path.write_text(BASE)
    assert main(["run", str(path), "--out", str(tmp_path / "run"), "--quiet"]) == ExitCode.OK
    (tmp_path / "run" / "preset.yaml").write_text("name: [unclosed\n")
    assert main(["resume", str(tmp_path / "run"), "--quiet"]) == ExitCode.RUN_FOLDER
    err = capsys.readouterr().err
    assert f"{tmp_path / 'run' / 'preset.yaml'} is damaged (not valid YAML at line 1, column 7: a [ list opened here" in err
    (tmp_path / "run" / "run.json").write_text("{ damaged")
    (tmp_path / "run" / "preset.yaml").write_text(BASE)
    assert main(["resume", str(tmp_path / "run"), "--quiet"]) == ExitCode.RUN_FOLDER
    assert f"{tmp_path / 'run' / 'run.json'} is damaged (not valid JSON at line 1)" in capsys.readouterr().err


def test_an_output_path_under_a_file_is_refused_naming_the_file(tmp_path, capsys):
    path = tmp_path / "p.yaml"
    path.write_text(BASE)
    (tmp_path / "results").write_text("a file, not a folder")
    assert main(["run", str(path), "--out", str(tmp_path / "results" / "run"), "--quiet"]) == ExitCode.OUTPUT_REFUSED
    assert f"cannot be made a folder: {tmp_path / 'results'} is a file" in capsys.readouterr().err
    assert main(["run", str(path), "--out", str(tmp_path / "results"), "--quiet"]) == ExitCode.OUTPUT_REFUSED
    assert f"{tmp_path / 'results'} is a file, not a folder" in capsys.readouterr().err


def test_an_output_path_that_is_a_fifo_or_a_dangling_link_is_refused_naming_what_it_is(tmp_path, capsys):
    """A FIFO and a link to nothing at --out were each called 'a file'."""
    import os

    path = tmp_path / "p.yaml"
    path.write_text(BASE)
    os.mkfifo(tmp_path / "pipe")
    (tmp_path / "gone").symlink_to(tmp_path / "nowhere")
    for name, what in (("pipe", "a FIFO (named pipe)"), ("gone", "a symbolic link to nothing")):
        assert main(["run", str(path), "--out", str(tmp_path / name), "--quiet"]) == ExitCode.OUTPUT_REFUSED
        assert f"{tmp_path / name} is {what}, not a folder" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["gone", "p.yaml", "pipe"]


def test_numbers_that_overflow_in_the_run_name_what_overflowed(tmp_path, capsys):
    # each value within the limit, their product not: the run says which numbers, and fails cleanly
    data = merge(SMALL_PRESET, {"output": {"plot": False}, "realizations": 2, "solver": {"params": {"youngs_modulus": 1e-100}},
                                "spectrum": {"params": {"rms_height": 1e-100, "spacing": 1e-100}},
                                "loading": {"start": 1e99, "stop": 1e100}})  # fmt: skip
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump(data))
    code = main(["run", str(path), "--out", str(tmp_path / "o"), "--quiet"])
    err = capsys.readouterr()
    assert code == ExitCode.RUNTIME_FAILURE and "internal error" not in err.err
    assert "the dimensionless force f = F / (k h X) is not finite" in err.err
    assert "warning" not in err.err


@pytest.mark.long  # a process of its own, seconds end to end: pytest -m long
def test_a_full_disk_on_stdout_is_an_error_not_a_bug(tmp_path):
    with open("/dev/full", "w") as full:
        done = subprocess.run(
            [sys.executable, "-m", "frictionlab", "plugins", "--json"], stdout=full, stderr=subprocess.PIPE,
            text=True, cwd=tmp_path, env={**os.environ, "PYTHONPATH": str(ROOT)}, timeout=30,
        )  # fmt: skip
    assert done.returncode == ExitCode.RUNTIME_FAILURE
    assert done.stderr == "error: cannot write the output: No space left on device\n"


def test_numbers_with_an_exponent_are_numbers_as_in_yaml_1_2_and_quoted_ones_stay_text():
    from frictionlab.io.safe_yaml import load_yaml

    data = load_yaml("a: 1e-16\nb: 1E5\nc: -2e+3\nd: 1.5e3\ne: .5e1\nf: '1e5'\ng: 1e\nh: e5\ni: 12\nj: 1.5")
    assert data == {"a": 1e-16, "b": 1e5, "c": -2e3, "d": 1.5e3, "e": 5.0, "f": "1e5", "g": "1e", "h": "e5", "i": 12, "j": 1.5}
    assert [type(data[k]) for k in "abcdei"] == [float] * 5 + [int]


def test_numbers_are_read_as_python_reads_them_not_as_yaml_1_1_bases():
    from frictionlab.io.safe_yaml import load_yaml

    data = load_yaml("a: 010\nb: 0o10\nc: 0x1F\nd: 1_000\ne: 1:30\nf: 1:30.5\ng: 1__0\nh: 0b101\ni: -.inf\nj: 2.5_0")
    assert data == {"a": 10, "b": 8, "c": 31, "d": 1000, "e": "1:30", "f": "1:30.5", "g": "1__0", "h": "0b101",
                    "i": -math.inf, "j": 2.5}
    assert [type(data[k]) for k in "abcd"] == [int] * 4


def test_a_key_yaml_1_1_reads_as_a_boolean_or_null_is_kept_as_written_and_values_are_not():
    from frictionlab.io.safe_yaml import YamlProblem, load_yaml

    assert load_yaml("yes: 1\non: 2\nNo: 3\n~: 4\nnull: 5\nx: [yes, off, ~]\n1: 6") == {
        "yes": 1, "on": 2, "No": 3, "~": 4, "null": 5, "x": [True, False, None], 1: 6}  # fmt: skip
    with pytest.raises(YamlProblem, match="duplicate key 'yes' at lines 1 and 2"):  # was: the last kept
        load_yaml('yes: 1\n"yes": 2')


def test_a_misplaced_yes_key_is_named_as_written(tmp_path, capsys):
    preset = tmp_path / "p.yaml"
    preset.write_text(yaml.safe_dump(SMALL_PRESET, sort_keys=False) + "yes: 3\n")
    assert main(["validate", str(preset)]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "yes: is not a known field" in err and "1:" not in err  # it was "1: keys should be strings, got True"


@pytest.mark.parametrize(("value", "field"), [("1:30", "seed"), ("2:00", "realizations")])
def test_a_clock_time_in_a_whole_number_field_is_refused_naming_it(value, field, tmp_path, capsys):
    # YAML 1.1 reads 1:30 as ninety (base 60); a seed of 90 run without a word is a surprise
    path = tmp_path / "p.yaml"
    path.write_text(re.sub(rf"^{field}: .*$", f"{field}: {value}", BASE, flags=re.M))
    assert main(["validate", str(path)]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert field in err and value in err


def test_a_set_value_with_an_exponent_is_checked_as_the_number_it_is(tmp_path, capsys):
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump(SMALL_PRESET))
    assert main(["validate", str(path), "--set", "spectrum.params.rms_height=1e200"]) == ExitCode.USAGE
    assert "rms_height: must be between 1e-100 and 1e+100, got 1e+200" in capsys.readouterr().err
    assert main(["validate", str(path), "--set", "spectrum.params.rms_height=2e-3"]) == ExitCode.OK


@pytest.mark.parametrize(("assignment", "said"), [
    ("loading.start=1e-320", "loading.start: must be between 1e-100 and 1e+100, got 1e-320"),  # gt=0
    # both bounds of its own (ge=1, le=10_000_000): those, not magnitudes that 1e99 would pass
    ("realizations=1e400", "realizations: must be >= 1 and <= 10000000, got '1e400'"),
    ("realizations=1.0e200", "realizations: must be >= 1 and <= 10000000, got 1e+200"),
    ("spectrum.params.hurst=1e400", "hurst: must be >= 0.0 and <= 1.5, got '1e400'"),
    ("spectrum.params.hurst=1e-400", "hurst: must be 0 or between 1e-100 and 1e+100 in magnitude"),  # 0 is within
    ("seed=1e400", "seed: must be 0 or between 1e-100 and 1e+100 in magnitude, got '1e400'"),  # ge=0
    ("solver.params.poisson_ratio=1e-200", "poisson_ratio: must be 0 or between 1e-100 and 1e+100 in magnitude"),
])  # fmt: skip
def test_the_range_a_magnitude_refusal_names_is_the_fields_own(tmp_path, capsys, assignment, said):
    """A number past the magnitudes a preset takes was told 'must be 0 or between 1e-100 and
    1e+100' whatever its field: a start of 1e-320, so told, was then given 0 and refused as
    'must be > 0'. A field whose own bounds refuse 0 is told the range without it."""
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump(SMALL_PRESET))
    assert main(["validate", str(path), "--set", assignment]) == ExitCode.USAGE
    assert said in capsys.readouterr().err


@pytest.mark.parametrize("end", ["start", "stop"])
@pytest.mark.parametrize("path", ["seed", "spectrum.params.hurst"])
def test_a_range_end_past_a_floats_range_is_refused_not_an_internal_error(tmp_path, capsys, end, path):
    """An integer range end of 310 digits: pydantic's finite check on an int or a float ran
    math.isfinite on it, an OverflowError, exit 70."""
    ends = {"start": 1, "stop": 2, end: -(10**309) if path == "seed" else 10**309}
    preset = merge(SMALL_PRESET, {"sweep": {"parameters": {path: {**ends, "num": 2}}}})
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(preset))
    assert main(["validate", str(tmp_path / "p.yaml")]) == ExitCode.USAGE
    said = capsys.readouterr().err
    assert f"sweep.parameters.{path}.{end}: must be 0 or between 1e-100 and 1e+100 in magnitude, got " in said, said
    whole = merge(SMALL_PRESET, {"sweep": {"parameters": {"seed": {"start": 1, "stop": 10**30, "num": 2}}}})
    (tmp_path / "p.yaml").write_text(yaml.safe_dump(whole))  # a whole number of 31 digits: a seed, kept whole
    assert main(["validate", str(tmp_path / "p.yaml")]) == 0, capsys.readouterr().err


@pytest.mark.parametrize(("assignment", "said"), [
    ("spectrum.params={hurst: 0.5, hurst: 0.6}", "duplicate key 'hurst'"),
    ("sweep.parameters.seed.values=[1, 2", "a [ list opened here is not closed"),
    pytest.param("description=" + "[" * 100 + "]" * 100, "nested more than", id="deep-list"),
])  # fmt: skip
def test_a_set_mapping_or_list_yaml_cannot_read_is_refused_with_its_reason(tmp_path, capsys, assignment, said):
    """A --set value YAML could not read was taken as text: a mapping with a key twice was then
    'must be a mapping of keys to values, got '{hurst: 0.5, hurst: 0.6}'', its reason unsaid, and a
    list left open became a description. One that starts as a mapping or list is refused with why."""
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump(SMALL_PRESET))
    assert main(["validate", str(path), "--set", assignment]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "a { mapping or [ list YAML cannot read: " in err and said in err and len(err) < 1000
    assert main(["validate", str(path), "--set", 'description="[draft"']) == ExitCode.OK  # quoted: text


def test_thousands_of_problems_are_said_as_the_first_fifty_and_a_count(tmp_path, capsys):
    """A preset of 5000 unknown keys (60 kB) made 890 kB of stderr, one line each; --json keeps every one."""
    path = tmp_path / "p.yaml"
    data = {**SMALL_PRESET, **{f"k{i}": i for i in range(5000)}}
    path.write_text(yaml.safe_dump(data))
    assert main(["validate", str(path)]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "5000 problems in preset" in err and err.count(": is not a known field") == 50
    assert "(and 4950 more; frictionlab validate --json lists every one)" in err and len(err) < 20_000
    assert main(["validate", str(path), "--json"]) == ExitCode.USAGE
    assert len(json.loads(capsys.readouterr().out)["presets"][0]["problems"]) == 5000


def test_a_set_into_a_sweep_takes_the_swept_path_as_one_key(tmp_path, capsys):
    """`sweep.parameters.spectrum.params.hurst.values=...`: the swept path is one key of
    sweep.parameters; it was split at every dot and refused as unknown fields."""
    from frictionlab.preset import set_path

    data = {"sweep": {"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.9]}}}}
    set_path(data, "sweep.parameters.spectrum.params.hurst.values", [0.3, 0.6, 0.9])
    set_path(data, "sweep.parameters.spectrum.params.spacing", {"values": [1.0, 2.0]})  # a mapping: all of it
    set_path(data, ("sweep", "parameters", "spectrum.params.hurst", "spacing"), "log")  # already one key
    assert data["sweep"]["parameters"] == {
        "spectrum.params.hurst": {"values": [0.3, 0.6, 0.9], "spacing": "log"},
        "spectrum.params.spacing": {"values": [1.0, 2.0]},
    }
    path = tmp_path / "sweep.yaml"
    path.write_text(preset_text(sweep={"parameters": {"spectrum.params.hurst": {"values": [0.5, 0.9]}}}))
    assert main(["validate", str(path), "--set", "sweep.parameters.spectrum.params.hurst.values=[0.3,0.6,0.9]"]) == 0
    assert "sweep of 3 points" in capsys.readouterr().out
    assert main(["validate", str(path), "--set", "sweep.parameters.spectrum.params.hurst.values=abc"]) == ExitCode.USAGE
    assert "sweep.parameters.spectrum.params.hurst.values: must be a list, got 'abc'" in capsys.readouterr().err


def test_a_value_of_none_of_a_unions_types_is_one_problem_at_its_own_path(tmp_path, capsys):
    """A swept value may be text, a bool or a number: a list there is one problem, not one per
    type at a path ending in the type's name (values.0.str, values.0.int...)."""
    path = tmp_path / "sweep.yaml"
    path.write_text(preset_text(sweep={"parameters": {"spectrum.params.hurst": {"values": [[1, 2], 0.5]}}}))
    assert main(["validate", str(path)]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "1 problem in preset" in err
    assert ("sweep.parameters.spectrum.params.hurst.values.0: must be text, true or false, a whole number or a "
            "number, got [1, 2]") in err  # fmt: skip


def test_a_number_past_double_precision_is_named_as_written(tmp_path, capsys):
    """1e400 was read as infinity ("must be a finite number, got inf") and 1e-400 as zero (a
    start of 0 said "must be > 0", a field allowing 0 took it silently): both are numbers
    beyond the range a preset allows, and the message quotes them as the user wrote them."""
    from frictionlab.io.safe_yaml import load_yaml

    assert load_yaml("a: 1e400\nb: -1.5E-400\nc: .inf\nd: 0e-500\ne: 1e-300") == {
        "a": "1e400", "b": "-1.5E-400", "c": math.inf, "d": 0.0, "e": 1e-300}  # fmt: skip
    path = tmp_path / "p.yaml"
    path.write_text(BASE.replace("stop: 20.0", "stop: 1e400"))
    digits = "9" * 5000  # past Python's own limit on the digits of an int read from text
    assert main(["validate", str(path), "--set", "loading.start=1.5e-400", "--set", f"seed={digits}"]) == 2
    err = capsys.readouterr().err
    assert "loading.stop: must be between 1e-100 and 1e+100, got '1e400'" in err
    assert "loading.start: must be between 1e-100 and 1e+100, got '1.5e-400'" in err
    assert "seed: must be 0 or between 1e-100 and 1e+100 in magnitude, got '99999" in err and "got inf" not in err


@pytest.mark.parametrize(("text", "opened", "found"), [
    ("name: x\nseed: 1\nrealizations: [3\nspectrum:\n  name: a\n", "line 3, column 15: a [ list", "at line 4"),
    ("a: {b: 1\nc: 2\n", "line 1, column 4: a { mapping", "at line 2"),
])  # fmt: skip
def test_a_bracket_left_open_mid_file_is_named_at_the_line_it_opened(text, opened, found):
    """An outsider's check: `realizations: [3` on line 3 was reported at line 4, where the
    parser stumbled on the next key, in the parser's own words."""
    from frictionlab.io.safe_yaml import YamlProblem, load_yaml

    with pytest.raises(YamlProblem) as refused:
        load_yaml(text)
    message = str(refused.value)
    assert message.startswith(f"not valid YAML at {opened} opened here is not closed (") and found in message


def test_a_whole_number_past_double_precision_in_a_plugins_field_is_named_not_an_internal_error(tmp_path, capsys):
    """A plugin's own check computed with it (points * spacing): 10**400 points raised OverflowError,
    which ended `frictionlab validate` in the catch-all internal error (exit code 70) and left
    frictionlab.validate with a Python exception; the number check had already named it."""
    import frictionlab
    from frictionlab.errors import PresetError

    huge, field = 10**400, "spectrum.params.points"
    data = yaml.safe_load(BASE)
    path = tmp_path / "p.yaml"
    path.write_text(yaml.safe_dump(data))
    assert main(["validate", str(path), "--set", f"{field}={huge}"]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert f"{field}: must be >= 8 and <= 1e+100, got 1000" in err  # was 'between 1e-100 and 1e+100': 2 is not
    assert "internal error" not in err
    slot, params, name = field.split(".")
    data = merge(data, {slot: {params: {name: huge}}})
    with pytest.raises(PresetError, match=rf"{field}: must be >= 8 and <= 1e\+100, got"):
        frictionlab.validate(data)


@pytest.mark.parametrize(("assignment", "said"), [
    ("realizations=1e30", "realizations: must be <= 10000000, got 1e+30"),
    ("fit.bootstrap=2e19", "fit.bootstrap: must be <= 100000, got 2e+19"),
    ("sweep.parameters.seed={start: 1, stop: 5, num: 1e19}", "sweep.parameters.seed.num: must be <= 100000, got 1e+19"),
    ("seed=1e19", "seed: must be a whole number, written in digits (one this large, written with an exponent, "
                  "is a float), got 1e+19"),
    ("spectrum.params.points=1e20", "spectrum.params.points: must be a whole number, written in digits"),
])  # fmt: skip
def test_a_whole_number_field_given_a_float_past_2_to_the_63_is_told_its_bound(tmp_path, capsys, assignment, said):
    """A whole float too large for pydantic to make an integer of (1e19 and up) was 'unable to
    parse input string as an integer, exceeded maximum size': a number called text, and no word
    of what the field takes. The field's upper bound is said where it has one (a sweep's num
    too), and where it has none, to write the number in digits."""
    path = tmp_path / "p.yaml"
    path.write_text(BASE)
    assert main(["validate", str(path), "--set", assignment]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert said in err and "input string" not in err


def test_a_sweep_range_past_double_precision_is_named_without_numpy_warnings(tmp_path, capsys):
    """A range from -1e308 to 1e308 (stop - start overflows) printed numpy's 'warning: overflow
    encountered in subtract' and 'invalid value encountered in multiply' before the problems,
    as the points were made to look for repeats; the two ends are refused by name, quietly."""
    import warnings

    path = tmp_path / "p.yaml"
    path.write_text(preset_text(sweep={"parameters": {"loading.stop": {"start": -1e308, "stop": 1e308, "num": 3}}}))
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # a warning is a failure here, as it is a line on the user's screen
        assert main(["validate", str(path)]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "warning" not in err
    assert "sweep.parameters.loading.stop.start: must be 0 or between 1e-100 and 1e+100 in magnitude, got -1e+308" in err
    assert "sweep.parameters.loading.stop.stop: must be 0 or between 1e-100 and 1e+100 in magnitude, got 1e+308" in err


@pytest.mark.parametrize(("path", "value"), [("seed", 10**4000), ("name", "a" * 3000)])
def test_a_sweep_point_refused_names_its_long_value_cut_short(tmp_path, capsys, path, value):
    """A refused sweep point's label quoted its swept value whole: a seed of 4000 digits (or a
    name of 3000 letters) made a problem line of over 4000 characters, though the value after
    'got' was cut short. The label cuts it too; the point's number and path stay."""
    path_file = tmp_path / "p.yaml"
    path_file.write_text(preset_text(sweep={"parameters": {path: {"values": [value, 1 if path == "seed" else "b"]}}}))
    assert main(["validate", str(path_file)]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert f"sweep point 1 ({path}=" in err
    assert max(map(len, err.splitlines())) < 500

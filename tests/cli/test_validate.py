"""The headless CLI as a user meets it: real files, real subprocesses, exit codes."""

import json

import pytest

from frictionlab.cli import main
from frictionlab.errors import ExitCode

from ..conftest import SMALL_PRESET, merge
from .conftest import write_preset


def test_validate_reports_every_problem_at_once(tmp_path, capsys):
    bad = merge(SMALL_PRESET, {"realizations": -3, "spectrum": {"params": {"hurst": -1}}, "solver": {"name": "nope"}})
    assert main(["validate", str(write_preset(tmp_path, bad))]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "3 problems in preset" in err
    for fragment in ("realizations: must be >= 1", "spectrum.params.hurst: must be >= 0", "solver.name: no solver"):
        assert fragment in err


def test_bad_set_override_is_a_usage_error(tmp_path, capsys):
    preset = write_preset(tmp_path, SMALL_PRESET)
    assert main(["validate", str(preset), "--set", "spectrum.params.hurst"]) == ExitCode.USAGE
    assert "must look like dotted.path=value" in capsys.readouterr().err
    assert main(["validate", str(preset), "--set", "seed.x=1"]) == ExitCode.USAGE
    assert "seed is a value, not a mapping" in capsys.readouterr().err


@pytest.mark.parametrize("assignments, said", [
    (["sweep.parameters.seed.values=[1, 2]", "sweep.parameters.seed.values.0=5"],
     "sweep.parameters.seed.values is a list, not a mapping: set the whole list (sweep.parameters.seed.values=[...])"),
    (["loading.stop=[1, 2]", "loading.stop.0=5"], "loading.stop is a list, not a mapping: set the whole list"),
])  # fmt: skip
def test_set_into_an_item_of_a_list_says_to_set_the_whole_list(tmp_path, capsys, assignments, said):
    """values.0 was taken as part of the swept path ('sweep.parameters.seed.values.0: must be a
    mapping ..., got 5'), and a list elsewhere was 'a value'; an item of a list is not a key."""
    preset = write_preset(tmp_path, SMALL_PRESET)
    assert main(["validate", str(preset), *[arg for a in assignments for arg in ("--set", a)]]) == ExitCode.USAGE
    assert said in capsys.readouterr().err


@pytest.mark.parametrize("count, said", [(1, "(1 realization, "), (2, "(2 realizations, ")])
def test_validate_counts_realizations_in_good_english(tmp_path, capsys, count, said):
    preset = write_preset(tmp_path, merge(SMALL_PRESET, {"realizations": count}))
    assert main(["validate", str(preset)]) == ExitCode.OK
    assert said in capsys.readouterr().out


@pytest.mark.parametrize(
    "spectrum, solver, pressed",
    [
        ({"name": "power-law", "params": {"points": 256}}, "mdr", "power-law lines"),
        ({"name": "power-law-2d", "params": {"points": 32}}, "mdr", "MDR-equivalent lines of power-law-2d surfaces"),
        ({"name": "power-law-2d", "params": {"points": 32}}, "bem-halfspace", "power-law-2d surfaces"),
    ],
)
def test_validate_says_what_is_pressed_by_the_name_the_preset_gives(tmp_path, capsys, spectrum, solver, pressed):
    preset = write_preset(tmp_path, merge(SMALL_PRESET, {"spectrum": spectrum, "solver": {"name": solver, "params": {}}}))
    assert main(["validate", str(preset)]) == ExitCode.OK
    assert f"realizations, {pressed} / {solver} / " in capsys.readouterr().out
    assert main(["validate", str(preset), "--json"]) == ExitCode.OK
    record = json.loads(capsys.readouterr().out)["presets"][0]
    assert record["spectrum"] == spectrum["name"] and record["pressed"] == pressed


def test_control_characters_typed_in_a_set_are_shown_escaped_never_sent_to_the_terminal(tmp_path, capsys):
    preset = write_preset(tmp_path, SMALL_PRESET)
    for command in ("validate", "run"):
        assert main([command, str(preset), "--set", "seed=\x1b[31m1\x07"]) == ExitCode.USAGE
        err = capsys.readouterr().err
        assert "\x1b" not in err and "\x07" not in err
        assert "--set seed=\\x1b[31m1\\x07" in err


def test_a_measured_profile_is_read_and_checked_by_validate_not_first_by_a_worker(tmp_path, capsys):
    (tmp_path / "scan.csv").write_text("\n".join(["0.1", "nan", *[str(0.01 * i) for i in range(30)]]))
    data = {**SMALL_PRESET, "spectrum": {"name": "profile-file", "params": {"path": "scan.csv", "spacing": 1.0}}}
    preset = write_preset(tmp_path, data)
    assert main(["validate", str(preset)]) == ExitCode.USAGE
    err = capsys.readouterr().err
    assert "spectrum.params: profile-file" in err and "1 value(s) in heights not finite" in err and "line 2, column 1 of the file" in err
    (tmp_path / "scan.csv").write_text("\n".join(str(0.01 * (i % 7)) for i in range(64)))
    assert main(["validate", str(preset)]) == ExitCode.OK


def test_a_refusal_that_is_not_a_preset_problem_names_its_preset(tmp_path, capsys, monkeypatch):
    """Of `validate a.yaml b.yaml`, a preset too large for this machine's memory was said as
    'this run would need about 1043 GiB ...', which of the files not named."""
    import frictionlab.runs.runner
    from frictionlab.errors import FrictionlabError

    def too_large(scene):
        raise FrictionlabError("this run would need about 1043.24 GiB at its peak")

    monkeypatch.setattr(frictionlab.runs.runner, "check_one_realization", too_large)
    first, second = write_preset(tmp_path, SMALL_PRESET, "a.yaml"), write_preset(tmp_path, SMALL_PRESET, "b.yaml")
    assert main(["validate", str(first), str(second)]) != ExitCode.OK
    err = capsys.readouterr().err
    assert f"{first}: this run would need about 1043.24 GiB" in err and f"{second}: this run would need" in err


def _builtin_text(name: str) -> str:
    from frictionlab.preset.builtin import find_builtin

    return find_builtin(name).path.read_text(encoding="utf-8")


@pytest.mark.parametrize("where", ["project", "user"])
def test_a_builtin_name_beside_a_preset_of_that_name_says_which_is_used(tmp_path, monkeypatch, capsys, where):
    """`tui quickstart` opens ./presets/quickstart.yaml (or the user folder's) where there is one;
    `validate quickstart` and `run quickstart` read the built-in, and now say so, naming the other."""
    folder = tmp_path / ("presets" if where == "project" else "mine")
    folder.mkdir()
    (folder / "quickstart.yaml").write_text(_builtin_text("quickstart").replace("realizations: 50", "realizations: 7"))
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("FRICTIONLAB_PRESETS_DIR", str(tmp_path / "mine"))
    assert main(["validate", "quickstart"]) == ExitCode.OK
    out, err = capsys.readouterr()
    assert "(50 realizations" in out  # the built-in, as before
    shown_path = "presets/quickstart.yaml" if where == "project" else str(folder / "quickstart.yaml")
    assert f"note: 'quickstart' is the built-in preset; {shown_path} is another of that name" in err
    assert f"frictionlab run {shown_path}" in err


def test_no_note_for_a_path_or_a_same_named_copy_of_the_builtin(tmp_path, monkeypatch, capsys):
    (tmp_path / "presets").mkdir()
    (tmp_path / "presets" / "quickstart.yaml").write_text(_builtin_text("quickstart"))  # a plain copy: nothing differs
    monkeypatch.chdir(tmp_path)
    monkeypatch.setenv("FRICTIONLAB_PRESETS_DIR", str(tmp_path / "mine"))
    assert main(["validate", "quickstart", "presets/quickstart.yaml"]) == ExitCode.OK
    assert "note:" not in capsys.readouterr().err

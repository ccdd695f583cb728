"""Saving presets: comments, key order and spelling kept (``folders.save_preset``)."""


import os

import yaml

from frictionlab.io.safe_yaml import load_yaml
from frictionlab.tui.folders import save_preset

from ..conftest import PRESETS

COMMENTED = """\
# why this preset
name: commented  # the name
description: >
  folded text
  over two lines
spectrum:
  name: power-law
  params:
    hurst: 0.8    # H
    points: 1024
solver:
  name: mdr
  params:
    # the modulus first
    youngs_modulus: 1.0  # E
    poisson_ratio: 0.0  # nu: zero, so E* = E
# the slope estimator below
slope:
  name: forward-difference
loading:
  stop: 2.0e+1
  values:
    - 1  # one
fit: {bootstrap: 50}
"""


def comment_lines(text):
    return [line.split("#", 1)[1].strip() for line in text.splitlines() if "#" in line]


def test_save_keeps_comments_order_and_spelling_with_nested_removed_and_added_keys(tmp_path):
    path, source = tmp_path / "saved.yaml", tmp_path / "source.yaml"
    source.write_text(COMMENTED)
    data = yaml.safe_load(COMMENTED)
    data["spectrum"]["params"]["hurst"] = 0.6  # a nested change
    data["solver"] = {"name": "winkler", "params": {"modulus": 1e-05}}  # two keys removed, one added
    data["fit"]["confidence"] = 0.9
    data["seed"] = 3  # a new top-level key: last, as in the edited data
    save_preset(path, data, template=source)
    text = path.read_text()
    assert yaml.safe_load(text) == data  # PyYAML (what frictionlab loads with) reads the new values
    assert comment_lines(text) == comment_lines(COMMENTED)  # every comment, in order
    lines = text.splitlines()
    # untouched lines are byte for byte the same, in the same order ("2.0e+1" is not rewritten as 20.0)
    kept = [line for line in COMMENTED.splitlines() if line in lines]
    assert kept == [line for line in lines if line in COMMENTED.splitlines()]
    for line in ("name: commented  # the name", "description: >", "  folded text", "  stop: 2.0e+1", "    - 1  # one"):
        assert line in lines
    assert "    hurst: 0.6    # H" in lines and "    modulus: 1.0e-05" in lines
    # the comment above `slope` stays above it; the removed keys' own comments stay in the solver section
    assert lines[lines.index("slope:") - 1] == "# the slope estimator below"
    assert lines.index("    modulus: 1.0e-05") < lines.index("    # E") < lines.index("slope:")
    assert "youngs_modulus" not in text and "poisson_ratio" not in text
    assert list(yaml.safe_load(text)) == ["name", "description", "spectrum", "solver", "slope", "loading", "fit", "seed"]


def test_save_without_changes_rewrites_every_shipped_preset_byte_for_byte(tmp_path):
    for preset in sorted(PRESETS.glob("*.yaml")):
        original = preset.read_text()
        save_preset(tmp_path / preset.name, yaml.safe_load(original), template=preset)
        assert (tmp_path / preset.name).read_text() == original, preset.name


def test_new_text_values_are_spelled_so_presets_read_them_back(tmp_path):
    # read back as a preset is read (load_yaml), not as PyYAML's YAML 1.1 reads: "1e4" is text
    # to the one and a number to the other
    source = tmp_path / "source.yaml"
    source.write_text("name: x  # n\nseed: 1\n")
    data = {"name": "yes", "seed": 1, "description": "1e4",
            "notes": {"on": "0o17", "nan": float("inf"), "ten": "010", "small": "1e-6", "clock": "1:30"}}
    save_preset(tmp_path / "out.yaml", data, template=source)
    text = (tmp_path / "out.yaml").read_text()
    assert load_yaml(text) == data and "# n" in text


def test_text_a_folded_or_quoted_value_cannot_hold_raw_is_written_escaped(tmp_path):
    """ruamel.yaml keeps a key's folded (``>-``) or quoted style for its new value: one holding a
    control character was written raw, a file no reader takes (``#x0001 is not allowed``), and a
    BEL, ruamel's own fold mark, broke the line and lost the character after it."""
    source = tmp_path / "source.yaml"
    source.write_text("name: x  # n\ndescription: >-\n  Folded\n  text.\nnotes: 'quoted'\n")
    data = {"name": "x", "description": "a\x07bc\x01d\re\x1bf", "notes": "q\x9bz\x85"}
    save_preset(tmp_path / "out.yaml", data, template=source)
    text = (tmp_path / "out.yaml").read_text()
    assert load_yaml(text) == data and "# n" in text


def test_the_built_in_presets_are_listed_after_the_users_and_copies_go_to_the_user(tmp_path, monkeypatch):
    from frictionlab.preset.builtin import builtin_folder
    from frictionlab.preset.builtin import preset_folders
    from frictionlab.tui.folders import writable_folder

    monkeypatch.chdir(tmp_path)  # no ./presets
    env = {"FRICTIONLAB_PRESETS_DIR": str(tmp_path / "mine")}
    folders = preset_folders(env=env)
    assert folders == [("user", tmp_path / "mine"), ("built-in", builtin_folder())]
    assert writable_folder(folders) == tmp_path / "mine"
    (tmp_path / "presets").mkdir()  # a project folder is listed first
    assert [label for label, _ in preset_folders(env=env)] == ["project", "user", "built-in"]


def test_a_file_that_is_no_mapping_is_listed_as_unreadable_and_offered_as_no_template(tmp_path):
    """A YAML list, a bare value or an empty file was listed as a preset '(no description)' and
    offered as New's template; opening it, or New from it, was refused."""
    from frictionlab.tui.folders import list_presets, templates

    (tmp_path / "list.yaml").write_text("- 1\n- 2\n")
    (tmp_path / "empty.yaml").write_text("")
    (tmp_path / "fine.yaml").write_text((PRESETS / "quickstart.yaml").read_text())
    entries = {entry.path.name: entry for entry in list_presets([("project", tmp_path)])}
    offered = {path.name for _, path in templates(list(entries.values())) if path.parent == tmp_path}
    assert entries["list.yaml"].error.startswith("cannot be read: a preset must be a mapping")
    assert entries["empty.yaml"].error.startswith("cannot be read: a preset must be a mapping")
    assert not entries["fine.yaml"].error and offered == {"fine.yaml"}


def test_a_preset_saved_again_keeps_its_files_permissions(tmp_path):
    """A preset kept private (0600) or shared with a group (0640) was made 0644 (0666 less the umask) by a save."""
    for mode in (0o600, 0o640):
        path = tmp_path / f"p{mode:o}.yaml"
        path.write_text(COMMENTED)
        path.chmod(mode)
        save_preset(path, {**yaml.safe_load(COMMENTED), "seed": 3}, template=path)
        assert (path.stat().st_mode & 0o777, yaml.safe_load(path.read_text())["seed"]) == (mode, 3)
    save_preset(tmp_path / "new.yaml", {"name": "new"})  # a new file: the usual permissions
    umask = os.umask(0)
    os.umask(umask)
    assert (tmp_path / "new.yaml").stat().st_mode & 0o777 == 0o666 & ~umask


NO_USER = "~frictionlab-no-such-user"


def test_a_home_folder_of_no_user_is_said_not_raised(monkeypatch, capsys):
    """~user of a user this system does not know: pathlib raised RuntimeError, and the TUI
    ended in a traceback (its locals, the whole environment, on the screen) at start, from
    FRICTIONLAB_PRESETS_DIR, or when such a path was typed in the save dialog; a preset's
    input path was taken as a folder named so beside the preset ('no such file')."""
    import pytest
    from pydantic import ValidationError

    from frictionlab.cli import main
    from frictionlab.errors import FrictionlabError
    from frictionlab.preset.builtin import user_presets_dir
    from frictionlab.tui.screens.dialogs import preset_path_problem
    from frictionlab_spectra import ProfileFile

    assert preset_path_problem(f"{NO_USER}/mine") == (None, f"path: {NO_USER} names no user of this system with a "
                                                              "home folder; give the path in full")  # fmt: skip
    for key in ("FRICTIONLAB_PRESETS_DIR", "XDG_CONFIG_HOME"):
        with pytest.raises(FrictionlabError, match=f"{key}='{NO_USER}/p': {NO_USER} names no user"):
            user_presets_dir(env={key: f"{NO_USER}/p"})
    monkeypatch.setenv("FRICTIONLAB_PRESETS_DIR", f"{NO_USER}/p")
    assert main(["tui"]) == 2
    err = capsys.readouterr().err
    assert f"FRICTIONLAB_PRESETS_DIR='{NO_USER}/p'" in err and "Traceback" not in err
    with pytest.raises(ValidationError, match=f"{NO_USER} names no user"):
        ProfileFile(path=f"{NO_USER}/scan.npy", spacing=1.0)
    assert user_presets_dir(env={"FRICTIONLAB_PRESETS_DIR": "~/p"}) == __import__("pathlib").Path.home() / "p"

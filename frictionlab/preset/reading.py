"""Reading a preset file safely, and taking its relative input-file paths from its folder."""

from __future__ import annotations

import copy
import os
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import FrictionlabError, PresetError, PresetFileError, short_repr
from ..io.inputs import InputFileProblem, input_fields, is_relative, read_regular_file
from ..io.safe_yaml import YamlLimit, YamlProblem, load_yaml
from .paths import apply_overrides

NOT_A_MAPPING = "a preset must be a mapping of keys to values (name: ..., spectrum: ...)"


def not_a_mapping(data, empty: str) -> str:
    """Why YAML that read as ``data`` (no dict) is no preset; ``empty`` says what None came from."""
    return f"{NOT_A_MAPPING}, got {empty if data is None else short_repr(data, 80)}"


if TYPE_CHECKING:
    from ..plugin.registry import Registry

MAX_PRESET_BYTES = 256 * 1024  # presets are a few kB; refused by size before anything is read


def load_preset_file(path: str | Path, *, follow_links: bool = True) -> dict:
    """Read a preset file: a regular file of at most MAX_PRESET_BYTES of UTF-8
    YAML within the limits of ``safe_yaml``. A file that cannot be used is a
    PresetFileError, bad YAML a PresetError; neither quotes the file.
    ``follow_links=False`` (a run folder's copy): a symbolic link is refused."""
    path = Path(path)
    try:
        raw = read_regular_file(path, limit=MAX_PRESET_BYTES, what="preset file", follow_links=follow_links)
    except InputFileProblem as exc:
        raise PresetFileError([f"(file): {exc}"], source=str(path)) from None
    try:
        text = raw.decode("utf-8").removeprefix("\ufeff")
    except UnicodeDecodeError as exc:
        line = raw.count(b"\n", 0, exc.start) + 1
        raise PresetFileError(
            [f"(file): not UTF-8 text (byte {exc.start + 1}, line {line}); save the preset as UTF-8"], source=str(path)
        ) from None
    try:
        data = load_yaml(text)
    except YamlLimit as exc:
        raise PresetFileError([f"(file): {exc}"], source=str(path)) from None
    except YamlProblem as exc:
        raise PresetError([f"(file): {exc}"], source=str(path)) from None
    if not isinstance(data, dict):
        raise PresetError([f"(file): {not_a_mapping(data, 'an empty file (or comments only)')}"], source=str(path))
    return data


def resolve_input_paths(data: dict, base_dir: str | Path, registry: Registry | None = None) -> dict:
    """A copy of preset ``data`` whose relative input-file paths (plugin
    parameters declared ``InputFile``, and swept values of one) are taken from
    ``base_dir``, the folder of the preset file they were written in."""
    from ..plugin import KINDS  # the plugins load only when a preset names its input files
    from ..plugin.registry import default_registry

    registry = registry or default_registry()
    data = copy.deepcopy(data)
    base = Path(os.path.abspath(base_dir))
    sweep = data.get("sweep") if isinstance(data.get("sweep"), dict) else {}
    swept = sweep.get("parameters") if isinstance(sweep.get("parameters"), dict) else {}
    for slot in KINDS:
        choice = data.get(slot) if isinstance(data.get(slot), dict) else {}
        names = [choice.get("name")]
        if isinstance(swept.get(f"{slot}.name"), dict):
            names += list(swept[f"{slot}.name"].get("values") or [])
        fields: set[str] = set()
        for name in names:
            try:
                fields.update(input_fields(registry.get(slot, name).Params))
            except (FrictionlabError, TypeError, AttributeError):  # reported when the preset is validated
                continue
        for field in fields:
            params = choice.get("params")
            if isinstance(params, dict) and is_relative(params.get(field)):
                params[field] = str(base / params[field])
            axis = swept.get(f"{slot}.params.{field}")
            if isinstance(axis, dict) and isinstance(axis.get("values"), list):
                axis["values"] = [str(base / v) if is_relative(v) else v for v in axis["values"]]
    return data


def read_preset(path: str | Path, overrides: list[str] = (), registry: Registry | None = None) -> dict:
    """Preset data from a file, its relative input paths taken from the file's
    folder, then ``--set`` overrides applied (a relative path given there is
    taken from the current folder, as in any command line)."""
    data = resolve_input_paths(load_preset_file(path), Path(path).parent, registry)
    return apply_overrides(data, overrides)  # a list or tuple: a string or mapping is refused there

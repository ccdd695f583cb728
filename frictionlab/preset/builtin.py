"""The presets that ship with frictionlab (the repository's ``presets/`` folder).

An installed package carries them as ``frictionlab/builtin_presets/`` (setup.py maps
the folder there); a source checkout or an editable install reads ``presets/`` beside
the package. Either way each is a real file, so a front end can open, show or copy it.
A preset argument that is not a path to a file but a built-in's name
(``frictionlab run quickstart``) means that file (``resolve_preset_path``).
"""

from __future__ import annotations

import os
import re
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path

from ..errors import FrictionlabError, PresetFileError, command_word, did_you_mean, short_repr, shown_name

_LONGEST = 100  # characters of a one-line description
_PACKAGE = Path(__file__).resolve().parent.parent


@dataclass(frozen=True)
class BuiltinPreset:
    """A preset shipped with frictionlab: its ``name`` (the file's stem, what
    ``frictionlab run NAME`` takes), its file, and a one-line ``description``."""

    name: str
    path: Path

    @cached_property
    def full_description(self) -> str:  # read when asked: finding one preset by name reads no file
        return _whole_description(self.path)

    @property
    def description(self) -> str:
        return _one_line(self.full_description)


def builtin_folder() -> Path | None:
    """The folder holding the built-in presets, or None if this install has none."""
    for folder in (_PACKAGE / "builtin_presets", _PACKAGE.parent / "presets"):
        if folder.is_dir() and any(folder.glob("*.yaml")):
            return folder
    return None


PROJECT_PRESETS_DIR = Path("presets")


def user_presets_dir(env=None) -> Path:
    """The user's own presets folder (the TUI lists it): ``$FRICTIONLAB_PRESETS_DIR``, else
    ``$XDG_CONFIG_HOME/frictionlab/presets``, else the platform's config folder. A FrictionlabError
    names the variable for a ``~user`` this system does not know."""
    from ..io.inputs import expand_user

    env = os.environ if env is None else env
    for key, below in (("FRICTIONLAB_PRESETS_DIR", ()), ("XDG_CONFIG_HOME", ("frictionlab", "presets"))):
        if env.get(key):
            try:
                return Path(expand_user(env[key]), *below)
            except ValueError as exc:
                raise FrictionlabError(f"{key}={env[key]!r}: {exc}") from None
    from platformdirs import user_config_path  # ~/.config on Linux, the platform's own folder elsewhere

    return user_config_path("frictionlab") / "presets"


BUILTIN = "built-in"  # the label of the presets shipped with frictionlab: read, copied, never written


def preset_folders(presets_dir: Path | None = None, env=None) -> list[tuple[str, Path]]:
    """(label, folder) pairs to browse: the given folder, or ./presets, the user
    folder and the built-in presets (unless ./presets is that folder: a checkout)."""
    if presets_dir is not None:
        return [("presets", Path(presets_dir))]
    folders = [("project", PROJECT_PRESETS_DIR)] if PROJECT_PRESETS_DIR.is_dir() else []
    folders.append(("user", user_presets_dir(env)))
    from ..io.files import real_path

    shipped = builtin_folder()
    if shipped is not None and not any(real_path(folder) == real_path(shipped) for _, folder in folders):
        folders.append((BUILTIN, shipped))
    return folders


def listed_preset_folders(presets_dir: str | Path | None = None) -> list[Path]:
    """The folders of presets the TUI's Presets list shows, in its order, less the built-ins':
    where ``frictionlab tui NAME`` looks for NAME first (``cli.tui.find_preset``)."""
    return [folder for label, folder in preset_folders(Path(presets_dir) if presets_dir else None) if label != BUILTIN]


def same_named_presets(argument: str | Path, resolved: Path) -> list[Path]:
    """Where ``argument`` is a built-in's name (``resolved`` its file), the files of that name in
    the folders ``frictionlab tui`` lists first (./presets, the user folder) that are not the
    built-in: ``tui NAME`` opens the first of them, ``run NAME`` the built-in. Unreadable
    folders and files are passed over (this only informs)."""
    argument, builtin = str(argument), find_builtin(str(argument))
    if len(Path(argument).parts) != 1 or builtin is None or Path(resolved) != builtin.path:
        return []
    try:
        folders, own = listed_preset_folders(), builtin.path.read_bytes()
    except (FrictionlabError, OSError):
        return []
    from ..io.files import real_path

    found = []
    for path in (folder / f"{builtin.name}{suffix}" for folder in folders for suffix in (".yaml", ".yml")):
        try:
            # read only a file the built-in's size: another size differs, however large it is
            if path.is_file() and real_path(path) != real_path(builtin.path) and (
                    path.stat().st_size != len(own) or path.read_bytes() != own):
                found.append(path)
        except OSError:
            pass
    return found


def same_name_note(argument: str | Path, resolved: Path) -> str | None:
    """What ``run NAME`` and ``validate NAME`` say where NAME is a built-in's and a listed folder
    holds another preset of that name (``same_named_presets``), or None."""
    others = same_named_presets(argument, resolved)
    if not others:
        return None
    return (f"note: {str(argument)!r} is the built-in preset; {shown_name(others[0])} is another of that name (the one "
            f"`frictionlab tui {argument}` opens); to use it, give its path: frictionlab run {command_word(others[0])}")


def preset_folder(presets_dir: str | Path | None, names: list[str], what: str) -> Path:
    """``presets_dir`` (else ./presets, else the built-in presets' folder) if it holds every file of
    ``names``; else FrictionlabError naming the folders looked in and, in ``presets_dir``, why each
    that is not a regular file is not (a FIFO, say). ``what`` says which presets they are."""
    from ..errors import FrictionlabError
    from ..io.inputs import regular_file_problem

    candidates = [Path(presets_dir)] if presets_dir else [Path("presets"), *filter(None, [builtin_folder()])]
    for folder in candidates:
        if all((folder / name).is_file() for name in names):
            return folder
    given = Path(presets_dir) if presets_dir and Path(presets_dir).is_dir() else None
    problems = {name: regular_file_problem(given / name) for name in names} if given else {}
    which = "; ".join(f"{name}: {problem}" for name, problem in problems.items() if problem)
    which = f" (in {shown_name(given)}, {which})" if which else ""
    raise FrictionlabError(f"--presets: no folder with {what}; looked in {', '.join(map(shown_name, candidates))}{which}")


def builtin_presets() -> list[BuiltinPreset]:
    """Every built-in preset, by name; the description is the first line of the
    preset's own ``description`` (or of its leading comment if it has none)."""
    folder = builtin_folder()
    if folder is None:
        return []
    return [BuiltinPreset(p.stem, p) for p in sorted(folder.glob("*.yaml"))]


def find_builtin(name: str) -> BuiltinPreset | None:
    """The built-in preset called ``name`` (``quickstart`` or ``quickstart.yaml``), or None."""
    stem = name.removesuffix(".yaml")
    return next((p for p in builtin_presets() if p.name == stem), None)


def resolve_preset_path(argument: str | Path) -> Path:
    """The preset file a command-line argument means: an existing path as given,
    else the built-in of that name. Neither is a PresetFileError naming the closest
    built-in names (a path that merely does not exist is reported by the reader)."""
    if not str(argument).strip():  # Path("") is the current folder
        raise PresetFileError(["(file): the preset is named by an empty string: give a preset file or a built-in's name"],
                              source=repr(str(argument)))  # fmt: skip
    path = Path(argument)
    if not path.exists() and re.match(r"[A-Za-z][A-Za-z0-9+.-]*://", str(argument)):  # Path() would show it as http:/host
        raise PresetFileError([f"(file): {shown_name(argument)} is an address; a preset is read from a file here, never "
                               "fetched: download it (curl -O ADDRESS), then give the file"], source=str(argument))  # fmt: skip
    if not path.exists() and path.suffix in (".yaml", ".yml") and find_builtin(path.stem):  # presets/quickstart.yaml
        raise PresetFileError(  # outside the clone: the file is not there, but the package has it
            [f"(file): no file {str(argument)!r} here; the built-in preset of that name is {path.stem!r} "
             f"(give the name alone: frictionlab run {path.stem})"],
            source=str(argument),
        )  # fmt: skip
    named = len(path.parts) == 1 and not path.suffix
    # a folder is never a preset: the run folder of `frictionlab run quickstart --out quickstart`, say
    if named and path.is_dir() and (shadowed := find_builtin(str(argument))) is not None:
        return shadowed.path
    if path.is_dir() and (path / "preset.yaml").is_file():  # a run folder given for its preset
        raise PresetFileError(
            [f"(file): a folder, not a preset; it holds a run, whose preset is {shown_name(path / 'preset.yaml')} (frictionlab "
             f"resume {command_word(path)} continues the run; frictionlab run {command_word(path / 'preset.yaml')} --out NEW runs it again)"],
            source=str(argument),
        )  # fmt: skip
    if path.is_dir() and (path / "sweep.json").is_file():
        raise PresetFileError([f"(file): a folder, not a preset; it holds a sweep (frictionlab resume {command_word(path)} continues "
                               f"it), each point's preset in {shown_name(path / 'points')}/<NN-label>/preset.yaml"],
                              source=str(argument))  # fmt: skip
    # a run's record given for its preset: its fields were listed as 37 problems of a preset
    if path.name in ("summary.json", "run.json") and (path.parent / "preset.yaml").is_file():
        raise PresetFileError(
            [f"(file): the {path.name} of a run, not a preset; the run's preset is {shown_name(path.parent / 'preset.yaml')} "
             f"(frictionlab run {command_word(path.parent / 'preset.yaml')} --out NEW runs it again)"],
            source=str(argument),
        )  # fmt: skip
    if path.exists() or not named:
        return path  # a path: read (and, if missing, reported) as one
    found = find_builtin(str(argument))
    if found is not None:
        return found.path
    names = [p.name for p in builtin_presets()]
    raise PresetFileError(
        [
            f"(file): no file {str(argument)!r} and no built-in preset of that name{did_you_mean(str(argument), names) or '.'} "
            f"Built-ins: {', '.join(names) or '(none installed)'} (`frictionlab presets` lists them)"
        ],
        source=str(argument),
    )


def _whole_description(path: Path) -> str:
    """The preset's description (or its leading comment), on one line; read without
    validating (a listing must not fail on one odd file)."""
    from ..io.safe_yaml import YamlProblem, load_yaml

    text = path.read_text(encoding="utf-8")
    try:
        data = load_yaml(text)
    except YamlProblem:
        data = None
    description = data.get("description") if isinstance(data, dict) else None
    if not isinstance(description, str) or not description.strip():
        comments = [ln.lstrip("# ").strip() for ln in text.splitlines() if ln.startswith("#")]
        description = comments[0] if comments else ""
    return " ".join(description.split())


def _one_line(description: str) -> str:
    """``description`` cut at its first sentence, and at a comma to fit a listing's line."""
    line = re.split(r"(?<!Fig)\.\s+(?=[A-Z])|;\s", description, maxsplit=1)[0].rstrip(".")
    if len(line) > _LONGEST:  # cut at a comma, so that a listing keeps one line per preset
        line = line[: line.rfind(", ", 0, _LONGEST)] + " ..."
    return line


def locate_preset(argument: str | Path) -> tuple[Path, str]:
    """The preset file ``argument`` means (``resolve_preset_path``) and how a message names
    it: as given, a built-in by its name (``preset_source``)."""
    path = resolve_preset_path(argument)
    return path, preset_source(argument) if path != Path(argument) else str(argument)


def preset_source(argument: str | Path, overrides=()) -> str:
    """How a message names a preset: as the user gave it (a path, or a built-in's name,
    never the installed file they did not touch), with the ``--set`` overrides they
    typed, since a problem may come from one of those."""
    where = str(argument) if Path(argument).suffix or len(Path(argument).parts) > 1 else f"built-in preset {str(argument)!r}"
    overrides = list(overrides)
    shown = "".join(f" --set {short_repr(str(item), 80)[1:-1]}" for item in overrides[:SHOWN_OVERRIDES])
    more = len(overrides) - SHOWN_OVERRIDES
    return where + shown + (f" (and {more} more --set)" if more > 0 else "")


SHOWN_OVERRIDES = 5  # a message names this many --set: 20,000 of them made megabytes of every error

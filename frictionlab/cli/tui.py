"""``frictionlab tui``: start the terminal UI. The one place the CLI reaches the TUI,
lazily: headless commands never import Textual."""

from __future__ import annotations

import os
from pathlib import Path

from ..errors import ExitCode, FrictionlabError, PresetFileError, did_you_mean, shown_name
from .options import add_workers_option, run_options


def add_parser(sub) -> None:
    p = sub.add_parser(
        "tui",
        help="terminal UI: edit presets, run with live progress, compare results",
        description="The terminal UI: browse and edit presets, run them with live progress, compare results.",
        epilog="examples:\n  frictionlab tui\n  frictionlab tui quickstart",
    )
    p.add_argument("preset", nargs="?", help="preset YAML file, or a preset's name (looked for in the folders the Presets list shows, "
                   "--presets DIR or ./presets and the user folder, then among the built-ins), to open (optional)")
    p.add_argument("--presets", metavar="DIR", help="presets folder to browse (default: ./presets and the user folder)")
    p.add_argument("--runs", metavar="DIR", help="where runs are written and listed (default: runs)")
    add_workers_option(p)
    p.set_defaults(handler=run)


# Textual draws by cursor addressing, which these terminals lack; it has no line mode to
# fall back to. Without colour (NO_COLOR set) it draws in monochrome.
TERMINALS_WITHOUT_CURSOR = ("dumb",)


def run(args) -> ExitCode:
    term = os.environ.get("TERM", "")
    if term in TERMINALS_WITHOUT_CURSOR:
        raise FrictionlabError(
            f"frictionlab tui draws a full screen, and TERM={term} says this terminal cannot move its cursor: "
            "run it in a terminal emulator (TERM=xterm-256color, ...), or run presets headless: frictionlab run "
            "PRESET (NO_COLOR=1 draws the TUI without colour)"
        )
    for option, folder in (("--presets", args.presets), ("--runs", args.runs)):
        # a file given as a folder: the TUI started and said "No presets in FILE", or listed no runs,
        # and only a save or a run then failed ("File exists")
        if folder is not None and os.path.lexists(folder) and not os.path.isdir(folder):
            raise FrictionlabError(f"{option}: {shown_name(folder)} is not a folder: give a folder (one not there yet is made when first written into)")
    if args.preset is not None:
        from ..preset import load_preset_file

        args.preset = str(find_preset(args.preset, args.presets))
        load_preset_file(args.preset)  # a missing or unreadable file is a usage error, before the UI starts
    options = run_options(workers=args.workers)
    from ..tui import run_app  # Textual is imported here only

    return run_app(args.preset, presets_dir=args.presets, runs_dir=args.runs, options=options)


def find_preset(argument: str, presets_dir: str | None) -> Path:
    """The preset file the command line names: a name (no folder in it, no file of that name here
    unless ``--presets DIR`` is given) is looked for first in the folders the Presets list shows,
    in its order (DIR; else ``./presets``, then the user folder): ``NAME.yaml``, ``NAME.yml``, or
    the file named; else, and then, as ``frictionlab run`` reads it (a path as given, or a
    built-in's name). Found nowhere: a PresetFileError naming the value and each place looked in."""
    from ..preset.builtin import builtin_presets, listed_preset_folders, resolve_preset_path

    if len(Path(argument).parts) != 1 or (presets_dir is None and os.path.lexists(argument)):
        return resolve_preset_path(argument)  # a path, or a file here: the one meant
    folders = listed_preset_folders(presets_dir)
    names = [argument] if Path(argument).suffix in (".yaml", ".yml") else [f"{argument}.yaml", f"{argument}.yml"]
    looked = [folder / name for folder in folders for name in names]
    found = next((path for path in looked if os.path.lexists(path) and not path.is_dir()), None)
    if found is not None:
        return found  # read (and, if it cannot be, reported) as a preset file
    try:
        elsewhere = resolve_preset_path(argument)
    except PresetFileError:
        elsewhere = None
    if elsewhere is not None and os.path.lexists(elsewhere):
        return elsewhere
    in_folders = sorted({path.stem for folder in folders if folder.is_dir() for path in folder.glob("*.y*ml")})
    listed = ", ".join(in_folders[:12]) + (f" and {len(in_folders) - 12} more" if len(in_folders) > 12 else "")
    hint = did_you_mean(Path(argument).stem, list(dict.fromkeys(in_folders + [p.name for p in builtin_presets()])))  # once each
    where = f"--presets {str(folders[0])!r}" if presets_dir else " or ".join(repr(str(folder)) for folder in folders)
    raise PresetFileError(
        [f"(file): no preset {argument!r} in {where} (looked for {' and '.join(map(str, looked))}), "
         f"no file {argument!r} here and no built-in preset of that name{hint or '.'} "
         f"Presets there: {listed or '(none)'} (`frictionlab presets` lists the built-ins)"],
        source=argument,
    )  # fmt: skip

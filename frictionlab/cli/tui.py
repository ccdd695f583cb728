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
    p.add_argument("preset", nargs="?", help="preset YAML file, or a preset's name (in --presets DIR first, then the built-ins), to open (optional)")
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
    """The preset file the command line names: with ``--presets DIR`` a name (no folder in it) is
    looked for in DIR first, as its Presets list shows it (``NAME.yaml``, ``NAME.yml``, or the file
    named); else, and then, as ``frictionlab run`` reads it (a path as given, or a built-in's name).
    Found nowhere: a PresetFileError naming the value and each place looked in."""
    from ..preset.builtin import builtin_presets, resolve_preset_path

    if presets_dir is None or len(Path(argument).parts) != 1:
        return resolve_preset_path(argument)
    folder = Path(presets_dir)
    names = [argument] if Path(argument).suffix in (".yaml", ".yml") else [f"{argument}.yaml", f"{argument}.yml"]
    looked = [folder / name for name in names]
    found = next((path for path in looked if os.path.lexists(path) and not path.is_dir()), None)
    if found is not None:
        return found  # read (and, if it cannot be, reported) as a preset file
    try:
        elsewhere = resolve_preset_path(argument)
    except PresetFileError:
        elsewhere = None
    if elsewhere is not None and os.path.lexists(elsewhere):
        return elsewhere
    in_folder = sorted(path.stem for path in folder.glob("*.y*ml")) if folder.is_dir() else []
    listed = ", ".join(in_folder[:12]) + (f" and {len(in_folder) - 12} more" if len(in_folder) > 12 else "")
    hint = did_you_mean(Path(argument).stem, in_folder + [p.name for p in builtin_presets()])
    raise PresetFileError(
        [f"(file): no preset {argument!r} in --presets {str(folder)!r} (looked for {' and '.join(map(str, looked))}), "
         f"no file {argument!r} here and no built-in preset of that name{hint or '.'} "
         f"Presets in {str(folder)!r}: {listed or '(none)'} (`frictionlab presets` lists the built-ins)"],
        source=argument,
    )  # fmt: skip

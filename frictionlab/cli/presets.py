"""``frictionlab presets``: the presets shipped with frictionlab, and ``presets copy``
to take one out to edit (never over an existing file without ``--force``)."""

from __future__ import annotations

import os
import sys
from pathlib import Path

from ..errors import ExitCode, FrictionlabError, OutputRefused, did_you_mean, shown, shown_name
from .options import dash_is_stdout

EXAMPLES = """examples:
  frictionlab presets                         list the built-in presets
  frictionlab presets copy quickstart         copy quickstart.yaml here, to edit
  frictionlab run quickstart                  run a built-in by its name
"""


def add_parser(sub) -> None:
    p = sub.add_parser(
        "presets",
        help="list the built-in presets, or copy one out to edit",
        description="The presets that ship with frictionlab. Run one by name (frictionlab run quickstart) "
        "or copy it out to edit.",
        epilog=EXAMPLES,
    )
    p.add_argument("--json", action="store_true", help="as JSON: name, whole description, path")
    actions = p.add_subparsers(dest="action", metavar="ACTION")
    c = actions.add_parser(
        "copy",
        help="copy a built-in preset to a file or folder",
        description="Copy a built-in preset out, to edit; an existing file is kept unless --force.",
        epilog="example:\n  frictionlab presets copy benad2012-fig2 my-fig2.yaml",
    )
    c.add_argument("name", metavar="NAME", help="a built-in preset (frictionlab presets lists them)")
    dash_is_stdout(c.add_argument("dest", nargs="?", default=".", metavar="DEST",
                                  help="file or folder (default: .); a name ending in / is a folder, made if missing; "
                                  "- prints the preset on stdout"))
    c.add_argument("--force", action="store_true", help="replace DEST if it exists")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    from ..preset.builtin import builtin_presets

    if getattr(args, "action", None) == "copy":
        if args.json:  # taken by `presets`, not by copy: a script waiting for JSON got a line of text
            raise FrictionlabError("--json lists the built-in presets as JSON; presets copy prints none: leave --json out")
        if args.dest == "-":  # stdout, by CLI convention
            return print_preset(args.name)
        dest = Path(args.dest)
        if args.dest.endswith(("/", os.sep)) and not dest.is_dir():  # "newdir/": a folder, not a file named newdir
            from ..io.files import output_path_problem

            problem = output_path_problem(dest)
            if problem:
                raise OutputRefused(f"DEST: {problem}; give a folder")
            dest.mkdir(parents=True)
        return copy_preset(args.name, dest, force=args.force)
    presets = builtin_presets()
    if args.json:  # the whole description (the table shows its first sentence)
        from .jsonout import emit

        emit("presets", {"presets": [{"name": p.name, "description": p.full_description, "path": str(p.path)}
                                     for p in presets]})  # fmt: skip
        return ExitCode.OK
    from .console import print_table

    print_table(["NAME", "DESCRIPTION"], [(p.name, p.description) for p in presets])
    return ExitCode.OK


def _builtin(name: str):
    from ..preset.builtin import builtin_presets, find_builtin

    preset = find_builtin(name)
    if preset is None:
        names = [p.name for p in builtin_presets()]
        raise FrictionlabError(f"no built-in preset {name!r}{did_you_mean(name, names) or '.'} Built-ins: {', '.join(names)}.")
    return preset


def print_preset(name: str) -> ExitCode:
    """``presets copy NAME -``: the built-in preset's file as it is, on stdout."""
    data = _builtin(name).path.read_bytes()
    sys.stdout.flush()
    sys.stdout.buffer.write(data)
    return ExitCode.OK


def copy_preset(name: str, dest: Path, *, force: bool = False) -> ExitCode:
    from ..io.files import atomic_write

    preset = _builtin(name)
    target = dest / preset.path.name if dest.is_dir() else dest
    from ..io.files import output_path_problem, refuse_unreplaceable

    problem, there = output_path_problem(target.parent), target.parent.is_dir()
    if problem or not there:  # open() would say only "No such file or directory" (/proc/self/x) with exit 1
        advice = "give a file in a folder you can write to" if there else "make the folder first, or give an existing one"
        raise OutputRefused(f"DEST {shown(target)}: {problem or f'the folder {shown(target.parent)} does not exist'}; {advice}")
    refuse_unreplaceable([target], "copy", "give another DEST")  # a folder: "exists, --force" then failed with exit 1
    data = preset.path.read_bytes()
    try:
        if force:  # replaced, never written through a link
            atomic_write(target, lambda out: out.write(data), binary=True, devices=True)
        else:
            with open(target, "xb") as out:  # "x": never over a file (or a link) that appeared meanwhile
                out.write(data)
    except FileExistsError:
        raise OutputRefused(f"{shown_name(target)} exists; give another DEST or --force to replace it") from None
    print(shown(f"copied {preset.name} to {target}"))  # DEST as typed, an escape code in it escaped
    return ExitCode.OK

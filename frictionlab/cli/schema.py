"""``frictionlab schema``: the JSON Schema of presets with the installed plugins' parameters (for editors)."""

from __future__ import annotations

import json

from ..errors import ExitCode
from .options import dash_is_stdout


def add_parser(sub) -> None:
    p = sub.add_parser(
        "schema",
        help="JSON Schema of presets with the installed plugins",
        description="Print the JSON Schema of a preset, with the parameters of every installed plugin (for editors).",
        epilog="example:\n  frictionlab schema --out preset.schema.json",
    )
    dash_is_stdout(p.add_argument("--out", metavar="FILE", help="write to FILE instead of stdout (an existing FILE is kept "
                                  "unless --force; - is stdout)"))
    p.add_argument("--force", action="store_true", help="replace FILE if it exists")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    from ..preset import preset_json_schema

    out = None
    if args.out and args.out != "-":  # '-': stdout
        from ..io.files import check_output_file

        out = check_output_file(args.out, "--out", force=args.force)  # before the work: refused at once
    text = json.dumps(preset_json_schema(), indent=2)
    if out is not None:
        from ..io.files import atomic_write

        atomic_write(out, lambda fh: fh.write(text + "\n"), devices=True)
    else:
        print(text)
    return ExitCode.OK

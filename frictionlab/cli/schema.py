"""``frictionlab schema``: the JSON Schema of presets with the installed plugins' parameters (for editors)."""

from __future__ import annotations

import json
from pathlib import Path

from ..errors import ExitCode


def add_parser(sub) -> None:
    p = sub.add_parser(
        "schema",
        help="JSON Schema of presets with the installed plugins",
        description="Print the JSON Schema of a preset, with the parameters of every installed plugin (for editors).",
        epilog="example:\n  frictionlab schema --out preset.schema.json",
    )
    p.add_argument("--out", metavar="FILE", help="write to FILE instead of stdout")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    from ..preset import preset_json_schema

    text = json.dumps(preset_json_schema(), indent=2)
    if args.out:
        from ..files import atomic_write

        atomic_write(Path(args.out), lambda fh: fh.write(text + "\n"))
    else:
        print(text)
    return ExitCode.OK

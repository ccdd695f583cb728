"""``frictionlab plugins``: the installed plugins of every kind, with their providers (and those that failed to load)."""

from __future__ import annotations

import json
import sys

from ..errors import ExitCode


def add_parser(sub) -> None:
    p = sub.add_parser("plugins", help="list installed plugins")
    p.add_argument("--json", action="store_true", help="as JSON")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    from ..registry import default_registry

    registry = default_registry()
    infos = registry.infos()
    if args.json:
        rows = [
            {"kind": i.kind, "name": i.name, "summary": i.summary, "provider": i.provider, "version": i.version}
            for i in infos
        ]
        failures = [f.__dict__ for f in registry.failures]
        print(json.dumps({"plugins": rows, "failed": failures}, indent=2))
        return ExitCode.OK
    header = ("KIND", "NAME", "PROVIDER", "VERSION", "SUMMARY")
    rows = [(i.kind, i.name, i.provider, i.version, i.summary) for i in infos]
    widths = [max(len(r[c]) for r in [header, *rows]) for c in range(4)]
    for row in [header, *rows]:
        print("  ".join(cell.ljust(w) for cell, w in zip(row[:4], widths)) + "  " + row[4])
    for failure in registry.failures:
        print(f"failed to load: {failure.entry_point} ({failure.distribution}): {failure.error}", file=sys.stderr)
    return ExitCode.OK

"""``frictionlab plugins``: the installed plugins of every kind, with their providers (and those that failed to load)."""

from __future__ import annotations

import sys

from ..errors import ExitCode


def add_parser(sub) -> None:
    p = sub.add_parser(
        "plugins",
        help="list installed plugins",
        description="The installed spectra, solvers and slope estimators, with the distribution that ships each.",
        epilog="examples:\n  frictionlab plugins\n  frictionlab plugins --json",
    )
    p.add_argument("--json", action="store_true", help="as JSON")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    from ..plugin.registry import default_registry

    registry = default_registry()
    infos = registry.infos()
    if args.json:
        rows = [
            {"kind": i.kind, "name": i.name, "summary": i.summary, "provider": i.provider, "version": i.version}
            for i in infos
        ]
        failures = [f.__dict__ for f in registry.failures]
        from .jsonout import emit

        emit("plugins", {"plugins": rows, "failed": failures, "clashes": registry.clashes})
        return ExitCode.OK
    from .console import print_table

    print_table(("KIND", "NAME", "PROVIDER", "VERSION", "SUMMARY"), [(i.kind, i.name, i.provider, i.version, i.summary) for i in infos])
    for failure in registry.failures:
        print(f"failed to load: {failure.entry_point} ({failure.distribution}): {failure.error}", file=sys.stderr)
    for clash in registry.clashes:
        print(f"not listed: {clash}", file=sys.stderr)
    return ExitCode.OK

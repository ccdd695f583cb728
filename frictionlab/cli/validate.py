"""``frictionlab validate PRESET...``: check presets (every point of a sweep too) and report every problem."""

from __future__ import annotations

import sys

from ..errors import ExitCode, FrictionlabError


def add_parser(sub) -> None:
    p = sub.add_parser("validate", help="check presets and report every problem")
    p.add_argument("presets", nargs="+", metavar="PRESET", help="preset YAML files or built-in names")
    p.add_argument("--set", action="append", metavar="PATH=VALUE", help="override before validating")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    from ..preset import build_scene, read_preset
    from ..preset.builtin import resolve_preset_path
    from ..sweep import plan_sweep

    worst = ExitCode.OK
    for path in args.presets:
        try:
            data = read_preset(resolve_preset_path(path), args.set or [])
            scene = build_scene(data, source=str(path))
            if scene.preset.sweep is not None:  # every point too
                points = len(plan_sweep(data, source=str(path)).points)
        except FrictionlabError as exc:
            print(str(exc), file=sys.stderr)
            worst = ExitCode(max(worst, exc.exit_code))
            continue
        preset = scene.preset
        print(
            f"{path}: ok ({preset.realizations} realizations, {scene.generator.name} / {scene.solver.name} / "
            f"{scene.slope.name}, {preset.loading.steps} {preset.loading.control} steps"
            + (f", sweep of {points} points)" if scene.preset.sweep is not None else ")")
        )
    return worst

"""``frictionlab validate PRESET...``: check presets (every point of a sweep too) and report every problem."""

from __future__ import annotations

import sys

from ..errors import ExitCode, FrictionlabError, PresetError, counted, shown
from .options import refuse_swept_overrides


def add_parser(sub) -> None:
    p = sub.add_parser(
        "validate",
        help="check presets and report every problem",
        description="Check presets (every point of a sweep too) without running them; every problem is named by its field.",
        epilog="examples:\n  frictionlab validate my.yaml\n  frictionlab validate quickstart --set realizations=0 --json",
    )
    p.add_argument("presets", nargs="+", metavar="PRESET", help="preset YAML files or built-in names")
    p.add_argument("--set", action="append", metavar="PATH=VALUE", help="override before validating")
    p.add_argument("--json", action="store_true", help="one JSON object on stdout: ok, and under presets one record per preset (ok, problems, what would run)")
    p.set_defaults(handler=run)


def run(args) -> ExitCode:
    from ..api import scene_record
    from ..io.inputs import input_lines
    from ..preset.loads import loads_lines
    from ..preset import build_scene, read_preset
    from ..preset.builtin import preset_source, resolve_preset_path, same_name_note
    from ..runs.runner import check_one_realization
    from ..runs.sweep import plan_sweep
    from ..plugin import SolveFailed
    from ..plugin.registry import solve_failed

    worst = ExitCode.OK
    records = []
    for path in args.presets:
        points = None
        try:
            resolved = resolve_preset_path(path)
            if (note := same_name_note(path, resolved)) and not args.json:
                print(shown(note), file=sys.stderr)
            data = read_preset(resolved, args.set or [])
            refuse_swept_overrides(args, data)
            source = preset_source(path, args.set or [])
            scene = build_scene(data, source=source, before_reading=check_one_realization)
            if scene.preset.sweep is not None:  # every point too
                points = len(plan_sweep(data, source=source, before_reading=check_one_realization).points)
            # its loads in every unit: refused here when the solver cannot take them
            record = {"preset": str(path), "ok": True, "problems": [], **scene_record(scene), "sweep_points": points}
        except (FrictionlabError, SolveFailed) as raised:  # a SolveFailed: the plugin's word, as run tells it
            exc = solve_failed(raised) or raised
            worst = ExitCode(max(worst, exc.exit_code))
            problems = exc.problems or [str(exc)]
            records.append({"preset": str(path), "ok": False, "problems": problems, "exit_code": int(exc.exit_code)})
            if not args.json:  # a preset's problems start with its name; any other refusal (its memory) is named here
                print(shown(str(exc) if isinstance(exc, PresetError) else f"{path}: {exc}"), file=sys.stderr)
            continue
        preset = scene.preset
        records.append(record)
        if not args.json:
            print(shown(
                f"{path}: ok ({counted(preset.realizations, 'realization')}, {scene.pressed} / {scene.solver.name} / "
                f"{scene.slope.name}, {preset.loading.steps} {preset.loading.control} steps"
                + (f", sweep of {counted(points, 'point')})" if points is not None else ")")
            ))
            if record["input"] is not None:  # its unit, as the instrument file wrote it
                for line in input_lines(record["input"]):
                    print(shown(f"  {line}"))
                for caveat in record["input"].get("caveats", ()):
                    print(f"  caveat: {shown(caveat)}")
            for caveat in record["caveats"]:  # of the spectrum's parameters (few pixels on the short cut-off)
                print(f"  caveat: {shown(caveat)}")
            for line in loads_lines(record["loads"], scene.normalisation.load_symbol):
                print(shown(f"  {line}"))
    if args.json:
        from .jsonout import emit

        emit("validate", {"ok": all(record["ok"] for record in records), "presets": records})
    return worst

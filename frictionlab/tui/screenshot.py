"""An SVG screenshot of the app with a preset open, for the docs:

    python -m frictionlab.tui.screenshot docs/tui/main.svg [--preset presets/quickstart.yaml] [--size 80x24]

The app runs headless (Textual's test driver) on the given preset, opens it in
the Edit tab with the cursor still, and writes what the terminal would show. The
preset is by default a clone's presets/quickstart.yaml, elsewhere the built-in quickstart.
"""

from __future__ import annotations

import argparse
import asyncio
from pathlib import Path

CLONE_PRESET = Path("presets/quickstart.yaml")  # what the docs' screenshot shows, made in a clone


async def take(out: Path, preset: Path, size: tuple[int, int]) -> None:
    from textual.widgets import Input

    from .app import FrictionlabApp

    app = FrictionlabApp(preset, presets_dir=preset.parent)
    async with app.run_test(size=size) as pilot:
        await pilot.pause()
        for field in app.screen.query(Input):
            field.cursor_blink = False
        await pilot.wait_for_scheduled_animations()  # the tabs' underline slides in: caught at its end, every time
        await pilot.pause()
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(app.export_screenshot(), encoding="utf-8")


def terminal_size(text: str) -> tuple[int, int]:
    """``COLUMNSxLINES`` as two whole numbers, in what a terminal has."""
    try:
        columns, lines = (int(n) for n in text.lower().split("x"))
    except ValueError:
        raise argparse.ArgumentTypeError(f"must be COLUMNSxLINES, such as 80x24. Got {text!r} instead.") from None
    if not (20 <= columns <= 1000 and 5 <= lines <= 500):
        raise argparse.ArgumentTypeError(f"must be 20 to 1000 columns by 5 to 500 lines. Got {text!r} instead.")
    return columns, lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m frictionlab.tui.screenshot", description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="the SVG file to write")
    parser.add_argument("--preset", type=Path, help="the preset to open (default: presets/quickstart.yaml, in a clone; "
                                                    "elsewhere the built-in quickstart)")  # fmt: skip
    parser.add_argument("--size", type=terminal_size, default=(80, 24), help="terminal columns x lines (default 80x24)")
    args = parser.parse_args(argv)
    preset = args.preset
    if preset is None:
        from ..preset.builtin import find_builtin

        preset = CLONE_PRESET if CLONE_PRESET.is_file() else find_builtin("quickstart").path
    if not preset.is_file():
        parser.error(f"--preset: no such file {preset}")
    asyncio.run(take(args.out, preset, args.size))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

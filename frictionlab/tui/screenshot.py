"""An SVG screenshot of the app with a preset open, for the docs:

    python -m frictionlab.tui.screenshot docs/tui/main.svg [--preset presets/quickstart.yaml] [--size 80x24]

The app runs headless (Textual's test driver) on the given preset, opens it in
the Edit tab with the cursor still, and writes what the terminal would show.
"""

from __future__ import annotations

import argparse
import asyncio
from pathlib import Path


async def take(out: Path, preset: Path, size: tuple[int, int]) -> None:
    from textual.widgets import Input

    from .app import FrictionlabApp

    app = FrictionlabApp(preset, presets_dir=preset.parent)
    async with app.run_test(size=size) as pilot:
        await pilot.pause()
        for field in app.screen.query(Input):
            field.cursor_blink = False
        await pilot.pause()
        out.parent.mkdir(parents=True, exist_ok=True)
        out.write_text(app.export_screenshot(), encoding="utf-8")


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(prog="python -m frictionlab.tui.screenshot", description=__doc__.splitlines()[0])
    parser.add_argument("out", type=Path, help="the SVG file to write")
    parser.add_argument("--preset", type=Path, default=Path("presets/quickstart.yaml"), help="the preset to open")
    parser.add_argument("--size", default="80x24", help="terminal columns x lines (default 80x24)")
    args = parser.parse_args(argv)
    columns, lines = (int(n) for n in args.size.lower().split("x"))
    if not args.preset.is_file():
        parser.error(f"--preset: no such file {args.preset}")
    asyncio.run(take(args.out, args.preset, (columns, lines)))
    print(f"wrote {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

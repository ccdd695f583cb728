"""What the benchmarks that time whole processes share: the check of their ``--repeat`` and
``--busy`` options, and the CPU-bound processes that ``--busy N`` runs beside a measurement,
as a busy machine has."""

from __future__ import annotations

import argparse
import contextlib
import subprocess
import sys


def check_repeat_and_busy(parser: argparse.ArgumentParser, args: argparse.Namespace) -> None:
    if args.repeat < 1:
        parser.error(f"--repeat must be >= 1. Got {args.repeat} instead.")
    if args.busy < 0:
        parser.error(f"--busy must be >= 0. Got {args.busy} instead.")


@contextlib.contextmanager
def busy_beside(count: int):
    """``count`` processes running ``while 1: pass`` while the block runs."""
    busy = [subprocess.Popen([sys.executable, "-c", "while 1: pass"]) for _ in range(count)]
    try:
        yield
    finally:
        for process in busy:
            process.kill()
            process.wait()

"""Helpers of the CLI's tests: presets written to files, the CLI in a subprocess."""

import os
import subprocess
import sys

import yaml


def write_preset(tmp_path, data, name="preset.yaml"):
    path = tmp_path / name
    path.write_text(yaml.safe_dump(data))
    return path


def run_cli(*args, env=None, **kwargs):
    return subprocess.run(
        [sys.executable, "-m", "frictionlab", *map(str, args)],
        capture_output=True,
        text=True,
        env={**os.environ, **(env or {})},
        **kwargs,
    )


RUN_DIRECTORY = {"run.json", "chunks"}  # the run directory's own files (frictionlab.rundir; run.lock is gone once it ends)

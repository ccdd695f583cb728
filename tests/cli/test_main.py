"""The headless CLI as a user meets it: real files, real subprocesses, exit codes."""

import subprocess
import sys

from frictionlab.errors import ExitCode

from ..conftest import PRESETS
from .conftest import run_cli


def test_bad_command_line_is_a_usage_error_without_traceback():
    result = run_cli("run")
    assert result.returncode == ExitCode.USAGE
    assert "usage:" in result.stderr and "Traceback" not in result.stderr
    result = run_cli("run", PRESETS / "quickstart.yaml", "--workers", "0")
    assert result.returncode == ExitCode.USAGE
    assert "--workers must be >= 1. Got 0 instead." in result.stderr


def test_headless_run_never_imports_textual(tmp_path):
    code = (
        "import sys; from frictionlab.cli import main; "
        f"rc = main(['run', {str(PRESETS / 'quickstart.yaml')!r}, '--out', {str(tmp_path / 'o')!r}, '--quiet']); "
        "bad = sorted(m for m in sys.modules if m.split('.')[0] in {'textual', 'rich'}); "
        "print(rc, bad)"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.stdout.strip().splitlines()[-1] == "0 []", result.stderr


def test_running_out_of_memory_is_said_as_such_not_as_a_bug(monkeypatch, capsys):
    import frictionlab.cli.validate
    from frictionlab.cli import main

    def allocate(args):
        raise MemoryError("Unable to allocate 29.8 TiB for an array with shape (1000000000, 4096)")

    monkeypatch.setattr(frictionlab.cli.validate, "run", allocate)  # the handler the parser is built with
    assert main(["validate", "quickstart"]) == ExitCode.RUNTIME_FAILURE
    err = capsys.readouterr().err
    assert err.startswith("error: out of memory: Unable to allocate 29.8 TiB") and "internal error" not in err


def test_the_dashboard_without_frictionlabs_own_dask_cluster_is_refused_not_ignored(capsys):
    from frictionlab.cli import main

    for extra in ([], ["--executor", "processes"], ["--executor", "dask", "--scheduler", "tcp://127.0.0.1:1"]):
        assert main(["run", "quickstart", "--dashboard", "--quiet", *extra]) == ExitCode.USAGE
        assert "--dashboard serves the dashboard of frictionlab's own Dask cluster" in capsys.readouterr().err

"""What every ``--json`` prints: one JSON object on stdout, and nothing else there.

Every object names its shape first, ``"schema": "frictionlab/<shape>/<version>"``; the
version goes up when a key is removed or changes meaning (keys may be added within a
version). ``SHAPES`` says what each holds; the reference page of the site is made from
it. A command refused or failed under ``--json`` prints the ``error`` shape (and says
the same on stderr, for a person watching). While such a command works, whatever else prints
(a plugin's debug line) goes to stderr: ``json_only``. ``frictionlab schema`` prints a JSON Schema
document, for editors, not one of these.
"""

from __future__ import annotations

import contextlib
import json
import re
import sys

VERSION = 1

SHAPES = {
    "run": ("run, resume", "the keys of the run's summary.json: `fit` (a, b, their intervals, R²), `realizations`, "
            "`normalisation` (what f is), `status`, `caveats`, `files`, ..."),
    "sweep": ("run, resume", "for a preset with a sweep: the keys of sweep.json: `sweep` (the swept paths), `points` "
              "(each point's values, fit and folder), `status`"),
    "validate": ("validate", "`ok` (every preset valid) and `presets`: a record per preset given, with `preset`, `ok`, "
                 "`problems` (each `field: what is wrong`), `exit_code` and, when valid, what would run (`name`, "
                 "`realizations`, `spectrum`, `solver`, `slope`, `steps`, `control`, `sweep_points`, and `loads`: the "
                 "`force_unit`, the `range` in every unit, `full_contact`)"),
    "presets": ("presets", "`presets`: each built-in's `name`, whole `description` and `path`"),
    "plugins": ("plugins", "`plugins` (each `kind`, `name`, `summary`, `provider`, `version`) and `failed` (the entry "
                "points that did not load, with their error)"),
    "predict": ("predict", "`f`, `xi` and `xi_ci`, with the law's `a` and `b`, `extrapolated`, `beyond_full_contact`"),
    "study": ("study", "`recommendation` (text), `rows` (one per setting: error against cost), `files`, `interrupted`"),
    "report": ("report", "`report` (the Markdown file) and `figures` (the files it shows)"),
    "detached": ("run --detach, resume --detach", "`folder`, `kind` (`run`, or `sweep` for a preset with a sweep), "
                 "`pid` of the run's own process, `status` (`running`)"),
    "runs": ("runs", "`runs_dir` and `runs`: each run folder's `folder`, `kind` (`run`, or `sweep`: a sweep's folder is "
             "one entry), `name`, `status` (`running` only while its process holds the folder; a run whose process "
             "died is `interrupted`; `damaged` when a file of it cannot be read), `done`, `total` (realizations; a "
             "sweep's points), `pid`, `reason` (why it is damaged, else null)"),
    "follow": ("follow", "the run's final state: `folder`, `kind`, `name`, `status` (`deleted` when its folder was "
               "deleted or replaced while it ran), `done`, `total`, `pid`, `reason`, and "
               "`error` (the run's error, or null); for a sweep also `points`: each point's row of sweep.json "
               "(its values, `status`, fit, `folder`)"),
    "error": ("any, when refused or failed", "`error` (the message), `field` (the preset field or option at fault, "
              "or null), `problems` (every problem of a preset, else the message alone), `exit_code` (the "
              "process's), `command`"),
}
"""Each shape's name: (the commands that print it, what it holds)."""
_FIELD = re.compile(r"(--[a-z][a-z-]*|[A-Za-z_][\w.\[\]-]*): ")  # "--workers: ..." or "spectrum.params.hurst: ..."


def shape(name: str) -> str:
    if name not in SHAPES:
        raise ValueError(f"no JSON shape {name!r}: document it in SHAPES")
    return f"frictionlab/{name}/{VERSION}"


def dumps(name: str, payload: dict) -> str:
    """``payload`` as the object of shape ``name`` (its ``schema`` key first)."""
    return json.dumps({"schema": shape(name), **payload}, indent=2, allow_nan=False)


_real_stdout = None  # while a --json command works (``json_only``): where its JSON goes


@contextlib.contextmanager
def json_only():
    """While a ``--json`` command works, ``sys.stdout`` is stderr: whatever else prints (a plugin's
    debug line, here or in a forked worker) cannot break the one JSON object, which ``emit`` writes
    to the real stdout."""
    global _real_stdout
    real = _real_stdout = sys.stdout
    sys.stdout = sys.stderr
    try:
        yield
    finally:
        sys.stdout, _real_stdout = real, None


def _stdout():
    return _real_stdout or sys.stdout


def emit(name: str, payload: dict) -> None:
    print(dumps(name, payload), file=_stdout())


def error_object(command: str | None, message: str, exit_code: int, problems: list[str] | None = None) -> dict:
    """The ``frictionlab/error/1`` object of a refusal or failure."""
    problems = list(problems or [message])
    found = _FIELD.match(problems[0]) or re.search(r"(--[a-z][a-z-]*)\b", problems[0])
    field = found.group(1) if found else None
    if field in ("(file)", "(preset)"):
        field = None
    return {"schema": shape("error"), "command": command, "error": message, "field": field, "problems": problems,
            "exit_code": int(exit_code)}  # fmt: skip


def emit_error(command: str | None, message: str, exit_code: int, problems: list[str] | None = None) -> None:
    print(json.dumps(error_object(command, message, exit_code, problems), indent=2), file=_stdout())

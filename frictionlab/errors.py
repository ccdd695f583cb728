"""Error types and process exit codes shared by every front end."""

from __future__ import annotations

import enum


class ExitCode(enum.IntEnum):
    """What ``frictionlab`` returns to the shell."""

    OK = 0
    RUNTIME_FAILURE = 1  # a realization or a write failed
    USAGE = 2  # bad command line, invalid preset, unknown or broken plugin
    INTERRUPTED = 130  # Ctrl-C / cancel: finished work was kept


class FrictionlabError(Exception):
    """Base of the errors a user can cause and fix; shown without a traceback."""

    exit_code = ExitCode.USAGE


class PluginError(FrictionlabError):
    """A plugin is missing, broken, or clashes with another."""


class PresetError(FrictionlabError):
    """A preset failed validation. ``problems`` holds one line per problem, each
    starting with the dotted path of the offending field."""

    def __init__(self, problems: list[str], source: str | None = None):
        self.problems = list(problems)
        self.source = source
        where = f"{source}: " if source else ""
        count = len(self.problems)
        head = f"{where}{count} problem{'s' if count != 1 else ''} in preset"
        super().__init__("\n".join([head, *("  " + p for p in self.problems)]))


class RunError(FrictionlabError):
    """The run could not complete (every realization failed, a write failed)."""

    exit_code = ExitCode.RUNTIME_FAILURE

"""Flags several commands share, and the ``RunOptions`` they make. Reading flags
happens here only; what an option means is ``frictionlab.options``."""

from __future__ import annotations

import argparse

from ..errors import FrictionlabError
from ..options import EXECUTORS


def add_workers_option(parser, default_help: str = "all cores; 1: in-process; more than the cores are no faster") -> None:
    parser.add_argument("--workers", type=int, metavar="N", help=f"worker processes (default: {default_help})")


def add_executor_options(parser) -> None:
    parser.add_argument(
        "--executor",
        choices=EXECUTORS,
        help="where realizations run (default: dask with --scheduler, else processes, or serial for --workers 1)",
    )
    parser.add_argument(
        "--scheduler", metavar="ADDRESS",
        help="an existing Dask scheduler, tls://HOST:PORT or tcp://HOST:PORT (the executor is then dask)",
    )
    parser.add_argument("--tls-ca-file", metavar="FILE", help="CA certificate of a tls:// Dask scheduler")
    parser.add_argument("--tls-cert", metavar="FILE", help="client certificate for a tls:// Dask scheduler")
    parser.add_argument("--tls-key", metavar="FILE", help="client key for a tls:// Dask scheduler")
    parser.add_argument(
        "--dashboard", action="store_true", help="serve the Dask dashboard of frictionlab's own local cluster (on 127.0.0.1; needs --executor dask, no --scheduler)"
    )
    parser.add_argument(
        "--no-memory-check", action="store_true", help="skip the peak-memory estimate made before the run starts"
    )


def run_options(**fields):
    """``RunOptions(**fields)``, a refused value named by its flag (``--workers``)."""
    from ..options import RunOptions

    try:
        return RunOptions(**fields)
    except FrictionlabError as exc:  # each message starts with the field's name
        raise FrictionlabError(f"--{exc}") from None


def executor_run_options(args, **fields):
    """The ``RunOptions`` of a command with the executor flags (Dask's TLS files and
    scheduler address are checked, and the TLS files taken, before anything starts)."""
    if args.scheduler is not None and not args.scheduler.strip():
        raise FrictionlabError(
            "--scheduler: the address is empty; give tls://HOST:PORT or tcp://HOST:PORT, "
            "or leave --scheduler out for frictionlab's own local cluster"
        )
    _use_tls_options(args)
    if args.executor == "serial" and args.workers is not None and args.workers > 1:
        raise FrictionlabError(
            f"--workers {args.workers} with --executor serial, which runs every realization in this process, one at "
            "a time: it would be ignored; give --executor processes (or dask), or leave --workers out"
        )
    if args.dashboard and (args.executor != "dask" or args.scheduler):
        raise FrictionlabError(
            "--dashboard serves the dashboard of frictionlab's own Dask cluster: it needs --executor dask "
            "without --scheduler (a scheduler of yours serves its own)"
        )
    return run_options(
        workers=args.workers,
        executor=args.executor,
        scheduler=args.scheduler,
        dashboard=args.dashboard,
        memory_check=not args.no_memory_check,
        **fields,
    )


def _use_tls_options(args) -> None:
    tls = {"ca_file": args.tls_ca_file, "cert": args.tls_cert, "key": args.tls_key}
    given = [_tls_flag(name) for name, value in tls.items() if value is not None]
    if given and not (args.scheduler and args.scheduler.startswith("tls://")):
        scheduler = "no --scheduler (frictionlab's own cluster makes its own)" if not args.scheduler else (
            f"--scheduler {args.scheduler}, which is not encrypted")
        raise FrictionlabError(
            f"{' and '.join(given)} {'are' if len(given) > 1 else 'is'} for a tls:// Dask scheduler, but there is "
            f"{scheduler}: {'they' if len(given) > 1 else 'it'} would be ignored; give --scheduler tls://HOST:PORT, "
            f"or leave {'them' if len(given) > 1 else 'it'} out"
        )
    if any(tls.values()) or (args.scheduler and args.scheduler.startswith("tls://")):
        for name, value in tls.items():
            if value:
                from ..io.inputs import regular_file_problem

                problem = regular_file_problem(value)
                if problem:
                    raise FrictionlabError(f"{_tls_flag(name)} {value}: {problem}")
        from ..compute.dask_security import use_tls_files

        use_tls_files(**tls)
    if args.scheduler:
        from ..compute.dask_security import check_address

        check_address(args.scheduler)


def _tls_flag(name: str) -> str:
    return "--tls-" + ("ca-file" if name == "ca_file" else name)


PATH_METAVARS = {"DIR": "folder", "RUN_DIR": "folder", "FILE": "file", "DEST": "file or folder"}


def refuse_empty_paths(parser, args) -> None:
    """A usage error for any path argument of the command (its metavar a ``PATH_METAVARS``)
    given as '-' where it does not mean stdout (a file or folder named '-' was made), or as the
    empty string, which Path() reads as this folder (``frictionlab resume ""`` resuming
    whatever run is here) and an option takes as not given (``exact3d --runs ""``: hours of
    work into a new runs/ folder): checked once here, for every command alike."""
    for action in _command_actions(parser, args):
        what = PATH_METAVARS.get(action.metavar)
        value = getattr(args, action.dest, None)
        if what is None or not isinstance(value, str) or (value.strip() and value != "-") or _dash_is_stdout(action, value):
            continue
        name = max(action.option_strings, key=len) if action.option_strings else action.metavar
        if value == "-":  # a file named '-' (or a folder): made silently where the user meant stdout
            raise FrictionlabError(f"{name} -: '-' stands for standard output or input, which {name} cannot be: it "
                                   f"names a {what}; give a {what} (./- for one named '-')")  # fmt: skip
        optional = action.option_strings or action.nargs == "?"
        leave = (f"leave {name} out" if action.option_strings else "leave it out") if optional else ""
        empty = "it is empty" if not value else "it is only spaces"  # a folder named ' ' is refused as a mistyped one
        raise FrictionlabError(f"{name} names no {what} ({empty}): give a {what}" + (f", or {leave}" if leave else ""))


def dash_is_stdout(action: argparse.Action) -> argparse.Action:
    """Mark ``action`` (a FILE or DEST) as one whose '-' means stdout, as by CLI convention; any
    other path argument refuses '-' (``refuse_empty_paths``)."""
    action.dash_is_stdout = True
    return action


def _dash_is_stdout(action: argparse.Action, value: str) -> bool:
    return value == "-" and getattr(action, "dash_is_stdout", False)


def _command_actions(parser, args):
    """The arguments of the command ``args`` were parsed for (a subcommand's, such as
    ``presets copy``, included)."""
    for action in parser._actions:
        if isinstance(action, argparse._SubParsersAction):
            chosen = getattr(args, action.dest, None)
            if chosen in action.choices:
                yield from _command_actions(action.choices[chosen], args)
        else:
            yield action


def command_options(parser, args) -> frozenset[str]:
    """The option strings of the command ``args`` were parsed for: what its messages may advise."""
    return frozenset(name for action in _command_actions(parser, args) for name in action.option_strings)


def preset_overrides(args) -> list[str]:
    """The ``--set`` assignments, then ``--seed S`` as ``seed=S``. A ``--set seed=`` of
    another value beside ``--seed`` is refused: which one the run took would be a guess."""
    overrides = list(args.set or [])
    if args.seed is None:
        return overrides
    for assignment in overrides:
        path, sep, value = assignment.partition("=")
        if sep and path.strip() == "seed" and value.strip() != str(args.seed):
            raise FrictionlabError(f"--seed {args.seed} and --set {assignment!r} both give the root seed: give it once")
    return [*overrides, f"seed={args.seed}"]


def refuse_swept_overrides(args, data: dict) -> None:
    """Refuse a ``--set`` (or ``--seed``) of a path the preset's sweep sets at each point
    (``preset.paths.swept_paths``)."""
    from ..preset.paths import SWEPT, swept_paths

    given = {assignment.partition("=")[0].strip(): f"--set {assignment!r}" for assignment in args.set or []}
    if getattr(args, "seed", None) is not None:
        given["seed"] = f"--seed {args.seed}"
    if swept := swept_paths(data, list(given)):
        path = swept[0]
        raise FrictionlabError(f"{given[path]}: {path} {SWEPT}; sweep other values (--set "
                               f"'sweep.parameters.{path}={{values: [...]}}'), or run the preset once (--set sweep=null)")


"""What every check shares: failing with a message that names the plugin class,
calling plugin code so that its exceptions become such failures, and checking
arrays and numbers. numpy is imported only when a check runs."""

from __future__ import annotations

import functools
import math
from collections.abc import Callable, Mapping
from typing import Any


def label(cls) -> str:
    """A plugin class named as a run names it: its kind, name, class and distribution."""
    from frictionlab.plugin import Plugin
    from frictionlab.plugin.registry import plugin_label

    if not isinstance(cls, type):
        return repr(cls)
    if issubclass(cls, Plugin) and getattr(cls, "kind", None) and isinstance(cls.name, str) and cls.name:
        return plugin_label(cls)
    return f"{cls.__module__}.{cls.__qualname__}"


def reported(check: Callable) -> Callable:
    """A public check whose failure shows, under pytest, the test that called it and the message:
    not the kit's own frames (this one pytest hides; the rest are cut). The plugin's own
    exception, where one was raised, stays chained with its traceback."""

    @functools.wraps(check)
    def checked(*args, **kwargs):
        __tracebackhide__ = True
        from frictionlab.errors.interrupts import interrupts_marked, raised_by_signal

        with interrupts_marked():
            try:
                return check(*args, **kwargs)
            except AssertionError as exc:
                raise exc.with_traceback(None)
            except (SystemExit, KeyboardInterrupt) as exc:  # the plugin's sys.exit() or own interrupt, where a
                if raised_by_signal(exc):  # check calls it outside ``call``: a failure, not the end of the tests
                    raise
                plugin = next((arg for arg in args if isinstance(arg, type)), None)
                said = f": {exc}" if str(exc) else ""
                error = AssertionError(f"{label(plugin)}: raised {type(exc).__name__}{said}; a plugin raises an "
                                       "exception where it cannot go on, it never exits nor interrupts")  # fmt: skip
                raise error.with_traceback(None) from exc

    return checked


def fail(cls, message: str, cause: BaseException | None = None):
    error = AssertionError(f"{label(cls)}: {message}")
    if cause is not None:
        raise error from cause
    raise error


def call(cls, what: str, fn: Callable[..., Any], *args, **kwargs):
    """Run plugin code; any exception becomes an AssertionError naming the call (a ``sys.exit()``
    and a ``KeyboardInterrupt`` the code raised itself included: a Ctrl-C stops the tests)."""
    from frictionlab.errors.interrupts import interrupts_marked, raised_by_signal

    with interrupts_marked():
        try:
            return fn(*args, **kwargs)
        except AssertionError:
            raise
        except (Exception, SystemExit, KeyboardInterrupt) as exc:
            if raised_by_signal(exc):
                raise
            said = f": {exc}" if str(exc) else ""
            fail(cls, f"{what} raised {type(exc).__name__}{said}", _from_the_call(exc))


def _from_the_call(exc: BaseException) -> BaseException:
    """``exc`` with its traceback from the frame ``call`` called on: the plugin's code first."""
    return exc.with_traceback(exc.__traceback__.tb_next) if exc.__traceback__ is not None else exc


def instantiate(cls, params: Mapping[str, Any]):
    return call(
        cls,
        f"{cls.__qualname__}(**{dict(params)!r}) (give the check the parameters it needs)",
        cls,
        **params,
    )


def check_array(cls, what: str, value, shape=None, floating=True):
    """``value`` as the run takes a plugin's array (``frictionlab.plugin.outputs``)."""
    from frictionlab.plugin.outputs import array_problem

    problem = array_problem(what, value, shape, floating)
    if problem:
        fail(cls, problem)
    return value


def check_positive_number(cls, what: str, value) -> float:
    try:
        number = float(value)
    except (TypeError, ValueError):
        fail(cls, f"{what} must be a number. Got {value!r} instead.")
    if not math.isfinite(number) or number <= 0:
        fail(cls, f"{what} must be finite and > 0. Got {number!r} instead.")
    return number


def is_not_implemented(cls, what: str, fn, *args):
    """Call an optional method: (True, None) if it raises NotImplementedError."""
    try:
        return False, fn(*args)
    except NotImplementedError:
        return True, None
    except Exception as exc:
        fail(cls, f"{what} raised {type(exc).__name__}: {exc}", exc)


def must_refuse(cls, what: str, call: Callable[[], Any]) -> None:
    """A ``periodic_only`` plugin must refuse ``what`` with a ValueError."""
    try:
        call()
    except ValueError:
        return
    except Exception as exc:
        fail(cls, f"periodic_only: {what} must raise ValueError. Got {type(exc).__name__}: {exc}", exc)
    fail(cls, f"periodic_only is True, but {what} was accepted; it must raise ValueError")

"""Figure files: ``write_figure`` writes one, saying why it could not; ``CurveFigure`` is
what plot.png shows, as plain data (built without matplotlib); ``DrawingProcess`` draws
plot.png in a process forked as a command starts.

A run's start (its imports, its preset) keeps one core busy and leaves the other idle;
its ensemble then keeps every core busy. matplotlib's import is about 0.3 s of a core:
made in this process while the workers compute, it takes that time from them. A process
forked as ``frictionlab run`` starts (numpy imported first: both need it) makes it on the
idle core instead, and is sent the figure (plain data: ``CurveFigure``) as soon as the
fit exists, to draw while this process writes the numbers. Where it cannot be had (no
fork on this platform, a thread already running, a failed fork) or dies, the figure is
drawn here: it is never lost.
"""

from __future__ import annotations

import os
import signal
import sys
import threading
from dataclasses import dataclass
from importlib import import_module
from pathlib import Path
from typing import TYPE_CHECKING

from ..errors import MissingDependency, RunError, RunFolderError, shown_name

# Imported only in the functions that use them: a command imports this module to fork
# before pydantic or matplotlib are imported.
if TYPE_CHECKING:
    from multiprocessing.connection import Connection

    import numpy as np

    from ..compute.ensemble import RunOutcome
    from ..compute.fit import LogFit
    from ..preset import Scene
    from ..result import Result

PLOT_MODULE = "frictionlab.plot"  # draws the figures: imported by name, where and when needed (it imports matplotlib)
SHOWN_CAVEATS = 8  # a run has a handful: a folder read back may hold any number (its summary.json up to 64 MB)
SHOWN_CAVEAT_CHARS = 1500  # frictionlab's own are shorter, but for a file's name in them
SHOWN_LABEL_CHARS = 400  # of a title or an axis's label read back: a run's own are under 300 (a preset's name 100)


def cut(text: str, limit: int) -> str:
    """``text``, or its first ``limit`` characters and "..."."""
    return text if len(text) <= limit else text[:limit] + "..."


def shown_caveats(caveats) -> list[str]:
    """``caveats`` as a figure or a screen shows them: the first SHOWN_CAVEATS, each cut at
    SHOWN_CAVEAT_CHARS, then how many more there are. A folder holding thousands of long ones
    (damaged, or a plugin's) took minutes to draw, the figure under them unreadable anyway."""
    said = [cut(caveat, SHOWN_CAVEAT_CHARS) for caveat in caveats[:SHOWN_CAVEATS]]
    if len(caveats) > SHOWN_CAVEATS:
        said.append(f"and {len(caveats) - SHOWN_CAVEATS} more, not shown here (the run's summary.json lists them all)")
    return said


WRITTEN = "the numbers are written"  # what a run's failed figure leaves: said after its failure


def write_figure(path: Path, draw, *, devices: bool = False, kept: str = WRITTEN) -> None:
    """Write a figure file with ``draw(file)``, which imports matplotlib itself. A
    failure is a RunError naming the file: a folder that said no, or matplotlib
    refusing (a bad MPLBACKEND, a broken font cache); the numbers are written by then.
    ``devices``: ``path`` is one the user named, a FIFO or device there written into, not
    replaced (``io.files.atomic_write``). ``kept``: what is left as it was, said after a failure."""
    from ..io.files import atomic_write

    try:
        atomic_write(path, draw, binary=True, devices=devices)
    except OSError as exc:
        raise RunError(f"cannot write {shown_name(path)}: {exc.strerror or exc}; {kept}") from None
    except ModuleNotFoundError as exc:  # a broken install: the message says how to mend it
        raise RunError(f"cannot draw {shown_name(path)}: {MissingDependency(exc.name or 'matplotlib', 'drawing')}; "
                       f"{kept}") from None  # fmt: skip
    except Exception as exc:
        raise RunError(f"cannot draw {shown_name(path)}: {type(exc).__name__}: {exc}; {kept}") from None


@dataclass(frozen=True)
class CurveFigure:
    """What plot.png shows of a run: small enough to send to the process that draws it."""

    title: str  # the preset's name, what was pressed, the solver and the slope estimator
    f_label: str  # what f is (the force normalisation's definition): the x axis
    f: np.ndarray
    xi: np.ndarray
    xi_sem: np.ndarray
    contact_count: np.ndarray
    fit: LogFit | None
    done: int  # realizations averaged
    caveats: tuple[str, ...]

    @classmethod
    def of(cls, scene: Scene, outcome: RunOutcome) -> CurveFigure:
        return cls(
            title=_title(scene.preset.name, scene.pressed, scene.solver.name, scene.slope.name),
            f_label=scene.normalisation.definition,
            f=outcome.f, xi=outcome.xi, xi_sem=outcome.xi_sem, contact_count=outcome.contact_count,
            fit=outcome.fit, done=outcome.done, caveats=tuple(shown_caveats(outcome.caveats)),
        )  # fmt: skip

    @classmethod
    def read_back(cls, result: Result) -> CurveFigure:
        """What ``of`` made of a run, from its folder read back (``frictionlab.load``): its
        curve, fit, caveats and f's definition as summary.json and curve.csv hold them; what
        was pressed worked out from the plugins its preset names (``preset.scene.recorded_pressed``),
        which summary.json does not say in words: the spectrum's name alone where they are not
        installed. RunFolderError where the preset recorded names no plugin. Its texts are cut at
        SHOWN_LABEL_CHARS (a damaged folder's title of 300000 characters left no room for the axes)."""
        from ..preset.scene import recorded_pressed

        names = {kind: _plugin_name(result, kind) for kind in ("spectrum", "solver", "slope")}
        pressed = recorded_pressed(names["spectrum"], names["solver"]) or names["spectrum"]
        table = result.table
        return cls(
            title=cut(_title(result.name, pressed, names["solver"], names["slope"]), SHOWN_LABEL_CHARS),
            f_label=cut(result.normalisation, SHOWN_LABEL_CHARS),
            f=table["f"], xi=table["xi"], xi_sem=table["xi_sem"], contact_count=table["contact_count"],
            fit=result.fit, done=result.realizations[0], caveats=tuple(shown_caveats(result.caveats)),
        )  # fmt: skip


def _title(name: str, pressed: str, solver: str, slope: str) -> str:
    return f"{name}: {pressed}, {solver}, {slope}"


def _plugin_name(result: Result, kind: str) -> str:
    """The name of the ``kind`` plugin in the preset ``result``'s folder recorded (untrusted: checked)."""
    section = result.preset.get(kind)
    name = section.get("name") if isinstance(section, dict) else None
    if not isinstance(name, str) or not name.strip():
        where = shown_name(Path(result.folder or ".") / "summary.json")
        raise RunFolderError(f"{where} is damaged: field 'preset.{kind}.name' must name the {kind} plugin the run used")
    return name


def plot_wanted(scene: Scene, outcome: RunOutcome) -> bool:
    """Whether a run has plot.png: the preset asks for it and some realization finished."""
    return bool(scene.preset.output.plot and outcome.done)


class DrawingProcess:
    """A process forked before a command's imports, which imports the plotting module and
    then draws the one plot.png it is sent. ``start()`` is None where none can be had;
    ``close()`` ends it (killed if it still waits or imports) and collects it."""

    def __init__(self, pid: int, connection: Connection) -> None:
        self.pid: int | None = pid
        self._connection = connection
        self._path: Path | None = None  # the figure it was sent: its temporary file is removed if it is killed

    @classmethod
    def start(cls) -> DrawingProcess | None:
        # fork only where it is the platform's own way (Linux), and with no other thread,
        # whose locks the child would inherit held
        if not sys.platform.startswith("linux") or threading.active_count() > 1:
            return None
        from multiprocessing.connection import Pipe

        import numpy  # noqa: F401 (both processes need it: imported once, before the fork)

        here, there = Pipe()
        for stream in (sys.stdout, sys.stderr):  # no buffered text printed twice
            try:
                stream.flush()
            except (OSError, ValueError, AttributeError):
                pass
        try:
            pid = os.fork()
        except OSError:  # a pids limit, no memory to copy the page tables
            here.close()
            there.close()
            return None
        if pid == 0:  # the child: it never returns into the command
            try:
                here.close()
                _serve(there)
            finally:
                os._exit(0)
        there.close()
        process = cls(pid, here)
        _forks_close(process)
        return process

    def send(self, path: Path, scene: Scene, outcome: RunOutcome) -> bool:
        """Have it draw ``path``, plot.png of ``outcome``, if the preset asks for it and anything
        finished (``plot_wanted``): False if not, or if the process is gone (``wait``)."""
        if self.pid is None or not plot_wanted(scene, outcome):
            return False
        self._path = Path(path)
        try:
            self._connection.send((str(path), CurveFigure.of(scene, outcome)))
        except OSError:  # it died: killed, out of memory
            self.close()
            return False
        return True

    def wait(self) -> bool:
        """Until the figure sent is written: True; a RunError as ``write_figure``'s if it could
        not be; False if the process died first (drawn here then)."""
        try:
            failure = self._connection.recv()
        except (OSError, EOFError):
            self.close()
            return False
        except BaseException:  # Ctrl-C while it draws: it is ended with this process
            self.close()
            raise
        self._path = None  # it answered: written, or its temporary file removed by atomic_write
        self.close()
        if failure is not None:
            raise RunError(failure)
        return True

    def close(self) -> None:
        if self.pid is None:
            return
        pid, self.pid = self.pid, None
        self._connection.close()
        if self in _open:
            _open.remove(self)
        try:
            os.kill(pid, signal.SIGKILL)  # nothing of its own to lose: it writes by atomic rename, or not at all
        except ProcessLookupError:
            pass
        try:
            os.waitpid(pid, 0)
        except ChildProcessError:
            pass
        if self._path is not None:  # killed while it wrote (the run ended by an error, a disk full)
            _remove_partial(self._path)


def _remove_partial(path: Path) -> None:
    """The temporary sibling ``io.files.atomic_write`` left of ``path`` in a process killed
    while writing it: the figure is then drawn again, or not at all, never half."""
    try:
        leftovers = [entry for entry in path.parent.iterdir()
                     if entry.name.startswith(f".{path.name}.") and entry.name.endswith(".tmp")]  # fmt: skip
    except OSError:
        return
    for entry in leftovers:
        try:
            entry.unlink()
        except OSError:
            pass


def _serve(connection: Connection) -> None:
    """The child: the plotting module imported (its failure is the drawing's to report),
    then one figure drawn, and its failure (or None) sent back."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # Ctrl-C is the command's to handle: it ends this process
    signal.signal(signal.SIGTERM, signal.SIG_DFL)
    try:
        import_module(PLOT_MODULE)
    except Exception:  # noqa: BLE001 (drawing imports it again, and reports the failure)
        pass
    try:
        path, figure = connection.recv()
    except (OSError, EOFError):  # the command ended without a figure
        return
    try:
        write_figure(Path(path), lambda fh: import_module(PLOT_MODULE).plot_curve(figure, fh))
        failure = None
    except RunError as exc:
        failure = str(exc)
    connection.send(failure)


_open: list[DrawingProcess] = []


def _forks_close(process: DrawingProcess) -> None:
    """A process forked later from this one (a pool's worker) closes its copy of the
    connection: the drawing process hears the command end only once every copy is closed."""
    if not _open and hasattr(os, "register_at_fork"):
        os.register_at_fork(after_in_child=_close_inherited)
    _open.append(process)


def _close_inherited() -> None:
    for process in _open:
        if process.pid is not None:
            process._connection.close()
            process.pid = None  # not this process's child: not killed or collected here
    _open.clear()

"""Fault-injecting plugins for the tests (importable by name, so worker
processes started by forkserver or spawn find them too).

* ``MidSendKiller``: a power-law line whose first worker process to make one
  dies while it sends its chunk's result to the parent: half of the message
  is written, then the process is killed (SIGKILL), as an OOM kill or a
  ``kill -9`` at the worst moment would do.
* ``CrashingPowerLaw``: a power-law line whose worker process (never the
  parent's) dies on the spot making one: the first to do so, or every one.
* ``FlakyPowerLaw``: a power-law line that fails (raises) for about a third
  of the realizations while a flag file exists, without touching the
  realization's random stream, so a rerun without the flag gives the clean
  numbers.
"""

from __future__ import annotations

import os
import signal
from multiprocessing import connection

import numpy as np

from frictionlab.preset import Scene
from frictionlab_spectra.power_law import PowerLaw


def _kill_mid_send(marker: str) -> None:
    """From now on, this process writes half of its next message on a pipe, notes
    how much in ``marker``, and dies."""
    original = connection.Connection._send

    def half_then_die(self, buf, write=os.write):
        data = bytes(buf)
        if len(data) < 64:  # a header sent apart from its body: let it through
            return original(self, buf)
        half = len(data) // 2
        written = 0
        while written < half:
            written += write(self._handle, data[written:half])
        with open(marker, "w") as fh:
            fh.write(f"{written} {len(data)}")
        os.kill(os.getpid(), signal.SIGKILL)

    connection.Connection._send = half_then_die


class MidSendKiller(PowerLaw):
    name = "mid-send-killer"

    class Params(PowerLaw.Params):
        flag: str  # created by the one worker that dies; its content: bytes sent of the message
        parent: int  # the process that must never die (the run's own)

    def generate(self, rng):
        p = self.params
        if os.getpid() != p.parent:
            try:
                os.close(os.open(p.flag, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
            except FileExistsError:
                pass
            else:
                _kill_mid_send(p.flag)
        return super().generate(rng)


class CrashingPowerLaw(PowerLaw):
    """The power-law line, but a worker process (never the test's own) that
    generates one dies on the spot: once per run (the first to create ``flag``),
    or every time (``always``)."""

    name = "crashing-power-law"

    class Params(PowerLaw.Params):
        flag: str
        parent: int
        always: bool = False

    def generate(self, rng):
        p = self.params
        if os.getpid() != p.parent:
            if p.always:
                os._exit(3)
            try:
                os.close(os.open(p.flag, os.O_CREAT | os.O_EXCL | os.O_WRONLY))
            except FileExistsError:
                pass
            else:
                os._exit(3)  # a killed worker: no exception, no cleanup
        return super().generate(rng)


class FlakyPowerLaw(PowerLaw):
    name = "flaky-power-law"

    class Params(PowerLaw.Params):
        flag: str  # while this file exists, about a third of the realizations fail

    def generate(self, rng):
        peek = np.random.Generator(type(rng.bit_generator)())
        peek.bit_generator.state = rng.bit_generator.state  # a look at the stream, not a draw from it
        if os.path.exists(self.params.flag) and peek.random() < 0.35:
            raise RuntimeError("a flaky failure")
        return super().generate(rng)


def with_spectrum(scene: Scene, cls, **extra) -> Scene:
    """``scene`` with its power-law spectrum replaced by ``cls`` (same parameters plus ``extra``)."""
    spectrum = cls(**scene.spectrum.params.model_dump(), **extra)
    return Scene(preset=scene.preset, spectrum=spectrum, solver=scene.solver, slope=scene.slope)

"""One Dask client for a command that runs many ensembles (a sweep, the exact 3D study,
the paper's report): the first run on Dask connects it (and starts this user's
``LocalCluster`` when no scheduler is given), the others reuse it, and it closes when
the command ends. A client and a cluster take 0.1 s to seconds to start: once per
command, not once per ensemble. Outside a session every run starts and closes its own.
"""

from __future__ import annotations

from collections.abc import Iterator
from contextlib import contextmanager
from contextvars import ContextVar

from . import dask_security
from ..options import RunOptions, default_workers


class DaskSession:
    """The client of the runs of one command on the scheduler ``scheduler`` (None: a
    ``LocalCluster`` of ``workers`` single-thread processes on loopback), connected by
    the first run that needs it."""

    def __init__(self, scheduler: str | None, workers: int, dashboard: bool = False):
        self.scheduler, self.workers, self.dashboard = scheduler, workers, dashboard
        self.client = None
        self.cluster = None

    def serves(self, options: RunOptions) -> bool:
        """Whether a run of ``options`` on Dask may use this session's client."""
        return options.scheduler == self.scheduler and options.dashboard == self.dashboard

    def connect(self):
        """The client, connected (and the cluster started) on first use."""
        if self.client is None:
            if self.scheduler:
                self.client = dask_security.connect_scheduler(self.scheduler)
            else:
                self.client, self.cluster = dask_security.start_local_cluster(self.workers, dashboard=self.dashboard)
        return self.client

    def close(self) -> None:
        client, cluster, self.client, self.cluster = self.client, self.cluster, None, None
        try:
            if client is not None:
                client.close()
        finally:
            if cluster is not None:
                cluster.close()


_session: ContextVar[DaskSession | None] = ContextVar("frictionlab_dask_session", default=None)


@contextmanager
def one_dask_cluster(options: RunOptions) -> Iterator[DaskSession]:
    """Within the block, every run on Dask with ``options``' scheduler shares one client
    (and one ``LocalCluster`` of ``options``' workers, every core by default), started by
    the first such run and closed at the end of the block. A block within another that
    serves the same options shares the outer one's. Nothing starts when no run uses Dask."""
    outer = _session.get()
    if outer is not None and outer.serves(options):
        yield outer
        return
    session = DaskSession(options.scheduler, options.workers or default_workers(), options.dashboard)
    token = _session.set(session)
    try:
        yield session
    finally:
        _session.reset(token)
        session.close()


def current_session(options: RunOptions) -> DaskSession | None:
    """The session of the enclosing ``one_dask_cluster`` block, if it serves ``options``."""
    session = _session.get()
    return session if session is not None and session.serves(options) else None

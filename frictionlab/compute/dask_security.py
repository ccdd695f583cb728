"""Who can reach the Dask cluster a run uses.

Anyone who can connect to a Dask scheduler can run code as the user of its
workers. So:

* without ``--scheduler``, frictionlab starts its own cluster on 127.0.0.1
  over TLS, with a certificate authority and keys made for this run alone
  (``distributed.Security.temporary()``, kept in memory): another user of the
  machine can reach the port but cannot complete the handshake. Its HTTP
  servers (scheduler and workers) serve nothing unless the dashboard is asked
  for (``--dashboard``, on 127.0.0.1 only).
* with ``--scheduler``, the connection uses Dask's own TLS settings (the
  ``distributed.comm.tls.*`` configuration, or ``--tls-ca-file``,
  ``--tls-cert``, ``--tls-key``); a ``tls://`` address needs them. An address
  that is neither loopback nor TLS gets a warning.
"""

from __future__ import annotations

import ipaddress
import logging
import warnings
from contextlib import contextmanager
from urllib.parse import urlsplit

from ..errors import FrictionlabError, MissingDependency, RunError, for_python, option_given, require, short_repr

DASK_PURPOSE = "the dask executor"
DASK_MISSING = str(MissingDependency("distributed", DASK_PURPOSE))
SCHEMES = ("tcp", "tls", "ws", "wss", "ucx", "inproc")
ENCRYPTED = ("tls", "wss")


def import_distributed():
    """``distributed`` (which imports ``dask``), or the message with the pip command."""
    return require("distributed", DASK_PURPOSE)


def use_tls_files(ca_file: str | None = None, cert: str | None = None, key: str | None = None) -> None:
    """Set Dask's TLS configuration for this process (what ``--tls-*`` give)."""
    import_distributed()
    import dask

    given = {"ca-file": ca_file, "client.cert": cert, "client.key": key}
    dask.config.set({f"distributed.comm.tls.{name}": value for name, value in given.items() if value})


_WARNED_PLAIN: set[str] = set()


def check_address(address: str) -> str:
    """``address`` if it is a scheduler address (``tcp://HOST:PORT``,
    ``tls://HOST:PORT``, or ``HOST:PORT`` for tcp); warns when it is neither
    loopback nor encrypted."""
    scheme, sep, _ = address.partition("://")
    scheme = scheme if sep else "tcp"
    try:
        parts = urlsplit(address if sep else f"tcp://{address}")
        host, port = parts.hostname, parts.port
    except ValueError:  # a port that is not a number, or out of range
        host = port = None
    if scheme not in SCHEMES or not host or not port:
        raise FrictionlabError(
            f"{option_given('--scheduler')} must be an address like tcp://HOST:PORT or tls://HOST:PORT. "
            f"Got {short_repr(address)} instead."
        )
    if scheme not in ENCRYPTED and not _loopback(host) and address not in _WARNED_PLAIN:
        _WARNED_PLAIN.add(address)  # checked by the command line and again on connecting: said once
        warnings.warn(
            f"the Dask scheduler at {address} is reached without TLS: anyone who can reach that address can run "
            "code as the user of its workers; use a tls:// address (see --tls-ca-file, --tls-cert, --tls-key)",
            stacklevel=2,
        )
    return address


def _loopback(host: str) -> bool:
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def _on_this_machine(address: str) -> bool:
    """Whether the scheduler at ``address`` is on loopback: its workers, on this machine too,
    can then be asked for results directly (through the scheduler, results travel twice;
    a remote cluster's workers may not be reachable from here)."""
    return _loopback(urlsplit(address).hostname or "")


def connect_scheduler(address: str):
    """A ``distributed.Client`` on the scheduler at ``address`` with Dask's TLS
    configuration, or a RunError that says why not."""
    distributed = import_distributed()
    check_address(address)
    security = distributed.Security()
    _check_answers_as_scheduler(address, security, CONNECT_SECONDS)
    try:
        return distributed.Client(
            address, timeout=f"{CONNECT_SECONDS}s", security=security, direct_to_workers=_on_this_machine(address)
        )
    except Exception as exc:  # refused, timed out, a TLS handshake or configuration that fails, ...
        reason = f"{type(exc).__name__}: {exc}"
        if address.startswith("tls://") and "ssl_context" in reason:  # what was given, not the network
            raise FrictionlabError(
                f"{option_given('--scheduler', address)}: a tls:// scheduler needs TLS certificates: "
                + ("configure them in Dask's distributed.comm.tls before the run" if for_python() else
                   "give --tls-ca-file, --tls-cert and --tls-key (or Dask's distributed.comm.tls configuration)")
            ) from None
        raise RunError(f"cannot reach the Dask scheduler at {address}: {short_repr(reason, 300)[1:-1]}") from None


CONNECT_SECONDS = 10


def _check_answers_as_scheduler(address: str, security, seconds: float) -> None:
    """RunError unless ``address`` answers Dask's ``identity`` request as a scheduler
    within ``seconds``: a Client would wait for minutes on a port that accepts and
    answers something else (an HTTP server, such as the dashboard's port)."""
    import asyncio
    import threading

    from distributed.comm import connect

    async def identity():
        comm = await connect(address, timeout=seconds, **security.get_connection_args("client"))
        try:
            await comm.write({"op": "identity", "reply": True})
            return await comm.read()
        finally:
            comm.abort()

    answer: list = []

    def ask() -> None:  # in a thread of its own: the caller may run an event loop (Jupyter)
        try:
            answer.append(asyncio.run(asyncio.wait_for(identity(), seconds)))
        except BaseException as exc:  # noqa: BLE001 - reported below
            answer.append(exc)

    thread = threading.Thread(target=ask, name="frictionlab-dask-handshake", daemon=True)
    thread.start()
    thread.join(seconds + 5)
    reply = answer[0] if answer else TimeoutError()
    if isinstance(reply, dict) and reply.get("type") == "Scheduler":
        return
    if address.startswith("tls://") and "ssl_context" in str(reply):
        return  # the missing certificates: said by the Client below, as before
    _refuse_nothing_listening(address, seconds)
    if isinstance(reply, BaseException) and not isinstance(reply, TimeoutError | asyncio.TimeoutError):
        reason = f"{type(reply).__name__}: {reply}"
        raise RunError(f"cannot reach the Dask scheduler at {address}: {short_repr(reason, 300)[1:-1]}")
    raise RunError(
        f"{option_given('--scheduler', address)} did not answer as a Dask scheduler within {seconds:g} s (is it another "
        "service, such as the dashboard's HTTP port? A scheduler listens on tcp://HOST:8786 by default)"
    )


def _refuse_nothing_listening(address: str, seconds: float) -> None:
    """RunError where nothing listens at ``address`` (the connection refused) or its host has no
    address: Dask retried those until its timeout, then asked whether the port was another service."""
    import socket

    parts = urlsplit(address if "://" in address else f"tcp://{address}")
    given = option_given("--scheduler", address)
    try:
        socket.create_connection((parts.hostname, parts.port), timeout=seconds).close()
    except ConnectionRefusedError:
        raise RunError(f"{given}: nothing listens there (the connection was refused): start the scheduler first "
                       "(dask scheduler), or give the address it listens on") from None  # fmt: skip
    except socket.gaierror as exc:
        raise RunError(f"{given}: no host named {short_repr(parts.hostname)} is known ({exc.strerror}): check "
                       "the address") from None  # fmt: skip
    except OSError:  # a timeout, a network that cannot be reached: said as before
        pass


# Dask's nanny gives its workers MALLOC_TRIM_THRESHOLD_=65536 (to hand freed memory back at
# once); glibc then maps every array above 128 KiB afresh, page faults and all: a 128^2
# half-space realization took 0.23 s instead of 0.16 s. This user's own cluster keeps glibc's
# adaptive default (None unsets the variable). Its workers do not sample their own stacks
# every 10 ms for the dashboard's profile page (4 % of a Fig. 2 task's time), unless the
# dashboard is asked for. Its workers log only what is critical: on a loaded machine a
# worker's heartbeat raced the cluster's close at the end of a run that had finished, and
# printed an ERROR with three tracebacks under its results (a task's failure is said by the run).
WORKER_CONFIG = {"distributed.nanny.pre-spawn-environ.MALLOC_TRIM_THRESHOLD_": None,
                 "distributed.nanny.pre-spawn-environ.DASK_LOGGING__DISTRIBUTED": "critical"}  # fmt: skip
PROFILE_OFF = {"distributed.worker.profile.enabled": False}


@contextmanager
def _said_if_not_started():
    """A local cluster whose processes did not start (``Nanny failed to start``: a system without
    the semaphores worker processes need, a full disk) is refused, naming its cause."""
    try:
        yield
    except (RuntimeError, OSError) as exc:
        cause = exc.__cause__ or exc.__context__
        why = f"{exc}" + (f" ({type(cause).__name__}: {cause})" if cause is not None else "")
        raise RunError(f"the local Dask cluster did not start: {why}") from None


def start_local_cluster(workers: int, dashboard: bool = False):
    """This user's own ``LocalCluster`` of ``workers`` single-thread processes on
    127.0.0.1 over TLS with credentials made now, and a client of it. Returns
    ``(client, cluster)``."""
    import dask

    distributed = import_distributed()
    try:
        security = distributed.Security.temporary()
    except ImportError:
        raise FrictionlabError(
            'the local Dask cluster is reached over TLS, which needs the cryptography package: '
            'pip install "frictionlab[dask]"'
        ) from None
    routes = {"distributed.scheduler.http.routes": [], "distributed.worker.http.routes": []}
    quiet = {} if dashboard else {**routes, **PROFILE_OFF}
    with dask.config.set({**quiet, **WORKER_CONFIG}), _said_if_not_started():
        cluster = distributed.LocalCluster(
            n_workers=workers,
            threads_per_worker=1,
            processes=True,
            host="127.0.0.1",
            protocol="tls://",
            security=security,
            dashboard_address=None,  # read as "no dashboard": the scheduler's own flag below says it
            scheduler_kwargs={"dashboard_address": "127.0.0.1:0", "dashboard": dashboard},  # loopback, any free port
            silence_logs=logging.ERROR,
        )
    try:
        client = distributed.Client(cluster, security=security, direct_to_workers=True)
    except BaseException:
        cluster.close()
        raise
    if dashboard:
        import sys

        print(f"Dask dashboard: {cluster.dashboard_link}", file=sys.stderr, flush=True)
    return client, cluster

"""The Dask cluster of a batch (``pbrkit batch``, :mod:`pbrkit.app.batch`): a
``LocalCluster`` of worker processes on this machine, or the scheduler that
``--scheduler ADDRESS`` names.

The address is untrusted input, and so is whatever answers there:

- :func:`check_scheduler_address` checks it before anything starts (and
  before Dask is imported): a scheme Dask connects with
  (:data:`SCHEDULER_SCHEMES`), a host, and a port in 1-65535
  (``inproc://`` addresses, Dask's in-process transport, name no port);
- :func:`connect_scheduler` gives up after a stated time
  (:data:`DEFAULT_SCHEDULER_TIMEOUT`, 30 s; ``--scheduler-timeout``): before
  the ``distributed.Client`` is made, :func:`probe_scheduler` connects with
  Dask's own transport, exchanges its handshake and asks for the scheduler's
  identity, all under one deadline (Dask's own ``Client(timeout=...)`` covers
  the TCP connection only: a server that accepts it and never answers holds
  the client for ever), and without unpickling anything.  Every failure --
  connection refused, an unknown host, no answer, a server that is not Dask
  (an HTTP server, random bytes: Dask then fails with whatever its decoder
  meets, ``MemoryError`` for a bogus length header included), a Dask worker
  rather than a scheduler -- is one line, :class:`SchedulerUnreachable`:
  ``--scheduler tcp://HOST:PORT: no Dask scheduler answered within 30 s
  (connection refused)``, never the bytes the server sent.

Dask's own trust model is unchanged: the scheduler and its workers, once
connected, are trusted (they exchange pickled tasks and results).
"""

from __future__ import annotations

import contextlib
import ipaddress
import math
import os
import re
import sys
import threading
import warnings

__all__ = [
    "SCHEDULER_SCHEMES",
    "DEFAULT_SCHEDULER_TIMEOUT",
    "SchedulerUnreachable",
    "check_scheduler_address",
    "check_scheduler_timeout",
    "probe_scheduler",
    "connect_scheduler",
    "dask_client",
    "default_workers",
    "cache_state",
    "cache_is_cold",
]

#: The schemes of a ``--scheduler`` address (Dask's transports: TCP, TLS, websockets, in-process).
SCHEDULER_SCHEMES = ("tcp", "tls", "ws", "wss", "inproc")
#: Seconds a ``--scheduler`` has to answer (``--scheduler-timeout``): connection, handshake and identity.
DEFAULT_SCHEDULER_TIMEOUT = 30.0
#: The longest ``--scheduler-timeout``, in seconds.
MAX_SCHEDULER_TIMEOUT = 3600.0
#: Seconds the scheduler may take to get its first worker before a batch gives up.
WORKERS_TIMEOUT = 60.0

_EXAMPLE = "expected an address such as tcp://HOST:PORT"
_HOST_NAME = re.compile(r"^[A-Za-z0-9_](?:[A-Za-z0-9_.-]{0,251}[A-Za-z0-9_])?$")


class SchedulerUnreachable(OSError):
    """No Dask scheduler answered at a ``--scheduler`` address in time; the message
    is one line naming the address, the time and the reason."""


def _shown(text, limit=80):
    """A user-typed value in a message: escaped (control characters), cut to ``limit``."""
    from ..core.inputs import describe

    return describe(text, limit)


def check_scheduler_address(address):
    """``address`` as Dask takes it (``scheme://HOST:PORT``; the scheme in lower
    case), or ValueError naming ``--scheduler`` and what was expected: a scheme of
    :data:`SCHEDULER_SCHEMES`, a host name, IPv4 address or bracketed IPv6 address
    (``tcp://[::1]:8786``) and a port in 1-65535.  Imports nothing of Dask."""
    text = str(address)
    scheme, sep, location = text.partition("://")
    if not sep or not scheme:
        raise ValueError(f"--scheduler: {_EXAMPLE}; got {_shown(text)}")
    scheme = scheme.lower()
    if scheme not in SCHEDULER_SCHEMES:
        raise ValueError(f"--scheduler: unknown scheme {_shown(scheme, 24)}; {_EXAMPLE} (schemes: "
                         f"{', '.join(SCHEDULER_SCHEMES)}); got {_shown(text)}")
    if scheme == "inproc":
        if not location or any(c.isspace() or not c.isprintable() for c in location):
            raise ValueError(f"--scheduler: expected an in-process address inproc://HOST/PID/N; got {_shown(text)}")
        return f"{scheme}://{location}"
    if location.startswith("["):  # [IPv6]:PORT
        host, bracket, tail = location[1:].partition("]")
        port, has_port = tail[1:], tail.startswith(":")
        try:
            ipaddress.IPv6Address(host)
        except ValueError:
            raise ValueError(f"--scheduler: {_shown(host, 50)} is not an IPv6 address; {_EXAMPLE} "
                             "(IPv6: tcp://[::1]:8786)") from None
        if not bracket:
            raise ValueError(f"--scheduler: no closing ']' after the IPv6 address; {_EXAMPLE}")
    else:
        host, has_port, port = location.rpartition(":")
        host, has_port = (host, True) if has_port else (location, False)
        if ":" in host:
            raise ValueError(f"--scheduler: an IPv6 host goes in brackets (tcp://[::1]:8786); got {_shown(text)}")
        if not host:
            raise ValueError(f"--scheduler: no host; {_EXAMPLE}; got {_shown(text)}")
        if not _HOST_NAME.match(host):
            raise ValueError(f"--scheduler: {_shown(host, 50)} is not a host name or IP address; {_EXAMPLE}")
    if not has_port:
        raise ValueError(f"--scheduler: no port; {_EXAMPLE}; got {_shown(text)}")
    if not (port.isascii() and port.isdigit()) or not 1 <= int(port) <= 65535:
        raise ValueError(f"--scheduler: the port must be a number in 1-65535; got {_shown(port, 24)} "
                         f"({_EXAMPLE})")
    return f"{scheme}://{location[:len(location) - len(port)]}{int(port)}"


def check_scheduler_timeout(seconds):
    """``seconds`` as a float if it is a finite number in (0, :data:`MAX_SCHEDULER_TIMEOUT`],
    else ValueError naming ``--scheduler-timeout``."""
    try:
        value = float(seconds)
    except (TypeError, ValueError):
        value = math.nan
    if isinstance(seconds, bool) or not math.isfinite(value) or not 0 < value <= MAX_SCHEDULER_TIMEOUT:
        raise ValueError(f"--scheduler-timeout: expected seconds in (0, {MAX_SCHEDULER_TIMEOUT:g}]; "
                         f"got {_shown(seconds, 24)}")
    return value


def _seconds_text(seconds):
    return f"{seconds:g} s"


def _unreachable(address, timeout, reason):
    return SchedulerUnreachable(f"--scheduler {address}: no Dask scheduler answered within "
                                f"{_seconds_text(timeout)} ({reason})")


def _chain(exc):
    """``exc`` and the exceptions it was raised from or during, outermost first."""
    seen = []
    while exc is not None and exc not in seen:
        seen.append(exc)
        exc = exc.__cause__ or exc.__context__
    return seen


def _connect_reason(exc):
    """Why a connection failed, in a few words, from the exceptions chained to ``exc``,
    and whether to try again (a refused connection: the scheduler may be starting)."""
    import socket

    for e in reversed(_chain(exc)):  # innermost first: the socket's own error
        if isinstance(e, ConnectionRefusedError):
            return "connection refused", True
        if isinstance(e, socket.gaierror):
            return "unknown host", False
        if isinstance(e, OSError) and e.errno is not None and e.strerror:
            return e.strerror[:1].lower() + e.strerror[1:], False
    if any(type(e).__name__ in ("CommClosedError", "StreamClosedError") for e in _chain(exc)):
        return "the server closed the connection: not a Dask scheduler", False
    return f"could not connect ({type(exc).__name__})", False


class _Failed(Exception):
    """The probe of a ``--scheduler`` gave up; the message is the reason, in a few words."""


async def _identity(address, timeout, connection_args):
    """The scheduler's identity (a dict), asked with Dask's transport under one
    deadline: its connector (a refused connection tried again until the deadline, as
    Dask's own ``connect`` does), the handshake of ``distributed.comm.core.connect``
    and an ``identity`` request, nothing unpickled."""
    import asyncio

    from distributed.comm.addressing import parse_address
    from distributed.comm.registry import get_backend
    from distributed.core import send_recv

    loop = asyncio.get_running_loop()
    deadline = loop.time() + timeout

    def left():
        return max(deadline - loop.time(), 0.0)

    scheme, location = parse_address(address)
    connector = get_backend(scheme).get_connector()
    reason, pause = "the connection was neither accepted nor refused", 0.05
    while True:
        try:
            comm = await asyncio.wait_for(connector.connect(location, deserialize=False, **connection_args), left())
            break
        except asyncio.TimeoutError:
            raise _Failed(reason) from None
        except OSError as exc:  # Dask's CommClosedError included
            reason, again = _connect_reason(exc)
            if not again or left() <= pause:
                raise _Failed(reason) from None
        await asyncio.sleep(pause)
        pause = min(2 * pause, 1.0)
    try:
        try:
            local = comm.handshake_info()
            await asyncio.wait_for(comm.write(local), left())
            remote = await asyncio.wait_for(comm.read(), left())
        except asyncio.TimeoutError:
            raise _Failed("the server accepted the connection but sent no Dask handshake") from None
        remote["address"], local["address"] = comm.peer_address, comm.local_address
        comm.remote_info, comm.local_info = remote, local
        comm.handshake_options = comm.handshake_configuration(local, remote)
        try:
            return await asyncio.wait_for(send_recv(comm, op="identity"), left())
        except asyncio.TimeoutError:
            raise _Failed("the server accepted the connection but did not answer") from None
    finally:
        comm.abort()


def _failure_reason(exc):
    """Why the probe of a ``--scheduler`` failed, in a few words (never what the server sent)."""
    if isinstance(exc, _Failed):
        return str(exc)
    if type(exc).__name__ in ("CommClosedError", "FatalCommClosedError", "StreamClosedError") \
            or isinstance(exc, EOFError):
        return "the server closed the connection: not a Dask scheduler"
    if isinstance(exc, OSError) and exc.errno is not None:
        return _connect_reason(exc)[0]
    return f"the server's answer is not Dask's protocol: {type(exc).__name__}"


def _in_thread(function, timeout, name):
    """``function()`` run in a daemon thread, waited for ``timeout`` seconds: (True, result),
    (False, exception) or (None, None) when it did not return in time."""
    box = {}

    def target():
        try:
            box["value"] = function()
        except BaseException as exc:  # noqa: BLE001 - handed to the caller, which words it
            box["error"] = exc

    thread = threading.Thread(target=target, name=name, daemon=True)
    thread.start()
    thread.join(timeout)
    if thread.is_alive():
        return None, None
    return ("error" not in box), box.get("error", box.get("value"))


def _connection_args(address):
    """The client's connection arguments from Dask's configuration (TLS), None for a
    TLS address without a TLS configuration."""
    from distributed.security import Security

    args = Security().get_connection_args("client")
    if address.split("://", 1)[0] in ("tls", "wss") and args.get("ssl_context") is None:
        return None
    return args


def probe_scheduler(address, timeout=DEFAULT_SCHEDULER_TIMEOUT):
    """The identity (a dict) of the Dask scheduler at ``address`` (checked with
    :func:`check_scheduler_address`), or :class:`SchedulerUnreachable` once
    ``timeout`` seconds have passed or as soon as the answer shows no scheduler
    is there (module doc)."""
    import asyncio

    address = check_scheduler_address(address)
    timeout = check_scheduler_timeout(timeout)
    import distributed.comm  # noqa: F401 - imported here, not on the probe's clock
    import distributed.core  # noqa: F401

    args = _connection_args(address)
    if args is None:
        raise _unreachable(address, timeout, "a TLS address needs Dask's TLS configuration: "
                                             "distributed.comm.tls.ca-file, client.cert and client.key")
    done, value = _in_thread(lambda: asyncio.run(_identity(address, timeout, args)), timeout + 5.0,
                             "pbrkit-scheduler-probe")
    if done is None:
        raise _unreachable(address, timeout, "no answer")
    if not done:
        if isinstance(value, (KeyboardInterrupt, SystemExit)):
            raise value
        raise _unreachable(address, timeout, _failure_reason(value)) from None
    identity = value
    kind = identity.get("type") if isinstance(identity, dict) else None
    if kind in ("Worker", "Nanny"):
        raise _unreachable(address, timeout, f"a Dask {kind.lower()} answers there, not a scheduler")
    if kind != "Scheduler":
        raise _unreachable(address, timeout, "the server's answer is not a Dask scheduler's identity")
    return identity


def connect_scheduler(address, timeout=DEFAULT_SCHEDULER_TIMEOUT):
    """A ``distributed.Client`` of the scheduler at ``address``: probed first
    (:func:`probe_scheduler`), then connected, each step within ``timeout``
    seconds; :class:`SchedulerUnreachable` (one line) for every failure."""
    from distributed import Client

    address = check_scheduler_address(address)
    timeout = check_scheduler_timeout(timeout)
    probe_scheduler(address, timeout)
    abandoned = threading.Event()

    def make():
        client = Client(address, timeout=timeout)
        if abandoned.is_set():  # given up meanwhile: do not keep a connection nobody uses
            client.close()
        return client

    done, value = _in_thread(make, timeout + 5.0, "pbrkit-scheduler-client")
    if done is None:
        abandoned.set()
        raise _unreachable(address, timeout, "the client's connection stalled after the scheduler answered")
    if not done:
        if isinstance(value, (KeyboardInterrupt, SystemExit)):
            raise value
        raise _unreachable(address, timeout, _failure_reason(value)) from None
    return value


# =================================================================== cluster


def cache_state(kind="bake"):
    """(cache directory, whether it holds compiled kernels of the subpackage the
    batch's tasks use: ``ibl`` for bakes, ``rendering`` for renders), as seen by the
    process that calls it (a worker)."""
    from ..core.cache import cache_directory, cached_kernels

    return str(cache_directory()), cached_kernels("ibl" if kind == "bake" else "rendering")


def cache_is_cold(client, kind):
    """True when every worker reports the same Numba cache directory and it has no
    kernels yet for ``kind`` (:func:`cache_state`): the batch then runs its first
    input alone, so that the other workers load what it compiled."""
    try:
        states = client.run(cache_state, kind)
    except Exception:  # a worker that cannot answer: no warm-up
        return False
    folders = {folder for folder, _ in states.values()}
    return bool(states) and len(folders) == 1 and not any(warm for _, warm in states.values())


def default_workers():
    """Worker processes of a LocalCluster by default: the cores this process may use."""
    try:
        return max(1, len(os.sched_getaffinity(0)))
    except (AttributeError, OSError):
        return max(1, os.cpu_count() or 1)


#: Modules a task imports (at its top or inside functions), imported once in this process
#: before a LocalCluster forks its workers, so that no worker imports them again.
_TASK_MODULES = {
    "bake": ("pbrkit.ibl.bake", "pbrkit.io.bake_files", "pbrkit.io.environment", "pbrkit.io.images",
             "pbrkit.albedo.tables", "pbrkit.ibl.sh", "pbrkit.ibl.spectral", "pbrkit.ibl.irradiance",
             "pbrkit.io.ktx2", "pbrkit.io.ktx1", "pbrkit.io.dds", "pbrkit.io.exr", "pbrkit.io.png",
             "pbrkit.io.lut_files", "pbrkit.io.babylon_env", "imageio.v3", "imageio.plugins.pillow"),
    "render": ("pbrkit.rendering.run", "pbrkit.rendering.scene", "pbrkit.npr.style", "pbrkit.npr.render",
               "pbrkit.io.environment", "pbrkit.io.images", "pbrkit.io.exr", "pbrkit.io.png", "pbrkit.ibl.bake",
               "pbrkit.io.bake_files", "pbrkit.albedo.tables", "imageio.v3", "imageio.plugins.pillow"),
}


def _fork_is_safe():
    """Whether a LocalCluster may fork its workers from this process: Linux (macOS's
    system libraries are not fork-safe, Windows cannot fork), and Numba's
    threading layer not launched here (a forked OpenMP or workqueue pool hangs in
    the child; the command's own process runs no kernel, a script that baked
    before calling :func:`pbrkit.app.batch.run_batch` has launched it)."""
    if not sys.platform.startswith("linux") or not hasattr(os, "register_at_fork"):
        return False
    parallel = sys.modules.get("numba.np.ufunc.parallel")
    return not getattr(parallel, "_is_initialized", False)


def _signals_as_default():
    """In a forked worker: SIGTERM and SIGINT as in a new Python process (the
    command's handlers, which raise in its main thread, are not the worker's)."""
    import signal

    with contextlib.suppress(ValueError, OSError):
        signal.signal(signal.SIGTERM, signal.SIG_DFL)
        signal.signal(signal.SIGINT, signal.default_int_handler)


_AT_FORK = []


@contextlib.contextmanager
def dask_client(scheduler=None, workers=None, threads=None, kind="bake", dashboard=True,
                scheduler_timeout=DEFAULT_SCHEDULER_TIMEOUT):
    """A ``distributed.Client``, and a line describing the cluster.

    With ``scheduler`` (``tcp://HOST:PORT``): a client of that scheduler (its
    workers as they were started), connected by :func:`connect_scheduler` within
    ``scheduler_timeout`` seconds.  Else a ``LocalCluster`` of ``workers``
    processes (default :func:`default_workers`), one Dask thread each (a task
    at a time) and ``threads`` (default 1) Numba threads for the parallel
    kernels inside a task (the jobs carry it: :func:`pbrkit.app.batch.run_task`
    calls ``numba.set_num_threads``).  Its workers share this process's Numba
    cache (``PBRKIT_CACHE_DIR``).  They are forked from this process, with the
    modules of ``kind``'s tasks already imported (:data:`_TASK_MODULES`), when
    that is safe (:func:`_fork_is_safe`); else spawned as fresh interpreters
    (Dask's default), which costs each about a second more to start and to
    import, and a second more to stop.  ``dashboard``: the scheduler's Bokeh
    dashboard on port 8787 (another if that one is taken), about 1 s of the
    start on the 2-core machine."""
    import logging

    import dask
    from distributed import LocalCluster

    if scheduler is not None:
        scheduler = check_scheduler_address(scheduler)
        client = connect_scheduler(scheduler, scheduler_timeout)
        try:
            n = len(client.scheduler_info().get("workers", {}))
            if n == 0:
                client.wait_for_workers(1, timeout=WORKERS_TIMEOUT)
                n = len(client.scheduler_info().get("workers", {}))
        except (OSError, TimeoutError):
            client.close()
            raise OSError(f"--scheduler {scheduler}: the scheduler has no workers (waited "
                          f"{WORKERS_TIMEOUT:g} s)") from None
        try:
            yield client, f"scheduler {scheduler} ({n} worker{'s' if n != 1 else ''})"
        finally:
            client.close()
        return
    from distributed import Client

    workers = default_workers() if workers is None else int(workers)
    threads = 1 if threads is None else int(threads)
    env = {}
    if os.environ.get("PBRKIT_CACHE_DIR"):
        env["PBRKIT_CACHE_DIR"] = os.environ["PBRKIT_CACHE_DIR"]
    method = "fork" if _fork_is_safe() else "spawn"
    if method == "spawn":  # a forked worker keeps Numba's configuration (and uses numba.set_num_threads)
        env["NUMBA_NUM_THREADS"] = str(threads)
    else:
        import importlib

        for name in _TASK_MODULES.get(kind, ()):
            with contextlib.suppress(ImportError):
                importlib.import_module(name)
        if not _AT_FORK:
            os.register_at_fork(after_in_child=_signals_as_default)
            _AT_FORK.append(True)
    with dask.config.set({"distributed.worker.multiprocessing-method": method}):  # restarts too
        with warnings.catch_warnings():
            warnings.filterwarnings("ignore", message=r"Port \d+ is already in use")  # it picks another
            cluster = LocalCluster(n_workers=workers, threads_per_worker=1, processes=True,
                                   silence_logs=logging.ERROR, env=env,
                                   dashboard_address=":8787" if dashboard else None)
        try:
            client = Client(cluster)
            try:
                yield client, (f"LocalCluster: {workers} worker{'s' if workers != 1 else ''} x "
                               f"{threads} Numba thread{'s' if threads != 1 else ''}")
            finally:
                client.close()
        finally:
            cluster.close()

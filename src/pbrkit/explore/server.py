"""The explorer's local web server (:func:`run`): a Panel / Bokeh server on the
loopback address that answers only requests made to it by a loopback name.

Binding to 127.0.0.1 keeps other machines out, but not other web sites: a page
on ``evil.example`` whose name is re-pointed at 127.0.0.1 (DNS rebinding) is,
for the browser, on the same origin as the server, so it could read the page
and its session token and open the websocket.  Bokeh checks only a websocket's
``Origin`` against ``websocket_origin``, and Tornado (6.6) skips that check
when ``Origin`` equals ``Host`` or ``Sec-Fetch-Site`` says same-origin, which a
rebinding pair always satisfies; nothing checks ``Host``.  So every request
(page, static files, websocket) passes :func:`refusal` first, as Jupyter
server's ``check_host`` does (``allow_remote_access`` off, ``local_hostnames``):

- its ``Host`` is a loopback name with the served port (:func:`allowed_hosts`:
  ``127.0.0.1:PORT``, ``localhost:PORT``; not ``[::1]:PORT``: the server does
  not listen on ::1, and Panel 1.9 cannot parse a bracketed host: error 500);
- its ``Origin``, if it has one, is ``http://127.0.0.1:PORT`` or
  ``http://localhost:PORT`` (:func:`allowed_origins`).

Anything else gets ``403 Forbidden`` with a fixed short body: no page, no token,
no websocket.  References: the DNS rebinding attack (Jackson et al.,
"Protecting browsers from DNS rebinding attacks", CCS 2007); Jupyter server's
``JupyterHandler.check_host``; Tornado's ``WebSocketHandler.check_origin``.

While serving, the ``bokeh``, ``tornado`` and ``panel`` loggers are silenced
(:func:`quiet_library_logs`): refused or malformed requests make them log
warnings and tracebacks that are not the user's concern; pbrkit's own lines
are printed, not logged, and still show.
"""

from __future__ import annotations

import contextlib
import errno
import logging
import socket

__all__ = ["ADDRESS", "LOOPBACK_NAMES", "LIBRARY_LOGGERS", "ListenError", "allowed_hosts", "allowed_origins",
           "refusal", "quiet_library_logs", "check_port", "free_port", "run"]

#: The only address served.
ADDRESS = "127.0.0.1"
#: The names under which a request may reach the server (with the served port).
LOOPBACK_NAMES = ("127.0.0.1", "localhost")
#: The libraries whose log lines are kept off the terminal while serving.
LIBRARY_LOGGERS = ("bokeh", "tornado", "panel")
_REFUSED_BODY = b"403 Forbidden: this server answers only http://127.0.0.1:PORT/ and http://localhost:PORT/\n"


class ListenError(OSError):
    """The server cannot listen on ``port`` (in use, or not allowed); ``errno`` and
    ``strerror`` are the operating system's; the message names ``--port``."""

    def __init__(self, port, exc):
        super().__init__(exc.errno, exc.strerror or str(exc))
        self.port = port

    def __str__(self):
        if self.errno == errno.EADDRINUSE:
            return (f"--port {self.port}: in use (another program listens on {ADDRESS}:{self.port}); "
                    f"choose another port, or 0 for a free one")
        return f"--port {self.port}: cannot listen on {ADDRESS}:{self.port} ({self.strerror})"


def allowed_hosts(port):
    """The ``Host`` header values accepted: each loopback name with ``port``."""
    return frozenset(f"{name}:{int(port)}" for name in LOOPBACK_NAMES)


def allowed_origins(port):
    """The ``Origin`` header values accepted: ``http://`` and an allowed host."""
    return frozenset(f"http://{host}" for host in allowed_hosts(port))


def refusal(headers, port):
    """Why a request with these headers (a mapping; Tornado's ``HTTPHeaders`` joins
    repeated headers with commas) is refused, or None when it is allowed (module
    doc).  Names are compared case-insensitively; a missing ``Host`` is refused."""
    host = (headers.get("Host") or "").strip().lower()
    if host not in allowed_hosts(port):
        return "foreign Host"
    origin = headers.get("Origin")
    if origin is not None and origin.strip().lower() not in allowed_origins(port):
        return "foreign Origin"
    return None


def _guard(tornado_app, port):
    """Put the :func:`refusal` check in front of every route of ``tornado_app`` (a
    ``tornado.web.Application``): a rule first in its default router, whose
    matcher takes the refused requests to a handler that answers 403 whatever the
    method (a websocket upgrade included: no 101)."""
    from tornado import web
    from tornado.routing import Matcher, Rule

    class Refused(web.RequestHandler):
        def prepare(self):
            self.clear()
            self.set_status(403)
            self.set_header("Content-Type", "text/plain; charset=utf-8")
            self.set_header("Cache-Control", "no-store")
            self.finish(_REFUSED_BODY)

        def check_xsrf_cookie(self):  # refused in prepare anyway
            pass

    class Foreign(Matcher):
        def match(self, request):
            return {} if refusal(request.headers, port) is not None else None

    router = tornado_app.default_router
    router.rules.insert(0, router.process_rule(Rule(Foreign(), Refused, name="pbrkit-loopback-only")))


@contextlib.contextmanager
def quiet_library_logs(names=LIBRARY_LOGGERS):
    """Within the block, the loggers ``names`` and their existing children log
    nothing (a level above CRITICAL; children created later inherit it); their
    levels are restored after."""
    loggers = [logging.getLogger(n) for n in names]
    loggers += [lg for key, lg in list(logging.root.manager.loggerDict.items())
                if isinstance(lg, logging.Logger) and any(key.startswith(n + ".") for n in names)]
    saved = [(lg, lg.level) for lg in loggers]
    for lg in loggers:
        lg.setLevel(logging.CRITICAL + 1)
    try:
        yield
    finally:
        for lg, level in saved:
            lg.setLevel(level)


def check_port(port):
    """Raise :class:`ListenError` if nothing could listen on 127.0.0.1:``port`` now
    (bound as Tornado binds, with ``SO_REUSEADDR``: a port in TIME_WAIT is free);
    port 0 is always free."""
    if port == 0:
        return
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        try:
            s.bind((ADDRESS, port))
            s.listen(1)
        except OSError as exc:
            raise ListenError(port, exc) from None


def free_port():
    """A TCP port free on 127.0.0.1 now (the OS's choice for port 0)."""
    with socket.socket(socket.AF_INET, socket.SOCK_STREAM) as s:
        s.bind((ADDRESS, 0))
        return s.getsockname()[1]


def run(make_layout, port=0, open_browser=True, announce=print, title="pbrkit explore"):
    """Serve ``make_layout()`` (a new Panel object per browser session) on
    http://127.0.0.1:PORT/ until the IO loop stops (Ctrl-C raises
    KeyboardInterrupt); port 0 picks a free one.  Requests pass :func:`refusal`;
    library logs are off (:func:`quiet_library_logs`); ``announce`` receives the
    URL once the server listens.  A port that cannot be bound raises
    :class:`ListenError`."""
    import panel as pn

    if port == 0:
        port = free_port()
    with quiet_library_logs():
        try:
            server = pn.serve({"/": make_layout}, port=port, address=ADDRESS, show=open_browser, start=False,
                              websocket_origin=sorted(allowed_hosts(port)), title=title,
                              verbose=False)
        except OSError as exc:
            raise ListenError(port, exc) from None
        tornado_app = getattr(server, "_tornado", None)  # bokeh.server.server.Server's BokehTornado
        if tornado_app is None or not hasattr(tornado_app, "default_router"):
            server.stop()
            raise RuntimeError("cannot check the Host of requests with this Bokeh version (no Tornado application)")
        _guard(tornado_app, port)
        server.start()
        announce(f"http://{ADDRESS}:{server.port}/")
        try:
            server.io_loop.start()
        finally:
            server.stop()

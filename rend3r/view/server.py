"""The view's web server (Tornado): the page, its JSON and PNG endpoints, and a websocket
that tells the page when the program changed (``docs/view.md``).

Safety: only the page's own files (read once at start, by name) and the program given on
the command line are served; requests must name this server as their ``Host`` (a web page
elsewhere cannot reach it by DNS rebinding); on a non-loopback address every request needs
the random token printed with the URL. Work runs on one worker thread, so a request's
cost is bounded by its parameters' limits and requests do not pile up in memory.
"""

from __future__ import annotations

import asyncio
import hmac
import ipaddress
import json
import secrets
import sys
from concurrent.futures import ThreadPoolExecutor
from importlib import resources
from pathlib import Path

import numpy as np
import tornado.web
import tornado.websocket
from tornado.httpserver import HTTPServer
from tornado.ioloop import IOLoop, PeriodicCallback
from tornado.netutil import bind_sockets

from ..errors import Rend3rError
from . import frames as fr
from . import svo as sv
from .params import RequestError, integer, one
from .source import ProgramSource

#: How often the program's files are looked at (a save shows within this plus a render).
POLL_MS = 200
#: Types of the page's own files, by suffix.
TYPES = {".html": "text/html; charset=utf-8", ".js": "text/javascript; charset=utf-8",
         ".css": "text/css; charset=utf-8", ".svg": "image/svg+xml"}


def is_loopback(host: str) -> bool:
    """Whether ``host`` names this machine only (``localhost``, 127.0.0.0/8, ``::1``)."""
    if host == "localhost":
        return True
    try:
        return ipaddress.ip_address(host.strip("[]")).is_loopback
    except ValueError:
        return False


def static_files() -> dict[str, tuple[bytes, str]]:
    """The page's files: name -> (bytes, type), read once; a file whose real path leaves the
    package's ``static`` folder (a symlink out) is not served."""
    root = Path(str(resources.files("rend3r.view") / "static")).resolve()
    out = {}
    for p in sorted(root.iterdir()):
        real = p.resolve()
        if p.is_file() and real.parent == root and p.suffix in TYPES:
            out[p.name] = (real.read_bytes(), TYPES[p.suffix])
    return out


class View:
    """What the handlers share: the program, caches, the worker thread and the live sockets."""

    def __init__(self, program: str, token: str | None, hosts: set[str], frames: int) -> None:
        self.source = ProgramSource(program)
        self.max_frames = frames
        self.token, self.hosts = token, hosts
        self.files = static_files()
        self.frames = fr.FrameCache()
        self.traces = fr.TraceCache()
        self.svo_cache: tuple[tuple, object] | None = None
        self.work = ThreadPoolExecutor(1, thread_name_prefix="rend3r-view")
        self.watch = ThreadPoolExecutor(1, thread_name_prefix="rend3r-watch")
        self.sockets: set[LiveSocket] = set()
        self._polling = False

    async def poll(self) -> None:
        """Reload the program if its files changed, and tell every page."""
        if self._polling:
            return
        self._polling = True
        try:
            changed = await IOLoop.current().run_in_executor(self.watch, self.source.refresh)
        except Exception as exc:  # a bug in reloading must not stop the server or print a traceback
            print(f"rend3r view: cannot reload {self.source.path}: {type(exc).__name__}: {exc}", file=sys.stderr)
            return
        finally:
            self._polling = False
        if changed:
            message = json.dumps({"type": "reload", **status(self)})
            for s in list(self.sockets):
                try:
                    s.write_message(message)
                except tornado.websocket.WebSocketClosedError:
                    self.sockets.discard(s)

    def good(self):
        """The last program that loaded; 409 when none has."""
        good = self.source.state.good
        if good is None:
            raise RequestError("the program has not loaded yet: see its diagnostics (/api/status)", 409)
        return good

    def svo_render(self, view: sv.SvoView):
        """The model's render for ``view`` (the last one is kept)."""
        good = self.good()
        if good.svo is None:
            raise RequestError("the program is not an .svo model", 404)
        key = (self.source.state.version, view)
        if self.svo_cache is None or self.svo_cache[0] != key:
            self.svo_cache = (key, sv.render(good.svo, view))
        return good.svo, self.svo_cache[1]


def status(view: View) -> dict:
    """The program's state: version, kind, mode, diagnostics."""
    from ..emu.quirks import PROFILES, QUIRKS

    st = view.source.state
    good = st.good
    return {"program": str(view.source.path), "kind": view.source.kind, "version": st.version,
            "ok": not st.message, "loaded": good is not None, "mode": None if good is None else good.mode,
            "message": st.message, "diagnostics": st.diagnostics,
            "profiles": list(PROFILES), "quirks": {q.name: q.summary for q in QUIRKS.values()}}


class Handler(tornado.web.RequestHandler):
    """Every endpoint: the token and Host checks, JSON errors, no traceback ever."""

    @property
    def view(self) -> View:
        return self.application.settings["view"]

    def prepare(self) -> None:
        v = self.view
        if v.token is not None and self.request.path.startswith("/static/"):
            return  # the page's own files: the same for everyone, nothing of the program's
        if v.token is not None:
            given = self.get_query_argument("token", "")
            if not hmac.compare_digest(given.encode(), v.token.encode()):
                raise RequestError("a valid token is required (the URL rend3r view printed)", 403)
        elif self.request.host.lower() not in v.hosts:
            raise RequestError(f"Host {self.request.host[:80]!r} is not this server", 403)

    def write_error(self, status_code: int, **kwargs) -> None:
        exc = kwargs.get("exc_info", (None, None, None))[1]
        if isinstance(exc, (RequestError, Rend3rError)):
            message = str(exc)
        elif isinstance(exc, tornado.web.HTTPError):
            message = exc.log_message or self._reason
        else:
            message = "internal error (reported on the server's standard error)"
        self.set_header("Content-Type", "application/json")
        self.clear_header("Content-Disposition")
        self.finish({"error": message, "status": status_code})

    def send_error(self, status_code: int = 500, **kwargs) -> None:
        exc = kwargs.get("exc_info", (None, None, None))[1]
        if isinstance(exc, RequestError):
            status_code = exc.status
        elif isinstance(exc, Rend3rError):
            status_code = 422
        super().send_error(status_code, **kwargs)

    def log_exception(self, typ, value, tb) -> None:
        if isinstance(value, (RequestError, Rend3rError, tornado.web.HTTPError)):
            return
        print(f"rend3r view: internal error on {self.request.path}: {typ.__name__}: {value}", file=sys.stderr)

    def set_default_headers(self) -> None:
        self.set_header("Cache-Control", "no-store")
        self.set_header("X-Content-Type-Options", "nosniff")
        self.set_header("Content-Security-Policy", "default-src 'self'; img-src 'self' blob:; "
                        "connect-src 'self' ws: wss:; frame-ancestors 'none'")

    async def run(self, fn, *args):
        """``fn(*args)`` on the worker thread."""
        return await IOLoop.current().run_in_executor(self.view.work, fn, *args)

    def png(self, data: bytes) -> None:
        self.set_header("Content-Type", "image/png")
        self.finish(data)


class NotFound(Handler):
    def prepare(self) -> None:
        raise RequestError(f"no such page: {self.request.path[:200]}", 404)


class Page(Handler):
    def get(self, name: str = "index.html") -> None:
        found = self.view.files.get(name)
        if found is None:
            raise RequestError(f"no such file: {name[:200]}", 404)
        self.set_header("Content-Type", found[1])
        self.finish(found[0])


class Status(Handler):
    def get(self) -> None:
        self.finish(status(self.view))


class Source(Handler):
    def get(self) -> None:
        src = self.view.source
        if src.kind == "svo":
            raise RequestError("an .svo model has no source text", 404)
        from ..fileio import read_limited

        data = read_limited(src.path, 1 << 20, what="source")
        self.set_header("Content-Type", "text/plain; charset=utf-8")
        self.finish(data)


def _options(view: View, args):
    from .params import emu_options

    good = view.good()
    if good.svo is not None:
        raise RequestError("the program is an .svo model: use /api/svo/...", 404)
    return good, emu_options(args, good.mode)


def _frame_number(args, count: int) -> int:
    return integer(args, "frame", 0, count - 1, 0)


def _images(view: View, args) -> tuple[dict, dict[str, np.ndarray]]:
    """The frame's figures, and its three pictures (RGB888): the frame, fp64's, the difference."""
    from ..emu.image import rgb565_to_rgb888

    good, options = _options(view, args)
    count = fr.frame_count(good.words, options, view.max_frames)
    number = _frame_number(args, count)
    version = view.source.state.version
    work = rgb565_to_rgb888(view.frames.frame(version, good.words, options, number))
    ref = rgb565_to_rgb888(view.frames.frame(version, good.words, fr.reference(options), number))
    heat, figures = fr.difference(work, ref)
    info = {"version": version, "frames": count, "frame": number, "width": options.width,
            "height": options.height, "precision": options.precision, "label": options.arith.label, **figures}
    return info, {"frame": work, "fp64": ref, "diff": heat}


class Frame(Handler):
    async def get(self) -> None:
        info, _ = await self.run(_images, self.view, self.request.arguments)
        self.finish(info)


class Image(Handler):
    async def get(self, which: str) -> None:
        def one_png() -> bytes:
            return fr.png(_images(self.view, self.request.arguments)[1][which])

        self.png(await self.run(one_png))


class Pixel(Handler):
    async def get(self) -> None:
        args = self.request.arguments

        def history() -> dict:
            good, options = _options(self.view, args)
            number = _frame_number(args, fr.frame_count(good.words, options, self.view.max_frames))
            x, y = integer(args, "x", 0, options.width - 1), integer(args, "y", 0, options.height - 1)
            shapes = one(args, "shapes", "hit")
            if shapes not in ("hit", "all"):
                raise RequestError(f"shapes: hit or all, not {shapes!r}")
            return fr.history(good.words, options, number, x, y, shapes == "all", self.view.traces,
                              self.view.source.state.version)

        self.finish(await self.run(history))


class SvoImage(Handler):
    async def get(self, which: str) -> None:
        def one_png() -> bytes:
            _, r = self.view.svo_render(sv.svo_view(self.request.arguments))
            return fr.png(r.rgb if which == "render" else sv.cost_rgb(r))

        self.png(await self.run(one_png))


class SvoRay(Handler):
    async def get(self) -> None:
        args = self.request.arguments

        def traversal() -> dict:
            view = sv.svo_view(args)
            model, r = self.view.svo_render(view)
            return {"version": self.view.source.state.version, "stats": r.result.stats(),
                    **sv.ray(model, view, r, integer(args, "x", 0, view.width - 1), integer(args, "y", 0, view.height - 1))}

        self.finish(await self.run(traversal))


class LiveSocket(tornado.websocket.WebSocketHandler, Handler):
    """Pushes ``{"type": "reload", ...status}`` whenever the program changes."""

    def open(self) -> None:
        self.view.sockets.add(self)
        self.write_message(json.dumps({"type": "hello", **status(self.view)}))

    def on_close(self) -> None:
        self.view.sockets.discard(self)

    def on_message(self, message) -> None:
        pass  # the page only listens


def make_app(view: View) -> tornado.web.Application:
    """The Tornado application of ``view``."""
    return tornado.web.Application([
        (r"/", Page),
        (r"/static/([A-Za-z0-9_-]{1,64}\.[a-z]{1,5})", Page),
        (r"/api/status", Status),
        (r"/api/source", Source),
        (r"/api/frame", Frame),
        (r"/api/image/(frame|fp64|diff)\.png", Image),
        (r"/api/pixel", Pixel),
        (r"/api/svo/image/(render|cost)\.png", SvoImage),
        (r"/api/svo/ray", SvoRay),
        (r"/api/live", LiveSocket),
    ], default_handler_class=NotFound, view=view, serve_traceback=False, compress_response=True,
        websocket_max_message_size=4096, log_function=lambda handler: None)  # errors: Handler.log_exception


def new_token() -> str:
    """A random token for a server on a non-loopback address."""
    return secrets.token_urlsafe(18)


async def serve(program: str, host: str, port: int, frames: int, on_ready) -> None:
    """Serve ``program`` (at most ``frames`` of its frames) on ``host:port`` until cancelled;
    ``on_ready(url, status)`` once listening."""
    token = None if is_loopback(host) else new_token()
    view = View(program, token, set(), frames)
    await view.poll()
    sockets = bind_sockets(port, host)
    server = HTTPServer(make_app(view), max_body_size=1 << 16)
    server.add_sockets(sockets)
    bound = sockets[0].getsockname()[1]
    shown = f"[{host}]" if ":" in host else host
    view.hosts = {f"{shown}:{bound}".lower(), f"localhost:{bound}", f"127.0.0.1:{bound}", f"[::1]:{bound}"}
    poller = PeriodicCallback(view.poll, POLL_MS)
    poller.start()
    on_ready(f"http://{shown}:{bound}/" + (f"?token={token}" if token else ""), status(view))
    try:
        await asyncio.Event().wait()
    finally:
        poller.stop()
        server.stop()
        view.work.shutdown(wait=False, cancel_futures=True)
        view.watch.shutdown(wait=False, cancel_futures=True)

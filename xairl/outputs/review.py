"""``xairl review --serve``: operators review recorded narratives in a local web page, with the evidence beside
each one (the state, the margin's waterfall, each sentence marked verified / contradicted / unchecked, the
verdict: verified, contradicted or partly checked with its coverage, and the account of the margin, the confidence
components), and accept, reject or correct it. Their decisions go to the same SQLite store as the terminal
review.

The server is Python's own (http.server), bound to 127.0.0.1 only. Defended against pages on other sites open in
the same browser and against hostile clients: a Host allow-list (``127.0.0.1:PORT``, ``localhost:PORT``; else 421)
against DNS rebinding, the Origin of a POST checked when sent (else 403), a token made at start-up in every form,
a body limit (413, decided before reading), a socket timeout per read or write, a total deadline per connection
(a client trickling one byte at a time is hung up on when it passes), a cap on open connections (503 beyond it),
and 400 for malformed forms, all without tracebacks. Not defended: anyone with a shell on this machine (they can
read the store anyway); there is no TLS and no authentication beyond the token.
"""

from __future__ import annotations

import html
import re
import secrets
import socket
import sys
import threading
import time
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from urllib.parse import parse_qs, urlencode, urlparse

from xairl.errors import InputError
from xairl.explanations.evidence import CARD_STYLE, card_html, lines_html
from xairl.outputs.feedback import STATUSES, FeedbackStore, Record

HOST = "127.0.0.1"
MAX_BODY = 1_000_000  # a correction is a few sentences; more than this is not from the page
TIMEOUT = 10.0  # seconds a client may stall before its connection is dropped
DEADLINE = 20.0  # seconds a connection may last in all (one request: HTTP/1.0), however it trickles
MAX_CONNECTIONS = 16  # open at once (a browser opens about 6); beyond it a connection is answered 503 and closed
_BUSY_TEXT = b"too many connections; retry shortly\n"
_BUSY = (
    b"HTTP/1.0 503 Service Unavailable\r\nContent-Type: text/plain; charset=utf-8\r\nRetry-After: 5\r\n"
    b"Content-Length: %d\r\nConnection: close\r\n\r\n%s" % (len(_BUSY_TEXT), _BUSY_TEXT)
)
_NUMBER = re.compile(r"[0-9]{1,18}")  # fits SQLite's 64-bit integer and stays under int()'s digit limit


class _Server(ThreadingHTTPServer):
    """A thread per connection, at most ``max_connections`` of them, each hung up on ``deadline`` seconds after it was
    accepted by one reaper thread (a socket timeout bounds one read, not a client that sends a byte per timeout)."""

    daemon_threads = True  # shutdown does not wait for a stalled client

    def __init__(self, address, handler, deadline: float = DEADLINE, max_connections: int = MAX_CONNECTIONS):
        super().__init__(address, handler)
        self.deadline, self.max_connections = float(deadline), int(max_connections)
        self._lock = threading.Condition()
        self._open: dict[socket.socket, float] = {}  # connection -> when it is hung up on (time.monotonic)
        self._expired: set[socket.socket] = set()
        self._serving = False

    def serve_forever(self, poll_interval: float = 0.5) -> None:
        with self._lock:
            self._serving = True
        reaper = threading.Thread(target=self._reap, name="xairl-review-reaper", daemon=True)
        reaper.start()
        try:
            super().serve_forever(poll_interval)
        finally:
            with self._lock:
                self._serving = False
                self._lock.notify_all()
            reaper.join()

    def _reap(self) -> None:
        """Hang up on every connection past its deadline: its thread's blocked read or write returns and it ends."""
        with self._lock:
            while self._serving:
                now = time.monotonic()
                for conn, end in self._open.items():
                    if end <= now and conn not in self._expired:
                        self._expired.add(conn)
                        try:
                            conn.shutdown(socket.SHUT_RDWR)
                        except OSError:  # closed meanwhile
                            pass
                waiting = [end for conn, end in self._open.items() if conn not in self._expired]
                self._lock.wait(max(min(waiting) - now, 0.0) if waiting else None)

    def expired(self, conn: socket.socket) -> bool:
        with self._lock:
            return conn in self._expired

    @property
    def open_connections(self) -> int:
        with self._lock:
            return len(self._open)

    def process_request(self, request, client_address):
        with self._lock:
            full = len(self._open) >= self.max_connections
            if not full:
                self._open[request] = time.monotonic() + self.deadline
                self._lock.notify_all()
        if full:  # answered at once, from the accepting thread: a fresh socket's buffer takes these bytes
            try:
                request.setblocking(False)
                request.send(_BUSY)
            except OSError:
                pass
            self.shutdown_request(request)
            return
        try:
            super().process_request(request, client_address)
        except BaseException:  # no thread started: free the slot
            self._forget(request)
            raise

    def process_request_thread(self, request, client_address):
        try:
            super().process_request_thread(request, client_address)
        finally:
            self._forget(request)

    def _forget(self, request) -> None:
        with self._lock:
            self._open.pop(request, None)
            self._expired.discard(request)

    def handle_error(self, request, client_address):
        """A client that vanished or stalled (OSError) is its own affair; a bug of ours still shows."""
        if not isinstance(sys.exc_info()[1], OSError):
            super().handle_error(request, client_address)


def _item(r: Record, token: str) -> str:
    meta = (
        f"#{r.id} &middot; {html.escape(r.policy or '?')} &middot; template {html.escape(r.template or '?')} "
        f"&middot; {html.escape(r.source or '?')} &middot; <b class=status>{html.escape(r.status)}</b>"
        + (f" &middot; correction: <i>{lines_html(r.correction)}</i>" if r.correction else "")
    )
    form = (
        f"<form method=post action='/review' class=verdict><input type=hidden name=id value='{r.id}'>"
        f"<input type=hidden name=token value='{token}'>"
        f"<button name=status value=accepted class=accept>Accept</button> "
        f"<button name=status value=rejected class=reject>Reject</button> "
        f"<textarea name=correction rows=2 cols=70 placeholder='corrected text'></textarea> "
        f"<button name=status value=corrected class=correct>Correct</button></form>"
    )
    ev = {
        **(r.evidence or {"sentences": [], "components": {}, "confidence": r.confidence}),
        "status": r.verdict,
        "coverage": r.coverage,
        "account": r.account or (r.evidence or {}).get("account", ""),
    }
    return f"<section class=item id='item-{r.id}'>{card_html(r.text, ev, meta, form)}</section>"


def page(store: FeedbackStore, token: str, show_all: bool = False, message: str = "") -> str:
    records = store.records() if show_all else store.records("pending")
    head = (
        f"<h1>Narratives to review</h1><p class=meta>{len(records)} {'recorded' if show_all else 'pending'} in "
        f"{html.escape(str(store.path))} &middot; <a href='/?all=1'>all</a> &middot; <a href='/'>pending</a></p>"
    )
    note = f"<p class=message>{html.escape(message)}</p>" if message else ""
    body = "".join(_item(r, token) for r in records) or "<p class=empty>Nothing to review.</p>"
    style = CARD_STYLE + (
        "body{font-family:sans-serif;max-width:1100px;margin:1.5em auto;color:#222}"
        ".message{background:#e6f4e6;padding:.4em}.verdict{margin-top:.6em}"
        "td,th{border:1px solid #ddd;padding:1px 6px}table{border-collapse:collapse}"
    )
    return (
        f"<!doctype html><html><head><meta charset='utf-8'><title>xairl review</title><style>{style}</style>"
        f"</head><body>{head}{note}{body}</body></html>"
    )


#: what the page says after a review, by the code its address carries: never text from the address itself (a crafted
#: link would make the page say anything)
MESSAGES = {
    **{status: f"#{{id}} {status}" for status in STATUSES},
    "bad-status": "not stored: choose accept, reject or correct.",
    "no-text": "not stored: a correction needs its text.",
    "unknown-id": "not stored: there is no narrative #{id} in this store.",
}


def _message(query: dict) -> str:
    """The message of the code in ``query['msg']`` (with its narrative's number); '' for no code or an unknown one."""
    text, number = MESSAGES.get(query.get("msg", ""), ""), query.get("id", "")
    return text.format(id=number) if _NUMBER.fullmatch(number) or "{id}" not in text else ""


class _Handler(BaseHTTPRequestHandler):
    """One request; the store, the form token and the allowed Hosts are the server's (:func:`make_server`)."""

    def _send(self, status: int, body: str = "", location: str | None = None) -> None:
        data = body.encode()
        self.send_response(status)
        if location:
            self.send_header("Location", location)
        self.send_header("Content-Type", f"text/{'plain' if status >= 400 else 'html'}; charset=utf-8")
        self.send_header("Content-Length", str(len(data)))
        self.end_headers()
        self.wfile.write(data)

    def parse_request(self) -> bool:
        """A request completed only by the hang-up at its deadline (its lines cut short) is not answered."""
        ok = not self.server.expired(self.connection) and super().parse_request()
        if self.server.expired(self.connection):
            self.close_connection = True
            return False
        return ok

    def _misdirected(self) -> bool:
        """DNS rebinding: a hostile name resolved to 127.0.0.1 arrives with that name as Host; answer 421."""
        sent = self.headers.get_all("Host") or []
        if len(sent) == 1 and sent[0].strip().lower() in self.server.hosts:
            return False
        self._send(
            HTTPStatus.MISDIRECTED_REQUEST,
            f"misdirected request: this page answers only to http://{HOST}:{self.server.server_address[1]}/",
        )
        return True

    def do_GET(self):  # noqa: N802 (http.server's naming)
        if self._misdirected():
            return
        url = urlparse(self.path)
        if url.path != "/":
            return self._send(HTTPStatus.NOT_FOUND, "not found")
        q = {k: v[0] for k, v in parse_qs(url.query).items()}
        self._send(HTTPStatus.OK, page(self.server.store, self.server.token, bool(q.get("all")), _message(q)))

    def _form(self) -> dict | None:
        """The posted form, once the Origin, the length and the token are checked; None after an error answer."""
        origin = self.headers.get("Origin")  # browsers send it; a client without one is judged by the token
        if origin is not None and origin.strip().lower() not in {f"http://{h}" for h in self.server.hosts}:
            return self._send(HTTPStatus.FORBIDDEN, "this form is not from this review page")
        length = self.headers.get("Content-Length")
        if length is None:
            return self._send(HTTPStatus.LENGTH_REQUIRED, "Content-Length required")
        if not _NUMBER.fullmatch(length.strip()):
            return self._send(HTTPStatus.BAD_REQUEST, "bad Content-Length")
        if int(length) > MAX_BODY:  # refused unread: cutting it would store part of a correction
            return self._send(HTTPStatus.REQUEST_ENTITY_TOO_LARGE, f"payload too large (over {MAX_BODY} bytes)")
        raw = self.rfile.read(int(length))
        if len(raw) < int(length):
            return self._send(HTTPStatus.BAD_REQUEST, "body shorter than its Content-Length")
        form = {k: v[0] for k, v in parse_qs(raw.decode("utf-8", "replace")).items()}
        sent = form.get("token", "").encode()  # bytes: compare_digest raises on non-ASCII str
        if not secrets.compare_digest(sent, self.server.token.encode()):
            return self._send(HTTPStatus.FORBIDDEN, "this form is not from this review page; reload it")
        if not _NUMBER.fullmatch(form.get("id", "")):
            return self._send(HTTPStatus.BAD_REQUEST, "id must be a narrative's number")
        return form

    def do_POST(self):  # noqa: N802
        if self._misdirected():
            return
        if urlparse(self.path).path != "/review":
            return self._send(HTTPStatus.NOT_FOUND, "not found")
        form = self._form()
        if form is None:
            return
        status = form.get("status", "")
        correction = form.get("correction", "").strip() if status == "corrected" else None
        try:
            self.server.store.review(int(form["id"]), status, correction)
            code = status
        except (InputError, ValueError):
            code = "bad-status" if status not in STATUSES else "no-text" if correction == "" else "unknown-id"
        self._send(HTTPStatus.SEE_OTHER, location="/?" + urlencode({"msg": code, "id": form["id"]}))

    def log_message(self, *args):  # quiet (log_error too): the terminal shows only the address
        pass


def make_server(
    store: FeedbackStore,
    port: int = 0,
    timeout: float = TIMEOUT,
    deadline: float = DEADLINE,
    max_connections: int = MAX_CONNECTIONS,
) -> ThreadingHTTPServer:
    """A review server for ``store`` on 127.0.0.1 (``port`` 0: any free port; ``server.server_address`` says).

    :param timeout: seconds a client may stall in one read or write before its connection is dropped.
    :param deadline: seconds a connection may last in all before it is hung up on and its thread freed.
    :param max_connections: connections served at once; one more is answered 503 and closed.
    """
    if not (deadline > 0 and timeout > 0 and max_connections >= 1):
        raise InputError(
            f"the review server needs a positive timeout and deadline and at least one connection, got "
            f"timeout={timeout}, deadline={deadline}, max_connections={max_connections}."
        )
    handler = type("Handler", (_Handler,), {"timeout": timeout})  # a socket timeout per server
    server = _Server((HOST, port), handler, deadline, max_connections)
    server.store, server.token = store, secrets.token_urlsafe(16)
    server.hosts = {f"{name}:{server.server_address[1]}" for name in (HOST, "localhost")}
    return server


def serve(store: FeedbackStore, port: int = 8765) -> None:
    """Serve the review page until interrupted."""
    try:
        server = make_server(store, port)
    except OSError as exc:
        raise InputError(f"cannot listen on {HOST}:{port} ({exc.strerror}); pass another --port.") from None
    print(f"reviewing {store.path} at http://{HOST}:{server.server_address[1]}/ (Ctrl-C stops)", flush=True)
    try:
        server.serve_forever()
    finally:
        server.server_close()


def serve_in_thread(
    store: FeedbackStore, timeout: float = TIMEOUT, deadline: float = DEADLINE, max_connections: int = MAX_CONNECTIONS
) -> tuple[ThreadingHTTPServer, str]:
    """A server on a free port in a daemon thread, and its address (for tests and notebooks); the parameters are
    :func:`make_server`'s."""
    server = make_server(store, 0, timeout, deadline, max_connections)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server, f"http://{HOST}:{server.server_address[1]}/"

"""Issue 51, round 3 of hardening, the display side: the review page hangs up on clients that trickle (item 7), the
figures keep their labels apart and inside, write values in the feature's unit and give actions their own marks
(14), the region beeswarm is readable (13), every figure names its view (15), and notebooks get no 'IProgress not
found' (18)."""
import socket
import time

import pytest

from xairl.feedback import FeedbackStore
from xairl.review import serve_in_thread

# --- item 7: a total deadline per connection and a cap on connections (loopback only) ---------------------------


@pytest.fixture
def server(tmp_path):
    """Starts a review server over an empty store with the given limits; every one started is shut down after."""
    started = []

    def start(**limits):
        srv, _ = serve_in_thread(FeedbackStore(tmp_path / "fb.sqlite"), **limits)
        started.append(srv)
        return srv, srv.server_address[1]

    yield start
    for srv in started:
        srv.shutdown()


def _get(port, timeout=5.0):
    """A whole GET / at once: (status, body); status 0 when the connection closed unanswered."""
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
        s.sendall(f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\n\r\n".encode())
        data = b""
        while chunk := s.recv(65536):
            data += chunk
    head, _, body = data.partition(b"\r\n\r\n")
    return (int(head.split()[1]) if data else 0), body.decode()


def _closed(s: socket.socket) -> bool:
    """Whether the server hung up on ``s`` (end of stream or reset), without waiting."""
    s.setblocking(False)
    try:
        return s.recv(1024) == b""
    except BlockingIOError:
        return False
    except OSError:
        return True
    finally:
        s.setblocking(True)


def _wait_until(condition, limit: float) -> bool:
    end = time.monotonic() + limit
    while time.monotonic() < end:
        if condition():
            return True
        time.sleep(0.05)
    return condition()


def test_clients_that_trickle_are_hung_up_on_at_the_deadline_and_a_normal_client_is_served(server):
    deadline, n = 1.5, 5
    srv, port = server(timeout=10.0, deadline=deadline, max_connections=n + 2)  # a read timeout alone never fires
    stream = f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nX-Slow: ".encode() + b"a" * 10_000  # never ends
    opened = time.monotonic()
    slow = [socket.create_connection(("127.0.0.1", port), timeout=5) for _ in range(n)]
    cut: dict[int, float] = {}
    served = None
    sent = 0
    while len(cut) < n and time.monotonic() - opened < deadline + 5:  # one byte per client every 50 ms
        for k, s in enumerate(slow):
            if k in cut:
                continue
            try:
                s.send(stream[sent:sent + 1])
            except OSError:
                cut[k] = time.monotonic() - opened
                continue
            if _closed(s):
                cut[k] = time.monotonic() - opened
        sent += 1
        if served is None and time.monotonic() - opened > deadline / 2:
            assert srv.open_connections == n  # all the slow ones are being held: this is during the trickle
            served = _get(port)
        time.sleep(0.05)
    for s in slow:
        s.close()
    assert served is not None and served[0] == 200 and "Nothing to review" in served[1]
    assert sorted(cut) == list(range(n)), f"hung up on {len(cut)} of {n} within {deadline + 5} s"
    assert min(cut.values()) >= deadline  # not before the deadline (timed from before the connection)...
    assert max(cut.values()) < deadline + 3  # ... and at it, give or take a loaded machine
    assert _wait_until(lambda: srv.open_connections == 0, 3)  # every thread freed


def test_connections_beyond_the_cap_are_answered_503_until_the_held_ones_pass_their_deadline(server):
    deadline, cap = 1.0, 3
    srv, port = server(timeout=10.0, deadline=deadline, max_connections=cap)
    held = [socket.create_connection(("127.0.0.1", port), timeout=5) for _ in range(cap)]
    for s in held:
        s.sendall(b"GET / HT")  # and nothing more
    assert _wait_until(lambda: srv.open_connections == cap, 3)
    for _ in range(10):  # a flood beyond the cap: answered at once, no thread kept
        status, body = _get(port)
        assert status == 503 and "too many connections" in body
        assert srv.open_connections <= cap
    assert _wait_until(lambda: all(_closed(s) for s in held), deadline + 3)
    for s in held:
        s.close()
    assert _wait_until(lambda: srv.open_connections == 0, 3)
    assert _get(port)[0] == 200


def test_a_request_cut_at_its_deadline_is_not_answered(server):
    """Headers cut short by the hang-up are not taken for a whole request (no page rendered for a slow client)."""
    srv, port = server(timeout=10.0, deadline=0.5)
    s = socket.create_connection(("127.0.0.1", port), timeout=5)
    s.sendall(f"GET / HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nX-Slow: abc".encode())
    data = b""
    try:
        while chunk := s.recv(65536):
            data += chunk
    except ConnectionResetError:
        pass
    s.close()
    assert data == b""


def test_review_limits_must_be_positive(tmp_path):
    from xairl.errors import InputError
    from xairl.review import make_server

    for limits in ({"deadline": 0}, {"max_connections": 0}, {"timeout": -1}):
        with pytest.raises(InputError, match="positive"):
            make_server(FeedbackStore(tmp_path / "fb.sqlite"), 0, **limits)

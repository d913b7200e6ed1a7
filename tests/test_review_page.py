"""The review page in a real browser (Debian's headless Chromium through its chromedriver): load it, see the
evidence beside each narrative, review items, and find the verdicts in the SQLite store."""

import re
import shutil
import socket
import struct
import time
import urllib.request

import pytest

import xairl
from xairl.outputs.feedback import FeedbackStore
from xairl.outputs.review import TIMEOUT, page, serve_in_thread
from xairl.toy import toy_policy

BROWSER = shutil.which("chromium") and shutil.which("chromedriver")


@pytest.fixture
def store(tmp_path):
    p = toy_policy()
    bg = p.background(50)
    exp = xairl.explain(p, p.background(3, seed=4), background=bg)
    store = FeedbackStore(tmp_path / "fb.sqlite")
    for i in range(2):
        xairl.narrate(exp, i, policy=p, background=bg, robustness=False, store=store)
    return store


def test_page_shows_the_evidence_without_a_browser(store):
    r = store.records()[0]
    assert r.evidence["runner_up"] and len(r.evidence["features"]) == 5 and r.evidence["sentences"]
    html = page(store, "t")
    assert html.count("class=item") == 2 and "class=waterfall" in html and "class=state" in html
    assert "s verified" in html and "margin of" in html and "coverage" in html


def test_a_post_without_the_page_token_is_refused(store):
    server, url = serve_in_thread(store)
    try:
        req = urllib.request.Request(url + "review", data=b"id=1&status=accepted&token=forged", method="POST")
        with pytest.raises(urllib.error.HTTPError, match="403"):
            urllib.request.urlopen(req, timeout=10)
        assert store.records()[0].status == "pending"
    finally:
        server.shutdown()


def _http(port, method, path, headers, body=b"", timeout=5):
    """One raw request (only the headers given, nothing added): the server's status and body."""
    head = f"{method} {path} HTTP/1.1\r\n" + "".join(f"{k}: {v}\r\n" for k, v in headers.items()) + "\r\n"
    with socket.create_connection(("127.0.0.1", port), timeout=timeout) as s:
        s.sendall(head.encode() + body)
        data = b""
        while chunk := s.recv(65536):
            data += chunk
    status, _, rest = data.partition(b"\r\n\r\n")
    return int(status.split()[1]) if data else 0, rest.decode()  # 0: the connection closed unanswered


def _post(port, form, origin=None, host=None):
    body = form.encode()
    headers = {
        "Host": host or f"127.0.0.1:{port}",
        "Content-Type": "application/x-www-form-urlencoded",
        "Content-Length": str(len(body)),
        **({"Origin": origin} if origin else {}),
    }
    return _http(port, "POST", "/review", headers, body)


def _token(port):
    return re.search(r"name=token value='([^']+)'", _http(port, "GET", "/", {"Host": f"127.0.0.1:{port}"})[1])[1]


def _statuses(store):
    return [(r.status, r.correction) for r in store.records()]


@pytest.fixture
def serve(store):
    """Starts the review server on a free port (``timeout``: seconds a client may stall) and returns the port; every
    server started is shut down after the test."""
    servers = []

    def start(timeout: float = TIMEOUT) -> int:
        server, _ = serve_in_thread(store, timeout)
        servers.append(server)
        return server.server_address[1]

    yield start
    for server in servers:
        server.shutdown()


def test_a_foreign_host_or_origin_is_refused(store, serve):
    port = serve()
    token = _token(port)
    status, body = _http(port, "GET", "/", {"Host": "evil.example"})
    assert status == 421 and token not in body
    assert _http(port, "GET", "/", {})[0] == 421  # no Host at all: an HTTP/1.0 rebinding request
    assert _http(port, "GET", "/", {"Host": f"localhost:{port + 1}"})[0] == 421
    form = f"id=1&status=accepted&token={token}"
    assert _post(port, form, host="evil.example", origin="http://evil.example")[0] == 421
    assert _post(port, form, origin="http://evil.example")[0] == 403
    assert _post(port, form, origin="null")[0] == 403
    assert _statuses(store) == [("pending", None)] * 2
    status, body = _http(port, "GET", "/", {"Host": f"localhost:{port}"})
    assert status == 200 and token in body
    assert _post(port, form, host=f"localhost:{port}", origin=f"http://localhost:{port}")[0] == 303
    assert _post(port, f"id=2&status=rejected&token={token}")[0] == 303  # no Origin: the token decides
    assert _statuses(store) == [("accepted", None), ("rejected", None)]


def test_a_body_over_the_limit_is_refused_unread(store, serve):
    port = serve()
    token = _token(port)
    headers = {"Host": f"127.0.0.1:{port}", "Content-Length": "10000000"}
    start = f"token={token}&id=1&status=corrected&correction=".encode()  # and never the rest
    status, body = _http(port, "POST", "/review", headers, start)
    assert status == 413 and "too large" in body.lower()
    assert _statuses(store) == [("pending", None)] * 2


@pytest.mark.slow
def test_a_stalled_request_is_dropped_and_others_are_served(store, serve):
    port = serve(timeout=1)
    stalled = [socket.create_connection(("127.0.0.1", port), timeout=10) for _ in range(5)]
    for s in stalled:  # claims 100 bytes, sends 10
        s.sendall(
            f"POST /review HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Length: 100\r\n\r\n".encode() + b"token=abcd"
        )
    assert _http(port, "GET", "/", {"Host": f"127.0.0.1:{port}"})[0] == 200
    start = time.monotonic()
    for s in stalled:
        assert s.recv(1024) == b""  # closed by the server, nothing answered
        s.close()
    assert time.monotonic() - start < 5
    assert _statuses(store) == [("pending", None)] * 2


def test_bad_ids_and_lengths_get_400(store, serve):
    port = serve()
    token = _token(port)
    for id_part in (f"id={10**30}", "id=abc", "", "id=-1", "id=1.0"):
        status, body = _post(port, f"{id_part}&status=accepted&token={token}")
        assert status == 400 and "id" in body, id_part
    host = {"Host": f"127.0.0.1:{port}"}
    assert _http(port, "POST", "/review", host, f"id=1&status=accepted&token={token}".encode())[0] in (400, 411)
    assert _http(port, "POST", "/review", {**host, "Content-Length": "ten"})[0] == 400
    assert _http(port, "POST", "/review", {**host, "Content-Length": "-5"})[0] == 400
    assert _statuses(store) == [("pending", None)] * 2
    status, _ = _post(port, f"id=1&status=approved&token={token}")  # unknown status: reported, not stored
    assert status == 303 and _statuses(store) == [("pending", None)] * 2


@pytest.mark.slow
def test_hostile_requests_print_no_traceback(store, capfd, serve):
    port = serve()
    token = _token(port)
    _post(port, f"id={10**30}&status=accepted&token={token}")
    assert _post(port, "id=1&status=accepted&token=%C3%A9")[0] == 403  # a non-ASCII token is just wrong
    s = socket.create_connection(("127.0.0.1", port))  # a client that resets mid-request
    s.sendall(f"POST /review HTTP/1.1\r\nHost: 127.0.0.1:{port}\r\nContent-Length: 100\r\n\r\nid=1".encode())
    time.sleep(0.2)
    s.setsockopt(socket.SOL_SOCKET, socket.SO_LINGER, struct.pack("ii", 1, 0))
    s.close()
    time.sleep(0.5)
    assert _http(port, "GET", "/", {"Host": f"127.0.0.1:{port}"})[0] == 200
    err = capfd.readouterr().err
    assert "Traceback" not in err and err == ""


@pytest.mark.slow
@pytest.mark.skipif(
    not BROWSER, reason="Debian's chromium and chromium-driver are not installed (make test installs them)"
)
def test_review_in_headless_chromium(store, tmp_path):
    from selenium import webdriver
    from selenium.common.exceptions import StaleElementReferenceException, WebDriverException
    from selenium.webdriver.chrome.service import Service
    from selenium.webdriver.common.by import By
    from selenium.webdriver.support.ui import WebDriverWait

    def message(driver):
        try:
            shown = driver.find_elements(By.CSS_SELECTOR, ".message")
            return shown[0].text if shown else False
        except WebDriverException as exc:  # chromedriver's word for a node of the page being replaced: read again
            if "does not belong to the document" in str(exc):
                return False
            raise

    def wait(driver):  # a click posts and the page reloads: an element read during the reload is stale, read again
        return WebDriverWait(driver, 20, ignored_exceptions=(StaleElementReferenceException,))

    opts = webdriver.ChromeOptions()
    opts.binary_location = shutil.which("chromium")
    for flag in (
        "--headless",
        "--no-sandbox",
        "--disable-gpu",
        "--no-first-run",
        "--disable-background-networking",
        "--disable-component-update",
        "--disable-sync",
        "--disable-dev-shm-usage",
        f"--user-data-dir={tmp_path / 'profile'}",
        "--window-size=1200,1600",
    ):
        opts.add_argument(flag)
    server, url = serve_in_thread(store)
    driver = webdriver.Chrome(options=opts, service=Service(shutil.which("chromedriver")))
    try:
        driver.get(url)
        items = driver.find_elements(By.CSS_SELECTOR, "section.item")
        assert len(items) == 2
        first, second = (i.get_attribute("id").split("-")[1] for i in items)
        card = driver.find_element(By.ID, f"item-{first}")
        assert card.find_elements(By.CSS_SELECTOR, ".wf-bar") and card.find_elements(By.CSS_SELECTOR, "table.state")
        assert card.find_elements(By.CSS_SELECTOR, "span.s.verified")
        driver.save_screenshot(str(tmp_path / "review.png"))
        card.find_element(By.CSS_SELECTOR, "button.accept").click()
        assert f"#{first} accepted" in wait(driver).until(message)
        card = driver.find_element(By.ID, f"item-{second}")
        card.find_element(By.NAME, "correction").send_keys("The policy turned: the goal was close.")
        card.find_element(By.CSS_SELECTOR, "button.correct").click()
        wait(driver).until(lambda d: f"#{second} corrected" in (message(d) or ""))
        assert "Nothing to review" in driver.page_source
    finally:
        driver.quit()
        server.shutdown()
    got = {r.id: (r.status, r.correction) for r in store.records()}
    assert got == {int(first): ("accepted", None), int(second): ("corrected", "The policy turned: the goal was close.")}
    assert (tmp_path / "review.png").stat().st_size > 10_000


def test_each_refusal_is_said_for_what_it_is(store, serve):
    """A correction of a narrative that does not exist says so (was: 'a correction needs its text'); a correction
    without text says that."""
    import http.client

    port = serve()
    token = _token(port)
    ids = [r.id for r in store.records()]

    def location(form):
        conn = http.client.HTTPConnection("127.0.0.1", port, timeout=5)
        conn.request("POST", "/review", form, {"Content-Type": "application/x-www-form-urlencoded"})
        res = conn.getresponse()
        conn.close()
        return res.status, res.getheader("Location")

    unknown = max(ids) + 10
    assert location(f"id={unknown}&status=corrected&correction=It+turned.&token={token}") == (
        303,
        f"/?msg=unknown-id&id={unknown}",
    )
    assert location(f"id={ids[0]}&status=corrected&correction=&token={token}") == (303, f"/?msg=no-text&id={ids[0]}")
    assert _statuses(store) == [("pending", None)] * 2

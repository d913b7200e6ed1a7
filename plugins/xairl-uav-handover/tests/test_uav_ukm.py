"""ukm.py on a fresh machine: download from a loopback server, cache, checksum, offline, env var, unsafe zips, and
the report's ``-o real=ukm`` when the data cannot be had. Offline; skips where ../shared/data is absent."""

import hashlib
import http.server
import io
import shutil
import socket
import threading
import zipfile
from pathlib import Path

import pytest

from xairl import InputError
from xairl_uav_handover import ukm
from xairl_uav_handover.exports import load_folder
from xairl_uav_handover.report import real_source

UKM = Path(__file__).resolve().parents[3].parent / "shared" / "data" / "ukm-uav-lte" / "raw"
NAMES = ("80m.csv", "140m-1.csv")
pytestmark = pytest.mark.skipif(not UKM.is_dir(), reason="../shared/data/ukm-uav-lte is not here")


def make_zip(members: dict[str, bytes]) -> bytes:
    buf = io.BytesIO()
    with zipfile.ZipFile(buf, "w", zipfile.ZIP_DEFLATED) as zf:
        for name, data in members.items():
            zf.writestr(name, data)
    return buf.getvalue()


@pytest.fixture(scope="module")
def flights_zip() -> bytes:
    """The pinned archive's layout with two real flights and a file that is not one."""
    members = {f"Measured Data/{n}": (UKM / n).read_bytes() for n in NAMES}
    return make_zip({**members, "README.txt": b"not a flight", "__MACOSX/Measured Data/._80m.csv": b"junk"})


class Server:
    """A loopback HTTP server answering every GET with ``payload`` (``short``: announce more bytes than sent)."""

    def __init__(self):
        self.payload, self.short, self.requests = b"", False, 0
        owner = self

        class Handler(http.server.BaseHTTPRequestHandler):
            def do_GET(self):
                owner.requests += 1
                self.send_response(200)
                self.send_header("Content-Length", str(len(owner.payload) * (2 if owner.short else 1)))
                self.end_headers()
                self.wfile.write(owner.payload)

            def log_message(self, *args):
                pass

        self.httpd = http.server.ThreadingHTTPServer(("127.0.0.1", 0), Handler)
        self.url = f"http://127.0.0.1:{self.httpd.server_address[1]}/raw_dataset.zip"
        threading.Thread(target=self.httpd.serve_forever, args=(0.05,), daemon=True).start()


@pytest.fixture
def server(flights_zip):
    s = Server()
    s.payload = flights_zip
    yield s
    s.httpd.shutdown()
    s.httpd.server_close()


@pytest.fixture(autouse=True)
def data_home(tmp_path, monkeypatch) -> Path:
    """The user data folder in tmp_path, and no $XAIRL_UKM_DATA: nothing touches the real home."""
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "share"))
    monkeypatch.delenv(ukm.ENV, raising=False)
    for var in ("no_proxy", "NO_PROXY"):  # the loopback server is never reached through a proxy
        monkeypatch.setenv(var, "127.0.0.1")
    return tmp_path / "share" / "xairl"


def sha(data: bytes) -> str:
    return hashlib.sha256(data).hexdigest()


def closed_port_url() -> str:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    return f"http://127.0.0.1:{port}/raw_dataset.zip"


def test_first_use_downloads_and_second_use_reads_the_cache(server, data_home, capsys):
    folder = ukm.flights_folder(url=server.url, sha256=sha(server.payload))
    assert folder == data_home / ukm.FOLDER and server.requests == 1
    assert sorted(p.name for p in folder.iterdir()) == sorted([*NAMES, "SOURCE.txt"])
    assert all((folder / n).read_bytes() == (UKM / n).read_bytes() for n in NAMES)
    note = (folder / "SOURCE.txt").read_text()
    assert "GPL-3.0" in note and server.url in note and ukm.COMMIT in note and ukm.REPO in note
    assert [p.name for p in data_home.iterdir()] == [ukm.FOLDER], "no temporary file or staging folder is left"
    assert "downloading the UKM UAV flights" in capsys.readouterr().err
    assert ukm.flights_folder(url=server.url, sha256=sha(server.payload)) == folder and server.requests == 1
    flights, bad = load_folder(folder)
    assert [f.altitude_m for f in flights] == [140.0, 80.0] and not bad


def test_wrong_checksum_is_refused_and_leaves_nothing(server, data_home):
    with pytest.raises(InputError, match="sha256 .* not the pinned 0{64}: refused and deleted") as info:
        ukm.flights_folder(url=server.url, sha256="0" * 64)
    assert "\n" not in str(info.value) and ukm.ENV in str(info.value)
    assert list(data_home.iterdir()) == []


def test_interrupted_download_leaves_nothing(server, data_home):
    server.short = True  # the connection closes before the announced length
    with pytest.raises(InputError, match="could not download the UKM flights"):
        ukm.flights_folder(url=server.url, sha256=sha(server.payload))
    assert list(data_home.iterdir()) == []


def test_unreachable_server_says_how_to_get_the_data(data_home):
    url = closed_port_url()
    with pytest.raises(InputError) as info:
        ukm.flights_folder(url=url, sha256="0" * 64, timeout=2)
    msg = str(info.value)
    assert msg.startswith("could not download the UKM flights (") and "\n" not in msg
    assert f"download {url} (sha256 {'0' * 64})" in msg and "-o real=PATH" in msg and f"{ukm.ENV}=PATH" in msg
    assert not (data_home / ukm.FOLDER).exists()


def test_env_var_folder_or_zip(tmp_path, monkeypatch, flights_zip, data_home):
    url = closed_port_url()  # any request would fail
    own = tmp_path / "own"
    own.mkdir()
    shutil.copy(UKM / NAMES[0], own / NAMES[0])
    monkeypatch.setenv(ukm.ENV, str(own))
    assert ukm.flights_folder(url=url) == own
    (tmp_path / "flights.zip").write_bytes(flights_zip)
    monkeypatch.setenv(ukm.ENV, str(tmp_path / "flights.zip"))
    folder = ukm.flights_folder(url=url)
    assert folder.parent == data_home and sorted(p.name for p in folder.glob("*.csv")) == sorted(NAMES)
    assert ukm.flights_folder(url=url) == folder
    monkeypatch.setenv(ukm.ENV, str(tmp_path / "missing"))
    with pytest.raises(InputError, match=f"{ukm.ENV}=.*missing: no such folder or zip"):
        ukm.flights_folder(url=url)
    assert ukm.flights_folder(own) == own, "an explicit path comes before the env var"


@pytest.mark.parametrize("name", ["../evil.csv", "Measured Data/../../evil.csv", "/tmp/evil.csv"])
def test_unsafe_zip_is_refused(server, data_home, tmp_path, name):
    server.payload = make_zip({"Measured Data/80m.csv": (UKM / "80m.csv").read_bytes(), name: b"x"})
    with pytest.raises(InputError, match="unsafe member name"):
        ukm.flights_folder(url=server.url, sha256=sha(server.payload))
    assert list(data_home.iterdir()) == [] and not list(tmp_path.rglob("evil.csv"))


def test_oversized_member_is_refused(server, data_home, monkeypatch):
    monkeypatch.setattr(ukm, "MAX_MEMBER", 100_000)
    with pytest.raises(InputError, match="unpacks to more than 100000 bytes"):
        ukm.flights_folder(url=server.url, sha256=sha(server.payload))
    assert list(data_home.iterdir()) == []


def test_report_skips_the_real_half_when_ukm_cannot_be_had(monkeypatch, capsys, tmp_path, server):
    monkeypatch.setattr(ukm, "URL", closed_port_url())
    folder, setting = real_source("ukm")
    err = capsys.readouterr().err.strip().splitlines()
    assert folder is None and setting.startswith("not available: could not download the UKM flights")
    assert len(err) == 1 and err[0].startswith("xairl: report: real-data half skipped: could not download")
    monkeypatch.setattr(ukm, "URL", server.url)
    monkeypatch.setattr(ukm, "SHA256", sha(server.payload))
    folder, setting = real_source("ukm")
    assert folder is not None and "GPL-3.0" in setting
    assert setting.startswith(f"{folder.name} (") and str(folder) not in setting  # a shared report: no local path
    assert real_source(None)[0] is None
    with pytest.raises(InputError, match="nowhere: no such folder or zip of flight exports"):
        real_source(str(tmp_path / "nowhere"))  # refused before Table I is computed

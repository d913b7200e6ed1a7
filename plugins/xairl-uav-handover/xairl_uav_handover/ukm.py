"""Locate or fetch the UKM UAV flights, the real data of ``xairl report --plugin uav-handover -o real=ukm``.

The data: 29 drive-test exports (Nemo CSV) of a drone flying at fixed heights over a live 4G LTE network on the UKM
campus (Bangi, Malaysia), folder ``Measured Data/`` of ``raw_dataset.zip`` in
github.com/Mehranbjt/Empirical-3D-Channel-Modeling-for-Cellular-Connected-UAVs, pinned at :data:`COMMIT` and
:data:`SHA256`. Licence: GNU GPL v3 (the repository's only licence; it covers the data); Zenodo
doi:10.5281/zenodo.17677745. Cite: M. Behjati, M. A. Zulkifley, H. A. H. Alobaidy, R. Nordin, N. F. Abdullah,
"Reliable Aerial Mobile Communications with RSRP & RSRQ Prediction Models for the Internet of Drones: A Machine
Learning Approach", Sensors 22(15):5522, 2022, doi:10.3390/s22155522. xairl never ships the data: it is fetched on
first use into the user's data folder.

:func:`flights_folder` says where the flights are; the first that applies wins: an explicit path (a folder of CSVs or
a zip of them), ``$XAIRL_UKM_DATA`` (same forms), the copy already extracted in the data folder (:func:`data_home`),
a download (:func:`download`). A download streams to a temporary file in the data folder, must match the pinned
sha256, has only its ``Measured Data/*.csv`` extracted (no path traversal, bounded sizes) beside a ``SOURCE.txt``
stating origin and licence, and is renamed into place in one step, so an interrupted one leaves no half folder under
the final name. Anything that fails raises :class:`xairl.InputError` with one line saying how to get the data.
"""

from __future__ import annotations

import hashlib
import http.client
import os
import shutil
import socket
import sys
import tempfile
import urllib.error
import urllib.request
import zipfile
import zlib
from pathlib import Path, PurePosixPath

from xairl import InputError

from .exports import MAX_FILE_BYTES, check_plain

REPO = "https://github.com/Mehranbjt/Empirical-3D-Channel-Modeling-for-Cellular-Connected-UAVs"
COMMIT = "5fa8f2ad98efde4d28466f5922c61ceb470f840a"
URL = f"{REPO}/raw/{COMMIT}/raw_dataset.zip"
SHA256 = "495129a7ccbd6bf1849ad2d56528e8e3179ba63bc6c5bc9a9a34c9f9dbc45c86"
LICENCE = "GPL-3.0"
ENV = "XAIRL_UKM_DATA"  # a folder of the CSVs or the zip, used instead of the cache or a download
KEYWORD = "ukm"  # the report's -o real=ukm
FOLDER = "ukm-uav-lte"  # the extracted copy under data_home()
MEMBER_DIR = "Measured Data"
TIMEOUT_S = 20.0
MAX_DOWNLOAD = 64 << 20  # bytes; the pinned zip is a few MB
MAX_MEMBER = MAX_FILE_BYTES  # uncompressed bytes per CSV (the largest is 1.2 MB), as a CSV in a folder
MAX_TOTAL = 128 << 20  # uncompressed bytes extracted in all (the 29 CSVs: 22 MB)
MAX_MEMBERS = 1000
NAME_MAX = 255  # bytes of a file name on the usual file systems (ext4, APFS, NTFS in UTF-16 units)


def data_home() -> Path:
    """xairl's user data folder: ``$XDG_DATA_HOME/xairl``, else ``~/.local/share/xairl``."""
    base = os.environ.get("XDG_DATA_HOME", "")
    return (Path(base) if os.path.isabs(base) else Path.home() / ".local" / "share") / "xairl"


def flights_folder(
    path: str | Path | None = None,
    *,
    root: str | Path | None = None,
    url: str | None = None,
    sha256: str | None = None,
    timeout: float = TIMEOUT_S,
) -> Path:
    """The folder of flight CSVs: ``path`` (a folder, or a zip extracted once under ``root``), else ``$XAIRL_UKM_DATA``,
    else the UKM copy cached under ``root`` (default :func:`data_home`), else downloaded there from ``url`` (default
    :data:`URL`), checked against ``sha256`` (default :data:`SHA256`).

    An explicit ``path`` that does not exist is returned as given, for the caller to report; one that exists but is
    no readable zip (empty, truncated, encrypted, unreadable, another kind of file) raises :class:`InputError`.
    """
    root = Path(root) if root is not None else data_home()
    if path is not None:
        return _given(Path(path).expanduser(), root) or Path(path)
    if os.environ.get(ENV):
        try:
            found = _given(Path(os.environ[ENV]).expanduser(), root)
        except InputError as exc:
            raise InputError(f"{ENV}={os.environ[ENV]}: {exc}") from None
        if found is None:
            raise InputError(f"{ENV}={os.environ[ENV]}: no such folder or zip of flight exports; fix or unset it.")
        return found
    if _has_csv(root / FOLDER):
        return root / FOLDER
    return download(root, url or URL, sha256 or SHA256, timeout)


def _given(path: Path, root: Path) -> Path | None:
    """A folder as is; a zip extracted once into ``root`` (the pinned one into the UKM cache); None where nothing is
    there. A file that is there but no readable zip raises :class:`InputError` saying what it is."""
    if path.is_dir():
        return path
    if not path.exists():
        return None
    _check_zip_file(path)
    digest = _sha256_file(path)
    pinned = digest == SHA256
    final = root / (FOLDER if pinned else f"{FOLDER}-zip-{digest[:12]}")
    if not _has_csv(final):
        _install(path, final, _note(str(path.resolve()), digest, pinned))
    return final


def _check_zip_file(path: Path) -> None:
    """Refuse, in one line, a path that exists but is not a zip that can be opened: not a regular file (a FIFO, a
    device: the folder path's check, :func:`exports.check_plain`), larger than a download may be, unreadable, empty,
    truncated (a zip's directory is at its end), or some other kind of file."""
    check_plain(path, MAX_DOWNLOAD)
    try:
        with open(path, "rb") as fh:
            head = fh.read(4)
    except OSError as exc:
        raise InputError(f"{path}: cannot read it ({_reason(exc, 0)}); {_GIVE}") from None
    if not head:
        raise InputError(
            f"{path}: the file is empty (0 bytes), not a zip of flight exports; download it again or {_GIVE}"
        )
    if zipfile.is_zipfile(path):
        return
    if head == b"PK\x03\x04":  # a zip's first member, but no directory at the end
        raise InputError(
            f"{path}: a zip without its directory at the end ({path.stat().st_size} bytes): truncated "
            f"(an interrupted download or copy); download it again."
        )
    raise InputError(f"{path}: a file, but neither a folder nor a zip of flight exports; {_GIVE}")


#: what a user can pass instead, ending every refusal of a given path
_GIVE = "give a folder of the Nemo CSVs or the UKM zip."


def download(root: str | Path, url: str = URL, sha256: str = SHA256, timeout: float = TIMEOUT_S) -> Path:
    """Fetch the zip from ``url`` into ``root``, check its sha256, extract its flights to ``root/ukm-uav-lte``."""
    root = Path(root)
    _make_folder(root, url, sha256)
    fd, name = tempfile.mkstemp(prefix=".ukm-download-", suffix=".zip", dir=root)
    tmp = Path(name)
    try:
        with os.fdopen(fd, "wb") as out:
            digest = _fetch(url, out, sha256, timeout)
        if digest != sha256:
            raise InputError(
                f"the UKM flights downloaded from {url} have sha256 {digest}, not the pinned {sha256}: "
                f"refused and deleted; {_how(url, sha256)}"
            )
        final = root / FOLDER
        _install(tmp, final, _note(url, digest, True))
        return final
    finally:
        tmp.unlink(missing_ok=True)


def _make_folder(root: Path, url: str, sha256: str) -> None:
    try:
        root.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise InputError(f"cannot create the data folder {root} ({_reason(exc, 0)}); {_how(url, sha256)}") from None


def _fetch(url: str, out, sha256: str, timeout: float) -> str:
    """Stream ``url`` into ``out`` (at most :data:`MAX_DOWNLOAD` bytes); its sha256."""
    digest, size = hashlib.sha256(), 0
    try:
        with urllib.request.urlopen(url, timeout=timeout) as resp:
            announced = int(resp.headers.get("Content-Length") or -1)
            print(f"xairl: downloading the UKM UAV flights ({LICENCE}) from {url}", file=sys.stderr)
            while chunk := resp.read(1 << 16):
                size += len(chunk)
                if size > MAX_DOWNLOAD:
                    raise InputError(
                        f"{url} sends more than {MAX_DOWNLOAD >> 20} MiB, not the UKM zip; refused; {_how(url, sha256)}"
                    )
                digest.update(chunk)
                out.write(chunk)
        if 0 <= size < announced:
            raise ConnectionError(f"the connection closed after {size} of {announced} bytes")
    except InputError:
        raise
    except (OSError, ValueError, http.client.HTTPException) as exc:  # ValueError: a malformed URL
        raise InputError(f"could not download the UKM flights ({_reason(exc, timeout)}); {_how(url, sha256)}") from None
    return digest.hexdigest()


def _reason(exc: BaseException, timeout: float) -> str:
    if isinstance(exc, urllib.error.HTTPError):
        text = f"HTTP {exc.code} {exc.reason}"
    elif isinstance(exc, (TimeoutError, socket.timeout)) or isinstance(getattr(exc, "reason", None), TimeoutError):
        text = f"no answer within {timeout:g} s"
    else:
        text = str(getattr(exc, "reason", None) or exc) or type(exc).__name__
    return " ".join(text.split())


def _how(url: str, sha256: str) -> str:
    return (
        f"download {url} (sha256 {sha256}) and pass -o real=PATH or set {ENV}=PATH (PATH: the zip, or a folder of "
        f"its '{MEMBER_DIR}' CSVs)"
    )


def _install(zip_path: Path, final: Path, note: str) -> None:
    """Extract the zip's flight CSVs and ``note`` into a staging folder beside ``final``, then rename it into place."""
    _make_folder(final.parent, URL, SHA256)
    stage = Path(tempfile.mkdtemp(prefix=f".{final.name}-", dir=final.parent))
    try:
        _extract_csvs(zip_path, stage)
        (stage / "SOURCE.txt").write_text(note, encoding="utf-8")
        try:
            os.rename(stage, final)
        except OSError:  # another process put it there first, or something else is in the way
            if not _has_csv(final):
                raise InputError(f"{final} is in the way and holds no CSV; delete it and retry.") from None
    finally:
        shutil.rmtree(stage, ignore_errors=True)


def _extract_csvs(zip_path: Path, dest: Path) -> int:
    """Copy the zip's flight CSVs into ``dest`` by base name; the bytes written."""
    try:
        with zipfile.ZipFile(zip_path) as zf:
            total = 0
            for info in _flight_members(zf, zip_path):
                total += _copy_member(zf, info, dest / PurePosixPath(info.filename).name, zip_path, MAX_TOTAL - total)
            return total
    except (zipfile.BadZipFile, zipfile.LargeZipFile, zlib.error, EOFError, NotImplementedError) as exc:
        raise InputError(f"{zip_path}: not a readable zip archive ({' '.join(str(exc).split())}).") from None
    except OSError as exc:  # reading the zip, or writing beside the data folder (disk full, read-only)
        raise InputError(f"{zip_path}: cannot extract it into {dest.parent} ({_reason(exc, 0)}).") from None


def _flight_members(zf: zipfile.ZipFile, zip_path: Path) -> list[zipfile.ZipInfo]:
    """The CSVs under a ``Measured Data/`` folder (else every CSV); refuses a zip with any unsafe member name."""
    infos = zf.infolist()
    if len(infos) > MAX_MEMBERS:
        raise InputError(f"{zip_path}: {len(infos)} members, more than {MAX_MEMBERS}; not a zip of flight exports.")
    for info in infos:
        parts = PurePosixPath(info.filename.replace("\\", "/"))
        if parts.is_absolute() or ".." in parts.parts or ":" in info.filename:
            raise InputError(f"{zip_path}: unsafe member name '{_short(info.filename)}' (absolute or '..'); refused.")
    csvs = [
        i
        for i in infos
        if not i.is_dir()
        and i.filename.lower().endswith(".csv")
        and "__MACOSX" not in PurePosixPath(i.filename).parts
        and not PurePosixPath(i.filename).name.startswith(".")
    ]
    chosen = [i for i in csvs if PurePosixPath(i.filename).parent.name == MEMBER_DIR] or csvs
    names = [PurePosixPath(i.filename).name for i in chosen]
    if not chosen:
        raise InputError(f"{zip_path}: no CSV in the zip (expected '{MEMBER_DIR}/*.csv').")
    if len(set(names)) < len(names):
        raise InputError(f"{zip_path}: two CSVs share a file name; extract it yourself and pass the folder.")
    for info, name in zip(chosen, names):
        if info.flag_bits & 0x1:
            raise InputError(
                f"{zip_path}: '{_short(info.filename)}' is encrypted (password-protected); extract "
                f"the zip yourself with its password and pass the folder."
            )
        if len(name.encode("utf-8", "surrogateescape")) > NAME_MAX:
            raise InputError(
                f"{zip_path}: the member '{_short(info.filename)}' has a file name longer than "
                f"the {NAME_MAX} bytes a file system allows; extract its CSVs under shorter names and "
                f"pass the folder."
            )
    return chosen


def _short(name: str, limit: int = 80) -> str:
    """A member name on one line, at most ``limit`` characters (a hostile one can be thousands)."""
    name = " ".join(name.split())
    return name if len(name) <= limit else f"{name[: limit // 2]}...{name[-limit // 2 :]}"


def _copy_member(zf: zipfile.ZipFile, info: zipfile.ZipInfo, target: Path, zip_path: Path, budget: int) -> int:
    limit = min(MAX_MEMBER, budget)
    too_big = InputError(
        f"{zip_path}: '{_short(info.filename)}' unpacks to more than {limit} bytes (limits: "
        f"{MAX_MEMBER} a file, {MAX_TOTAL} in all); refused."
    )
    if info.file_size > limit:
        raise too_big
    written = 0
    with zf.open(info) as src, open(target, "xb") as dst:
        while chunk := src.read(1 << 16):
            written += len(chunk)
            if written > limit:
                raise too_big
            dst.write(chunk)
    return written


def _note(origin: str, digest: str, ukm: bool) -> str:
    """The text of SOURCE.txt: where the files came from and under which licence."""
    if not ukm:
        return (
            f"Flight exports extracted by xairl-uav-handover from {origin} (sha256 {digest}).\n"
            "This is not the pinned UKM archive: its licence is whatever its source states.\n"
        )
    return (
        f"UKM UAV LTE flights: drive-test exports of a drone over a live 4G LTE network (UKM, Bangi, Malaysia).\n"
        f"Licence: GNU General Public License v3 ({LICENCE}), the licence of the source repository, which covers "
        f"this data. Not part of xairl and not redistributed with it.\n"
        f"Origin: {origin}\nRepository: {REPO}\nCommit: {COMMIT}\n"
        f"Archive: raw_dataset.zip (sha256 {digest}); folder '{MEMBER_DIR}/', CSVs extracted unmodified.\n"
        f"Zenodo: doi:10.5281/zenodo.17677745\n"
        'Cite: M. Behjati, M. A. Zulkifley, H. A. H. Alobaidy, R. Nordin, N. F. Abdullah, "Reliable Aerial Mobile '
        "Communications with RSRP & RSRQ Prediction Models for the Internet of Drones: A Machine Learning "
        'Approach", Sensors 22(15):5522, 2022, doi:10.3390/s22155522.\n'
    )


def _has_csv(folder: Path) -> bool:
    return folder.is_dir() and any(folder.glob("*.csv"))


def _sha256_file(path: Path) -> str:
    digest = hashlib.sha256()
    with open(path, "rb") as f:
        while chunk := f.read(1 << 20):
            digest.update(chunk)
    return digest.hexdigest()

"""Writing files so that a crash, a ``kill -9`` or a full disk never leaves a partial file under its final name.

Everything xairl writes for a user (explanations, reports, figures, exports, checkpoints) goes through
:func:`atomic_write`: the bytes go to a hidden temporary file beside the target (``.NAME.*.part``), are flushed to
disk, and only then renamed over the target, which is atomic on POSIX and Windows file systems. A reader sees the
old file or the complete new one, never a mix; an interrupted write leaves at most a ``.part`` file. The file gets
the permissions any new file gets under the user's umask (``mkstemp`` alone makes it ``-rw-------``, which no web
server or colleague can read).
"""

from __future__ import annotations

import os
import tempfile
from collections.abc import Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO


@contextmanager
def atomic_write(path: str | Path, mode: str = "w") -> Iterator[IO]:
    """A file object to write ``path`` through (``mode`` 'w' for UTF-8 text, 'wb' for bytes); renamed into place
    when the block ends without an exception, removed otherwise."""
    path = Path(path)
    fd, tmp = tempfile.mkstemp(dir=path.parent, prefix=f".{path.name}.", suffix=".part")
    try:
        os.chmod(tmp, 0o666 & ~_umask())  # as open() would make it: a report can be served and shared
        with os.fdopen(fd, mode, **({} if "b" in mode else {"encoding": "utf-8"})) as fh:
            yield fh
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
    except BaseException:
        try:
            os.unlink(tmp)
        except OSError:
            pass
        raise


def _umask() -> int:
    """The process's umask (read by setting it, then setting it back: the only way POSIX offers)."""
    mask = os.umask(0o022)
    os.umask(mask)
    return mask


def write_text(path: str | Path, text: str) -> Path:
    """``path.write_text(text)``, atomically."""
    with atomic_write(path) as fh:
        fh.write(text)
    return Path(path)


def save_figure(fig, path: str | Path, **kwargs) -> Path:
    """``fig.savefig(path)``, atomically (the format is taken from the name's suffix)."""
    path = Path(path)
    with atomic_write(path, "wb") as fh:
        fig.savefig(fh, format=path.suffix.lstrip(".") or "png", **kwargs)
    return path

"""Human-in-the-loop store (SQLite): every shown narrative, and the operator's verdict on it.

Each write is one short ``BEGIN IMMEDIATE`` transaction on its own connection, in WAL mode with a generous busy
timeout, so many processes can record at once without losing rows, and an interrupted write rolls back cleanly.
"""

from __future__ import annotations

import json
import sqlite3
import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TextIO

from xairl.errors import InputError
from xairl.policies.policy import model_hash
from xairl.runs.paths import user_dir

SCHEMA = """
CREATE TABLE IF NOT EXISTS narratives (
    id INTEGER PRIMARY KEY AUTOINCREMENT,
    created REAL NOT NULL,
    policy TEXT, model_hash TEXT, template TEXT, source TEXT, method TEXT,
    state_index INTEGER,
    text TEXT NOT NULL,
    claims TEXT NOT NULL,
    verified INTEGER NOT NULL,
    confidence REAL NOT NULL,
    status TEXT NOT NULL DEFAULT 'pending' CHECK (status IN ('pending', 'accepted', 'rejected', 'corrected')),
    correction TEXT,
    reviewed REAL,
    evidence TEXT
)"""
STATUSES = ("accepted", "rejected", "corrected")


@dataclass(frozen=True)
class Record:
    id: int
    policy: str | None
    template: str | None
    source: str | None
    text: str
    claims: list
    verified: bool
    confidence: float
    status: str
    correction: str | None
    evidence: dict | None = None  # xairl.explanations.evidence.evidence(): the state, contributions, sentence statuses


class FeedbackStore:
    """:param path: SQLite file; default ``<user dir>/feedback.sqlite``."""

    def __init__(self, path: str | Path | None = None):
        self.path = Path(path) if path else user_dir() / "feedback.sqlite"
        if path is None:
            self.path.parent.mkdir(parents=True, exist_ok=True)
        elif not self.path.parent.is_dir():
            raise InputError(
                f"{self.path}: the folder {self.path.parent} does not exist; create it or pass another path."
            )
        if self.path.is_dir():
            raise InputError(f"{self.path} is a folder; pass a file path for the feedback store.")
        try:
            with self._tx() as db:
                db.execute(SCHEMA)
                if "evidence" not in {row[1] for row in db.execute("PRAGMA table_info(narratives)")}:
                    db.execute("ALTER TABLE narratives ADD COLUMN evidence TEXT")  # a store from before 0.3
        except sqlite3.DatabaseError as exc:
            raise InputError(
                f"{self.path}: not a usable feedback store ({exc}); move it away or pass another path."
            ) from None

    @contextmanager
    def _tx(self) -> Iterator[sqlite3.Connection]:
        db = sqlite3.connect(self.path, timeout=60, isolation_level=None)
        try:
            db.execute("PRAGMA journal_mode=WAL")
            db.execute("PRAGMA busy_timeout=60000")
            db.execute("BEGIN IMMEDIATE")
            try:
                yield db
                db.execute("COMMIT")
            except BaseException:
                db.execute("ROLLBACK")
                raise
        finally:
            db.close()

    def record(self, narrative, policy=None, explanation=None) -> int:
        """Store a shown :class:`xairl.Narrative` with its evidence for the review page (the one it carries, else
        computed from ``explanation``); returns its id."""
        from xairl.explanations.evidence import evidence

        ev = getattr(narrative, "evidence", None)
        if ev is None and explanation is not None:
            ev = evidence(explanation, narrative)
        row = (
            time.time(),
            getattr(policy, "name", None),
            model_hash(policy.module) if policy is not None else None,
            narrative.template,
            narrative.source,
            narrative.extras.get("method"),
            narrative.index,
            narrative.text,
            json.dumps([{k: v for k, v in c.__dict__.items() if k != "span"} for c in narrative.claims]),
            int(narrative.verified),
            narrative.confidence,
            json.dumps(ev) if ev is not None else None,
        )
        with self._tx() as db:
            cur = db.execute(
                "INSERT INTO narratives (created, policy, model_hash, template, source, method, "
                "state_index, text, claims, verified, confidence, evidence) "
                "VALUES (?,?,?,?,?,?,?,?,?,?,?,?)",
                row,
            )
            return int(cur.lastrowid)

    def records(self, status: str | None = None) -> list[Record]:
        db = sqlite3.connect(self.path, timeout=60)
        try:
            q = (
                "SELECT id, policy, template, source, text, claims, verified, confidence, status, correction, "
                "evidence FROM narratives" + (" WHERE status = ?" if status else "") + " ORDER BY id"
            )
            rows = db.execute(q, (status,) if status else ()).fetchall()
        finally:
            db.close()
        return [
            Record(
                r[0],
                r[1],
                r[2],
                r[3],
                r[4],
                json.loads(r[5]),
                bool(r[6]),
                r[7],
                r[8],
                r[9],
                json.loads(r[10]) if r[10] else None,
            )
            for r in rows
        ]

    def review(self, record_id: int, status: str, correction: str | None = None) -> None:
        """Mark a narrative accepted, rejected or corrected (with the operator's text)."""
        if status not in STATUSES:
            raise InputError(f"status must be one of {', '.join(STATUSES)}, not '{status}'.")
        if (status == "corrected") != bool(correction and correction.strip()):
            raise InputError("a correction needs its text, and only 'corrected' takes one.")
        with self._tx() as db:
            cur = db.execute(
                "UPDATE narratives SET status = ?, correction = ?, reviewed = ? WHERE id = ?",
                (status, correction, time.time(), record_id),
            )
            if cur.rowcount == 0:
                raise InputError(f"no narrative with id {record_id} in {self.path}.")

    def export_corrections(self, out: TextIO) -> int:
        """Write corrected narratives as JSON lines (original, correction, template); returns how many."""
        n = 0
        for r in self.records("corrected"):
            out.write(
                json.dumps(
                    {
                        "id": r.id,
                        "template": r.template,
                        "policy": r.policy,
                        "original": r.text,
                        "correction": r.correction,
                    }
                )
                + "\n"
            )
            n += 1
        return n

    def examples(self, limit: int = 3) -> list[str]:
        """The latest corrections and accepted texts, as examples for the local LM narrator."""
        recs = [
            r.correction if r.status == "corrected" else r.text
            for r in self.records()
            if r.status in ("corrected", "accepted")
        ]
        return recs[-limit:]

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
from xairl.explanations.evidence import verdict_of
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
    evidence TEXT,
    verdict TEXT,
    coverage REAL,
    account TEXT
)"""
#: columns added after the first release, each with its type: a store from before them gains them when opened (its
#: rows read the verdict from ``verified`` and their evidence's sentences)
ADDED = {"evidence": "TEXT", "verdict": "TEXT", "coverage": "REAL", "account": "TEXT"}
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
    status: str  # the operator's: pending, accepted, rejected or corrected
    correction: str | None
    evidence: dict | None = None  # xairl.explanations.evidence.evidence(): the state, contributions, sentence statuses
    verdict: str = ""  # the verifier's: verified, contradicted or partly checked
    coverage: float | None = None  # the share of the text's claims that were checked (None: not recorded)
    account: str = ""  # what its features account for of the margin, and what it leaves out


def _record(r: tuple) -> Record:
    """A row as a :class:`Record`; a row from before the three verdicts reads its verdict from ``verified`` and its
    evidence's sentences (:func:`xairl.explanations.evidence.verdict_of`)."""
    ev = json.loads(r[10]) if r[10] else None
    verdict = r[11] or verdict_of({**(ev or {}), "verified": bool(r[6])})
    coverage = r[12] if r[12] is not None else (ev or {}).get("coverage")
    return Record(*r[:5], json.loads(r[5]), bool(r[6]), *r[7:10], ev, verdict, coverage, r[13] or "")


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
                have = {row[1] for row in db.execute("PRAGMA table_info(narratives)")}
                for column, kind in ADDED.items():
                    if column not in have:  # a store from before it
                        db.execute(f"ALTER TABLE narratives ADD COLUMN {column} {kind}")
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
            getattr(narrative, "status", None) or ("verified" if narrative.verified else None),
            getattr(narrative, "coverage", None),
            getattr(narrative, "account", ""),
        )
        with self._tx() as db:
            cur = db.execute(
                "INSERT INTO narratives (created, policy, model_hash, template, source, method, "
                "state_index, text, claims, verified, confidence, evidence, verdict, coverage, account) "
                "VALUES (?,?,?,?,?,?,?,?,?,?,?,?,?,?,?)",
                row,
            )
            return int(cur.lastrowid)

    def records(self, status: str | None = None) -> list[Record]:
        db = sqlite3.connect(self.path, timeout=60)
        try:
            q = (
                "SELECT id, policy, template, source, text, claims, verified, confidence, status, correction, "
                "evidence, verdict, coverage, account FROM narratives"
                + (" WHERE status = ?" if status else "")
                + " ORDER BY id"
            )
            rows = db.execute(q, (status,) if status else ()).fetchall()
        finally:
            db.close()
        return [_record(r) for r in rows]

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

"""The results journal of a sweep: one JSON line per finished point, appended as points finish.

``journal.jsonl`` in the study's output directory is the durable record of a
sweep. The client appends a line as soon as a point's result arrives and
flushes it to disk (``fsync``) before doing anything else, so an interrupted
sweep (Ctrl-C, a crash, a lost cluster) loses no finished point, and a worker
dying after its task returned cannot matter. The CSV table and the plots are
regenerated from the journal; running the study again skips points the
journal already holds (see :mod:`orchestrator.study.sweep`).

Each line is a JSON object with at least ``key`` (the point's identity),
``index``, ``status`` (``ok``, ``failed`` or ``error``), ``parameters``,
``measures`` and ``error``. Reading tolerates a torn last line (a crash in the
middle of a write): it is skipped, and the next append starts on a new line.
A line that cannot be written whole (a full disk) is cut off again and the error
names the journal. Only one sweep may write a journal at a time (an exclusive ``flock``).
"""

from __future__ import annotations

import fcntl
import json
import os
from pathlib import Path
from typing import Any, Iterable, Mapping

from components.errors import DtcosimError

from ..output_folders import STUDY_JOURNAL

JOURNAL_FILE = STUDY_JOURNAL


class JournalError(DtcosimError, RuntimeError):
    """The journal cannot be written (locked by another sweep, or an I/O error)."""


class Journal:
    """Append-only writer of a sweep journal (use as a context manager).

    Parameters
    ----------
    path : path
        The ``journal.jsonl`` file (created with its directory if missing).

    Raises
    ------
    JournalError
        When another process holds the journal (a sweep of the same study into
        the same directory is running).
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self._fh = None

    def __enter__(self) -> "Journal":
        self.path.parent.mkdir(parents=True, exist_ok=True)
        fh = open(self.path, "a+b", buffering=0)  # unbuffered: nothing left to write when the file is closed
        try:
            fcntl.flock(fh.fileno(), fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            fh.close()
            raise JournalError(f"{self.path} is in use by another sweep (wait for it, or use another --out)") from None
        fh.seek(0, os.SEEK_END)
        if fh.tell() > 0:
            fh.seek(-1, os.SEEK_END)
            if fh.read(1) != b"\n":  # a torn last line: start the next record on a line of its own
                try:
                    _write_all(fh.fileno(), b"\n")
                except OSError as exc:
                    fh.close()
                    raise OSError(exc.errno, exc.strerror or str(exc), str(self.path)) from None
        self._fh = fh
        return self

    def __exit__(self, *exc) -> None:
        self.close()

    def append(self, record: Mapping[str, Any]) -> None:
        """Write one record as a line and force it to disk (fsync); raises OSError naming the journal."""
        if self._fh is None:
            raise JournalError(f"{self.path} is not open for writing")
        line = (json.dumps(record, allow_nan=False, separators=(",", ":")) + "\n").encode("utf-8")
        fd = self._fh.fileno()
        end = os.lseek(fd, 0, os.SEEK_END)
        try:
            _write_all(fd, line)
            os.fsync(fd)
        except OSError as exc:  # a full disk: no part of the line stays (the journal holds whole records)
            try:
                os.ftruncate(fd, end)
            except OSError:
                pass
            raise OSError(exc.errno, exc.strerror or str(exc), str(self.path)) from None

    def close(self) -> None:
        """Release the lock and close the file."""
        if self._fh is not None:
            try:
                fcntl.flock(self._fh.fileno(), fcntl.LOCK_UN)
            finally:
                self._fh.close()
                self._fh = None


def _write_all(fd: int, data: bytes) -> None:
    """Write every byte of ``data`` to ``fd`` (a write may take part of it)."""
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


#: the statuses a journal record may have
RECORD_STATUSES = ("ok", "failed", "error")


def read_journal(path: str | Path) -> list[dict[str, Any]]:
    """Every complete record of a journal, in file order (empty if the file does not exist).

    Lines that are not a JSON object with a ``key`` and a known ``status`` (a torn
    last line, a record edited by hand) are skipped: their points count as not
    run yet, and the next sweep runs them again.
    """
    path = Path(path)
    if not path.is_file():
        return []
    out = []
    with open(path, encoding="utf-8", errors="replace") as fh:
        for line in fh:
            line = line.strip()
            if not line:
                continue
            try:
                record = json.loads(line)
            except json.JSONDecodeError:
                continue
            if isinstance(record, dict) and isinstance(record.get("key"), str) \
                    and record.get("status") in RECORD_STATUSES:
                out.append(record)
    return out


def latest_by_key(records: Iterable[Mapping[str, Any]]) -> dict[str, dict[str, Any]]:
    """The last record of every key (a re-tried point's newest result wins)."""
    out: dict[str, dict[str, Any]] = {}
    for record in records:
        out[record["key"]] = dict(record)
    return out

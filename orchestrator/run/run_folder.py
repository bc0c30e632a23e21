"""The output folder of one run: checked before anything starts, holding the files of one run only.

:meth:`RunFolder.prepare` makes sure the folder can be written (it is not a
file, it can be created, a probe file can be written) and removes what a
previous run left in it: the files its ``summary.json`` lists (whole or not)
and the summary itself. Files that are not a dtcosim run's are never touched.
Then it writes a first ``summary.json`` that says the run is in progress
(``"status": "running"``, ``"complete": false``); :meth:`RunFolder.commit`
adds each file to that summary as soon as it is whole, so at every moment the
summary tells what the folder holds, also after the process was killed.

One run at a time: :meth:`RunFolder.prepare` takes an exclusive lock (``flock``) on the
folder itself and keeps it until :meth:`RunFolder.release` (or the process ends); a second
run into a folder in use is refused before it touches anything, naming the folder and the
holder's pid from its running summary (two runs into one folder corrupted each other's files).

Every file goes in by temporary file and rename (:mod:`orchestrator.atomic_files`);
the results file is streamed into ``<name>.partial`` and renamed when whole
(:mod:`orchestrator.run.writers`).
"""

from __future__ import annotations

import contextlib
import datetime as _dt
import json
import os
from pathlib import Path
from typing import Any, Mapping

from ..errors import EntryError
from ..result_files import write_summary
from .writers import PARTIAL_SUFFIX

SUMMARY_FILE = "summary.json"
RUNNING, COMPLETE, STOPPED, FAILED = "running", "complete", "stopped", "failed"


class OutputFolderError(EntryError):
    """The output folder cannot hold a run's results (names the option, the folder and the reason)."""

    kind = "command-line"


def _now() -> str:
    return _dt.datetime.now(_dt.timezone.utc).isoformat(timespec="seconds")


def _plain_name(name: Any) -> bool:
    return isinstance(name, str) and name and "/" not in name and "\\" not in name and name not in (".", "..")


def listed_files(summary: Mapping[str, Any]) -> set[str]:
    """File names a run's summary lists (``files`` and ``files_incomplete``), plain names only."""
    names: set[str] = set()
    for entry in dict(summary.get("files") or {}).values():
        if _plain_name(entry):
            names.add(entry)
    for entry in dict(summary.get("files_incomplete") or {}).values():
        name = entry.get("file") if isinstance(entry, Mapping) else entry
        if _plain_name(name):
            names.add(name)
    return names


class RunFolder:
    """The folder a run writes into (see the module docstring).

    Parameters
    ----------
    path : path
        The output folder.
    """

    def __init__(self, path: str | Path) -> None:
        self.path = Path(path)
        self.header: dict[str, Any] = {}
        self.files: dict[str, str] = {}
        self.incomplete: dict[str, dict[str, Any]] = {}
        self.replaced: list[str] = []

    @property
    def summary_path(self) -> Path:
        return self.path / SUMMARY_FILE

    # ------------------------------------------------------------- checks
    @classmethod
    def check(cls, path: str | Path, key: str = "--out") -> Path:
        """Raise :class:`OutputFolderError` unless ``path`` is (or can become) a writable folder."""
        path = Path(path)
        if path.exists() and not path.is_dir():
            raise OutputFolderError(key, str(path), "a folder for the results (this is a file)")
        try:
            path.mkdir(parents=True, exist_ok=True)
            probe = path / f".dtcosim-write-test-{os.getpid()}"
            probe.write_bytes(b"")
            probe.unlink()
        except OSError as exc:
            raise OutputFolderError(key, str(path), f"a folder dtcosim can write ({exc.strerror or exc})") from None
        return path

    @classmethod
    def prepare(cls, path: str | Path, header: Mapping[str, Any], key: str = "--out") -> "RunFolder":
        """Check the folder, remove the previous run's files, write the 'running' summary.

        Parameters
        ----------
        header : mapping
            What the summary says from the start (``scenario``, ``scenario_file``, ...).
        """
        folder = cls(cls.check(path, key))
        folder._lock(key)
        folder.header = {**dict(header), "started_at": _now(), "pid": os.getpid()}
        folder._clear_previous()
        folder.save()
        return folder

    def _lock(self, key: str) -> None:
        """Take the folder's run lock (see the module docstring); OutputFolderError when another run holds it."""
        import fcntl

        fd = os.open(self.path, os.O_RDONLY | os.O_DIRECTORY)  # the folder itself: no file of its own
        try:
            fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        except BlockingIOError:
            os.close(fd)
            try:
                holder = json.loads(self.summary_path.read_text(encoding="utf-8")).get("pid", "unknown")
            except (OSError, ValueError, AttributeError):
                holder = "unknown"
            raise OutputFolderError(key, str(self.path), f"a folder no other run is writing into (the run with pid "
                                    f"{holder} holds it: wait for it or choose another {key})") from None
        self._lock_fd = fd

    def release(self) -> None:
        """Release the folder's run lock."""
        fd = getattr(self, "_lock_fd", None)
        if fd is not None:
            self._lock_fd = None
            os.close(fd)

    def __del__(self) -> None:
        self.release()

    def _clear_previous(self) -> None:
        names: set[str] = set()
        try:
            previous = json.loads(self.summary_path.read_text(encoding="utf-8"))
        except (OSError, ValueError):
            previous = None
        if isinstance(previous, dict) and "scenario" in previous and "complete" in previous:
            names = listed_files(previous) | {SUMMARY_FILE}
        names |= {p.name for p in self.path.glob("*" + PARTIAL_SUFFIX)}
        names |= {p.name for p in self.path.glob(".*.tmp*")}  # temporary files of a killed run
        for name in sorted(names):
            target = self.path / name
            if target.is_file() or target.is_symlink():
                with contextlib.suppress(FileNotFoundError):
                    target.unlink()
                if name != SUMMARY_FILE and not name.startswith("."):
                    self.replaced.append(name)

    # ------------------------------------------------------------ summary
    def state(self) -> dict[str, Any]:
        """The running summary: header, status, files whole and not."""
        return {**self.header, "status": RUNNING, "complete": False, "files": dict(self.files),
                "files_incomplete": dict(self.incomplete)}

    def save(self, summary: Mapping[str, Any] | None = None) -> Path:
        """Write ``summary`` (default: the running state) as ``summary.json`` (atomic)."""
        return write_summary(self.summary_path, self.state() if summary is None else summary)

    def commit(self, role: str, path: Path) -> None:
        """Record a whole file (and update the running summary)."""
        self.files[role] = Path(path).name
        self.incomplete.pop(role, None)
        self.save()

    def mark_incomplete(self, role: str, path: Path, reason: str, **info: Any) -> None:
        """Record a file that is there but not whole (e.g. cut by a write error)."""
        self.files.pop(role, None)
        self.incomplete[role] = {"file": Path(path).name, "reason": reason, **info}
        with contextlib.suppress(OSError):
            self.save()

    def listing(self) -> dict[str, Any]:
        """``files`` and ``files_incomplete`` for the final summary."""
        out: dict[str, Any] = {"files": {**self.files, "summary": SUMMARY_FILE}}
        if self.incomplete:
            out["files_incomplete"] = dict(self.incomplete)
        return out

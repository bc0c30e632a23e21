"""The output folder of one run: checked before anything starts, holding the files of one run only.

:meth:`RunFolder.prepare` makes sure the folder can be written (it is not a
file, it can be created, a probe file can be written) and removes what a
previous run left in it: the files its ``summary.json`` lists (whole or not)
and the summary itself. Files that are not a dtcosim run's are never touched.
Then it writes a first ``summary.json`` that says the run is in progress
(``"status": "running"``, ``"complete": false``); :meth:`RunFolder.commit`
adds each file to that summary as soon as it is whole, so at every moment the
summary tells what the folder holds, also after the process was killed.

Every file a run writes is named in the running summary before it appears
(``files_being_written``: :meth:`RunFolder.claim`, called by
:func:`orchestrator.atomic_files.atomic_path` for every file written into the
folder), so the next run removes also the files of a run killed between writing a
file and listing it (a plot of seed 1 beside the results of seed 7). When the run
ends, a claimed file that was never listed (its stage failed after writing it) is
removed: the folder holds the files its summary lists and files that are not a
dtcosim run's.

A run that ends in any way other than SIGKILL leaves a summary that does not say
``running`` (:meth:`RunFolder.finish`, :meth:`RunFolder.abandon`): on a disk too
full for the whole summary a short one (status, stage, error, files), and if not
even that fits, none at all (the running summary is removed: it would say the run
is still going).

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

from ..atomic_files import claims_for, describe_os_error
from ..errors import EntryError, reason_of, signal_name
from ..output_folders import RUN_SUMMARY, check_for_run
from ..result_files import write_summary
from .writers import PARTIAL_SUFFIX

SUMMARY_FILE = RUN_SUMMARY
RUNNING, COMPLETE, STOPPED, FAILED = "running", "complete", "stopped", "failed"
#: the probe file :meth:`RunFolder.check` writes and removes
PROBE_PREFIX = ".dtcosim-write-test-"
#: what a summary shortened for a full disk keeps (:meth:`RunFolder.finish`)
BRIEF_KEYS = ("scenario", "description", "scenario_file", "results_format", "started_at", "pid", "status",
              "complete", "stage", "stopped_at", "error", "interrupted", "signal", "problems", "post_processing",
              "samples", "files", "files_incomplete")


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
    pending = summary.get("files_being_written")
    for name in pending if isinstance(pending, list) else ():
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
        #: names claimed (:meth:`claim`) and not listed yet
        self.pending: set[str] = set()
        #: why :meth:`finish` wrote a short summary (None: the whole one)
        self.shortened: str | None = None
        #: the last error of a running summary that could not be saved (a full disk); None after a save
        self.save_error: OSError | None = None
        self._claims: contextlib.ExitStack | None = None

    @property
    def summary_path(self) -> Path:
        return self.path / SUMMARY_FILE

    # ------------------------------------------------------------- checks
    @classmethod
    def check(cls, path: str | Path, key: str = "--out") -> Path:
        """Raise :class:`OutputFolderError` unless ``path`` is (or can become) a writable folder no other run holds.

        A folder that holds a sweep's or load set's results is refused too
        (:class:`~orchestrator.output_folders.MixedFolderError`). The run lock is only
        tried here (:meth:`prepare` takes it): a run into a folder in use is refused before
        it says anything about the folder's previous run.
        """
        path = Path(path)
        if path.exists() and not path.is_dir():
            raise OutputFolderError(key, str(path), "a folder for the results (this is a file)")
        try:
            path.mkdir(parents=True, exist_ok=True)
            probe = path / f"{PROBE_PREFIX}{os.getpid()}"
            try:
                probe.write_bytes(b"")
            finally:
                with contextlib.suppress(OSError):
                    probe.unlink()
        except OSError as exc:
            raise OutputFolderError(key, str(path), f"a folder dtcosim can write ({exc.strerror or exc})") from None
        check_for_run(path, key)  # a sweep's or load set's folder: refused (folders never mix)
        probe = cls(path)
        probe._lock(key)
        probe.release()
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
        try:
            folder._clear_previous()
            folder.save()
        except OSError as exc:  # a full disk: refused before anything runs (no summary: nothing ran)
            folder.release()
            with contextlib.suppress(OSError):
                folder.summary_path.unlink()
            raise OutputFolderError(key, str(folder.path), f"a folder with room for the results "
                                    f"({describe_os_error(exc)})") from None
        folder._claims = contextlib.ExitStack()
        folder._claims.enter_context(claims_for(folder.path, folder.claim))
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
        """Release the folder's run lock (and stop claiming the files written into it)."""
        claims, self._claims = getattr(self, "_claims", None), None
        if claims is not None:
            claims.close()
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
        names |= {p.name for p in self.path.glob(PROBE_PREFIX + "*")}
        for name in sorted(names):
            target = self.path / name
            if target.is_file() or target.is_symlink():
                with contextlib.suppress(FileNotFoundError):
                    target.unlink()
                if name != SUMMARY_FILE and not name.startswith("."):
                    self.replaced.append(name)

    # ------------------------------------------------------------ summary
    def state(self) -> dict[str, Any]:
        """The running summary: header, status, files whole and not, files about to be written."""
        state = {**self.header, "status": RUNNING, "complete": False, "files": dict(self.files),
                 "files_incomplete": dict(self.incomplete)}
        if self.pending:
            state["files_being_written"] = sorted(self.pending)
        return state

    def save(self, summary: Mapping[str, Any] | None = None) -> Path:
        """Write ``summary`` (default: the running state) as ``summary.json`` (atomic)."""
        path = write_summary(self.summary_path, self.state() if summary is None else summary)
        self.save_error = None
        return path

    def _listed(self) -> set[str]:
        return set(self.files.values()) | {e["file"] for e in self.incomplete.values()} | self.pending

    def claim(self, path: str | Path) -> None:
        """Name ``path`` in the running summary before it is written (raises ``OSError`` if that cannot be saved)."""
        name = Path(path).name
        if name == SUMMARY_FILE or name in self._listed():
            return
        self.pending.add(name)
        try:
            self.save()
        except OSError as exc:  # the file is not written: named as the file that could not be written
            self.pending.discard(name)
            raise OSError(exc.errno, exc.strerror or str(exc), str(path)) from None

    def _save_running(self) -> None:
        """Save the running summary; a failure (a full disk) is kept for :meth:`finish` and not raised."""
        try:
            self.save()
        except OSError as exc:
            self.save_error = exc

    def commit(self, role: str, path: Path) -> None:
        """Record a whole file (and update the running summary)."""
        self.files[role] = Path(path).name
        self.incomplete.pop(role, None)
        self.pending.discard(Path(path).name)
        self._save_running()

    def mark_incomplete(self, role: str, path: Path, reason: str, **info: Any) -> None:
        """Record a file that is there but not whole (e.g. cut by a write error)."""
        self.files.pop(role, None)
        self.incomplete[role] = {"file": Path(path).name, "reason": reason, **info}
        self.pending.discard(Path(path).name)
        self._save_running()

    def _remove_unlisted(self) -> None:
        """Remove the files claimed but never listed (their stage failed after writing them)."""
        for name in sorted(self.pending):
            with contextlib.suppress(OSError):
                (self.path / name).unlink()
        self.pending.clear()

    def finish(self, summary: Mapping[str, Any]) -> Path:
        """Write the final ``summary``; on a full disk a short one (:data:`BRIEF_KEYS`), else none.

        Returns
        -------
        pathlib.Path
            ``summary.json``; :attr:`shortened` says why when it is the short one (whose
            ``problems`` say so too, and whose status is ``failed`` rather than ``complete``).

        Raises
        ------
        OSError
            Not even the short summary could be written: the running summary is removed
            too (it would say the run is still going), so the folder holds no summary.
        """
        self._remove_unlisted()
        self.shortened = None
        try:
            return self.save(summary)
        except OSError as exc:
            first = exc
        self.shortened = f"summary.json shortened to the run's status and files ({describe_os_error(first)})"
        brief = {k: summary[k] for k in BRIEF_KEYS if k in summary}
        brief["problems"] = [*brief.get("problems", []), self.shortened]
        if brief.get("status") == COMPLETE:
            brief["status"] = FAILED  # a run is complete when every file it writes is whole
        try:
            return self.save(brief)
        except OSError:
            pass
        with contextlib.suppress(OSError):
            self.summary_path.unlink()  # its blocks make room for the short summary
        try:
            return self.save(brief)
        except OSError:
            with contextlib.suppress(OSError):
                self.summary_path.unlink()
            raise first from None

    def abandon(self, exc: BaseException) -> None:
        """After ``exc`` ended the run unexpectedly: a final summary that says so (never ``running``); never raises."""
        signum = getattr(exc, "signum", None)
        if isinstance(exc, KeyboardInterrupt):
            status, error = STOPPED, str(exc) or reason_of(signum or 2)
        else:
            status, error = FAILED, f"{type(exc).__name__}: {exc}"
        summary = {**self.state(), "status": status, "complete": False, "error": error,
                   "interrupted": isinstance(exc, KeyboardInterrupt), **self.listing()}
        summary.pop("files_being_written", None)
        if isinstance(exc, KeyboardInterrupt):
            summary["signal"] = signal_name(signum or 2)
        with contextlib.suppress(OSError):
            self.finish(summary)

    def listing(self) -> dict[str, Any]:
        """``files`` and ``files_incomplete`` for the final summary."""
        out: dict[str, Any] = {"files": {**self.files, "summary": SUMMARY_FILE}}
        if self.incomplete:
            out["files_incomplete"] = dict(self.incomplete)
        return out

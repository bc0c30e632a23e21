"""File objects that fail like real disks, for tests of the result writers."""

from __future__ import annotations

import errno


class FillingDisk:
    """A file object that takes ``room`` more bytes, then fails like a full disk (after a partial write)."""

    def __init__(self, fh, room: int) -> None:
        self.fh, self.room = fh, room

    def write(self, data) -> int:
        if self.room <= 0:
            raise OSError(errno.ENOSPC, "No space left on device")
        n = self.fh.write(bytes(data[:self.room]))
        self.room -= n
        return n

    def __getattr__(self, name):
        return getattr(self.fh, name)


class FullDisk:
    """``write_summary`` on a disk that is full for some summaries (a stand-in for a completely full disk).

    ``refuse(summary, old_there)`` says which writes fail with ENOSPC (``old_there``: a
    ``summary.json`` is in place, as an atomic write needs room for the new file
    beside the old one); the default refuses every write. ``writes`` counts the
    attempts, ``refused`` the ENOSPC.
    """

    def __init__(self, refuse=lambda summary, old_there: True) -> None:
        self.refuse = refuse
        self.writes = self.refused = 0

    def __call__(self, path, summary):
        from pathlib import Path

        from orchestrator.result_files import write_summary

        self.writes += 1
        path = Path(path)
        if self.refuse(summary, path.exists()):
            self.refused += 1
            raise OSError(errno.ENOSPC, "No space left on device", str(path))
        return write_summary(path, summary)


class FullAt:
    """``os.replace`` on a disk that is full when the file named ``name`` is put in place (ENOSPC, no file name).

    Every file dtcosim writes is renamed into place (:mod:`orchestrator.atomic_files`), so this is a full
    disk at that file, after the files before it: ``monkeypatch.setattr(os, "replace", FullAt("x.png"))``.
    """

    def __init__(self, name: str) -> None:
        import os

        self.name, self.replace = name, os.replace

    def __call__(self, src, dst) -> None:
        from pathlib import Path

        if Path(dst).name == self.name:
            raise OSError(errno.ENOSPC, "No space left on device")
        self.replace(src, dst)

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

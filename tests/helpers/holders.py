"""Another process holding an unpacked FMU's folder, as a run that loads it does (orchestrator.cosim.unpacked_fmus)."""

from __future__ import annotations

import contextlib
import subprocess
import sys
from pathlib import Path
from typing import Iterator

from orchestrator.cosim.unpacked_fmus import MANIFEST

_HOLD = ("import fcntl, os, sys; fd = os.open(sys.argv[1], os.O_RDONLY); fcntl.flock(fd, fcntl.LOCK_SH); "
         "print('held', flush=True); sys.stdin.read()")


@contextlib.contextmanager
def held_elsewhere(folder: Path) -> Iterator[None]:
    """A process holding ``folder`` (a shared lock on its manifest) until the block ends."""
    proc = subprocess.Popen([sys.executable, "-c", _HOLD, str(folder / MANIFEST)], stdin=subprocess.PIPE,
                            stdout=subprocess.PIPE, text=True)
    try:
        assert proc.stdout.readline().strip() == "held"
        yield
    finally:
        proc.stdin.close()
        proc.wait(10)

"""Files that appear whole or not at all: write to a temporary file beside the target, then rename.

Every result file dtcosim writes goes through :func:`atomic_path` (or the two
helpers on top of it): the data goes to ``.<name>.<random>.tmp<suffix>`` in the
target's folder, is flushed to disk, and only then replaces ``<name>`` with
``os.replace`` (atomic on POSIX file systems). A reader, a crash, a full disk or
a second Ctrl-C therefore never leaves half a file under the final name: either
the previous file or the new one is there. The temporary file keeps the
target's suffix, so tools that choose the format by extension (matplotlib's
``savefig``) write the right one.

A folder whose owner must know of a file before it appears (a run's folder, whose
``summary.json`` lists what the run is writing so that the next run can clear it
also after a SIGKILL) registers a claim callback with :func:`claims_for`:
:func:`atomic_path` calls it with the target before anything is written, and an
error the callback raises (a full disk) means the file is not written.
"""

from __future__ import annotations

import contextlib
import os
import tempfile
from pathlib import Path
from typing import Callable, Iterator

#: permissions of a new file under the process's umask (mkstemp alone would give 0600)
_UMASK = os.umask(0)
os.umask(_UMASK)
FILE_MODE = 0o666 & ~_UMASK


def describe_os_error(exc: OSError) -> str:
    """``"cannot write results/x.csv: No space left on device"``: the file and the system's reason."""
    reason = exc.strerror or str(exc) or type(exc).__name__
    where = exc.filename if exc.filename is not None else None
    return f"cannot write {where}: {reason}" if where else f"cannot write: {reason}"


def fsync_directory(folder: Path) -> None:
    """Make a rename in ``folder`` durable (best effort: not every file system supports it)."""
    with contextlib.suppress(OSError):
        fd = os.open(folder, os.O_RDONLY)
        try:
            os.fsync(fd)
        finally:
            os.close(fd)


#: claim callbacks by the real path of their folder (:func:`claims_for`)
_CLAIMS: dict[str, Callable[[Path], None]] = {}


@contextlib.contextmanager
def claims_for(folder: str | Path, claim: Callable[[Path], None]) -> Iterator[None]:
    """Call ``claim(target)`` before :func:`atomic_path` writes any file into ``folder``, for the ``with`` block."""
    key = os.path.realpath(folder)
    previous = _CLAIMS.get(key)
    _CLAIMS[key] = claim
    try:
        yield
    finally:
        if previous is None:
            _CLAIMS.pop(key, None)
        else:
            _CLAIMS[key] = previous


def _named(exc: OSError, path: Path) -> OSError:
    """``exc`` naming ``path`` (the target, not the temporary file) when it names no file or the temporary one."""
    if exc.errno is not None and (exc.filename is None or Path(exc.filename).name.startswith(f".{path.name}.")):
        return OSError(exc.errno, exc.strerror or str(exc), str(path))
    return exc


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """A temporary path to write ``path``'s content to; renamed to ``path`` when the block succeeds.

    On an exception the temporary file is removed and the exception propagates
    (an existing ``path`` is left as it was); an ``OSError`` names ``path``.

    Examples
    --------
    >>> with atomic_path(out / "plot.png") as tmp:   # doctest: +SKIP
    ...     fig.savefig(tmp)
    """
    path = Path(path)
    claim = _CLAIMS.get(os.path.realpath(path.parent)) if _CLAIMS else None
    try:
        if claim is not None:
            claim(path)
        fd, name = tempfile.mkstemp(prefix=f".{path.name}.", suffix=f".tmp{path.suffix}", dir=path.parent)
    except OSError as exc:
        raise _named(exc, path) from None
    os.close(fd)
    tmp = Path(name)
    try:
        yield tmp
        with open(tmp, "rb+") as fh:
            os.fsync(fh.fileno())
        os.chmod(tmp, FILE_MODE)
        os.replace(tmp, path)
    except BaseException as exc:
        with contextlib.suppress(OSError):
            tmp.unlink()
        if isinstance(exc, OSError):
            raise _named(exc, path) from None
        raise
    fsync_directory(path.parent)


def write_bytes_atomic(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file; returns ``path``."""
    path = Path(path)
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return path


def write_text_atomic(path: str | Path, text: str) -> Path:
    """Write UTF-8 ``text`` to ``path`` through a temporary file; returns ``path``."""
    return write_bytes_atomic(path, text.encode("utf-8"))

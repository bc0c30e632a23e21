"""The user's input files: reading TOML, the packaged files, finding a file by path or name.

Scenarios (:mod:`orchestrator.inputs.scenario`) and studies (:mod:`orchestrator.inputs.study`)
are both TOML files that may also be named by the stem of a file shipped in a
folder of this package; every failure is the caller's :class:`EntryError`
subclass, raised before anything runs.
"""

from __future__ import annotations

import errno
import os
import stat
import sys
import tomllib
from importlib import resources
from pathlib import Path
from typing import Any

from ..errors import EntryError

#: the package whose data folders (``scenarios/``, ``studies/``) hold the packaged input files
DATA_PACKAGE = "orchestrator"


#: the largest input file read [bytes]: the packaged ones are below 20 kB
MAX_INPUT_BYTES = 16 * 2**20


def read_toml(path: str | Path, error: type[EntryError]) -> dict[str, Any]:
    """The parsed TOML file at ``path``.

    Only a regular file of at most :data:`MAX_INPUT_BYTES` is read (a FIFO or ``/dev/zero`` would
    block or never end); nesting too deep for the parser and integers of more digits than Python
    converts are refused as invalid TOML.

    Raises
    ------
    EntryError
        ``error`` with key ``(file)`` if the file cannot be read, is no regular file, is too large
        or is not UTF-8 text, ``(syntax)`` if it is not valid TOML.
    """
    path = Path(path)
    try:
        info = os.stat(path)
    except OSError as exc:
        raise error("(file)", str(path), f"a readable {error.kind} file ({exc.strerror})") from None
    if not stat.S_ISREG(info.st_mode):
        raise error("(file)", str(path), f"a regular {error.kind} file (this is a device, pipe or folder)") from None
    if info.st_size > MAX_INPUT_BYTES:
        raise error("(file)", str(path), f"a {error.kind} file of at most {MAX_INPUT_BYTES // 2**20} MiB "
                    f"({info.st_size} bytes)") from None
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as exc:
        raise error("(file)", str(path), f"a readable {error.kind} file ({exc.strerror})") from None
    except UnicodeDecodeError as exc:
        line = exc.object[:exc.start].count(b"\n") + 1
        raise error("(file)", str(path), f"a UTF-8 text file (byte 0x{exc.object[exc.start]:02x} on line {line} "
                    "is not UTF-8)") from None
    try:
        return tomllib.loads(text)
    except tomllib.TOMLDecodeError as exc:
        raise error("(syntax)", str(path), f"valid TOML ({exc})") from None
    except RecursionError:
        raise error("(syntax)", str(path), "valid TOML nested less deeply (arrays or inline tables nested "
                    "beyond what the parser follows)") from None
    except ValueError:  # an integer beyond Python's int-from-string limit
        raise error("(syntax)", str(path), f"valid TOML with integers of at most {sys.get_int_max_str_digits()} "
                    "digits") from None


def read_regular_bytes(path: str | Path, max_bytes: int = MAX_INPUT_BYTES) -> bytes:
    """The content of the regular file ``path`` of at most ``max_bytes`` bytes.

    Raises
    ------
    OSError
        The file cannot be read, is a device, pipe or folder (``EINVAL``: reading it would block
        or never end), or is larger (``EFBIG``); the message names the file.
    """
    info = os.stat(path)
    if not stat.S_ISREG(info.st_mode):
        raise OSError(errno.EINVAL, "not a regular file (a device, pipe or folder)", str(path))
    if info.st_size > max_bytes:
        raise OSError(errno.EFBIG, f"larger than {max_bytes} bytes ({info.st_size} bytes)", str(path))
    return Path(path).read_bytes()


def packaged_files(folder: str) -> dict[str, Path]:
    """The TOML files shipped in the data folder ``<folder>`` of :data:`DATA_PACKAGE`, by stem (e.g. ``"paper-60s"``)."""
    root = Path(str(resources.files(DATA_PACKAGE) / folder))
    return {p.stem: p for p in sorted(root.glob("*.toml"))}


def find_input_file(
    spec: str | Path,
    folder: str,
    error: type[EntryError],
    suffixes: tuple[str, ...] = (".toml",),
    directories: bool = False,
    described: str | None = None,
    plural: str | None = None,
) -> Path:
    """A file from a path, or the packaged file of that name.

    Parameters
    ----------
    spec : str or pathlib.Path
        A path (recognised by one of ``suffixes`` or by existing) or a packaged name.
    folder : str
        Folder of the packaged files (see :func:`packaged_files`).
    error : type of EntryError
        Raised, with key ``(file)`` or ``(<kind>)``, when nothing is found.
    suffixes : tuple of str
        Suffixes that mark ``spec`` as a path even if it does not exist.
    directories : bool
        Whether an existing directory is an acceptable path (an unpacked SSP).
    described, plural : str, optional
        Wording of the message: ``"a scenario file"``, ``"scenarios"`` (default from ``error.kind``).
    """
    kind = error.kind
    p = Path(spec)
    if p.suffix in suffixes or p.exists():
        if not p.exists():
            raise error("(file)", str(p), f"an existing {kind} file")
        if not (directories or p.is_file()):
            raise error("(file)", str(p), f"a regular {kind} file (this is a device, pipe or folder)")
        return p
    shipped = packaged_files(folder)
    if str(spec) in shipped:
        return shipped[str(spec)]
    described = described or f"a {kind} file"
    plural = plural or f"{kind}s"
    raise error(f"({kind})", str(spec), f"{described} or one of the packaged {plural}: " + ", ".join(shipped))

"""Records of recorded time series: OpenFAST/FAST outputs and CSV files, read and converted to SI.

Formats (by suffix):

``.outb``
    OpenFAST binary output, read with ``openfast-io`` (``FAST_output_reader.load_binary_output``),
    after a check of its header (a file of another kind is refused, not decoded into garbage).
``.out``
    OpenFAST/FAST text output (header lines, a ``Time`` channel-name row, a units row ``(rpm)``),
    read with ``openfast-io`` (``load_ascii_output``). Old FAST v6 files are not UTF-8 (the unit
    ``kN·m`` is one Latin-1 byte, ``0xb7``) and openfast-io opens text in the locale's encoding:
    such a file is first transcoded (Latin-1 -> ASCII, ``·`` -> ``-``) into a temporary copy.
``.csv``
    A header row of ``name [unit]`` cells, then numbers; the first column is the time [s].

Every reading problem is a :class:`LoadRecordError` naming the file, the channel and what was expected:
an empty file, a binary file of the wrong kind, a missing channel (with "did you mean"), a unit
with no known conversion, NaN, time that does not increase strictly.
"""

from __future__ import annotations

import csv
import math
import re
import stat
import struct
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import Mapping

import numpy as np

from ..errors import EntryError, suggestion
from .limits import MAX_RECORD_BYTES

RECORD_SUFFIXES = (".outb", ".out", ".csv")


class LoadRecordError(EntryError):
    """A record file (OpenFAST output, CSV) or a channel selected from it is unusable."""

    kind = "record"


#: unit as recorded (normalised: lower case, no spaces, '·'/'*'/'.' -> '-') -> (SI unit, factor)
UNIT_CONVERSIONS: dict[str, tuple[str, float]] = {
    "s": ("s", 1.0), "sec": ("s", 1.0),
    "rpm": ("rad/s", math.pi / 30.0), "rad/s": ("rad/s", 1.0), "deg/s": ("rad/s", math.pi / 180.0),
    "deg": ("rad", math.pi / 180.0), "rad": ("rad", 1.0),
    "n-m": ("N.m", 1.0), "nm": ("N.m", 1.0), "kn-m": ("N.m", 1.0e3), "knm": ("N.m", 1.0e3),
    "mn-m": ("N.m", 1.0e6),
    "n": ("N", 1.0), "kn": ("N", 1.0e3),
    "w": ("W", 1.0), "kw": ("W", 1.0e3), "mw": ("W", 1.0e6),
    "m/s": ("m/s", 1.0), "m/sec": ("m/s", 1.0), "m": ("m", 1.0),
    "-": ("1", 1.0), "": ("1", 1.0),
}


def normalised_unit(unit: str) -> str:
    """``"kN·m"``, ``"kN-m"``, ``"kN*m"``, ``"kN m"`` -> ``"kn-m"``; brackets/parentheses removed."""
    u = unit.strip().strip("()[]").strip()
    u = u.replace("\u00b7", "-").replace("*", "-").replace(" ", "-")
    u = re.sub(r"(?<=[a-zA-Z])\.(?=[a-zA-Z])", "-", u)
    return u.lower()


def si_conversion(unit: str, channel: str, source: str) -> tuple[str, float]:
    """(SI unit, factor) of a recorded unit; a :class:`LoadRecordError` naming the channel if unknown."""
    key = normalised_unit(unit)
    if key not in UNIT_CONVERSIONS:
        known = sorted({u for u in UNIT_CONVERSIONS if u})
        raise LoadRecordError(f"{channel}.unit", unit, "a unit with a known conversion to SI: " + ", ".join(known)
                          + suggestion(key, known), source)
    return UNIT_CONVERSIONS[key]


@dataclass(frozen=True)
class Record:
    """The channels of one record file, as recorded (not converted).

    Attributes
    ----------
    source : str
        The file.
    time_s : ndarray, shape (n,)
    channels : mapping of str -> (unit, ndarray)
        By channel name, without the time channel.
    """

    source: str
    time_s: np.ndarray
    channels: Mapping[str, tuple[str, np.ndarray]]

    def channel(self, name: str) -> tuple[str, np.ndarray]:
        """Unit and samples of channel ``name``; a missing one is a LoadRecordError with "did you mean"."""
        if name not in self.channels:
            raise LoadRecordError("channel", name, f"a channel of the record ({len(self.channels)} channels)"
                              + suggestion(name, self.channels), self.source)
        return self.channels[name]


def _check_not_empty(path: Path) -> bytes:
    try:
        info = path.stat()
        if not stat.S_ISREG(info.st_mode):  # a pipe or /dev/zero would block or never end
            raise LoadRecordError("(file)", str(path), "a regular record file (this is a device, pipe or folder)")
        size = info.st_size
        if size > MAX_RECORD_BYTES:  # refused before it is read
            raise LoadRecordError("(file)", str(path), f"a record of at most {MAX_RECORD_BYTES:,} bytes "
                              f"({MAX_RECORD_BYTES / 2**20:.3g} MiB); the file has {size:,} bytes")
        data = path.read_bytes()
    except OSError as exc:
        raise LoadRecordError("(file)", str(path), f"a readable record file ({exc.strerror or exc})") from None
    if not data.strip():
        raise LoadRecordError("(file)", str(path), "a record with channels and samples (the file is empty)")
    return data


def _check_outb_header(data: bytes, source: str) -> None:
    """Refuse a file that is not an OpenFAST binary output before openfast-io decodes it."""
    if len(data) < 14:
        raise LoadRecordError("(file)", source, f"an OpenFAST binary output (.outb); the file has only {len(data)} bytes")
    file_id = struct.unpack("<h", data[:2])[0]
    if file_id not in (1, 2, 3, 4):
        raise LoadRecordError("(file)", source, f"an OpenFAST binary output (.outb) starting with a format id 1-4; "
                          f"it starts with bytes {data[:8]!r}, not a FAST binary file")
    at = 2 + (2 if file_id == 4 else 0)
    n_chan, n_t = struct.unpack("<ii", data[at:at + 8])
    name_len = struct.unpack("<h", data[2:4])[0] if file_id == 4 else 10
    if not (0 < n_chan < 100000 and 0 < n_t < 10 ** 9 and 0 < name_len < 1000):
        raise LoadRecordError("(file)", source, f"an OpenFAST binary output (.outb); its header says {n_chan} channels, "
                          f"{n_t} time steps, not a FAST binary file")
    value_size = 8 if file_id == 3 else 2
    least = n_chan * n_t * value_size + (n_t * 4 if file_id == 1 else 0)
    if len(data) < least:
        raise LoadRecordError("(file)", source, f"an OpenFAST binary output with {n_chan} channels x {n_t} steps "
                          f"(>= {least} bytes); the file has {len(data)} bytes (truncated or another kind)")


def _read_outb(path: Path, data: bytes) -> tuple[list[str], list[str], np.ndarray]:
    from openfast_io.FAST_output_reader import load_binary_output

    _check_outb_header(data, str(path))
    try:
        values, info, _ = load_binary_output(str(path))
    except (struct.error, ValueError, Exception) as exc:  # noqa: BLE001 - a broken file of the right id
        raise LoadRecordError("(file)", str(path), f"a readable OpenFAST binary output ({type(exc).__name__}: {exc})") from None
    return list(info["attribute_names"]), list(info["attribute_units"]), np.asarray(values, dtype=float)


def _read_out(path: Path, data: bytes) -> tuple[list[str], list[str], np.ndarray]:
    from openfast_io.FAST_output_reader import load_ascii_output

    if b"\0" in data[:4096]:
        raise LoadRecordError("(file)", str(path), "an OpenFAST text output (.out); the file is binary "
                          "(an .outb renamed?)")
    text = data.decode("latin-1").replace("\u00b7", "-")
    lines = text.splitlines()
    header = next((i for i, line in enumerate(lines) if line.split() and line.split()[0] == "Time"), None)
    if header is None or header + 1 >= len(lines):
        raise LoadRecordError("(file)", str(path), "an OpenFAST text output with a row of channel names starting with "
                          "Time and a units row")
    while lines and not lines[-1].strip():  # openfast-io turns every line below the header into a row
        lines.pop()
    ascii_text = "\n".join(lines).encode("ascii", "replace").decode("ascii") + "\n"
    with tempfile.TemporaryDirectory(prefix="dtcosim_record_") as tmp:
        copy = Path(tmp) / path.name
        copy.write_text(ascii_text, encoding="ascii")
        try:
            values, info = load_ascii_output(str(copy), headerLines=header + 2, descriptionLine=max(header - 2, 0),
                                             attributeLine=header, unitLine=header + 1)
        except ValueError as exc:
            raise LoadRecordError("(file)", str(path), f"numbers below the header ({exc})") from None
    return list(info["attribute_names"]), list(info["attribute_units"]), np.asarray(values, dtype=float)


_CSV_HEADER = re.compile(r"^\s*(?P<name>[^\[\]]+?)\s*\[(?P<unit>[^\]]*)\]\s*$")


def _read_csv(path: Path, data: bytes) -> tuple[list[str], list[str], np.ndarray]:
    if b"\0" in data[:4096]:
        raise LoadRecordError("(file)", str(path), "a CSV text file; the file is binary")
    text = data.decode("utf-8-sig", errors="replace")
    rows = list(csv.reader(text.splitlines()))
    rows = [r for r in rows if any(c.strip() for c in r)]
    if len(rows) < 2:
        raise LoadRecordError("(file)", str(path), "a header row of 'name [unit]' and at least one row of numbers")
    names, units = [], []
    for i, cell in enumerate(rows[0]):
        m = _CSV_HEADER.match(cell)
        if not m:
            raise LoadRecordError(f"header[{i}]", cell, "a column header 'name [unit]', e.g. 'RotSpeed [rpm]'", str(path))
        names.append(m.group("name"))
        units.append(m.group("unit"))
    try:
        values = np.array([[float(c) for c in r] for r in rows[1:]], dtype=float)
    except ValueError as exc:
        raise LoadRecordError("(rows)", str(exc), f"{len(names)} numbers per row", str(path)) from None
    if values.ndim != 2 or values.shape[1] != len(names):
        raise LoadRecordError("(rows)", str(path), f"{len(names)} numbers per row, as many as header cells")
    return names, units, values


def read_load_record(path: str | Path) -> Record:
    """The channels of a record file (``.outb``, ``.out``, ``.csv``; see the module docstring).

    Raises
    ------
    LoadRecordError
        Naming the file and what is wrong with it (empty, the wrong kind of file, no time channel,
        NaN in the time channel, time not strictly increasing).
    """
    path = Path(path)
    source = str(path)
    if path.suffix.lower() not in RECORD_SUFFIXES:
        raise LoadRecordError("(file)", source, "a record file ending in " + ", ".join(RECORD_SUFFIXES))
    data = _check_not_empty(path)
    reader = {".outb": _read_outb, ".out": _read_out, ".csv": _read_csv}[path.suffix.lower()]
    names, units, values = reader(path, data)
    if values.ndim != 2 or values.shape[0] < 2 or values.shape[1] != len(names) or len(units) != len(names):
        raise LoadRecordError("(file)", source, "two or more rows of samples with one value per channel")
    names = [n.strip() for n in names]
    if names[0].lower() != "time":
        raise LoadRecordError("channel[0]", names[0], "the time channel Time first", source)
    t_unit, t_factor = si_conversion(units[0], names[0], source)
    if t_unit != "s":
        raise LoadRecordError(f"{names[0]}.unit", units[0], "a time unit (s)", source)
    time_s = values[:, 0] * t_factor
    bad = np.flatnonzero(~np.isfinite(time_s))
    if bad.size:
        raise LoadRecordError("Time", f"NaN at row {int(bad[0])}", "finite times", source)
    steps = np.diff(time_s)
    if not np.all(steps > 0.0):
        i = int(np.flatnonzero(~(steps > 0.0))[0])
        raise LoadRecordError("Time", f"{time_s[i]:g} s then {time_s[i + 1]:g} s at rows {i}, {i + 1}",
                          "strictly increasing (monotonic) time", source)
    channels = {n: (u, values[:, j]) for j, (n, u) in enumerate(zip(names, units)) if j > 0}
    return Record(source, time_s, channels)

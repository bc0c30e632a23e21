"""Result writers: one interface for every format a run streams its samples into.

A run hands its samples to a writer block by block while it steps
(:class:`orchestrator.cosim.master.CoSimulation` calls :meth:`ResultWriter.append`
with each finished block of rows), so memory for the file stays bounded and a
run that is killed leaves a readable file up to its last complete chunk.

The life cycle is the same for every format:

``open(columns)``
    Create ``<file>.partial`` beside the final path and write the header
    (column names, units, per-column formats).
``append(time_s, values[, text])``
    Add a chunk of rows (``time_s`` shape (n,), ``values`` shape (n, m); ``text``
    column index -> n strings for String columns, whose ``values`` are NaN). A chunk
    is written whole or, on a write error, cut back to the previous chunk; the
    error (an ``OSError`` naming the file) propagates.
``close()``
    Flush to disk and rename ``<file>.partial`` to the final name: the file under
    the final name is always whole. Returns the final path.
``abandon()``
    Stop without renaming (after a write error): what was written stays in
    ``<file>.partial``, readable up to its last complete chunk.

:class:`CsvWriter` is the text format; :class:`~orchestrator.run.parquet_writer.ParquetWriter`
the binary columnar one. Both stream into their ``.partial`` file through
:class:`StreamedFile` (all-or-nothing chunks, fsync and rename on close) and
implement the same four methods (:class:`ResultWriter`).
"""

from __future__ import annotations

import contextlib
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Protocol, Sequence

import numpy as np

from ..atomic_files import fsync_directory
from ..columnar_files import header_field

#: suffix of a results file while it is being written
PARTIAL_SUFFIX = ".partial"
#: full double precision: every float64 reads back exactly
REAL_FORMAT = "%.17g"
#: value format of each FMI 2.0 type (a Boolean is 0.0/1.0, an Integer an exact float, in the row arrays)
TYPE_FORMATS = {"Real": REAL_FORMAT, "Integer": "%d", "Enumeration": "%d", "Boolean": "%d", "String": "%s"}


@dataclass(frozen=True)
class Column:
    """One column of a results file.

    Attributes
    ----------
    name : str
        ``component.variable`` (or ``time``).
    unit : str
        Unit as the FMU declares it ("" for none).
    fmi_type : str
        FMI 2.0 type (``Real``, ``Integer``, ``Enumeration``, ``Boolean``, ``String``):
        Reals with 17 significant digits, Integers, Enumerations and Booleans (0/1) as
        integers, Strings quoted with doubled inner quotes (:data:`TYPE_FORMATS`).
    """

    name: str
    unit: str = ""
    fmi_type: str = "Real"

    @property
    def format(self) -> str:
        """printf-style format of a value."""
        return TYPE_FORMATS[self.fmi_type]

    @property
    def header(self) -> str:
        """``component.variable [unit]`` (``[-]`` without a unit, ``[Boolean 0/1]``, ``[String]`` for those types)."""
        return header_field(self.name, self.unit, self.fmi_type)


class ResultWriter(Protocol):
    """What a results format implements (see the module docstring)."""

    #: the format's name (``csv``, ``parquet``: :data:`orchestrator.inputs.results_format.RESULTS_FORMATS`)
    format: str
    path: Path
    rows_written: int

    @property
    def partial_path(self) -> Path:
        """Where the file is while it is written."""

    def open(self, columns: Sequence[Column]) -> None:
        """Create the partial file with the header (``columns`` after the time column)."""

    def append(self, time_s: np.ndarray, values: np.ndarray, text: dict[int, np.ndarray] | None = None) -> None:
        """Add a chunk of rows; on a write error cut back to the previous chunk and raise ``OSError``."""

    def close(self) -> Path:
        """Make the file whole under its final name and return that path."""

    def abandon(self) -> None:
        """Stop writing; the partial file keeps every complete chunk."""


def csv_field(text: str) -> str:
    """A CSV header field, quoted if it holds a comma, a quote or a line break (RFC 4180)."""
    return '"' + text.replace('"', '""') + '"' if any(c in text for c in ',"\r\n') else text


class StreamedFile:
    """A results file written chunk by chunk into ``<path>.partial`` and renamed to ``path`` when whole.

    The part every format shares: :meth:`_write` writes a chunk whole or cuts the
    file back to the previous chunk and raises; :meth:`close` forces the file to
    the disk and renames it; :meth:`abandon` leaves the partial file as it is.

    Parameters
    ----------
    path : path
        Final file name; written as ``<path>.partial`` until :meth:`close`.
    fsync_every_chunk : bool
        Also force every chunk to the disk (survives a power cut, costs a disk
        flush per chunk). Without it a chunk survives the process being killed
        (it is in the kernel's page cache once :meth:`append` returns).
    """

    time_column = Column("time", "s")

    def __init__(self, path: str | Path, fsync_every_chunk: bool = False) -> None:
        self.path = Path(path)
        self.fsync_every_chunk = fsync_every_chunk
        self.rows_written = 0
        self._fh = None
        self._size = 0

    @property
    def partial_path(self) -> Path:
        return self.path.with_name(self.path.name + PARTIAL_SUFFIX)

    def _create(self) -> None:
        self._fh = open(self.partial_path, "wb", buffering=0)
        self._size = 0

    def _write(self, data: bytes) -> None:
        """Write all of ``data`` or cut the file back to where it was and raise."""
        view = memoryview(data)
        try:
            while view:
                n = self._fh.write(view)
                view = view[n:]
            if self.fsync_every_chunk:
                os.fsync(self._fh.fileno())
        except OSError as exc:
            with contextlib.suppress(OSError):
                os.ftruncate(self._fh.fileno(), self._size)
            if exc.filename is None:
                exc.filename = str(self.partial_path)
            raise
        self._size += len(data)

    def _close_partial(self) -> None:
        """Force the partial file to the disk and close it."""
        fh, self._fh = self._fh, None
        try:
            os.fsync(fh.fileno())
        finally:
            fh.close()

    def close(self) -> Path:
        self._close_partial()
        os.replace(self.partial_path, self.path)
        fsync_directory(self.path.parent)
        return self.path

    def abandon(self) -> None:
        fh, self._fh = self._fh, None
        if fh is not None:
            with contextlib.suppress(OSError):
                fh.close()


class CsvWriter(StreamedFile):
    """``timeseries.csv``: ``time [s]`` then one column per recorded variable, one line per sample.

    Parameters
    ----------
    path : path
        Final file name; written as ``<path>.partial`` until :meth:`close`.
    fsync_every_chunk : bool
        See :class:`StreamedFile`.
    """

    format = "csv"

    def __init__(self, path: str | Path, fsync_every_chunk: bool = False) -> None:
        super().__init__(path, fsync_every_chunk)
        self._row_format = ""

    def open(self, columns: Sequence[Column]) -> None:
        columns = [self.time_column, *columns]
        self._row_format = ",".join(c.format for c in columns) + "\n"
        self._n_values = len(columns) - 1
        self._string_columns = [j for j, c in enumerate(columns[1:]) if c.fmi_type == "String"]
        header = (",".join(csv_field(c.header) for c in columns) + "\n").encode("utf-8")
        self._create()
        self._write(header)

    def append(self, time_s: np.ndarray, values: np.ndarray, text: dict[int, np.ndarray] | None = None) -> None:
        n = len(time_s)
        if n == 0:
            return
        if self._string_columns:
            self._write(self._typed_rows(time_s, values, text or {}).encode("utf-8"))
            self.rows_written += n
            return
        table = np.empty((n, self._n_values + 1))
        table[:, 0] = time_s
        table[:, 1:] = values
        text = (self._row_format * n) % tuple(table.ravel().tolist())
        self._write(text.encode("ascii"))
        self.rows_written += n

    def _typed_rows(self, time_s: np.ndarray, values: np.ndarray, text: dict[int, np.ndarray]) -> str:
        """Rows with String columns (one Python object per field: only FMUs with String outputs pay it)."""
        missing = [j for j in self._string_columns if j not in text]
        if missing:
            raise ValueError(f"{self.path}: no strings given for String column(s) {missing}")
        out = []
        for i, t in enumerate(time_s):
            fields = [t, *values[i].tolist()]
            for j in self._string_columns:
                fields[j + 1] = '"' + str(text[j][i]).replace('"', '""') + '"'
            out.append(self._row_format % tuple(fields))
        return "".join(out)

"""``timeseries.parquet``: the binary columnar results format, streamed like ``timeseries.csv``.

While the run steps, every chunk of rows is appended to ``timeseries.parquet.partial``
as one Arrow IPC record batch (encoded by :mod:`orchestrator.arrow_stream`, without
pyarrow; the format: :mod:`orchestrator.columnar_files`): a stream without a
footer, readable up to its last whole batch after the process was killed, and cut
back to the previous batch on a write error, like the CSV.
:meth:`ParquetWriter.close` converts the stream to ``timeseries.parquet``
(written to a temporary file and renamed; in a child process unless pyarrow is
imported here: :func:`orchestrator.parquet_conversion.convert_stream`) and removes
the stream. If the conversion fails (a full disk), the stream stays as the partial
file and ``OSError`` propagates.
"""

from __future__ import annotations

import contextlib
from pathlib import Path
from typing import Sequence

import numpy as np

from ..atomic_files import atomic_path, fsync_directory
from ..arrow_stream import record_batch_message, schema_message
from ..columnar_files import ARROW_END_OF_STREAM
from ..parquet_conversion import convert_stream
from .writers import Column, StreamedFile


class ParquetWriter(StreamedFile):
    """Stream rows into an Arrow IPC ``<path>.partial``; :meth:`close` makes ``path`` a Parquet file.

    Parameters
    ----------
    path : path
        Final file name (``timeseries.parquet``).
    fsync_every_chunk : bool
        See :class:`~orchestrator.run.writers.StreamedFile`.
    """

    format = "parquet"

    def __init__(self, path: str | Path, fsync_every_chunk: bool = False) -> None:
        super().__init__(path, fsync_every_chunk)
        self._columns: list[Column] = []
        #: where :meth:`close` converted the stream ("child" or "here"; "" before)
        self.converted_in = ""

    def open(self, columns: Sequence[Column]) -> None:
        self._columns = [self.time_column, *columns]
        self._create()
        self._write(schema_message(self._columns))

    def append(self, time_s: np.ndarray, values: np.ndarray, text: dict[int, np.ndarray] | None = None) -> None:
        n = len(time_s)
        if n == 0:
            return
        self._write(record_batch_message(self._columns, np.asarray(time_s, dtype=float), np.asarray(values), text))
        self.rows_written += n

    def close(self) -> Path:
        self._write(ARROW_END_OF_STREAM)
        self._close_partial()
        with atomic_path(self.path) as tmp:
            self.converted_in = convert_stream(self.partial_path, tmp)
        with contextlib.suppress(FileNotFoundError):
            self.partial_path.unlink()
        fsync_directory(self.path.parent)
        return self.path

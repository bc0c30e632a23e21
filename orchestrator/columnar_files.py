"""Binary columnar results: the Parquet file of a run and the Arrow IPC stream it is streamed into.

A run streams its samples into ``timeseries.parquet.partial``, an `Arrow IPC
stream <https://arrow.apache.org/docs/format/Columnar.html#ipc-streaming-format>`_:
the schema, then one record batch per chunk of rows, each appended whole. The
format has no footer, so a stream cut anywhere (a killed process) is readable up
to its last whole batch (:func:`read_columnar`). When the run ends the stream is
converted to ``timeseries.parquet`` (:func:`stream_to_parquet`), which pandas
(``pandas.read_parquet``), MATLAB (``parquetread``), R (``arrow::read_parquet``)
and every Parquet reader read.

Columns and metadata
--------------------
``time`` (float64, unit ``s``), then one column per recorded variable named
``component.variable``: FMI Real as float64, Integer and Enumeration as int32,
Boolean as bool, String as UTF-8 string. Each field carries ``unit`` and
``fmi_type`` in its field metadata; the schema metadata carries the same as JSON
under ``dtcosim`` (``{"columns": [{"name", "unit", "fmi_type"}, ...]}``) and under
``PANDAS_ATTRS`` (``{"units": {name: unit}, "fmi_types": {name: type}}``), which
pandas restores as ``DataFrame.attrs``.

The Parquet file is written with Snappy compression and PLAIN encoding (no
dictionary), the combination every Parquet reader supports (it is MATLAB's
``parquetwrite`` default codec); :data:`PARQUET_OPTIONS`.

The stream is encoded without pyarrow (:mod:`orchestrator.arrow_stream`); only
this module imports ``pyarrow``, to read a columnar file and to convert the stream,
which a run does in a child process (:mod:`orchestrator.parquet_conversion`), so
pyarrow's ~45 MB of resident memory never adds to the run's.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np

#: first bytes of a Parquet file
PARQUET_MAGIC = b"PAR1"
#: first bytes of an Arrow IPC stream message (the continuation marker)
ARROW_STREAM_MAGIC = b"\xff\xff\xff\xff"
#: the end-of-stream marker of an Arrow IPC stream
ARROW_END_OF_STREAM = b"\xff\xff\xff\xff\x00\x00\x00\x00"
#: rows per Parquet row group: the conversion holds one (1.5 MB for 23 float64 columns; 65536 rows cost 25 MB more peak RSS)
ROW_GROUP_ROWS = 8192
#: options of the Parquet writer: Snappy and PLAIN encoding, which every Parquet reader supports
PARQUET_OPTIONS = {"compression": "snappy", "use_dictionary": False}
#: header tag of the non-Real columns that have no unit (as in ``timeseries.csv``)
TYPE_TAGS = {"Boolean": "Boolean 0/1", "String": "String"}


def header_field(name: str, unit: str, fmi_type: str = "Real") -> str:
    """``name [unit]`` as in a CSV header (``[-]`` without a unit, ``[Boolean 0/1]``, ``[String]``)."""
    return f"{name} [{TYPE_TAGS.get(fmi_type) or unit or '-'}]"


@dataclass
class ColumnarTable:
    """The content of a columnar results file.

    Attributes
    ----------
    names, units, fmi_types : list of str
        Per column, ``time`` first.
    data : ndarray, shape (n, m)
        Every column as float (Boolean 0.0/1.0, Integer exact, String NaN).
    text : dict of int -> ndarray of object
        Column index -> the strings of a String column.
    whole : bool
        False for a stream without its end-of-stream marker or cut inside a batch
        (the rows are those of the whole batches).
    """

    names: list[str]
    units: list[str]
    fmi_types: list[str]
    data: np.ndarray
    text: dict[int, np.ndarray] = field(default_factory=dict)
    whole: bool = True

    @property
    def header(self) -> list[str]:
        """The CSV header fields of the columns (``time [s]``, ``component.variable [unit]``, ...)."""
        return [header_field(n, u, t) for n, u, t in zip(self.names, self.units, self.fmi_types)]


def is_columnar(path: str | Path) -> bool:
    """True if ``path`` starts like a Parquet file or an Arrow IPC stream."""
    with open(path, "rb") as fh:
        head = fh.read(4)
    return head in (PARQUET_MAGIC, ARROW_STREAM_MAGIC)


def _table_of(schema, batches, whole: bool) -> ColumnarTable:
    meta = {k.decode(): v.decode() for k, v in (schema.metadata or {}).items()}
    try:
        described = json.loads(meta["dtcosim"])["columns"]
        names = [c["name"] for c in described]
        units = [c["unit"] for c in described]
        fmi_types = [c["fmi_type"] for c in described]
    except (KeyError, ValueError, TypeError):  # a foreign file: field metadata or nothing
        names = list(schema.names)
        fm = [{k.decode(): v.decode() for k, v in (f.metadata or {}).items()} for f in schema]
        units = [m.get("unit", "") for m in fm]
        fmi_types = [m.get("fmi_type", "String" if str(f.type) in ("string", "large_string") else "Real")
                     for m, f in zip(fm, schema)]
    n = sum(b.num_rows for b in batches)
    data = np.empty((n, len(names)))
    text: dict[int, np.ndarray] = {}
    row = 0
    for b in batches:
        m = b.num_rows
        for j in range(len(names)):
            col = b.column(j)
            if fmi_types[j] == "String":
                text.setdefault(j, []).extend(col.to_pylist())
                data[row:row + m, j] = np.nan
            else:
                data[row:row + m, j] = col.to_numpy(zero_copy_only=False)
        row += m
    return ColumnarTable(names, units, fmi_types, data, {j: np.array(v, dtype=object) for j, v in text.items()},
                         whole)


def read_columnar(path: str | Path) -> ColumnarTable:
    """Read a Parquet results file, or an Arrow IPC stream (``timeseries.parquet.partial``) up to its last whole batch."""
    import pyarrow as pa

    path = Path(path)
    with open(path, "rb") as fh:
        head = fh.read(4)
    if head == PARQUET_MAGIC:
        import pyarrow.parquet as pq

        pf = pq.ParquetFile(path)
        batches = [pf.read_row_group(i) for i in range(pf.num_row_groups)]
        return _table_of(pf.schema_arrow, [b for t in batches for b in t.to_batches()], True)
    import pyarrow.ipc as ipc

    with pa.OSFile(str(path)) as src:
        reader = ipc.open_stream(src)
        batches, whole = [], True
        while True:
            try:
                batches.append(reader.read_next_batch())
            except StopIteration:
                break
            except (OSError, pa.ArrowInvalid):  # a batch cut by a kill: not a sample
                whole = False
                break
    if whole:
        with open(path, "rb") as fh:
            fh.seek(-len(ARROW_END_OF_STREAM), 2)
            whole = fh.read() == ARROW_END_OF_STREAM
    return _table_of(reader.schema, batches, whole)


def _naming(exc: OSError, path: str | Path) -> OSError:
    """``exc`` naming ``path``: its ``filename`` set where missing; pyarrow's, which have no errno, re-worded."""
    if exc.errno is None:  # pyarrow's own I/O errors: the text alone ("Invalid flatbuffers message.")
        return OSError(f"{path}: {exc}")
    if exc.filename is None:
        exc.filename = str(path)
    return exc


def stream_to_parquet(stream_path: str | Path, parquet_path: str | Path) -> None:
    """Convert an Arrow IPC stream to a Parquet file, :data:`ROW_GROUP_ROWS` rows per row group.

    Reads batch by batch (bounded memory); the metadata of the stream's schema
    goes into the Parquet file. Raises ``OSError`` naming ``stream_path`` if the
    stream cannot be opened, else naming ``parquet_path`` (the file cannot be
    written, or a batch of the stream cannot be read).
    """
    import pyarrow as pa
    import pyarrow.ipc as ipc
    import pyarrow.parquet as pq

    pool = pa.system_memory_pool()  # the C library's malloc: pyarrow's own pool keeps freed memory
    try:
        src = pa.OSFile(str(stream_path))
        reader = ipc.open_stream(src, memory_pool=pool)
    except OSError as exc:
        raise _naming(exc, stream_path) from exc
    with src:
        try:
            writer = pq.ParquetWriter(str(parquet_path), reader.schema, memory_pool=pool, **PARQUET_OPTIONS)
            try:
                pending, rows = [], 0
                for batch in reader:
                    pending.append(batch)
                    rows += batch.num_rows
                    if rows >= ROW_GROUP_ROWS:
                        writer.write_table(pa.Table.from_batches(pending), row_group_size=ROW_GROUP_ROWS)
                        pending, rows = [], 0
                if pending:
                    writer.write_table(pa.Table.from_batches(pending), row_group_size=ROW_GROUP_ROWS)
            finally:
                writer.close()
        except OSError as exc:
            raise _naming(exc, parquet_path) from exc

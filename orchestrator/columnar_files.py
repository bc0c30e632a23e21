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

Only this module imports ``pyarrow``, and only when a columnar file is written or
read. Arrays are built from the numpy buffers (``pyarrow.Array.from_buffers``):
``pyarrow.array`` would load pyarrow's conversion machinery, about 50 MB of
resident memory, into the run's process.
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import numpy as np

#: first bytes of a Parquet file
PARQUET_MAGIC = b"PAR1"
#: first bytes of an Arrow IPC stream message (the continuation marker)
ARROW_STREAM_MAGIC = b"\xff\xff\xff\xff"
#: the end-of-stream marker of an Arrow IPC stream
ARROW_END_OF_STREAM = b"\xff\xff\xff\xff\x00\x00\x00\x00"
#: FMI 2.0 type -> numpy dtype of its Arrow column (String: see :func:`_string_array`)
NUMPY_TYPES = {"Real": np.float64, "Integer": np.int32, "Enumeration": np.int32, "Boolean": np.bool_}
#: rows per Parquet row group: the conversion holds one (1.5 MB for 23 float64 columns; 65536 rows cost 25 MB more peak RSS)
ROW_GROUP_ROWS = 8192
#: options of the Parquet writer: Snappy and PLAIN encoding, which every Parquet reader supports
PARQUET_OPTIONS = {"compression": "snappy", "use_dictionary": False}
#: header tag of the non-Real columns that have no unit (as in ``timeseries.csv``)
TYPE_TAGS = {"Boolean": "Boolean 0/1", "String": "String"}


def _memory_pool(pa):
    """The allocator of the buffers written here: the C library's ``malloc``.

    pyarrow's default pool (mimalloc or jemalloc) keeps freed memory for reuse; in a
    run's process, beside the FMUs, that is resident memory nothing else can use
    (~2 MB of the peak of streaming and converting a 600 s run). The file bytes do not
    depend on it.
    """
    return pa.system_memory_pool()


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


def arrow_schema(columns: Sequence[Any]):
    """The Arrow schema of ``columns`` (objects with ``name``, ``unit``, ``fmi_type``; ``time`` first)."""
    import pyarrow as pa

    types = {"Real": pa.float64(), "Integer": pa.int32(), "Enumeration": pa.int32(), "Boolean": pa.bool_(),
             "String": pa.string()}
    fields = [pa.field(c.name, types[c.fmi_type], nullable=c.fmi_type == "String",
                       metadata={"unit": c.unit, "fmi_type": c.fmi_type}) for c in columns]
    described = [{"name": c.name, "unit": c.unit, "fmi_type": c.fmi_type} for c in columns]
    attrs = {"units": {c.name: c.unit for c in columns}, "fmi_types": {c.name: c.fmi_type for c in columns}}
    return pa.schema(fields, metadata={"dtcosim": json.dumps({"columns": described}),
                                       "PANDAS_ATTRS": json.dumps(attrs)})


def _numeric_array(pa, arrow_type, values: np.ndarray, fmi_type: str):
    if fmi_type == "Boolean":
        bits = np.packbits(np.asarray(values) != 0.0, bitorder="little")
        return pa.Array.from_buffers(arrow_type, len(values), [None, pa.py_buffer(bits)])
    data = np.ascontiguousarray(values, dtype=NUMPY_TYPES[fmi_type])
    return pa.Array.from_buffers(arrow_type, len(data), [None, pa.py_buffer(data)])


def _string_array(pa, strings: np.ndarray):
    """A UTF-8 string array from its offsets and bytes (no ``pyarrow.array``)."""
    encoded = [str(s).encode("utf-8") for s in strings]
    offsets = np.zeros(len(encoded) + 1, dtype=np.int32)
    np.cumsum([len(b) for b in encoded], out=offsets[1:])
    return pa.Array.from_buffers(pa.string(), len(encoded),
                                 [None, pa.py_buffer(offsets), pa.py_buffer(b"".join(encoded))])


def record_batch_bytes(schema, time_s: np.ndarray, values: np.ndarray,
                       text: dict[int, np.ndarray] | None = None) -> bytes:
    """One encapsulated Arrow IPC record-batch message of rows ``time_s`` (n,), ``values`` (n, m).

    ``text``: value column index -> the n strings of a String column.
    """
    import pyarrow as pa

    arrays = [_numeric_array(pa, schema.field(0).type, time_s, "Real")]
    for j in range(values.shape[1]):
        f = schema.field(j + 1)
        fmi_type = f.metadata[b"fmi_type"].decode()
        if fmi_type == "String":
            if not text or j not in text:
                raise ValueError(f"no strings given for String column {f.name!r}")
            arrays.append(_string_array(pa, text[j]))
        else:
            arrays.append(_numeric_array(pa, f.type, values[:, j], fmi_type))
    return pa.RecordBatch.from_arrays(arrays, schema=schema).serialize(memory_pool=_memory_pool(pa)).to_pybytes()


def schema_bytes(schema) -> bytes:
    """The encapsulated schema message that starts an Arrow IPC stream."""
    import pyarrow as pa

    return schema.serialize(memory_pool=_memory_pool(pa)).to_pybytes()


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


def stream_to_parquet(stream_path: str | Path, parquet_path: str | Path) -> None:
    """Convert an Arrow IPC stream to a Parquet file, :data:`ROW_GROUP_ROWS` rows per row group.

    Reads batch by batch (bounded memory); the metadata of the stream's schema
    goes into the Parquet file. Raises ``OSError`` (naming ``parquet_path``) if the
    file cannot be written.
    """
    import pyarrow as pa
    import pyarrow.ipc as ipc
    import pyarrow.parquet as pq

    pool = _memory_pool(pa)
    with pa.OSFile(str(stream_path)) as src:
        reader = ipc.open_stream(src, memory_pool=pool)
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
            if exc.filename is None:
                exc.filename = str(parquet_path)
            raise

"""The Arrow IPC stream a run appends its samples to, encoded with numpy and ``flatbuffers`` only.

A run streams ``timeseries.parquet.partial`` as an `Arrow IPC stream
<https://arrow.apache.org/docs/format/Columnar.html#ipc-streaming-format>`_ (the
format and its reading: :mod:`orchestrator.columnar_files`). The messages are
encoded here, not by pyarrow: importing pyarrow costs a run's process ~45 MB of
resident memory (its shared libraries and Python modules, which stay loaded),
measured with ``python benchmarks/bench_long_run.py --imports``; the encoding of
flat columns is small and fixed. pyarrow reads what is written here
(``tests/orchestrator/test_arrow_stream.py`` compares every column type, the
field and schema metadata, against the table pyarrow builds itself).

What is written
---------------
Each message is *encapsulated*: the continuation marker ``0xFFFFFFFF``, the
length of the ``Message`` flatbuffer (padded so the body starts 8-byte aligned),
the flatbuffer, then the body. The schema message has no body; a record batch's
body holds, per column, its validity buffer (empty: no nulls), then its data
buffer(s), each padded to 8 bytes. Types: FMI Real -> float64, Integer and
Enumeration -> int32, Boolean -> bool (bit-packed, least significant bit first),
String -> utf8 (int32 offsets, then the bytes). Metadata version V5 (Arrow >= 1.0).
"""

from __future__ import annotations

import json
from functools import lru_cache
from typing import Protocol, Sequence

import flatbuffers
import numpy as np

from .columnar_files import ARROW_STREAM_MAGIC as CONTINUATION  # the marker that starts every message

#: alignment of the flatbuffer's end and of every body buffer [bytes]
ALIGNMENT = 8
#: ``MetadataVersion.V5`` of Schema.fbs
METADATA_V5 = 4
#: ``MessageHeader`` union tags of Message.fbs
HEADER_SCHEMA, HEADER_RECORD_BATCH = 1, 3
#: ``Type`` union tags of Schema.fbs
TYPE_INT, TYPE_FLOATING_POINT, TYPE_UTF8, TYPE_BOOL = 2, 3, 5, 6
#: ``Precision.DOUBLE`` of Schema.fbs
PRECISION_DOUBLE = 2
#: FMI 2.0 type -> numpy dtype of its Arrow data buffer (Boolean: packed bits; String: offsets + bytes)
NUMPY_TYPES = {"Real": np.float64, "Integer": np.int32, "Enumeration": np.int32, "Boolean": np.bool_}
#: the FMI 2.0 types a column may have
FMI_TYPES = (*NUMPY_TYPES, "String")


class StreamColumn(Protocol):
    """What the encoder needs of a column (:class:`orchestrator.run.writers.Column` is one)."""

    name: str  #: ``time`` or ``component.variable``
    unit: str  #: "" for none
    fmi_type: str  #: one of :data:`FMI_TYPES`


def schema_metadata(columns: Sequence[StreamColumn]) -> dict[str, str]:
    """The schema's key-value metadata: ``dtcosim`` (the columns) and ``PANDAS_ATTRS`` (units for pandas)."""
    described = [{"name": c.name, "unit": c.unit, "fmi_type": c.fmi_type} for c in columns]
    attrs = {"units": {c.name: c.unit for c in columns}, "fmi_types": {c.name: c.fmi_type for c in columns}}
    return {"dtcosim": json.dumps({"columns": described}), "PANDAS_ATTRS": json.dumps(attrs)}


def _aligned(size: int) -> int:
    """``size`` rounded up to a multiple of :data:`ALIGNMENT`."""
    return -(-size // ALIGNMENT) * ALIGNMENT


def _encapsulate(builder: flatbuffers.Builder, body: bytes = b"") -> bytes:
    meta = bytes(builder.Output())
    size = _aligned(len(meta) + 8) - 8  # after the marker and the length: the body starts 8-byte aligned
    return CONTINUATION + size.to_bytes(4, "little", signed=True) + meta + bytes(size - len(meta)) + body


def _message(builder: flatbuffers.Builder, header_type: int, header: int, body_length: int) -> None:
    builder.StartObject(5)  # Message: version, header_type, header, bodyLength, custom_metadata
    builder.PrependInt16Slot(0, METADATA_V5, 0)
    builder.PrependUint8Slot(1, header_type, 0)
    builder.PrependUOffsetTRelativeSlot(2, header, 0)
    builder.PrependInt64Slot(3, body_length, 0)
    builder.Finish(builder.EndObject())


def _offsets_vector(builder: flatbuffers.Builder, offsets: Sequence[int]) -> int:
    builder.StartVector(4, len(offsets), 4)
    for off in reversed(offsets):
        builder.PrependUOffsetTRelative(off)
    return builder.EndVector()


def _key_values(builder: flatbuffers.Builder, metadata: dict[str, str]) -> int:
    pairs = []
    for key, value in metadata.items():
        k, v = builder.CreateString(key), builder.CreateString(value)
        builder.StartObject(2)  # KeyValue: key, value
        builder.PrependUOffsetTRelativeSlot(0, k, 0)
        builder.PrependUOffsetTRelativeSlot(1, v, 0)
        pairs.append(builder.EndObject())
    return _offsets_vector(builder, pairs)


def _type_table(builder: flatbuffers.Builder, fmi_type: str) -> tuple[int, int]:
    """(Type union tag, offset of the type table) of an FMI type."""
    if fmi_type == "Real":
        builder.StartObject(1)  # FloatingPoint: precision
        builder.PrependInt16Slot(0, PRECISION_DOUBLE, 0)
        return TYPE_FLOATING_POINT, builder.EndObject()
    if fmi_type in ("Integer", "Enumeration"):
        builder.StartObject(2)  # Int: bitWidth, is_signed
        builder.PrependInt32Slot(0, 32, 0)
        builder.PrependBoolSlot(1, True, False)
        return TYPE_INT, builder.EndObject()
    builder.StartObject(0)  # Bool and Utf8 have no fields
    return (TYPE_BOOL if fmi_type == "Boolean" else TYPE_UTF8), builder.EndObject()


def schema_message(columns: Sequence[StreamColumn]) -> bytes:
    """The encapsulated schema message that starts the stream (``time`` first in ``columns``)."""
    for c in columns:
        if c.fmi_type not in FMI_TYPES:
            raise ValueError(f"column {c.name!r}: fmi_type {c.fmi_type!r} is not one of {', '.join(FMI_TYPES)}")
    builder = flatbuffers.Builder(1024)
    fields = []
    for c in columns:
        name = builder.CreateString(c.name)
        type_tag, type_table = _type_table(builder, c.fmi_type)
        children = _offsets_vector(builder, [])
        field_metadata = _key_values(builder, {"unit": c.unit, "fmi_type": c.fmi_type})
        builder.StartObject(7)  # Field: name, nullable, type_type, type, dictionary, children, custom_metadata
        builder.PrependUOffsetTRelativeSlot(0, name, 0)
        builder.PrependBoolSlot(1, c.fmi_type == "String", False)
        builder.PrependUint8Slot(2, type_tag, 0)
        builder.PrependUOffsetTRelativeSlot(3, type_table, 0)
        builder.PrependUOffsetTRelativeSlot(5, children, 0)
        builder.PrependUOffsetTRelativeSlot(6, field_metadata, 0)
        fields.append(builder.EndObject())
    field_vector = _offsets_vector(builder, fields)
    metadata = _key_values(builder, schema_metadata(columns))
    builder.StartObject(4)  # Schema: endianness (Little = 0, the default), fields, custom_metadata, features
    builder.PrependUOffsetTRelativeSlot(1, field_vector, 0)
    builder.PrependUOffsetTRelativeSlot(2, metadata, 0)
    _message(builder, HEADER_SCHEMA, builder.EndObject(), 0)
    return _encapsulate(builder)


def _column_buffers(fmi_type: str, values: np.ndarray, strings: np.ndarray | None) -> list[bytes]:
    """The data buffer(s) of one column of n rows (after its empty validity buffer)."""
    if fmi_type == "String":
        encoded = [str(s).encode("utf-8") for s in strings]
        offsets = np.zeros(len(encoded) + 1, dtype="<i4")
        np.cumsum([len(b) for b in encoded], out=offsets[1:])
        return [offsets.tobytes(), b"".join(encoded)]
    if fmi_type == "Boolean":
        return [np.packbits(np.asarray(values) != 0.0, bitorder="little").tobytes()]
    return [np.ascontiguousarray(values, dtype=np.dtype(NUMPY_TYPES[fmi_type]).newbyteorder("<")).tobytes()]


def _struct_vector(builder: flatbuffers.Builder, pairs: Sequence[tuple[int, int]]) -> int:
    """A vector of structs of two int64 (FieldNode: length, null_count; Buffer: offset, length)."""
    builder.StartVector(16, len(pairs), 8)
    for first, second in reversed(pairs):
        builder.Prep(8, 16)
        builder.PrependInt64(second)
        builder.PrependInt64(first)
    return builder.EndVector()


def record_batch_message(columns: Sequence[StreamColumn], time_s: np.ndarray, values: np.ndarray,
                         text: dict[int, np.ndarray] | None = None) -> bytes:
    """One encapsulated record-batch message of rows ``time_s`` (n,) and ``values`` (n, m).

    ``columns`` are the stream's (``time`` first, then the m value columns);
    ``text``: value column index -> the n strings of a String column.
    """
    n = len(time_s)
    if values.shape != (n, len(columns) - 1):
        raise ValueError(f"values of shape {values.shape} for {n} rows of {len(columns) - 1} value columns")
    body, buffers, offset = [], [], 0
    for j, c in enumerate(columns):
        if c.fmi_type == "String" and (not text or j - 1 not in text):
            raise ValueError(f"no strings given for String column {c.name!r}")
        data = _column_buffers(c.fmi_type, time_s if j == 0 else values[:, j - 1],
                               text.get(j - 1) if c.fmi_type == "String" else None)
        buffers.append((offset, 0))  # validity: no nulls
        for chunk in data:
            padded = _aligned(len(chunk))
            buffers.append((offset, len(chunk)))
            body.append(chunk + bytes(padded - len(chunk)))
            offset += padded
    return _record_batch_header(n, len(columns), tuple(buffers), offset) + b"".join(body)


@lru_cache(maxsize=8)
def _record_batch_header(rows: int, n_columns: int, buffers: tuple[tuple[int, int], ...], body_length: int) -> bytes:
    """The encapsulated RecordBatch flatbuffer (cached: every full chunk of numeric columns has the same)."""
    builder = flatbuffers.Builder(256 + 32 * len(buffers))
    buffer_vector = _struct_vector(builder, buffers)
    node_vector = _struct_vector(builder, [(rows, 0)] * n_columns)
    builder.StartObject(5)  # RecordBatch: length, nodes, buffers, compression, variadicBufferCounts
    builder.PrependInt64Slot(0, rows, 0)
    builder.PrependUOffsetTRelativeSlot(1, node_vector, 0)
    builder.PrependUOffsetTRelativeSlot(2, buffer_vector, 0)
    _message(builder, HEADER_RECORD_BATCH, builder.EndObject(), body_length)
    return _encapsulate(builder)

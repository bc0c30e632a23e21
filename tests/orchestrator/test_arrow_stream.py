"""The Arrow IPC stream encoded without pyarrow: what pyarrow reads from it equals the table pyarrow builds itself."""

from __future__ import annotations

import json

import numpy as np
import pytest

from orchestrator.arrow_stream import record_batch_message, schema_message, schema_metadata
from orchestrator.columnar_files import ARROW_END_OF_STREAM
from orchestrator.run.writers import Column

pa = pytest.importorskip("pyarrow")
ipc = pytest.importorskip("pyarrow.ipc")

COLUMNS = [Column("time", "s"), Column("gearbox.F_sp[1]", "N"), Column("fail.mode", "", "Integer"),
           Column("gen.state", "", "Enumeration"), Column("gen.tripped", "", "Boolean"),
           Column("gen.message", "", "String")]
ARROW_TYPES = {"Real": pa.float64(), "Integer": pa.int32(), "Enumeration": pa.int32(), "Boolean": pa.bool_(),
               "String": pa.string()}


def rows(n: int, k: int = 0):
    t = (k * 1000 + np.arange(n)) * 1e-3
    values = np.column_stack([np.pi * (1 + t) * 1e5, np.arange(n) - 7.0 - k, np.full(n, 2.0),
                              (np.arange(n) % 3 == 0).astype(float), np.full(n, np.nan)]).reshape(n, 5)
    text = {4: np.array([["", "row ü", 'say "hi"', "x" * 13][i % 4] for i in range(n)], dtype=object)}
    return t, values, text


def expected_table(chunks):
    """The same rows and metadata as pyarrow builds them."""
    fields = [pa.field(c.name, ARROW_TYPES[c.fmi_type], nullable=c.fmi_type == "String",
                       metadata={"unit": c.unit, "fmi_type": c.fmi_type}) for c in COLUMNS]
    schema = pa.schema(fields, metadata=schema_metadata(COLUMNS))
    batches = []
    for t, values, text in chunks:
        arrays = [pa.array(t), pa.array(values[:, 0]), pa.array(values[:, 1].astype(np.int32)),
                  pa.array(values[:, 2].astype(np.int32)), pa.array(values[:, 3] != 0), pa.array(list(text[4]))]
        batches.append(pa.RecordBatch.from_arrays(arrays, schema=schema))
    return pa.Table.from_batches(batches, schema=schema)


@pytest.mark.parametrize("sizes", [(4,), (1, 250, 7), (0, 3), (8, 8, 8)], ids=["one", "uneven", "empty-batch", "same"])
def test_pyarrow_reads_every_column_type_and_the_metadata_as_it_builds_them(sizes):
    chunks = [rows(n, k) for k, n in enumerate(sizes)]
    stream = schema_message(COLUMNS) + b"".join(record_batch_message(COLUMNS, *c) for c in chunks) + ARROW_END_OF_STREAM
    table = ipc.open_stream(pa.py_buffer(stream)).read_all()
    table.validate(full=True)
    assert table.equals(expected_table(chunks), check_metadata=True)
    assert table.schema.field("gearbox.F_sp[1]").metadata == {b"unit": b"N", b"fmi_type": b"Real"}
    described = json.loads(table.schema.metadata[b"dtcosim"])["columns"]
    assert [c["name"] for c in described] == [c.name for c in COLUMNS]


def test_every_message_is_8_byte_aligned_and_starts_with_the_continuation_marker():
    for message in (schema_message(COLUMNS), record_batch_message(COLUMNS, *rows(5))):
        assert message[:4] == b"\xff\xff\xff\xff" and len(message) % 8 == 0
        assert (8 + int.from_bytes(message[4:8], "little")) % 8 == 0


@pytest.mark.parametrize("bad, match", [
    (lambda: schema_message([Column("time", "s"), Column("x", "", "Float")]), r"column 'x': fmi_type 'Float'"),
    (lambda: record_batch_message(COLUMNS, np.zeros(3), np.zeros((3, 4))), r"shape \(3, 4\) for 3 rows of 5"),
    (lambda: record_batch_message(COLUMNS, *rows(3)[:2]), r"no strings given for String column 'gen.message'"),
])
def test_bad_columns_or_rows_are_named(bad, match):
    with pytest.raises(ValueError, match=match):
        bad()

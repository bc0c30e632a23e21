"""The stream -> Parquet conversion in a child process: the same file, errors with their errno, pyarrow kept out."""

from __future__ import annotations

import errno
import json
import re
import subprocess
import sys
import textwrap

import numpy as np
import pytest

from orchestrator.arrow_stream import record_batch_message, schema_message
from orchestrator.columnar_files import ARROW_END_OF_STREAM, read_columnar
from orchestrator.parquet_conversion import PACKAGE_ROOT, convert_stream
from orchestrator.run.writers import Column

COLUMNS = [Column("time", "s"), Column("gearbox.omega_out", "rad/s"), Column("gen.tripped", "", "Boolean")]


def write_stream(path, batches: int = 3, n: int = 100):
    parts = [schema_message(COLUMNS)]
    for k in range(batches):
        t = (k * n + np.arange(n)) * 1e-3
        parts.append(record_batch_message(COLUMNS, t, np.column_stack([np.sin(t), t > 0.1])))
    path.write_bytes(b"".join(parts) + ARROW_END_OF_STREAM)
    return path


def test_the_child_writes_the_file_this_process_writes(tmp_path):
    stream = write_stream(tmp_path / "timeseries.parquet.partial")
    assert convert_stream(stream, tmp_path / "child.parquet", where="child") == "child"
    assert convert_stream(stream, tmp_path / "here.parquet", where="here") == "here"
    assert (tmp_path / "child.parquet").read_bytes() == (tmp_path / "here.parquet").read_bytes()
    table = read_columnar(tmp_path / "child.parquet")
    assert table.names == ["time", "gearbox.omega_out", "gen.tripped"] and table.data.shape == (300, 3)
    np.testing.assert_array_equal(table.data[:, 1], np.sin(np.arange(300) * 1e-3))
    assert convert_stream(stream, tmp_path / "auto.parquet") == "here"  # pyarrow is imported in this process now


def test_a_run_process_that_never_imported_pyarrow_converts_in_a_child_and_stays_without_it(tmp_path):
    code = textwrap.dedent(f"""
        import sys, numpy as np
        sys.path.insert(0, {str(PACKAGE_ROOT)!r})
        from orchestrator.run.parquet_writer import ParquetWriter
        from orchestrator.run.writers import Column
        w = ParquetWriter({str(tmp_path / "timeseries.parquet")!r})
        w.open([Column("x", "N")])
        w.append(np.arange(5) * 0.1, np.arange(5.0).reshape(5, 1))
        w.close()
        print(w.converted_in, "pyarrow" in sys.modules)
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["child", "False"]
    np.testing.assert_array_equal(read_columnar(tmp_path / "timeseries.parquet").data[:, 1], np.arange(5.0))


def test_a_missing_folder_is_an_os_error_with_its_errno_and_file_name(tmp_path):
    stream = write_stream(tmp_path / "s.partial")
    target = tmp_path / "gone" / "timeseries.parquet"
    with pytest.raises(OSError, match="gone") as info:
        convert_stream(stream, target, where="child")
    assert info.value.errno == errno.ENOENT


def test_a_file_size_limit_during_the_conversion_is_efbig_naming_the_parquet_file(tmp_path):
    stream = write_stream(tmp_path / "s.partial", batches=20)  # ~50 kB; the limit is set after it is written
    target = tmp_path / "timeseries.parquet"
    code = textwrap.dedent(f"""
        import json, resource, sys
        sys.path.insert(0, {str(PACKAGE_ROOT)!r})
        from orchestrator.parquet_conversion import convert_stream
        resource.setrlimit(resource.RLIMIT_FSIZE, (8192, 8192))
        try:
            convert_stream({str(stream)!r}, {str(target)!r}, where="child")
        except OSError as exc:
            print(json.dumps([exc.errno, exc.strerror, exc.filename]))
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    code_, message, filename = json.loads(proc.stdout)
    assert code_ == errno.EFBIG and "too large" in message and filename == str(target)


def test_a_child_that_fails_otherwise_is_an_os_error_saying_how_it_ended(tmp_path):
    stream = write_stream(tmp_path / "s.partial")
    target = tmp_path / "timeseries.parquet"
    code = textwrap.dedent(f"""
        import json, resource, sys
        sys.path.insert(0, {str(PACKAGE_ROOT)!r})
        from orchestrator.parquet_conversion import convert_stream
        resource.setrlimit(resource.RLIMIT_AS, (150_000_000, 150_000_000))  # too little for numpy and pyarrow
        try:
            convert_stream({str(stream)!r}, {str(target)!r}, where="child")
        except OSError as exc:
            print(json.dumps([exc.errno, str(exc), exc.filename]))
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    code_, message, filename = json.loads(proc.stdout)
    assert re.match(re.escape(str(target)) + r": the Parquet conversion of s.partial "
                    r"(ended with exit status \d+|was killed by signal \d+): ", message), message
    assert code_ is None and not target.exists() and "[Errno None]" not in message


@pytest.mark.parametrize("where", ["child", "here"])
def test_an_error_without_an_errno_names_the_file_and_says_what_failed(tmp_path, where):
    bad = tmp_path / "s.partial"
    bad.write_bytes(b"\xff\xff\xff\xff\x10\x00\x00\x00" + b"not a flatbuffer")
    with pytest.raises(OSError, match=r"^" + re.escape(str(bad)) + r": .*flatbuffer") as info:
        convert_stream(bad, tmp_path / "timeseries.parquet", where=where)
    assert "[Errno None]" not in str(info.value)


@pytest.mark.parametrize("where", ["child", "here"])
def test_a_missing_stream_is_named(tmp_path, where):
    with pytest.raises(OSError, match="gone.partial") as info:
        convert_stream(tmp_path / "gone.partial", tmp_path / "timeseries.parquet", where=where)
    assert info.value.errno == errno.ENOENT


def test_without_a_python_to_start_auto_converts_here(tmp_path):
    stream = write_stream(tmp_path / "s.partial")
    code = textwrap.dedent(f"""
        import sys
        sys.path.insert(0, {str(PACKAGE_ROOT)!r})
        from orchestrator.parquet_conversion import convert_in_child, convert_stream
        before = convert_in_child()
        sys.executable = ""  # as in an embedded interpreter
        print(before, convert_in_child(), convert_stream({str(stream)!r}, {str(tmp_path / "t.parquet")!r}))
    """)
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["True", "False", "here"]
    assert read_columnar(tmp_path / "t.parquet").data.shape == (300, 3)


def test_where_must_be_one_of_three():
    with pytest.raises(ValueError, match=r"where='elsewhere': expected 'auto', 'child' or 'here'"):
        convert_stream("a", "b", where="elsewhere")


# the run's process: a stop flag for SIGINT (as a run's StopRequests), then the conversion in a child whose program
# is changed to receive a SIGINT at a chosen point; prints the outcome and whether the Parquet file is there
SIGNALLED_CONVERSION = """
import os, signal, sys
sys.path.insert(0, {root!r})
from orchestrator import parquet_conversion as pc
seen = []
signal.signal(signal.SIGINT, lambda signum, frame: seen.append(signum))
pc.CHILD_CODE = pc.CHILD_CODE.replace({anchor!r}, {injected!r} + {anchor!r})
try:
    pc.convert_stream({stream!r}, {parquet!r}, where="child")
    outcome = "converted"
except OSError as exc:
    outcome = "failed: " + str(exc)
print(outcome, os.path.exists({parquet!r}), seen)
"""


@pytest.mark.parametrize("anchor, injected", [
    # a Ctrl-C on the terminal: SIGINT to the run's whole process group, as the child starts (before sys.path)
    ("import sys;", "import os, signal; os.killpg(os.getpgid(os.getppid()), signal.SIGINT); "),
    # a SIGINT to the child itself, before its conversion starts
    ("from orchestrator.parquet_conversion import main;", "import os, signal; os.kill(os.getpid(), signal.SIGINT); "),
], ids=["ctrl-c-to-the-process-group", "sigint-to-the-child"])
def test_a_sigint_never_kills_the_conversion_child(tmp_path, anchor, injected):
    """Issue 35.5: the child ignored SIGINT only once inside main(); a Ctrl-C before that killed the conversion."""
    stream = write_stream(tmp_path / "timeseries.parquet.partial")
    parquet = tmp_path / "timeseries.parquet"
    code = SIGNALLED_CONVERSION.format(root=str(PACKAGE_ROOT), anchor=anchor, injected=injected,
                                       stream=str(stream), parquet=str(parquet))
    # a session of its own, so the signal to "the run's process group" reaches no test process
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120,
                          start_new_session=True)
    assert proc.returncode == 0, proc.stderr
    expect_seen = "[2]" if "killpg" in injected else "[]"  # the run itself still receives the Ctrl-C
    assert proc.stdout.strip() == f"converted True {expect_seen}", proc.stdout
    assert read_columnar(parquet).data.shape == (300, 3)

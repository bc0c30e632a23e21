"""Converting a run's Arrow IPC stream to ``timeseries.parquet``, in a child process where that saves memory.

The conversion needs pyarrow (:func:`orchestrator.columnar_files.stream_to_parquet`),
whose libraries and modules cost a process ~45 MB of resident memory and stay
loaded once imported. A run converts when its co-simulation is over, before its
analyses and plots (which load matplotlib where a run draws its event or spectrum
figures, ~40 MB more): in the run's own process the two would add up. :func:`convert_stream` therefore runs the conversion in a
short-lived child Python process unless this process has imported pyarrow
already (a notebook, a test), where converting here costs nothing more. The
child's peak adds to the run's only while it runs, when the run holds the least
(measured: ``python benchmarks/bench_long_run.py``, the ``converter`` column).

Signals: the child runs in a process group of its own (a Ctrl-C on the terminal goes
to the run alone, which finishes the conversion and then stops) and ignores SIGINT
from its first statement on (a SIGINT sent to it directly); a run that is stopped
waits for the conversion, which takes a second or two for an hour of samples.

Errors keep their meaning across the process boundary: an ``OSError`` of the
child (a full disk, a file-size limit) is raised here with its errno, message and
file name (pyarrow's own, which have no errno, with their text, which names the
file); a child that fails otherwise or is killed raises ``OSError`` whose text
names the Parquet file, how the child ended and its last line on stderr. The
stream is never removed here (:class:`orchestrator.run.parquet_writer.ParquetWriter`
removes it after a conversion that succeeded).
"""

from __future__ import annotations

import json
import signal
import subprocess
import sys
from pathlib import Path
from typing import Literal

#: the folder that holds the ``orchestrator`` package (the child imports the same code)
PACKAGE_ROOT = Path(__file__).resolve().parents[1]
#: exit status of a child whose conversion raised OSError (its fields as JSON on stderr)
EXIT_OS_ERROR = 3
#: the child's program: SIGINT ignored first, then this module's :func:`main` with the same package first on sys.path
CHILD_CODE = ("import signal; signal.signal(signal.SIGINT, signal.SIG_IGN); "
              "import sys; sys.path.insert(0, sys.argv[1]); "
              "from orchestrator.parquet_conversion import main; sys.exit(main(sys.argv[2:]))")

Where = Literal["auto", "child", "here"]


def convert_in_child() -> bool:
    """True where :func:`convert_stream` with ``where="auto"`` starts a child.

    That is where pyarrow is not imported in this process and there is a Python to
    start (``sys.executable`` is empty in an embedded interpreter).
    """
    return "pyarrow" not in sys.modules and bool(sys.executable)


def convert_stream(stream_path: str | Path, parquet_path: str | Path, where: Where = "auto") -> str:
    """Convert the Arrow IPC stream ``stream_path`` to the Parquet file ``parquet_path``.

    Parameters
    ----------
    stream_path, parquet_path : path
        The (complete) stream and the file to write.
    where : {"auto", "child", "here"}
        ``"child"``: in a child Python process; ``"here"``: in this process;
        ``"auto"``: a child where :func:`convert_in_child` says so, else here.

    Returns
    -------
    str
        ``"child"`` or ``"here"``: where it ran.

    Raises
    ------
    OSError
        As :func:`orchestrator.columnar_files.stream_to_parquet` raises it (the stream
        cannot be read, the file cannot be written: errno and file name kept), or the
        child failed otherwise or was killed (naming ``parquet_path``).
    """
    if where not in ("auto", "child", "here"):
        raise ValueError(f"where={where!r}: expected 'auto', 'child' or 'here'")
    if where == "auto" and not convert_in_child():
        where = "here"
    if where == "here":
        from .columnar_files import stream_to_parquet

        stream_to_parquet(stream_path, parquet_path)
        return "here"
    _convert_in_child(Path(stream_path), Path(parquet_path))
    return "child"


def _convert_in_child(stream_path: Path, parquet_path: Path) -> None:
    cmd = [sys.executable, "-c", CHILD_CODE, str(PACKAGE_ROOT), str(stream_path), str(parquet_path)]
    try:
        # a process group of its own: a terminal's Ctrl-C (sent to the foreground process group) never reaches
        # the child, from its first instruction on; the run's own stop handling decides what a signal means
        proc = subprocess.run(cmd, stdin=subprocess.DEVNULL, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE,
                              text=True, process_group=0)
    except OSError as exc:  # no process to start (the process limit, no memory to fork)
        raise OSError(exc.errno, f"could not start the Parquet conversion of {stream_path.name}: {exc.strerror}",
                      str(parquet_path)) from exc
    if proc.returncode == 0:
        return
    said = proc.stderr.strip()
    if proc.returncode == EXIT_OS_ERROR:
        try:
            fields = json.loads(said.splitlines()[-1])
            error = (OSError(fields["text"]) if fields["errno"] is None
                     else OSError(fields["errno"], fields["strerror"], fields["filename"] or str(parquet_path)))
        except (ValueError, KeyError, IndexError, TypeError):
            error = None
        if error is not None:
            raise error
    how = (f"was killed by signal {-proc.returncode}" if proc.returncode < 0
           else f"ended with exit status {proc.returncode}")
    last = said.splitlines()[-1] if said else "nothing on stderr"
    raise OSError(f"{parquet_path}: the Parquet conversion of {stream_path.name} {how}: {last}")


def main(argv: list[str]) -> int:
    """The child: convert ``argv[0]`` (stream) to ``argv[1]`` (Parquet); 0, or :data:`EXIT_OS_ERROR` with JSON."""
    signal.signal(signal.SIGINT, signal.SIG_IGN)  # as CHILD_CODE does first: Ctrl-C is the run's to handle
    from .columnar_files import stream_to_parquet

    stream_path, parquet_path = argv
    try:
        stream_to_parquet(stream_path, parquet_path)
    except OSError as exc:
        print(json.dumps({"errno": exc.errno, "strerror": exc.strerror, "text": str(exc),
                          "filename": None if exc.filename is None else str(exc.filename)}), file=sys.stderr)
        return EXIT_OS_ERROR
    return 0

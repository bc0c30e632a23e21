"""Several FMUs built on two processes: this one and a forked child, each taking the next name from one queue.

An FMU build is single-threaded Python - staging its package, pythonfmu's archive, zip compression,
the stand-alone cross-check run - of 0.2-0.6 s each. A first ``dtcosim run`` builds three, a
drivetrain file's run two to four, while the second core of a 2-core machine idles. With a fork
the child starts with everything this process has imported and computed (the source closures,
the compiled sources, pythonfmu and fmpy), so it costs no start-up; the names wait in a pipe
(one byte each, read one at a time: a read from a pipe is atomic), so whichever process is free
builds the next one, and the results come back pickled through a second pipe.

Where a fork is unsafe or useless the builds run here one after another, as before:

* no ``os.fork`` (Windows), one name, or a single CPU available to the process;
* ``DTCOSIM_BUILD_WORKERS=1``;
* another thread is running in this process (a forked child gets a copy of every lock such a
  thread may hold, and would wait for it forever).

The callers hold the output folder's build lock (:func:`fmus.build_lock.build_lock`) around the
pool: the child inherits the lock (an ``flock`` belongs to the open file, shared by the fork) and
its bookkeeping, so its builds take it as a nested holder. A child ends with ``os._exit``: it never
runs this process's ``finally`` blocks or exit handlers, nor flushes its output buffers twice.

Failures: a build that raises stops its process from taking more names; the error of the first
name that failed (in the order given) is raised once both processes have stopped, as it would have
been raised by the sequential loop. A child killed by a signal, or one that cannot send its result,
is a :class:`BuildPoolError` naming the FMUs it left unbuilt. A stop signal (Ctrl-C, SIGTERM)
reaching this process while it builds is passed to the child as SIGINT, whose build then ends
the way an interrupted build here does (its temporary folder removed); this process waits for it
and raises its own interruption.
"""

from __future__ import annotations

import os
import pickle
import signal
import sys
import threading
from typing import Callable, Sequence, TypeVar

from components.errors import DtcosimError

#: the number of processes (this one included) that build FMUs; ``1``: one after another in this process
WORKERS_ENV = "DTCOSIM_BUILD_WORKERS"
#: the most processes a pool uses (the queue holds each name's index in one byte)
MAX_WORKERS = 2
_MAX_NAMES = 255

T = TypeVar("T")


class BuildPoolError(DtcosimError):
    """The forked build process ended without reporting its builds."""


def workers() -> int:
    """Processes to build with: ``DTCOSIM_BUILD_WORKERS`` if set (at least 1), else the CPUs available (at most
    :data:`MAX_WORKERS`)."""
    value = os.environ.get(WORKERS_ENV, "").strip()
    if value:
        try:
            return max(1, int(value))
        except ValueError:
            raise BuildPoolError(f"environment variable {WORKERS_ENV}={value!r}: not a whole number "
                                 "(1: build FMUs one after another in one process)") from None
    cpus = len(os.sched_getaffinity(0)) if hasattr(os, "sched_getaffinity") else (os.cpu_count() or 1)
    return max(1, min(MAX_WORKERS, cpus))


def can_fork() -> bool:
    """True where this process may fork a builder: POSIX, and no other thread running."""
    return hasattr(os, "fork") and threading.active_count() == 1


def build_each(build: Callable[[str], T], names: Sequence[str], processes: int | None = None) -> list[T]:
    """``[build(name) for name in names]``, on this process and a forked child when that helps.

    Parameters
    ----------
    build : callable(str)
        Builds one FMU; its result must be picklable (it may come from the child).
    names : sequence of str
    processes : int, optional
        Processes to use (default :func:`workers`); only 1 and 2 are distinguished.

    Raises
    ------
    Exception
        What ``build`` raised for the first name (in ``names`` order) that failed.
    BuildPoolError
        The child ended (killed by a signal) without reporting the FMUs it was building.
    """
    names = list(names)
    processes = workers() if processes is None else processes
    if processes < 2 or len(names) < 2 or len(names) > _MAX_NAMES or not can_fork():
        return [build(name) for name in names]
    return _Pool(build, names).run()


class _Pool:
    """One run of :func:`build_each` on two processes."""

    def __init__(self, build: Callable[[str], T], names: list[str]) -> None:
        self.build = build
        self.names = names

    def run(self) -> list:
        queue_r, queue_w = os.pipe()
        os.write(queue_w, bytes(range(len(self.names))))
        os.close(queue_w)  # read to the end: the queue is empty
        result_r, result_w = os.pipe()
        for stream in (sys.stdout, sys.stderr):  # the child must not write what this process had buffered
            if stream is not None:
                stream.flush()
        pid = os.fork()
        if pid == 0:  # pragma: no cover - the child's coverage is not collected
            os.close(result_r)
            self._child(queue_r, result_w)
        os.close(result_w)
        try:
            mine = self._take_and_build(queue_r)
        except BaseException:  # interrupted: the child stops too, and its build cleans up
            _drain(queue_r)
            _signal(pid, signal.SIGINT)
            _read_all(result_r)
            _wait(pid)
            raise
        finally:
            os.close(queue_r)
        payload = _read_all(result_r)
        os.close(result_r)
        status = _wait(pid)
        done = dict(mine)
        try:
            done.update(pickle.loads(payload))
        except Exception:  # noqa: BLE001 - no result: killed, or it died before writing it
            left = [n for i, n in enumerate(self.names) if i not in done]
            if left:
                raise BuildPoolError(f"{', '.join(n + '.fmu' for n in left)} not built: the forked build process "
                                     f"(pid {pid}) {_ended(status)}") from None
        for i, _ in enumerate(self.names):
            ok, value = done[i]
            if not ok:
                raise value
        return [done[i][1] for i in range(len(self.names))]

    def _take_and_build(self, queue_r: int) -> list[tuple[int, tuple[bool, object]]]:
        """Build names from the queue until it is empty or a build failed (the failure is the last entry)."""
        out = []
        while True:
            index = _take(queue_r)
            if index is None:
                return out
            try:
                out.append((index, (True, self.build(self.names[index]))))
            except Exception as exc:  # noqa: BLE001 - reported in names order once both processes have stopped
                out.append((index, (False, exc)))
                _drain(queue_r)  # neither process starts another build
                return out

    def _child(self, queue_r: int, result_w: int) -> None:  # pragma: no cover - runs in the child
        status = 1
        try:
            mine = self._take_and_build(queue_r)
            _write_all(result_w, _dumps(mine))
            status = 0
        except BaseException:  # noqa: BLE001 - interrupted (the parent was too): its builds have cleaned up
            pass
        finally:
            os._exit(status)


def _take(queue_r: int) -> int | None:
    data = os.read(queue_r, 1)
    return data[0] if data else None


def _drain(queue_r: int) -> None:
    while os.read(queue_r, 4096):
        pass


def _dumps(results: list) -> bytes:
    """The child's results, with an exception that does not pickle sent as a BuildPoolError of its text."""
    safe = []
    for index, (ok, value) in results:
        if not ok:
            try:
                pickle.loads(pickle.dumps(value))
            except Exception:  # noqa: BLE001 - an exception that does not survive pickling
                value = BuildPoolError(f"{type(value).__name__}: {value}")
        safe.append((index, (ok, value)))
    return pickle.dumps(safe)


def _write_all(fd: int, data: bytes) -> None:
    view = memoryview(data)
    while view:
        view = view[os.write(fd, view):]


def _read_all(fd: int) -> bytes:
    chunks = []
    while True:
        chunk = os.read(fd, 1 << 16)
        if not chunk:
            return b"".join(chunks)
        chunks.append(chunk)


def _signal(pid: int, signum: int) -> None:
    try:
        os.kill(pid, signum)
    except ProcessLookupError:
        pass


def _wait(pid: int) -> int:
    """The child's wait status (waiting again where a signal interrupted the wait)."""
    while True:
        try:
            return os.waitpid(pid, 0)[1]
        except ChildProcessError:
            return 0
        except InterruptedError:
            continue


def _ended(status: int) -> str:
    if os.WIFSIGNALED(status):
        signum = os.WTERMSIG(status)
        try:
            name = signal.Signals(signum).name
        except ValueError:
            name = f"signal {signum}"
        return f"was killed by {name}"
    return f"ended with status {os.waitstatus_to_exitcode(status)} without reporting its builds"

"""Signal handlers that never interrupt an import.

A Ctrl-C that lands while a C extension is being imported does not reach the
user as a KeyboardInterrupt: numpy, for one, turns it into an ``ImportError``
("PyCapsule_Import could not import module datetime") with a page of advice,
and a half-imported module stays broken for the rest of the process. dtcosim
imports most of its dependencies lazily (the command's modules, fmpy, numba,
pydantic, lxml, the FMU slaves), so a stop signal can land in an import at
almost any stage.

:func:`outside_imports` wraps a handler: a signal that arrives while an
import is running is delivered again every :data:`REDELIVERY_S` until it
lands outside every import, where the wrapped handler runs (and may raise).
It is sent again until the handler has run, not once: a signal that arrives
just before the main thread enters a blocking call (``time.sleep``, a wait)
is noted by CPython but wakes nothing, and would otherwise wait for the call
to end. One redelivery is pending per signal at a time, so a signal handled
inside an import starts no further thread.
:func:`install` puts such handlers in place for the signals a process does
not ignore, and :func:`restore` puts the previous ones back.
"""

from __future__ import annotations

import signal
import threading
import time
from collections.abc import Callable, Mapping
from types import FrameType

#: the import machinery's own frames
_IMPORT_FILES = frozenset({"<frozen importlib._bootstrap>", "<frozen importlib._bootstrap_external>"})

#: how long a signal that landed inside an import waits before it is delivered again [s]
REDELIVERY_S = 0.02

Handler = Callable[[int, "FrameType | None"], object]


def inside_import(frame: FrameType | None) -> bool:
    """True if ``frame`` (a signal handler's frame argument) runs inside an import."""
    while frame is not None:
        if frame.f_code.co_filename in _IMPORT_FILES:
            return True
        frame = frame.f_back
    return False


def _to_main_thread(signum: int) -> None:
    """Send ``signum`` to the main thread, so it also wakes a ``sleep`` or a wait there."""
    if hasattr(signal, "pthread_kill"):
        signal.pthread_kill(threading.main_thread().ident, signum)
    else:  # Windows: the handler runs in the main thread anyway
        signal.raise_signal(signum)


#: signals deferred out of an import whose handler has not run yet (changed under the GIL only)
_pending: set[int] = set()


def _redeliver(signum: int) -> None:
    """Send ``signum`` to the main thread every :data:`REDELIVERY_S` until its handler has run.

    Where the deferring handler is gone by then (:func:`restore` put the previous one back),
    the signal is sent once more, to the handler in place, and no longer.
    """
    while signum in _pending:
        if not hasattr(signal.getsignal(signum), "wrapped"):
            _pending.discard(signum)
        _to_main_thread(signum)
        time.sleep(REDELIVERY_S)


def _deliver_again(signum: int) -> None:
    if signum in _pending:  # a redelivery is under way: it sends this one too
        return
    _pending.add(signum)
    timer = threading.Timer(REDELIVERY_S, _redeliver, (signum,))
    timer.daemon = True
    timer.start()


def outside_imports(handler: Handler) -> Handler:
    """``handler``, run only where no import is in progress.

    Parameters
    ----------
    handler : callable
        A Python signal handler ``handler(signum, frame)``.

    Returns
    -------
    callable
        A handler that, inside an import, asks for the signal to be delivered
        again shortly and returns; elsewhere it calls ``handler``.
    """

    def deferring(signum: int, frame: FrameType | None) -> object:
        if inside_import(frame):
            _deliver_again(signum)
            return None
        _pending.discard(signum)
        return handler(signum, frame)

    deferring.wrapped = handler  # type: ignore[attr-defined]
    return deferring


def install(handlers: Mapping[int, Handler]) -> dict[int, object]:
    """Put each handler in place, kept out of imports (:func:`outside_imports`).

    Only in the main thread (elsewhere Python cannot set handlers: nothing is
    changed), and not for a signal the process ignores (SIGHUP under ``nohup``
    stays ignored).

    Parameters
    ----------
    handlers : mapping of int to callable
        Signal number -> Python handler ``handler(signum, frame)``.

    Returns
    -------
    dict
        The handlers replaced, for :func:`restore`.
    """
    previous: dict[int, object] = {}
    if threading.current_thread() is threading.main_thread():
        for signum, handler in handlers.items():
            if signal.getsignal(signum) is not signal.SIG_IGN:
                previous[signum] = signal.signal(signum, outside_imports(handler))
    return previous


def restore(previous: Mapping[int, object]) -> None:
    """Put back the handlers :func:`install` replaced."""
    for signum, handler in previous.items():
        signal.signal(signum, handler)

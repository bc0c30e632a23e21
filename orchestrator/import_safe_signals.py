"""Signal handlers that never interrupt an import.

A Ctrl-C that lands while a C extension is being imported does not reach the
user as a KeyboardInterrupt: numpy, for one, turns it into an ``ImportError``
("PyCapsule_Import could not import module datetime") with a page of advice,
and a half-imported module stays broken for the rest of the process. dtcosim
imports most of its dependencies lazily (the command's modules, fmpy, numba,
pydantic, lxml, the FMU slaves), so a stop signal can land in an import at
almost any stage.

:func:`outside_imports` wraps a handler: a signal that arrives while an
import is running is delivered again :data:`REDELIVERY_S` later, until it
lands outside every import, where the wrapped handler runs (and may raise).
"""

from __future__ import annotations

import signal
import threading
from collections.abc import Callable
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


def _deliver_again(signum: int) -> None:
    timer = threading.Timer(REDELIVERY_S, _to_main_thread, (signum,))
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
        return handler(signum, frame)

    deferring.wrapped = handler  # type: ignore[attr-defined]
    return deferring

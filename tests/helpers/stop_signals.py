"""Stop signals at their defaults in a test, as a shell's job has them.

A suite started under ``nohup`` (or by a runner that ignores SIGHUP) passes the ignored SIGHUP on to
every process it starts, and dtcosim keeps an ignored signal ignored (``nohup dtcosim ...`` must survive
the hang-up). A test of what a command does *on* SIGHUP therefore puts the default back first.
"""

from __future__ import annotations

import contextlib
import signal
from collections.abc import Iterator

STOP_SIGNALS = (signal.SIGINT, signal.SIGTERM, signal.SIGHUP)


def as_from_a_terminal(then=None):
    """A ``preexec_fn`` putting the child's stop signals at their defaults (then calling ``then``)."""

    def preexec():
        for signum in STOP_SIGNALS:
            signal.signal(signum, signal.SIG_DFL)
        if then is not None:
            then()

    return preexec


@contextlib.contextmanager
def ignored_stop_signals_at_defaults() -> Iterator[None]:
    """In this process, while the block runs: every ignored stop signal at its default."""
    ignored = [s for s in STOP_SIGNALS if signal.getsignal(s) is signal.SIG_IGN]
    for signum in ignored:
        signal.signal(signum, signal.SIG_DFL)
    try:
        yield
    finally:
        for signum in ignored:
            signal.signal(signum, signal.SIG_IGN)

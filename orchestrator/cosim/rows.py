"""Where the master's finished rows go: the run's sink and, optionally, the outcome's arrays.

After each block of communication steps the master hands its finished rows to a
:class:`FinishedRows`, which passes them to the run's :class:`RowSink` (e.g. a results
file writer of :mod:`orchestrator.run.writers`) and keeps them for the
:class:`~orchestrator.cosim.outcome.RunOutcome` unless ``keep_values`` is off.
"""

from __future__ import annotations

from typing import Protocol

import numpy as np

from ..atomic_files import describe_os_error
from .values import TextStore


class RowSink(Protocol):
    """Where the master hands each finished block of rows (e.g. :class:`orchestrator.run.writers.CsvWriter`)."""

    def append(self, time_s: np.ndarray, values: np.ndarray, text: dict[int, np.ndarray] | None = None) -> None:
        """Rows at ``time_s`` (n,), ``values`` (n, m) in the order of ``system.recorded``; may raise OSError.

        ``text`` (only when String variables are recorded): column index -> the n
        strings of that column (its ``values`` column is NaN).
        """


class FinishedRows:
    """The rows a run has finished: handed to the sink and, optionally, kept for the outcome.

    Parameters
    ----------
    start_s, interval_s : float
        Time of row 0 and between rows [s].
    order : ndarray of int
        Block-buffer column of each recorded variable (``system.recorded`` order).
    capacity : int
        Rows to keep (0: keep none). The array is allocated uninitialised, so the
        memory is taken as rows arrive.
    sink : RowSink, optional
    text : TextStore, optional
        String samples of the run (rows by sample index).
    text_columns : dict of int -> int, optional
        Recorded column -> TextStore column of the recorded String variables.
    """

    def __init__(self, start_s: float, interval_s: float, order: np.ndarray, capacity: int,
                 sink: RowSink | None, text: TextStore | None = None,
                 text_columns: dict[int, int] | None = None) -> None:
        self.start_s, self.interval_s = start_s, interval_s
        self.order = order
        self.sink = sink
        self.count = 0
        self.kept = np.empty((capacity, len(order))) if capacity else None
        self.text = text
        self.text_columns = dict(text_columns or {})
        self.last_time_s: float | None = None  # a last row off the output grid (an FMU ended the run)

    def deliver(self, rows: np.ndarray, last_time_s: float | None = None) -> str | None:
        """Hand over ``rows`` (block-buffer columns), the last one at ``last_time_s`` if given (off the grid);
        the sink's write error as text, else None."""
        n = len(rows)
        if n == 0:
            return None
        values = rows[:, self.order]
        index = self.count + np.arange(n)
        times = self.start_s + self.interval_s * index
        if last_time_s is not None:
            times[-1] = self.last_time_s = last_time_s
        if self.kept is not None:
            self.kept[self.count:self.count + n] = values
        text = {j: self.text.rows[self.count:self.count + n, col] for j, col in self.text_columns.items()}
        self.count += n
        if self.sink is not None:
            try:
                if text:
                    self.sink.append(times, values, text)
                else:
                    self.sink.append(times, values)
            except OSError as exc:
                self.sink = None  # nothing more goes to a sink that failed
                return f"results not written: {describe_os_error(exc)}"
        return None

    def time_s(self) -> np.ndarray:
        """Times of the kept rows [s] (the last one off the grid if an FMU ended the run there)."""
        n = self.count if self.kept is not None else 0
        times = self.start_s + self.interval_s * np.arange(n, dtype=float)
        if n and self.last_time_s is not None:
            times[-1] = self.last_time_s
        return times

    def values(self) -> np.ndarray:
        """The kept rows, columns in ``system.recorded`` order (none without keeping)."""
        if self.kept is None:
            return np.empty((0, len(self.order)))
        return self.kept[:self.count]

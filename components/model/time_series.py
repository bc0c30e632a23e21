"""Recorded time series played back in time: interpolation, integrated angles, out-of-record policy.

The samples come from a record (an aeroelastic code's output, a CSV file) already
converted to SI units by the orchestrator (:mod:`orchestrator.inputs.series_file`);
this module only plays them. Two interpolants, both exact at every record point:

``linear``
    piecewise linear, C0 (torque channels: a held input of the receiving FMU needs no more);
``pchip``
    piecewise cubic Hermite with Fritsch-Carlson (monotonicity-preserving) slopes, C1
    (speed channels that drive the Gearbox's stage-1 carrier kinematically: the Gearbox
    builds a C1 motion from speed and angle, and a C1 speed gives it a continuous
    acceleration, no overshoot at steps such as a brake or a torque drop).

An *angle* output is the exact integral of a speed channel's interpolant from the
first record point plus an initial angle, so ``d angle / dt = speed`` holds exactly.
Outside the record the policy is ``hold`` (first/last sample; the angle continues with
the held speed) or ``error`` (:class:`~components.errors.SolverError`).
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError, SolverError

INTERPOLATIONS = ("linear", "pchip")
OUT_OF_RECORD = ("hold", "error")


def pchip_slopes(t: np.ndarray, y: np.ndarray) -> np.ndarray:
    """Fritsch-Carlson slopes at the samples: C1, no overshoot (weighted harmonic mean, one-sided ends)."""
    n = t.size
    if n == 2:
        d = (y[1] - y[0]) / (t[1] - t[0])
        return np.array([d, d])
    h = np.diff(t)
    delta = np.diff(y) / h
    m = np.zeros(n)
    w1 = 2.0 * h[1:] + h[:-1]
    w2 = h[1:] + 2.0 * h[:-1]
    same = delta[:-1] * delta[1:] > 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        harm = (w1 + w2) / (w1 / delta[:-1] + w2 / delta[1:])
    m[1:-1] = np.where(same, harm, 0.0)
    for end, (h0, h1, d0, d1) in ((0, (h[0], h[1], delta[0], delta[1])), (n - 1, (h[-1], h[-2], delta[-1], delta[-2]))):
        s = ((2.0 * h0 + h1) * d0 - h0 * d1) / (h0 + h1)  # three-point end formula, limited
        if np.sign(s) != np.sign(d0):
            s = 0.0
        elif np.sign(d0) != np.sign(d1) and abs(s) > abs(3.0 * d0):
            s = 3.0 * d0
        m[end] = s
    return m


class Interpolant:
    """Interpolant of one channel with the exact running integral (for an angle).

    Parameters
    ----------
    time_s, values : ndarray, shape (n,)
        Strictly increasing record times [s] and the samples (SI), n >= 2, finite.
    method : {"linear", "pchip"}
    """

    def __init__(self, time_s: np.ndarray, values: np.ndarray, method: str = "pchip") -> None:
        if method not in INTERPOLATIONS:
            raise ParameterError("interpolation", method, "one of " + ", ".join(INTERPOLATIONS))
        t = np.asarray(time_s, dtype=float)
        y = np.asarray(values, dtype=float)
        if t.ndim != 1 or t.shape != y.shape or t.size < 2:
            raise ParameterError("time series", t.shape, "two or more samples of time and value")
        if not np.all(np.isfinite(t)) or not np.all(np.isfinite(y)):
            raise ParameterError("time series", "NaN/inf", "finite samples")
        if not np.all(np.diff(t) > 0.0):
            raise ParameterError("time series", "time", "strictly increasing record times")
        self.method = method
        self.t, self.y = t, y
        self._times = t.tolist()
        h = np.diff(t)
        self.m = pchip_slopes(t, y) if method == "pchip" else None
        # integral of each interval [t_i, t_i+1] and the cumulative integral at the samples
        if method == "pchip":
            area = h * (y[:-1] + y[1:]) / 2.0 + h * h * (self.m[:-1] - self.m[1:]) / 12.0
        else:
            area = h * (y[:-1] + y[1:]) / 2.0
        self.cumulative = np.concatenate([[0.0], np.cumsum(area)])

    @property
    def start_s(self) -> float:
        return float(self.t[0])

    @property
    def end_s(self) -> float:
        return float(self.t[-1])

    def _segment(self, t: float) -> int:
        return min(max(bisect.bisect_right(self._times, t) - 1, 0), len(self._times) - 2)

    def value(self, t: float) -> float:
        """Value at ``t`` inside the record (exactly the sample at a record time)."""
        i = self._segment(t)
        t0, h = self.t[i], self.t[i + 1] - self.t[i]
        s = (t - t0) / h
        y0, y1 = self.y[i], self.y[i + 1]
        if self.method == "linear":
            return float(y0 + s * (y1 - y0))
        m0, m1 = self.m[i] * h, self.m[i + 1] * h
        s2, s3 = s * s, s * s * s
        return float((2 * s3 - 3 * s2 + 1) * y0 + (s3 - 2 * s2 + s) * m0 + (-2 * s3 + 3 * s2) * y1 + (s3 - s2) * m1)

    def integral(self, t: float) -> float:
        """``int_{t_0}^{t} value dt`` for ``t`` inside the record (exact for the interpolant)."""
        i = self._segment(t)
        t0, h = self.t[i], self.t[i + 1] - self.t[i]
        s = (t - t0) / h
        y0, y1 = self.y[i], self.y[i + 1]
        if self.method == "linear":
            part = h * (y0 * s + 0.5 * s * s * (y1 - y0))
        else:
            m0, m1 = self.m[i] * h, self.m[i + 1] * h
            s2, s3, s4 = s * s, s ** 3, s ** 4
            part = h * ((s4 / 2 - s3 + s) * y0 + (s4 / 4 - 2 * s3 / 3 + s2 / 2) * m0
                        + (-s4 / 2 + s3) * y1 + (s4 / 4 - s3 / 3) * m1)
        return float(self.cumulative[i] + part)


@dataclass(frozen=True)
class ChannelSpec:
    """One output of a time-series player.

    Parameters
    ----------
    output : str
        FMU output name.
    column : int
        Column of the packed sample matrix.
    method : {"linear", "pchip"}
    integral_of : bool
        True: the output is the integral (angle) of the column's interpolant, plus ``initial``.
    initial : float
        Value of an integral output at the record's first time.
    """

    output: str
    column: int
    method: str = "pchip"
    integral_of: bool = False
    initial: float = 0.0


class TimeSeriesPlayer:
    """Plays recorded channels: ``output(t) = interpolant(t + time_offset)``.

    Parameters
    ----------
    time_s : ndarray, shape (n,)
        Record times [s].
    samples : ndarray, shape (n, k)
        Samples in SI units.
    channels : sequence of ChannelSpec
    time_offset_s : float
        Record time = simulation time + offset (a record of 30-90 s played from 0 s: offset 30 s).
    out_of_record : {"hold", "error"}
    """

    def __init__(self, time_s, samples, channels, time_offset_s: float = 0.0, out_of_record: str = "error") -> None:
        if out_of_record not in OUT_OF_RECORD:
            raise ParameterError("out_of_record", out_of_record, "one of " + ", ".join(OUT_OF_RECORD))
        if not np.isfinite(time_offset_s):
            raise ParameterError("time_offset", time_offset_s, "a finite number [s]")
        samples = np.asarray(samples, dtype=float)
        self.channels = tuple(channels)
        self.offset_s = float(time_offset_s)
        self.policy = out_of_record
        self.interpolants = {}
        for ch in self.channels:
            key = (ch.column, ch.method)
            if key not in self.interpolants:
                self.interpolants[key] = Interpolant(time_s, samples[:, ch.column], ch.method)
        first = next(iter(self.interpolants.values()))
        self.start_s, self.end_s = first.start_s, first.end_s

    def covers(self, t0_s: float, t1_s: float) -> bool:
        """Whether simulation times [t0, t1] lie inside the record."""
        eps = 1e-9 * max(1.0, abs(self.end_s))
        return self.start_s - eps <= t0_s + self.offset_s and t1_s + self.offset_s <= self.end_s + eps

    def values(self, t_s: float) -> list[float]:
        """Every output at simulation time ``t_s``, in channel order."""
        tr = t_s + self.offset_s
        eps = 1e-9 * max(1.0, abs(self.end_s))
        if not self.start_s - eps <= tr <= self.end_s + eps:
            if self.policy == "error":
                raise SolverError(f"record time {tr:.9g} s (simulation time {t_s:.9g} s + offset {self.offset_s:g} s) is "
                                  f"outside the record [{self.start_s:g}, {self.end_s:g}] s (out_of_record = error)", t_s)
        inside = min(max(tr, self.start_s), self.end_s)
        out = []
        for ch in self.channels:
            f = self.interpolants[(ch.column, ch.method)]
            if ch.integral_of:
                extra = 0.0
                if tr > self.end_s:
                    extra = (tr - self.end_s) * f.value(self.end_s)
                elif tr < self.start_s:
                    extra = (tr - self.start_s) * f.value(self.start_s)
                out.append(ch.initial + f.integral(inside) + extra)
            else:
                out.append(f.value(inside))
        return out

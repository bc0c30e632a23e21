"""Resolution and sampling of a recorded signal: the quantisation step of its values, the sampling interval.

A record written by an aeroelastic code carries its numbers with a finite resolution. Three
kinds are recognised from the values alone (any unit: the estimate is in the unit the numbers
are written in, so the decimal analysis must see them as recorded, before a unit conversion):

``significant_digits``
    Text written in a floating format with ``S`` significant digits (FAST v6 ``ES10.3E2``:
    ``9.98E+00``, 3 digits): the step is relative, ``10**(floor(log10|x|) - S + 1)`` at a value
    ``x`` (0.01 rpm between 1 and 10 rpm, 0.1 rpm between 10 and 100 rpm).
``decimals``
    Text written with ``D`` decimals (``F10.2``, CSV ``%.2f``): one step ``10**-D`` everywhere.
``uniform``
    Values on an evenly spaced lattice that is not decimal: OpenFAST's compressed binary
    (``.outb`` format 4 and 2 store each channel as 16-bit integers with a scale and an offset,
    so the step is the channel's range / 65535).
``none``
    No common step above the floating-point resolution (a record of full-precision numbers).
``constant``
    Fewer than two distinct values: no step to be seen.

How (:func:`estimate_resolution`): each non-zero value is written with the fewest significant
decimal digits that give back the same double (``s_i``; ``9.98`` needs 3). When every value
needs at most :data:`MAX_DECIMAL_DIGITS`, the numbers are decimal text and two explanations are
weighed: a fixed step (the finest last digit of all values, ``10**min(p_i)`` with ``p_i`` the place of
the last digit of value ``i``) and a significant-digit format (``S = max s_i``, the step
``10**(e_i - S + 1)`` of each value of decade ``e_i``). Both explain every value; the coarser one
(the larger geometric mean step) is the record's resolution: a fixed-decimal record needs more
significant digits for its large values (so the digits model gives its small values too fine a
step), a significant-digit record has last digits of every decade (so the fixed model gives its
large values too fine a step). Values of one decade give the same steps either way (reported
as ``decimals``). Otherwise the distinct values are tested for a lattice: the smallest distance
between distinct values, or a whole fraction of it (1/2 to 1/10), of which every distance is a
whole multiple to within :data:`LATTICE_TOLERANCE` of a step.

:func:`sampling_of` gives the sampling interval (median of the time steps), the rate and whether
the sampling is uniform (every step within :data:`UNIFORM_SAMPLING_TOLERANCE` of the median).

:func:`step_ratio` compares a channel's step with how much the signal changes from sample to
sample: ``sum of the steps / sum of |x[i+1] - x[i]|`` over a span, the acceleration one step implies
when it is interpolated over one sampling interval (``q / dt``) against the signal's mean rate of
change (``sum |dx| / T``). A staircase that moves one step every ``n`` samples has the ratio ``n``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError

#: decimal text has at most this many significant digits (more: full-precision numbers, no decimal step)
MAX_DECIMAL_DIGITS = 9
#: relative difference under which a value counts as written exactly with a number of digits
_DIGITS_RTOL = 1.0e-12
#: a distance between distinct values is a whole multiple of the lattice step to within this fraction of it
LATTICE_TOLERANCE = 0.01
#: a sampling is uniform when every time step lies within this fraction of the median step
UNIFORM_SAMPLING_TOLERANCE = 1.0e-6
KINDS = ("significant_digits", "decimals", "uniform", "none", "constant")


def _decades(x: np.ndarray) -> np.ndarray:
    """``floor(log10(x))`` of positive values, corrected where log10 rounds across a power of ten."""
    e = np.floor(np.log10(x))
    e = np.where(x >= 10.0 ** (e + 1), e + 1, e)
    return np.where(x < 10.0 ** e, e - 1, e).astype(int)


def _rounded(x: np.ndarray, decimals: np.ndarray) -> np.ndarray:
    """``x`` rounded to ``decimals`` decimal places (negative: to tens, hundreds, ...), elementwise."""
    out = np.empty_like(x)
    pos = decimals >= 0
    scale = 10.0 ** np.abs(decimals)
    out[pos] = np.round(x[pos] * scale[pos]) / scale[pos]
    out[~pos] = np.round(x[~pos] / scale[~pos]) * scale[~pos]
    return out


def significant_digits(values: np.ndarray, max_digits: int = 15) -> np.ndarray:
    """The fewest significant decimal digits that write each value (0 for zero; ``max_digits + 1`` if more).

    ``9.98`` -> 3, ``10.0`` -> 1, ``0.0493`` -> 3, ``1/3`` -> 12 (the first to give it back within
    the relative tolerance ``1e-12``).
    """
    x = np.abs(np.asarray(values, dtype=float))
    out = np.zeros(x.shape, dtype=int)
    todo = x > 0.0
    if not np.any(todo):
        return out
    e = np.zeros(x.shape, dtype=int)
    e[todo] = _decades(x[todo])
    out[todo] = max_digits + 1
    for s in range(1, max_digits + 1):
        idx = np.flatnonzero(todo)
        if idx.size == 0:
            break
        xi = x[idx]
        ok = np.abs(_rounded(xi, s - 1 - e[idx]) - xi) <= _DIGITS_RTOL * xi
        out[idx[ok]] = s
        todo[idx[ok]] = False
    return out


@dataclass(frozen=True, eq=False)
class Resolution:
    """The quantisation of a record's values (see the module docstring).

    Attributes
    ----------
    kind : str
        One of :data:`KINDS`.
    digits : int or None
        Significant digits (``significant_digits``) or decimals (``decimals``; negative for
        steps of 10, 100, ...); None for the other kinds.
    steps : ndarray, shape (n,)
        The step at each value, in the unit of the values (0 at an exact zero of a
        significant-digit record, and everywhere for ``none`` and ``constant``).
    """

    kind: str
    digits: int | None
    steps: np.ndarray

    @property
    def step(self) -> float:
        """The largest step [unit of the values] (0: no step found)."""
        return float(np.max(self.steps)) if self.steps.size else 0.0

    @property
    def smallest_step(self) -> float:
        """The smallest non-zero step (0: no step found)."""
        nz = self.steps[self.steps > 0.0]
        return float(np.min(nz)) if nz.size else 0.0

    def describe(self, unit: str = "") -> str:
        """``"3 significant digits: steps 1e-4 to 0.1 rpm"``, ``"2 decimals: step 0.01 rpm"``."""
        u = f" {unit}" if unit else ""
        if self.kind == "significant_digits":
            lo, hi = self.smallest_step, self.step
            span = f"step {hi:.3g}{u}" if lo == hi else f"steps {lo:.3g} to {hi:.3g}{u}"
            return f"{self.digits} significant digits: {span}"
        if self.kind == "decimals":
            return f"{self.digits} decimal{'' if self.digits == 1 else 's'}: step {self.step:.3g}{u}"
        if self.kind == "uniform":
            return f"an even step of {self.step:.6g}{u}"
        if self.kind == "constant":
            return "constant (one value)"
        return "no common step (full-precision numbers)"

    def as_dict(self, unit: str = "", factor: float = 1.0) -> dict:
        """``kind``, ``digits``, ``step``, ``smallest_step`` (in ``unit``) and the same in SI (times ``factor``)."""
        return {"kind": self.kind, "digits": self.digits, "unit": unit, "step": self.step,
                "smallest_step": self.smallest_step, "step_si": self.step * factor,
                "smallest_step_si": self.smallest_step * factor, "description": self.describe(unit)}


def _decimal_resolution(x: np.ndarray) -> Resolution | None:
    """The decimal-text explanation of the values (None: not decimal text)."""
    nz = x != 0.0
    if not np.any(nz):
        return None
    s = significant_digits(x[nz], MAX_DECIMAL_DIGITS)
    if s.max() > MAX_DECIMAL_DIGITS:
        return None
    e = _decades(np.abs(x[nz]))
    last = e - s + 1  # the place of each value's last digit
    fixed = int(last.min())
    sig = int(s.max())
    sig_exp = e - sig + 1
    steps = np.zeros(x.shape)
    if float(np.mean(sig_exp)) > fixed + 1.0e-9:  # the coarser explanation (larger geometric mean step)
        steps[nz] = 10.0 ** sig_exp.astype(float)
        return Resolution("significant_digits", sig, steps)
    steps[:] = 10.0 ** fixed
    return Resolution("decimals", -fixed, steps)


def _lattice_step(distinct: np.ndarray) -> float | None:
    """The step of an even lattice the sorted distinct values lie on, or None."""
    d = np.diff(distinct)
    smallest = float(d.min())
    floor = 64.0 * np.finfo(float).eps * float(np.max(np.abs(distinct)))
    for m in range(1, 11):
        q = smallest / m
        if q <= floor:
            return None
        k = d / q
        if np.all(np.abs(k - np.round(k)) <= LATTICE_TOLERANCE):
            levels = round((distinct[-1] - distinct[0]) / q)
            return float((distinct[-1] - distinct[0]) / levels)
    return None


def estimate_resolution(values) -> Resolution:
    """The resolution of recorded values (see the module docstring).

    Raises
    ------
    ParameterError
        For no values or a non-finite one.
    """
    x = np.asarray(values, dtype=float).ravel()
    if x.size == 0 or not np.all(np.isfinite(x)):
        raise ParameterError("values", "empty or non-finite", "finite recorded values")
    distinct = np.unique(x)
    if distinct.size < 2:
        return Resolution("constant", None, np.zeros(x.shape))
    decimal = _decimal_resolution(x)
    if decimal is not None:
        return decimal
    step = _lattice_step(distinct)
    if step is not None:
        return Resolution("uniform", None, np.full(x.shape, step))
    return Resolution("none", None, np.zeros(x.shape))


@dataclass(frozen=True)
class Sampling:
    """The time grid of a record.

    Attributes
    ----------
    interval_s : float
        The median time step [s].
    uniform : bool
        Every step within :data:`UNIFORM_SAMPLING_TOLERANCE` of the median.
    smallest_s, largest_s : float
        The extreme time steps [s].
    """

    interval_s: float
    uniform: bool
    smallest_s: float
    largest_s: float

    @property
    def rate_hz(self) -> float:
        return 1.0 / self.interval_s

    @property
    def nyquist_hz(self) -> float:
        """Half the sampling rate: the highest frequency the samples carry."""
        return 0.5 / self.interval_s

    def as_dict(self) -> dict:
        return {"interval_s": self.interval_s, "rate_hz": self.rate_hz, "nyquist_hz": self.nyquist_hz,
                "uniform": self.uniform, "smallest_interval_s": self.smallest_s, "largest_interval_s": self.largest_s}


def sampling_of(time_s) -> Sampling:
    """The sampling of strictly increasing times [s] (two or more)."""
    t = np.asarray(time_s, dtype=float)
    if t.ndim != 1 or t.size < 2 or not np.all(np.isfinite(t)) or not np.all(np.diff(t) > 0.0):
        raise ParameterError("time", "not strictly increasing", "two or more strictly increasing finite times [s]")
    h = np.diff(t)
    med = float(np.median(h))
    uniform = bool(np.all(np.abs(h - med) <= UNIFORM_SAMPLING_TOLERANCE * med))
    return Sampling(med, uniform, float(h.min()), float(h.max()))


def step_ratio(values, steps) -> float:
    """``sum of the interval steps / sum |x[i+1] - x[i]|`` (see the module docstring); 0 for a constant span.

    ``steps`` is the step at each value (:attr:`Resolution.steps`, same unit as ``values``); the
    step of an interval is the larger of its two ends'.
    """
    x = np.asarray(values, dtype=float)
    q = np.asarray(steps, dtype=float)
    if x.shape != q.shape or x.ndim != 1:
        raise ParameterError("steps", q.shape, f"one step per value ({x.shape})")
    if x.size < 2:
        return 0.0
    moved = float(np.sum(np.abs(np.diff(x))))
    if moved == 0.0:
        return 0.0
    return float(np.sum(np.maximum(q[:-1], q[1:])) / moved)


def lowpass_zero_phase(values, interval_s: float, cutoff_hz: float, order: int = 2) -> np.ndarray:
    """``values`` sampled every ``interval_s`` through a zero-phase Butterworth low-pass at ``cutoff_hz``.

    The filter runs forward and backward (``scipy.signal.sosfiltfilt``): no delay, the gain
    squared (-6 dB at the cut-off, an effective order ``2 * order``), the record's mean and
    slow trends kept. Edges are padded by odd reflection (scipy's default), so the first and
    last samples stay close to the record's.

    Raises
    ------
    ParameterError
        For a cut-off at or above the Nyquist frequency ``0.5 / interval_s``, or too few samples.
    """
    from scipy.signal import butter, sosfiltfilt

    x = np.asarray(values, dtype=float)
    nyquist = 0.5 / interval_s
    if not (0.0 < cutoff_hz < nyquist):
        raise ParameterError("lowpass_hz", cutoff_hz, f"a cut-off in (0, {nyquist:g}) Hz (below the record's "
                                                      f"Nyquist frequency, half its sampling rate)")
    sos = butter(order, cutoff_hz, btype="low", fs=1.0 / interval_s, output="sos")
    pad = 3 * (2 * len(sos) + 1)
    if x.size <= pad:
        raise ParameterError("lowpass_hz", cutoff_hz, f"a record of more than {pad} samples to filter ({x.size})")
    return sosfiltfilt(sos, x)

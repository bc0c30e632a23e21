"""Where the ticks of an axis go and what their labels say: linear "nice" steps and log decades.

The rules are those a reader of matplotlib's figures knows (and every other figure dtcosim
draws uses): on a linear axis the step is the smallest of 1, 2, 2.5, 5 or 10 times a power
of ten that puts at most ``bins`` intervals over the range (matplotlib's ``MaxNLocator`` as
its ``AutoLocator`` configures it), ``bins`` being what fits the axis' length: one label per
three font sizes along a horizontal axis, per two up a vertical one, at most 9. Labels carry
as many decimals as tell the ticks apart; a common offset (``+1.6e3``) leaves the labels where
it saves four digits or more, and a power of ten (``1e-5``) where the values reach 1e6 or drop
to 1e-5 (matplotlib's ``ScalarFormatter``). A log axis has a major tick at every decade (every
n-th where more decades than ticks fit), labelled as plain numbers (``0.01``, ``1``, ``100``),
and minor ticks at 2 and 5 times each decade.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass

import numpy as np

#: the steps of a linear axis within one power of ten (and the next power of ten)
STEPS = (1.0, 2.0, 2.5, 5.0, 10.0)
#: the steps tried: a tenth of each below 10, each, and twice ten
_EXTENDED = np.array([s / 10.0 for s in STEPS[:-1]] + list(STEPS) + [10.0 * STEPS[1]])
#: at most this many intervals on an axis
MAX_BINS = 9
#: a common offset leaves the labels only if it saves at least this many digits
OFFSET_DIGITS = 4
#: labels switch to a power of ten at or beyond these exponents
POWER_LIMITS = (-5, 6)
MINUS = "\u2212"


def tick_bins(length_pt: float, fontsize_pt: float, horizontal: bool) -> int:
    """Intervals that fit on an axis ``length_pt`` long with labels of ``fontsize_pt`` (1 to 9)."""
    per_label = fontsize_pt * (3.0 if horizontal else 2.0)
    return int(min(max(math.floor(length_pt / per_label), 1), MAX_BINS))


def nonsingular(vmin: float, vmax: float, expander: float = 0.05, tiny: float = 1e-15) -> tuple[float, float]:
    """``(vmin, vmax)`` in increasing order, widened by ``expander`` of their size where they (nearly) coincide."""
    if not (math.isfinite(vmin) and math.isfinite(vmax)):
        return -expander, expander
    vmin, vmax = sorted((float(vmin), float(vmax)))
    largest = max(abs(vmin), abs(vmax))
    if largest < 1e6 / tiny * np.finfo(float).tiny or (vmin == 0.0 and vmax == 0.0):
        return -expander, expander
    if vmax - vmin <= largest * tiny:
        return vmin - expander * abs(vmin), vmax + expander * abs(vmax)
    return vmin, vmax


def _multiples(x: float, step: float, offset: float) -> tuple[int, int]:
    """(largest n with n step <= x, smallest n with n step >= x), tolerant to rounding at a large offset."""
    if offset > 0.0:
        tol = min(0.4999, max(1e-10, 10.0 ** (math.log10(offset / step) - 12.0)))
    else:
        tol = 1e-10
    whole, rest = divmod(x, step)
    frac = rest / step
    below = whole + 1 if abs(frac - 1.0) < tol else whole
    above = whole if abs(frac) < tol else whole + 1
    return int(below), int(above)


def linear_ticks(vmin: float, vmax: float, bins: int) -> np.ndarray:
    """Tick positions of a linear axis over ``[vmin, vmax]``: a nice step, at most ``bins`` intervals.

    The ticks span the range (the first at or below ``vmin``, the last at or above ``vmax``);
    only those inside it are drawn. At least two fall inside it.
    """
    vmin, vmax = nonsingular(vmin, vmax, expander=1e-13, tiny=1e-14)
    span = vmax - vmin
    mean = 0.5 * (vmax + vmin)
    offset = 0.0 if abs(mean) / span < 100.0 else math.copysign(10.0 ** (math.log10(abs(mean)) // 1), mean)
    scale = 10.0 ** (math.log10(span / bins) // 1)
    low_v, high_v = vmin - offset, vmax - offset
    steps = _EXTENDED * scale
    large = np.nonzero(steps >= (high_v - low_v) / bins)[0]
    first = int(large[0]) if large.size else steps.size - 1
    for step in steps[:first + 1][::-1]:
        base = (low_v // step) * step
        low, _ = _multiples(low_v - base, step, abs(offset))
        _, high = _multiples(high_v - base, step, abs(offset))
        ticks = np.arange(low, high + 1) * step + base
        if np.count_nonzero((ticks >= low_v) & (ticks <= high_v)) >= 2:
            break
    return ticks + offset


@dataclass(frozen=True)
class TickLabels:
    """The labels of an axis' ticks and the text that goes beside the axis (offset, power of ten; '' if none)."""

    labels: tuple[str, ...]
    offset_text: str = ""
    offset: float = 0.0
    power: int = 0


def _minus(text: str) -> str:
    return text.replace("-", MINUS)


def _plain(value: float) -> str:
    """A value as ``1.6e3`` (significand and decimal exponent; ``5`` for an exponent of 0)."""
    exponent = math.floor(math.log10(abs(value)))
    significand = round(value / 10.0 ** exponent, 10)
    text = "%d" % significand if significand % 1 == 0 else "%1.10g" % significand
    return text if exponent == 0 else f"{text}e{exponent}"


def _common_offset(visible: np.ndarray) -> float:
    """The offset the labels of ``visible`` ticks leave out: the leading digits they share, if that saves 4 digits."""
    if visible.size == 0:
        return 0.0
    lmin, lmax = float(visible.min()), float(visible.max())
    if lmin == lmax or lmin <= 0.0 <= lmax:
        return 0.0
    abs_min, abs_max = sorted((abs(lmin), abs(lmax)))
    top = math.ceil(math.log10(abs_max))
    oom = 1 + next(k for k in itertools.count(top, -1) if abs_min // 10.0 ** k != abs_max // 10.0 ** k)
    if (abs_max - abs_min) / 10.0 ** oom <= 1e-2:  # straddling a multiple of a large power of ten
        oom = 1 + next(k for k in itertools.count(top, -1) if abs_max // 10.0 ** k - abs_min // 10.0 ** k > 1)
    leading = abs_max // 10.0 ** oom
    return math.copysign(leading * 10.0 ** oom, lmin) if leading >= 10 ** (OFFSET_DIGITS - 1) else 0.0


def linear_labels(ticks: np.ndarray, vmin: float, vmax: float) -> TickLabels:
    """Labels of linear ``ticks`` shown over ``[vmin, vmax]``: decimals that tell them apart, offset, power of ten."""
    ticks = np.asarray(ticks, dtype=float)
    low, high = sorted((vmin, vmax))
    visible = ticks[(ticks >= low) & (ticks <= high)]
    offset = _common_offset(visible)
    if visible.size == 0:
        power = 0
    else:
        largest = float(np.abs(visible).max())
        oom = math.floor(math.log10(high - low)) if offset else (math.floor(math.log10(largest)) if largest else 0)
        power = oom if oom <= POWER_LIMITS[0] or oom >= POWER_LIMITS[1] else 0
    values = ticks if ticks.size >= 2 else np.concatenate([ticks, [low, high]])
    scaled = (values - offset) / 10.0 ** power
    spread = float(np.ptp(scaled)) or float(np.max(np.abs(scaled))) or 1.0
    spread_oom = math.floor(math.log10(spread))
    decimals = max(0, 3 - spread_oom)
    scaled = scaled[:ticks.size]
    while decimals >= 0 and np.abs(scaled - np.round(scaled, decimals)).max() < 1e-3 * 10.0 ** spread_oom:
        decimals -= 1
    decimals += 1
    labels = []
    for v in scaled:
        labels.append(_minus("%1.*f" % (decimals, 0.0 if abs(v) < 1e-8 else v)))
    text = ""
    if offset or power:
        text = (f"1e{power}" if power else "") + (("+" if offset > 0 else "") + _plain(offset) if offset else "")
    return TickLabels(tuple(labels), _minus(text), offset, power)


def log_ticks(vmin: float, vmax: float, bins: int) -> tuple[np.ndarray, np.ndarray]:
    """(major, minor) tick positions of a base-10 log axis over ``[vmin, vmax]`` (both > 0).

    Majors at the decades, every n-th where more than ``bins`` of them fall inside; minors at 2
    and 5 times every decade (at the decades between the majors where those are spaced).
    """
    if not (vmin > 0.0 and vmax > 0.0):
        raise ValueError(f"a log axis needs positive limits, not {vmin:g}..{vmax:g}")
    low, high = sorted((math.log10(vmin), math.log10(vmax)))
    first, last = math.floor(low), math.ceil(high)
    inside = math.floor(high) - math.ceil(low) + 1
    stride = max(inside // (bins + 1) + 1, 1)
    decades = np.arange(first - first % stride, last + stride, stride)
    major = 10.0 ** decades.astype(float)
    if stride == 1:
        minor = np.concatenate([[2.0 * 10.0 ** d, 5.0 * 10.0 ** d] for d in range(first, last + 1)])
    else:
        minor = 10.0 ** np.array([d for d in range(first, last + 1) if d % stride], dtype=float)
    return major, minor


def log_labels(ticks: np.ndarray) -> TickLabels:
    """Labels of log decades as plain numbers: ``0.01``, ``1``, ``100`` (``1e+06`` from a million)."""
    return TickLabels(tuple(_minus(f"{v:g}") for v in ticks))

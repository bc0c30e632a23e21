"""The stand-alone run each FMU kind declares as its cross-check (:data:`fmus.registry.KINDS`), and its inputs.

Declarations only (numpy): the registry reads them without the run and the comparison of
:mod:`fmus.cross_check`.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from components.errors import DtcosimError


class CrossCheckError(DtcosimError):
    """A cross-check could not be made or read (no reference in the FMU, an unreadable result file)."""


@dataclass(frozen=True)
class Ramp:
    """An input that moves piecewise-linearly through ``(times[k], factors[k] x its start value)``, or through
    ``(times[k], values[k])`` where ``values`` is given (e.g. for a start value of 0); held before and after."""

    name: str
    times: tuple[float, ...]
    factors: tuple[float, ...] = ()
    values: tuple[float, ...] = ()


@dataclass(frozen=True)
class CrossCheckCase:
    """The stand-alone run an FMU kind carries as its cross-check.

    Attributes
    ----------
    stop_time : float
        [s].
    ramps : tuple of Ramp
        Inputs that move; the others stay at their start values.
    integrals : tuple of (str, str)
        ``(angle input, speed input)``: the angle is the speed's exact integral from its start value.
    start_time : float
        [s] (a load record's FMU starts where its record does).
    """

    stop_time: float
    ramps: tuple[Ramp, ...] = ()
    integrals: tuple[tuple[str, str], ...] = ()
    start_time: float = 0.0


def _inputs_of(md) -> list:
    return [v for v in md.modelVariables if v.causality == "input"]


def _start(v) -> float:
    if v.start in (None, ""):
        return 0.0
    if v.type == "Boolean":
        return 1.0 if str(v.start).lower() in ("true", "1") else 0.0
    return float(v.start)


def stated_inputs(case: CrossCheckCase, md, step: float) -> np.ndarray:
    """The stated inputs as a structured array (``time`` and one field per input of ``md``)."""
    n = int(round((case.stop_time - case.start_time) / step))
    t = case.start_time + np.arange(n + 1) * step
    values = {v.name: np.full(t.size, _start(v)) for v in _inputs_of(md)}
    for ramp in case.ramps:
        if ramp.name not in values:
            raise CrossCheckError(f"cross-check case: {ramp.name!r} is not an input of {md.modelName}")
        points = ramp.values or tuple(f * values[ramp.name][0] for f in ramp.factors)
        values[ramp.name] = np.interp(t, ramp.times, points)
    for angle, speed in case.integrals:
        w = values[speed]
        # exact integral of the piecewise-linear speed (trapezoids are exact for it)
        values[angle] = values[angle][0] + np.concatenate([[0.0], np.cumsum(0.5 * (w[1:] + w[:-1]) * np.diff(t))])
    dtype = [("time", float)] + [(name, float) for name in values]
    return np.array(list(zip(t, *values.values())), dtype=dtype)

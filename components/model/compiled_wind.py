"""Compiled (numba) phasor step of the rotor-speed process (eq. 13): one loop instead of three numpy calls.

:class:`components.model.wind.PhasorStepper` holds the harmonics as phasors
``z_k = exp(i (f_k t + phi_k))``; a step rotates them by ``exp(i f_k h)`` and the
speed and angle are the sums ``sum_k Re(z_k) W_k`` and ``sum_k Im(z_k) W_k / f_k``
(the amplitudes are real). The numpy path does that in three calls (a complex
multiply and two BLAS dot products, ~2.5 us for 256 harmonics); here it is one
loop (~0.6 us). The sums run in index order, so they differ from BLAS's in the last
bits only; :func:`phasor_sums` is the same summation without the rotation, used
wherever the stepper forms its sums from phasors it did not rotate (closed form,
restored state), so a stepper continues bit-identically whichever way its phasors
were formed. This module imports numba; :class:`~components.model.wind.PhasorStepper`
decides whether it is used (:func:`components.model.kernel.choose_kernel`).
"""

from __future__ import annotations

from numba import njit  # optional requirement: the compiled wind step; without it the numpy path runs

from .numba_cache import enable_stable_cache


@njit(cache=False)
def phasor_sums(z, amplitudes, amplitudes_over_f):
    """``(sum Re(z) W, sum Im(z) W / f)`` in index order."""
    speed_sum = 0.0
    angle_sum = 0.0
    for k in range(z.shape[0]):
        v = z[k]
        speed_sum += v.real * amplitudes[k]
        angle_sum += v.imag * amplitudes_over_f[k]
    return speed_sum, angle_sum


@njit(cache=False)
def rotate_and_sum(z, rotation, amplitudes, amplitudes_over_f):
    """``z *= rotation`` in place, then :func:`phasor_sums` of the rotated phasors (one pass)."""
    speed_sum = 0.0
    angle_sum = 0.0
    for k in range(z.shape[0]):
        v = z[k] * rotation[k]
        z[k] = v
        speed_sum += v.real * amplitudes[k]
        angle_sum += v.imag * amplitudes_over_f[k]
    return speed_sum, angle_sum


@njit(cache=False)
def derivative_sums(z, amplitudes_times_f, amplitudes_times_f2):
    """``(sum Im(z) W f, sum Re(z) W f^2)`` in index order: minus the acceleration and minus the jerk."""
    alpha_sum = 0.0
    jerk_sum = 0.0
    for k in range(z.shape[0]):
        v = z[k]
        alpha_sum += v.imag * amplitudes_times_f[k]
        jerk_sum += v.real * amplitudes_times_f2[k]
    return alpha_sum, jerk_sum


DISPATCHERS = (phasor_sums, rotate_and_sum, derivative_sums)
#: entry points of the ahead-of-time compiled module (:mod:`components.model.aot`) and their signatures
AOT_EXPORTS = {
    "phasor_sums": "UniTuple(f8, 2)(c16[::1], f8[::1], f8[::1])",
    "rotate_and_sum": "UniTuple(f8, 2)(c16[::1], c16[::1], f8[::1], f8[::1])",
    "derivative_sums": "UniTuple(f8, 2)(c16[::1], f8[::1], f8[::1])",
}
#: True when the machine code is cached on disk (see :mod:`components.model.numba_cache`)
DISK_CACHE = enable_stable_cache(DISPATCHERS, __file__, __name__)

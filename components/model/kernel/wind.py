"""The phasor step of the rotor-speed process (eq. 13): rotate the harmonics' phasors and sum them.

:class:`components.model.wind.PhasorStepper` holds the harmonics as phasors
``z_k = exp(i (f_k t + phi_k))``; a step rotates them by ``exp(i f_k h)`` and the speed and angle
are the sums ``sum_k Re(z_k) W_k`` and ``sum_k Im(z_k) W_k / f_k`` (the amplitudes are real); the
acceleration and jerk are ``-sum Im(z) W f`` and ``-sum Re(z) W f^2``. Written with numpy (the
interpreted form) and as one loop each (what numba compiles, ``COMPILED``: ~0.6 us for 256
harmonics); both sum in index order, so the two forms give the same numbers. Phasors the stepper
did not rotate itself (closed form, restored state) are summed the same way (:func:`phasor_sums`),
so a stepper continues bit-identically.
This is the wind kernel's entry module (see :mod:`components.compile`).
"""

from __future__ import annotations

import numpy as np


def _sum(x):
    """The sum from the first term on (as the loops add; BLAS's blocked sums differ in the last bits)."""
    return float(np.cumsum(x)[-1]) if x.size else 0.0


def phasor_sums(z, amplitudes, amplitudes_over_f):
    """``(sum Re(z) W, sum Im(z) W / f)``."""
    return _sum(z.real * amplitudes), _sum(z.imag * amplitudes_over_f)


def rotate_and_sum(z, rotation, amplitudes, amplitudes_over_f):
    """``z *= rotation`` in place, then :func:`phasor_sums` of the rotated phasors."""
    z *= rotation
    return phasor_sums(z, amplitudes, amplitudes_over_f)


def derivative_sums(z, amplitudes_times_f, amplitudes_times_f2):
    """``(sum Im(z) W f, sum Re(z) W f^2)``: minus the acceleration and minus the jerk."""
    return _sum(z.imag * amplitudes_times_f), _sum(z.real * amplitudes_times_f2)


def _phasor_sums_loop(z, amplitudes, amplitudes_over_f):
    speed_sum = 0.0
    angle_sum = 0.0
    for k in range(z.shape[0]):
        v = z[k]
        speed_sum += v.real * amplitudes[k]
        angle_sum += v.imag * amplitudes_over_f[k]
    return speed_sum, angle_sum


def _rotate_and_sum_loop(z, rotation, amplitudes, amplitudes_over_f):
    speed_sum = 0.0
    angle_sum = 0.0
    for k in range(z.shape[0]):
        v = z[k] * rotation[k]
        z[k] = v
        speed_sum += v.real * amplitudes[k]
        angle_sum += v.imag * amplitudes_over_f[k]
    return speed_sum, angle_sum


def _derivative_sums_loop(z, amplitudes_times_f, amplitudes_times_f2):
    alpha_sum = 0.0
    jerk_sum = 0.0
    for k in range(z.shape[0]):
        v = z[k]
        alpha_sum += v.imag * amplitudes_times_f[k]
        jerk_sum += v.real * amplitudes_times_f2[k]
    return alpha_sum, jerk_sum


#: the loops numba compiles in place of the numpy forms (see :mod:`components.compile.jit`)
COMPILED = {"phasor_sums": _phasor_sums_loop, "rotate_and_sum": _rotate_and_sum_loop,
            "derivative_sums": _derivative_sums_loop}
#: entry points of the ahead-of-time compiled module (:mod:`components.compile.aot`) and their signatures
AOT_EXPORTS = {
    "phasor_sums": "UniTuple(f8, 2)(c16[::1], f8[::1], f8[::1])",
    "rotate_and_sum": "UniTuple(f8, 2)(c16[::1], c16[::1], f8[::1], f8[::1])",
    "derivative_sums": "UniTuple(f8, 2)(c16[::1], f8[::1], f8[::1])",
}

"""The input motion over a communication step: Taylor targets and cubic Hermite curves.

Over ``[t_n, t_n + h]`` the gearbox moves the driver (rotor) and the generator end of its
output shaft along cubic Hermite curves ``x(tau)`` with the value and slope the motion had at
the end of the previous step and, at ``tau = h``, the target extrapolated from the new inputs:
``phi_n + omega_n h + alpha h^2 / 2 (+ j h^3 / 6)`` with its speed. The motions are C1 in time
(a new input never makes a kinematic body jump in speed) and track the inputs to the order of
the extrapolation without drift (each target is anchored on the received angle). A curve is
the four coefficients ``c`` of ``c0 + c1 tau + c2 tau^2 + c3 tau^3``.
"""

from __future__ import annotations


def fit(c, h, x0, dx0, x1, dx1):
    """The cubic on ``[0, h]`` with value and slope ``x0, dx0`` at 0 and ``x1, dx1`` at ``h``, into ``c``."""
    delta = (x1 - x0) / h
    c[0] = x0
    c[1] = dx0
    c[2] = (3.0 * delta - 2.0 * dx0 - dx1) / h
    c[3] = (dx0 + dx1 - 2.0 * delta) / (h * h)


def value(c, tau):
    return c[0] + tau * (c[1] + tau * (c[2] + tau * c[3]))


def rate(c, tau):
    return c[1] + tau * (2.0 * c[2] + 3.0 * tau * c[3])


def accel(c, tau):
    return 2.0 * c[2] + 6.0 * tau * c[3]


def jerk(c):
    return 6.0 * c[3]


def taylor_target(h, angle, speed, alpha, jerk_):
    """Angle and speed after ``h`` from ``angle, speed, alpha, jerk_`` at the start (third-order Taylor)."""
    return (angle + h * (speed + h * (0.5 * alpha + h * (jerk_ / 6.0))),
            speed + h * (alpha + h * (0.5 * jerk_)))


def linear_target(h, angle, speed, alpha):
    """Angle and speed after ``h`` with the acceleration ``alpha`` held (second order)."""
    return angle + h * (speed + 0.5 * h * alpha), speed + h * alpha


INLINE = ("fit", "value", "rate", "accel", "jerk", "taylor_target", "linear_target")

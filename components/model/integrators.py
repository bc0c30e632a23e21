"""A one-step, L-stable, linearly implicit integrator for stiff mechanical systems.

:class:`Rosenbrock23` is the modified Rosenbrock formula of Shampine and
Reichelt (MATLAB's ``ode23s``): second order, L-stable, with an embedded
third-order error estimate and no Newton iteration. It is written for
second-order systems

    q_dot = v,    v_dot = a(t, q, v)

with analytic Jacobian blocks ``da/dq`` and ``da/dv``; the ``2n x 2n`` stage
equations ``(I - h d J) k = r`` are reduced to one ``n x n`` system (Schur
complement); the inverse of ``I - h d J`` is formed once per Jacobian and step
size and applied by one matrix-vector product per stage.

Jacobian reuse
--------------
The formula is a W-method: expanding the stages gives
``y1 = y0 + h f + h^2/2 (J f + f_t) + O(h^3)`` for *any* matrix ``W``, so it stays
second order when the Jacobian is not current. The integrator therefore keeps
the Jacobian (and the inverse for the current step size) and refreshes it when
it is older than ``jacobian_max_age`` steps or after a rejected step; the
inverse is formed again when the step size changes. The error estimate guards
the approximation: a stale Jacobian that hurts accuracy causes a rejection,
which forces a refresh.

The inverse of the step size used before is kept too (same Jacobian): a
communication step whose last internal step was shortened to end on the
communication point starts the next one with the step size before, and takes its
inverse back instead of forming it again (in the paper's co-simulation at
H = 5 ms, a third of the factorisations). It is the same matrix, so results are
unchanged bit for bit.

Step-size control after a rejection
-----------------------------------
The controller's ``0.9 err^(-1/3)`` assumes the local error shrinks like ``h^3``.
At a co-simulation communication point the prescribed input motions change their
acceleration (the generator's torque input is piecewise constant), which starts a
fast, heavily damped transient of the stiff mesh modes; over such a transient the
estimate shrinks only like ``h^0.2 .. h^0.5`` and the ``h^3`` rule needed up to ten
rejections in a row per communication step (H = 20 ms). After a second rejection at
the same time with a fresh Jacobian the controller therefore uses the order
observed between the two attempts, ``p = log(err1 / err2) / log(h1 / h2)`` (clipped
to [0.2, 3]), and proposes ``h (0.9 / err)^(1/p)`` (at least a tenth of ``h``).

Being a one-step method, it carries no history: nothing needs restarting between
communication steps. The complete integrator state is :meth:`get_state`.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Callable, Protocol

import numpy as np

from ..errors import SolverError
from ..validation import integer_at_least, positive

_D = 1.0 / (2.0 + math.sqrt(2.0))
_E32 = 6.0 + math.sqrt(2.0)
#: _E32 as a 0-d array: multiplying an array by it is the same operation as by the float, but
#: skips numpy's conversion of a Python scalar (a measurable cost on arrays this small)
_E32_ARRAY = np.array(_E32)
#: bounds of the error order observed between two rejected attempts (see module docstring)
OBSERVED_ORDER_MIN, OBSERVED_ORDER_MAX = 0.2, 3.0


def shrink_after_rejection(h: float, err: float, previous: tuple[float, float] | None) -> float:
    """Factor on ``h`` after a rejected step with a fresh Jacobian (see the module docstring).

    Parameters
    ----------
    h, err : float
        Size [s] and error norm of the rejected step (``err > 1``; may be inf).
    previous : (float, float) or None
        ``(h, err)`` of the rejected attempt just before, at the same time with a fresh
        Jacobian, or None.
    """
    if not math.isfinite(err):
        return 0.1
    if previous is not None and err < previous[1] and h < previous[0]:
        order = math.log(previous[1] / err) / math.log(previous[0] / h)
        order = min(OBSERVED_ORDER_MAX, max(OBSERVED_ORDER_MIN, order))
        return max(0.1, (0.9 / err) ** (1.0 / order))
    return max(0.1, 0.9 * err ** (-1.0 / 3.0))


class SecondOrderSystem(Protocol):
    """What :class:`Rosenbrock23` integrates; ``y = [q, v]`` has shape (2n,)."""

    def acceleration(self, t: float, y: np.ndarray) -> np.ndarray:
        """a(t, q, v), shape (n,)."""

    def jacobian(self, t: float, y: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(da/dq, da/dv) at one state, each shape (n, n)."""

    def time_derivative(self, t: float, y: np.ndarray) -> np.ndarray:
        """Partial da/dt (may be approximate: the method is a W-method)."""

    # Optional: when ``time_derivative_basis`` returns a matrix ``B`` (k, n) that only
    # changes when the Jacobian is re-evaluated, and ``time_derivative_coefficients(t)``
    # the k numbers with ``da/dt = c(t) @ B``, the integrator applies ``W^-1`` to ``B``
    # once per factorisation instead of to ``da/dt`` at every step.


@dataclass(frozen=True)
class StepControl:
    """Error control of :class:`Rosenbrock23`.

    Parameters
    ----------
    rtol : float
        Relative tolerance.
    atol_q : float
        Absolute tolerance on positions (deviation angles) [rad].
    atol_v : float
        Absolute tolerance on speeds [rad/s].
    h_min : float
        Smallest step [s] before the integrator gives up.
    max_steps : int
        Maximum steps (accepted + rejected) per call of :meth:`Rosenbrock23.advance`.
    jacobian_max_age : int
        Accepted steps after which the Jacobian is re-evaluated (1: every step).
    """

    rtol: float = 1e-4
    atol_q: float = 1e-8
    atol_v: float = 1e-5
    h_min: float = 1e-12
    max_steps: int = 100_000
    jacobian_max_age: int = 20

    def __post_init__(self) -> None:
        positive("rtol", self.rtol)
        positive("atol_q", self.atol_q)
        positive("atol_v", self.atol_v)
        positive("h_min", self.h_min)
        integer_at_least("max_steps", self.max_steps, 1)
        integer_at_least("jacobian_max_age", self.jacobian_max_age, 1)


class Rosenbrock23:
    """Adaptive ROS2(3) W-method for ``q_dot = v, v_dot = a(t, q, v)``.

    Parameters
    ----------
    system : SecondOrderSystem
        Provides the acceleration, its Jacobian and time derivative.
    n : int
        Number of positions.
    control : StepControl
        Tolerances and Jacobian reuse.

    Attributes
    ----------
    h_next : float
        Step size proposed for the next step [s].
    accepted, rejected, jacobians : int
        Counters.
    """

    def __init__(self, system: SecondOrderSystem, n: int, control: StepControl | None = None) -> None:
        self.system = system
        self.control = control or StepControl()
        self.n = n
        self.h_next = 0.0
        self.accepted = 0
        self.rejected = 0
        self.jacobians = 0
        self._dq = np.zeros((n, n))
        self._dv = np.zeros((n, n))
        self._age = -1  # < 0: no Jacobian yet
        self._hd = -1.0  # step*d the inverse was formed for
        self._winv = np.zeros((2 * n, 2 * n))
        self._winv_v = np.zeros((2 * n, n))
        self._w_basis = None
        #: the factorisation before the current one, (hd, winv, winv_v, w_basis), same Jacobian; None: none
        self._previous: tuple | None = None
        basis = getattr(system, "time_derivative_basis", None)
        self._basis_form = basis is not None and basis() is not None
        c = self.control
        self._atol = np.concatenate((np.full(n, c.atol_q), np.full(n, c.atol_v)))
        self._rtol = np.array(c.rtol)  # 0-d, see _E32_ARRAY
        #: (y, |y|) of the last step's end state: the next step starts there (arrays are never mutated)
        self._abs_end: tuple[np.ndarray | None, np.ndarray | None] = (None, None)
        #: called as ``on_accept(t, y, f)`` after every accepted step, ``t`` its end time [s], ``y`` the
        #: state and ``f = [v, a]`` the derivative there (shape (2n,), not to be modified); None: no call
        self.on_accept: Callable[[float, np.ndarray, np.ndarray], None] | None = None

    # ------------------------------------------------------------- linear algebra
    def _refresh_jacobian(self, t: float, y: np.ndarray) -> None:
        self._dq, self._dv = self.system.jacobian(t, y)
        self._age = 0
        self._hd = -1.0
        self._previous = None
        self.jacobians += 1

    def _use_factorisation(self, hd: float) -> None:
        """Make ``W^-1`` for ``hd`` current: the kept previous one if it was formed for ``hd``, else a new one."""
        current = (self._hd, self._winv, self._winv_v, self._w_basis) if self._hd > 0.0 else None
        previous = self._previous
        if previous is not None and previous[0] == hd:
            self._hd, self._winv, self._winv_v, self._w_basis = previous
        else:
            self._factor(hd)
        self._previous = current

    def _factor(self, hd: float) -> None:
        """Form ``W^-1 = (I - hd J)^-1`` for ``J = [[0, I], [dq, dv]]`` via the n x n Schur complement."""
        n = self.n
        G = -hd * self._dv - (hd * hd) * self._dq
        G.flat[:: n + 1] += 1.0
        ginv = np.linalg.inv(G)
        ginv_dq = ginv @ self._dq
        winv = np.empty((2 * n, 2 * n))
        winv[:n, :n] = (hd * hd) * ginv_dq
        winv[:n, :n].flat[:: n + 1] += 1.0
        winv[:n, n:] = hd * ginv
        winv[n:, :n] = hd * ginv_dq
        winv[n:, n:] = ginv
        self._winv = winv
        self._winv_v = np.ascontiguousarray(winv[:, n:])
        self._w_basis = None  # W^-1 applied to the time-derivative basis, formed on first use
        self._hd = hd

    # -------------------------------------------------------------------- step
    def _step(self, t: float, y: np.ndarray, f0: np.ndarray, h: float):
        """One step from ``y = [q, v]`` with ``f0 = [v, a(t, q, v)]``; returns (y_new, f_new, error_norm).

        Hot path of the co-simulation gearbox: the arrays are tiny, so the cost is the
        number of numpy calls. Products use ``np.dot`` (the same BLAS product as ``@``
        without the ufunc machinery) and ``2 x`` is written ``x + x`` (exact either way).
        """
        n = self.n
        dot = np.dot
        system = self.system
        hd = h * _D
        if hd != self._hd:
            self._use_factorisation(hd)
        winv = self._winv
        if self._basis_form:  # W^-1 [0, h d a_t] with a_t = c(t) @ B
            if self._w_basis is None:
                self._w_basis = dot(self._winv_v, system.time_derivative_basis().T)
            w_hdT = dot(self._w_basis, np.array([hd * c for c in system.time_derivative_coefficients(t)]))
        else:
            w_hdT = dot(self._winv_v, hd * system.time_derivative(t, y))
        k1 = dot(winv, f0) + w_hdT
        y1 = y + (0.5 * h) * k1
        f1 = np.concatenate((y1[n:], system.acceleration(t + 0.5 * h, y1)))
        k2 = dot(winv, f1 - k1) + k1
        yn = y + h * k2
        fn = np.concatenate((yn[n:], system.acceleration(t + h, yn)))
        d10 = k1 - f0
        k3 = dot(winv, fn - _E32_ARRAY * (k2 - f1) - (d10 + d10)) + w_hdT
        start, abs_start = self._abs_end
        abs_end = np.abs(yn)
        self._abs_end = (yn, abs_end)
        if start is not y:
            abs_start = np.abs(y)
        scale = self._atol + self._rtol * np.maximum(abs_start, abs_end)
        err = (h / 6.0) * float((np.abs(k1 + k3 - (k2 + k2)) / scale).max())
        if not math.isfinite(err):
            err = math.inf
        return yn, fn, err

    def advance(self, t: float, y: np.ndarray, t_end: float, a0: np.ndarray | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Integrate from ``t`` to exactly ``t_end`` [s].

        Parameters
        ----------
        y : ndarray, shape (2n,)
            State ``[q, v]`` at ``t``.
        a0 : ndarray, optional
            ``a(t, q, v)`` if already known (first-same-as-last reuse).

        Returns
        -------
        y, a : ndarray
            State and acceleration at ``t_end``; the last call of
            ``system.acceleration`` was made at exactly this state.

        Raises
        ------
        SolverError
            If the step size falls below ``h_min`` or ``max_steps`` is exceeded.
        """
        c = self.control
        n = self.n
        h = self.h_next if self.h_next > 0.0 else t_end - t
        if a0 is None:
            a0 = self.system.acceleration(t, y)
        f = np.concatenate((y[n:], a0))
        steps = 0
        rejected_before: tuple[float, float] | None = None  # (h, err) of a rejection at this t, fresh Jacobian
        while t < t_end:
            remaining = t_end - t
            last = h >= remaining * (1.0 - 1e-12)
            if last:
                h = remaining
            if self._age < 0 or self._age >= c.jacobian_max_age:
                self._refresh_jacobian(t, y)
            yn, fn, err = self._step(t, y, f, h)
            steps += 1
            if err <= 1.0:
                rejected_before = None
                self.accepted += 1
                self._age += 1
                t = t_end if last else t + h
                y, f = yn, fn
                if self.on_accept is not None:
                    self.on_accept(t, y, f)
                factor = 5.0 if err == 0.0 else min(5.0, 0.9 * err ** (-1.0 / 3.0))
                # keep the step (and the factorisation) unless it clearly should change
                factor = 1.0 if 1.0 <= factor <= 2.0 else factor
                if not last or factor < 1.0:
                    self.h_next = h * factor
                else:  # a step shortened to hit t_end must not shrink the proposal
                    self.h_next = max(self.h_next, h * factor)
                h = self.h_next
            else:
                self.rejected += 1
                if self._age > 0:  # retry with a fresh Jacobian before shrinking the step much
                    self._refresh_jacobian(t, y)
                    h *= max(0.5, min(1.0, 0.9 * err ** (-1.0 / 3.0))) if math.isfinite(err) else 0.1
                    rejected_before = None
                else:
                    factor = shrink_after_rejection(h, err, rejected_before)
                    rejected_before = (h, err) if math.isfinite(err) else None
                    h *= factor
                self.h_next = h
                if h < c.h_min:
                    raise SolverError(f"step size {h:.3g} s below h_min {c.h_min:.3g} s (error norm {err:.3g})", t)
            if steps > c.max_steps:
                raise SolverError(f"more than {c.max_steps} steps in one advance", t)
        return y, f[n:]

    def snapshot(self) -> tuple:
        """Cheap in-memory copy of the state (arrays are replaced, never mutated, so references suffice)."""
        return (self.h_next, self.accepted, self.rejected, self.jacobians, self._age, self._hd, self._dq, self._dv,
                self._winv, self._winv_v, self._w_basis, self._previous)

    def restore(self, snap: tuple) -> None:
        """Undo to a :meth:`snapshot`."""
        (self.h_next, self.accepted, self.rejected, self.jacobians, self._age, self._hd, self._dq, self._dv,
         self._winv, self._winv_v, self._w_basis, self._previous) = snap

    # ------------------------------------------------------------------- state
    def get_state(self) -> dict:
        """Complete integrator state (JSON-serialisable, exact float round trip)."""
        return {
            "h_next": self.h_next,
            "accepted": self.accepted,
            "rejected": self.rejected,
            "jacobians": self.jacobians,
            "age": self._age,
            "hd": self._hd,
            "dq": self._dq.ravel().tolist(),
            "dv": self._dv.ravel().tolist(),
            "winv": self._winv.ravel().tolist(),
        }

    def set_state(self, state: dict) -> None:
        """Restore a state from :meth:`get_state`."""
        n = self.n
        self.h_next = float(state["h_next"])
        self.accepted = int(state["accepted"])
        self.rejected = int(state["rejected"])
        self.jacobians = int(state["jacobians"])
        self._age = int(state["age"])
        self._hd = float(state["hd"])
        self._dq = np.array(state["dq"], dtype=float).reshape(n, n)
        self._dv = np.array(state["dv"], dtype=float).reshape(n, n)
        self._winv = np.array(state["winv"], dtype=float).reshape(2 * n, 2 * n)
        self._winv_v = np.ascontiguousarray(self._winv[:, n:])
        self._w_basis = None  # re-formed from the restored factorisation and basis on first use
        self._previous = None  # formed again when needed (the same matrix)

    def reset(self) -> None:
        """Forget the step size and the Jacobian (e.g. after re-initialisation)."""
        self.h_next = 0.0
        self._age = -1
        self._hd = -1.0
        self._previous = None

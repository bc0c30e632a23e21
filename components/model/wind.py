"""Stochastic rotor-speed process ("wind"), eq. 13-14.

    omega(t) = omega0 + sum_k W_k cos(f_k t + phi_k),   S(f) = a exp(-a f / sigma^2)

``f`` is an angular frequency [rad/s] (the paper writes ``cos(f_k t)``), the
phases ``phi_k`` are drawn uniformly on [0, 2 pi) from a seeded generator, and
the frequencies are the midpoints of ``n_harmonics`` equal bins of
``[f_min, f_max]``. Once the phases are drawn the signal is a closed-form
function of t, so speed, angle and acceleration are exact at any time.

Amplitude conventions
---------------------
``"variance"`` (default): ``W_k = sqrt(2 S(f_k) df)``, the standard spectral
representation; the fluctuation has variance ``sum S df ~= sigma^2``.

``"paper"``: ``W_k = S(f_k) df`` evaluated literally in the paper's rpm-based
units and converted to rad/s afterwards. The formula is not dimensionally
consistent; with the paper's parameters it makes the speed fluctuation about
0.001 rpm and the contact-force std about 400 times smaller than Table 7.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from .. import units
from ..errors import ParameterError
from . import kernel as model_kernel
from ..validation import (
    finite,
    integer_at_least,
    non_negative,
    one_of,
    positive,
    set_fields,
)

AMPLITUDE_CONVENTIONS = ("variance", "paper")
#: most harmonics a rotor-speed process may have (each evaluation sums all of them; the paper's use 256)
MAX_HARMONICS = 100_000


@dataclass(frozen=True)
class WindParameters:
    """Parameters of the rotor-speed process, SI units.

    Parameters
    ----------
    mean_speed_rad_s : float
        omega0 [rad/s] (paper: 16 rpm).
    spectrum_level : float
        a [(rad/s)^2 / (rad/s)]: spectral density at f = 0 (paper: 0.02 in rpm units).
    sigma_rad_s : float
        Fluctuation intensity sigma [rad/s] (paper: 0.12 rpm).
    n_harmonics : int
        Number of harmonics N (1 to :data:`MAX_HARMONICS`).
    f_min_rad_s, f_max_rad_s : float
        Frequency range [rad/s] of the harmonics.
    seed : int
        Seed of the phase generator (numpy ``default_rng``), 0 to 2147483647: an FMI
        Integer is 32 bits, so a larger seed could not reach the FMU; 2^31 seeds give as
        many independent phase sets as any study needs.
    amplitude : {"variance", "paper"}
        Amplitude convention, see module docstring.
    """

    mean_speed_rad_s: float = units.rpm(16.0)
    spectrum_level: float = 0.02 * units.RPM_TO_RAD_PER_S * units.RPM_TO_RAD_PER_S
    sigma_rad_s: float = units.rpm(0.12)
    n_harmonics: int = 256
    f_min_rad_s: float = 0.0
    f_max_rad_s: float = 2.0 * np.pi
    seed: int = 1
    amplitude: str = "variance"

    def __post_init__(self) -> None:
        set_fields(
            self,
            mean_speed_rad_s=finite("wind.omega0", self.mean_speed_rad_s),
            spectrum_level=non_negative("wind.a", self.spectrum_level),
            sigma_rad_s=positive("wind.sigma", self.sigma_rad_s),
            n_harmonics=integer_at_least("wind.n_harmonics", self.n_harmonics, 1, MAX_HARMONICS),
            f_min_rad_s=non_negative("wind.f_min", self.f_min_rad_s),
            f_max_rad_s=positive("wind.f_max", self.f_max_rad_s),
            seed=integer_at_least("wind.seed", self.seed, 0),
            amplitude=one_of("wind.amplitude", self.amplitude, AMPLITUDE_CONVENTIONS),
        )
        if not self.f_max_rad_s > self.f_min_rad_s:
            raise ParameterError("wind.f_max", self.f_max_rad_s, f"> f_min = {self.f_min_rad_s:g} rad/s")

    @classmethod
    def from_paper(
        cls,
        omega0_rpm: float = 16.0,
        a: float = 0.02,
        sigma_rpm: float = 0.12,
        **kwargs,
    ) -> "WindParameters":
        """Build from the paper's rpm-based values (Sec. 4.2: 16 rpm, 0.02, 0.12)."""
        c = units.RPM_TO_RAD_PER_S
        return cls(
            mean_speed_rad_s=units.rpm(finite("wind.omega0", omega0_rpm)),
            spectrum_level=non_negative("wind.a", a) * c * c,
            sigma_rad_s=units.rpm(positive("wind.sigma", sigma_rpm)),
            **kwargs,
        )

    @property
    def decay_s_per_rad(self) -> float:
        """Spectral slope a / sigma^2 [s/rad] (eq. 14); unit-invariant."""
        return self.spectrum_level / self.sigma_rad_s**2


class RotorSpeedProcess:
    """Closed-form realisation of the rotor-speed process.

    Parameters
    ----------
    params : WindParameters
        Process parameters; the phases are drawn once, here.

    Attributes
    ----------
    frequencies_rad_s : ndarray, shape (N,)
    amplitudes_rad_s : ndarray, shape (N,)
    phases_rad : ndarray, shape (N,)
    """

    def __init__(self, params: WindParameters) -> None:
        if not isinstance(params, WindParameters):
            raise ParameterError("wind", params, "a WindParameters")
        self.params = params
        n = params.n_harmonics
        df = (params.f_max_rad_s - params.f_min_rad_s) / n
        f = params.f_min_rad_s + (np.arange(n) + 0.5) * df
        spectrum = params.spectrum_level * np.exp(-params.decay_s_per_rad * f)  # eq. 14
        if params.amplitude == "variance":
            w = np.sqrt(2.0 * spectrum * df)
        else:  # paper-literal W_k = S(f_k) df in rpm units (eq. 13), then to rad/s
            c = units.RPM_TO_RAD_PER_S
            w = (spectrum / c**2) * df * c
        rng = np.random.default_rng(params.seed)
        self.frequencies_rad_s = f
        self.amplitudes_rad_s = w
        self.phases_rad = rng.uniform(0.0, 2.0 * np.pi, n)
        self._w_over_f = w / f
        self._w_times_f = w * f
        self._w_times_f2 = w * f * f
        self._angle_offset = float(np.sum(self._w_over_f * np.sin(self.phases_rad)))

    @property
    def mean_speed_rad_s(self) -> float:
        """omega0 [rad/s]."""
        return self.params.mean_speed_rad_s

    def _phase(self, t: np.ndarray) -> np.ndarray:
        return np.multiply.outer(t, self.frequencies_rad_s) + self.phases_rad

    def speed_and_angle(self, t: float) -> tuple[float, float]:
        """Speed [rad/s] and angle [rad] at one time ``t`` [s], in one pass over the harmonics."""
        ph = self.frequencies_rad_s * t + self.phases_rad
        w0 = self.params.mean_speed_rad_s
        return (
            float(w0 + np.cos(ph) @ self.amplitudes_rad_s),
            float(w0 * t + (np.sin(ph) @ self._w_over_f - self._angle_offset)),  # same association as angle()
        )

    def motion(self, t: float) -> tuple[float, float, float]:
        """Angle [rad], speed [rad/s] and acceleration [rad/s^2] at one time ``t`` [s], in one pass.

        Bit-identical to :meth:`angle`, :meth:`speed` and :meth:`acceleration` called one by one
        (same operations), at the cost of one evaluation of the phases, cosines and sines.
        """
        ph = self.frequencies_rad_s * t + self.phases_rad
        sin = np.sin(ph)
        w0 = self.params.mean_speed_rad_s
        return (
            float(w0 * t + (sin @ self._w_over_f - self._angle_offset)),
            float(w0 + np.cos(ph) @ self.amplitudes_rad_s),
            float(0.0 + -(sin @ self._w_times_f)),
        )

    def speed(self, t: float | np.ndarray) -> float | np.ndarray:
        """Rotor speed omega(t) [rad/s] (eq. 13); ``t`` scalar or array [s]."""
        return self._evaluate(t, lambda ph: np.cos(ph) @ self.amplitudes_rad_s, self.params.mean_speed_rad_s)

    def angle(self, t: float | np.ndarray) -> float | np.ndarray:
        """Rotor angle phi(t) = integral of omega from 0 [rad]."""
        base = self.params.mean_speed_rad_s * np.asarray(t, dtype=float)
        return self._evaluate(t, lambda ph: np.sin(ph) @ self._w_over_f - self._angle_offset, base)

    def acceleration(self, t: float | np.ndarray) -> float | np.ndarray:
        """Rotor acceleration d omega / dt [rad/s^2]."""
        return self._evaluate(t, lambda ph: -(np.sin(ph) @ self._w_times_f), 0.0)

    def jerk(self, t: float | np.ndarray) -> float | np.ndarray:
        """Rotor jerk d^2 omega / dt^2 [rad/s^3]."""
        return self._evaluate(t, lambda ph: -(np.cos(ph) @ self._w_times_f2), 0.0)

    def kinematics(self, t: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Angle [rad], speed [rad/s] and acceleration [rad/s^2] at many times.

        The frequencies are equally spaced, ``f_k = f_0 + k df``, so
        ``sum_k c_k exp(i f_k t) = exp(i f_0 t) sum_k c_k z^k`` with ``z = exp(i df t)``:
        a polynomial in ``z`` evaluated by Horner's rule (stable on the unit circle),
        which costs ``N`` vector multiply-adds instead of ``N x len(t)`` trig calls.

        Parameters
        ----------
        t : ndarray, shape (M,)
            Times [s].

        Returns
        -------
        angle, speed, acceleration : ndarray, shape (M,)
        """
        t = np.asarray(t, dtype=float)
        f = self.frequencies_rad_s
        df = f[1] - f[0] if f.size > 1 else 0.0
        rot = np.exp(1j * self.phases_rad)
        coeffs = np.stack([self.amplitudes_rad_s * rot, self._w_over_f * rot, self._w_times_f * rot])  # (3, N)
        z = np.exp(1j * df * t)
        acc = np.zeros((3, t.size), dtype=complex)
        for k in range(f.size - 1, -1, -1):
            acc *= z
            acc += coeffs[:, k : k + 1]
        acc *= np.exp(1j * f[0] * t)
        speed = self.params.mean_speed_rad_s + acc[0].real
        angle = self.params.mean_speed_rad_s * t + acc[1].imag - self._angle_offset
        acceleration = -acc[2].imag
        return angle, speed, acceleration

    def _evaluate(self, t, series, base):
        ta = np.asarray(t, dtype=float)
        if ta.ndim == 0:
            return float(base + series(self._phase(ta)))
        out = np.empty(ta.shape)
        flat = ta.reshape(-1)
        chunk = max(1, 2_000_000 // self.params.n_harmonics)
        res = out.reshape(-1)
        for i in range(0, flat.size, chunk):
            res[i : i + chunk] = series(self._phase(flat[i : i + chunk]))
        return base + out


class PhasorStepper:
    """The rotor-speed process stepped in time by rotating its harmonics' phasors (no trigonometry per step).

    Holds ``z_k = exp(i (f_k t + phi_k))`` at the current time. A step of ``h`` multiplies
    them by ``exp(i f_k h)`` (formed once per step size), so the speed ``omega0 + Re(z) . W``
    and the angle ``omega0 t + Im(z) . W / f - const`` cost a complex multiply and two dot
    products instead of 2 x N cosines and sines. Every :data:`REANCHOR_STEPS` steps, and
    whenever a step does not start where the last one ended, the phasors are recomputed in
    closed form, so round-off cannot accumulate (measured: |difference| to the closed form
    below 1e-13 rad/s over 600 s at H = 1 ms). The complete state is :meth:`get_state`; a
    restored state continues bit-identically. The rotation and the sums are the wind kernel's
    (:mod:`components.model.kernel.wind`): one compiled loop (~0.6 us for 256 harmonics) or numpy
    (~2.5 us); the loop sums in index order, so the two forms differ in the last bits.

    Parameters
    ----------
    process : RotorSpeedProcess
        The realisation (frequencies, amplitudes, phases).
    kernel : {None, "auto", "numpy", "compiled"}
        The kernel's form (:func:`components.compile.choice.requested_kernel`; None:
        ``$DTCOSIM_KERNEL``, else ``auto``).

    Attributes
    ----------
    kernel : str
        ``"compiled"`` or ``"numpy"``: the path in use.
    kernel_note : str or None
        Why the compiled path was wanted but is not used (numba missing); None otherwise.
    """

    #: steps between two closed-form evaluations of the phasors
    REANCHOR_STEPS = 4096

    def __init__(self, process: RotorSpeedProcess, kernel: str | None = None) -> None:
        self.process = process
        self._kernel, self.kernel, self.kernel_note = model_kernel.wind(kernel)
        self._w_real = np.ascontiguousarray(process.amplitudes_rad_s, dtype=float)  # the compiled sums'
        self._w_over_f_real = np.ascontiguousarray(process._w_over_f, dtype=float)
        self._w_times_f = np.ascontiguousarray(process._w_times_f, dtype=float)  # the derivatives' weights
        self._w_times_f2 = np.ascontiguousarray(process._w_times_f2, dtype=float)
        self._offset = process._angle_offset
        self._w0 = process.params.mean_speed_rad_s
        self.time_s = 0.0
        self.steps_since_anchor = 0
        self._z = np.ones(process.params.n_harmonics, dtype=complex)
        self._sums = (0.0, 0.0)  # (speed sum, angle sum) at the current time
        self._step_s = math.nan
        self._rotation = self._z
        self.reset(0.0)

    def reset(self, t: float) -> None:
        """Phasors in closed form at time ``t`` [s]."""
        self.time_s = float(t)
        self._z = np.exp(1j * (self.process.frequencies_rad_s * self.time_s + self.process.phases_rad))
        self.steps_since_anchor = 0
        self._form_sums()

    def _form_sums(self) -> None:
        """The sums of phasors the stepper did not rotate itself (the same summation as a step's)."""
        self._sums = self._kernel.phasor_sums(self._z, self._w_real, self._w_over_f_real)

    def advance(self, t: float, h: float) -> None:
        """Move the phasors from ``t`` to ``t + h`` [s] (closed form if ``t`` is not where they are)."""
        t1 = t + h
        steps = self.steps_since_anchor + 1
        # a master computing t = n h instead of summing may differ from time_s in the last bits: same point
        if abs(t - self.time_s) > 1e-12 * (t if t > 1.0 else -t if t < -1.0 else 1.0) or steps >= self.REANCHOR_STEPS:
            self.reset(t1)
            return
        if h != self._step_s:
            self._rotation = np.exp(1j * (self.process.frequencies_rad_s * h))
            self._step_s = h
        self._sums = self._kernel.rotate_and_sum(self._z, self._rotation, self._w_real, self._w_over_f_real)
        self.time_s = t1
        self.steps_since_anchor = steps

    def speed_and_angle(self) -> tuple[float, float]:
        """Speed [rad/s] and angle [rad] at the current time (from the sums the last step formed)."""
        speed_sum, angle_sum = self._sums
        return (self._w0 + speed_sum, self._w0 * self.time_s + (angle_sum - self._offset))

    def acceleration_and_jerk(self) -> tuple[float, float]:
        """Acceleration [rad/s^2] and jerk [rad/s^3] at the current time, ``-Im(z) . W f`` and ``-Re(z) . W f^2``.

        Two more sums over the phasors, formed when called (:mod:`components.model.kernel.wind`).
        """
        alpha_sum, jerk_sum = self._kernel.derivative_sums(self._z, self._w_times_f, self._w_times_f2)
        return -alpha_sum, -jerk_sum

    def get_state(self) -> dict:
        """Complete state (JSON-serialisable, exact float round trip)."""
        return {"time": self.time_s, "steps_since_anchor": self.steps_since_anchor,
                "re": self._z.real.tolist(), "im": self._z.imag.tolist()}

    def set_state(self, state: dict) -> None:
        """Restore :meth:`get_state`."""
        re = np.asarray(state["re"], dtype=float)
        im = np.asarray(state["im"], dtype=float)
        if re.shape != self._z.shape or im.shape != self._z.shape:
            raise ParameterError("state.phasors", re.shape, f"{self._z.shape[0]} harmonics")
        self._z = re + 1j * im
        self.time_s = float(state["time"])
        self.steps_since_anchor = int(state["steps_since_anchor"])
        self._form_sums()


@dataclass(frozen=True)
class ConstantSpeed:
    """Constant kinematic speed driver.

    Parameters
    ----------
    speed_rad_s : float
        Speed [rad/s].
    """

    speed_rad_s: float

    def __post_init__(self) -> None:
        set_fields(self, speed_rad_s=finite("driver.speed_rad_s", self.speed_rad_s))

    def speed(self, t):
        """Speed [rad/s]."""
        return self.speed_rad_s + 0.0 * np.asarray(t, dtype=float) if np.ndim(t) else self.speed_rad_s

    def angle(self, t):
        """Angle [rad], zero at t = 0."""
        return self.speed_rad_s * (np.asarray(t, dtype=float) if np.ndim(t) else float(t))

    def acceleration(self, t):
        """Acceleration [rad/s^2] (zero)."""
        return 0.0 * np.asarray(t, dtype=float) if np.ndim(t) else 0.0

    def motion(self, t: float) -> tuple[float, float, float]:
        """Angle [rad], speed [rad/s] and acceleration [rad/s^2] at one time [s]."""
        return float(self.angle(t)), float(self.speed(t)), float(self.acceleration(t))


@dataclass(frozen=True)
class SineSpeed:
    """Sinusoidal kinematic speed driver ``omega = amplitude sin(frequency t)`` (Fig. 10-11).

    Parameters
    ----------
    amplitude_rad_s : float
        Speed amplitude [rad/s].
    frequency_rad_s : float
        Angular frequency [rad/s].
    """

    amplitude_rad_s: float
    frequency_rad_s: float

    def __post_init__(self) -> None:
        set_fields(
            self,
            amplitude_rad_s=finite("driver.amplitude_rad_s", self.amplitude_rad_s),
            frequency_rad_s=positive("driver.frequency_rad_s", self.frequency_rad_s),
        )

    def speed(self, t):
        """Speed [rad/s]."""
        return self.amplitude_rad_s * np.sin(self.frequency_rad_s * np.asarray(t, dtype=float))

    def angle(self, t):
        """Angle [rad], zero at t = 0."""
        w = self.frequency_rad_s
        return self.amplitude_rad_s / w * (1.0 - np.cos(w * np.asarray(t, dtype=float)))

    def acceleration(self, t):
        """Acceleration [rad/s^2]."""
        w = self.frequency_rad_s
        return self.amplitude_rad_s * w * np.cos(w * np.asarray(t, dtype=float))

    def motion(self, t: float) -> tuple[float, float, float]:
        """Angle [rad], speed [rad/s] and acceleration [rad/s^2] at one time [s]."""
        return float(self.angle(t)), float(self.speed(t)), float(self.acceleration(t))

"""Generator rotor: an inertia with a counter torque (Table 6, Sec. 4.2).

The counter torque is a piecewise-constant schedule: a base torque (Table 6:
2.54e7 N mm = 25.4 kN m, a 4 MW generator at 1500 rpm) modified by load
events (torque step, grid fault, emergency stop). Piecewise-constant torque
lets the rotor be integrated exactly over any step.

Sign conventions: generator speed positive in normal operation; the shaft
torque drives the rotor; a positive counter torque brakes it.
"""

from __future__ import annotations

import bisect
from dataclasses import dataclass, field

import numpy as np

from .. import units
from ..errors import ParameterError
from ..validation import finite, non_negative, one_of, positive, set_fields

EVENT_KINDS = ("torque_step", "grid_fault", "emergency_stop")
#: the generator's body in a drivetrain's assembly, and so in its linear and modal models
GENERATOR_BODY = "generator"


@dataclass(frozen=True)
class LoadEvent:
    """A change of the generator counter torque.

    Parameters
    ----------
    kind : {"torque_step", "grid_fault", "emergency_stop"}
        ``torque_step``: from ``start_s`` on (for ``duration_s``, default forever) the
        torque is ``factor`` x base torque. ``grid_fault``: the torque drops to zero
        for ``duration_s``, then returns. ``emergency_stop``: the torque is reversed,
        ``-factor`` x base torque, for ``duration_s``.
    start_s : float
        Event start [s].
    duration_s : float
        Event duration [s] (``inf`` allowed for a permanent step).
    factor : float
        Torque multiplier [-] (see ``kind``).
    """

    kind: str
    start_s: float
    duration_s: float = float("inf")
    factor: float = 1.0

    def __post_init__(self) -> None:
        set_fields(
            self,
            kind=one_of("event.kind", self.kind, EVENT_KINDS),
            start_s=non_negative("event.start_s", self.start_s),
            factor=finite("event.factor", self.factor),
        )
        d = float(self.duration_s)
        if not (d > 0.0):
            raise ParameterError("event.duration_s", self.duration_s, "> 0")
        if self.kind != "torque_step" and not np.isfinite(d):
            raise ParameterError("event.duration_s", self.duration_s, f"a finite duration for a {self.kind}")
        set_fields(self, duration_s=d)

    @property
    def end_s(self) -> float:
        """Event end [s]."""
        return self.start_s + self.duration_s

    def torque(self, base_torque_nm: float) -> float:
        """Counter torque [N m] while the event is active."""
        if self.kind == "grid_fault":
            return 0.0
        if self.kind == "emergency_stop":
            return -abs(self.factor) * base_torque_nm
        return self.factor * base_torque_nm


@dataclass(frozen=True)
class GeneratorParameters:
    """Generator rotor parameters, SI units.

    Parameters
    ----------
    inertia_kgm2 : float
        Rotor inertia [kg m^2] (Table 6: 1.51e8 kg mm^2 = 151 kg m^2).
    counter_torque_nm : float
        Base counter torque [N m] (Sec. 4.2: 2.54e7 N mm = 25.4 kN m).
    events : tuple of LoadEvent
        Load events, applied in the order given (a later event overrides an
        earlier one where they overlap).
    """

    inertia_kgm2: float = units.kgmm2(1.51e8)
    counter_torque_nm: float = units.nmm(2.54e7)
    events: tuple[LoadEvent, ...] = field(default_factory=tuple)

    def __post_init__(self) -> None:
        set_fields(
            self,
            inertia_kgm2=positive("generator.inertia_kgm2", self.inertia_kgm2),
            counter_torque_nm=finite("generator.counter_torque_nm", self.counter_torque_nm),
            events=tuple(self.events),
        )
        for i, ev in enumerate(self.events):
            if not isinstance(ev, LoadEvent):
                raise ParameterError(f"generator.events[{i}]", ev, "a LoadEvent")

    def schedule(self) -> "TorqueSchedule":
        """The piecewise-constant counter-torque schedule."""
        return TorqueSchedule.from_events(self.counter_torque_nm, self.events)


class TorqueSchedule:
    """Piecewise-constant torque ``T(t)``: value ``values[i]`` on ``[breaks[i], breaks[i+1])``.

    Parameters
    ----------
    breaks : array_like, shape (n + 1,)
        Increasing break times [s]; ``breaks[0] = -inf``, ``breaks[-1] = +inf``.
    values : array_like, shape (n,)
        Torque on each interval [N m].
    """

    def __init__(self, breaks, values) -> None:
        self.breaks = np.asarray(breaks, dtype=float)
        self.values = np.asarray(values, dtype=float)
        self._break_list = self.breaks.tolist()
        self._value_list = self.values.tolist()

    @classmethod
    def from_events(cls, base_torque_nm: float, events: tuple[LoadEvent, ...] = ()) -> "TorqueSchedule":
        """Build from a base torque [N m] and load events."""
        pts = sorted({t for ev in events for t in (ev.start_s, ev.end_s) if np.isfinite(t)})
        breaks = np.array([-np.inf, *pts, np.inf])
        mids = [(a + b) / 2 if np.isfinite(a) and np.isfinite(b) else (b - 1.0 if np.isfinite(b) else a + 1.0)
                for a, b in zip(breaks[:-1], breaks[1:])]
        values = []
        for m in mids:
            v = base_torque_nm
            for ev in events:
                if ev.start_s <= m < ev.end_s:
                    v = ev.torque(base_torque_nm)
            values.append(v)
        return cls(breaks, values)

    @property
    def event_times(self) -> np.ndarray:
        """Finite break times [s] (where the torque may jump)."""
        return self.breaks[1:-1]

    def __call__(self, t: float | np.ndarray) -> float | np.ndarray:
        """Torque [N m] at time(s) ``t`` [s] (right-continuous)."""
        if isinstance(t, float):  # scalar fast path (called every communication step)
            i = bisect.bisect_right(self._break_list, t) - 1
            return self._value_list[min(max(i, 0), len(self._value_list) - 1)]
        idx = np.searchsorted(self.breaks, t, side="right") - 1
        out = self.values[np.clip(idx, 0, self.values.size - 1)]
        return float(out) if np.ndim(out) == 0 else out

    def integrals(self, t0: float, t1: float) -> tuple[float, float]:
        """``(int_t0^t1 T dt, int_t0^t1 (t1 - s) T(s) ds)`` [N m s, N m s^2], exact."""
        if len(self._value_list) == 1:  # no events (every communication step: plain floats)
            h = t1 - t0
            v = self._value_list[0]
            return v * h, 0.5 * v * h * h
        impulse = 0.0
        moment = 0.0
        for a, b, v in zip(self.breaks[:-1], self.breaks[1:], self.values):
            lo, hi = max(a, t0), min(b, t1)
            if hi > lo:
                impulse += v * (hi - lo)
                moment += v * 0.5 * ((t1 - lo) ** 2 - (t1 - hi) ** 2)
        return impulse, moment


class ShaftTorquePrediction:
    """The mean shaft torque over the coming communication step, extrapolated from the step means received.

    A host that steps every component from its partners' values at the last communication point
    (Jacobi: libcosim, ecos) gives the generator at ``t_n`` the gearbox's shaft torque averaged over the
    step before, ``[t_n-1, t_n]``: held over ``[t_n, t_n+1]`` it lags one step, and the generator speed
    with it (first order in ``h``). Each mean is the torque at its step's midpoint up to ``h^2 T'' / 24``;
    the mean over the coming step is the polynomial through the last three (midpoint, mean) pairs at
    ``t_n + h / 2``: ``3 T_n - 3 T_n-1 + T_n-2`` at a constant step, exact for a torque quadratic in time.
    The first torque received (the gearbox's at the start time) counts as the value at ``t_0``; until
    three are known the polynomial is of lower degree (held, then linear).
    """

    def __init__(self) -> None:
        self.points: list[tuple[float, float]] = []  # (time the mean stands for [s], mean [N m]), at most 3
        self.last_time: float | None = None

    def predict(self, t: float, h: float, mean_nm: float) -> float:
        """The mean torque over ``[t, t + h]`` [N m], given the mean ``mean_nm`` over the step that ended at ``t``."""
        at = t if self.last_time is None else 0.5 * (self.last_time + t)
        self.points = (self.points + [(at, float(mean_nm))])[-3:]
        self.last_time = t
        target = t + 0.5 * h
        out = 0.0
        for i, (ti, vi) in enumerate(self.points):
            weight = 1.0
            for j, (tj, _) in enumerate(self.points):
                if j != i:
                    weight *= (target - tj) / (ti - tj)
            out += weight * vi
        return out

    def get_state(self) -> dict:
        return {"points": [list(p) for p in self.points], "last_time": self.last_time}

    def set_state(self, state: dict) -> None:
        self.points = [(float(a), float(b)) for a, b in state["points"]]
        self.last_time = None if state["last_time"] is None else float(state["last_time"])


class GeneratorRotor:
    """The generator rotor as a stepping component (exact for a held shaft torque).

    Parameters
    ----------
    params : GeneratorParameters
        Inertia and counter-torque schedule.
    initial_speed_rad_s : float
        Initial speed [rad/s].
    initial_angle_rad : float
        Initial angle [rad].
    """

    def __init__(self, params: GeneratorParameters, initial_speed_rad_s: float = 0.0, initial_angle_rad: float = 0.0):
        if not isinstance(params, GeneratorParameters):
            raise ParameterError("generator", params, "a GeneratorParameters")
        self.params = params
        self.schedule = params.schedule()
        self.speed_rad_s = finite("generator.initial_speed", initial_speed_rad_s)
        self.angle_rad = finite("generator.initial_angle", initial_angle_rad)

    def counter_torque(self, t: float) -> float:
        """Counter torque at time ``t`` [N m]."""
        return self.schedule(t)

    def step(self, t: float, h: float, shaft_torque_nm: float, counter_torque_nm: float | None = None,
             brake_torque_nm: float = 0.0) -> None:
        """Advance from ``t`` to ``t + h`` [s] with the shaft torque [N m] held.

        ``I omega_dot = T_shaft - T_gen(t) - T_brake sign(omega)``, integrated exactly. ``T_gen`` is the
        schedule (base torque and events) unless ``counter_torque_nm`` is given (a torque input, e.g. a
        controller's demand, held over the step). The high-speed-shaft brake ``|brake_torque_nm|`` acts
        against the speed like dry friction: where it would reverse the rotor within the step, the rotor
        stops there and stays at rest while the brake can hold the other torques.
        """
        inv_i = 1.0 / self.params.inertia_kgm2
        if counter_torque_nm is None:
            impulse, moment = self.schedule.integrals(t, t + h)
        else:
            impulse, moment = counter_torque_nm * h, 0.5 * counter_torque_nm * h * h
        brake = abs(brake_torque_nm)
        if brake > 0.0:
            drive = shaft_torque_nm - impulse / h  # mean of the other torques over the step
            w = self.speed_rad_s
            if w == 0.0 and abs(drive) <= brake:
                return  # held at rest
            sign = (1.0 if w > 0.0 else -1.0) if w != 0.0 else (1.0 if drive > 0.0 else -1.0)
            acc = (drive - sign * brake) * inv_i
            if w != 0.0 and acc * w < 0.0 and -w / acc < h:  # comes to rest inside the step
                tau = -w / acc
                self.angle_rad += w * tau + 0.5 * acc * tau * tau
                self.speed_rad_s = 0.0
                if abs(drive) > brake:  # the brake slips again at once
                    self.step(t + tau, h - tau, shaft_torque_nm, counter_torque_nm if counter_torque_nm is not None
                              else impulse / h, brake_torque_nm)
                return
            self.angle_rad += w * h + 0.5 * acc * h * h
            self.speed_rad_s += acc * h
            return
        self.angle_rad += self.speed_rad_s * h + (0.5 * shaft_torque_nm * h * h - moment) * inv_i
        self.speed_rad_s += (shaft_torque_nm * h - impulse) * inv_i

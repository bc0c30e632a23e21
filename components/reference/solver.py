"""Monolithic reference solver: driver + gearbox + output as one stiff ODE.

The state is ``y = [q, v, W_in, W_out, E_diss]``: deviation angles and speeds
of every free body (see :mod:`components.model.assembly`) plus three quadrature
states (rotor work, output work, dissipated energy) for the energy audit.
The ODE is integrated by LSODA (``scipy.integrate.odeint``, stiff BDF with the
analytic Jacobian) segment by segment between load-event times, so the
piecewise-constant counter torque never jumps inside a segment.

The result holds every contact force, deflection, shaft torque, body speed,
the rotor torque and the output acceleration at the requested output times.
"""

from __future__ import annotations

import math
import time
from dataclasses import dataclass
from typing import Protocol

import numpy as np
from scipy.integrate import odeint

from ..errors import ParameterError, SolverError, WallTimeLimitError
from ..model import kernel as model_kernel
from ..model.assembly import Assembly
from ..model.drivetrain import Drivetrain
from ..model.gearbox_model import STARTS
from ..model.signals import (
    GENERATOR_ANGLE,
    GENERATOR_SPEED,
    GENERATOR_TORQUE,
    OUTPUT_SPEED,
    ROTOR_ANGLE,
    ROTOR_SPEED,
    ROTOR_TORQUE,
    Signal,
    deflection_name,
    deflection_signal,
    gearbox_signals,
)
from ..validation import finite, non_negative, one_of, positive
from .results import EnergyAudit, SimulationResult


class SpeedDriver(Protocol):
    """A kinematic speed driver: closed-form speed, angle and acceleration of time."""

    def speed(self, t): ...

    def angle(self, t): ...

    def acceleration(self, t): ...


@dataclass(frozen=True)
class SolverSettings:
    """Tolerances of the monolithic solver.

    Parameters
    ----------
    rtol : float
        Relative tolerance.
    atol_angle_rad : float
        Absolute tolerance on deviation angles [rad].
    atol_speed_rad_s : float
        Absolute tolerance on deviation speeds [rad/s].
    max_step_s : float
        Largest internal step [s] (0: unlimited). With time-varying mesh stiffness the
        solver caps the step at half a stiffness transition anyway
        (:func:`components.model.mesh_stiffness.max_step_s`).
    max_steps : int
        Maximum internal steps between two output times.
    wall_time_limit_s : float
        Wall-clock time [s] one integration may take (0: unlimited); past it the
        right-hand side raises :class:`~components.errors.WallTimeLimitError`.
    """

    rtol: float = 1e-7
    atol_angle_rad: float = 1e-10
    atol_speed_rad_s: float = 1e-7
    max_step_s: float = 0.0
    max_steps: int = 200_000
    wall_time_limit_s: float = 0.0

    def __post_init__(self) -> None:
        positive("rtol", self.rtol)
        positive("atol_angle_rad", self.atol_angle_rad)
        positive("atol_speed_rad_s", self.atol_speed_rad_s)
        non_negative("wall_time_limit_s", self.wall_time_limit_s)


class MonolithicSystem:
    """Right-hand side and Jacobian of the monolithic ODE.

    The right-hand side evaluates the driver once per call (its ``motion(t)`` where it
    has one: angle, speed and acceleration from one set of phases) and the contact forces
    without their derivatives; the Jacobian evaluates the derivatives. Both are the kernel's
    :func:`components.model.kernel.monolithic.monolithic_rhs` / ``monolithic_jacobian`` (the
    co-simulation gearbox's equations), compiled by numba or interpreted.

    Parameters
    ----------
    drivetrain : Drivetrain
        Gearbox (and generator, if any).
    driver : SpeedDriver
        Kinematic rotor-speed driver of the first stage's input member.
    kernel : {"auto", "numpy", "compiled"}, optional
        Implementation (default ``$DTCOSIM_KERNEL``, else ``auto``).
    """

    def __init__(self, drivetrain: Drivetrain, driver: SpeedDriver, kernel: str | None = None) -> None:
        self.assembly = Assembly(drivetrain)
        self.driver = driver
        self.schedule = drivetrain.load_schedule()
        self.load_torque_nm = float(self.schedule(0.0))
        a = self.assembly
        self.n = a.n_dof
        self._out = a.output_dof
        self._kappa_out = float(a.kinematic_ratio[self._out])
        self._jac = np.zeros((2 * self.n + 3, 2 * self.n + 3))
        self._jac[: self.n, self.n : 2 * self.n] = np.eye(self.n)
        self.rhs_calls = 0
        self.jac_calls = 0
        self.deadline = math.inf  # time.perf_counter() value past which rhs raises (see start_clock)
        self.wall_time_limit_s = 0.0
        self._motion = getattr(driver, "motion", None)
        #: the driver angle sets the mesh stiffness or the direction of gravity
        self._needs_angle = a.time_varying_stiffness or a.load_rates.size > 0
        # the monolithic right-hand side is not compiled ahead of time: numba's just-in-time kernel, or interpreted
        self._module, self.kernel, self.kernel_note = model_kernel.monolithic(kernel)
        self._rhs_args, self._jac_args = self._kernel_arrays()

    def _kernel_arrays(self) -> tuple[tuple, tuple]:
        """The constant and work arrays of the kernel's right-hand side and Jacobian (after ``y`` and the factors)."""
        a = self.assembly
        n, m = a.n_dof, a.n_mesh
        c = np.ascontiguousarray
        self._ones = np.ones(m)
        self._rhs_out = np.zeros(2 * n + 3)
        rhs_args = (
            self._out, self._kappa_out, float(a.driver_inertia_kgm2), a.nz_index, a.nz_value, np.zeros(m),
            c(a.mesh_offset),
            c(a.fast_matrix), a.law.table, c(a.load_rates), c(a.springs), c(a.springs_k, dtype=float),
            c(a.springs_c, dtype=float), c(a.BT_driver), c(a.springs_driver), c(a.cos_alpha), c(a.inv_inertia),
            np.zeros(m), np.zeros(m), np.zeros((2, m)), np.zeros(m + 2 * n + 4 + a.load_matrix.shape[0]), np.zeros(n),
            self._rhs_out,
        )
        jac_args = (
            np.zeros(m), c(a.mesh_offset), a.law.table, np.zeros((2, m)), a.nz_index, a.nz_value,
            c(a.cos_alpha), c(a.STkS), c(a.STcS), np.zeros(n), np.zeros(n), c(a.inv_inertia), np.zeros(m), np.zeros(m),
            np.zeros((n, n)), np.zeros((n, n)), np.zeros((2, n)), self._jac,
        )
        # compile or load from the disk cache now, not inside the timed integration
        self._module.monolithic_rhs(np.zeros(2 * n + 3), 0.0, 0.0, 0.0, self._ones, 0.0, *rhs_args)
        self._module.monolithic_jacobian(np.zeros(2 * n + 3), self._ones, *jac_args)
        return rhs_args, jac_args

    def start_clock(self, wall_time_limit_s: float) -> None:
        """Let :meth:`rhs` raise :class:`WallTimeLimitError` ``wall_time_limit_s`` [s] from now (0: never)."""
        self.wall_time_limit_s = float(wall_time_limit_s)
        self.deadline = time.perf_counter() + wall_time_limit_s if wall_time_limit_s > 0 else math.inf

    def _driver_state(self, t: float) -> tuple[float, float, float, float | np.ndarray]:
        """Driver angle [rad], speed [rad/s], acceleration [rad/s^2] and the mesh stiffness factors at ``t``."""
        if self._motion is not None:
            angle, omega, alpha = self._motion(t)
        else:
            omega, alpha = float(self.driver.speed(t)), float(self.driver.acceleration(t))
            angle = float(self.driver.angle(t)) if self._needs_angle else 0.0
        kfac = self.assembly.stiffness_factor(angle) if self.assembly.time_varying_stiffness else 1.0
        return angle, omega, alpha, kfac

    def _stiffness_factor(self, t: float) -> np.ndarray | float:
        """Mesh stiffness factors at ``t`` (1.0 without the option; the driver angle only is evaluated)."""
        if not self.assembly.time_varying_stiffness:
            return 1.0
        return self.assembly.stiffness_factor(float(self.driver.angle(t)))

    def rhs(self, t: float, y: np.ndarray) -> np.ndarray:
        """dy/dt at time t [s]."""
        self.rhs_calls += 1
        if time.perf_counter() > self.deadline:
            raise WallTimeLimitError(self.wall_time_limit_s, t)
        angle_in, omega_in, alpha_in, kfac = self._driver_state(t)
        factor = self._ones if type(kfac) is float else np.ascontiguousarray(kfac, dtype=float)
        self._module.monolithic_rhs(np.ascontiguousarray(y, dtype=float), omega_in, alpha_in, angle_in, factor,
                                    self.load_torque_nm, *self._rhs_args)
        return self._rhs_out.copy()

    def jacobian(self, t: float, y: np.ndarray) -> np.ndarray:
        """d(dy/dt)/dy; the quadrature rows are left zero (they do not feed back)."""
        self.jac_calls += 1
        kfac = self._stiffness_factor(t)
        factor = self._ones if type(kfac) is float else np.ascontiguousarray(kfac, dtype=float)
        self._module.monolithic_jacobian(np.ascontiguousarray(y, dtype=float), factor, *self._jac_args)
        return self._jac


def simulate_monolithic(
    drivetrain: Drivetrain,
    driver: SpeedDriver,
    t_end_s: float,
    output_interval_s: float = 1e-3,
    settings: SolverSettings | None = None,
    t_start_s: float = 0.0,
    raise_on_failure: bool = False,
    initial_state: np.ndarray | None = None,
    kernel: str | None = None,
    start: str = "operating_point",
) -> SimulationResult:
    """Integrate the monolithic drivetrain model.

    Initial state: kinematically consistent speeds at the initial driver speed, and by
    default (``start="operating_point"``) the static deflection of the load at the start
    time (:meth:`Assembly.static_deflection`; undeflected without a load), so a constant
    input gives a constant output from the start - as the co-simulation's Gearbox starts.
    ``start="rest"``: zero deflection (teeth centred in the backlash), the load a step at
    the start (the paper's convention). ``initial_state`` starts from any other state.

    Parameters
    ----------
    drivetrain : Drivetrain
        Gearbox, shafts and output (generator or counter torque).
    driver : SpeedDriver
        Kinematic rotor-speed driver (e.g. :class:`~components.model.wind.RotorSpeedProcess`).
    t_end_s : float
        End time [s].
    output_interval_s : float
        Output sampling interval [s].
    settings : SolverSettings, optional
        Tolerances.
    t_start_s : float
        Start time [s].
    raise_on_failure : bool
        Raise :class:`SolverError` instead of returning an incomplete result.
    initial_state : ndarray, shape (2 n_dof,), optional
        ``[q, v]`` at ``t_start_s``: deviation angles [rad] and deviation speeds
        [rad/s] of the free bodies (order of ``Assembly.dof_names``), relative to
        the kinematic motion ``kappa * theta_in``. Default: per ``start``.
    kernel : {"auto", "numpy", "compiled"}, optional
        Implementation of the right-hand side and Jacobian (see :class:`MonolithicSystem`).
    start : {"operating_point", "rest"}
        Where the default initial state is (above).

    Returns
    -------
    SimulationResult
        Samples at ``t_start, t_start + dt, ..., t_end``; ``complete`` False and the
        samples up to the failure if the integrator stopped early. ``info`` holds
        ``rhs_calls``, ``jacobian_calls``, ``steps`` (LSODA's internal steps) and
        ``cpu_time_s`` (process CPU time of the integration alone [s], like
        ``wall_time_s`` without the evaluation of the recorded variables),
        ``total_cpu_time_s`` (integration and evaluation of the recorded variables [s])
        and ``kernel`` (``compiled`` or ``numpy``).
    """
    settings = settings or SolverSettings()
    t0 = finite("t_start_s", t_start_s)
    t1 = finite("t_end_s", t_end_s)
    if not t1 > t0:
        raise ParameterError("t_end_s", t_end_s, f"> t_start_s = {t0:g}")
    dt = positive("output_interval_s", output_interval_s)
    system = MonolithicSystem(drivetrain, driver, kernel)
    n = system.n
    # whole output intervals that fit (never past t_end), then t_end itself if it is not one of them
    n_out = int(math.floor((t1 - t0) / dt + 1e-9))
    t_out = t0 + dt * np.arange(n_out + 1)
    t_out[-1] = min(t_out[-1], t1) if abs(t_out[-1] - t1) < 1e-9 * max(1.0, abs(t1)) else t_out[-1]
    if t_out[-1] < t1 - 1e-12:
        t_out = np.append(t_out, t1)

    atol = np.concatenate(
        [np.full(n, settings.atol_angle_rad), np.full(n, settings.atol_speed_rad_s), np.full(3, 1e-3)]
    )
    y = np.zeros(2 * n + 3)
    one_of("start", start, STARTS)
    if initial_state is not None:
        y0 = np.asarray(initial_state, dtype=float)
        if y0.shape != (2 * n,) or not np.all(np.isfinite(y0)):
            raise ParameterError("initial_state", y0.shape, f"finite [q, v] of shape ({2 * n},)")
        y[: 2 * n] = y0
    elif start == "operating_point" and float(system.schedule(t0)) != 0.0:
        angle0, omega0, _, kfac0 = system._driver_state(t0)
        y[:n] = system.assembly.static_deflection(float(system.schedule(t0)), kfac0, kernel=kernel,
                                                  driver_angle_rad=angle0, driver_speed_rad_s=omega0)[0]
    Y = np.full((t_out.size, y.size), np.nan)
    Y[0] = y
    hmax = settings.max_step_s
    a = system.assembly
    if a.time_varying_stiffness:
        # a step longer than a pair-count zone could skip it unseen: cap at half a transition
        from ..model.mesh_stiffness import max_step_s

        omega_max = float(np.max(np.abs(np.asarray(driver.speed(np.linspace(t0, t1, 2001)), dtype=float))))
        cap = max_step_s(a.mesh_phase_rate, a.mesh_stiffness_variation, 1.05 * omega_max)
        hmax = cap if hmax <= 0.0 else min(hmax, cap)
    breaks = [t for t in system.schedule.event_times if t0 < t < t1]
    edges = [t0, *breaks, t1]
    complete = True
    message = "integration successful"
    reached = 0
    steps = 0
    start = time.perf_counter()
    cpu_start = time.process_time()
    system.start_clock(settings.wall_time_limit_s)
    for a, b in zip(edges[:-1], edges[1:]):
        system.load_torque_nm = float(system.schedule(0.5 * (a + b)))
        inside = np.flatnonzero((t_out > a + 1e-12) & (t_out < b - 1e-12))
        times = np.concatenate([[a], t_out[inside], [b]])
        try:
            sol, info = odeint(
                system.rhs,
                y,
                times,
                Dfun=system.jacobian,
                tfirst=True,
                rtol=settings.rtol,
                atol=atol,
                hmax=hmax,
                mxstep=settings.max_steps,
                full_output=True,
            )
        except WallTimeLimitError as exc:
            # odeint returns nothing when the right-hand side raises: the samples up to
            # the start of this load segment are kept
            complete = False
            message = f"{exc}; samples kept up to t = {float(t_out[reached]):.6g} s"
            if raise_on_failure:
                raise
            break
        ok = info["message"].startswith("Integration successful")
        nst = np.asarray(info.get("nst", [0]))
        steps += int(nst.max()) if nst.size else 0
        if not ok or not np.all(np.isfinite(sol[-1])):
            complete = False
            tcur = np.asarray(info.get("tcur", [a]))
            good = int(np.searchsorted(times, float(np.max(tcur)) if tcur.size else a, side="right"))
            good = max(1, min(good, times.size))
            finite_rows = np.all(np.isfinite(sol[:good]), axis=1)
            good = int(np.argmin(finite_rows)) if not finite_rows.all() else good
            message = f"LSODA failed: {info['message'].strip()}"
            idx = inside[: max(0, good - 1)]
            Y[idx] = sol[1 : 1 + idx.size]
            reached = int(idx[-1]) if idx.size else reached
            stop_time = float(t_out[reached])
            message += f"; stopped at t = {stop_time:.6g} s"
            if raise_on_failure:
                raise SolverError(message, stop_time)
            break
        Y[inside] = sol[1:-1]
        end_idx = np.flatnonzero(np.abs(t_out - b) <= 1e-12)
        if end_idx.size:
            Y[end_idx[0]] = sol[-1]
            reached = int(end_idx[0])
        elif inside.size:
            reached = int(inside[-1])
        y = sol[-1]
    wall = time.perf_counter() - start
    cpu = time.process_time() - cpu_start
    valid = reached + 1 if not complete else t_out.size
    result = _collect(system, t_out[:valid], Y[:valid])
    total_cpu = time.process_time() - cpu_start
    result.complete = complete
    result.message = message
    result.wall_time_s = wall
    result.info = {"rhs_calls": system.rhs_calls, "jacobian_calls": system.jac_calls, "solver": "LSODA",
                   "steps": steps, "cpu_time_s": cpu, "total_cpu_time_s": total_cpu, "kernel": system.kernel}
    return result


def element_series(a: Assembly, force: np.ndarray, speeds: np.ndarray, omega_in: np.ndarray) -> dict[str, np.ndarray]:
    """The bearings' and supports' outputs (the Gearbox FMU's names): components, magnitude and bearing speed.

    ``force``: the bearing rows' forces, shape (N, n_spring); ``speeds``: the free bodies' absolute speeds.
    """
    names = [b.name for b in a.bodies]

    def speed(body: str) -> np.ndarray:
        j = names.index(body)
        free = np.flatnonzero(a.free == j)
        return speeds[:, int(free[0])] if free.size else a.kinematic_ratio_all[j] * omega_in

    out: dict[str, np.ndarray] = {}
    for e in a.elements:
        parts = [force[:, r] for r in e.rows]
        for component, part in zip(e.components, parts):
            out[f"{e.name}.{'torque' if component == 'torque' else 'F_' + component}"] = part
        if e.kind != "torsion":
            out[f"{e.name}.F"] = np.sqrt(sum(p * p for p in parts))
        if e.speed:
            out[f"{e.name}.omega"] = speed(e.speed[0]) - (speed(e.speed[1]) if len(e.speed) > 1 else 0.0)
    return out


def _collect(system: MonolithicSystem, t: np.ndarray, Y: np.ndarray) -> SimulationResult:
    """Evaluate every recorded variable on the sampled states."""
    a = system.assembly
    n = system.n
    q = Y[:, :n]
    v = Y[:, n : 2 * n]
    drv = system.driver
    if hasattr(drv, "kinematics"):
        angle_in, omega_in, alpha_in = drv.kinematics(t)
    else:
        omega_in = np.asarray(drv.speed(t), dtype=float) * np.ones_like(t)
        alpha_in = np.asarray(drv.acceleration(t), dtype=float) * np.ones_like(t)
        angle_in = np.asarray(drv.angle(t), dtype=float) * np.ones_like(t)
    kfac = a.stiffness_factor(angle_in) if a.time_varying_stiffness else 1.0
    loads = a.loads(q, v, stiffness_factor=kfac, derivatives=False)
    load_torque = np.asarray(system.schedule(t), dtype=float) * np.ones_like(t)
    Q = a.generalised_forces(loads) + a.external_forces(angle_in, omega_in)
    Q[:, system._out] -= load_torque
    acc = a.inv_inertia * Q - a.kinematic_ratio * alpha_in[:, None]
    speeds = np.outer(omega_in, a.kinematic_ratio) + v
    # every series is declared where it is made (unit, kind): analyses never read them from the names
    signals = gearbox_signals(a)  # contact forces, shaft torques, body speeds: as the Gearbox FMU declares them
    signals |= {"omega_rotor": Signal("rad/s", "rotor speed driving the gearbox", ROTOR_SPEED),
               "phi_rotor": Signal("rad", "rotor angle", ROTOR_ANGLE)}
    series: dict[str, np.ndarray] = {"omega_rotor": omega_in, "phi_rotor": angle_in}
    for i, name in enumerate(a.mesh_names):
        series[name] = loads.contact_force_n[:, i]
    for i, name in enumerate(a.mesh_names):
        series[deflection_name(name)] = loads.deflection_m[:, i]
        signals[deflection_name(name)] = deflection_signal(name)
    for i, name in enumerate(a.shaft_names):
        series[f"{name}.torque"] = loads.shaft_torque_nm[:, i]
    for i, body in enumerate(a.bodies[j] for j in a.free):
        series[f"{body.name}.omega" if body.rotation else body.name] = speeds[:, i] if body.rotation else q[:, i]
    series.update(element_series(a, loads.bearing_force_n, speeds, omega_in))
    out = system._out
    alpha_out = acc[:, out] + a.kinematic_ratio[out] * alpha_in
    series["torque_rotor"] = a.driver_torque(loads, alpha_in)
    series["load_torque"] = load_torque
    last = a.drivetrain.stages[-1]
    out_member = a.stage_members[last.name]["output"]
    series["omega_out"] = series[f"{out_member}.omega"]
    series["alpha_out"] = (
        alpha_out if a.output_body == out_member else acc[:, a.dof_index(out_member)] + a.kinematic_ratio[a.dof_index(out_member)] * alpha_in
    )
    signals.update(
        torque_rotor=Signal("N.m", "torque the rotor applies to the gearbox", ROTOR_TORQUE),
        load_torque=Signal("N.m", "counter torque on the output", GENERATOR_TORQUE),
        omega_out=Signal("rad/s", f"speed of the output member {out_member}", OUTPUT_SPEED),
        alpha_out=Signal("rad/s2", f"angular acceleration of the output member {out_member}"),
    )
    if a.drivetrain.generator is not None:
        series["omega_gen"] = speeds[:, out]
        series["phi_gen"] = a.kinematic_ratio[out] * angle_in + q[:, out]
        signals.update(omega_gen=Signal("rad/s", "generator speed", GENERATOR_SPEED),
                       phi_gen=Signal("rad", "generator angle", GENERATOR_ANGLE))
    energy = None
    if t.size >= 2:
        ke = a.kinetic_energy(speeds[[0, -1]], omega_in[[0, -1]])
        pe0 = a.potential_energy(a.loads(q[0], v[0]))
        pe1 = a.potential_energy(a.loads(q[-1], v[-1]))
        energy = EnergyAudit(
            input_work_j=float(Y[-1, 2 * n] - Y[0, 2 * n]),
            output_work_j=float(Y[-1, 2 * n + 1] - Y[0, 2 * n + 1]),
            dissipated_j=float(Y[-1, 2 * n + 2] - Y[0, 2 * n + 2]),
            stored_change_j=float(ke[1] - ke[0] + pe1 - pe0),
        )
    return SimulationResult(time_s=t, series=series, energy=energy, signals={n: signals[n] for n in series})

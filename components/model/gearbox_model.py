"""The gearbox side of the co-simulation cut, as a stepping component.

Inputs at each communication point ``t_n``: rotor speed and angle (the
kinematic driver of the stage-1 carrier) and generator speed and angle (the
far end of shaft 3, which stays in the gearbox). Over a step the inputs are
interpreted consistently: speeds are held and angles advance with them,
``phi(t) = phi_n + omega_n (t - t_n)``. The internal state is integrated with
:class:`~components.model.integrators.Rosenbrock23` (linearly implicit, analytic
Jacobian, one-step: no cold start at communication points).

The state is kept in deviation coordinates relative to the rotor angle; when a
new rotor input arrives the deviation is re-referenced so the bodies' absolute
angles and speeds stay continuous (only the kinematically driven carrier
follows the input jump).

Outputs after each step: the shaft-3 torque on the generator (end-of-step
value and step average), every contact force, shaft torque and body speed,
the output speed and the rotor torque.
"""

from __future__ import annotations

import math

import numpy as np

from ..errors import ParameterError, SolverError
from ..validation import finite, one_of
from .assembly import Assembly
from .drivetrain import Drivetrain
from .integrators import Rosenbrock23, StepControl
from .kernel import choose_kernel

SHAFT_TORQUE_MODES = ("average", "end")
#: how the generator end of shaft 3 moves within a communication step (see :class:`GearboxModel`)
GENERATOR_INTERFACES = ("motion", "inertia")


#: the inputs of :meth:`GearboxModel.step`, in order
STEP_INPUTS = ("omega_rotor", "phi_rotor", "omega_gen", "phi_gen", "counter_torque", "alpha_rotor", "jerk_rotor")


def non_finite_input(inputs: tuple[float, ...]) -> str:
    """``"non-finite input (jerk_rotor=inf)"``: the message of a step refused for its inputs (all of them if
    every one is finite and only their combination overflowed)."""
    pairs = [(f"{name}={value!r}", value) for name, value in zip(STEP_INPUTS, inputs)]
    named = [text for text, value in pairs if not math.isfinite(value)] or [text for text, _ in pairs]
    return f"non-finite input ({', '.join(named)})"


class _Hermite:
    """Cubic ``x(tau)`` on [0, h] with given value and slope at both ends."""

    __slots__ = ("c0", "c1", "c2", "c3")

    def __init__(self) -> None:
        self.c0 = self.c1 = self.c2 = self.c3 = 0.0

    def fit(self, h: float, x0: float, dx0: float, x1: float, dx1: float) -> None:
        delta = (x1 - x0) / h
        self.c0 = x0
        self.c1 = dx0
        self.c2 = (3.0 * delta - 2.0 * dx0 - dx1) / h
        self.c3 = (dx0 + dx1 - 2.0 * delta) / (h * h)

    def value(self, tau: float) -> float:
        return self.c0 + tau * (self.c1 + tau * (self.c2 + tau * self.c3))

    def rate(self, tau: float) -> float:
        return self.c1 + tau * (2.0 * self.c2 + 3.0 * tau * self.c3)

    def value_and_rate(self, tau: float) -> tuple[float, float]:
        """``(value(tau), rate(tau))`` in one call (the same expressions)."""
        c2, c3 = self.c2, self.c3
        return self.c0 + tau * (self.c1 + tau * (c2 + tau * c3)), self.c1 + tau * (2.0 * c2 + 3.0 * tau * c3)

    def rate_and_accel(self, tau: float) -> tuple[float, float]:
        """``(rate(tau), accel(tau))`` in one call (the same expressions)."""
        c2, c3 = self.c2, self.c3
        return self.c1 + tau * (2.0 * c2 + 3.0 * tau * c3), 2.0 * c2 + 6.0 * tau * c3

    def accel(self, tau: float) -> float:
        return 2.0 * self.c2 + 6.0 * tau * self.c3

    def jerk(self) -> float:
        return 6.0 * self.c3


class _StepSystem:
    """The gearbox ODE over one communication step (local time tau = t - t_n).

    The driver angle relative to its value at tau = 0 and the generator-port
    deviation angle are cubic Hermite curves over the step. The most recent
    force evaluation is cached: after an accepted step it holds the loads at
    the end state, which give the outputs and the next step's first stage.
    """

    def __init__(self, assembly: Assembly) -> None:
        self.assembly = assembly
        self.driver = _Hermite()  # theta_in(tau) - theta_in(0)
        self.port = _Hermite()  # the port input: q_port(tau) = theta_gen - kappa_gen theta_in, or the counter torque
        self.angle0 = 0.0  # theta_in(0), absolute [rad]
        n = assembly.n_dof
        self.port_jacobian = np.zeros((2, n))  # d a / d q_port, d a / d v_port (from the last Jacobian)
        self.last_acceleration = np.zeros(n)
        self.last_alpha = 0.0  # driver acceleration used in the last evaluation [rad/s^2]
        self.last_force = np.zeros(assembly.n_mesh)
        self.last_deflection = np.zeros((2, assembly.n_mesh))
        self._constant_stiffness = not assembly.time_varying_stiffness

    def stiffness_factor(self, tau: float):
        a = self.assembly
        if not a.time_varying_stiffness:
            return 1.0
        return a.phasing.factor(self.angle0 + self.driver.value(tau))

    def acceleration(self, tau: float, y: np.ndarray) -> np.ndarray:
        alpha = self.driver.accel(tau)
        port_angle, port_speed = self.port.value_and_rate(tau)
        factor = 1.0 if self._constant_stiffness else self.stiffness_factor(tau)
        acc, force, deflection = self.assembly.fast_acceleration(y, port_angle, port_speed, alpha, factor)
        self.last_acceleration, self.last_alpha, self.last_force, self.last_deflection = acc, alpha, force, deflection
        return acc

    def cache(self) -> tuple:
        """The cached last evaluation (for undo)."""
        return (self.last_acceleration, self.last_alpha, self.last_force, self.last_deflection)

    def restore(self, cached: tuple) -> None:
        """Undo to :meth:`cache`."""
        self.last_acceleration, self.last_alpha, self.last_force, self.last_deflection = cached

    def jacobian(self, tau: float, y: np.ndarray):
        a = self.assembly
        n = a.n_dof
        if not a.ports.size:  # the port input is a torque: the accelerations are linear in it, no loads depend on it
            loads = a.loads(y[:n], y[n:], stiffness_factor=self.stiffness_factor(tau))
            dq, dv, _, _ = a.acceleration_jacobian(loads)
            self.port_jacobian = np.zeros((2, n))
            return dq, dv
        qx = np.array([self.port.value(tau)])
        vx = np.array([self.port.rate(tau)])
        loads = a.loads(y[:n], y[n:], qx, vx, self.stiffness_factor(tau))
        dq, dv, dqx, dvx = a.acceleration_jacobian(loads)
        self.port_jacobian = np.stack([dqx[:, 0], dvx[:, 0]])
        return dq, dv

    def time_derivative_basis(self) -> np.ndarray | None:
        """Rows ``[da/dq_port, da/dv_port, -kappa]``: ``da/dt = [port speed, port accel, driver jerk] @ rows``.

        None with time-varying mesh stiffness (then ``da/dt`` is not of this form).
        """
        if self.assembly.time_varying_stiffness:
            return None
        return np.vstack((self.port_jacobian, -self.assembly.kinematic_ratio))

    def time_derivative_coefficients(self, tau: float) -> tuple[float, float, float]:
        """Coefficients of :meth:`time_derivative_basis` at local time ``tau`` [s]."""
        return (*self.port.rate_and_accel(tau), self.driver.jerk())

    def time_derivative(self, tau: float, y: np.ndarray) -> np.ndarray:
        a = self.assembly
        # prescribed motions: port angle/speed and driver jerk
        pj = self.port_jacobian
        da = pj[0] * self.port.rate(tau) + pj[1] * self.port.accel(tau) - a.kinematic_ratio * self.driver.jerk()
        if a.time_varying_stiffness:  # the mesh stiffness varies with the driver angle: df/dt = slope x speed
            factor, slope = a.phasing.factor_and_slope(self.angle0 + self.driver.value(tau))
            da = da + a.stiffness_rate_acceleration(
                y, self.port.value(tau), self.port.rate(tau), factor, slope * self.driver.rate(tau)
            )
        return da


class GearboxModel:
    """Gearbox with shaft 3, cut at the generator, stepped by a co-simulation master.

    Input model
    -----------
    FMI inputs are the rotor and generator speed and angle at the communication
    point ``t_n``. Over ``[t_n, t_n + h]`` the gearbox moves the driver (and the
    generator end of shaft 3) along a cubic Hermite curve that starts at the
    motion it had at the end of the previous step and ends at the target
    extrapolated from the new inputs, ``phi_n + omega_n h + alpha h^2 / 2`` with
    speed ``omega_n + alpha h`` (``alpha`` estimated from the last two speed
    inputs; zero on the first step or with ``extrapolate=False``). The
    prescribed motions are therefore C1 in time: a new input never makes the
    kinematic carrier jump in speed, which would kick the stiff, heavily damped
    meshes into a fast transient at every step. They track the inputs to second
    order in ``h`` without drift, because each target is re-anchored on the
    received angle.

    Parameters
    ----------
    drivetrain : Drivetrain
        Must have a generator (its rotor is the cut; only shaft 3 is used here).
    control : StepControl, optional
        Integrator tolerances.
    shaft_torque_mode : {"average", "end"}
        Which value :attr:`shaft_torque_nm` reports: the torque averaged over the
        last step (conserves the exchanged impulse: the twist integrated along the
        accepted internal steps) or its end-of-step value.
    extrapolate : bool
        Estimate the input slopes from the last two inputs (True) or hold the
        input speeds over the step (False).
    generator_interface : {"motion", "inertia"}
        ``motion``: the generator end of shaft 3 follows the Hermite curve of the
        generator-motion inputs (above). ``inertia`` (an interface model): the
        generator rotor's inertia (the drivetrain's ``generator.inertia_kgm2``) is a
        degree of freedom of the step, driven by shaft 3 against the counter-torque
        input held over the step, ``I_g omega_g' = T_3 - T_c``; at every
        communication point its speed is set to the generator-speed input, so the
        generator component stays the owner of the generator's speed (with the
        step-averaged shaft torque and the same held counter torque, both integrate
        the same impulse: the speeds agree). Its angle stays the gearbox's own: the
        generator component's angle integrates a step-mean torque, and anchoring to
        it would twist shaft 3 by that error at every communication point. Within the
        step the generator answers the shaft torque at once instead of one step
        later, so the gearbox - generator loop adds no coupling error.
    rotor_derivatives : bool
        Extrapolate the rotor motion over the step from the inputs ``alpha_rotor``
        and ``jerk_rotor`` (the source's acceleration and jerk at ``t_n``: a third-order
        Taylor target, ``phi_n + omega_n h + alpha h^2 / 2 + j h^3 / 6``) instead of
        the acceleration estimated from the last two speed inputs.
    kernel : {"auto", "numpy", "compiled"}, optional
        Implementation of the step (:mod:`components.model.kernel`; default:
        ``$DTCOSIM_KERNEL``, else ``auto``). Both give the same results to round-off.

    Attributes
    ----------
    y : ndarray, shape (2 n_dof,)
        State ``[q, v]`` relative to the driver motion.
    kernel : str
        ``"compiled"`` or ``"numpy"``: the implementation in use.
    kernel_note : str or None
        Why the compiled kernel was wanted but is not used (None if it is, or if
        ``numpy`` was asked for).
    """

    def __new__(cls, *args, kernel: str | None = None, **kwargs):
        if cls is GearboxModel and choose_kernel(kernel)[0] == "compiled":
            from .gearbox_kernel import CompiledGearboxModel

            cls = CompiledGearboxModel
        return super().__new__(cls)

    _SCALARS = (
        "time_s", "driver_angle_rad", "driver_speed_rad_s", "driver_accel_rad_s2", "port_angle_rad",
        "port_speed_rad_s", "last_step_s", "last_omega_rotor", "last_omega_gen", "shaft_torque_average_nm",
        "output_twist_rad", "alpha_out_max_rad_s2", "alpha_out_average_rad_s2",
    )

    def __init__(
        self,
        drivetrain: Drivetrain,
        control: StepControl | None = None,
        shaft_torque_mode: str = "average",
        extrapolate: bool = True,
        kernel: str | None = None,
        generator_interface: str = "motion",
        rotor_derivatives: bool = False,
    ) -> None:
        self.generator_interface = one_of("generator_interface", generator_interface, GENERATOR_INTERFACES)
        inertia = self.generator_interface == "inertia"
        if inertia and drivetrain.generator is None:
            raise ParameterError("generator_interface", "inertia", "a drivetrain with a generator")
        self.assembly = a = Assembly(drivetrain, cut_at_generator=not inertia)
        #: the generator's degree of freedom (inertia interface) or None (motion interface: it is the port)
        self.generator_dof = a.output_dof if inertia else None
        #: the bodies whose speeds are outputs: the gearbox's (the generator's is not, with either interface)
        self.gearbox_dofs = np.array([j for j in range(a.n_dof) if j != self.generator_dof], dtype=int)
        self.kernel, self.kernel_note = choose_kernel(kernel)
        self._compiled_stale = True  # (compiled model) the buffer must be loaded from the numpy-side state
        self._allocate()
        self.shaft_torque_mode = one_of("shaft_torque_mode", shaft_torque_mode, SHAFT_TORQUE_MODES)
        self.extrapolate = bool(extrapolate)
        self.rotor_derivatives = bool(rotor_derivatives)
        self.system = _StepSystem(a)
        self._integrator = Rosenbrock23(self.system, a.n_dof, control)
        self._kx = float(a.port_ratio[0] if not inertia else a.kinematic_ratio[self.generator_dof])
        self._out_member = a.dof_index(a.stage_members[drivetrain.stages[-1].name]["output"])
        self.initialized = False
        self.y = np.zeros(2 * a.n_dof)
        self.time_s = 0.0
        self.driver_angle_rad = 0.0  # driver (rotor) motion at the current time
        self.driver_speed_rad_s = 0.0
        self.driver_accel_rad_s2 = 0.0
        self.port_angle_rad = 0.0  # generator-port deviation theta_gen - ratio * theta_rotor
        self.port_speed_rad_s = 0.0
        self.last_step_s = 0.0
        self.last_omega_rotor = 0.0
        self.last_omega_gen = 0.0
        self.shaft_torque_average_nm = 0.0
        self.output_twist_rad = 0.0  # twist of the output shaft (shaft 3) [rad]
        # output twist = _twist_q . q + _twist_port * port angle
        self._twist_q = np.concatenate((a.S[-1], np.zeros(a.n_dof)))
        # twist and its rate in one product: the same weights on q and on v (and _twist_port on the port's)
        self._twist_qv = np.stack((self._twist_q, np.concatenate((np.zeros(a.n_dof), a.S[-1]))))
        #: (time, twist, twist rate, integral of the twist) at the last accepted internal step of the current step
        self._twist_accumulator = [0.0, 0.0, 0.0, 0.0]
        self._twist_port = float(a.port_twist[-1])
        self._out_shaft_kc = (float(a.shaft_k[-1]), float(a.shaft_c[-1]))  # shaft 3 stiffness, damping
        self._output_matrix = self._build_output_matrix()
        self._out_kinematic = float(a.kinematic_ratio[self._out_member])
        self._out_rate_index = a.n_dof + self._out_member  # its speed in [q, v], its acceleration in [v, a]
        #: eq. 11: largest |d omega_out / dt| since initialisation over every accepted internal step [rad/s^2]
        self.alpha_out_max_rad_s2 = 0.0
        #: d omega_out / dt averaged over the last step [rad/s^2] (instantaneous before the first step)
        self.alpha_out_average_rad_s2 = 0.0
        self._integrator.on_accept = self._on_accept
        self._finish_allocation()

    # ------------------------------------------------------------ outputs
    @property
    def ratio(self) -> float:
        """Kinematic speed ratio generator / rotor [-]."""
        return self._kx

    @property
    def contact_force_n(self) -> np.ndarray:
        """Contact forces at the current time [N], shape (n_mesh,)."""
        return self.system.last_force

    @property
    def deflection_m(self) -> np.ndarray:
        """Mesh deflections at the current time [m], shape (n_mesh,)."""
        return self.system.last_deflection[0]

    @property
    def shaft_twist_rad(self) -> np.ndarray:
        """Shaft twists [rad] and their rates [rad/s], shape (2, n_shaft)."""
        a = self.assembly
        n = a.n_dof
        qv = self.y.reshape(2, n) @ a.S.T
        qv[0] += a.port_twist * self.port_angle_rad
        qv[1] += a.port_twist * self.port_speed_rad_s
        return qv

    @property
    def shaft_torques_nm(self) -> np.ndarray:
        """Shaft torques at the current time [N m], shape (n_shaft,)."""
        tw = self.shaft_twist_rad
        return self.assembly.shaft_k * tw[0] + self.assembly.shaft_c * tw[1]

    @property
    def shaft_torque_end_nm(self) -> float:
        """Shaft-3 torque on the generator at the end of the last step [N m]."""
        return float(self.shaft_torques_nm[-1])

    @property
    def shaft_torque_nm(self) -> float:
        """Shaft-3 torque on the generator [N m], per :attr:`shaft_torque_mode`."""
        return self.shaft_torque_average_nm if self.shaft_torque_mode == "average" else self.shaft_torque_end_nm

    @property
    def speeds_rad_s(self) -> np.ndarray:
        """Absolute speeds of the free bodies [rad/s], shape (n_dof,)."""
        return self.assembly.kinematic_ratio * self.driver_speed_rad_s + self.y[self.assembly.n_dof :]

    @property
    def output_speed_rad_s(self) -> float:
        """Speed of the last stage's output member [rad/s] (its entry of :attr:`speeds_rad_s`)."""
        return self._out_kinematic * self.driver_speed_rad_s + self.y.item(self._out_rate_index)

    @property
    def output_acceleration_rad_s2(self) -> float:
        """Angular acceleration of the last stage's output member at the current time [rad/s^2].

        Within a step the driver and generator ends follow C1 Hermite curves whose
        acceleration is piecewise linear, so at the step ends this value carries the
        input model's acceleration jumps (shaft 3's damping locks the output gear to the
        generator end); :attr:`alpha_out_average_rad_s2` does not.
        """
        sysm = self.system
        return float(self._out_kinematic * sysm.last_alpha + sysm.last_acceleration[self._out_member])

    def _on_accept(self, tau: float, y: np.ndarray, f: np.ndarray) -> None:
        """After every accepted internal step: eq. 11's running maximum and the integral of the output twist."""
        # absolute acceleration = kinematic part of the driver's + relative (deviation) part
        alpha = abs(self._out_kinematic * self.system.driver.accel(tau) + f.item(self._out_rate_index))
        if alpha > self.alpha_out_max_rad_s2:
            self.alpha_out_max_rad_s2 = float(alpha)
        twist, rate = self._twist_and_rate(y, *self.system.port.value_and_rate(tau))
        acc = self._twist_accumulator
        dt = tau - acc[0]
        # Hermite-corrected trapezoid over the internal step (exact for a cubic twist)
        acc[3] += 0.5 * dt * (acc[1] + twist) + dt * dt * (acc[2] - rate) / 12.0
        acc[0], acc[1], acc[2] = tau, twist, rate

    @property
    def rotor_torque_nm(self) -> float:
        """Torque the rotor applies to the gearbox [N m] (driven carrier inertia + mesh/shaft reactions)."""
        return self.rotor_torque_from(self.shaft_torques_nm)

    def rotor_torque_from(self, shaft_torques_nm: np.ndarray) -> float:
        """Rotor torque [N m] given the current shaft torques [N m], shape (n_shaft,)."""
        a = self.assembly
        return float(
            a.driver_inertia_kgm2 * self.driver_accel_rad_s2
            + self.contact_force_n @ a.BT_driver
            + shaft_torques_nm @ a.s_driver
        )

    @property
    def output_names(self) -> list[str]:
        """Names of the entries of :meth:`output_vector`, in order (FMU variable names)."""
        a = self.assembly
        return (
            ["shaft_torque", "shaft_torque_avg", "shaft_torque_end", "omega_out", "torque_rotor"]
            + a.mesh_names
            + [f"{s}.torque" for s in a.shaft_names]
            + [f"{a.dof_names[j]}.omega" for j in self.gearbox_dofs]
            + ["alpha_out", "alpha_out_max"]
        )

    def _build_output_matrix(self) -> np.ndarray:
        """Linear map ``z -> [shaft_torque_end, omega_out, torque_rotor, forces, shaft torques, speeds]``.

        ``z = [contact forces (n_mesh), q, v (n_dof each), port angle, port speed,
        driver speed, driver acceleration]``: every output except the step-averaged
        shaft torque is linear in ``z``.
        """
        a = self.assembly
        n, m, ns = a.n_dof, a.n_mesh, a.n_shaft
        rows = m + 2 * n + 4
        shafts = np.zeros((rows, ns))
        shafts[m : m + n] = (a.shaft_k[:, None] * a.S).T
        shafts[m + n : m + 2 * n] = (a.shaft_c[:, None] * a.S).T
        shafts[m + 2 * n] = a.shaft_k * a.port_twist
        shafts[m + 2 * n + 1] = a.shaft_c * a.port_twist
        speeds = np.zeros((rows, n))
        speeds[m + n : m + 2 * n] = np.eye(n)
        speeds[m + 2 * n + 2] = a.kinematic_ratio
        forces = np.zeros((rows, m))
        forces[:m] = np.eye(m)
        rotor = shafts @ a.s_driver  # shaft reactions on the driven carrier
        rotor[:m] += a.BT_driver  # mesh reactions
        rotor[m + 2 * n + 3] += a.driver_inertia_kgm2  # carrier (and orbital planet) inertia
        return np.column_stack((shafts[:, -1], speeds[:, self._out_member], rotor, forces, shafts,
                                speeds[:, self.gearbox_dofs]))

    def output_vector(self) -> np.ndarray:
        """Every output at the current time in one pass, ordered as :attr:`output_names`.

        Units: torques [N m], speeds [rad/s], contact forces [N], accelerations [rad/s^2]
        (``alpha_out``: the output member's acceleration averaged over the last step;
        ``alpha_out_max``: eq. 11's running maximum of its magnitude over every accepted
        internal step since initialisation).
        """
        z = np.concatenate((self.system.last_force, self.y, self._output_extra()))
        out = np.empty(self._output_matrix.shape[1] + 4)
        linear = np.dot(z, self._output_matrix, out=out[2:-2])
        avg = self.shaft_torque_average_nm
        out[0] = avg if self.shaft_torque_mode == "average" else linear[0]
        out[1] = avg
        out[-2] = self.alpha_out_average_rad_s2
        out[-1] = self.alpha_out_max_rad_s2
        return out

    def output_list(self) -> list[float]:
        """:meth:`output_vector` as a list of floats (what an FMU writes into its variables)."""
        return self._output_array().tolist()

    def _output_array(self) -> np.ndarray:
        """The outputs as an array that may be reused (the compiled model returns its buffer's view)."""
        return self.output_vector()

    def _output_extra(self) -> tuple[float, float, float, float]:
        return (self.port_angle_rad, self.port_speed_rad_s, self.driver_speed_rad_s, self.driver_accel_rad_s2)

    # ------------------------------------------------------------ stepping
    def initialize(self, t0: float, omega_rotor: float, phi_rotor: float, omega_gen: float, phi_gen: float,
                   counter_torque_nm: float = 0.0) -> None:
        """Kinematically consistent start with zero deflection at time ``t0`` [s].

        Parameters
        ----------
        omega_rotor, phi_rotor : float
            Rotor speed [rad/s] and angle [rad] at ``t0``.
        omega_gen, phi_gen : float
            Generator speed [rad/s] and angle [rad] at ``t0``.
        counter_torque_nm : float
            Counter torque on the generator rotor [N m] (used by the ``inertia`` interface only).
        """
        self.time_s = finite("start_time", t0)
        for name, val in (("omega_rotor", omega_rotor), ("phi_rotor", phi_rotor), ("omega_gen", omega_gen),
                          ("phi_gen", phi_gen), ("counter_torque", counter_torque_nm)):
            finite(name, val)
        n = self.assembly.n_dof
        self.y = np.zeros(2 * n)
        self.driver_angle_rad = float(phi_rotor)
        self.driver_speed_rad_s = float(omega_rotor)
        self.driver_accel_rad_s2 = 0.0
        port_angle = float(phi_gen - self._kx * phi_rotor)
        port_speed = float(omega_gen - self._kx * omega_rotor)
        if self.generator_dof is None:  # the port input is the generator end's deviation motion
            self.port_angle_rad, self.port_speed_rad_s = port_angle, port_speed
        else:  # the generator is a degree of freedom; the port input is its counter torque
            y = self.y
            y[self.generator_dof], y[n + self.generator_dof] = port_angle, port_speed
            self.y = y
            self.port_angle_rad, self.port_speed_rad_s = float(counter_torque_nm), 0.0
        self.last_omega_rotor = float(omega_rotor)
        self.last_omega_gen = float(omega_gen)
        self.last_step_s = 0.0
        self._store_compiled()
        self._integrator.reset()
        sysm = self.system
        sysm.angle0 = self.driver_angle_rad
        sysm.driver.fit(1.0, 0.0, self.driver_speed_rad_s, self.driver_speed_rad_s, self.driver_speed_rad_s)
        sysm.port.fit(1.0, self.port_angle_rad, self.port_speed_rad_s, self.port_angle_rad + self.port_speed_rad_s, self.port_speed_rad_s)
        sysm.acceleration(0.0, self.y)  # loads at the initial state
        self.alpha_out_average_rad_s2 = self.output_acceleration_rad_s2
        self.alpha_out_max_rad_s2 = abs(self.alpha_out_average_rad_s2)
        self.output_twist_rad = self._output_twist()
        self.shaft_torque_average_nm = self.shaft_torque_end_nm
        self.initialized = True

    def step(self, t: float, h: float, omega_rotor: float, phi_rotor: float, omega_gen: float, phi_gen: float,
             counter_torque_nm: float = 0.0, alpha_rotor: float = 0.0, jerk_rotor: float = 0.0) -> None:
        """Advance from ``t`` to ``t + h`` [s] with the inputs received at ``t``.

        ``counter_torque_nm`` [N m] is held over the step (``inertia`` interface; ignored by ``motion``);
        ``phi_gen`` is not used by ``inertia``. ``alpha_rotor`` [rad/s^2] and ``jerk_rotor`` [rad/s^3] are
        used with ``rotor_derivatives`` only. On failure the state is left as it was at ``t`` and
        :class:`SolverError` is raised.
        """
        if not self.initialized:
            self.initialize(t, omega_rotor, phi_rotor, omega_gen, phi_gen, counter_torque_nm)
        if not h > 0.0:
            raise ParameterError("step_size", h, "> 0")
        inertia = self.generator_dof is not None
        extrapolate = self.extrapolate and self.last_step_s > 0.0
        alpha_gen = (omega_gen - self.last_omega_gen) / self.last_step_s if extrapolate and not inertia else 0.0
        if self.rotor_derivatives:  # Taylor to third order from the source's derivatives
            angle1 = phi_rotor + h * (omega_rotor + h * (0.5 * alpha_rotor + h * (jerk_rotor / 6.0)))
            speed1 = omega_rotor + h * (alpha_rotor + h * (0.5 * jerk_rotor))
        else:
            alpha = (omega_rotor - self.last_omega_rotor) / self.last_step_s if extrapolate else 0.0
            angle1 = phi_rotor + h * (omega_rotor + 0.5 * h * alpha)
            speed1 = omega_rotor + h * alpha
        kx = self._kx
        a = self.assembly
        sysm = self.system
        y = self.y
        correction = None
        if inertia:  # the port input is the counter torque, held; the generator speed re-anchored on its input
            port0, port_speed0 = float(counter_torque_nm), 0.0
            port1, port_speed1 = port0, 0.0
            g, n, m = self.generator_dof, a.n_dof, a.n_mesh
            dv = omega_gen - kx * self.driver_speed_rad_s - y[n + g]
            if not math.isfinite(dv + port0):
                raise SolverError(non_finite_input((omega_rotor, phi_rotor, omega_gen, phi_gen, counter_torque_nm,
                                                    alpha_rotor, jerk_rotor)), t)
            y = y.copy()
            y[n + g] += dv
            # the generator is in no mesh: the accelerations are linear in its speed and in the torque
            fast = a._fast_matrix
            correction = dv * fast[m + n + g] + (port0 - self.port_angle_rad) * fast[m + 2 * n]
        else:
            port0, port_speed0 = self.port_angle_rad, self.port_speed_rad_s
            port1 = phi_gen + h * (omega_gen + 0.5 * h * alpha_gen) - kx * angle1
            port_speed1 = omega_gen + h * alpha_gen - kx * speed1
        if not math.isfinite(angle1 + speed1 + port1 + port_speed1):
            raise SolverError(non_finite_input((omega_rotor, phi_rotor, omega_gen, phi_gen, counter_torque_nm,
                                                alpha_rotor, jerk_rotor)), t)
        sysm.angle0 = self.driver_angle_rad
        sysm.driver.fit(h, 0.0, self.driver_speed_rad_s, angle1 - self.driver_angle_rad, speed1)
        sysm.port.fit(h, port0, port_speed0, port1, port_speed1)
        # first stage reuses the loads at the end of the previous step: the prescribed
        # motions are C1, so only the driver-acceleration term changes (and the re-anchoring's, above)
        a0 = sysm.last_acceleration + a.kinematic_ratio * (sysm.last_alpha - sysm.driver.accel(0.0))
        if correction is not None:
            a0 = a0 + correction
        twist_start = self.output_twist_rad  # (the re-anchored generator speed leaves the twist)
        rate_start = self._twist_and_rate(y, port0, port_speed0)[1]
        out_index = self._out_rate_index
        speed_start = self._out_kinematic * self.driver_speed_rad_s + y.item(out_index)
        self._twist_accumulator[:] = (0.0, twist_start, rate_start, 0.0)
        saved = (self._integrator.snapshot(), sysm.cache(), sysm.port_jacobian, self.alpha_out_max_rad_s2)
        try:
            y_end, _ = self._integrator.advance(0.0, y, h, a0=a0)
        except SolverError as exc:
            self._integrator.restore(saved[0])
            sysm.restore(saved[1])
            sysm.port_jacobian = saved[2]
            self.alpha_out_max_rad_s2 = saved[3]
            raise SolverError(str(exc).rsplit(" (at t =", 1)[0], t + exc.time_s) from None
        self.y = y_end
        self.time_s = t + h
        self.driver_angle_rad = angle1
        self.driver_speed_rad_s = speed1
        self.driver_accel_rad_s2 = sysm.driver.accel(h)
        self.port_angle_rad = port1
        self.port_speed_rad_s = port_speed1
        self.last_omega_rotor = omega_rotor
        self.last_omega_gen = omega_gen
        self.last_step_s = h
        # (1/h) int T dt = k mean(twist) + c (twist_end - twist_start) / h, the mean twist integrated along the
        # accepted internal steps (_on_accept)
        twist_end = self.output_twist_rad = self._output_twist()
        k, c = self._out_shaft_kc
        self.shaft_torque_average_nm = k * self._twist_accumulator[3] / h + c * (twist_end - twist_start) / h
        self.alpha_out_average_rad_s2 = (self.output_speed_rad_s - speed_start) / h

    @property
    def integrator(self) -> Rosenbrock23:
        """The integrator (its counters and state current also when the compiled kernel steps)."""
        self._store_compiled()
        return self._integrator

    def _allocate(self) -> None:
        """Hook of the compiled model: allocate its buffer (called before any state is set)."""

    def _finish_allocation(self) -> None:
        """Hook of the compiled model: fill its buffer's constants (called at the end of ``__init__``)."""

    def _store_compiled(self) -> None:
        """Hook of the compiled model: hand the state its buffer holds back to the numpy side."""

    def _twist_and_rate(self, y: np.ndarray, port_angle_rad: float, port_speed_rad_s: float) -> tuple[float, float]:
        """Twist [rad] and twist rate [rad/s] of the output shaft (shaft 3) at the state ``y`` and port motion."""
        twist, rate = (self._twist_qv @ y).tolist()
        return twist + self._twist_port * port_angle_rad, rate + self._twist_port * port_speed_rad_s

    def _output_twist(self) -> float:
        """Twist of the output shaft (shaft 3) [rad]."""
        return float(np.dot(self._twist_q, self.y)) + self._twist_port * self.port_angle_rad

    # ---------------------------------------------------------------- state
    def get_state(self) -> dict:
        """Complete internal state, integrator included (JSON-serialisable, exact float round trip)."""
        self._store_compiled()
        state = {name: float(getattr(self, name)) for name in self._SCALARS}
        sysm = self.system
        state.update(
            y=self.y.tolist(),
            initialized=self.initialized,
            integrator=self._integrator.get_state(),
            last_acceleration=sysm.last_acceleration.tolist(),
            last_alpha=sysm.last_alpha,
            last_force=sysm.last_force.tolist(),
            last_deflection=sysm.last_deflection.tolist(),
            port_jacobian=sysm.port_jacobian.tolist(),
        )
        return state

    def set_state(self, state: dict) -> None:
        """Restore a state produced by :meth:`get_state`."""
        y = np.array(state["y"], dtype=float)
        if y.shape != self.y.shape:
            raise ParameterError("state.y", y.shape, f"shape {self.y.shape}")
        for name in self._SCALARS:
            setattr(self, name, float(state[name]))
        self.y = y
        self.initialized = bool(state["initialized"])
        self._integrator.set_state(state["integrator"])
        sysm = self.system
        sysm.last_acceleration = np.array(state["last_acceleration"], dtype=float)
        sysm.last_alpha = float(state["last_alpha"])
        sysm.last_force = np.array(state["last_force"], dtype=float)
        sysm.last_deflection = np.array(state["last_deflection"], dtype=float)
        sysm.port_jacobian = np.array(state["port_jacobian"], dtype=float)
        self._compiled_stale = True

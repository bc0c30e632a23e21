"""The gearbox side of the co-simulation cut, as a stepping component.

Inputs at each communication point ``t_n``: rotor speed and angle (the
kinematic driver of the stage-1 carrier) and generator speed and angle (the
far end of shaft 3, which stays in the gearbox). Over a step the inputs are
interpreted as C1 motions (:mod:`components.model.kernel.motion`). The internal
state is integrated by the kernel's ROS2(3) W-method
(:mod:`components.model.kernel.integrator`: linearly implicit, analytic
Jacobian, one-step: no cold start at communication points); one communication
step is one call of :func:`components.model.kernel.step.gearbox_step`, compiled
or interpreted (:mod:`components.compile`).

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
from dataclasses import dataclass

import numpy as np

from ..compile.jit import entry_point
from ..errors import ParameterError, SolverError
from ..validation import finite, one_of
from . import kernel as model_kernel
from .assembly import Assembly, column_sparsity
from .gearbox_outputs import gearbox_outputs
from .drivetrain import Drivetrain
from .integrators import StepControl
from .kernel import layout as L

SHAFT_TORQUE_MODES = ("average", "end")
#: how the generator end of shaft 3 moves within a communication step (see :class:`GearboxModel`)
GENERATOR_INTERFACES = ("motion", "inertia", "inertia_own")
#: where a run starts: at the static deflection of its initial load, or undeflected (today's start before issue 29)
STARTS = ("operating_point", "rest")
#: the static deflection's convergence (relative generalised-force imbalance) and Newton iterations
STATIC_RTOL, STATIC_MAX_ITERATIONS = 1e-11, 60


#: the inputs of :meth:`GearboxModel.step`, in order
STEP_INPUTS = ("omega_rotor", "phi_rotor", "omega_gen", "phi_gen", "counter_torque", "alpha_rotor", "jerk_rotor")


def non_finite_input(inputs: tuple[float, ...]) -> str:
    """``"non-finite input (jerk_rotor=inf)"``: the message of a step refused for its inputs (all of them if
    every one is finite and only their combination overflowed)."""
    pairs = [(f"{name}={value!r}", value) for name, value in zip(STEP_INPUTS, inputs)]
    named = [text for text, value in pairs if not math.isfinite(value)] or [text for text, _ in pairs]
    return f"non-finite input ({', '.join(named)})"




def _buffer_scalar(index: int, doc: str) -> property:
    def get(self) -> float:
        return float(self._scalars[index])

    def set(self, value: float) -> None:
        self._scalars[index] = value

    return property(get, set, doc=doc)


@dataclass(frozen=True)
class IntegratorCounters:
    """The integrator's counters since initialisation and its proposed next step.

    Attributes
    ----------
    accepted, rejected, jacobians : int
        Accepted and rejected internal steps, Jacobian evaluations.
    h_next : float
        Step size proposed for the next internal step [s] (0 before the first).
    """

    accepted: int
    rejected: int
    jacobians: int
    h_next: float


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
    received angle (:mod:`components.model.kernel.motion`).

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
    generator_interface : {"motion", "inertia", "inertia_own"}
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
        later, so the gearbox - generator loop adds no coupling error - when the generator
        component is stepped after the gearbox (Gauss-Seidel). ``inertia_own``: the same
        interface model, but the generator speed is the gearbox's own, re-anchored at every
        communication point on its impulse balance ``I_g (w_n+1 - w_n) = h (mean shaft torque -
        counter torque)`` (the generator component's equation, on the same torques) instead of
        on the generator-speed input, which is not used. For hosts that step every component
        from its partners' values of the last communication point (Jacobi: libcosim, ecos), whose
        generator-speed input lags one step; the generator component follows the gearbox
        (:class:`~components.model.generator.ShaftTorquePrediction`).
    rotor_derivatives : bool
        Extrapolate the rotor motion over the step from the inputs ``alpha_rotor``
        and ``jerk_rotor`` (the source's acceleration and jerk at ``t_n``: a third-order
        Taylor target, ``phi_n + omega_n h + alpha h^2 / 2 + j h^3 / 6``) instead of
        the acceleration estimated from the last two speed inputs.
    kernel : {"auto", "numpy", "compiled"}, optional
        Form of the kernel that steps it (:mod:`components.compile.choice`; default:
        ``$DTCOSIM_KERNEL``, else ``auto``): the same equations compiled or interpreted.
    start : {"operating_point", "rest"}
        ``operating_point``: :meth:`initialize` puts the gearbox at the static deflection of its
        initial load (the counter torque input at constant speed; :mod:`components.model.kernel.statics`),
        so constant inputs give constant outputs from the start. With the ``motion`` interface the
        generator-angle input is then read relative to the static twist of shaft 3 (a constant port
        offset: the generator's angle origin is arbitrary). Without a load (counter torque 0) the teeth
        float in the backlash and the start is undeflected. ``rest``: undeflected at full load, the
        load applied as a step at the start (the paper's convention).

    Attributes
    ----------
    y : ndarray, shape (2 n_dof,)
        State ``[q, v]`` relative to the driver motion (a view of the kernel's buffer).
    kernel : str
        ``"compiled"`` or ``"numpy"``: the form in use.
    kernel_note : str or None
        Why the compiled kernel was wanted but is not used (None if it is, or if
        ``numpy`` was asked for).
    """

    def __init__(
        self,
        drivetrain: Drivetrain,
        control: StepControl | None = None,
        shaft_torque_mode: str = "average",
        extrapolate: bool = True,
        kernel: str | None = None,
        generator_interface: str = "motion",
        rotor_derivatives: bool = False,
        start: str = "operating_point",
    ) -> None:
        self.generator_interface = one_of("generator_interface", generator_interface, GENERATOR_INTERFACES)
        self.start = one_of("start", start, STARTS)
        inertia = self.generator_interface != "motion"
        if inertia and drivetrain.generator is None:
            raise ParameterError("generator_interface", self.generator_interface, "a drivetrain with a generator")
        self.shaft_torque_mode = one_of("shaft_torque_mode", shaft_torque_mode, SHAFT_TORQUE_MODES)
        self.extrapolate = bool(extrapolate)
        self.rotor_derivatives = bool(rotor_derivatives)
        self.control = control or StepControl()
        self.assembly = a = Assembly(drivetrain, cut_at_generator=not inertia)
        #: the generator's degree of freedom (inertia interface) or None (motion interface: it is the port)
        self.generator_dof = a.output_dof if inertia else None
        #: the bodies whose speeds are outputs: the gearbox's (the generator's is not, with either interface)
        self.gearbox_dofs = np.array([j for j in range(a.n_dof) if j != self.generator_dof], dtype=int)
        self._module, self.kernel, self.kernel_note = model_kernel.gearbox(kernel)
        self._kx = float(a.port_ratio[0] if not inertia else a.kinematic_ratio[self.generator_dof])
        self._out_member = a.dof_index(a.stage_members[drivetrain.stages[-1].name]["output"])
        self._out_kinematic = float(a.kinematic_ratio[self._out_member])
        self._out_rate_index = a.n_dof + self._out_member  # its speed in [q, v], its acceleration in [v, a]
        self._allocate()
        # the buffer's offsets and sizes as the kernel takes them: int64 arrays (compiled), or lists of ints
        # (interpreted: Python indexes a list several times faster than an array, ~10 us of every step)
        self._lay, self._sizes = ((self._offsets, self._dims) if self.kernel == "compiled"
                                  else (self._offsets.tolist(), self._dims.tolist()))
        self._step = entry_point(self._module.gearbox_step,
                                 ("float64[::1]", "int64[::1]", "int64[::1]") + ("float64",) * 9)
        self.initialized = False
        #: Newton iterations of the static deflection at the last initialisation (0: started undeflected)
        self.static_iterations = 0

    # ------------------------------------------------------------ the kernel's buffer
    def _slot_shapes(self) -> dict[str, tuple[int, ...]]:
        """Shape of every slot of the buffer (:mod:`components.model.kernel.layout`)."""
        a = self.assembly
        n, m, n2 = a.n_dof, a.n_mesh, 2 * a.n_dof
        width = a.nz_index.shape[1]
        n_ext = a.load_matrix.shape[0]
        n_linear, n_mag = self._out_index.shape[0], self._magnitudes.shape[0]
        shapes = {
            "a_t": (n, m), "a_port": (m,), "fast": (m + n2 + 3 + n_ext, n), "contact": a.law.table.shape,
            "stks": (n, n), "stcs": (n, n), "stks_port": (n,), "stcs_port": (n,), "inv_m": (n,),
            "phasing": a.phasing_table.shape, "kappa": (n,), "force_rows": (m, n), "nz_index": (m, width),
            "nz_value": (m, width), "cos_alpha": (m,), "control": (L.N_CONTROL,), "twist_q": (n2,),
            "offset": (m,), "load_rates": a.load_rates.shape, "magnitudes": (n_mag, 2),
            "fast_index": a.fast_index.shape, "fast_value": a.fast_value.shape, "jac_index": a.jacobian_index.shape,
            "out_index": self._out_index.shape, "out_value": self._out_index.shape,
            "z": (m + n2 + 4 + n_ext,), "defl": (2, m), "acc": (n,), "fd": (m,), "fv": (m,), "factor": (m,),
            "slope": (m,), "sens": (m,),
            **{name: (n2,) for name in ("f0", "f1", "fn", "k1", "k2", "k3", "y1", "yn", "rhs", "w_hdt")},
            "w_ext": (max(n_ext, 1),),
            "da": (n,), "sol": (n,), "istate": (L.N_ISTATE,), "dq": (n, n), "dv": (n, n),
            # G^-1 (or its LU factors, pivots and pattern) and the time-derivative basis of every kept factorisation
            "winvs": (L.N_SLOTS, n, n), "pivots": (L.N_SLOTS, 2 * n + 1, n), "w_bases": (L.N_SLOTS, 3 + n_ext, n2),
            "port_jac": (2, n), "last_acc": (n,), "last_force": (m,), "last_defl": (2, m), "y": (n2,),
            "driver": (4,), "port": (4,), "scalars": (len(L.SCALAR_NAMES),), "outputs": (n_linear + n_mag + 5,),
            "anchor": (n + 1,),
        }
        shapes["backup"] = (sum(int(np.prod(shapes[name])) for name in L.STATE_SLOTS),)
        return shapes

    def _allocate(self) -> None:
        """The buffer with its views, constants and sizes."""
        a = self.assembly
        output_matrix, self._magnitudes, self._output_names = gearbox_outputs(a, self.gearbox_dofs, self._out_member)
        self._out_index, self._out_value = column_sparsity(output_matrix)
        shapes = self._slot_shapes()
        sizes = [int(np.prod(shapes[name])) for name in L.SLOTS]
        self._offsets = np.concatenate(([0], np.cumsum(sizes))).astype(np.int64)
        self._buffer = np.zeros(int(self._offsets[-1]))
        v = self._views = {name: self._buffer[self._offsets[i]: self._offsets[i + 1]].reshape(shapes[name])
                           for i, name in enumerate(L.SLOTS)}
        self._scalars = v["scalars"]
        self._istate = v["istate"]
        self._state = self._buffer[self._offsets[L.STATE_FIRST]: self._offsets[L.STATE_LAST + 1]]
        ports = a.ports.size
        v["a_t"][:] = a.A_T
        v["a_port"][:] = a.port_deflection
        v["fast"][:] = a.fast_matrix
        v["contact"][:] = a.law.table
        v["stks"][:] = a.STkS
        v["stcs"][:] = a.STcS
        v["stks_port"][:] = a.STkS_port[:, 0] if ports else 0.0
        v["stcs_port"][:] = a.STcS_port[:, 0] if ports else 0.0
        v["inv_m"][:] = a.inv_inertia
        v["phasing"][:] = a.phasing_table
        v["kappa"][:] = a.kinematic_ratio
        v["force_rows"][:] = a.force_rows
        v["nz_index"][:], v["nz_value"][:] = a.nz_index, a.nz_value
        v["cos_alpha"][:] = a.cos_alpha
        v["offset"][:] = a.mesh_offset
        v["load_rates"][:] = a.load_rates
        v["magnitudes"][:] = self._magnitudes
        c = self.control
        v["control"][:] = (c.rtol, c.atol_q, c.atol_v, c.h_min, float(c.max_steps), float(c.jacobian_max_age),
                           self._out_kinematic, float(self._out_rate_index))
        # output-shaft twist = twist_q . q + twist_port * port angle (its rate: the same weights on v)
        self._twist_q = np.concatenate((a.S[-1], np.zeros(a.n_dof)))
        v["twist_q"][:] = self._twist_q
        v["out_index"][:], v["out_value"][:] = self._out_index, self._out_value
        v["fast_index"][:], v["fast_value"][:] = a.fast_index, a.fast_value
        v["jac_index"][:] = a.jacobian_index
        sc = self._scalars
        sc[L.S_KX] = self._kx
        sc[L.S_TWIST_PORT] = float(a.port_twist[-1])
        sc[L.S_SHAFT_K] = float(a.shaft_k[-1])
        sc[L.S_SHAFT_C] = float(a.shaft_c[-1])
        dims = self._dims = np.zeros(L.N_DIMS, dtype=np.int64)
        dims[L.D_N] = a.n_dof
        dims[L.D_M] = a.n_mesh
        dims[L.D_WIDTH] = a.nz_index.shape[1]
        dims[L.D_TVS] = int(a.time_varying_stiffness)
        dims[L.D_EXTRAPOLATE] = int(self.extrapolate)
        dims[L.D_END_TORQUE] = int(self.shaft_torque_mode == "end")
        dims[L.D_GEN_DOF] = -1 if self.generator_dof is None else self.generator_dof
        dims[L.D_ROTOR_DERIVATIVES] = int(self.rotor_derivatives)
        dims[L.D_OWN_GEN_SPEED] = int(self.generator_interface == "inertia_own")
        dims[L.D_EXT] = a.load_matrix.shape[0]
        dims[L.D_MAGNITUDES] = self._magnitudes.shape[0]

    # the scalar state lives in the buffer
    time_s = _buffer_scalar(L.S_TIME, "Current time [s].")
    driver_angle_rad = _buffer_scalar(L.S_DRIVER_ANGLE, "Driver (rotor) angle [rad].")
    driver_speed_rad_s = _buffer_scalar(L.S_DRIVER_SPEED, "Driver speed [rad/s].")
    driver_accel_rad_s2 = _buffer_scalar(L.S_DRIVER_ACCEL, "Driver acceleration [rad/s^2].")
    port_angle_rad = _buffer_scalar(L.S_PORT_ANGLE, "Port input: generator-port deviation angle [rad] (motion "
                                                    "interface) or counter torque [N m] (inertia interface).")
    port_speed_rad_s = _buffer_scalar(L.S_PORT_SPEED, "Generator-port deviation speed [rad/s] (motion interface).")
    last_step_s = _buffer_scalar(L.S_LAST_STEP, "Last communication step [s].")
    shaft_torque_average_nm = _buffer_scalar(L.S_SHAFT_TORQUE_AVG, "Shaft-3 torque averaged over the last step [N m].")
    output_twist_rad = _buffer_scalar(L.S_OUTPUT_TWIST, "Twist of the output shaft [rad].")
    alpha_out_average_rad_s2 = _buffer_scalar(L.S_ALPHA_OUT_AVG,
                                              "Output-member acceleration averaged over the last step [rad/s^2].")

    @property
    def alpha_out_max_rad_s2(self) -> float:
        """Eq. 11: largest |d omega_out / dt| over every accepted internal step since initialisation [rad/s^2]."""
        return float(self._istate[L.ALPHA_OUT_MAX])

    @property
    def y(self) -> np.ndarray:
        """State ``[q, v]`` (a view of the buffer)."""
        return self._views["y"]

    @property
    def integrator(self) -> IntegratorCounters:
        """The integrator's counters and proposed step."""
        ist = self._istate
        return IntegratorCounters(int(ist[L.ACCEPTED]), int(ist[L.REJECTED]), int(ist[L.JACOBIANS]),
                                  float(ist[L.H_NEXT]))

    # ------------------------------------------------------------ outputs
    @property
    def ratio(self) -> float:
        """Kinematic speed ratio generator / rotor [-]."""
        return self._kx

    @property
    def contact_force_n(self) -> np.ndarray:
        """Contact forces at the current time [N], shape (n_mesh,)."""
        return self._views["last_force"]

    @property
    def deflection_m(self) -> np.ndarray:
        """Mesh deflections at the current time [m], shape (n_mesh,)."""
        return self._views["last_defl"][0]

    @property
    def shaft_twist_rad(self) -> np.ndarray:
        """Shaft twists [rad] and their rates [rad/s], shape (2, n_shaft)."""
        a = self.assembly
        qv = self.y.reshape(2, a.n_dof) @ a.S.T
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
        """Shaft-3 torque on the generator at the current time [N m]."""
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
        alpha = self._scalars[L.S_LAST_ALPHA]
        return float(self._out_kinematic * alpha + self._views["last_acc"][self._out_member])

    @property
    def rotor_torque_nm(self) -> float:
        """Torque the rotor applies to the gearbox [N m] (driven carrier inertia + mesh/shaft reactions)."""
        return self.rotor_torque_from(self.shaft_torques_nm)

    def rotor_torque_from(self, shaft_torques_nm: np.ndarray) -> float:
        """Rotor torque [N m] given the current shaft torques [N m], shape (n_shaft,)."""
        a = self.assembly
        bearing = self.y.reshape(2, a.n_dof) @ a.B.T
        return float(
            a.driver_inertia_kgm2 * self.driver_accel_rad_s2
            + self.contact_force_n @ a.BT_driver
            + shaft_torques_nm @ a.s_driver
            + (a.bearing_k * bearing[0] + a.bearing_c * bearing[1]) @ a.b_driver
        )

    @property
    def output_names(self) -> list[str]:
        """Names of the entries of :meth:`output_vector`, in order (FMU variable names)."""
        return list(self._output_names)

    def output_vector(self) -> np.ndarray:
        """Every output at the current time, ordered as :attr:`output_names` (a copy).

        Units: torques [N m], speeds [rad/s], contact forces [N], accelerations [rad/s^2]
        (``alpha_out``: the output member's acceleration averaged over the last step;
        ``alpha_out_max``: eq. 11's running maximum of its magnitude over every accepted
        internal step since initialisation; ``omega_generator``: the generator speed the next step
        starts from with ``inertia_own``, the generator's impulse balance over the last step with
        ``inertia``, the extrapolated generator-speed input with ``motion``). The kernel writes them at every step
        (:func:`components.model.kernel.step.outputs`).
        """
        return self._views["outputs"].copy()

    def output_list(self) -> list[float]:
        """:meth:`output_vector` as a list of floats (what an FMU writes into its variables)."""
        return self._views["outputs"].tolist()

    @property
    def outputs_view(self) -> np.ndarray:
        """The outputs in the kernel's buffer (overwritten by every step; do not modify)."""
        return self._views["outputs"]

    # ------------------------------------------------------------ stepping
    def initialize(self, t0: float, omega_rotor: float, phi_rotor: float, omega_gen: float, phi_gen: float,
                   counter_torque_nm: float = 0.0) -> None:
        """Kinematically consistent start at time ``t0`` [s], at the static deflection of the counter torque
        (``start = "operating_point"``) or undeflected.

        Parameters
        ----------
        omega_rotor, phi_rotor : float
            Rotor speed [rad/s] and angle [rad] at ``t0``.
        omega_gen, phi_gen : float
            Generator speed [rad/s] and angle [rad] at ``t0``.
        counter_torque_nm : float
            Counter torque on the generator rotor [N m]: the load of the static deflection, and the port
            input of the ``inertia`` interface.

        Raises
        ------
        SolverError
            The static deflection was not found.
        """
        finite("start_time", t0)
        for name, val in (("omega_rotor", omega_rotor), ("phi_rotor", phi_rotor), ("omega_gen", omega_gen),
                          ("phi_gen", phi_gen), ("counter_torque", counter_torque_nm)):
            finite(name, val)
        n = self.assembly.n_dof
        self._state[:] = 0.0
        ist = self._istate
        ist[L.AGE] = -1.0  # no Jacobian yet
        ist[L.HD] = -1.0  # no factorisation
        ist[L.SLOT_HD:L.SLOT_HD + L.N_SLOTS] = -1.0
        sc = self._scalars
        sc[[L.S_LAST_STEP, L.S_SHAFT_TORQUE_AVG, L.S_OUTPUT_TWIST, L.S_ALPHA_OUT_AVG, L.S_DRIVER_ACCEL,
            L.S_LAST_ALPHA]] = 0.0
        sc[L.S_TIME] = t0
        sc[L.S_DRIVER_ANGLE] = phi_rotor
        sc[L.S_DRIVER_SPEED] = omega_rotor
        port_angle = phi_gen - self._kx * phi_rotor
        port_speed = omega_gen - self._kx * omega_rotor
        if self.generator_dof is None:  # the port input is the generator end's deviation motion
            sc[L.S_PORT_ANGLE], sc[L.S_PORT_SPEED] = port_angle, port_speed
        else:  # the generator is a degree of freedom; the port input is its counter torque
            self.y[self.generator_dof], self.y[n + self.generator_dof] = port_angle, port_speed
            sc[L.S_PORT_ANGLE], sc[L.S_PORT_SPEED] = counter_torque_nm, 0.0
        sc[L.S_LAST_OMEGA_ROTOR] = omega_rotor
        sc[L.S_LAST_OMEGA_GEN] = omega_gen
        sc[L.S_GEN_SPEED] = omega_gen
        sc[L.S_PORT_OFFSET] = 0.0
        buf, lay, dims = self._buffer, self._lay, self._sizes
        self.static_iterations = 0
        if self.start == "operating_point" and counter_torque_nm != 0.0:
            self._settle(t0, omega_rotor, phi_rotor, omega_gen, phi_gen, counter_torque_nm)
        self._module.current_loads(buf, lay, dims)  # loads at the initial state
        alpha = self.output_acceleration_rad_s2
        sc[L.S_ALPHA_OUT_AVG] = alpha
        ist[L.ALPHA_OUT_MAX] = abs(alpha)
        sc[L.S_OUTPUT_TWIST] = float(np.dot(self._twist_q, self.y)) + sc[L.S_TWIST_PORT] * sc[L.S_PORT_ANGLE]
        sc[L.S_SHAFT_TORQUE_AVG] = self.shaft_torque_end_nm
        self._module.outputs(buf, lay, dims)
        self.initialized = True

    def _settle(self, t0: float, omega_rotor: float, phi_rotor: float, omega_gen: float, phi_gen: float,
                counter_torque_nm: float) -> None:
        """The static deflection at the counter torque (inertia interface: this model's own generator; motion
        interface: a copy with the generator as a degree of freedom, whose static twist of shaft 3 becomes the
        port offset)."""
        flank = math.copysign(1.0, counter_torque_nm)
        if self.generator_dof is not None:
            status, iterations, imbalance = self._module.settle(self._buffer, self._lay, self._sizes, flank,
                                                                STATIC_RTOL, STATIC_MAX_ITERATIONS)
            self._static_result(status, iterations, imbalance, t0)
            return
        free = GearboxModel(self.assembly.drivetrain, self.control, kernel=self.kernel, generator_interface="inertia",
                            start="operating_point")
        free.initialize(t0, omega_rotor, phi_rotor, omega_gen, phi_gen, counter_torque_nm)
        n = self.assembly.n_dof
        names = free.assembly.dof_names
        self.y[:n] = [free.y[names.index(body)] for body in self.assembly.dof_names]
        static_port = float(free.y[free.generator_dof])
        sc = self._scalars
        sc[L.S_PORT_OFFSET] = static_port - sc[L.S_PORT_ANGLE]
        sc[L.S_PORT_ANGLE] = static_port
        self.static_iterations = free.static_iterations

    def _static_result(self, status: int, iterations: int, imbalance: float, t0: float) -> None:
        """Raise the SolverError of a static deflection that was not found; else note its iterations."""
        if status != 0:
            what = "a singular stiffness" if status == 2 else f"{iterations} Newton iterations"
            raise SolverError(f"the static deflection at the initial load was not found ({what}, relative imbalance "
                              f"{imbalance:.3g}); start at rest instead (start = 'rest', FMU: start_at_rest)", t0)
        self.static_iterations = iterations

    def step(self, t: float, h: float, omega_rotor: float, phi_rotor: float, omega_gen: float, phi_gen: float,
             counter_torque_nm: float = 0.0, alpha_rotor: float = 0.0, jerk_rotor: float = 0.0) -> None:
        """Advance from ``t`` to ``t + h`` [s] with the inputs received at ``t``.

        ``counter_torque_nm`` [N m] is held over the step (``inertia`` interface; ignored by ``motion``);
        ``phi_gen`` is not used by ``inertia``. ``alpha_rotor`` [rad/s^2] and ``jerk_rotor`` [rad/s^3] are
        used with ``rotor_derivatives`` only. On failure the state is left as it was at ``t`` and
        :class:`SolverError` is raised. Hot path: one check, one kernel call, one status test.
        """
        if not self.initialized:
            self.initialize(t, omega_rotor, phi_rotor, omega_gen, phi_gen, counter_torque_nm)
        if not h > 0.0:
            raise ParameterError("step_size", h, "> 0")
        status, tau, h_fail, err = self._step(self._buffer, self._lay, self._sizes, t, h, omega_rotor, phi_rotor,
                                              omega_gen, phi_gen, counter_torque_nm, alpha_rotor, jerk_rotor)
        if status:  # OK is 0
            self._step_failed(status, t, tau, h_fail, err, (omega_rotor, phi_rotor, omega_gen, phi_gen,
                                                            counter_torque_nm, alpha_rotor, jerk_rotor))

    def _step_failed(self, status: int, t: float, tau: float, h_fail: float, err: float, inputs: tuple) -> None:
        """Raise the SolverError of a failed kernel step (the buffer is as it was at ``t``)."""
        c = self.control
        if status == L.NON_FINITE_INPUT:
            raise SolverError(non_finite_input(inputs), t)
        if status == L.STEP_TOO_SMALL:
            raise SolverError(f"step size {h_fail:.3g} s below h_min {c.h_min:.3g} s (error norm {err:.3g})", t + tau)
        raise SolverError(f"more than {c.max_steps} steps in one advance", t + tau)

    # ---------------------------------------------------------------- state
    def get_state(self) -> dict:
        """Complete internal state, integrator included (JSON-serialisable, exact float round trip).

        ``{"initialized": bool, "scalars": {name: value}, "state": {slot: [values]}}`` with the
        scalars and state slots of :mod:`components.model.kernel.layout` (the integrator's counters
        and step size in ``state["istate"]``, its Jacobian and both kept ``W^-1``, the last loads, ``y``).
        """
        return {
            "initialized": self.initialized,
            "scalars": dict(zip(L.SCALAR_NAMES, self._scalars.tolist())),
            "state": {name: self._views[name].ravel().tolist() for name in L.STATE_SLOTS},
        }

    def set_state(self, state: dict) -> None:
        """Restore a state produced by :meth:`get_state` (of a model of the same drivetrain and options)."""
        scalars = state["scalars"]
        slots = state["state"]
        if sorted(scalars) != sorted(L.SCALAR_NAMES) or sorted(slots) != sorted(L.STATE_SLOTS) or any(
                len(slots[name]) != self._views[name].size for name in L.STATE_SLOTS):
            raise ParameterError("state", "a state of another model",
                                 "a state of this gearbox (get_state of a model of the same drivetrain and options)")
        for name in L.STATE_SLOTS:
            self._views[name].ravel()[:] = slots[name]
        self._scalars[:] = [scalars[name] for name in L.SCALAR_NAMES]
        self.initialized = bool(state["initialized"])
        if self.initialized:
            self._module.outputs(self._buffer, self._lay, self._sizes)

"""Layout of the compiled gearbox kernel's data: buffer slots, scalar, state, settings and status indices.

Plain integers and names shared by :mod:`components.model.compiled_kernel` (numba code
reads them as compile-time constants), :mod:`components.model.gearbox_kernel` (which
fills the buffer) and the ahead-of-time compiled kernel's facade
(:mod:`components.model.kernel`), which must know them without importing numba.
"""

from __future__ import annotations

# columns of the per-mesh contact parameter table (gearbox_kernel.contact_table)
K0, EXPONENT, DAMPING, LAMBDA, HALF_JT, IMPACT, DMAX, CMAX, DEEP = range(9)
N_CONTACT_COLUMNS = 9

# entries of the integrator/state vector ``istate``: step-size memory and counters, Jacobian age, the
# ``h d`` of the active factorisation ``W^-1`` and of the other one kept (``HD_PREV``, -1: none), their
# time-derivative-basis flags, which of the two slots is active, eq. 11's running maximum
(H_NEXT, ACCEPTED, REJECTED, JACOBIANS, AGE, HD, BASIS_VALID, ALPHA_OUT_MAX, HD_PREV, BASIS_PREV_VALID,
 ACTIVE) = range(11)
N_ISTATE = 11

# entries of the settings vector ``control``
RTOL, ATOL_Q, ATOL_V, H_MIN, MAX_STEPS, JAC_MAX_AGE, OUT_KINEMATIC, OUT_RATE_INDEX = range(8)

# status codes of advance()
OK, STEP_TOO_SMALL, TOO_MANY_STEPS = 0, 1, 2

# slots of the flat buffer (gearbox_kernel.BufferLayout lists them with their shapes, in this order)
SLOTS = (
    "a_t", "a_port", "fast", "contact", "force_w", "defl_w", "acc_w", "bt", "stks", "stcs", "stks_port",
    "stcs_port", "inv_m", "fd_w", "fv_w", "phasing", "kappa", "force_rows", "factor_w", "slope_w", "sens_w",
    "f0", "f1", "fn", "k1", "k2", "k3", "y1", "yn", "rhs", "w_hdt", "da", "nz_index", "nz_value", "cos_alpha",
    "control",
    # the state a failed step restores: contiguous, so that saving it is one copy into "backup"
    "istate", "dq", "dv", "winv", "w_basis", "port_jac", "last_acc", "last_force", "last_defl", "y",
    "backup", "driver", "port", "scalars", "twist_q", "output_matrix", "outputs",
    # the generator speed and the loads before the inertia interface's re-anchoring (restored on failure)
    "anchor",
)
(A_T, A_PORT, FAST, CONTACT, FORCE_W, DEFL_W, ACC_W, BT, STKS, STCS, STKS_PORT, STCS_PORT, INV_M, FD_W, FV_W,
 PHASING, KAPPA, FORCE_ROWS, FACTOR_W, SLOPE_W, SENS_W, F0, F1, FN, K1, K2, K3, Y1, YN, RHS, W_HDT, DA, NZ_INDEX,
 NZ_VALUE, COS_ALPHA, CONTROL,
 ISTATE, DQ, DV, WINV, W_BASIS, PORT_JAC, LAST_ACC, LAST_FORCE, LAST_DEFL, Y, BACKUP, DRIVER, PORT, SCALARS,
 TWIST_Q, OUTPUT_MATRIX, OUTPUTS, ANCHOR) = range(len(SLOTS))
#: first and last slot of the restorable state
STATE_FIRST, STATE_LAST = ISTATE, Y

# scalars of GearboxModel kept in the buffer (``scalars`` slot)
SCALAR_NAMES = (
    "time_s", "driver_angle_rad", "driver_speed_rad_s", "driver_accel_rad_s2", "port_angle_rad",
    "port_speed_rad_s", "last_step_s", "last_omega_rotor", "last_omega_gen", "shaft_torque_average_nm",
    "output_twist_rad", "alpha_out_average_rad_s2", "angle0", "last_alpha", "kx", "twist_port", "shaft_k",
    "shaft_c",
)
(S_TIME, S_DRIVER_ANGLE, S_DRIVER_SPEED, S_DRIVER_ACCEL, S_PORT_ANGLE, S_PORT_SPEED, S_LAST_STEP, S_LAST_OMEGA_ROTOR,
 S_LAST_OMEGA_GEN, S_SHAFT_TORQUE_AVG, S_OUTPUT_TWIST, S_ALPHA_OUT_AVG, S_ANGLE0, S_LAST_ALPHA, S_KX, S_TWIST_PORT,
 S_SHAFT_K, S_SHAFT_C) = range(len(SCALAR_NAMES))

# entries of the integer vector ``dims``: sizes, flags, the generator's degree of freedom (-1: the motion
# interface, the generator is the port) and whether the rotor motion is extrapolated from its derivative inputs
D_N, D_M, D_TVS, D_SQRT_CFS, D_EXTRAPOLATE, D_END_TORQUE, D_GEN_DOF, D_ROTOR_DERIVATIVES = range(8)
N_DIMS = 8
NON_FINITE_INPUT = 3

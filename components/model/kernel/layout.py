"""Layout of the gearbox kernel's data: buffer slots and the indices of its state, settings, scalars and sizes.

One float64 buffer holds everything a communication step reads and writes (constants, work
arrays, state, inputs' curves, outputs), with an offset table: the compiled step is one call
with three array arguments, and saving or restoring the state is one copy of a contiguous
region. :class:`components.model.gearbox_model.GearboxModel` allocates and fills it.
"""

from __future__ import annotations

# entries of the integrator's state vector ``istate``: step-size memory and counters, Jacobian age, the ``h d`` of
# the active factorisation (``G^-1`` of ``W``, or its LU factors) and its slot, eq. 11's running maximum, the step
# the last communication step's first internal step proposed for the next one's (0: none yet), a clock; then per
# kept factorisation (``N_SLOTS``) its ``h d`` (-1: none), whether its time-derivative basis is valid, and when it
# was last used (the least recently used is replaced)
(H_NEXT, ACCEPTED, REJECTED, JACOBIANS, AGE, HD, ALPHA_OUT_MAX, ACTIVE, H_FIRST, CLOCK) = range(10)
#: factorisations kept: the step sizes of one communication step recur in the next (integrator's equal steps)
N_SLOTS = 4
SLOT_HD, SLOT_BASIS, SLOT_USED = 10, 10 + N_SLOTS, 10 + 2 * N_SLOTS
N_ISTATE = 10 + 3 * N_SLOTS

# entries of the settings vector ``control``
RTOL, ATOL_Q, ATOL_V, H_MIN, MAX_STEPS, JAC_MAX_AGE, OUT_KINEMATIC, OUT_RATE_INDEX = range(8)
N_CONTROL = 8

# status codes of a step
OK, STEP_TOO_SMALL, TOO_MANY_STEPS, NON_FINITE_INPUT = range(4)

# slots of the buffer, in this order (GearboxModel gives their shapes)
CONSTANT_SLOTS = ("a_t", "a_port", "fast", "contact", "stks", "stcs", "stks_port", "stcs_port", "inv_m", "phasing",
                  "kappa", "force_rows", "nz_index", "nz_value", "cos_alpha", "control", "twist_q", "offset",
                  "load_rates", "magnitudes", "fast_index", "fast_value", "out_index", "out_value", "jac_index")
WORK_SLOTS = ("z", "defl", "acc", "fd", "fv", "factor", "slope", "sens", "f0", "f1", "fn", "k1", "k2", "k3", "y1",
              "yn", "rhs", "w_hdt", "da", "w_ext", "sol")
#: the state a failed step restores: contiguous, so that saving it is one copy into "backup"
STATE_SLOTS = ("istate", "dq", "dv", "winvs", "pivots", "w_bases", "port_jac", "last_acc", "last_force", "last_defl",
               "y")
#: the inputs' curves, scalars, outputs, and the generator speed and loads before the inertia interface's
#: re-anchoring (restored on failure)
STEP_SLOTS = ("backup", "driver", "port", "scalars", "outputs", "anchor")
SLOTS = CONSTANT_SLOTS + WORK_SLOTS + STATE_SLOTS + STEP_SLOTS
(A_T, A_PORT, FAST, CONTACT, STKS, STCS, STKS_PORT, STCS_PORT, INV_M, PHASING, KAPPA, FORCE_ROWS, NZ_INDEX, NZ_VALUE,
 COS_ALPHA, CONTROL, TWIST_Q, OFFSET, LOAD_RATES, MAGNITUDES, FAST_INDEX, FAST_VALUE, OUT_INDEX, OUT_VALUE,
 JAC_INDEX,
 Z, DEFL, ACC, FD, FV, FACTOR, SLOPE, SENS, F0, F1, FN, K1, K2, K3, Y1, YN, RHS, W_HDT, DA, W_EXT, SOL,
 ISTATE, DQ, DV, WINVS, PIVOTS, W_BASES, PORT_JAC, LAST_ACC, LAST_FORCE, LAST_DEFL, Y,
 BACKUP, DRIVER, PORT, SCALARS, OUTPUTS, ANCHOR) = range(len(SLOTS))
#: first and last slot of the restorable state
STATE_FIRST, STATE_LAST = ISTATE, Y

# the model's scalars (``scalars`` slot)
SCALAR_NAMES = (
    "time_s", "driver_angle_rad", "driver_speed_rad_s", "driver_accel_rad_s2", "port_angle_rad",
    "port_speed_rad_s", "last_step_s", "last_omega_rotor", "last_omega_gen", "shaft_torque_average_nm",
    "output_twist_rad", "alpha_out_average_rad_s2", "last_alpha", "kx", "twist_port", "shaft_k", "shaft_c",
    "port_offset_rad", "generator_speed_rad_s",
)
(S_TIME, S_DRIVER_ANGLE, S_DRIVER_SPEED, S_DRIVER_ACCEL, S_PORT_ANGLE, S_PORT_SPEED, S_LAST_STEP, S_LAST_OMEGA_ROTOR,
 S_LAST_OMEGA_GEN, S_SHAFT_TORQUE_AVG, S_OUTPUT_TWIST, S_ALPHA_OUT_AVG, S_LAST_ALPHA, S_KX, S_TWIST_PORT,
 S_SHAFT_K, S_SHAFT_C, S_PORT_OFFSET, S_GEN_SPEED) = range(len(SCALAR_NAMES))

# entries of the integer vector ``dims``: sizes, flags, the generator's degree of freedom (-1: the motion
# interface, the generator is the port), whether the rotor motion is extrapolated from its derivative inputs,
# whether the generator speed is the gearbox's own (``inertia_own``: not re-anchored on the generator-speed input),
# the number of external terms (0: no external loads) and of output magnitudes (bearing forces)
(D_N, D_M, D_WIDTH, D_TVS, D_EXTRAPOLATE, D_END_TORQUE, D_GEN_DOF, D_ROTOR_DERIVATIVES, D_OWN_GEN_SPEED, D_EXT,
 D_MAGNITUDES) = range(11)
N_DIMS = 11

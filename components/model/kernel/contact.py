"""The gear contact laws of one mesh: CFS (eq. 2-4) and impact (eq. 1), with the flank-consistent clipping.

A mesh's parameters are one row of the contact table (:func:`components.model.contact.contact_table`),
its columns named below. The force acts along the line of action; a positive deflection
``d`` compresses the flank loaded in normal power flow.

* **CFS** (eq. 2): ``F = k0 sgn(d_BL) |d_BL|^e + c0 |d_BL| d_BL_dot`` on the tanh-regularised
  indentation of eq. 3-4, ``d_BL = d + (x1 tanh(lambda x1) - x2 tanh(lambda x2)) / 2`` with
  ``x1,2 = d -+ j_t/2`` (exactly ``d -+ j_t/2`` beyond ``DEEP``, where tanh is 1 in double precision).
* **impact** (eq. 1): the same stiffness term on the sharp penetration, damping
  ``STEP(p, 0, 0, d_max, c_max) d_dot`` with MSC.Adams' cubic STEP.
* **Clipping**: a flank pushes, never pulls. The force is zero (and so are its derivatives)
  wherever it would point against the flank in contact; the literal eq. 2 would let the
  damping term glue separating teeth (the paper's sign rule).

Adding a law: a code in :data:`LAWS` and :data:`LAW_DESCRIPTIONS`, its columns if it needs new ones, a branch in
:func:`contact_force` (and :func:`stiffness_sensitivity` if its force is not linear in ``k0``).
"""

from __future__ import annotations

import math

#: contact laws by code (the column ``LAW`` of a mesh's row), and what each is
LAWS = ("cfs", "impact")
LAW_DESCRIPTIONS = ("CFS (eq. 2-4)", "impact (eq. 1)")
CFS, IMPACT = range(len(LAWS))
#: columns of a mesh's row of the contact table
K0, EXPONENT, DAMPING, LAMBDA, HALF_JT, LAW, DMAX, CMAX, DEEP = range(9)
N_CONTACT_COLUMNS = 9


def sign(x):
    """-1, 0 or 1."""
    if x > 0.0:
        return 1.0
    if x < 0.0:
        return -1.0
    return 0.0


def _power_minus_one(x, e):
    """``x^(e - 1)`` for ``x >= 0`` (the square root, exactly, for the Hertzian e = 3/2)."""
    return math.sqrt(x) if e == 1.5 else x ** (e - 1.0)


def regularised(d, p):
    """``(d_BL, d d_BL/d d, d^2 d_BL/d d^2)`` of eq. 3-4 for the deflection ``d`` [m] of a mesh with row ``p``."""
    h = p[HALF_JT]
    if abs(d) >= p[DEEP]:  # tanh saturated exactly: d_BL = d -+ j_t/2
        return d - sign(d) * h, 1.0, 0.0
    lam = p[LAMBDA]
    x1 = d - h
    x2 = d + h
    u1 = lam * x1
    u2 = lam * x2
    t1 = math.tanh(u1)
    t2 = math.tanh(u2)
    s1 = 1.0 - t1 * t1
    s2 = 1.0 - t2 * t2
    return (d + 0.5 * (x1 * t1 - x2 * t2),  # eq. 3, 4
            1.0 + 0.5 * (t1 + u1 * s1 - t2 - u2 * s2),
            lam * (s1 * (1.0 - u1 * t1) - s2 * (1.0 - u2 * t2)))


def contact_force(d, rate, factor, p):
    """Force [N], dF/dd [N/m], dF/d(rate) [N s/m] and elastic part [N] of one mesh.

    Parameters
    ----------
    d, rate : float
        Deflection [m] and its rate [m/s].
    factor : float
        Multiplier on ``k0`` (time-varying mesh stiffness; 1 for the paper's model).
    p : ndarray
        The mesh's row of the contact table.
    """
    k = p[K0] * factor
    e = p[EXPONENT]
    if p[LAW] == IMPACT:  # eq. 1: sharp backlash, cubic STEP damping
        h = p[HALF_JT]
        pen = d - h if d > h else (d + h if d < -h else 0.0)
        abs_p = abs(pen)
        sgn = sign(pen)
        pow_em1 = _power_minus_one(abs_p, e)
        elastic = k * sgn * pow_em1 * abs_p
        s = min(max(abs_p / p[DMAX], 0.0), 1.0)
        step = p[CMAX] * s * s * (3.0 - 2.0 * s)  # STEP(p, 0, 0, d_max, c_max)
        force = elastic + step * rate
        df_dd = k * e * pow_em1 + p[CMAX] * 6.0 * s * (1.0 - s) / p[DMAX] * sgn * rate
        df_dv = step
        active = force * sgn > 0.0
    else:  # CFS, eq. 2-4
        d_bl, d_bl_p, d_bl_pp = regularised(d, p)
        abs_bl = abs(d_bl)
        sgn = sign(d_bl)
        pow_em1 = _power_minus_one(abs_bl, e)
        elastic = k * sgn * pow_em1 * abs_bl  # k0 sgn(d_BL) |d_BL|^e (eq. 2)
        c = p[DAMPING]
        rate_bl = d_bl_p * rate
        force = elastic + c * abs_bl * rate_bl  # + c0 |d_BL| d_BL_dot (eq. 2, 9)
        df_dd = (k * e * pow_em1 + c * sgn * rate_bl) * d_bl_p + c * abs_bl * d_bl_pp * rate
        df_dv = c * abs_bl * d_bl_p
        active = force * sign(d) > 0.0
    if not active:  # flank-consistent clipping
        return 0.0, 0.0, 0.0, elastic
    return force, df_dd, df_dv, elastic


def stiffness_sensitivity(d, rate, factor, p):
    """dF / d(stiffness factor) of one mesh [N]: ``k0 sgn(d_BL) |d_BL|^e`` where the flank is in contact, else 0.

    The force is linear in the factor on ``k0`` (both laws), so this is the elastic force per unit factor.
    """
    force, _, _, elastic = contact_force(d, rate, factor, p)
    return elastic / factor if force != 0.0 else 0.0


def _every_mesh(defl, factor, contact):
    """:func:`contact_force` of every mesh at deflections ``defl`` (rows: deflection, rate), on Python floats.

    What the numpy forms below evaluate: the same law on the same numbers (Python's float arithmetic and
    :mod:`math` are the IEEE operations the compiled loops run; numpy's vectorised ``tanh`` is not, it differs
    in the last bit), without numpy's cost per element read (~2.5 x faster for the paper's 13 meshes than the
    loop over the arrays, and than the law vectorised over the meshes).
    """
    d, rate = defl.tolist()
    return list(map(contact_force, d, rate, factor.tolist(), table_rows(contact)))


#: contact tables whose rows :func:`table_rows` keeps as lists, at most (all dropped when one more is asked for)
KEPT_TABLES = 8
_kept_rows: dict = {}


def table_rows(contact):
    """The rows of a contact table as lists of Python floats, kept by the table's identity (numpy form only).

    A table is written once, when its model's buffer is made, and never changed in place; a model evaluates its
    meshes with the same table object every time (the kept views of :func:`components.model.kernel.step.views`),
    so its rows are read once (``tolist`` of the 13 x 9 table of the paper's gearbox costs ~1.5 us, a tenth of the
    contact laws it feeds). A kept entry holds the table, so no other object can take its identity; dict
    operations are atomic, so threads stepping models of one process may share it.
    """
    kept = _kept_rows.get(id(contact))
    if kept is not None and kept[0] is contact:
        return kept[1]
    if len(_kept_rows) >= KEPT_TABLES:
        _kept_rows.clear()
    rows = contact.tolist()
    _kept_rows[id(contact)] = (contact, rows)
    return rows


def mesh_forces(defl, factor, contact, force, elastic):
    """Forces and their elastic parts of every mesh at deflections ``defl`` (rows: deflection, rate)."""
    laws = _every_mesh(defl, factor, contact)
    force[:] = [law[0] for law in laws]
    elastic[:] = [law[3] for law in laws]


def forces(defl, factor, contact, out):
    """Force of every mesh at deflections ``defl`` (rows: deflection, rate) into ``out`` [N]."""
    out[:] = [law[0] for law in _every_mesh(defl, factor, contact)]


def stiffness_force_rates(defl, factor, contact, slope, speed, out):
    """dF/dt [N/s] of every mesh from its stiffness factor's rate ``slope speed`` (:func:`stiffness_sensitivity`)."""
    d, rate = defl.tolist()
    out[:] = list(map(stiffness_sensitivity, d, rate, factor.tolist(), table_rows(contact)))
    out *= slope * speed


def force_slopes(defl, factor, contact, d_force_d_deflection, d_force_d_rate):
    """dF/dd [N/m] and dF/d(rate) [N s/m] of every mesh at deflections ``defl`` (rows: deflection, rate)."""
    laws = _every_mesh(defl, factor, contact)
    d_force_d_deflection[:] = [law[1] for law in laws]
    d_force_d_rate[:] = [law[2] for law in laws]


# ---------------------------------------------------------------- the compiled forms
def _mesh_forces_loop(defl, factor, contact, force, elastic):
    for i in range(force.shape[0]):
        f, _, _, el = contact_force(defl[0, i], defl[1, i], factor[i], contact[i])
        force[i] = f
        elastic[i] = el


def _forces_loop(defl, factor, contact, out):
    for i in range(out.shape[0]):
        out[i] = contact_force(defl[0, i], defl[1, i], factor[i], contact[i])[0]


def _stiffness_force_rates_loop(defl, factor, contact, slope, speed, out):
    for i in range(out.shape[0]):
        out[i] = stiffness_sensitivity(defl[0, i], defl[1, i], factor[i], contact[i]) * (slope[i] * speed)


def _force_slopes_loop(defl, factor, contact, d_force_d_deflection, d_force_d_rate):
    for i in range(d_force_d_deflection.shape[0]):
        _, d_force_d_deflection[i], d_force_d_rate[i], _ = contact_force(defl[0, i], defl[1, i], factor[i], contact[i])


#: the loops numba compiles in place of the numpy forms (see :mod:`components.compile.jit`)
COMPILED = {"mesh_forces": _mesh_forces_loop, "forces": _forces_loop, "force_slopes": _force_slopes_loop,
            "stiffness_force_rates": _stiffness_force_rates_loop}
#: inlined into their callers by numba; the loops over the meshes above are compiled once and called (inlined at each
#: of their sites they cost the ahead-of-time build ~15 s more and the step no time)
INLINE = ("sign", "_power_minus_one", "regularised", "contact_force")

"""The Gearbox's outputs: their names, the linear map from the kernel's ``z`` and the force magnitudes.

:class:`components.model.gearbox_model.GearboxModel` hands these to its kernel
(:func:`components.model.kernel.step.outputs`), which writes every output at every step.
"""

from __future__ import annotations

import numpy as np

from .assembly import Assembly


def gearbox_outputs(a: Assembly, gearbox_dofs: np.ndarray, out_member: int) -> tuple[np.ndarray, np.ndarray, list[str]]:
    """The linear map of the outputs, the index pairs of the magnitudes and every output's name.

    Every output but the step-averaged shaft torque and the bearing-force magnitudes is linear in the
    kernel's ``z`` (contact forces, ``q``, ``v``, port angle and speed, driver speed and acceleration):
    the end-of-step shaft torque, ``omega_out``, the rotor torque, the contact forces, the shaft torques,
    the speeds of the rotations, the displacements of the translations, and per bearing its force
    components and speed; a magnitude is ``hypot`` of a bearing's two components
    (:func:`components.model.kernel.step.outputs`).

    Parameters
    ----------
    a : Assembly
        The Gearbox's assembly.
    gearbox_dofs : ndarray of int
        The degrees of freedom whose speeds (or displacements) are outputs.
    out_member : int
        The degree of freedom of the last stage's output member (``omega_out``).

    Returns
    -------
    matrix : ndarray, shape (n_z, n_linear)
        The linear outputs ``z @ matrix``.
    pairs : ndarray, shape (n_magnitudes, 2)
        The linear outputs whose ``hypot`` each magnitude is (-1: none).
    names : list of str
        Every output's name, in the kernel's order.
    """
    n, m = a.n_dof, a.n_mesh
    rows = m + 2 * n + 4
    shafts = np.zeros((rows, a.n_shaft))
    shafts[m : m + n] = (a.shaft_k[:, None] * a.S).T
    shafts[m + n : m + 2 * n] = (a.shaft_c[:, None] * a.S).T
    shafts[m + 2 * n] = a.shaft_k * a.port_twist
    shafts[m + 2 * n + 1] = a.shaft_c * a.port_twist
    bearings = np.zeros((rows, a.n_spring))
    bearings[m : m + n] = (a.bearing_k[:, None] * a.B).T
    bearings[m + n : m + 2 * n] = (a.bearing_c[:, None] * a.B).T
    speeds = np.zeros((rows, n))
    speeds[m + n : m + 2 * n] = np.eye(n)
    speeds[m + 2 * n + 2] = a.kinematic_ratio
    forces = np.zeros((rows, m))
    forces[:m] = np.eye(m)
    rotor = shafts @ a.s_driver + bearings @ a.b_driver  # shaft and bearing reactions on the driven carrier
    rotor[:m] += a.BT_driver  # mesh reactions
    rotor[m + 2 * n + 3] += a.driver_inertia_kgm2  # carrier (and orbital planet) inertia
    rotations = [j for j in gearbox_dofs if a.bodies[a.free[j]].rotation]
    translations = [j for j in gearbox_dofs if not a.bodies[a.free[j]].rotation]
    positions = np.zeros((rows, len(translations)))
    positions[m + np.array(translations, dtype=int), np.arange(len(translations))] = 1.0
    columns = [shafts[:, -1:], speeds[:, [out_member]], rotor[:, None], forces, shafts,
               speeds[:, rotations], positions]
    names = (["shaft_torque_end", "omega_out", "torque_rotor"] + a.mesh_names + [f"{s}.torque" for s in a.shaft_names]
             + [f"{a.dof_names[j]}.omega" for j in rotations] + [a.dof_names[j] for j in translations])
    pairs = []
    for element in a.elements:
        first = len(names)
        columns.append(bearings[:, list(element.rows)])
        names += [f"{element.name}.{'torque' if c == 'torque' else 'F_' + c}" for c in element.components]
        if element.kind != "torsion":
            pairs.append((first, first + 1 if len(element.rows) > 1 else -1))
        if element.speed:
            column = _speed_column(a, element.speed[0], rows)
            if len(element.speed) > 1:
                column = column - _speed_column(a, element.speed[1], rows)
            columns.append(column[:, None])
            names.append(f"{element.name}.omega")
    magnitudes = [f"{e.name}.F" for e in a.elements if e.kind != "torsion"]
    output_names = (["shaft_torque", "shaft_torque_avg"] + names + magnitudes
                    + ["alpha_out", "alpha_out_max", "omega_generator"])
    return np.column_stack(columns), np.array(pairs, dtype=float).reshape(-1, 2), output_names


def _speed_column(a: Assembly, body: str, rows: int) -> np.ndarray:
    """The output column of a body's absolute speed ``kappa omega_in + v`` (the driver: ``omega_in``)."""
    n, m = a.n_dof, a.n_mesh
    j = [b.name for b in a.bodies].index(body)
    column = np.zeros(rows)
    column[m + 2 * n + 2] = a.kinematic_ratio_all[j]
    free = np.flatnonzero(a.free == j)
    if free.size:
        column[m + n + int(free[0])] = 1.0
    return column


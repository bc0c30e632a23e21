"""The linearised drivetrain with its rotor: held (a prescribed speed) or torque-driven (free).

:func:`components.analysis.equilibrium.linearise` holds the stage-1 carrier at the
prescribed rotor speed: the wind source of the paper prescribes it, so a rotor-held
model is the right one there. A torque-driven rotor (the Rotor FMU,
``J_r omega_r' = T_aero - T_gearbox``) leaves the carrier free, and the drivetrain's
lowest mode is then the free-free torsion of rotor against generator (about 2.2 Hz for
the NREL 5-MW instead of the 2.0 Hz of the held rotor).

Coordinates ``z``: the deviation angles from the steady rotation of every body, absolute
(so the inertia matrix stays diagonal) - the rotor (carrying the stage-1 carrier when the
main shaft is rigid), with a main shaft its gearbox end (the Rotor FMU's lumped
``carrier_inertia`` plus the stage-1 carrier), then the gearbox's free bodies. The
gearbox's own deviation coordinates are ``q = z_free - kappa z_carrier``; its meshes and
shafts see ``q`` only, so

    K_z = P^T K P + k_ms s s^T,   C_z = P^T C P + c_ms s s^T,   P = [-kappa e_c^T | I]

(``s`` the main shaft's twist row, ``k_ms``/``c_ms`` its stiffness and damping). With the
rotor driven by a torque and the generator braked by one, nothing holds the train: it has a
rigid-body mode ``z = (1, [1], kappa)``, an eigenvalue 0 that makes the first-order
system defective. Its flexible modes are mass-orthogonal to it (the momentum conjugate to the
rigid rotation, ``sum_j kappa_j J_j z_j'``, is zero), so the rotor's coordinate follows from the
others, ``z_r = -sum_j kappa_j J_j z_j / J_r`` (``z = B y``, ``y`` the other coordinates), and
the reduced system ``B^T M B y'' + B^T C B y' + B^T K B y = 0`` has the flexible modes only.
A generator torque that depends on speed (a controller) is held constant here.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import ParameterError
from ..model.rotor import RotorParameters
from .equilibrium import LinearModel

#: name of the rotor's coordinate
ROTOR_BODY = "rotor"


@dataclass(frozen=True)
class CoupledModel:
    """A linearised drivetrain in the coordinates of its modal analysis.

    Attributes
    ----------
    mass, damping, stiffness : ndarray, shape (n_y, n_y)
        The (reduced) matrices whose modes are the drivetrain's.
    basis : ndarray, shape (n_z, n_y)
        Body deviations ``z = basis @ y``.
    body_names : list of str
        Names of the ``z`` coordinates (the held model: the gearbox's free bodies).
    body_inertia_kgm2 : ndarray, shape (n_z,)
        Diagonal inertia in ``z`` (kinetic energy ``0.5 J z'^2``).
    kinematic_ratio : ndarray, shape (n_z,)
        Speed of each body per unit rotor speed (1 for the rotor and the carrier).
    to_gearbox : ndarray, shape (n_q, n_z)
        The gearbox's deviation coordinates ``q = to_gearbox @ z`` (strain of meshes and shafts).
    main_shaft : tuple of (ndarray, float) or None
        With a flexible main shaft: its twist row over ``z`` and its stiffness [N m/rad].
    rotor : RotorParameters or None
        None: the rotor is held (a prescribed speed), or there is none (a free input member).
    """

    mass: np.ndarray
    damping: np.ndarray
    stiffness: np.ndarray
    basis: np.ndarray
    body_names: list[str]
    body_inertia_kgm2: np.ndarray
    kinematic_ratio: np.ndarray
    to_gearbox: np.ndarray
    main_shaft: tuple[np.ndarray, float] | None
    rotor: RotorParameters | None

    @property
    def held(self) -> bool:
        """True if the rotor speed is prescribed (the input member is no coordinate)."""
        return len(self.body_names) == self.mass.shape[0] and self.rotor is None


def held_rotor(model: LinearModel) -> CoupledModel:
    """The rotor-held model as it is: ``z = y = q``."""
    n = model.mass.shape[0]
    eye = np.eye(n)
    return CoupledModel(model.mass, model.damping, model.stiffness, eye, list(model.dof_names),
                        np.diag(model.mass).copy(), model.assembly.kinematic_ratio.copy(), eye, None, None)


def free_rotor(model: LinearModel, rotor: RotorParameters | None) -> CoupledModel:
    """The drivetrain driven by a torque on a rotor inertia (and main shaft), rigid-body mode removed.

    Parameters
    ----------
    model : LinearModel
        The rotor-held linearisation (its stiffness and damping are the gearbox's).
    rotor : RotorParameters or None
        Rotor inertia; with ``shaft_stiffness > 0`` the main shaft (stiffness, damping) and
        the inertia lumped at its gearbox end. None: no rotor, the stage-1 input member is free
        with its own inertia (a gearbox on its own, as in the free vibration of Lin and Parker, 1999).
    """
    if rotor is not None and not isinstance(rotor, RotorParameters):
        raise ParameterError("rotor", rotor, "a RotorParameters")
    a = model.assembly
    n_q = model.mass.shape[0]
    kappa = a.kinematic_ratio
    carrier = a.bodies[a.driver].name
    j_driver = a.driver_inertia_kgm2
    if rotor is None:
        names = [carrier]
        inertia_lead = [j_driver]
    elif rotor.has_shaft:
        names = [ROTOR_BODY, carrier]
        inertia_lead = [rotor.inertia_kgm2, rotor.carrier_inertia_kgm2 + j_driver]
    else:
        names = [ROTOR_BODY]
        inertia_lead = [rotor.inertia_kgm2 + j_driver]
    lead = len(names)
    c_index = lead - 1  # the coordinate that turns the stage-1 carrier
    n_z = lead + n_q
    p = np.zeros((n_q, n_z))  # q = P z
    p[:, c_index] = -kappa
    p[:, lead:] = np.eye(n_q)
    k_z = p.T @ model.stiffness @ p
    c_z = p.T @ model.damping @ p
    shaft = None
    if rotor is not None and rotor.has_shaft:
        s = np.zeros(n_z)
        s[0], s[1] = 1.0, -1.0
        k_z += rotor.shaft_stiffness_nm_rad * np.outer(s, s)
        c_z += rotor.shaft_damping_nms_rad * np.outer(s, s)
        shaft = (s, rotor.shaft_stiffness_nm_rad)
    inertia = np.concatenate([inertia_lead, np.diag(model.mass)])
    ratio = np.concatenate([np.ones(lead), kappa])
    # no rigid-body motion: r^T M z = 0 with r = ratio, so z_rotor = -sum_j kappa_j J_j z_j / J_rotor
    basis = np.zeros((n_z, n_z - 1))
    basis[0, :] = -(ratio[1:] * inertia[1:]) / inertia[0]
    basis[1:, :] = np.eye(n_z - 1)
    m_z = np.diag(inertia)
    reduce = lambda x: basis.T @ x @ basis  # noqa: E731
    m_y, c_y, k_y = reduce(m_z), reduce(c_z), reduce(k_z)
    return CoupledModel(0.5 * (m_y + m_y.T), 0.5 * (c_y + c_y.T), 0.5 * (k_y + k_y.T), basis,
                        names + list(model.dof_names), inertia, ratio, p, shaft, rotor)


def coupled(model: LinearModel, rotor: RotorParameters | None, free_input: bool = False) -> CoupledModel:
    """:func:`held_rotor` without a rotor, else :func:`free_rotor`; ``free_input``: the input member free, no rotor."""
    if free_input:
        if rotor is not None:
            raise ParameterError("free_input", True, "no rotor (a free input member has no rotor on it)")
        return free_rotor(model, None)
    return held_rotor(model) if rotor is None else free_rotor(model, rotor)

"""Modes of a drivetrain at an operating point: named bodies, energy shares, mode kinds.

:func:`drivetrain_modes` linearises the drivetrain at its static equilibrium
(:mod:`components.analysis.equilibrium`), takes its undamped and complex modes
(:mod:`components.analysis.eigen`) and reports them with body names, the
kinetic-energy share of every body and the strain-energy share of every mesh group
and shaft.

Mode kinds (Lin and Parker, 1999): *planet modes* - only the planets of one stage move, the
central members (sun, carrier, ring; the other stages) stand still; multiplicity ``n - 1`` in a
torsional model with ``n`` equally spaced identical planets, ``n - 3`` in a lateral-torsional one.
*Rotational modes* - no central member translates; simple. *Translational modes* (lateral-torsional
stages) - no central member rotates, they translate; multiplicity 2. A mode that fits none (unequal
planets, several lateral stages coupled) is *coupled*. Whether a coordinate moves is judged by its
share of the modal kinetic energy (translations and rotations alike).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, replace

import numpy as np

from ..model.assembly import Assembly
from ..model.drivetrain import Drivetrain
from ..model.rotor import RotorParameters
from .eigen import Mode, StateSpaceModes, modal_analysis, normalise_shape
from .equilibrium import LinearModel, OperatingPoint, linearise
from .rotor_coupling import ROTOR_BODY, coupled

#: name of the main shaft's strain-energy group (torque-driven rotor with a flexible main shaft)
MAIN_SHAFT = "main_shaft"

#: Shape components below this fraction of the largest count as "not moving" (planet modes of a torsional model).
STILL_TOLERANCE = 1e-6
#: Shares of the modal kinetic energy below this count as "not moving" (the kinds of lateral-torsional modes).
STILL_ENERGY = 1e-9
#: Natural frequencies within this relative distance belong to one repeated mode (multiplicity).
REPEATED_TOLERANCE = 1e-6


# --------------------------------------------------------------------------- drivetrain modes
def _element_groups(a: Assembly) -> tuple[list[str], np.ndarray]:
    """Names of mesh groups / shafts / bearings and the (n_group, n_mesh + n_shaft + n_spring) membership matrix.

    A stage's planet bearings are one group, as its meshes of one kind are.
    """
    names: list[str] = []
    member = []

    def add(group: str) -> None:
        if group not in names:
            names.append(group)
        member.append(names.index(group))

    for mesh in a.meshes:
        add(f"{mesh.stage}.{mesh.kind}")
    for s in a.shafts:
        add(s.name)
    row_group = [""] * a.n_spring
    for e in a.elements:
        for r in e.rows:
            row_group[r] = f"{e.stage}.planet_bearings" if e.name.startswith(f"{e.stage}.planet_bearing[") else e.name
    for group in row_group:
        add(group)
    mat = np.zeros((len(names), len(member)))
    mat[member, np.arange(len(member))] = 1.0
    return names, mat


def _share_text(names: list[str], share: np.ndarray, cover: float = 0.9, at_most: int = 3) -> str:
    order = np.argsort(share)[::-1]
    parts, total = [], 0.0
    for j in order[:at_most]:
        parts.append(f"{names[j]} {100 * share[j]:.0f}%")
        total += share[j]
        if total >= cover:
            break
    return ", ".join(parts)


@dataclass(frozen=True)
class DrivetrainMode:
    """A mode of the linearised drivetrain, with names.

    Attributes
    ----------
    mode : Mode
        The generic mode (frequencies, damping, flags, shapes).
    kind : str
        ``"planet"`` (only the planets of ``stage`` move), ``"rotational"``, ``"translational"``, ``"coupled"``
        or ``"rigid"`` (module docstring).
    stage : str or None
        The stage of a planet mode.
    shape_referred : ndarray, shape (n_dof,)
        Deviation angles referred to the rotor, ``q_i / kappa_i`` (a rigid rotation of the
        whole train is uniform), normalised to a largest component of +1.
    dominant_bodies : str
        Bodies holding most of the modal kinetic energy, e.g. ``"generator 100%"`` (the
        planets of a stage counted together as ``"stage1.planets"``).
    strain_energy_fraction : dict of str -> float
        Share of the modal strain energy per mesh group (``stage1.sun_planet``, ...) and shaft.
    dominant_elements : str
        The springs holding most of the modal strain energy.
    multiplicity : int
        How many modes of this kind (and stage) share its natural frequency (Lin and Parker: 1, 2 or n - 3).
    """

    mode: Mode
    kind: str
    stage: str | None
    shape_referred: np.ndarray
    dominant_bodies: str
    strain_energy_fraction: dict[str, float]
    dominant_elements: str
    multiplicity: int = 1

    def as_dict(self, dof_names: list[str]) -> dict:
        """Plain dict (JSON-ready)."""
        m = self.mode
        lam = m.eigenvalue
        return {
            "mode": m.index,
            "kind": self.kind,
            "stage": self.stage,
            "multiplicity": self.multiplicity,
            "undamped_frequency_hz": m.undamped_frequency_hz,
            "damped_frequency_hz": None if m.overdamped else m.damped_frequency_hz,
            "damping_ratio": m.damping_ratio,
            "modal_damping_ratio": m.modal_damping_ratio,
            "overdamped": m.overdamped,
            "eigenvalue_per_s": None if lam is None else [lam.real, lam.imag],
            "dominant_bodies": self.dominant_bodies,
            "dominant_elements": self.dominant_elements,
            "kinetic_energy_fraction": dict(zip(dof_names, map(float, m.energy_fraction))),
            "strain_energy_fraction": dict(self.strain_energy_fraction),
            "shape": dict(zip(dof_names, map(float, m.shape))),
            "shape_referred": dict(zip(dof_names, map(float, self.shape_referred))),
        }


@dataclass(frozen=True)
class DrivetrainModalAnalysis:
    """Modal analysis of a drivetrain at an operating point (see :func:`drivetrain_modes`).

    Attributes
    ----------
    modes : list of DrivetrainMode
        In order of undamped natural frequency.
    model : LinearModel
        The linearisation (matrices, equilibrium, assembly).
    state_space : StateSpaceModes
        All ``2 n`` eigenvalues with right and left eigenvectors (of the reduced coordinates
        with a torque-driven rotor).
    bodies : list of str, optional
        Names of the shapes' components (default: the model's degrees of freedom).
    rotor : RotorParameters or None
        The torque-driven rotor; None: the rotor speed is held (or the input is free).
    free_input : bool
        The stage-1 input member is free, no rotor on it.
    """

    modes: list[DrivetrainMode]
    model: LinearModel
    state_space: StateSpaceModes
    bodies: list[str] | None = None
    rotor: RotorParameters | None = None
    free_input: bool = False

    @property
    def dof_names(self) -> list[str]:
        """Names of the bodies of the mode shapes (with a torque-driven rotor: the rotor first)."""
        return list(self.model.dof_names) if self.bodies is None else self.bodies

    @property
    def rotor_held(self) -> bool:
        """True if the rotor speed was held (prescribed); False with a torque-driven rotor or a free input."""
        return self.rotor is None and not self.free_input

    @property
    def underdamped(self) -> list[DrivetrainMode]:
        """The oscillatory modes."""
        return [m for m in self.modes if not m.mode.overdamped]

    @property
    def overdamped_roots_per_s(self) -> np.ndarray:
        """Decay rates ``-lambda`` of the real eigenvalues [1/s], ascending."""
        ss = self.state_space
        lam = ss.eigenvalues[~ss.is_complex()]
        return np.sort(-lam.real)

    def table_rows(self) -> list[dict]:
        """One flat row per mode (CSV-ready): frequencies, damping, flags, dominant bodies, referred shape."""
        rows = []
        for dm in self.modes:
            m = dm.mode
            row = {
                "mode": m.index,
                "kind": dm.kind if dm.stage is None else f"{dm.kind} ({dm.stage})",
                "multiplicity": dm.multiplicity,
                "undamped_frequency_hz": m.undamped_frequency_hz,
                "damped_frequency_hz": m.damped_frequency_hz,
                "damping_ratio": m.damping_ratio,
                "modal_damping_ratio": m.modal_damping_ratio,
                "overdamped": m.overdamped,
                "dominant_bodies": dm.dominant_bodies,
                "dominant_elements": dm.dominant_elements,
            }
            for name, x in zip(self.dof_names, dm.shape_referred):
                row[f"shape_referred[{name}]"] = float(x)
            rows.append(row)
        return rows

    def as_dict(self) -> dict:
        """Plain dict (JSON-ready): operating point, equilibrium, modes, overdamped roots."""
        a = self.model.assembly
        eq = self.model.equilibrium
        return {
            "operating_point": self.model.operating_point.as_dict(),
            "rotor": ("free input member, no rotor" if self.free_input else "held (prescribed speed)")
            if self.rotor is None else {
                "driven_by": "torque", "inertia_kgm2": self.rotor.inertia_kgm2,
                "shaft_stiffness_nm_rad": self.rotor.shaft_stiffness_nm_rad,
                "shaft_damping_nms_rad": self.rotor.shaft_damping_nms_rad,
                "carrier_inertia_kgm2": self.rotor.carrier_inertia_kgm2},
            "dof_names": list(self.dof_names),
            "equilibrium": {
                "contact_force_n": dict(zip(a.mesh_names, map(float, eq.contact_force_n))),
                "mesh_stiffness_n_per_m": dict(zip(a.mesh_names, map(float, eq.mesh_stiffness_n_per_m))),
                "mesh_damping_ns_per_m": dict(zip(a.mesh_names, map(float, eq.mesh_damping_ns_per_m))),
                "shaft_torque_nm": dict(zip(a.shaft_names, map(float, eq.shaft_torque_nm))),
                "rotor_torque_nm": eq.rotor_torque_nm,
                "newton_iterations": eq.iterations,
            },
            "modes": [m.as_dict(self.dof_names) for m in self.modes],
            "n_underdamped": len(self.underdamped),
            "overdamped_roots_per_s": [float(x) for x in self.overdamped_roots_per_s],
        }


def _kind(energy: np.ndarray, roles: list[str], stages: list[str], rotation: list[bool],
          rigid: bool) -> tuple[str, str | None]:
    """The kind of a mode from the kinetic-energy shares of its coordinates (module docstring) and its stage."""
    moving = energy > STILL_ENERGY
    planets = {stages[i] for i in np.flatnonzero(moving) if roles[i] == "planet"}
    central = moving & np.array([r != "planet" for r in roles])
    if rigid:
        return "rigid", None
    if moving.any() and not central.any() and len(planets) == 1:
        return "planet", planets.pop()
    if not (central & ~np.array(rotation)).any():
        return "rotational", None
    if not (central & np.array(rotation)).any():
        return "translational", None
    return "coupled", None


def _multiplicities(out: list[DrivetrainMode]) -> list[DrivetrainMode]:
    """Each mode with the number of modes of its kind and stage at its natural frequency."""
    f = np.array([dm.mode.system_frequency_hz for dm in out])
    counts = []
    for dm, fi in zip(out, f):
        same = [o for o, fj in zip(out, f) if o.kind == dm.kind and o.stage == dm.stage
                and abs(fj - fi) <= REPEATED_TOLERANCE * max(abs(fi), 1e-300)]
        counts.append(len(same))
    return [replace(dm, multiplicity=c) for dm, c in zip(out, counts)]


def drivetrain_modes(drivetrain: Drivetrain, operating_point: OperatingPoint, stiffness_factor: np.ndarray | float = 1.0,
                     rotor: RotorParameters | None = None, free_input: bool = False) -> DrivetrainModalAnalysis:
    """Linearise a drivetrain at an operating point and analyse its modes.

    Parameters
    ----------
    drivetrain : Drivetrain
        E.g. ``table6_gearbox()``; a scenario supplies its drivetrain the same way.
    operating_point : OperatingPoint
        Rotor speed and output counter torque (e.g. ``OperatingPoint.from_rpm(16, 25.4e3)``
        or ``OperatingPoint.of_drivetrain(dt, omega)``).
    stiffness_factor : float or ndarray
        Mesh stiffness multiplier (1: mean stiffness).
    rotor : RotorParameters, optional
        A torque-driven rotor (and main shaft) on the stage-1 carrier: the drivetrain is free
        at both ends (:func:`components.analysis.rotor_coupling.free_rotor`). None: the rotor
        speed is held (a wind source prescribes it).
    free_input : bool
        The stage-1 input member free and no rotor on it (a gearbox on its own; Lin and Parker's free
        vibration); its rigid-body rotation is removed.

    Returns
    -------
    DrivetrainModalAnalysis
    """
    model = linearise(drivetrain, operating_point, stiffness_factor)
    a = model.assembly
    cm = coupled(model, rotor, free_input)
    modes, ss, _ = modal_analysis(cm.mass, cm.damping, cm.stiffness)
    names = cm.body_names
    lead = len(names) - a.n_dof
    driver = a.bodies[a.driver]
    coords = [driver if name != ROTOR_BODY else None for name in names[:lead]] + [a.bodies[j] for j in a.free]
    roles = [b.role if b is not None else "rotor" for b in coords]
    stages = [b.stage if b is not None else ROTOR_BODY for b in coords]
    rotation = [b.rotation if b is not None else True for b in coords]
    group_names, membership = _element_groups(a)
    body_groups = [f"{stages[i]}.planets" if roles[i] == "planet" else names[i].rpartition(".")[0]
                   if not rotation[i] else names[i] for i in range(len(names))]
    body_group_names = list(dict.fromkeys(body_groups))
    body_membership = np.array([[g == h for h in body_groups] for g in body_group_names], dtype=float)
    k_mesh = a.cos_alpha * model.equilibrium.mesh_stiffness_n_per_m
    k_elem = np.concatenate([k_mesh, a.shaft_k, a.bearing_k])
    rows = np.vstack([a.A, a.S, a.B])
    if cm.main_shaft is not None:
        group_names = group_names + [MAIN_SHAFT]
        membership = np.pad(membership, ((0, 1), (0, 1)))
        membership[-1, -1] = 1.0
    lateral = not all(rotation)
    out = []
    for m in modes:  # each row's own undamped shape (the rows are in the order of their eigenvalues' |lambda|)
        u = cm.basis @ m.shape  # body deviations
        kinetic = cm.body_inertia_kgm2 * u * u
        energy = kinetic / kinetic.sum() if kinetic.sum() > 0 else kinetic
        if lateral:
            kind, stage = _kind(energy, roles, stages, rotation, m.kind == "rigid")
        else:  # by the shape itself: a torsional planet mode is exact to the last digits
            moving = np.abs(u) > STILL_TOLERANCE * np.abs(u).max()
            planet_stages = {stages[i] for i in np.flatnonzero(moving)}
            if moving.any() and all(roles[i] == "planet" for i in np.flatnonzero(moving)) and len(planet_stages) == 1:
                kind, stage = "planet", planet_stages.pop()
            else:
                kind, stage = ("rigid" if m.kind == "rigid" else "rotational"), None
        kappa = cm.kinematic_ratio
        referred = normalise_shape(np.divide(u, kappa, out=u.copy(), where=kappa != 0.0))  # translations as they are
        strain = k_elem * (rows @ (cm.to_gearbox @ u)) ** 2
        if cm.main_shaft is not None:
            twist, k_shaft = cm.main_shaft
            strain = np.append(strain, k_shaft * (twist @ u) ** 2)
        strain_share = membership @ strain / strain.sum() if strain.sum() > 0 else membership @ strain
        mode = replace(m, kind=kind, shape=normalise_shape(u), energy_fraction=energy)
        out.append(
            DrivetrainMode(
                mode=mode,
                kind=kind,
                stage=stage,
                shape_referred=referred,
                dominant_bodies=_share_text(body_group_names, body_membership @ energy),
                strain_energy_fraction=dict(zip(group_names, map(float, strain_share))),
                dominant_elements=_share_text(group_names, strain_share),
            )
        )
    return DrivetrainModalAnalysis(_multiplicities(out), model, ss, list(names), rotor, free_input)


def two_inertia_frequency_hz(stiffness_nm_per_rad: float, inertia1_kgm2: float, inertia2_kgm2: float) -> float:
    """Closed-form natural frequency of two inertias on a torsional shaft [Hz].

    ``f = sqrt(k (J1 + J2) / (J1 J2)) / (2 pi)``.
    """
    k, j1, j2 = stiffness_nm_per_rad, inertia1_kgm2, inertia2_kgm2
    return math.sqrt(k * (j1 + j2) / (j1 * j2)) / (2.0 * math.pi)

"""Campbell diagram: natural frequencies over rotor speed against the excitation orders.

Load law
--------
A torsional drivetrain model has no speed-dependent terms, so its modes change with
rotor speed only through the load: the CFS mesh stiffness grows with the contact
force (``k = e k0 d_BL^(e-1)``, i.e. ``k ~ F^(1/3)`` for ``e = 3/2``). The diagram therefore
states a load law, the generator torque as a function of rotor speed:

* ``"quadratic"`` (default): ``T = T_rated (Omega / Omega_rated)^2`` up to rated speed and
  ``T_rated`` above - the optimal-tip-speed-ratio torque law of a variable-speed turbine
  below rated wind (region 2), held at rated torque above it. Rated point default:
  the paper's 16 rpm and 25.4 kN m.
* ``"constant"``: ``T = T_rated`` at every speed (a frozen load, e.g. to separate the
  speed dependence of the excitation from the load dependence of the modes).

Excitation lines
----------------
* rotor orders ``kP`` (default 1P and 3P of a three-bladed rotor): ``k Omega / 2 pi``;
* gear-mesh frequency of every stage (and optional harmonics): planetary stage with the
  ring fixed ``Z_ring omega_carrier / 2 pi``, parallel stage ``Z_drive omega_drive / 2 pi``,
  member speeds from the kinematic ratios.

Modes are sorted by undamped frequency at each speed (no mode tracking through
crossings). Crossings of a mode with an excitation line are located by linear
interpolation between speed points; an overdamped mode cannot resonate, and the
crossing records say which it is.
"""

from __future__ import annotations

import csv
import math
from dataclasses import dataclass
from pathlib import Path
from typing import Sequence

import numpy as np

from ..errors import ParameterError
from ..model.assembly import Assembly
from ..model.drivetrain import Drivetrain
from ..model.rotor import RotorParameters
from ..model.stages import PlanetaryStage
from ..units import rad_per_s_to_rpm
from .equilibrium import OperatingPoint
from .load_law import LoadLaw
from .modes import drivetrain_modes


def excitation_frequencies(
    drivetrain: Drivetrain,
    rotor_speed_rad_s: float | np.ndarray,
    rotor_orders: Sequence[int] = (1, 3),
    mesh_harmonics: Sequence[int] = (1,),
) -> dict[str, np.ndarray]:
    """Excitation frequencies [Hz] at rotor speed(s) [rad/s].

    Parameters
    ----------
    drivetrain : Drivetrain
    rotor_speed_rad_s : float or ndarray, shape (S,)
    rotor_orders : sequence of int
        Rotor orders k of the ``kP`` lines.
    mesh_harmonics : sequence of int
        Harmonics of every stage's gear-mesh frequency.

    Returns
    -------
    dict of str -> ndarray, shape (S,)
        ``"1P"``, ``"3P"``, ``"stage1 mesh"``, ``"stage1 mesh x2"``, ...
    """
    w = np.abs(np.atleast_1d(np.asarray(rotor_speed_rad_s, dtype=float)))
    a = Assembly(drivetrain)
    out: dict[str, np.ndarray] = {}
    for k in rotor_orders:
        out[f"{int(k)}P"] = int(k) * w / (2.0 * math.pi)
    for st in drivetrain.stages:
        member = a.stage_members[st.name]["input"]
        kappa = float(a.kinematic_ratio_all[[b.name for b in a.bodies].index(member)])
        base = np.array([st.mesh_frequency_hz(kappa * x) for x in w])
        for h in mesh_harmonics:
            out[f"{st.name} mesh" + ("" if h == 1 else f" x{int(h)}")] = int(h) * base
    return out


def mesh_description(drivetrain: Drivetrain) -> dict[str, str]:
    """How each stage's mesh frequency is formed, e.g. ``"Z_ring = 180 x carrier speed"``."""
    out = {}
    for st in drivetrain.stages:
        if isinstance(st, PlanetaryStage):
            out[st.name] = f"Z_ring = {st.ring_teeth:g} x carrier speed (ring fixed)"
        else:
            out[st.name] = f"Z_drive = {st.drive_teeth:g} x drive-gear speed"
    return out


@dataclass(frozen=True)
class CampbellDiagram:
    """Natural frequencies and excitation lines over rotor speed.

    Attributes
    ----------
    rotor_speed_rad_s : ndarray, shape (S,)
    output_torque_nm : ndarray, shape (S,)
        Torque of the load law at each speed [N m].
    undamped_frequency_hz, damped_frequency_hz, damping_ratio : ndarray, shape (S, n)
        Per speed and mode (sorted by undamped frequency); damped NaN if overdamped.
    overdamped : ndarray of bool, shape (S, n)
    mode_kind : list of str, length n
        Kind of each mode at the first speed (``rotational``, ``planet (stage1)``, ...).
    mode_label : list of str, length n
        Dominant bodies of each mode at the first speed (e.g. ``"generator 100%"``).
    excitation_hz : dict of str -> ndarray, shape (S,)
    load_law : LoadLaw
    mesh_formula : dict of str -> str
    """

    rotor_speed_rad_s: np.ndarray
    output_torque_nm: np.ndarray
    undamped_frequency_hz: np.ndarray
    damped_frequency_hz: np.ndarray
    damping_ratio: np.ndarray
    overdamped: np.ndarray
    mode_kind: list[str]
    mode_label: list[str]
    excitation_hz: dict[str, np.ndarray]
    load_law: LoadLaw
    mesh_formula: dict[str, str]

    @property
    def rotor_speed_rpm(self) -> np.ndarray:
        """Rotor speeds [rpm]."""
        return rad_per_s_to_rpm(self.rotor_speed_rad_s)

    @property
    def n_modes(self) -> int:
        """Number of modes."""
        return self.undamped_frequency_hz.shape[1]

    def crossings(self) -> list[dict]:
        """Where a mode's undamped frequency meets an excitation line.

        Returns
        -------
        list of dict
            ``{"mode", "excitation", "rotor_speed_rpm", "frequency_hz", "overdamped",
            "damping_ratio"}`` sorted by speed; a crossing exactly on a grid point is
            reported once.
        """
        s = self.rotor_speed_rpm
        out = []
        for name, line in self.excitation_hz.items():
            for j in range(self.n_modes):
                f = self.undamped_frequency_hz[:, j]
                g = f - line
                for i in range(s.size - 1):
                    g0, g1 = g[i], g[i + 1]
                    if g0 == 0.0 or (g0 * g1 < 0.0):
                        x = 0.0 if g0 == 0.0 else g0 / (g0 - g1)
                        k = i if x < 0.5 else i + 1
                        out.append({
                            "mode": j + 1,
                            "excitation": name,
                            "rotor_speed_rpm": float(s[i] + x * (s[i + 1] - s[i])),
                            "frequency_hz": float(f[i] + x * (f[i + 1] - f[i])),
                            "overdamped": bool(self.overdamped[k, j]),
                            "damping_ratio": float(self.damping_ratio[k, j]),
                        })
                if g[-1] == 0.0:
                    out.append({"mode": j + 1, "excitation": name, "rotor_speed_rpm": float(s[-1]),
                                "frequency_hz": float(f[-1]), "overdamped": bool(self.overdamped[-1, j]),
                                "damping_ratio": float(self.damping_ratio[-1, j])})
        return sorted(out, key=lambda c: (c["rotor_speed_rpm"], c["mode"]))

    def rows(self) -> list[dict]:
        """Wide CSV rows: speed, torque, every mode's frequencies and damping, every excitation."""
        rows = []
        for i, w in enumerate(self.rotor_speed_rad_s):
            row = {"rotor_speed_rpm": float(rad_per_s_to_rpm(w)), "output_torque_nm": float(self.output_torque_nm[i])}
            for j in range(self.n_modes):
                row[f"mode{j + 1}_undamped_hz"] = float(self.undamped_frequency_hz[i, j])
            for j in range(self.n_modes):
                row[f"mode{j + 1}_damped_hz"] = float(self.damped_frequency_hz[i, j])
            for j in range(self.n_modes):
                row[f"mode{j + 1}_damping_ratio"] = float(self.damping_ratio[i, j])
            for j in range(self.n_modes):
                row[f"mode{j + 1}_overdamped"] = bool(self.overdamped[i, j])
            for name, line in self.excitation_hz.items():
                row[f"{name.replace(' ', '_')}_hz"] = float(line[i])
            rows.append(row)
        return rows

    def as_dict(self) -> dict:
        """Plain dict (JSON-ready)."""
        return {
            "load_law": self.load_law.as_dict(),
            "mesh_frequency": self.mesh_formula,
            "mode_kind": list(self.mode_kind),
            "mode_label": list(self.mode_label),
            "rows": [{k: (None if isinstance(v, float) and math.isnan(v) else v) for k, v in r.items()} for r in self.rows()],
            "crossings": self.crossings(),
        }


def campbell_diagram(
    drivetrain: Drivetrain,
    rotor_speeds_rad_s: Sequence[float] | np.ndarray,
    load_law: LoadLaw | None = None,
    rotor_orders: Sequence[int] = (1, 3),
    mesh_harmonics: Sequence[int] = (1,),
    rotor: RotorParameters | None = None,
    free_input: bool = False,
) -> CampbellDiagram:
    """Linearise at every rotor speed under a load law and collect the modes.

    Parameters
    ----------
    drivetrain : Drivetrain
    rotor_speeds_rad_s : sequence of float
        Increasing rotor speeds [rad/s], > 0 (the quadratic law has no load at 0).
    load_law : LoadLaw, optional
        Default: quadratic to the paper's rated point (16 rpm, 25.4 kN m).
    rotor_orders, mesh_harmonics : sequence of int
        Excitation lines (see :func:`excitation_frequencies`).
    rotor : RotorParameters, optional
        A torque-driven rotor (free drivetrain); default: the rotor held.
    free_input : bool
        The input member free, no rotor (:func:`components.analysis.modes.drivetrain_modes`).

    Returns
    -------
    CampbellDiagram
    """
    law = load_law or LoadLaw()
    w = np.asarray(rotor_speeds_rad_s, dtype=float)
    if w.ndim != 1 or w.size < 2 or np.any(~np.isfinite(w)) or np.any(w <= 0.0) or np.any(np.diff(w) <= 0.0):
        raise ParameterError("rotor_speeds_rad_s", rotor_speeds_rad_s, ">= 2 increasing positive speeds")
    torques = law.torque_nm(w)
    und, dmp, zeta, over = [], [], [], []
    kinds: list[str] = []
    labels: list[str] = []
    for i, (speed, torque) in enumerate(zip(w, torques)):
        an = drivetrain_modes(drivetrain, OperatingPoint(float(speed), float(torque)), rotor=rotor, free_input=free_input)
        und.append([m.mode.undamped_frequency_hz for m in an.modes])
        dmp.append([m.mode.damped_frequency_hz for m in an.modes])
        zeta.append([m.mode.damping_ratio for m in an.modes])
        over.append([m.mode.overdamped for m in an.modes])
        if i == 0:
            kinds = [m.kind if m.stage is None else f"{m.kind} ({m.stage})" for m in an.modes]
            labels = [m.dominant_bodies for m in an.modes]
    return CampbellDiagram(
        rotor_speed_rad_s=w,
        output_torque_nm=torques,
        undamped_frequency_hz=np.array(und),
        damped_frequency_hz=np.array(dmp),
        damping_ratio=np.array(zeta),
        overdamped=np.array(over, dtype=bool),
        mode_kind=kinds,
        mode_label=labels,
        excitation_hz=excitation_frequencies(drivetrain, w, rotor_orders, mesh_harmonics),
        load_law=law,
        mesh_formula=mesh_description(drivetrain),
    )


def write_rows_csv(path: str | Path, rows: list[dict]) -> Path:
    """Write a list of flat dicts (same keys) as CSV and return the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    if not rows:
        raise ParameterError("rows", rows, "at least one row")
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    return path

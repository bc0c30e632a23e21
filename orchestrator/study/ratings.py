"""The ratings of a load-case set from its run files: ``gear_rating.csv`` (ISO 6336) and ``bearing_life.csv`` (ISO 281).

What is rated is planned before the runs (:mod:`orchestrator.study.rating_plan`); here the
lifetime spectra are formed and rated, so a changed material, factor or reliability needs
no run again (``dtcosim loads SET --report``).

Spectra
-------
Each finished run ``r`` holds, for every rated force, its load levels (cells of width
``2^e`` of :mod:`components.analysis.load_spectrum`) with the revolutions of each gear (a
gear's load cycles) or of the bearing at each level. A level counts at its cell's middle
(within half a cell, at most 1/2048 of the run's range, of every sample in it), its counts
times the run's lifetime weight ``w_r`` (:func:`components.analysis.lifetime.run_weights`), so
the spectrum is that of the design life (the hours in the bins with finished runs).

Gears
-----
Per mesh and gear (:func:`components.analysis.gear_rating.gear_damage`): the stresses at the
largest force and at the equivalent one, the strengths, the safety factors and the Miner damage in
contact and bending over the design life, from that mesh's cycles. Per gear, over its meshes: a
tooth flank takes the cycles of every mesh that loads it together (the sun's flank meets every
planet, the ring's too: damage and the spectrum's safety factor of the combined spectrum); the
planet's two flanks (sun side, ring side) are two flanks, so its contact rating is the worse one;
its root sees one alternating cycle per revolution from its two meshes (``Y_M``), so its bending
rating is the worse of the two meshes' as well.

Bearings
--------
Per bearing (:func:`components.analysis.bearing_life.bearing_life`): the equivalent load over the
design life's revolutions, L10 (and L_nm) in million revolutions and in hours at the life's mean
revolutions per operating hour, against the design life's operating hours.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

from components.analysis.bearing_life import UNLOADED_BELOW, BearingLife, bearing_life
from components.analysis.gear_rating import GearDamage, gear_damage, miner_damage
from components.errors import ParameterError

from .lifetime_results import HOURS, LifetimeResults
from .rating_plan import BearingPlan, MeshPlan

GEAR_FILE, BEARING_FILE = "gear_rating.csv", "bearing_life.csv"
MPA = 1.0e6


@dataclass(frozen=True)
class GearRow:
    """The rating of one gear in one mesh: the plan, the damage over the life, and its damage per bin."""

    mesh: MeshPlan
    index: int  # 0 pinion, 1 wheel
    damage: GearDamage
    contact_by_bin: np.ndarray
    bending_by_bin: np.ndarray
    spectrum: tuple[np.ndarray, np.ndarray] = (np.zeros(0), np.zeros(0))  # forces [N], lifetime load cycles

    @property
    def gear(self) -> str:
        """The gear's name."""
        return self.mesh.stresses[self.index].gear

    @property
    def member(self) -> str:
        """sun, planet, ring, drive or driven."""
        return self.mesh.members[self.index]


@dataclass(frozen=True)
class GearTotal:
    """One gear over its meshes (module docstring)."""

    gear: str
    stage: str
    member: str
    meshes: int
    contact_damage: float
    bending_damage: float
    safety_contact: float  # the spectrum's S_H (ISO 6336-6) of its most damaged flank, its meshes' cycles together
    safety_bending: float
    safety_contact_static: float
    safety_bending_static: float
    contact_share_by_bin: np.ndarray
    bending_share_by_bin: np.ndarray


@dataclass
class Ratings:
    """The ratings of a load-case set's finished runs."""

    gears: list[GearRow] = field(default_factory=list)
    totals: list[GearTotal] = field(default_factory=list)
    bearings: list[tuple[BearingPlan, BearingLife | None, str]] = field(default_factory=list)
    operating_hours: float = 0.0
    design_hours: float = 0.0


def _spectrum(res: LifetimeResults, column: str, gear: str, weighted: bool = True):
    """(levels at cell middles, counts x w_r, bin of each level) over the finished runs."""
    levels, counts, bins = [], [], []
    for run, w in zip(res.runs, res.weights):
        h = run.levels[column]
        revs = h.revolutions.get(gear)
        if revs is None or h.indices.size == 0:
            continue
        levels.append((h.indices.astype(float) + 0.5) * h.width)
        counts.append(revs * (w if weighted else 1.0))
        bins.append(np.full(h.indices.size, res.plc.cases[run.case_index].bin))
    if not levels:
        return np.zeros(0), np.zeros(0), np.zeros(0, dtype=int)
    return np.concatenate(levels), np.concatenate(counts), np.concatenate(bins)


def _hours(res: LifetimeResults) -> tuple[float, float]:
    """Operating hours over the life in the bins with finished runs, and in every bin."""
    plc = res.plc
    life = plc.load_cases.life
    done = {plc.cases[r.case_index].bin for r in res.runs}
    per_bin = {b.index: life.availability * b.probability * life.seconds / HOURS for b in plc.bins}
    return sum(h for b, h in per_bin.items() if b in done), sum(per_bin.values())


def _by_bin(stress, levels, counts, bins, n_bins: int) -> tuple[np.ndarray, np.ndarray]:
    contact, bending = np.zeros(n_bins), np.zeros(n_bins)
    for b in np.unique(bins):
        sel = bins == b
        f = np.abs(levels[sel])
        contact[b] = miner_damage(stress.contact_stress(f), counts[sel], stress.contact_reference_pa, stress.contact_curve)
        bending[b] = miner_damage(stress.root_stress(f), counts[sel], stress.root_reference_pa, stress.bending_curve)
    return contact, bending


def _share(values: np.ndarray) -> np.ndarray:
    total = float(values.sum())
    return values / total if total > 0 else np.zeros_like(values)


def _totals(rows: list[GearRow], n_bins: int) -> list[GearTotal]:
    out = []
    for gear in dict.fromkeys(r.gear for r in rows):
        mine = [r for r in rows if r.gear == gear]
        flanks: dict[str, list[GearRow]] = {}
        for r in mine:  # a flank per mesh kind (the planet's sun and ring sides); its meshes share one stress law
            flanks.setdefault(r.mesh.mesh, []).append(r)
        rated = []
        for rs in flanks.values():
            stress = rs[0].mesh.stresses[rs[0].index]
            levels = np.concatenate([r.spectrum[0] for r in rs])
            counts = np.concatenate([r.spectrum[1] for r in rs])
            rated.append((gear_damage(stress, levels, counts), sum(r.contact_by_bin for r in rs),
                          sum(r.bending_by_bin for r in rs)))
        # contact: the most damaged flank; bending: the sum over the meshes of one flank side, for an idler
        # (planet) the larger side's (its alternating root, Y_M): the same rule, a flank per mesh kind
        contact = max(rated, key=lambda x: (x[0].contact_damage, -x[0].safety_contact_life))
        bending = max(rated, key=lambda x: (x[0].bending_damage, -x[0].safety_bending_life))
        out.append(GearTotal(gear, mine[0].mesh.stage, mine[0].member, len(mine), contact[0].contact_damage,
                             bending[0].bending_damage, contact[0].safety_contact_life, bending[0].safety_bending_life,
                             min(x[0].safety_contact_static for x in rated), min(x[0].safety_bending_static for x in rated),
                             _share(np.asarray(contact[1], dtype=float) + np.zeros(n_bins)),
                             _share(np.asarray(bending[2], dtype=float) + np.zeros(n_bins))))
    return out


def compute_ratings(res: LifetimeResults) -> Ratings:
    """Gear ratings and bearing lives of the finished runs (module docstring)."""
    plan = res.plc.ratings
    n_bins = len(res.plc.bins)
    out = Ratings()
    out.operating_hours, out.design_hours = _hours(res)
    if not res.runs:
        return out
    for mesh in plan.meshes:
        for k, stress in enumerate(mesh.stresses):
            levels, counts, bins = _spectrum(res, mesh.column, stress.gear)
            dmg = gear_damage(stress, levels, counts)
            contact, bending = _by_bin(stress, levels, counts, bins, n_bins)
            out.gears.append(GearRow(mesh, k, dmg, contact, bending, (levels, counts)))
    out.totals = _totals(out.gears, n_bins)
    for b in plan.bearings:
        if b.problem:
            out.bearings.append((b, None, b.problem))
            continue
        levels, counts, _ = _spectrum(res, b.column, b.name)
        try:
            life = bearing_life(b.name, b.bearing_type, b.rating_n, levels, counts, out.operating_hours, b.modification)
        except ParameterError as exc:  # e.g. the bearing never turned in the analysed windows
            out.bearings.append((b, None, f"not rated: {exc.expected} ({exc.name} = {exc.value})"))
            continue
        out.bearings.append((b, life, f"unloaded: P_eq at round-off (below {UNLOADED_BELOW:g} C), no fatigue life"
                             if life.unloaded else ""))
    return out


# -------------------------------------------------------------------- tables
def _mpa(x: float | None) -> float | None:
    return None if x is None else x / MPA


def _fin(x: float | None) -> float | None:
    return None if x is None or not math.isfinite(x) else x


GEAR_FACTOR_COLUMNS = ("eps_alpha", "Z_H", "Z_E [sqrt(MPa)]", "Z_eps", "Z_B/Z_D", "Y_F", "Y_S", "Y_B", "Y_M", "K_A",
                       "K_v", "K_Hbeta", "K_Halpha", "K_Fbeta", "K_Falpha", "x")


def gear_rows(res: LifetimeResults, ratings: Ratings) -> list[list[Any]]:
    """``gear_rating.csv``: a row per mesh and gear."""
    rows = [["mesh", "stage", "mesh_kind", "planet", "gear", "member", "role", "teeth [-]", "material", "cycles [-]",
             "F_max [N]", "sigma_H_max [MPa]", "sigma_HG_static [MPa]", "sigma_HP_static [MPa]", "S_H_static [-]",
             "F_eq_contact [N]", "sigma_H_eq [MPa]", "sigma_HG_life [MPa]", "sigma_HP_life [MPa]", "S_H_life [-]",
             "damage_contact [-]", "sigma_F_max [MPa]", "sigma_FG_static [MPa]", "sigma_FP_static [MPa]",
             "S_F_static [-]", "F_eq_bending [N]", "sigma_F_eq [MPa]", "sigma_FG_life [MPa]", "sigma_FP_life [MPa]",
             "S_F_life [-]", "damage_bending [-]", "S_Hmin [-]", "S_Fmin [-]", "design_life_met", "safety_met",
             *GEAR_FACTOR_COLUMNS]]
    for r in ratings.gears:
        m, d, s = r.mesh, r.damage, r.mesh.stresses[r.index]
        f = res.plc.load_cases.gear_rating.stage(m.stage).factors
        used = dict(s.factors)
        used["Z_B/Z_D"] = used.pop("Z_B", used.pop("Z_D", None))
        met = d.contact_damage <= 1.0 and d.bending_damage <= 1.0
        safe = (min(d.safety_contact_static, d.safety_contact_life) >= f.S_Hmin
                and min(d.safety_bending_static, d.safety_bending_life) >= f.S_Fmin)
        rows.append([m.column, m.stage, m.mesh, m.planet or None, r.gear, r.member, s.role, s.teeth, m.material.name,
                     d.cycles, d.largest_force_n, _mpa(d.sigma_h_max_pa), _mpa(d.sigma_hg_static_pa),
                     _mpa(d.sigma_hg_static_pa / f.S_Hmin), _fin(d.safety_contact_static), d.force_eq_contact_n,
                     _mpa(d.sigma_h_eq_pa), _mpa(d.sigma_hg_life_pa), _mpa(d.sigma_hg_life_pa / f.S_Hmin),
                     _fin(d.safety_contact_life), d.contact_damage, _mpa(d.sigma_f_max_pa), _mpa(d.sigma_fg_static_pa),
                     _mpa(d.sigma_fg_static_pa / f.S_Fmin), _fin(d.safety_bending_static), d.force_eq_bending_n,
                     _mpa(d.sigma_f_eq_pa), _mpa(d.sigma_fg_life_pa), _mpa(d.sigma_fg_life_pa / f.S_Fmin),
                     _fin(d.safety_bending_life), d.bending_damage, f.S_Hmin, f.S_Fmin, met, safe,
                     *(used.get(c) for c in GEAR_FACTOR_COLUMNS)])
    return rows


def bearing_rows(ratings: Ratings) -> list[list[Any]]:
    """``bearing_life.csv``: a row per bearing."""
    rows = [["bearing", "column", "body", "stage", "type", "C [N]", "exponent [-]", "P_eq [N]", "revolutions [-]",
             "operating_hours [h]", "L10 [1e6 rev]", "L10 [h]", "Lnm [1e6 rev]", "Lnm [h]", "life_modification",
             "design_life [h]", "met", "note"]]
    for plan, life, note in ratings.bearings:
        head = [plan.name, plan.column, plan.info.get("body"), plan.info.get("stage"), plan.bearing_type, plan.rating_n]
        if life is None:
            rows.append(head + [None] * 10 + [None, note])
            continue
        rows.append(head + [life.exponent, life.equivalent_load_n, life.revolutions, life.duty_hours,
                            _fin(life.l10_mrev), _fin(life.l10_h), _fin(life.lnm_mrev), _fin(life.lnm_h),
                            life.modification.describe(), ratings.design_hours, life.life_h >= ratings.design_hours, note])
    return rows


def report_lines(res: LifetimeResults, ratings: Ratings) -> list[str]:
    """The lifetime report's section on the ratings."""
    plan = res.plc.ratings
    bins = res.plc.bins
    lines = []
    if plan.gear_note:
        lines.append(plan.gear_note)
    elif ratings.totals:
        lines.append(f"gear ratings (ISO 6336-2/-3/-5/-6; {plan.description}; {GEAR_FILE}): Miner damage over the "
                     "design life; safety factors of the spectrum (S life: the factor on its stresses that makes D = 1, "
                     "ISO 6336-6) and at the largest load against the static strength (S static)")
        for t in ratings.totals:
            share = t.contact_share_by_bin if t.contact_damage >= t.bending_damage else t.bending_share_by_bin
            top = int(np.argmax(share))
            where = (f"most damage in {bins[top].label} ({100 * share[top]:.0f} %)"
                     if max(t.contact_damage, t.bending_damage) > 0 else "no damage: every stress below the endurance limit")
            lines.append(f"  {t.gear:<22} ({t.member}, {t.meshes} mesh{'es' if t.meshes > 1 else ''})  contact "
                         f"D = {t.contact_damage:.4g}, S_H life {t.safety_contact:.3g} static "
                         f"{t.safety_contact_static:.3g};  bending D = {t.bending_damage:.4g}, S_F life "
                         f"{t.safety_bending:.3g} static {t.safety_bending_static:.3g};  {where}")
        worst = max(ratings.totals, key=lambda t: max(t.contact_damage, t.bending_damage))
        d = max(worst.contact_damage, worst.bending_damage)
        least = min(ratings.totals, key=lambda t: min(t.safety_contact, t.safety_bending))
        s_min = min(least.safety_contact, least.safety_bending)
        lines.append(f"  the most damaged gear: {worst.gear}, D = {d:.4g} ({'within' if d <= 1.0 else 'BEYOND'} the "
                     f"design life); the least safety factor of a spectrum: {least.gear}, {s_min:.3g}")
    elif res.runs:
        lines.append("gear ratings: no finished run holds the rated forces")
    if plan.bearing_note:
        lines.append(plan.bearing_note)
    elif ratings.bearings:
        lines.append(f"bearing lives (ISO 281; {BEARING_FILE}); design life {ratings.design_hours:.6g} operating hours:")
        for p, life, note in ratings.bearings:
            if life is None:
                lines.append(f"  {p.name:<22} {note}")
                continue
            head = f"  {p.name:<22} {p.bearing_type}, C = {p.rating_n:.4g} N, P_eq = {life.equivalent_load_n:.4g} N: "
            if life.unloaded:
                lines.append(head + f"no load to rate (round-off of the model's forces, below {UNLOADED_BELOW:g} C): "
                             "no fatigue life (met)")
                continue
            lnm = "" if life.lnm_h is None else f", L_nm {life.lnm_h:.4g} h"
            lines.append(head + f"L10 {life.l10_h:.4g} h{lnm} ({'met' if life.life_h >= ratings.design_hours else 'NOT met'})")
    return lines


def summary(ratings: Ratings) -> dict[str, Any]:
    """The ratings in ``lifetime.json``."""
    return {
        "gears": [{"gear": t.gear, "stage": t.stage, "member": t.member, "meshes": t.meshes,
                   "contact_damage": t.contact_damage, "bending_damage": t.bending_damage,
                   "S_H_life": _fin(t.safety_contact), "S_F_life": _fin(t.safety_bending),
                   "S_H_static": _fin(t.safety_contact_static), "S_F_static": _fin(t.safety_bending_static),
                   "contact_share_by_bin": [float(x) for x in t.contact_share_by_bin],
                   "bending_share_by_bin": [float(x) for x in t.bending_share_by_bin]} for t in ratings.totals],
        "bearings": [life.as_dict() if life is not None else {"name": p.name, "note": note}
                     for p, life, note in ratings.bearings],
        "operating_hours": ratings.operating_hours, "design_hours": ratings.design_hours,
    }

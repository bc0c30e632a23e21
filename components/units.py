"""Conversions from the paper's units to SI.

The paper's tables use millimetres, kg mm^2, N mm/deg and rpm. Inside dtcosim
everything is SI. These helpers turn the paper's units into SI where the physics
itself needs them (the presets read like the tables they come from, the FMUs carry
them without any units library); the user's inputs are converted by the unit
registry of :mod:`orchestrator.inputs.quantities` (pint). Both give the same
numbers to the last bit: each helper multiplies by one factor, as pint does, and
``tests/orchestrator/inputs/test_quantities.py`` checks every factor against pint.
"""

from __future__ import annotations

import math

MM_TO_M = 1.0e-3
RPM_TO_RAD_PER_S = 2.0 * math.pi / 60.0
DEG_TO_RAD = math.pi / 180.0
#: [N mm/deg] -> [N m/rad] (and [N mm s/deg] -> [N m s/rad])
NMM_PER_DEG_TO_NM_PER_RAD = MM_TO_M / DEG_TO_RAD


def mm(value_mm: float) -> float:
    """Length [mm] -> [m]."""
    return value_mm * MM_TO_M


def kgmm2(value_kgmm2: float) -> float:
    """Moment of inertia [kg mm^2] -> [kg m^2]."""
    return value_kgmm2 * 1.0e-6


def nmm(value_nmm: float) -> float:
    """Torque [N mm] -> [N m]."""
    return value_nmm * 1.0e-3


def rpm(value_rpm: float) -> float:
    """Rotational speed [rpm] -> [rad/s]."""
    return value_rpm * RPM_TO_RAD_PER_S


def rad_per_s_to_rpm(value_rad_s: float) -> float:
    """Rotational speed [rad/s] -> [rpm]."""
    return value_rad_s / RPM_TO_RAD_PER_S


def contact_stiffness(k0_n_per_mm_e: float, exponent: float) -> float:
    """Hertzian contact stiffness k0 [N/mm^e] -> [N/m^e] (eq. 2)."""
    return k0_n_per_mm_e * 1000.0**exponent


def contact_damping(c0_ns_per_mm2: float) -> float:
    """Contact damping c0 [N s/mm^2] -> [N s/m^2] (eq. 2, 9: c = c0 |delta|)."""
    return c0_ns_per_mm2 * 1.0e6


def regularisation(lambda_per_mm: float) -> float:
    """Backlash regularisation factor lambda [1/mm] -> [1/m] (eq. 4)."""
    return lambda_per_mm * 1.0e3


def torsional_stiffness(k_nmm_per_deg: float) -> float:
    """Shaft stiffness [N mm/deg] -> [N m/rad] (Table 6)."""
    return k_nmm_per_deg * NMM_PER_DEG_TO_NM_PER_RAD


def torsional_damping(c_nmms_per_deg: float) -> float:
    """Shaft damping [N mm s/deg] -> [N m s/rad] (Table 6)."""
    return c_nmms_per_deg * NMM_PER_DEG_TO_NM_PER_RAD

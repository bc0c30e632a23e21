"""Unit conversions of a drivetrain file: its ``[units]`` table names the quantities not in SI."""

from __future__ import annotations

import math

from components import units

from .drivetrain_schema import UnitsTable


class FileUnits:
    """Conversions of the file's numbers to SI, per the ``[units]`` table."""

    def __init__(self, table: UnitsTable) -> None:
        self.t = table

    def length(self, v: float) -> float:
        return units.mm(v) if self.t.length == "mm" else v

    def angle(self, v: float) -> float:
        return math.radians(v) if self.t.angle == "deg" else v

    def inertia(self, v: float) -> float:
        return units.kgmm2(v) if self.t.inertia == "kg.mm2" else v

    def k0(self, v: float, exponent: float) -> float:
        return units.contact_stiffness(v, exponent) if self.t.contact_stiffness == "N/mm^e" else v

    def c0(self, v: float) -> float:
        return units.contact_damping(v) if self.t.contact_damping == "N.s/mm2" else v

    def regularisation(self, v: float) -> float:
        return units.regularisation(v) if self.t.regularisation == "1/mm" else v

    def impact_damping(self, v: float) -> float:
        return v * 1e3 if self.t.impact_damping == "N.s/mm" else v

    def shaft_stiffness(self, v: float) -> float:
        return units.torsional_stiffness(v) if self.t.torsional_stiffness == "N.mm/deg" else v

    def shaft_damping(self, v: float) -> float:
        return units.torsional_damping(v) if self.t.torsional_damping == "N.mm.s/deg" else v

    def torque(self, v: float) -> float:
        return units.nmm(v) if self.t.torque == "N.mm" else v

    def speed(self, v: float) -> float:
        return units.rpm(v) if self.t.speed == "rpm" else v


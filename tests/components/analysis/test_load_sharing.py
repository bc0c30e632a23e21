"""Planet load sharing: the factor of a window, and a pin position error against its hand estimate (issue 33.3)."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest

from components.analysis.load_sharing import load_sharing, pin_error_factor
from components.errors import ParameterError
from components.model.assembly import Assembly
from orchestrator.inputs.drivetrain_file import find_drivetrain, load_drivetrain_file


def test_the_factor_is_the_largest_instantaneous_ratio_and_the_shares_the_means():
    forces = np.array([[120.0, 90.0, 90.0], [110.0, 95.0, 95.0], [100.0, 100.0, 100.0]])
    ls = load_sharing("stage1", forces, ("a", "b", "c"))
    assert ls.factor == pytest.approx(1.2) and ls.mean_factor == pytest.approx((1.2 + 1.1 + 1.0) / 3)
    assert ls.shares == pytest.approx((110.0 / 100.0, 95.0 / 100.0, 95.0 / 100.0)) and ls.most_loaded == 1
    assert load_sharing("s", np.full((4, 3), 7.0)).factor == 1.0


@pytest.mark.parametrize("forces, match", [(np.ones((3, 1)), "two planets"), (np.array([[1.0, -2.0]]), "> 0 at every")])
def test_no_factor_without_planets_or_load(forces, match):
    with pytest.raises(ParameterError, match=match):
        load_sharing("stage1", forces)


def test_hand_estimate_by_hand():
    # K = 1 + (1 - 1/3) k_eff e / F, k_eff = k / (1 + 2 k cos(alpha) / k_b)
    alpha = math.radians(20.0)
    assert pin_error_factor(1e-5, 1e5, 1e9, 3, alpha) == pytest.approx(1.0 + (2.0 / 3.0) * 1e9 * 1e-5 / 1e5)
    k_eff = 1e9 / (1.0 + 2e9 * math.cos(alpha) / 4e9)
    assert pin_error_factor(-1e-5, 1e5, 1e9, 3, alpha, 4e9) == pytest.approx(1.0 + (2.0 / 3.0) * k_eff * 1e-5 / 1e5)


def _stage1(drivetrain, error_m: float, stiff_centre: bool = False):
    """Stage 1's sun-mesh forces at 25.4 kN m with a tangential pin error of planet 1 (static equilibrium)."""
    st = drivetrain.stages[0]
    if stiff_centre:
        lat = st.lateral
        st = replace(st, lateral=replace(lat, sun_bearing=replace(lat.sun_bearing, stiffness_n_per_m=1e13),
                                         carrier_bearing=replace(lat.carrier_bearing, stiffness_n_per_m=1e13)))
    st = replace(st, pin_errors_m=((0.0, error_m), (0.0, 0.0), (0.0, 0.0)))
    a = Assembly(replace(drivetrain, stages=(st,) + drivetrain.stages[1:]))
    q, _, _ = a.static_deflection(25.4e3)
    forces = a.loads(q, np.zeros_like(q)).contact_force_n
    return forces[[i for i, m in enumerate(a.meshes) if m.stage == "stage1" and m.kind == "sun_planet"]]


@pytest.mark.parametrize("file, stiff_centre, bearing", [("paper-table6", False, math.inf),
                                                          ("paper-table6-lateral", True, 5e9)])
def test_a_pin_error_loads_its_planet_as_the_hand_estimate_says(file, stiff_centre, bearing):
    """The torsional model (rigid everything) and the lateral one with the sun and carrier held stiff: K from the
    static equilibrium of Table 6 with a 20 um error of planet 1 against 1 + (2/3) k_eff e / F, the mesh's tangent
    stiffness 1.5 F / d from the CFS law (eq. 2) at the error-free force."""
    dt = load_drivetrain_file(find_drivetrain(file)).drivetrain
    free = _stage1(dt, 0.0, stiff_centre)
    f = float(free.mean())
    mesh = dt.stages[0].sun_mesh
    k = 1.5 * f / (f / mesh.stiffness) ** (1.0 / 1.5)
    estimate = pin_error_factor(20e-6, f, k, 3, mesh.pressure_angle_rad, bearing)
    forces = _stage1(dt, 20e-6, stiff_centre)
    factor = load_sharing("stage1", forces[None, :]).factor
    assert forces.sum() == pytest.approx(free.sum(), rel=1e-6)  # the planets carry the stage torque together
    assert int(np.argmax(forces)) == 0  # the planet whose pin is ahead
    assert factor - 1.0 == pytest.approx(estimate - 1.0, rel=2e-3)  # measured: 1e-3 (torsional), 2e-4 (lateral)
    assert factor > 1.005

"""Modes with a torque-driven rotor: the drivetrain free at both ends (issue 29, item 5)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import scipy.linalg as sla

from components.analysis.equilibrium import OperatingPoint, linearise
from components.analysis.modes import drivetrain_modes, two_inertia_frequency_hz
from components.analysis.rotor_coupling import free_rotor, held_rotor
from components.errors import ParameterError
from components.model.rotor import RotorParameters
from orchestrator.inputs.drivetrain_file import find_drivetrain, load_drivetrain_file

#: NREL 5-MW (Jonkman et al. 2009): rotor (hub + blades) inertia, generator inertia about the HSS, LSS torsion
J_ROTOR = 38759228.0
J_GENERATOR = 534.116
K_LSS = 867.637e6


@pytest.fixture(scope="module")
def nrel5mw():
    spec = load_drivetrain_file(find_drivetrain("nrel5mw"))
    return spec.drivetrain, OperatingPoint.of_drivetrain(spec.drivetrain, spec.rotor_speed_rad_s)


def _flexible_frequencies_hz(mass: np.ndarray, stiffness: np.ndarray) -> np.ndarray:
    """Non-zero undamped frequencies of a (possibly free-free) system by the symmetric generalised eigenproblem."""
    w2 = sla.eigh(stiffness, mass, eigvals_only=True)
    w2 = w2[w2 > 1e-9 * w2.max()]
    return np.sqrt(np.sort(w2)) / (2 * math.pi)


def test_the_free_nrel5mw_torsion_is_the_two_mass_value(nrel5mw):
    """Rotor 38.76e6 kg m^2 against the generator 534.116 kg m^2 x 97^2 on the 5-MW drivetrain torsion.

    The published two-mass value, sqrt(k (1/J_r + 1/J_g')) / 2 pi = 2.2227 Hz, within 3 % (the
    gearbox's own compliance and inertias lower it); with the held model's effective stiffness
    k = J_g' (2 pi f_held)^2 the two-mass formula holds to 0.05 %.
    """
    dt, op = nrel5mw
    j_gen = J_GENERATOR * 97.0**2
    published = two_inertia_frequency_hz(K_LSS, J_ROTOR, j_gen)
    assert published == pytest.approx(2.2227, abs=1e-4)
    held = drivetrain_modes(dt, op).modes[0].mode
    free = drivetrain_modes(dt, op, rotor=RotorParameters(J_ROTOR)).modes[0].mode
    assert held.undamped_frequency_hz == pytest.approx(2.04, abs=0.01)  # the rotor-held mode of the issue
    assert abs(free.undamped_frequency_hz / published - 1.0) < 0.03
    k_eff = j_gen * (2 * math.pi * held.system_frequency_hz) ** 2
    assert free.system_frequency_hz == pytest.approx(two_inertia_frequency_hz(k_eff, J_ROTOR, j_gen), rel=5e-4)
    assert free.damped_frequency_hz <= free.undamped_frequency_hz


@pytest.mark.parametrize("rotor", [
    RotorParameters(J_ROTOR),
    RotorParameters(J_ROTOR, shaft_stiffness_nm_rad=K_LSS, shaft_damping_nms_rad=6.215e6, carrier_inertia_kgm2=2000.0),
], ids=["rigid-main-shaft", "flexible-main-shaft"])
def test_the_reduced_model_has_the_free_systems_flexible_modes(nrel5mw, rotor):
    """Removing the rigid-body rotation keeps every flexible frequency of the full free-free system.

    The full system in absolute deviations (M_z diagonal, K_z = P^T K P (+ main shaft)) has one zero
    eigenvalue; its others are the reduced model's.
    """
    dt, op = nrel5mw
    model = linearise(dt, op)
    cm = free_rotor(model, rotor)
    n_z = cm.basis.shape[0]
    m_z = np.diag(cm.body_inertia_kgm2)
    p = cm.to_gearbox
    k_z = p.T @ model.stiffness @ p
    if cm.main_shaft is not None:
        s, k = cm.main_shaft
        k_z = k_z + k * np.outer(s, s)
    # the rigid rotation is a null vector of the full stiffness
    assert np.abs(k_z @ cm.kinematic_ratio).max() < 1e-6 * np.abs(k_z).max()
    full = _flexible_frequencies_hz(m_z, k_z)
    assert full.size == n_z - 1
    reduced = _flexible_frequencies_hz(cm.mass, cm.stiffness)
    assert reduced == pytest.approx(full, rel=1e-7)
    # the body shapes carry no rigid rotation: zero momentum, sum kappa_j J_j z_j = 0
    an = drivetrain_modes(dt, op, rotor=rotor)
    for m in an.modes:
        u = np.array([m.mode.shape[i] for i in range(n_z)])
        assert abs(cm.kinematic_ratio * cm.body_inertia_kgm2 @ u) < 1e-9 * (cm.body_inertia_kgm2 @ np.abs(u))
    assert an.dof_names[0] == "rotor"
    assert all(r.mode.damped_frequency_hz <= r.mode.undamped_frequency_hz for r in an.underdamped)


def test_a_very_heavy_rotor_is_the_held_rotor(nrel5mw):
    dt, op = nrel5mw
    held = [m.mode.undamped_frequency_hz for m in drivetrain_modes(dt, op).modes]
    heavy = [m.mode.undamped_frequency_hz for m in drivetrain_modes(dt, op, rotor=RotorParameters(1e16)).modes]
    assert heavy == pytest.approx(held, rel=1e-7)


def test_main_shaft_strain_and_rotor_energy_are_reported(nrel5mw):
    """With the 5-MW LSS as the Rotor's main shaft on the (stiff) OC3 gearbox the lowest mode twists the shaft."""
    spec = load_drivetrain_file(find_drivetrain("nrel5mw-oc3"))
    rotor = RotorParameters(J_ROTOR, K_LSS, 6.215e6, 2000.0)
    an = drivetrain_modes(spec.drivetrain, OperatingPoint.of_drivetrain(spec.drivetrain, spec.rotor_speed_rad_s),
                          rotor=rotor)
    first = an.modes[0]
    assert first.strain_energy_fraction["main_shaft"] > 0.85
    assert an.dof_names[:2] == ["rotor", "planetary1.carrier"]
    energy = dict(zip(an.dof_names, first.mode.energy_fraction))
    assert energy["rotor"] > 0.05 and energy["generator"] > 0.5
    d = an.as_dict()
    assert d["rotor"]["driven_by"] == "torque" and d["rotor"]["shaft_stiffness_nm_rad"] == K_LSS


def test_held_rotor_coordinates_are_the_linear_models():
    from components.model.presets import table6_gearbox

    model = linearise(table6_gearbox(), OperatingPoint.from_rpm(16.0, 25.4e3))
    cm = held_rotor(model)
    assert cm.held and cm.body_names == model.dof_names
    np.testing.assert_array_equal(cm.stiffness, model.stiffness)
    with pytest.raises(ParameterError, match="RotorParameters"):
        free_rotor(model, 3.0e7)

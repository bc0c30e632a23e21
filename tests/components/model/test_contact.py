"""Contact laws (eq. 1-4) against hand-computed values and finite differences."""

import math

import numpy as np
import pytest

from components.model.contact import ContactLaw, MeshContact

K0 = 1.0e9  # N/m^1.5
C0 = 1.0e8  # N s/m^2
LAM = 1.0e5  # 1/m
JN = 0.5e-3  # m
ALPHA = math.radians(20.0)
HALF_JT = 0.5 * JN / math.cos(ALPHA)


def law(**kw) -> ContactLaw:
    params = dict(stiffness=K0, damping=C0, regularisation=LAM, backlash_normal_m=JN, pressure_angle_rad=ALPHA)
    params.update(kw)
    return ContactLaw([MeshContact(**params)])


def test_paper_units_are_converted_to_si():
    m = MeshContact.from_paper(5.0e5, 5.0e4, 600.0, 0.56, 20.0)
    assert m.stiffness == pytest.approx(5.0e5 * 1000**1.5)
    assert m.damping == pytest.approx(5.0e4 * 1e6)
    assert m.regularisation == pytest.approx(6.0e5)
    assert m.backlash_normal_m == pytest.approx(0.56e-3)
    assert m.backlash_circumferential_m == pytest.approx(0.56e-3 / math.cos(math.radians(20)))


@pytest.mark.parametrize("sign", [1.0, -1.0])
def test_deep_contact_is_hertz_with_backlash_removed(sign):
    pen = 3.0e-4  # lambda * pen = 30: tanh saturated
    d = sign * (HALF_JT + pen)
    f = law().evaluate(np.array([d]), np.array([0.0])).force[0]
    assert f == pytest.approx(sign * K0 * pen**1.5, rel=1e-12)  # eq. 2 with d_BL = d -+ j_t/2


def test_damping_term_is_c0_times_indentation_times_rate():
    pen, rate = 3.0e-4, 1.0e-3
    d = HALF_JT + pen
    f = law().evaluate(np.array([d]), np.array([rate])).force[0]
    assert f == pytest.approx(K0 * pen**1.5 + C0 * pen * rate, rel=1e-12)  # eq. 2, 9


def test_no_force_inside_the_backlash():
    d = np.linspace(-0.9 * HALF_JT, 0.9 * HALF_JT, 41)
    f = law().evaluate(d, np.full_like(d, 0.1)).force
    assert np.all(np.abs(f) < 1e-6)


def test_regularised_indentation_has_the_tanh_form_of_eq3():
    x = np.array([-2 * HALF_JT, -0.3 * HALF_JT, 0.5 * HALF_JT, HALF_JT, 3 * HALF_JT])
    d_bl, _, _ = law().backlash_deflection(x)
    g1 = (x - HALF_JT) * np.tanh(LAM * (x - HALF_JT))
    g2 = (x + HALF_JT) * np.tanh(LAM * (x + HALF_JT))
    np.testing.assert_allclose(d_bl, x + 0.5 * (g1 - g2), rtol=0, atol=1e-15)


def test_flank_never_pulls_while_separating_fast():
    """The paper's sign-change warning: a large separation speed must not make the force pull."""
    pen = 1.0e-5
    d = HALF_JT + pen
    rate = -10.0  # damping c0 pen rate = -1e4 N >> elastic 3e1 N
    cf = law().evaluate(np.array([d]), np.array([rate]))
    assert K0 * pen**1.5 + C0 * pen * rate < 0  # the raw eq. 2 would pull
    assert cf.force[0] == 0.0
    assert cf.d_force_d_deflection[0] == 0.0 and cf.d_force_d_rate[0] == 0.0


def test_regularisation_dip_inside_the_edge_does_not_pull():
    """x tanh(lambda x) < |x| makes d_BL dip to -0.139/lambda at 0.64/lambda inside the edge; no force there."""
    x = HALF_JT - 0.6392 / LAM
    d_bl, _, _ = law().backlash_deflection(np.array([x]))
    assert d_bl[0] == pytest.approx(-0.139232 / LAM, rel=1e-4)
    assert law().evaluate(np.array([x]), np.array([0.0])).force[0] == 0.0


@pytest.mark.parametrize("contact_law", ["cfs", "impact"])
@pytest.mark.parametrize("d_over_h", [-3.0, -1.05, 1.02, 1.3, 4.0])
def test_derivatives_match_finite_differences(contact_law, d_over_h):
    cl = law(law=contact_law, regularisation=2e4)
    d = np.array([d_over_h * HALF_JT])
    rate = np.array([2e-4 * np.sign(d_over_h)])
    cf = cl.evaluate(d, rate)
    eps_d, eps_v = 1e-10, 1e-8
    fd_d = (cl.evaluate(d + eps_d, rate).force - cl.evaluate(d - eps_d, rate).force) / (2 * eps_d)
    fd_v = (cl.evaluate(d, rate + eps_v).force - cl.evaluate(d, rate - eps_v).force) / (2 * eps_v)
    np.testing.assert_allclose(cf.d_force_d_deflection, fd_d, rtol=1e-5)
    np.testing.assert_allclose(cf.d_force_d_rate, fd_v, rtol=1e-5)


def test_impact_law_step_damping_reaches_cmax_at_dmax():
    dmax, cmax = 1.0e-4, 5.0e4
    cl = law(law="impact", impact_depth_m=dmax, impact_damping=cmax)
    rate = 1.0e-3
    full = cl.evaluate(np.array([HALF_JT + 2 * dmax]), np.array([rate])).force[0]
    assert full == pytest.approx(K0 * (2 * dmax) ** 1.5 + cmax * rate)
    half = cl.evaluate(np.array([HALF_JT + 0.5 * dmax]), np.array([rate])).force[0]
    assert half == pytest.approx(K0 * (0.5 * dmax) ** 1.5 + cmax * 0.5 * rate)  # s^2 (3 - 2 s) = 1/2 at s = 1/2


def test_impact_damping_defaults_to_c0_times_depth():
    m = MeshContact(stiffness=K0, damping=C0, impact_depth_m=1e-4)
    assert m.impact_damping_max == pytest.approx(C0 * 1e-4)


def test_potential_energy_is_integral_of_elastic_force():
    pen = 2.0e-4
    d = HALF_JT + pen
    v = law(regularisation=1e7).potential_energy(np.array([d]))[0]
    assert v == pytest.approx(K0 * pen**2.5 / 2.5, rel=1e-4)

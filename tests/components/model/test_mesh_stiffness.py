"""Time-varying mesh stiffness: pair counts, mean preserved, smoothing, phasing, spectrum of a contact force."""

import math
from dataclasses import replace

import numpy as np
import pytest

from components import units
from components.analysis.campbell import excitation_frequencies
from components.analysis.equilibrium import static_equilibrium
from components.analysis.spectrum import amplitude_spectrum, spectral_peak_hz
from components.errors import ParameterError
from components.model.assembly import Assembly
from components.model.contact import MeshContact
from components.model.mesh_stiffness import (
    TRANSITION_FRACTION,
    max_step_s,
    mesh_frequency_hz,
    multi_pair_indicator,
    pair_fraction,
    stiffness_factor,
)
from components.model.presets import table6_gearbox, with_stage
from components.model.stages import PlanetaryStage
from components.model.wind import ConstantSpeed
from components.reference.solver import simulate_monolithic

CYCLE = np.linspace(0.0, 2.0 * math.pi, 200_000, endpoint=False)


@pytest.mark.parametrize("eps", [1.3, 1.62, 2.4, 5.64])
@pytest.mark.parametrize("variation", [0.1, 0.3, 0.6])
def test_mean_is_preserved_and_peak_to_peak_is_the_variation(eps, variation):
    p = eps - math.floor(eps)
    if variation * p >= 1.0:
        pytest.skip("stiffness would not stay positive")
    f = stiffness_factor(CYCLE, eps, variation)
    assert f.mean() == pytest.approx(1.0, abs=1e-9)
    assert f.max() - f.min() == pytest.approx(variation, rel=1e-12)
    assert f.max() == pytest.approx(1.0 + variation * (1.0 - p), rel=1e-12)
    assert f.min() == pytest.approx(1.0 - variation * p, rel=1e-12)


def test_multi_pair_zone_lasts_the_fraction_p_of_each_cycle():
    eps = 1.62
    r = multi_pair_indicator(CYCLE, eps)
    assert pair_fraction(eps) == pytest.approx(0.62)
    # zone where ceil(eps) pairs carry load (r > 1/2): [0, 2 pi p)
    inside = r > 0.5
    assert inside.mean() == pytest.approx(0.62, abs=1e-4)
    assert inside[int(0.03 * CYCLE.size)] and inside[int(0.6 * CYCLE.size)] and not inside[int(0.63 * CYCLE.size)]
    assert r[0] == pytest.approx(0.5)  # phase 0 is the middle of the rising edge
    # periodic: one mesh cycle later the same value
    assert multi_pair_indicator(CYCLE + 2 * math.pi, eps) == pytest.approx(r, abs=1e-9)


def test_variation_one_over_epsilon_is_stiffness_proportional_to_pairs_in_contact():
    eps = 1.62
    f = stiffness_factor(CYCLE, eps, 1.0 / eps)
    assert f.max() / f.min() == pytest.approx(2.0 / 1.0, rel=1e-12)  # 2 pairs vs 1 pair


def test_integer_contact_ratio_gives_constant_stiffness():
    assert stiffness_factor(CYCLE, 2.0, 0.5) == pytest.approx(np.ones_like(CYCLE))


def test_transitions_are_smooth_c2_ramps_of_the_documented_width():
    eps, v = 1.62, 0.3
    x = np.linspace(-0.1, 0.1, 40_001) * 2 * math.pi  # +-0.1 mesh cycle around the rising edge at phase 0
    f = stiffness_factor(x, eps, v)
    ramp = (f > f.min() + 1e-12) & (f < f.max() - 1e-12)
    width = (x[ramp].max() - x[ramp].min()) / (2 * math.pi)
    assert width == pytest.approx(TRANSITION_FRACTION, rel=1e-3)
    # refining the grid: k-th differences shrink like h^k only if the k-th derivative is bounded;
    # a kink (C0) would give h, a jump in curvature (C1) h^2 for the third difference
    for k in (2, 3):
        d = [np.abs(np.diff(stiffness_factor(np.linspace(-0.05, 0.05, n), eps, v), k)).max() for n in (2_001, 4_001)]
        assert d[1] / d[0] == pytest.approx(0.5**k, rel=0.05)


@pytest.mark.parametrize("kwargs, match", [
    (dict(contact_ratio=0.8, variation=0.1), "contact_ratio"),
    (dict(contact_ratio=1.62, variation=-0.1), "stiffness_variation"),
    (dict(contact_ratio=1.62, variation=1.7), "stiffness_variation"),
])
def test_bad_stiffness_parameters_are_rejected(kwargs, match):
    with pytest.raises(ParameterError, match=match):
        stiffness_factor(CYCLE[:10], **kwargs)


def test_mesh_contact_validates_the_variation():
    with pytest.raises(ParameterError, match="stiffness_variation"):
        MeshContact(stiffness=1e10, stiffness_variation=0.95)


def test_mesh_rates_match_the_campbell_mesh_frequencies():
    """The stiffness phase advances at each stage's mesh frequency (Z_ring x carrier, Z_drive x drive)."""
    dt = table6_gearbox()
    a = Assembly(dt)
    w = units.rpm(16.0)
    lines = excitation_frequencies(dt, w)
    for m in a.meshes:
        f = float(mesh_frequency_hz(m.teeth_per_driver_rad, w))
        assert f == pytest.approx(float(lines[f"{m.stage} mesh"][0]), rel=1e-12)
    assert float(lines["stage1 mesh"][0]) == pytest.approx(180 * 16 / 60)
    assert float(lines["stage2 mesh"][0]) == pytest.approx(140 * 10 * 16 / 60)
    assert float(lines["stage3 mesh"][0]) == pytest.approx(20 * 80 * 16 / 60)


def test_sequential_planet_phasing_follows_parker_and_lin():
    """Offsets -Z_sun psi_i (sun meshes) and +Z_ring psi_i (ring meshes); with the assembly condition
    (Z_sun + Z_ring) / n integer the sun and ring mesh of every planet are in the same relative phase."""
    dt = table6_gearbox()
    s1 = dt.stages[0]
    # Z_sun 21, Z_ring 81: (21 + 81) / 3 = 34, equally spaced planets can be assembled
    r_s, r_r = PlanetaryStage.radii_from_teeth("stage1", 10.0, 21, 81)
    ok = with_stage(dt, 0, sun_radius_m=r_s, ring_radius_m=r_r)
    for drivetrain, z_s, z_r in ((dt, 20, 180), (ok, 21, 81)):
        a = Assembly(drivetrain)
        sun = [m for m in a.meshes if m.stage == "stage1" and m.kind == "sun_planet"]
        ring = [m for m in a.meshes if m.stage == "stage1" and m.kind == "ring_planet"]
        for i, (ms, mr) in enumerate(zip(sun, ring)):
            psi = 2 * math.pi * i / s1.n_planets
            assert ms.phase_offset_rad == pytest.approx(-z_s * psi)
            assert mr.phase_offset_rad == pytest.approx(z_r * psi)
        gap = [(mr.phase_offset_rad - ms.phase_offset_rad) % (2 * math.pi) for ms, mr in zip(sun, ring)]
        consistent = np.allclose(np.minimum(gap, 2 * math.pi - np.array(gap)), 0.0, atol=1e-9)
        assert consistent is ((z_s + z_r) % 3 == 0)  # the paper's 20/180 teeth violate the assembly condition


def test_step_cap_is_half_a_transition_of_the_fastest_varying_mesh():
    a = Assembly(table6_gearbox().with_meshes(stiffness_variation=0.3))
    w = units.rpm(16.0)
    period = 1.0 / (20 * 80 * 16 / 60)  # stage-3 mesh period
    assert max_step_s(a.mesh_phase_rate, a.mesh_stiffness_variation, w) == pytest.approx(0.5 * TRANSITION_FRACTION * period)
    assert max_step_s(a.mesh_phase_rate, np.zeros(a.n_mesh), w) == math.inf


@pytest.fixture(scope="module")
def stage3_varying_run():
    """Table 6 at constant 16 rpm from the static equilibrium, stage-3 stiffness varying (v = 0.3)."""
    base = table6_gearbox()
    s3 = base.stages[2]
    dt = with_stage(base, 2, mesh=replace(s3.mesh, stiffness_variation=0.3))
    eq = static_equilibrium(dt, dt.generator.counter_torque_nm)
    h = 1e-4  # 10 kHz sampling, Nyquist 5 kHz
    result = simulate_monolithic(dt, ConstantSpeed(units.rpm(16.0)), 0.12, output_interval_s=h, initial_state=eq.state)
    return result, h


def test_stage3_force_spectrum_peaks_at_the_stage3_mesh_frequency(stage3_varying_run):
    result, h = stage3_varying_run
    assert result.complete
    f_mesh = 20 * 80 * 16 / 60  # Z_drive x drive speed: 426.67 Hz
    x = result["stage3.F_mesh"]
    freq, amp = amplitude_spectrum(x, h)
    bin_hz = freq[1] - freq[0]
    k = int(np.argmax(amp[1:])) + 1
    assert abs(freq[k] - f_mesh) <= bin_hz
    assert abs(spectral_peak_hz(x, h, window="hann") - f_mesh) <= 0.1 * bin_hz


def test_time_varying_stiffness_keeps_the_mean_force(stage3_varying_run):
    """Mean force unchanged (mean stiffness preserved); no spurious drops from steps across a zone."""
    result, _ = stage3_varying_run
    x = result["stage3.F_mesh"][result.time_s > 0.005]  # after the start from the mean-stiffness equilibrium
    quasi_static = 25.4e3 / (0.08 * math.cos(math.radians(20.0)))
    assert x.mean() == pytest.approx(quasi_static, rel=2e-3)
    assert x.min() > 0.98 * quasi_static  # the heavy mesh damping absorbs most of the stiffness change


def test_mesh_phasing_matches_the_stiffness_factor_and_its_slope_is_the_derivative():
    """The phasing table the kernel reads (validated once, analytic slope) is the same model as stiffness_factor."""
    from components.model.mesh_stiffness import MeshPhasing

    dt = table6_gearbox().with_meshes(stiffness_variation=0.3)
    dt = with_stage(dt, 2, mesh=replace(dt.stages[2].mesh, contact_ratio=2.0))  # integer ratio: constant
    a = Assembly(dt)
    ph = MeshPhasing(a.mesh_phase_rate, a.mesh_phase_offset, a.mesh_contact_ratio, a.mesh_stiffness_variation)
    eps = 1e-9
    largest_slope = 0.3 * 30 / 16 / TRANSITION_FRACTION * a.mesh_phase_rate.max() / (2 * math.pi)  # v S'(1/2) / w x cycles/rad
    for angle in np.linspace(0.0, 0.05, 997):  # many stage-1/2 mesh transitions
        phase = angle * a.mesh_phase_rate + a.mesh_phase_offset
        expected = stiffness_factor(phase, a.mesh_contact_ratio, a.mesh_stiffness_variation)
        f, slope = ph.factor_and_slope(angle)
        np.testing.assert_allclose(ph.factor(angle), expected, rtol=0, atol=1e-12)
        np.testing.assert_allclose(f, expected, rtol=0, atol=1e-12)
        fd = (ph.factor(angle + eps) - ph.factor(angle - eps)) / (2 * eps)
        np.testing.assert_allclose(slope, fd, rtol=1e-5, atol=1e-6 * largest_slope)
    assert np.all(ph.factor(0.0123)[-1] == 1.0)  # the integer-ratio stage-3 mesh
    with pytest.raises(ParameterError, match="stiffness_variation"):
        MeshPhasing(a.mesh_phase_rate, a.mesh_phase_offset, a.mesh_contact_ratio, np.full(a.n_mesh, 2.0))


def test_the_kernels_stiffness_rate_is_the_time_derivative_of_the_acceleration():
    """da/dt of the gearbox at a fixed state with the stiffness varying with the driver angle
    (:func:`components.model.kernel.dynamics.stiffness_rate`) against a central difference of the kernel's
    acceleration in time, inside a stage-3 stiffness transition."""
    from components.model.kernel import dynamics

    base = table6_gearbox()
    dt = with_stage(base, 2, mesh=replace(base.stages[2].mesh, stiffness_variation=0.3))
    a = Assembly(dt, cut_at_generator=True)
    n, m = a.n_dof, a.n_mesh
    # loaded state: the static equilibrium of the whole drivetrain, generator (the port) removed
    eq = static_equilibrium(dt, dt.generator.counter_torque_nm)
    names = Assembly(dt).dof_names
    y = np.concatenate((eq.q_rad[[names.index(b) for b in a.dof_names]], np.zeros(n)))
    port = float(eq.q_rad[names.index("generator")])
    speed = units.rpm(16.0)
    angles = np.linspace(0.0, speed * 1e-3, 20001)
    tau_angle = float(angles[np.argmax(np.abs(a.phasing.factors(angles)[1][:, -1]))])  # steepest stage-3 ramp

    def acc(angle):
        out, z, defl = np.zeros(n), np.zeros(m + 2 * n + 4), np.zeros((2, m))
        dynamics.acceleration(y, port, 0.0, 0.0, a.stiffness_factor(angle), a.nz_index, a.nz_value, a.port_deflection,
                              a.mesh_offset, a.fast_index, a.fast_value, a.law.table, z, defl, out)
        return out

    h = 1e-9 * speed
    fd = (acc(tau_angle + h) - acc(tau_angle - h)) / (2 * h / speed)
    analytic = np.zeros(n)
    dynamics.stiffness_rate(y, n, tau_angle, speed, port, 0.0, a.nz_index, a.nz_value, a.port_deflection, a.mesh_offset,
                            a.law.table,
                            a.phasing_table, a.force_rows, np.zeros(m), np.zeros(m), np.zeros((2, m)), np.zeros(m),
                            analytic)
    assert np.abs(analytic).max() > 1e3  # the stiffness term dominates here
    np.testing.assert_allclose(analytic, fd, rtol=1e-4, atol=1e-5 * np.abs(fd).max())

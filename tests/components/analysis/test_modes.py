"""Modal analysis: generic eigen-solutions, linearisation, Lin-Parker planet modes, closed forms, free response."""

import json
import math

import numpy as np
import pytest

from components import units
from components.analysis.eigen import modal_analysis, state_space_modes, undamped_modes
from components.analysis.equilibrium import OperatingPoint, static_equilibrium
from components.analysis.modal_verification import free_response_check
from components.analysis.modes import drivetrain_modes, two_inertia_frequency_hz
from components.analysis.spectrum import spectral_peak_hz
from components.errors import ParameterError
from components.model.assembly import Assembly
from components.model.presets import cosim_preset, table5_planetary, table6_gearbox
from components.model.wind import ConstantSpeed
from components.reference.solver import MonolithicSystem

COS20 = math.cos(math.radians(20.0))
TABLE6_POINT = OperatingPoint.from_rpm(16.0, 25.4e3)


@pytest.fixture(scope="module")
def table6_modes():
    return drivetrain_modes(table6_gearbox(), TABLE6_POINT)


# ------------------------------------------------------------------ generic core
@pytest.mark.parametrize("k, j1, j2", [(1.0e3, 1.0, 1.0), (5.73e3, 151.0, 0.025), (5.73e7, 0.0612, 4.3)])
def test_two_inertia_shaft_matches_closed_form(k, j1, j2):
    modes = undamped_modes(np.array([j1, j2]), k * np.array([[1.0, -1.0], [-1.0, 1.0]]))
    assert modes.frequency_hz[0] == 0.0  # free-free: rigid-body rotation
    expected = math.sqrt(k * (j1 + j2) / (j1 * j2)) / (2 * math.pi)
    assert modes.frequency_hz[1] == pytest.approx(expected, rel=1e-12)
    assert two_inertia_frequency_hz(k, j1, j2) == pytest.approx(expected, rel=1e-15)
    u = modes.shapes[:, 1]
    assert j1 * u[0] == pytest.approx(-j2 * u[1], rel=1e-9)  # the nodal point: zero net angular momentum


def test_free_free_system_has_no_state_space_modes():
    with pytest.raises(ParameterError, match="rigid-body"):
        state_space_modes(np.array([1.0, 2.0]), np.zeros((2, 2)), np.array([[1.0, -1.0], [-1.0, 1.0]]))


@pytest.mark.parametrize("zeta", [0.02, 0.3, 0.99, 1.5, 20.0])
def test_single_oscillator_damping_ratio_and_overdamped_flag(zeta):
    m, k = 2.0, 800.0
    wn = math.sqrt(k / m)
    c = 2.0 * zeta * math.sqrt(k * m)
    modes, ss, _ = modal_analysis(np.array([m]), np.array([[c]]), np.array([[k]]))
    mode = modes[0]
    assert mode.undamped_frequency_hz == pytest.approx(wn / (2 * math.pi), rel=1e-12)
    assert mode.damping_ratio == pytest.approx(zeta, rel=1e-9)
    assert mode.overdamped is (zeta >= 1.0)
    if zeta < 1.0:
        assert mode.damped_frequency_hz == pytest.approx(wn * math.sqrt(1 - zeta**2) / (2 * math.pi), rel=1e-9)
    else:
        assert math.isnan(mode.damped_frequency_hz)
        roots = np.sort(-ss.eigenvalues.real)
        assert roots == pytest.approx(np.sort([wn * (zeta - math.sqrt(zeta**2 - 1)), wn * (zeta + math.sqrt(zeta**2 - 1))]), rel=1e-9)


def test_left_eigenvectors_are_biorthonormal(table6_modes):
    ss = table6_modes.state_space
    gram = ss.left.conj().T @ ss.right
    assert np.abs(gram - np.eye(gram.shape[0])).max() < 1e-8


@pytest.mark.parametrize("bad, match", [
    (dict(mass=np.array([[1.0, 0.5], [0.0, 1.0]]), stiffness=np.eye(2)), "symmetric"),
    (dict(mass=np.eye(2), stiffness=np.eye(3)), "square matrix of size 2"),
    (dict(mass=np.eye(2), stiffness=-np.eye(2)), "positive semi-definite"),
])
def test_undamped_modes_rejects_bad_matrices(bad, match):
    with pytest.raises(ParameterError, match=match):
        undamped_modes(**bad)


# ------------------------------------------------------------------ linearisation
def test_table6_equilibrium_carries_the_quasi_static_loads(table6_modes):
    eq = table6_modes.model.equilibrium
    a = table6_modes.model.assembly
    f = dict(zip(a.mesh_names, eq.contact_force_n))
    t_gen = 25.4e3
    # torque on each stage's output member / (n planets * sun pitch radius * cos alpha)
    assert f["stage1.F_sp[1]"] == pytest.approx(t_gen * 8 * 1.25 / (3 * 0.1 * COS20), rel=1e-9)
    assert f["stage1.F_rp[2]"] == pytest.approx(f["stage1.F_sp[2]"], rel=1e-9)
    assert f["stage2.F_sp[3]"] == pytest.approx(t_gen * 1.25 / (3 * 0.1 * COS20), rel=1e-9)
    assert f["stage3.F_mesh"] == pytest.approx(t_gen / (0.08 * COS20), rel=1e-9)
    # Table 7 means are these quasi-static forces
    assert f["stage1.F_sp[1]"] == pytest.approx(9.0067e5, rel=1e-3)
    assert f["stage2.F_sp[1]"] == pytest.approx(1.1261e5, rel=1e-3)
    assert f["stage3.F_mesh"] == pytest.approx(3.3786e5, rel=1e-3)
    assert eq.shaft_torque_nm == pytest.approx([254e3, 31.75e3, 25.4e3], rel=1e-9)
    assert eq.rotor_torque_nm == pytest.approx(100 * t_gen, rel=1e-9)


def test_equilibrium_newton_converges_with_unequal_planet_stiffness():
    dt = table6_gearbox()
    a = Assembly(dt)
    factor = np.linspace(0.8, 1.25, a.n_mesh)  # planets no longer share equally
    eq = static_equilibrium(a, 25.4e3, stiffness_factor=factor)
    assert eq.iterations >= 1
    assert eq.residual_nm < 1e-9 * 2.54e6
    sp1 = eq.contact_force_n[:3]
    assert np.ptp(sp1) > 1e3  # unequal load sharing
    assert sp1.sum() == pytest.approx(3 * 25.4e3 * 10 / (3 * 0.1 * COS20), rel=1e-9)  # the sun torque is still T * 10


def test_stiffness_and_damping_are_the_simulation_jacobian(table6_modes):
    """K = -M dA/dq and C = -M dA/dv agree with finite differences of the monolithic right-hand side."""
    model = table6_modes.model
    system = MonolithicSystem(table6_gearbox(), ConstantSpeed(TABLE6_POINT.rotor_speed_rad_s))
    n = system.n
    y0 = np.concatenate([model.equilibrium.state, np.zeros(3)])
    m = np.diag(model.mass)
    for block, matrix, scale in ((0, model.stiffness, 1e-9), (n, model.damping, 1e-7)):
        fd = np.zeros((n, n))
        for j in range(n):
            h = scale
            yp, ym = y0.copy(), y0.copy()
            yp[block + j] += h
            ym[block + j] -= h
            fd[:, j] = -(m * (system.rhs(0.0, yp)[n : 2 * n] - system.rhs(0.0, ym)[n : 2 * n])) / (2 * h)
        assert np.abs(fd - matrix).max() < 1e-5 * np.abs(matrix).max()


def test_operating_point_rejects_zero_torque():
    with pytest.raises(ParameterError, match="non-zero"):
        OperatingPoint.from_rpm(16.0, 0.0)


@pytest.mark.parametrize("torque_nm", [2.0e3, 25.4e3, -10.0e3])
def test_parallel_stage_with_generator_matches_two_degree_of_freedom_closed_form(torque_nm):
    """Table 3 stage + shaft 3 + generator: ground -(mesh)- driven gear -(shaft 3)- generator.

    (lambda = 600/mm as in Table 6 so the teeth are deep in the flank: d_BL = delta - j_t / 2.)

    Mesh force F = T / (r_driven cos alpha); penetration p = (|F| / k0)^(2/3); torsional mesh
    stiffness cos alpha * 1.5 k0 p^0.5 * r^2 and damping cos alpha * c0 p * r^2. The
    eigenvalues solve det(lambda^2 M + lambda C + K) = 0, a quartic in closed form.
    """
    dt = cosim_preset("table3").with_meshes(regularisation=units.regularisation(600.0))  # deep contact
    st = dt.stages[0]
    mesh = st.mesh
    r = st.driven_radius_m
    force = abs(torque_nm) / (r * COS20)
    pen = (force / mesh.stiffness) ** (1 / 1.5)
    k_m = COS20 * 1.5 * mesh.stiffness * pen**0.5 * r**2
    c_m = COS20 * mesh.damping * pen * r**2
    k3, c3 = dt.output_shaft.stiffness_nm_per_rad, dt.output_shaft.damping_nms_per_rad
    jd, jg = st.driven_inertia_kgm2, dt.generator.inertia_kgm2
    # undamped: jd jg w^4 - (jd k3 + jg (k_m + k3)) w^2 + k_m k3 = 0
    b = jd * k3 + jg * (k_m + k3)
    w2 = np.sort(np.roots([jd * jg, -b, k_m * k3]).real)
    an = drivetrain_modes(dt, OperatingPoint.from_rpm(5.0, torque_nm))
    f = [m.mode.system_frequency_hz for m in an.modes]  # the undamped system's
    assert f == pytest.approx(np.sqrt(w2) / (2 * math.pi), rel=1e-8)
    quartic = np.polysub(np.polymul([jd, c_m + c3, k_m + k3], [jg, c3, k3]), np.polymul([c3, k3], [c3, k3]))
    lam = np.roots(quartic)
    got = an.state_space.eigenvalues
    assert np.sort_complex(got) == pytest.approx(np.sort_complex(lam), rel=1e-6)
    # each row: the undamped (|lambda|) and damped (Im lambda) frequency of one eigenvalue of the quartic
    oscillating = np.sort_complex(lam[lam.imag > 0])
    rows = [m.mode for m in an.modes if not m.mode.overdamped]
    assert [r.undamped_frequency_hz for r in rows] == pytest.approx(np.sort(np.abs(oscillating)) / (2 * math.pi),
                                                                    rel=1e-6)
    assert all(r.damped_frequency_hz <= r.undamped_frequency_hz for r in rows)


# ------------------------------------------------------------------ Lin and Parker
def test_table6_planet_modes_have_multiplicity_n_minus_1(table6_modes):
    """3 equally spaced identical planets per stage: one pair of equal frequencies per planetary stage."""
    modes = table6_modes.modes
    f = np.array([m.mode.undamped_frequency_hz for m in modes])
    pairs = [(i, i + 1) for i in range(f.size - 1) if abs(f[i + 1] - f[i]) <= 1e-9 * f[i]]
    assert len(pairs) == 2
    stages = []
    for i, j in pairs:
        assert modes[i].kind == modes[j].kind == "planet"
        assert modes[i].stage == modes[j].stage
        stages.append(modes[i].stage)
    assert sorted(stages) == ["stage1", "stage2"]
    # every other mode is simple (well separated) and rotational
    simple = [k for k in range(f.size) if not any(k in p for p in pairs)]
    assert all(modes[k].kind == "rotational" for k in simple)
    gaps = np.diff(np.sort(f[simple]))
    assert gaps.min() > 1e-3 * f[simple].min()
    # planet modes: central members still, planet deflections sum to zero
    names = table6_modes.dof_names
    for i, _ in pairs:
        u = modes[i].mode.shape
        planets = [k for k, nm in enumerate(names) if nm.startswith(modes[i].stage + ".planet")]
        others = [k for k in range(len(names)) if k not in planets]
        assert np.abs(u[others]).max() < 1e-8
        assert abs(u[planets].sum()) < 1e-8


def test_planet_mode_roots_are_repeated_in_the_damped_system(table6_modes):
    """Each overdamped planet-mode pair gives two real roots, each (at least) twice."""
    roots = table6_modes.overdamped_roots_per_s
    n_over = sum(m.mode.overdamped for m in table6_modes.modes)
    assert roots.size == 2 * n_over  # two real roots per overdamped mode
    groups = []
    for r in roots:
        if groups and abs(r - groups[-1][0]) <= 1e-6 * r:
            groups[-1].append(r)
        else:
            groups.append([r])
    repeated = [g for g in groups if len(g) >= 2]
    assert len(repeated) >= 4  # 2 planetary stages x 2 roots


@pytest.mark.parametrize("n_planets", [3, 4, 5])
def test_planet_mode_multiplicity_for_n_planets(n_planets):
    dt = table5_planetary(output_torque_nm=1000.0, n_planets=n_planets)
    an = drivetrain_modes(dt, OperatingPoint.from_rpm(5.0, 1000.0))
    f = np.array([m.mode.undamped_frequency_hz for m in an.modes])
    planet = [m for m in an.modes if m.kind == "planet"]
    assert len(planet) == n_planets - 1
    fp = np.array([m.mode.undamped_frequency_hz for m in planet])
    assert np.ptp(fp) <= 1e-9 * fp[0]
    rotational = [m.mode.undamped_frequency_hz for m in an.modes if m.kind == "rotational"]
    assert len(rotational) == f.size - (n_planets - 1)
    assert np.min(np.abs(np.subtract.outer(rotational, fp[0]))) > 1e-3 * fp[0]


# ------------------------------------------------------------------ Table 6 operating point
def test_table6_only_the_generator_mode_is_underdamped(table6_modes):
    under = table6_modes.underdamped
    assert [m.mode.index for m in under] == [1]
    gen = under[0]
    assert gen.dominant_bodies.startswith("generator")
    assert gen.mode.damping_ratio == pytest.approx(0.2965, abs=5e-4)
    assert gen.mode.damped_frequency_hz == pytest.approx(0.9102, abs=5e-4)
    for dm in table6_modes.modes[1:]:  # every gear mode: overdamped, zeta far above 1
        assert dm.mode.overdamped and dm.mode.damping_ratio > 30.0


def test_table6_generator_mode_matches_the_series_stiffness_closed_form(table6_modes):
    """Generator rotor on the drivetrain's torsional compliance chain, gear inertias neglected.

    Referred to the generator (speed ratio 100), in series: stage-1 meshes (3 planets, sun
    and ring mesh of a planet in series, on the sun at ratio 10), shaft 1 (ratio 10), stage-2
    meshes (ratio 80), shaft 2 (ratio 80), the parallel mesh (on the driven gear, ratio 100)
    and shaft 3. Tangent mesh stiffness 1.5 k0 p^0.5 at p = (F / k0)^(2/3), F the
    quasi-static force; moment arm cos(alpha) r. f = sqrt(k_eff / J_gen) / (2 pi).
    """
    dt = table6_gearbox()
    s1, s2, s3 = dt.stages
    k0 = s1.sun_mesh.stiffness
    t_gen = dt.generator.counter_torque_nm

    def k_tangent(force):
        return 1.5 * k0 * (force / k0) ** (1.0 / 3.0)

    def planetary(force, stage):  # 3 planets in parallel, each sun + ring mesh in series
        return 3 * COS20 * 0.5 * k_tangent(force) * stage.sun_radius_m**2

    f1 = t_gen * 10 / (3 * s1.sun_radius_m * COS20)
    f2 = t_gen * 1.25 / (3 * s2.sun_radius_m * COS20)
    f3 = t_gen / (s3.driven_radius_m * COS20)
    sh1, sh2, sh3 = dt.all_shafts
    chain = [
        (planetary(f1, s1), 10.0), (sh1.stiffness_nm_per_rad, 10.0),
        (planetary(f2, s2), 80.0), (sh2.stiffness_nm_per_rad, 80.0),
        (COS20 * k_tangent(f3) * s3.driven_radius_m**2, 100.0), (sh3.stiffness_nm_per_rad, 100.0),
    ]
    k_eff = 1.0 / sum(1.0 / (k * (ratio / 100.0) ** 2) for k, ratio in chain)
    expected = math.sqrt(k_eff / dt.generator.inertia_kgm2) / (2 * math.pi)
    assert table6_modes.modes[0].mode.system_frequency_hz == pytest.approx(expected, rel=1e-5)
    # the gearbox compliance lowers it 2.8 % below the rigid-gearbox value sqrt(k3 / J_gen)
    rigid = math.sqrt(sh3.stiffness_nm_per_rad / dt.generator.inertia_kgm2) / (2 * math.pi)
    assert expected / rigid == pytest.approx(0.9718, abs=1e-3)
    for dm in table6_modes.modes[1:]:
        assert dm.mode.overdamped and dm.mode.damping_ratio > 1.0


def test_modal_analysis_is_json_serialisable(table6_modes):
    d = json.loads(json.dumps(table6_modes.as_dict()))
    assert d["n_underdamped"] == 1
    assert len(d["modes"]) == 12
    assert d["modes"][0]["damped_frequency_hz"] == pytest.approx(0.9102, abs=5e-4)
    rows = table6_modes.table_rows()
    assert rows[3]["kind"] == "planet (stage1)" and rows[3]["overdamped"] is True


@pytest.mark.parametrize("c0_ns_per_mm2, min_underdamped", [(5.0e4, 1), (50.0, 8)])
def test_free_response_peaks_match_every_underdamped_mode(c0_ns_per_mm2, min_underdamped):
    """Impulse from the static equilibrium, nonlinear monolithic model, modal projection: within 2 %.

    5e4 N s/mm^2 is Table 6 (only the generator mode oscillates); 50 N s/mm^2 is the
    contact damping of the paper's Fig. 10-11 run, which leaves most gear modes underdamped.
    """
    dt = table6_gearbox().with_meshes(damping=units.contact_damping(c0_ns_per_mm2))
    analysis = drivetrain_modes(dt, TABLE6_POINT)
    checks = free_response_check(dt, TABLE6_POINT, analysis)
    assert len(checks) == len(analysis.underdamped) >= min_underdamped
    for c in checks:
        assert abs(c.relative_error) < 0.02, c
        assert abs(c.relative_error) < 1e-3, c  # what it actually achieves


def test_spectral_peak_of_a_complex_mode_is_the_damped_frequency():
    lam = complex(-1.8, 2 * math.pi * 0.91)
    dt = 0.01
    t = np.arange(0.0, 8.0, dt)
    eta = np.exp(lam * t)
    assert spectral_peak_hz(eta, dt) == pytest.approx(0.91, rel=1e-4)
    # a real decaying oscillation would peak elsewhere (why the check projects on the complex mode)
    assert abs(spectral_peak_hz(np.real(eta), dt) / 0.91 - 1.0) > 0.02


# ------------------------------------------------------- a user's gearbox with 4 and 5 planets (issue 29.5)
@pytest.fixture(scope="module")
def four_and_five_planets():
    """Planetary stages with 4 and 5 planets and a parallel stage, lightly damped: 12 of its 15 modes oscillate."""
    from pathlib import Path

    from orchestrator.inputs.drivetrain_file import load_drivetrain_file

    spec = load_drivetrain_file(Path(__file__).parents[2] / "data" / "drivetrains" / "four-and-five-planets.toml")
    return drivetrain_modes(spec.drivetrain, TABLE6_POINT)


def test_each_row_gives_the_undamped_and_damped_frequency_of_one_eigenvalue(four_and_five_planets):
    """The table paired the undamped frequency of one mode with the damped frequency of another (283 -> 964 Hz)."""
    ss = four_and_five_planets.state_space
    oscillating = np.flatnonzero(ss.is_complex() & (ss.eigenvalues.imag > 0))
    rows = [m.mode for m in four_and_five_planets.modes if not m.mode.overdamped]
    assert len(rows) == oscillating.size >= 10
    assert sorted(r.eigen_index for r in rows) == sorted(oscillating)  # every oscillating eigenvalue, once
    for r in rows:
        lam = ss.eigenvalues[r.eigen_index]
        assert r.eigenvalue == lam
        assert r.undamped_frequency_hz == pytest.approx(abs(lam) / (2 * math.pi), rel=1e-12)
        assert r.damped_frequency_hz == pytest.approx(lam.imag / (2 * math.pi), rel=1e-12)
        assert r.damped_frequency_hz <= r.undamped_frequency_hz
        assert r.damping_ratio == pytest.approx(-lam.real / abs(lam), rel=1e-12)


def test_each_row_is_described_by_its_own_shape(four_and_five_planets):
    """Rows are ordered by |lambda|, the undamped shapes by the undamped system's frequency: the kinds and dominant
    bodies were taken from the shape of the same position in the other order (a planet mode called rotational,
    a rotational one 'planet stage1')."""
    modes = four_and_five_planets.modes
    planet = {stage: [m for m in modes if m.kind == "planet" and m.stage == stage] for stage in ("stage1", "stage2")}
    assert [len(planet["stage1"]), len(planet["stage2"])] == [3, 4]  # n - 1 planet modes per stage
    for group in planet.values():
        f = [m.mode.undamped_frequency_hz for m in group]
        assert np.ptp(f) <= 1e-9 * f[0]
        assert all(m.dominant_bodies == f"{m.stage}.planets 100%" for m in group)
    rotational = [m for m in modes if m.kind == "rotational"]
    assert all(".planets 100%" not in m.dominant_bodies for m in rotational)
    assert [m.mode.undamped_frequency_hz for m in modes] == sorted(m.mode.undamped_frequency_hz for m in modes)
    assert [m.mode.system_frequency_hz for m in modes] != sorted(m.mode.system_frequency_hz for m in modes)

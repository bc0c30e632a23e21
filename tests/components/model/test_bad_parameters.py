"""Every bad parameter raises ParameterError naming it and its value, before anything is integrated."""

import math
from dataclasses import replace

import pytest

from components.errors import ParameterError
from components.model.contact import MeshContact
from components.model.generator import GeneratorParameters, LoadEvent
from components.model.parameter_map import unflatten
from components.model.presets import table6_gearbox
from components.model.stages import PlanetaryStage, Shaft
from components.model.wind import WindParameters

NAN = float("nan")


def stage1():
    return table6_gearbox().stages[0]


CASES = [
    ("negative inertia", lambda: replace(stage1(), planet_inertia_kgm2=-1.0), r"stage1\.planet_inertia_kgm2 = -1\.0"),
    ("zero inertia", lambda: replace(stage1(), sun_inertia_kgm2=0.0), r"stage1\.sun_inertia_kgm2 = 0\.0"),
    ("zero generator inertia", lambda: GeneratorParameters(inertia_kgm2=0.0), r"generator\.inertia_kgm2 = 0\.0"),
    ("zero module", lambda: PlanetaryStage.radii_from_teeth("stage1", 0.0, 20, 180), r"stage1\.sun\.module = 0\.0"),
    ("ring not larger than sun", lambda: replace(stage1(), ring_radius_m=0.1), r"stage1\.ring_radius_m = 0\.1.*larger than sun"),
    ("negative backlash", lambda: MeshContact.from_paper(5e5, 5e4, 600, -0.1), r"backlash = -0\.1"),
    ("lambda zero", lambda: MeshContact.from_paper(5e5, 5e4, 0.0, 0.56), r"lambda = 0\.0"),
    ("lambda negative", lambda: MeshContact(stiffness=1e9, regularisation=-5.0), r"lambda = -5\.0"),
    ("no harmonics", lambda: WindParameters(n_harmonics=0), r"wind\.n_harmonics = 0"),
    ("NaN inertia", lambda: replace(stage1(), planet_mass_kg=NAN), r"stage1\.planet_mass_kg = nan"),
    ("NaN stiffness", lambda: MeshContact(stiffness=NAN), r"stiffness = nan"),
    ("NaN wind sigma", lambda: WindParameters(sigma_rad_s=NAN), r"wind\.sigma = nan"),
    ("NaN shaft", lambda: Shaft("shaft2", NAN), r"shaft2\.stiffness_nm_per_rad = nan"),
    ("NaN torque", lambda: GeneratorParameters(counter_torque_nm=NAN), r"generator\.counter_torque_nm = nan"),
    ("inf damping", lambda: MeshContact(stiffness=1e9, damping=math.inf), r"damping = inf"),
    ("NaN event", lambda: LoadEvent("grid_fault", NAN, 1.0), r"event\.start_s = nan"),
    ("flat NaN", lambda: unflatten(table6_gearbox(), {"stage2.c0": NAN}), r"stage2\.c0 = nan"),
    ("flat negative backlash", lambda: unflatten(table6_gearbox(), {"stage3.backlash": -1e-4}), r"stage3\.backlash = -0\.0001"),
    ("unknown flat name", lambda: unflatten(table6_gearbox(), {"stage9.k0": 1.0}), r"stage9\.k0"),
    ("wrong type", lambda: WindParameters(seed="one"), r"wind\.seed = 'one'"),
]


@pytest.mark.parametrize("label,make,pattern", CASES, ids=[c[0] for c in CASES])
def test_bad_parameter_is_named(label, make, pattern):
    with pytest.raises(ParameterError, match=pattern):
        make()


def test_error_carries_name_value_expectation():
    with pytest.raises(ParameterError) as info:
        WindParameters(f_min_rad_s=3.0, f_max_rad_s=2.0)
    err = info.value
    assert (err.name, err.value) == ("wind.f_max", 2.0)
    assert "f_min" in err.expected


def test_bad_parameter_raises_before_integration(monkeypatch):
    """A bad drivetrain never reaches the integrator."""
    import components.reference.solver as ref

    called = []
    monkeypatch.setattr(ref, "odeint", lambda *a, **k: called.append(1))
    with pytest.raises(ParameterError):
        ref.simulate_monolithic(unflatten(table6_gearbox(), {"stage1.lambda": 0.0}), None, 1.0)
    assert not called

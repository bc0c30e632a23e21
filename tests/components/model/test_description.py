"""Parameter sets as plain JSON data and back (the record an FMU carries of its physics)."""

from __future__ import annotations

import json
import math
from dataclasses import replace

import pytest

from components.errors import ParameterError
from components.model.description import build, describe
from components.model.generator import GeneratorParameters, LoadEvent
from components.model.presets import PRESETS, cosim_preset, preset, sensitivity_variant
from components.model.wind import WindParameters


@pytest.mark.parametrize("obj", [
    *(preset(name) for name in PRESETS),
    *(cosim_preset(name) for name in PRESETS),
    sensitivity_variant(8.0, 300.0),
    WindParameters(seed=7, amplitude="paper"),
    GeneratorParameters(events=(LoadEvent("torque_step", 10.0), LoadEvent("grid_fault", 20.0, 0.5))),
], ids=lambda o: type(o).__name__)
def test_describe_then_build_gives_the_same_object_through_strict_json(obj):
    text = json.dumps(describe(obj), allow_nan=False)  # strict JSON: inf is written as {"float": "inf"}
    assert build(json.loads(text)) == obj


def test_a_permanent_event_keeps_its_infinite_duration():
    data = describe(LoadEvent("torque_step", 1.0))
    assert data["duration_s"] == {"float": "inf"}
    assert math.isinf(build(data).duration_s)


@pytest.mark.parametrize("change, match", [
    (lambda d: d | {"type": "Turbine"}, "description.type"),
    (lambda d: {k: v for k, v in d.items() if k != "seed"}, "exactly the fields of WindParameters"),
    (lambda d: d | {"colour": "red"}, "colour"),
    (lambda d: d | {"seed": -3}, "wind.seed"),
])
def test_a_bad_description_is_a_named_error(change, match):
    with pytest.raises(ParameterError, match=match):
        build(change(describe(WindParameters())))


def test_values_are_validated_again_when_built():
    data = describe(replace(cosim_preset("table6")))
    data["stages"][0]["n_planets"] = 0
    with pytest.raises(ParameterError, match="stage1.n_planets"):
        build(data)

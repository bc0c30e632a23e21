"""The Modelica Reference-FMUs through ``dtcosim run``: every output of every type equals fmpy, and the published results.

fmpy's ``simulate_fmu(..., fmi_type="CoSimulation")`` steps the FMU once per output
interval, so a one-FMU scenario with ``step`` = that interval makes the same FMI calls:
Reals must agree exactly (difference 0), the other types be equal. fmpy records no
String variables; Feedthrough's String output is checked against the published result.
"""

from __future__ import annotations

import json

import numpy as np
import pytest
from fmpy import read_model_description, simulate_fmu

from tests.helpers.reference_fmus import (
    NAMES,
    as_numbers,
    published_result,
    read_typed_timeseries,
    reference_fmu,
)
from tests.helpers.scenarios import dtcosim, write_scenario

#: the published results' experiment: (stop time [s], output interval [s])
EXPERIMENTS = {"BouncingBall": (3.0, 0.01), "Dahlquist": (10.0, 0.1), "Feedthrough": (2.0, 0.1),
               "Stair": (10.0, 0.2), "VanDerPol": (20.0, 0.01), "Resource": (1.0, 1.0)}
#: published Reals are the same FMU's output written with ~16 significant digits
PUBLISHED_RTOL = 1e-12


def scenario_text(name: str, stop: float, step: float, start_values: dict | None = None) -> str:
    lines = [f'name = "{name.lower()}"', "[simulation]", f"stop = {stop!r}", f"step = {step!r}",
             f"[components.{name.lower()}]", f'fmu = "{reference_fmu(name).as_posix()}"']
    if start_values:
        lines.append(f"[components.{name.lower()}.parameters]")
        lines += [f'"{k}" = {v!r}' for k, v in start_values.items()]
    return "\n".join(lines) + "\n"


def run_dtcosim(tmp_path, name: str, stop: float, step: float, start_values: dict | None = None):
    scenario = write_scenario(tmp_path, scenario_text(name, stop, step, start_values), f"{name}.toml")
    out = tmp_path / f"out-{name}"
    proc = dtcosim("run", str(scenario), "--out", str(out), "--no-plots", "--quiet", "--no-build", cwd=tmp_path)
    return proc, out


def fmpy_outputs(name: str, stop: float, step: float, start_values: dict | None = None):
    path = reference_fmu(name)
    md = read_model_description(str(path))
    outputs = [v.name for v in md.modelVariables if v.causality == "output" and v.type != "String"]
    return simulate_fmu(str(path), fmi_type="CoSimulation", stop_time=stop, output_interval=step, output=outputs,
                        start_values=start_values or {})


def assert_equal_to_fmpy(columns: dict, tags: dict, component: str, result) -> None:
    np.testing.assert_array_equal(as_numbers(columns["time"]), result["time"])
    for field in result.dtype.names[1:]:
        ours = columns[f"{component}.{field}"]
        theirs = result[field]
        if theirs.dtype.kind == "f":
            assert np.max(np.abs(as_numbers(ours) - theirs)) == 0.0, field
        elif theirs.dtype.kind == "b":
            assert tags[f"{component}.{field}"] == "Boolean 0/1"
            assert ours == [str(int(v)) for v in theirs], field
        else:  # Integer, Enumeration: written as integers
            assert ours == [str(int(v)) for v in theirs], field


@pytest.mark.parametrize("name", NAMES)
def test_every_output_equals_fmpy_and_the_published_result(name, tmp_path):
    stop, step = EXPERIMENTS[name]
    proc, out = run_dtcosim(tmp_path, name, stop, step)
    assert proc.returncode == 0, proc.stderr
    tags, columns = read_typed_timeseries(out / "timeseries.csv")
    component = name.lower()
    md = read_model_description(str(reference_fmu(name)))
    outputs = [v.name for v in md.modelVariables if v.causality == "output"]
    assert sorted(columns) == sorted(["time"] + [f"{component}.{o}" for o in outputs])  # every output, any type
    assert_equal_to_fmpy(columns, tags, component, fmpy_outputs(name, stop, step))

    published = published_result(name)
    np.testing.assert_allclose(as_numbers(columns["time"]), as_numbers(published["time"]), rtol=1e-12, atol=0)
    types = {v.name: v.type for v in md.modelVariables}
    for field, expected in published.items():
        if field == "time" or f"{component}.{field}" not in columns:
            continue  # the published Feedthrough result also has the FMI 3 variants' columns
        ours = columns[f"{component}.{field}"]
        if types[field] == "Real":
            np.testing.assert_allclose(as_numbers(ours), as_numbers(expected), rtol=PUBLISHED_RTOL, atol=1e-300,
                                       err_msg=field)
        elif types[field] == "Boolean":
            assert ours == [{"false": "0", "true": "1"}[x] for x in expected], field
        else:  # Integer, Enumeration, String (written as they are)
            assert ours == expected, field


def test_stair_ends_the_run_itself_normally(tmp_path):
    proc, out = run_dtcosim(tmp_path, "Stair", 20.0, 0.2)  # the FMU terminates at t = 9 s, long before 20 s
    assert proc.returncode == 0, proc.stderr
    summary = json.loads((out / "summary.json").read_text())
    assert summary["complete"] is True and summary["ended_by"] == "stair" and summary["stopped_at"] == 9.0
    _, columns = read_typed_timeseries(out / "timeseries.csv")
    assert columns["time"][-1] == "9" and columns["stair.counter"][-1] == "10"  # its last sample is kept
    assert len(columns["time"]) == 46


@pytest.mark.parametrize("name, start_values", [("BouncingBall", {"h": 2.0}), ("VanDerPol", {"x0": 1.5})])
def test_start_values_of_states_match_fmpy(name, start_values, tmp_path):
    stop, step = EXPERIMENTS[name]
    proc, out = run_dtcosim(tmp_path, name, stop, step, start_values)
    assert proc.returncode == 0, proc.stderr
    tags, columns = read_typed_timeseries(out / "timeseries.csv")
    state = next(iter(start_values))
    assert float(columns[f"{name.lower()}.{state}"][0]) == start_values[state]
    assert_equal_to_fmpy(columns, tags, name.lower(), fmpy_outputs(name, stop, step, start_values))

"""``bearing_life.csv`` from a run's bearing-force spectrum: the ISO 281 hand value at constant load and speed.

No packaged gearbox declares bearing forces yet (the lateral-torsional model does, issue 33): the run
data here are built by the same functions a worker uses (:func:`components.analysis.load_spectrum.level_histogram`
of a force and the bearing's speed), the set and its bins by the load-case file reader.
"""

from __future__ import annotations

import csv
import io
import math

import numpy as np
import pytest

from components.analysis.bearing_life import LifeModification
from components.analysis.lifetime import run_weights
from components.analysis.load_spectrum import level_histogram
from orchestrator.inputs.load_case_file import load_cases_from_dict
from orchestrator.study.lifetime_results import LifetimeResults, RunData
from orchestrator.study.load_cases import Case, PreparedLoadCases
from orchestrator.study.rating_plan import BearingPlan, RatingPlan
from orchestrator.study.ratings import bearing_rows, compute_ratings, report_lines
from tests.orchestrator.inputs.test_load_cases import _doc

#: a load at the middle of its level cell (2^7 N wide for this load): the spectrum holds it exactly
LOAD_N = 1536.5 * 128.0
RPM = 120.0
C_N = 1.0e6


def _results(plans, loads_n):
    lcs = load_cases_from_dict(_doc(bins={"edges": [10.0, 12.0]}, runs={"length": 10.0, "transient": 0.0, "seeds": 1}))
    t = np.linspace(0.0, 10.0, 5001)
    levels = {p.column: level_histogram(t, np.full(t.size, load), {p.name: np.full(t.size, RPM * math.pi / 30.0)})
              for p, load in zip(plans, loads_n)}
    plan = RatingPlan(bearings=tuple(plans))
    plc = PreparedLoadCases(lcs, lcs.bins, (Case(0, 0, 1, {}),), (), None, None, {}, ratings=plan)
    weights = run_weights([0], [10.0], [b.probability for b in lcs.bins], lcs.life)
    return LifetimeResults(plc, [RunData(0, 10.0, {}, levels)], weights, {}, [])


def _plan(name, kind="roller", rating=C_N, modification=LifeModification(), speed="gearbox.b.bearing_speed"):
    return BearingPlan(f"gearbox.{name}.bearing_force", name, {"bearing": name, "body": "stage1.planet[1]"}, speed,
                       kind, rating, modification)


def test_constant_load_at_constant_speed_gives_the_iso_281_hours():
    res = _results([_plan("b1"), _plan("b2", "ball", modification=LifeModification(99.0, a_iso=2.0))],
                   [LOAD_N, LOAD_N])
    ratings = compute_ratings(res)
    buf = io.StringIO()
    csv.writer(buf).writerows(bearing_rows(ratings))
    rows = list(csv.DictReader(io.StringIO(buf.getvalue())))
    roller, ball = rows
    # L10h = (C / P)^p 1e6 / (60 n): roller (1e6 / 196672)^(10/3) 1e6 / 7200 = 3.005e6 h
    expected = (C_N / LOAD_N) ** (10.0 / 3.0) * 1e6 / (60.0 * RPM)
    assert float(roller["P_eq [N]"]) == pytest.approx(LOAD_N, rel=1e-12)
    assert float(roller["L10 [h]"]) == pytest.approx(expected, rel=1e-9)
    assert float(ball["L10 [h]"]) == pytest.approx((C_N / LOAD_N) ** 3 * 1e6 / (60.0 * RPM), rel=1e-9)
    assert float(ball["Lnm [h]"]) == pytest.approx(0.25 * 2.0 * float(ball["L10 [h]"]), rel=1e-12)
    # the design life: 20 years x 0.97 x the bin's probability, in operating hours; the revolutions of that life
    hours = ratings.design_hours
    assert float(roller["operating_hours [h]"]) == pytest.approx(hours)
    assert float(roller["revolutions [-]"]) == pytest.approx(hours * 60.0 * RPM, rel=1e-9)
    assert roller["met"] == str(expected >= hours)
    lines = report_lines(res, ratings)
    assert any(line.startswith("bearing lives (ISO 281; bearing_life.csv)") for line in lines)
    assert any("b1" in line and "L10 " in line for line in lines)


def test_a_bearing_without_its_rating_is_listed_with_the_reason():
    res = _results([_plan("b1", rating=None), _plan("b2", kind=None), _plan("b3", speed=None)], [LOAD_N] * 3)
    ratings = compute_ratings(res)
    notes = [r[-1] for r in bearing_rows(ratings)[1:]]
    assert notes == ["no dynamic load rating C given for b1 in the drivetrain",
                     "no bearing type (ball or roller) given for b2 in the drivetrain",
                     "no bearing_speed output declared for bearing b3"]

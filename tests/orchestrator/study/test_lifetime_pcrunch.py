"""The field's library on a real dtcosim run: pCrunch's DELs, lifetime DELs and damage within 0.5 % of dtcosim's.

The paper run (60 s, Sec. 4.2) is split into two equal runs of [5, 60] s that
stand for two wind-speed bins; its declared load channels are those a load-case
set analyses. dtcosim counts with the ``repeat`` residue, pCrunch's convention
(``fatpack.find_rainflow_ranges``); pCrunch's 256 load classes and its 100 range
bins (midpoints) are the remaining differences (``docs/lifetime.md``).
"""

from __future__ import annotations

import numpy as np
import pytest

from components.analysis.fatigue import damage_equivalent_load, rainflow
from components.analysis.lifetime import DesignLife, lifetime_damage, lifetime_del, run_weights
from components.analysis.sn_curve import SNCurve
from components.analysis.wind_distribution import WindDistribution, bin_probabilities

pytestmark = pytest.mark.slow

EXPONENTS = (3.0, 5.0, 8.0, 10.0)
LIFE = DesignLife(20.0, 0.97)


@pytest.fixture(scope="module")
def split_run(paper_run, fmu_dir, tmp_path_factory):
    """(channels, [(t, {channel: y}), (t, {channel: y})]) of the paper run's two halves after 5 s."""
    from orchestrator.inputs.load_case_file import load_cases_from_dict
    from orchestrator.study.load_cases import prepare_load_cases

    out, _, _ = paper_run
    lcs = load_cases_from_dict({"base": {"scenario": "paper-60s"}, "runs": {"length": 1.0},
                                "wind": {"distribution": "rayleigh", "iec_class": "II"},
                                "bins": {"edges": [8.0, 10.0, 12.0]}, "operating_law": {"rated_wind_speed": 11.0}})
    channels = [c.column for c in prepare_load_cases(lcs, fmu_dir=fmu_dir).channels]
    with open(out / "timeseries.csv") as fh:
        header = [h.rsplit(" [", 1)[0] for h in fh.readline().strip().split(",")]
    data = np.loadtxt(out / "timeseries.csv", delimiter=",", skiprows=1)
    t = data[:, 0]
    halves = []
    for lo, hi in ((5.0, 32.5), (32.5, 60.0)):
        m = (t >= lo - 1e-9) & (t <= hi + 1e-9)
        halves.append((t[m], {c: data[m, header.index(c)] for c in channels}))
    return channels, halves


def _crunch(halves, channels, params, probs):
    from pCrunch import AeroelasticOutput, Crunch

    outputs = [AeroelasticOutput({"Time": t, **series}, name=f"half{i}") for i, (t, series) in enumerate(halves)]
    crunch = Crunch(outputs, probability=np.asarray(probs, dtype=float), fatigue_channels=params)
    crunch.process_outputs()
    return crunch


@pytest.mark.parametrize("m", EXPONENTS)
def test_short_term_and_lifetime_dels_agree_with_pcrunch_within_half_a_percent(split_run, m):
    from pCrunch import FatigueParams

    channels, halves = split_run
    probs = bin_probabilities(WindDistribution.iec("II"), np.array([8.0, 10.0, 12.0]))
    crunch = _crunch(halves, channels, {c: FatigueParams(slope=m, S_intercept=1.0) for c in channels}, probs)
    # pCrunch: 365-day years, probabilities renormalised over the runs
    _, damage = crunch.compute_total_fatigue(lifetime=LIFE.years * 365.25 / 365.0, availability=LIFE.availability)
    lengths = [t[-1] - t[0] for t, _ in halves]
    weights = run_weights([0, 1], lengths, probs, LIFE)
    for c in channels:
        cycles = [rainflow(s[c], 1e-3 * float(np.ptp(s[c])), "repeat") for _, s in halves]
        ours = [damage_equivalent_load(cy, m, T) for cy, T in zip(cycles, lengths)]
        assert crunch.dels[c].to_numpy() == pytest.approx(ours, rel=5e-3), c
        pcrunch_life = (float(damage[c]["Weighted"]) * probs.sum() / 1e7) ** (1 / m)
        assert lifetime_del(cycles, weights, m, 1e7) == pytest.approx(pcrunch_life, rel=5e-3), c


def test_lifetime_miner_damage_with_goodman_agrees_with_pcrunch_within_half_a_percent(split_run):
    from pCrunch import FatigueParams

    channels, halves = split_run
    probs = bin_probabilities(WindDistribution.iec("II"), np.array([8.0, 10.0, 12.0]))
    lengths = [t[-1] - t[0] for t, _ in halves]
    weights = run_weights([0, 1], lengths, probs, LIFE)
    params, curves = {}, {}
    for c in channels:
        mean = float(np.mean(halves[0][1][c]))
        curves[c] = SNCurve(5.0, 0.05 * mean, 2e6, ultimate_load=4.0 * mean, goodman=True)
        params[c] = FatigueParams(slope=5.0, Sc=0.05 * mean, Nc=2e6, ultimate_stress=4.0 * mean, goodman=True)
    crunch = _crunch(halves, channels, params, probs)
    _, damage = crunch.compute_total_fatigue(lifetime=LIFE.years * 365.25 / 365.0, availability=LIFE.availability)
    for c in channels:
        cycles = [rainflow(s[c], 1e-3 * float(np.ptp(s[c])), "repeat") for _, s in halves]
        ours = lifetime_damage(cycles, weights, [0, 1], 2, curves[c]).total
        assert ours == pytest.approx(float(damage[c]["Weighted"]) * probs.sum(), rel=5e-3), c

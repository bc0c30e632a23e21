"""A load-case set's runs on disk and its lifetime results: run files, damage, DELs, rankings.

Run files
---------
A worker returns each run's cycles and level histograms
(:mod:`orchestrator.study.run_data`); the client writes them, before the run's
journal line, to ``runs/<index>-<key>.npz`` (compressed NumPy arrays, written
through a temporary file and rename, so a file is complete or absent) and the
journal line names the file. The journal line is the commit mark: a run is done
when its line is in the journal (status ``ok``) and its file exists; a run whose
file went missing is marked for a re-run (:func:`mark_missing_run_files`). The
lifetime figures are computed from the run files each time the outputs are
written, so the wind distribution, the life, the S-N curves and the equivalent
cycle count can be changed without running anything again
(``dtcosim loads SET --report``).

Why files and not the journal: a run's exact cycles and ~2000 levels per
channel are tens of kB per channel in compressed binary, several times that as
JSON text, and the journal is re-read on every start; why exact cycles and not
a rainflow matrix: DELs and damage need the ranges themselves to agree with
hand-computed values to 1e-9 (a binned matrix shifts every range to its bin's
middle, which is what pCrunch does, see ``docs/lifetime.md``).

The tables, the report and the plots written from these results are
:mod:`orchestrator.study.lifetime_outputs` (and :mod:`orchestrator.study.lifetime_plots`).
"""

from __future__ import annotations

import json
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from components.analysis.fatigue import RainflowCycles, damage_equivalent_load
from components.analysis.lifetime import LifetimeDamage, lifetime_damage, lifetime_del, run_weights
from components.analysis.load_spectrum import LevelHistogram, merge_histograms
from components.analysis.sn_curve import SNCurve

from ..atomic_files import atomic_path
from .engine import OK
from .journal import JOURNAL_FILE, Journal, latest_by_key, read_journal
from .load_cases import PreparedLoadCases
from .run_data import Channel

RUNS_DIR = "runs"
HOURS = 3600.0
ERROR = "error"


# ------------------------------------------------------------------ run files
def run_file_name(index: int, key: str) -> str:
    """``runs/0007-<key>.npz`` (relative to the output directory)."""
    return f"{RUNS_DIR}/{index:04d}-{key}.npz"


def store_run_data(plc: PreparedLoadCases, out_dir: str | Path) -> Callable[[int, dict], dict]:
    """The sweep's ``on_result`` hook: write a run's data to its file, return the journal fields."""
    out = Path(out_dir)
    columns = [c.column for c in plc.channels]

    def on_result(i: int, result: dict[str, Any]) -> dict[str, Any]:
        data = result.get("data")
        if data is None:
            return {}
        arrays: dict[str, np.ndarray] = {}
        loads = {}
        for j, column in enumerate(columns):
            ch = data["channels"][column]
            arrays[f"{j}.ranges"] = np.asarray(ch["ranges"], dtype=float)
            arrays[f"{j}.means"] = np.asarray(ch["means"], dtype=float)
            arrays[f"{j}.counts"] = np.asarray(ch["counts"], dtype=float)
            for k, v in ch["levels"].items():
                arrays[f"{j}.levels.{k}"] = np.asarray(v)
            loads[column] = {k: ch[k] for k in ("mean", "std", "min", "max")}
        meta = {"key": plc.keys[i], "index": i, "analysed_time_s": data["analysed_time_s"], "window_s": data["window_s"],
                "columns": columns}
        arrays["meta"] = np.array(json.dumps(meta))
        name = run_file_name(i, plc.keys[i])
        path = out / name
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_path(path) as tmp:  # whole or not there, no temporary file left (a full disk left a .npz.part)
            with open(tmp, "wb") as fh:
                np.savez_compressed(fh, **arrays)
        return {"run_file": name, "analysed_time_s": data["analysed_time_s"], "loads": loads}

    return on_result


@dataclass(frozen=True)
class RunData:
    """One finished run read back from its file."""

    case_index: int
    analysed_time_s: float
    cycles: Mapping[str, RainflowCycles]
    levels: Mapping[str, LevelHistogram]


def read_run_file(path: str | Path) -> RunData:
    """A run file (see the module docstring)."""
    with np.load(path, allow_pickle=False) as z:
        meta = json.loads(str(z["meta"]))
        cycles, levels = {}, {}
        for j, column in enumerate(meta["columns"]):
            cycles[column] = RainflowCycles(z[f"{j}.ranges"], z[f"{j}.means"], z[f"{j}.counts"])
            prefix = f"{j}.levels."
            levels[column] = LevelHistogram.from_arrays({k[len(prefix):]: z[k] for k in z.files if k.startswith(prefix)})
    return RunData(int(meta["index"]), float(meta["analysed_time_s"]), cycles, levels)


def finished_runs(plc: PreparedLoadCases, out_dir: str | Path) -> dict[int, dict]:
    """Journal record of every run that is done (status ok and its file present), by case index."""
    out = Path(out_dir)
    latest = latest_by_key(read_journal(out / JOURNAL_FILE))
    done = {}
    for c, key in zip(plc.cases, plc.keys):
        rec = latest.get(key)
        if rec and rec.get("status") == OK and rec.get("run_file") and (out / rec["run_file"]).is_file():
            done[c.index] = rec
    return done


def mark_missing_run_files(plc: PreparedLoadCases, out_dir: str | Path) -> int:
    """Journal an ``error`` record for every ok run whose file is missing (the next sweep runs it again).

    Returns the number of such runs.
    """
    out = Path(out_dir)
    path = out / JOURNAL_FILE
    latest = latest_by_key(read_journal(path))
    missing = []
    for c, key in zip(plc.cases, plc.keys):
        rec = latest.get(key)
        if rec and rec.get("status") == OK and not (rec.get("run_file") and (out / rec["run_file"]).is_file()):
            missing.append((c, key))
    if missing:
        with Journal(path) as journal:
            for c, key in missing:
                journal.append({"key": key, "index": c.index, "study": plc.prepared.study.name, "status": ERROR,
                                "parameters": {}, "measures": {}, "error": "run file missing: run again",
                                "error_type": "MissingRunFile"})
    return len(missing)


# ------------------------------------------------------------------ lifetime
@dataclass
class ChannelLifetime:
    """Lifetime results of one channel.

    Attributes
    ----------
    channel : Channel
    short_term_del : ndarray, shape (R, M)
        DEL of each finished run per Woehler exponent [unit] (N_ref = f_ref x T_r).
    lifetime_del : dict of float -> float
        DEL_life,m at N_eq [unit].
    curve : SNCurve or None
    damage : LifetimeDamage or None
        With an S-N curve.
    ranking_share : ndarray, shape (B,)
        Share of the lifetime damage per bin (without an S-N curve: of ``sum w n S^m`` for the
        largest Woehler exponent).
    ldd : LevelHistogram
        Lifetime time [s] (and revolutions per gear) at each level.
    ldd_by_bin : dict of int -> LevelHistogram
        Sum of each bin's finished runs (simulated seconds), on the lifetime's lattice.
    """

    channel: Channel
    short_term_del: np.ndarray
    lifetime_del: dict[float, float]
    curve: SNCurve | None
    damage: LifetimeDamage | None
    ranking_share: np.ndarray
    ldd: LevelHistogram
    ldd_by_bin: dict[int, LevelHistogram] = field(default_factory=dict)


@dataclass
class LifetimeResults:
    """Lifetime results of a load-case set from its finished runs.

    Attributes
    ----------
    plc : PreparedLoadCases
    runs : list of RunData
        Finished runs, in case order.
    weights : ndarray, shape (R,)
        w_r of each (:func:`components.analysis.lifetime.run_weights`).
    channels : dict of str -> ChannelLifetime
    missing : list of int
        Cases without a finished run (not in the figures).
    """

    plc: PreparedLoadCases
    runs: list[RunData]
    weights: np.ndarray
    channels: dict[str, ChannelLifetime]
    missing: list[int]

    @property
    def complete(self) -> bool:
        """Every run finished."""
        return not self.missing


def curve_for(channel: Channel, plc: PreparedLoadCases) -> SNCurve | None:
    """The S-N curve of a channel: a rule naming its column, else ``<kind>:<stage>``, else its kind."""
    rules = plc.load_cases.curves
    stage = channel.info.get("stage")
    for wanted in (channel.column, f"{channel.kind}:{stage}" if stage else None, channel.kind):
        for rule in rules:
            if wanted is not None and wanted in rule.applies_to:
                return rule.curve
    return None


def check_curves(plc: PreparedLoadCases) -> None:
    """Every ``applies_to`` entry names a channel, ``kind:stage`` or kind of the set (LoadCaseError otherwise)."""
    from ..inputs.load_cases import LoadCaseError

    known = set()
    for ch in plc.channels:
        known |= {ch.column, ch.kind}
        if ch.info.get("stage"):
            known.add(f"{ch.kind}:{ch.info['stage']}")
    for i, rule in enumerate(plc.load_cases.curves):
        for j, entry in enumerate(rule.applies_to):
            if entry not in known:
                from ..errors import suggestion

                raise LoadCaseError(f"sn_curves[{i}].applies_to[{j}]", entry, "a channel, signal kind or "
                                    f"<kind>:<stage> of the set{suggestion(entry, sorted(known))}",
                                    plc.load_cases.source)


def compute_lifetime(plc: PreparedLoadCases, out_dir: str | Path) -> LifetimeResults:
    """Lifetime DELs, damage, LDD and LRD of every channel from the finished runs' files."""
    out = Path(out_dir)
    lcs = plc.load_cases
    done = finished_runs(plc, out)
    finished = [c for c in plc.cases if c.index in done]
    runs = [replace(read_run_file(out / done[c.index]["run_file"]), case_index=c.index) for c in finished]
    missing = [c.index for c in plc.cases if c.index not in done]
    run_bins = [c.bin for c in finished]
    lengths = [r.analysed_time_s for r in runs]
    probs = [b.probability for b in plc.bins]
    weights = run_weights(run_bins, lengths, probs, lcs.life) if runs else np.zeros(0)
    f = lcs.fatigue
    results = {}
    for ch in plc.channels:
        cycles = [r.cycles[ch.column] for r in runs]
        short = np.array([[damage_equivalent_load(c, m, f.reference_frequency_hz * t) for m in f.wohler_exponents]
                          for c, t in zip(cycles, lengths)]).reshape(len(runs), len(f.wohler_exponents))
        life_del = {m: lifetime_del(cycles, weights, m, f.equivalent_cycles) for m in f.wohler_exponents} if runs else {}
        curve = curve_for(ch, plc)
        dmg = lifetime_damage(cycles, weights, run_bins, len(plc.bins), curve) if (curve and runs) else None
        if dmg is not None:
            share = dmg.share_by_bin
        else:
            unit_curve = SNCurve(max(f.wohler_exponents), 1.0)
            share = (lifetime_damage(cycles, weights, run_bins, len(plc.bins), unit_curve).share_by_bin
                     if runs else np.zeros(len(plc.bins)))
        if runs:
            hists = [r.levels[ch.column] for r in runs]
            ldd = merge_histograms(hists, weights).with_at_most(f.levels)
            by_bin = {}
            for b in sorted(set(run_bins)):
                mine = [h for h, rb in zip(hists, run_bins) if rb == b]
                by_bin[b] = merge_histograms(mine).coarsened(ldd.exponent)
        else:
            ldd, by_bin = LevelHistogram(0, np.zeros(0, dtype=np.int64), np.zeros(0)), {}
        results[ch.column] = ChannelLifetime(ch, short, life_del, curve, dmg, share, ldd, by_bin)
    return LifetimeResults(plc, runs, weights, results, missing)


# -------------------------------------------------------------------- rankings
def ranking_targets(res: LifetimeResults) -> list[tuple[str, str]]:
    """(label, column) of the high-speed shaft and of each stage's mesh (its most damaged planet)."""
    plc = res.plc
    out = []
    if plc.high_speed_shaft:
        out.append(("high-speed shaft", plc.high_speed_shaft))
    for label, columns in plc.meshes.items():
        def badness(col: str) -> float:
            c = res.channels[col]
            if c.damage is not None:
                return c.damage.total
            return max(c.lifetime_del.values(), default=0.0)

        out.append((f"{label} mesh", max(columns, key=badness)))
    return out


def ranked_bins(res: LifetimeResults, column: str) -> list[tuple[int, float]]:
    """(bin, share of the lifetime damage) from the largest share down."""
    share = res.channels[column].ranking_share
    return sorted(enumerate(map(float, share)), key=lambda x: -x[1])

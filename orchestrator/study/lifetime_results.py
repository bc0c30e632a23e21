"""A load-case set's runs on disk and its lifetime results: run files, tables, report.

Run files
---------
A worker returns each run's cycles and level histograms
(:mod:`orchestrator.study.run_data`); the client writes them, before the run's
journal line, to ``runs/<index>-<key>.npz`` (compressed NumPy arrays, written
to a temporary name and renamed, so a file is complete or absent) and the
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

Outputs (:func:`write_lifetime_outputs`)
---------------------------------------
``bins.csv``, ``runs.csv``, ``lifetime_del.csv``, ``damage_by_bin.csv``,
``ldd.csv``, ``lrd.csv``, ``lifetime.json``, ``lifetime_report.txt`` and the
plots ``damage_by_bin.png``, ``ldd.png``, ``lrd.png`` (see ``docs/lifetime.md``).
"""

from __future__ import annotations

import csv
import io
import json
import os
from dataclasses import dataclass, field, replace
from pathlib import Path
from typing import Any, Callable, Mapping

import numpy as np

from components import units
from components.analysis.fatigue import RainflowCycles, damage_equivalent_load
from components.analysis.lifetime import LifetimeDamage, lifetime_damage, lifetime_del, run_weights
from components.analysis.load_spectrum import LevelHistogram, merge_histograms
from components.analysis.sn_curve import SNCurve

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
        tmp = path.with_name(path.name + ".part")
        with open(tmp, "wb") as fh:
            np.savez_compressed(fh, **arrays)
            fh.flush()
            os.fsync(fh.fileno())
        os.replace(tmp, path)
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


# ---------------------------------------------------------------------- files
def _write_atomic(path: Path, text: str) -> Path:
    tmp = path.with_name(path.name + ".tmp")
    tmp.write_text(text, encoding="utf-8")
    os.replace(tmp, path)
    return path


def _csv(rows: list[list[Any]]) -> str:
    buf = io.StringIO()
    w = csv.writer(buf, lineterminator="\n")
    for row in rows:
        w.writerow(["" if v is None else (repr(float(v)) if isinstance(v, (float, np.floating)) else v) for v in row])
    return buf.getvalue()


def _bins_rows(res: LifetimeResults) -> list[list[Any]]:
    plc = res.plc
    life = plc.load_cases.life
    rows = [["bin", "wind_speed_low [m/s]", "wind_speed_high [m/s]", "wind_speed [m/s]", "probability [-]",
             "lifetime_operation [h]", "region", "rotor_speed [rpm]", "generator_torque [N.m]", "sigma [rpm]",
             "runs_finished", "runs"]]
    finished = [plc.cases[r.case_index].bin for r in res.runs]
    for b in plc.bins:
        p = b.point
        rpm = lambda x: None if x is None else units.rad_per_s_to_rpm(x)  # noqa: E731
        rows.append([b.index, b.low_m_s, b.high_m_s, b.centre_m_s, b.probability,
                     life.availability * b.probability * life.seconds / HOURS, p.region, rpm(p.rotor_speed_rad_s),
                     p.generator_torque_nm, rpm(p.sigma_rad_s), finished.count(b.index),
                     sum(1 for c in plc.cases if c.bin == b.index)])
    return rows


def _runs_rows(res: LifetimeResults, out_dir: Path) -> list[list[Any]]:
    plc = res.plc
    exps = plc.load_cases.fatigue.wohler_exponents
    rows = [["run", "bin", "wind_speed_low [m/s]", "wind_speed_high [m/s]", "seed", "status", "channel", "unit",
             "analysed_time [s]", "mean", "std", "min", "max", "cycles [-]", *(f"DEL m={m:g}" for m in exps),
             "damage [-]", "lifetime_weight [-]", "key"]]
    latest = latest_by_key(read_journal(out_dir / JOURNAL_FILE))
    by_case = {r.case_index: (k, r) for k, r in enumerate(res.runs)}
    for c, key in zip(plc.cases, plc.keys):
        b = plc.bins[c.bin]
        head = [c.index, c.bin, b.low_m_s, b.high_m_s, c.seed]
        if c.index not in by_case:
            rec = latest.get(key)
            status = rec["status"] if rec else "pending"
            rows.append(head + [status] + [None] * (len(rows[0]) - 7) + [key])
            continue
        k, run = by_case[c.index]
        loads = latest[key].get("loads", {})
        for ch in plc.channels:
            cl = res.channels[ch.column]
            stats = loads.get(ch.column, {})
            cyc = run.cycles[ch.column]
            rows.append(head + [OK, ch.column, ch.unit, run.analysed_time_s, stats.get("mean"), stats.get("std"),
                                stats.get("min"), stats.get("max"), cyc.total_cycles, *cl.short_term_del[k],
                                None if cl.damage is None else cl.damage.per_run[k], res.weights[k], key])
    return rows


def _del_rows(res: LifetimeResults) -> list[list[Any]]:
    n_eq = res.plc.load_cases.fatigue.equivalent_cycles
    rows = [["channel", "kind", "unit", "wohler_exponent [-]", "equivalent_cycles [-]", "lifetime_del"]]
    for col, cl in res.channels.items():
        for m, v in cl.lifetime_del.items():
            rows.append([col, cl.channel.kind, cl.channel.unit, m, n_eq, v])
    return rows


def _damage_rows(res: LifetimeResults) -> list[list[Any]]:
    rows = [["channel", "kind", "sn_curve", "bin", "wind_speed_low [m/s]", "wind_speed_high [m/s]", "damage [-]",
             "share [-]"]]
    for col, cl in res.channels.items():
        if cl.damage is None:
            continue
        rows.append([col, cl.channel.kind, cl.curve.describe(), "lifetime", None, None, cl.damage.total, 1.0])
        for b in res.plc.bins:
            rows.append([col, cl.channel.kind, cl.curve.describe(), b.index, b.low_m_s, b.high_m_s,
                         cl.damage.by_bin[b.index], cl.damage.share_by_bin[b.index]])
    return rows


def _ldd_rows(res: LifetimeResults) -> tuple[list[list[Any]], list[list[Any]]]:
    ldd = [["channel", "unit", "scope", "level_low", "level_high", "time [s]", "time [h]"]]
    lrd = [["channel", "gear", "unit", "scope", "level_low", "level_high", "revolutions [-]"]]
    for col, cl in res.channels.items():
        scopes = [("lifetime", cl.ldd)] + [(f"bin {b}", h) for b, h in cl.ldd_by_bin.items()]
        for scope, h in scopes:
            for lo, hi, t in zip(h.lower, h.upper, h.time_s):
                ldd.append([col, cl.channel.unit, scope, lo, hi, t, t / HOURS])
            for gear, revs in h.revolutions.items():
                for lo, hi, r in zip(h.lower, h.upper, revs):
                    lrd.append([col, gear, cl.channel.unit, scope, lo, hi, r])
    return ldd, lrd


def report_text(res: LifetimeResults) -> str:
    """The lifetime report: the set, completeness, lifetime DELs and the bins ranked by damage share."""
    plc = res.plc
    lcs = plc.load_cases
    f = lcs.fatigue
    lines = [f"load-case set {lcs.name}: {len(plc.bins)} wind-speed bins x {len(lcs.seeds)} seeds = {len(plc.cases)} runs "
             f"of {lcs.length_s:g} s (after a {lcs.transient_s:g} s transient)",
             f"wind: {lcs.wind.describe()}; bins {lcs.edges_m_s[0]:g}-{lcs.edges_m_s[-1]:g} m/s hold "
             f"{100 * lcs.operating_share:.2f} % of the time",
             f"life: {lcs.life.years:g} years, availability {lcs.life.availability:g}; lifetime DELs at "
             f"N_eq = {f.equivalent_cycles:g} cycles"]
    if lcs.law is not None:
        lines.append(f"operating law: {lcs.law.describe()}")
    if res.missing:
        lines.append(f"INCOMPLETE: {len(res.missing)} of {len(plc.cases)} runs not finished (runs "
                     f"{', '.join(map(str, res.missing[:20]))}{' ...' if len(res.missing) > 20 else ''}); the figures "
                     "cover the finished runs only")
    lines.append("")
    lines.append("lifetime DEL [unit] " + "  ".join(f"m={m:g}" for m in f.wohler_exponents))
    for col, cl in res.channels.items():
        values = "  ".join(f"{cl.lifetime_del.get(m, float('nan')):.5g}" for m in f.wohler_exponents)
        dmg = f"  damage {cl.damage.total:.4g}" if cl.damage is not None else ""
        lines.append(f"  {col} [{cl.channel.unit}]  {values}{dmg}")
    lines.append("")
    for label, col in ranking_targets(res):
        cl = res.channels[col]
        what = (f"lifetime damage {cl.damage.total:.4g} ({cl.curve.describe()})" if cl.damage is not None else
                f"no S-N curve: shares of sum n S^m, m = {max(f.wohler_exponents):g}")
        lines.append(f"{label} ({col}): {what}; bins by share of lifetime damage:")
        for rank, (b, share) in enumerate(ranked_bins(res, col), 1):
            lines.append(f"  {rank:2d}. {plc.bins[b].label:<16} {100 * share:7.2f} %  (probability "
                         f"{plc.bins[b].probability:.4f})")
        lines.append("")
    return "\n".join(lines)


def summary(res: LifetimeResults) -> dict[str, Any]:
    """``lifetime.json``."""
    plc = res.plc
    lcs = plc.load_cases
    return {
        "load_case_set": lcs.name, "source": lcs.source, "complete": res.complete, "missing_runs": res.missing,
        "runs": len(plc.cases), "finished_runs": len(res.runs), "wind": lcs.wind.as_dict(),
        "operating_share": lcs.operating_share, "life": {"years": lcs.life.years, "availability": lcs.life.availability,
                                                         "seconds": lcs.life.seconds},
        "equivalent_cycles": lcs.fatigue.equivalent_cycles, "wohler_exponents": list(lcs.fatigue.wohler_exponents),
        "bins": [{"index": b.index, "low_m_s": b.low_m_s, "high_m_s": b.high_m_s, "probability": b.probability,
                  "region": b.point.region} for b in plc.bins],
        "channels": {col: {"kind": cl.channel.kind, "unit": cl.channel.unit,
                           "lifetime_del": {f"m={m:g}": v for m, v in cl.lifetime_del.items()},
                           "sn_curve": None if cl.curve is None else cl.curve.as_dict(),
                           "lifetime_damage": None if cl.damage is None else cl.damage.total,
                           "damage_share_by_bin": [float(x) for x in cl.ranking_share],
                           "gears": [g for g, _ in cl.channel.gears]}
                     for col, cl in res.channels.items()},
        "rankings": {label: {"channel": col, "bins_by_share": [[b, s] for b, s in ranked_bins(res, col)]}
                     for label, col in ranking_targets(res)},
    }


def write_lifetime_outputs(plc: PreparedLoadCases, out_dir: str | Path, plots: bool = True) -> dict[str, Path]:
    """Compute the lifetime results from the run files and write every table, the report and the plots.

    Returns
    -------
    dict of str -> pathlib.Path
        Files by role.
    """
    out = Path(out_dir)
    out.mkdir(parents=True, exist_ok=True)
    res = compute_lifetime(plc, out)
    files = {
        "bins": _write_atomic(out / "bins.csv", _csv(_bins_rows(res))),
        "runs": _write_atomic(out / "runs.csv", _csv(_runs_rows(res, out))),
        "lifetime_del": _write_atomic(out / "lifetime_del.csv", _csv(_del_rows(res))),
        "damage_by_bin": _write_atomic(out / "damage_by_bin.csv", _csv(_damage_rows(res))),
    }
    ldd, lrd = _ldd_rows(res)
    files["ldd"] = _write_atomic(out / "ldd.csv", _csv(ldd))
    files["lrd"] = _write_atomic(out / "lrd.csv", _csv(lrd))
    files["report"] = _write_atomic(out / "lifetime_report.txt", report_text(res))
    if plots and res.runs:
        from .lifetime_plots import plot_damage_by_bin, plot_ldd, plot_lrd

        files["plot:damage_by_bin"] = plot_damage_by_bin(res, out / "damage_by_bin.png")
        files["plot:ldd"] = plot_ldd(res, out / "ldd.png")
        files["plot:lrd"] = plot_lrd(res, out / "lrd.png")
    files["summary"] = out / "lifetime.json"
    doc = summary(res)
    doc["files"] = {k: p.name for k, p in files.items()}
    _write_atomic(files["summary"], json.dumps(doc, indent=2) + "\n")
    return files

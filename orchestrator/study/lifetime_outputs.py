"""The lifetime outputs of a load-case set: tables, report, summary and plots, written from its run files.

:func:`write_lifetime_outputs` computes the results (:func:`orchestrator.study.lifetime_results.compute_lifetime`)
and writes ``bins.csv``, ``runs.csv``, ``lifetime_del.csv``, ``damage_by_bin.csv``,
``ldd.csv``, ``lrd.csv``, ``gear_rating.csv`` and ``bearing_life.csv`` (:mod:`orchestrator.study.ratings`,
where there is something to rate), ``lifetime.json``, ``lifetime_report.txt`` and the
plots ``damage_by_bin.png``, ``ldd.png``, ``lrd.png`` (:mod:`orchestrator.study.lifetime_plots`;
see ``docs/lifetime.md``).
"""

from __future__ import annotations

import csv
import io
import json
from pathlib import Path
from typing import Any

import numpy as np

from components import units
from components.analysis.lifetime import ONE_EVENT_SHARE

from ..atomic_files import write_text_atomic
from .engine import OK
from .journal import JOURNAL_FILE, latest_by_key, read_journal
from .lifetime_plots import plot_damage_by_bin, plot_ldd, plot_lrd
from .lifetime_results import HOURS, LifetimeResults, compute_lifetime, ranked_bins, ranking_targets
from .load_cases import PreparedLoadCases
from .ratings import BEARING_FILE, GEAR_FILE, bearing_rows, compute_ratings, gear_rows, report_lines
from .ratings import summary as ratings_summary


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
             *([f"settling time of the drivetrain: {plc.settling['description']}"] if plc.settling else []),
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
        one = one_event_note(res, col)
        if one:
            lines.append(f"  NOTE: {one}")
        lines.append("")
    return "\n".join(lines)


def _largest_cycle(res: LifetimeResults, col: str) -> dict[str, Any] | None:
    cl = res.channels[col]
    big = None if cl.damage is None else cl.damage.largest_cycle
    if big is None:
        return None
    case = next(c for c in res.plc.cases if c.index == res.runs[big.run].case_index)
    return {"share": big.share, "range": big.range, "count": big.count, "run": case.index,
            "bin": res.plc.bins[case.bin].label}


def one_event_note(res: LifetimeResults, col: str) -> str:
    """A sentence when one counted cycle carries more than ONE_EVENT_SHARE of a channel's lifetime damage, else ''."""
    big = _largest_cycle(res, col)
    if big is None or big["share"] <= ONE_EVENT_SHARE:
        return ""
    kind = "a half cycle of the residue (typically a record's slow drift)" if big["count"] < 1.0 \
        else "one full cycle"
    return (f"{100 * big['share']:.0f} % of this lifetime damage comes from one cycle, {kind}, range "
            f"{big['range']:.5g} {res.channels[col].channel.unit} in run {big['run']} (bin {big['bin']}): the "
            "figure rests on one event and moves with any window that cuts it; analyse longer or more records "
            "(IEC 61400-1: six 10-minute seeds per bin) before using it")


def summary(res: LifetimeResults) -> dict[str, Any]:
    """``lifetime.json``."""
    plc = res.plc
    lcs = plc.load_cases
    return {
        "load_case_set": lcs.name, "source": lcs.source, "complete": res.complete, "missing_runs": res.missing,
        "transient_s": lcs.transient_s, "length_s": lcs.length_s, "settling": plc.settling,
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
                           "largest_cycle": _largest_cycle(res, col),
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
        "bins": write_text_atomic(out / "bins.csv", _csv(_bins_rows(res))),
        "runs": write_text_atomic(out / "runs.csv", _csv(_runs_rows(res, out))),
        "lifetime_del": write_text_atomic(out / "lifetime_del.csv", _csv(_del_rows(res))),
        "damage_by_bin": write_text_atomic(out / "damage_by_bin.csv", _csv(_damage_rows(res))),
    }
    ldd, lrd = _ldd_rows(res)
    files["ldd"] = write_text_atomic(out / "ldd.csv", _csv(ldd))
    files["lrd"] = write_text_atomic(out / "lrd.csv", _csv(lrd))
    ratings = compute_ratings(res)  # ISO 6336 gear ratings and ISO 281 bearing lives (orchestrator.study.ratings)
    if res.plc.ratings.meshes:
        files["gear_rating"] = write_text_atomic(out / GEAR_FILE, _csv(gear_rows(res, ratings)))
    if res.plc.ratings.bearings:
        files["bearing_life"] = write_text_atomic(out / BEARING_FILE, _csv(bearing_rows(ratings)))
    report = report_text(res) + "\n".join(report_lines(res, ratings)) + "\n"
    files["report"] = write_text_atomic(out / "lifetime_report.txt", report)
    if plots and res.runs:
        files["plot:damage_by_bin"] = plot_damage_by_bin(res, out / "damage_by_bin.png")
        files["plot:ldd"] = plot_ldd(res, out / "ldd.png")
        files["plot:lrd"] = plot_lrd(res, out / "lrd.png")
    files["summary"] = out / "lifetime.json"
    doc = summary(res)
    doc["ratings"] = ratings_summary(ratings)
    doc["files"] = {k: p.name for k, p in files.items()}
    write_text_atomic(files["summary"], json.dumps(doc, indent=2) + "\n")
    return files

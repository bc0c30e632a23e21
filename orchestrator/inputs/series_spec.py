"""The recorded time series a TimeSeriesSource FMU is built from: the scenario's ``[components.<name>.series]``.

::

    [components.loads]
    fmu = "TimeSeriesSource.fmu"
    [components.loads.series]
    record = "openfast-data/DLC1.1_0_NREL5MW_OC3_spar_0.outb"   # see "Where a record is found"
    time_offset = 0.0            # s: record time = simulation time + time_offset
    out_of_record = "error"      # or "hold" (first/last sample)
    check_speed_ratio = true     # a record with rotor and generator speeds must have the drivetrain's ratio (2 %)
    [[components.loads.series.channels]]
    channel = "RotSpeed"         # as in the record
    output = "rotor_speed"       # FMU output (default: the channel name)
    interpolation = "pchip"      # C1 (default) or "linear" (C0)
    angle = "rotor_angle"        # optional: also the integral of this channel (a speed), from angle_initial
    quantity = "rotor_speed"     # optional: what it records (default from the OpenFAST channel name)
    lowpass_hz = 1.0             # optional: a zero-phase low-pass of the channel at this cut-off [Hz]

Each channel's resolution (the quantisation step of its numbers: 3 significant digits, 2 decimals,
the 16-bit steps of a compressed ``.outb``) and sampling are checked when the record is read
(:mod:`components.analysis.record_resolution`). A channel that prescribes a motion (a rotor or
generator speed or angle) whose steps are larger than half of its own sample-to-sample motion
(:data:`STEP_RATIO_WARNING`) plays a staircase that excites the drivetrain's modes: a warning
names the channel, its step and the remedy (``lowpass_hz``, or the torque-driven Rotor). The
low-pass runs forward and backward (no delay; :func:`~components.analysis.record_resolution.lowpass_zero_phase`)
on the SI samples before the FMU is built; an ``angle`` is the integral of the filtered speed.
The resolution, the step ratio and the cut-off of each channel are in the FMU's record model and in
``summary.json`` (``fmus.<name>.records``).

Several records of the same channels (e.g. the seeds of one load case) in one FMU: ``records = [...]``
instead of ``record``; the FMU then has an Integer parameter ``record`` (1-based, default 1, bounds
``[1, len(records)]`` declared like every other parameter) that selects the one it plays. Every record
must cover the run (``out_of_record = "error"``); the record's span is the one all of them cover.

Where a record is found: a path relative to the scenario file; else relative to each *data root*:
the folders of ``$DTCOSIM_DATA`` (``os.pathsep``-separated), then ``shared/`` beside the dtcosim
checkout (``<repo>/../shared``, where the project's OpenFAST data live). The record is read, its
channels converted to SI and checked when the scenario is loaded, before any FMU exists; the FMU
built from it (:mod:`orchestrator.provision.series_fmus`) carries the converted samples and runs
without the file.
"""

from __future__ import annotations

import hashlib
import io
import json
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Literal

import numpy as np
from pydantic import Field

from components.analysis.record_resolution import (
    estimate_resolution,
    lowpass_zero_phase,
    sampling_of,
    step_ratio,
)
from components.errors import ParameterError

from ..errors import ScenarioError
from .schema import Table
from .series_file import LoadRecordError, read_load_record, si_conversion

#: environment variable with data roots
DATA_ENV = "DTCOSIM_DATA"
#: what an OpenFAST channel records (the signal kind of the simulated counterpart); several channels may record
#: one quantity (ElastoDyn's RotSpeed and LSSTipVxa, GenSpeed and HSShftV, RotTorq and LSShftTq, ...)
OPENFAST_QUANTITIES = {
    "RotSpeed": "rotor_speed", "LSSTipVxa": "rotor_speed", "LSSGagVxa": "rotor_speed",
    "GenSpeed": "generator_speed", "HSShftV": "generator_speed",
    "GenTq": "generator_torque", "Azimuth": "rotor_angle", "LSSTipPxa": "rotor_angle",
    "RtFldMxh": "aerodynamic_torque", "RtAeroMxh": "aerodynamic_torque",
    "RotTorq": "low_speed_shaft_torque", "LSShftTq": "low_speed_shaft_torque", "LSShftMxa": "low_speed_shaft_torque",
    "HSShftTq": "high_speed_shaft_torque", "HSSBrTq": "brake_torque",
    "BldPitch1": "blade_pitch", "GenPwr": "generator_power", "HSShftPwr": "generator_power",
    "Wind1VelX": "wind_speed",
}
#: a record's generator/rotor speed ratio may differ from its drivetrain's by this much before a run is refused
SPEED_RATIO_TOLERANCE = 0.02
_ANGLE_QUANTITIES = {"rotor_speed": "rotor_angle", "generator_speed": "generator_angle"}
#: quantities a record prescribes as a motion of the drivetrain (kinematic inputs)
KINEMATIC_QUANTITIES = ("rotor_speed", "generator_speed", "rotor_angle", "generator_angle")
#: a kinematic channel whose steps sum to more than this fraction of its own motion gets a warning
STEP_RATIO_WARNING = 0.5


class ChannelTable(Table):
    channel: str = Field(description="a channel name of the record")
    output: str | None = Field(None, description="an FMU output name (default: the channel name)")
    interpolation: Literal["pchip", "linear"] = "pchip"
    angle: str | None = Field(None, description="an output name for the integral of this channel")
    angle_initial: float = Field(0.0, description="the angle at the record's first time [rad]")
    quantity: str | None = Field(None, description="what the channel records, e.g. generator_speed")
    lowpass_hz: float | None = Field(None, gt=0.0, description="a zero-phase low-pass cut-off [Hz] (none by default)")


class SeriesTable(Table):
    record: str | None = Field(None, description="a record file (.outb, .out, .csv)")
    records: list[str] | None = Field(None, min_length=1, description="a list of record files (.outb, .out, .csv)")
    time_offset: float = Field(0.0, description="record time minus simulation time [s]")
    out_of_record: Literal["hold", "error"] = "error"
    check_speed_ratio: bool = Field(True, description="true or false: refuse a record whose generator/rotor speed "
                                                      "ratio is not the drivetrain's")
    channels: list[ChannelTable] = Field(min_length=1, description="an array of tables [[...channels]]")


def data_roots() -> list[Path]:
    """Where records are looked for after the scenario's folder: ``$DTCOSIM_DATA``, then ``<repo>/../shared``."""
    roots = [Path(p) for p in os.environ.get(DATA_ENV, "").split(os.pathsep) if p]
    roots.append(Path(__file__).resolve().parents[2].parent / "shared")
    return roots


def find_record(spec: str, base_dir: Path | None, key: str, source: str | None) -> Path:
    """The record file a scenario names (see the module docstring)."""
    candidates = ([base_dir / spec] if base_dir is not None else [Path(spec)]) + [r / spec for r in data_roots()]
    for path in candidates:
        if path.is_file():
            return path.resolve()
    raise ScenarioError(key, spec, "a record file relative to the scenario file or a data root: tried "
                        + ", ".join(str(p) for p in candidates), source)


@dataclass(frozen=True, eq=False)
class RecordedSamples:
    """The selected channels of one record file, converted to SI.

    Attributes
    ----------
    record : Path
    time_s : ndarray, shape (n,)
    samples : ndarray, shape (n, k)
        One column per selected channel.
    """

    record: Path
    time_s: np.ndarray
    samples: np.ndarray
    #: ``{"ratio", "generator", "rotor"}``: the record's generator/rotor speed ratio and the channels it comes
    #: from (:func:`speed_ratio`), or None where the record does not carry both speeds
    speed_ratio: dict | None = None
    #: what the record's check found (:func:`_resolution_warning`): ``(outputs, message)`` per quantised kinematic
    #: channel, ``outputs`` the FMU outputs it feeds (its value and its angle)
    warnings: tuple = ()
    #: per selected channel: ``channel``, ``resolution`` (:meth:`Resolution.as_dict`), ``step_ratio``, ``sampling``,
    #: ``lowpass_hz``
    checks: tuple = ()

    @property
    def data_sha256(self) -> str:
        return hashlib.sha256(self.time_s.tobytes() + self.samples.tobytes()).hexdigest()

    @property
    def start_s(self) -> float:
        return float(self.time_s[0])

    @property
    def end_s(self) -> float:
        return float(self.time_s[-1])

    def summary(self) -> dict[str, Any]:
        out = {"source": self.record.name, "start_s": self.start_s, "end_s": self.end_s,
               "samples": int(self.time_s.size), "data_sha256": self.data_sha256}
        if self.speed_ratio is not None:
            out["speed_ratio"] = self.speed_ratio
        out["channels"] = [dict(c) for c in self.checks]
        return out


@dataclass(frozen=True, eq=False)
class SeriesSpec:
    """A checked selection of recorded channels, converted to SI, from one record or several.

    Attributes
    ----------
    records : tuple of RecordedSamples
        The record (``record = "..."``) or the records (``records = [...]``), same outputs in each.
    outputs : tuple of dict
        Per FMU output: output, channel, record_unit, unit (SI), column, interpolation, integral_of,
        initial, quantity.
    time_offset_s : float
    out_of_record : str
    selectable : bool
        True for ``records = [...]``: the FMU packs them all and its ``record`` parameter selects one.
    check_speed_ratio : bool
        Refuse a run whose drivetrain's speed ratio is not the records' (the check needs the drivetrain:
        :func:`orchestrator.cosim.parameter_checks.record_speed_ratio`).
    """

    records: tuple
    outputs: tuple
    time_offset_s: float
    out_of_record: str
    selectable: bool = False
    check_speed_ratio: bool = True

    def warnings(self, used_outputs=None) -> list[str]:
        """The records' warnings (quantised kinematic channels), each once.

        ``used_outputs``: the FMU outputs that drive another component (None: all); a channel whose
        outputs (its value and its angle) drive nothing is only recorded, and not warned about.
        """
        return list(dict.fromkeys(message for r in self.records for outputs, message in r.warnings
                                  if used_outputs is None or set(outputs) & set(used_outputs)))

    @property
    def record(self) -> Path:
        """The (first) record file."""
        return self.records[0].record

    @property
    def time_s(self) -> np.ndarray:
        """Times of the (first) record [s]."""
        return self.records[0].time_s

    @property
    def samples(self) -> np.ndarray:
        """Samples of the (first) record."""
        return self.records[0].samples

    @property
    def start_s(self) -> float:
        """The latest first time of the records: every record covers [start_s, end_s]."""
        return max(r.start_s for r in self.records)

    @property
    def end_s(self) -> float:
        return min(r.end_s for r in self.records)

    @property
    def data_sha256(self) -> str:
        if len(self.records) == 1 and not self.selectable:
            return self.records[0].data_sha256
        return hashlib.sha256("".join(r.data_sha256 for r in self.records).encode()).hexdigest()

    @property
    def source(self) -> str:
        return ", ".join(r.record.name for r in self.records)

    def model(self) -> dict[str, Any]:
        """The TimeSeriesSource record model (:mod:`fmus.slaves.time_series_source`)."""
        series = {"source": self.source, "time_offset_s": self.time_offset_s,
                  "out_of_record": self.out_of_record, "outputs": [dict(o) for o in self.outputs],
                  "start_s": self.start_s, "end_s": self.end_s,
                  "samples": int(self.time_s.size), "data_sha256": self.data_sha256}
        ratios = [r.speed_ratio for r in self.records if r.speed_ratio is not None]
        if ratios and self.check_speed_ratio:
            series["speed_ratio"] = dict(ratios[0], records=[r.record.name for r in self.records
                                                             if r.speed_ratio is not None],
                                         ratios=[x["ratio"] for x in ratios])
        if self.selectable:
            series["records"] = [r.summary() for r in self.records]
        else:
            series["channels"] = [dict(c) for c in self.records[0].checks]
        return {"series": series}

    @property
    def key(self) -> str:
        """Folder name of the FMU built from it: ``<record stem>[-<n>records]-<sha256[:16] of model and data>``."""
        text = json.dumps(self.model(), sort_keys=True)
        stem = self.record.stem + (f"-{len(self.records)}records" if self.selectable else "")
        return f"{stem}-{hashlib.sha256(text.encode()).hexdigest()[:16]}"

    def npz_bytes(self) -> bytes:
        """The packed samples: ``time_s``, ``samples``; with ``records``: ``time_s_<i>``, ``samples_<i>``, i = 1..n."""
        buf = io.BytesIO()
        if self.selectable:
            arrays = {}
            for i, r in enumerate(self.records, start=1):
                arrays[f"time_s_{i}"], arrays[f"samples_{i}"] = r.time_s, r.samples
            np.savez(buf, **arrays)
        else:
            np.savez(buf, time_s=self.time_s, samples=self.samples)
        return buf.getvalue()

    def covers(self, start_s: float, stop_s: float) -> bool:
        eps = 1e-9 * max(1.0, abs(self.end_s))
        return (self.start_s - eps <= start_s + self.time_offset_s
                and stop_s + self.time_offset_s <= self.end_s + eps)

    def check_covers(self, start_s: float, stop_s: float, key: str, source: str | None) -> None:
        """With ``out_of_record = "error"``: a ScenarioError when the run leaves a record."""
        if self.out_of_record == "error" and not self.covers(start_s, stop_s):
            off = self.time_offset_s
            short = next(r for r in self.records if not (
                r.start_s - 1e-9 * max(1.0, abs(r.end_s)) <= start_s + off
                and stop_s + off <= r.end_s + 1e-9 * max(1.0, abs(r.end_s))))
            raise ScenarioError(key, f"{short.record.name} [{short.start_s:g}, {short.end_s:g}] s", (
                f"a record covering the run [{start_s:g}, {stop_s:g}] s + time_offset {off:g} s = "
                f"[{start_s + off:g}, {stop_s + off:g}] s (the record is shorter than the run: shorten the run, "
                f"set time_offset, or out_of_record = \"hold\")"), source)


def speed_ratio(record) -> dict | None:
    """The generator/rotor speed ratio of a record that carries both speeds, or None.

    The median of ``generator / rotor`` over the samples where the rotor turns at more than a tenth
    of its largest speed (in one unit: both speeds are converted to SI first), with the channels used
    (the first of :data:`OPENFAST_QUANTITIES` for each quantity present in the record).
    """
    def first(quantity: str) -> str | None:
        return next((c for c, q in OPENFAST_QUANTITIES.items() if q == quantity and c in record.channels), None)

    rotor, generator = first("rotor_speed"), first("generator_speed")
    if rotor is None or generator is None:
        return None
    speeds = []
    for name in (rotor, generator):
        unit, values = record.channel(name)
        try:
            speeds.append(np.asarray(values, dtype=float) * si_conversion(unit, name, record.source)[1])
        except LoadRecordError:
            return None
    w_r, w_g = speeds
    turning = np.isfinite(w_r) & np.isfinite(w_g) & (np.abs(w_r) > 0.1 * np.nanmax(np.abs(w_r)))
    if not np.any(turning):
        return None
    return {"ratio": float(np.median(w_g[turning] / w_r[turning])), "generator": generator, "rotor": rotor}


def _channel(record, name: str) -> tuple[str, np.ndarray]:
    """:meth:`Record.channel`; a missing channel also names the record's channels of the same quantity."""
    if name not in record.channels and name in OPENFAST_QUANTITIES:
        quantity = OPENFAST_QUANTITIES[name]
        same = [c for c, q in OPENFAST_QUANTITIES.items() if q == quantity and c in record.channels]
        if same:
            raise LoadRecordError("channel", name, f"a channel of the record; it records the {quantity.replace('_', ' ')} "
                                  f"as {', '.join(same)} (did you mean {same[0]}?)", record.source)
    return record.channel(name)


def _resolution_warning(path: Path, ckey: str, ch: ChannelTable, unit: str, quantity: str, check: dict) -> str | None:
    """The warning for a kinematic channel whose quantisation steps dominate its motion (None: no warning)."""
    if quantity not in KINEMATIC_QUANTITIES or ch.lowpass_hz is not None or check["step_ratio"] <= STEP_RATIO_WARNING:
        return None
    return (f"{path.name}: {ckey} = {ch.channel} is recorded with {check['resolution']['description']}, sampled "
            f"every {check['sampling']['interval_s']:.3g} s; its steps add up to {check['step_ratio']:.2g}x its own "
            f"sample-to-sample motion (more than {STEP_RATIO_WARNING:g}), so played as a prescribed "
            f"{quantity.replace('_', ' ')} the staircase excites the drivetrain's modes and the torques show the "
            f"quantisation. Remedy: {ckey}.lowpass_hz = 1.0 (a zero-phase low-pass below the drivetrain's first mode), "
            f"or drive the rotor by its torque (Rotor FMU)")


def _selected(table: SeriesTable, path: Path, key: str, source: str | None) -> tuple[list[dict], RecordedSamples]:
    """The outputs and the converted (and, where asked, low-passed) samples of ``table.channels`` in the record ``path``."""
    record = read_load_record(path)
    outputs, columns, seen, warnings, checks = [], [], {}, [], []
    sampling = sampling_of(record.time_s)
    for i, ch in enumerate(table.channels):
        ckey = f"{key}.channels[{i}]"
        unit, values = _channel(record, ch.channel)
        si_unit, factor = si_conversion(unit, ch.channel, record.source)
        bad = np.flatnonzero(~np.isfinite(values))
        if bad.size:
            raise LoadRecordError(ch.channel, f"NaN at t = {record.time_s[bad[0]]:g} s (row {int(bad[0])})",
                              f"finite samples ({bad.size} of {values.size} are not)", record.source)
        quantity = ch.quantity or OPENFAST_QUANTITIES.get(ch.channel, "")
        raw = np.asarray(values, dtype=float)
        resolution = estimate_resolution(raw)  # on the numbers as written, before the unit conversion
        check = {"resolution": resolution.as_dict(unit, factor), "step_ratio": step_ratio(raw, resolution.steps),
                 "sampling": sampling.as_dict(), "lowpass_hz": ch.lowpass_hz}
        warning = _resolution_warning(path, ckey, ch, unit, quantity, check)
        if warning is not None:
            warnings.append(((ch.output or ch.channel,) + ((ch.angle,) if ch.angle else ()), warning))
        si_values = raw * factor
        if ch.lowpass_hz is not None:
            if not sampling.uniform:
                raise ScenarioError(f"{ckey}.lowpass_hz", ch.lowpass_hz, f"a record sampled evenly to filter "
                                    f"({path.name}: time steps {sampling.smallest_s:g} to {sampling.largest_s:g} s)",
                                    source)
            try:
                si_values = lowpass_zero_phase(si_values, sampling.interval_s, ch.lowpass_hz)
            except ParameterError as exc:
                raise ScenarioError(f"{ckey}.lowpass_hz", ch.lowpass_hz, f"{exc.expected} ({path.name})",
                                    source) from None
        column = len(columns)
        columns.append(si_values)
        names = [(ch.output or ch.channel, False, quantity)]
        if ch.angle:
            if si_unit != "rad/s":
                raise ScenarioError(f"{ckey}.angle", ch.angle, f"an angle of a speed channel (rad/s); {ch.channel} "
                                    f"is in {unit}", source)
            names.append((ch.angle, True, _ANGLE_QUANTITIES.get(quantity, "")))
        for name, integral, q in names:
            if name in seen:
                raise ScenarioError(f"{ckey}.output", name, f"a new output name (already {seen[name]})", source)
            seen[name] = ckey
            outputs.append({"output": name, "channel": ch.channel, "record_unit": unit,
                            "unit": "rad" if integral else si_unit, "column": column,
                            "interpolation": ch.interpolation, "integral_of": integral,
                            "initial": float(ch.angle_initial) if integral else 0.0, "quantity": q,
                            "lowpass_hz": ch.lowpass_hz})
        checks.append({"channel": ch.channel, **check})
    return outputs, RecordedSamples(path, record.time_s.copy(), np.column_stack(columns), speed_ratio(record),
                                    tuple(warnings), tuple(checks))


def series_from_table(table: SeriesTable, key: str, base_dir: Path | None, source: str | None) -> SeriesSpec:
    """Read, select, convert and check the channels of a ``series`` table.

    Raises
    ------
    ScenarioError, LoadRecordError
        Neither or both of ``record`` and ``records``; a file not found; any problem of a record
        (:func:`read_load_record`) or of a channel: missing (with "did you mean"), a unit with no SI
        conversion, NaN, a duplicate output; a record whose channel has another SI unit than the first's.
    """
    if (table.record is None) == (table.records is None):
        given = {k: v for k, v in (("record", table.record), ("records", table.records)) if v is not None}
        raise ScenarioError(key, given or None, 'either record = "file" or records = ["file", ...] (exactly one)', source)
    names = [table.record] if table.record is not None else list(table.records)
    where = [f"{key}.record"] if table.record is not None else [f"{key}.records[{i}]" for i in range(len(names))]
    outputs, recorded = None, []
    for name, rkey in zip(names, where):
        path = find_record(name, base_dir, rkey, source)
        these, samples = _selected(table, path, key, source)
        if outputs is not None:  # the same SI units (the recorded ones may differ: kN-m and N-m are converted)
            diff = next((f"{a['channel']} in {a['record_unit']} = {a['unit']} (first record: {b['record_unit']})"
                         for a, b in zip(these, outputs) if a["unit"] != b["unit"]), None)
            if diff is not None:
                raise ScenarioError(rkey, name, f"a record whose channels have the SI units of the first: {diff}",
                                    source)
        else:
            outputs = these
        recorded.append(samples)
    return SeriesSpec(tuple(recorded), tuple(outputs), float(table.time_offset), table.out_of_record,
                      selectable=table.records is not None, check_speed_ratio=table.check_speed_ratio)

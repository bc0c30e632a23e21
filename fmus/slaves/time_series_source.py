"""TimeSeriesSource FMU: recorded channels played back (:mod:`components.model.time_series`).

The samples (SI, converted at build time from the record) are packed into the FMU as
``resources/series.npz`` (arrays ``time_s`` and ``samples``); the record's ``model["series"]``
names the outputs: one per channel (its interpolation: ``linear`` C0 or ``pchip`` C1) and
angles integrated from a speed channel. Parameters: ``time_offset`` [s] (record time =
simulation time + offset), ``out_of_record`` (0 = hold the first/last sample, 1 = error: the
step is discarded with a message) and ``<angle>.initial`` [rad] per integrated output. No
inputs. Built from several records (``model["series"]["records"]``, the seeds of one load case,
say), the FMU packs each as ``time_s_<i>`` / ``samples_<i>`` and an Integer parameter ``record``
(1-based, bounds ``[1, n]``) selects the one it plays. Only numpy is imported at run time; no file outside the FMU is read.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any, Hashable, Iterable, Mapping

import numpy as np

from components.errors import DtcosimError, ParameterError, SolverError
from components.model.time_series import OUT_OF_RECORD, ChannelSpec, TimeSeriesPlayer
from components.validation import Bounds, choice_bounds, finite

from .base import DtcosimSlave
from .interface import Variable, enumeration_text, integer_parameter, real_output, real_parameter

#: the packed samples inside resources/
DATA_FILE = "series.npz"


class TimeSeriesSource(DtcosimSlave):
    """Recorded time series as FMU outputs."""

    description = "dtcosim TimeSeriesSource: recorded channels (SI) played back with C0/C1 interpolation"
    eager_output_groups = frozenset({"series"})

    @classmethod
    def build_interface(cls, model: Mapping[str, Any]) -> Iterable[Variable]:
        series = model["series"]
        variables = [
            real_parameter("time_offset", float(series["time_offset_s"]), "s",
                           "record time = simulation time + time_offset"),
            integer_parameter("out_of_record", OUT_OF_RECORD.index(series["out_of_record"]),
                              f"outside the record: {enumeration_text(OUT_OF_RECORD)}"),
        ]
        records = series.get("records")
        if records:
            variables.append(integer_parameter("record", 1, "the packed record played: " + ", ".join(
                f"{i} = {r['source']}" for i, r in enumerate(records, start=1))))
        for ch in series["outputs"]:
            if ch["integral_of"]:
                variables.append(real_parameter(f"{ch['output']}.initial", float(ch["initial"]), ch["unit"],
                                                f"value of {ch['output']} at the record's first time"))
        for ch in series["outputs"]:
            what = (f"integral of recorded {ch['channel']} ({ch['interpolation']})" if ch["integral_of"]
                    else f"recorded {ch['channel']} [{ch['record_unit']}] in SI ({ch['interpolation']} interpolation)")
            variables.append(real_output(ch["output"], ch["unit"], f"{what}, from {series['source']}", "recorded",
                                         channel=ch["channel"], record_unit=ch["record_unit"], quantity=ch["quantity"],
                                         integral=str(bool(ch["integral_of"])).lower()))
        return variables

    def output_group(self, name: str) -> Hashable:
        return "series"

    def _configure(self) -> None:
        series = self.model["series"]
        policy = self.value("out_of_record")
        if not 0 <= policy < len(OUT_OF_RECORD):
            text = enumeration_text(OUT_OF_RECORD)
            raise ParameterError("out_of_record", policy, text, choice_bounds(OUT_OF_RECORD, text))
        offset = finite("time_offset", self.value("time_offset"))
        channels = []
        for ch in series["outputs"]:
            initial = finite(f"{ch['output']}.initial", self.value(f"{ch['output']}.initial")) if ch["integral_of"] else 0.0
            channels.append(ChannelSpec(ch["output"], int(ch["column"]), ch["interpolation"], bool(ch["integral_of"]),
                                        initial))
        suffix = ""
        records = series.get("records")
        if records:
            n = len(records)
            number = Bounds(1, n, True, f"one of the {n} packed records: an integer within [1, {n}]").check(
                "record", self.value("record"))
            suffix = f"_{int(number)}"
        path = Path(self.resources) / DATA_FILE
        try:
            with np.load(path) as data:
                time_s, samples = data["time_s" + suffix], data["samples" + suffix]
        except (OSError, KeyError, ValueError) as exc:
            raise DtcosimError(f"cannot read the packed samples {path}: {exc}") from None
        self.player = TimeSeriesPlayer(time_s, samples, channels, offset, OUT_OF_RECORD[policy])
        self._vr_out = [self.vr[ch.output] for ch in channels]

    def _initialize(self, start_time: float) -> None:
        self.player.values(start_time)  # outside the record with out_of_record = error: refused here

    def _step(self, time: float, step_size: float) -> None:
        if not step_size > 0.0:
            raise ParameterError("step_size", step_size, "> 0")
        self.player.values(time + step_size)  # raises SolverError outside the record (policy error)

    def _refresh(self, group: Hashable) -> None:
        try:
            out = self.player.values(self._time)
        except SolverError:  # reported by the step; outputs hold the record's end
            out = self.player.values(min(max(self._time, self.player.start_s - self.player.offset_s),
                                         self.player.end_s - self.player.offset_s))
        for vr, value in zip(self._vr_out, out):
            self._values[vr] = value

    def _component_state(self) -> dict:
        return {}

    def _restore_component_state(self, state: dict) -> None:
        return None

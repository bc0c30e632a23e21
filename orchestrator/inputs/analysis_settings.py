"""How a run's results are analysed: the scenario's ``[analysis]`` table.

::

    [analysis]
    woehler_exponents = [3, 5, 8, 10]   # S-N exponents m of the damage-equivalent loads
    reference_frequency_hz = 1.0        # N_ref = f_ref x analysed time (1 Hz-equivalent DEL)
    ldd_bins = 64                       # load duration distribution: bin count, or explicit edges [N m]
    rainflow_residue = "half"           # "half" (ASTM E1049 half cycles) or "repeat"
    contact_loss_threshold_n = 1.0      # N: |F| below this counts as inside the backlash
    spectrum = "auto"                   # contact-force spectrum PNG: "auto" (when a mesh stiffness
                                        # varies), "always" or "never"

Every key is optional (defaults as above). All analyses use the scenario's
analysis window ``simulation.window``. See :mod:`orchestrator.run.analyses` for
what is computed and ``docs/analyses.md`` for the definitions.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

from components.analysis.fatigue import (
    DEFAULT_REFERENCE_FREQUENCY_HZ,
    DEFAULT_WOHLER_EXPONENTS,
    RESIDUE_METHODS,
    FatigueSettings,
)
from components.model.contact import CONTACT_LOSS_THRESHOLD_N
from components.validation import is_number

from ..errors import ScenarioError
from .limits import MAX_LDD_BINS
from .schema import Table

SPECTRUM_MODES = ("auto", "always", "never")


def _positive_number(value: Any) -> bool:
    return is_number(value) and math.isfinite(value) and value > 0


@dataclass(frozen=True)
class AnalysisSettings:
    """Settings of the analyses run on every result (validated).

    Parameters
    ----------
    woehler_exponents : tuple of float
        Woehler (S-N) exponents m [-] of the damage-equivalent loads, each > 0.
    reference_frequency_hz : float
        Reference frequency of the DEL [Hz]: ``N_ref = f_ref T``.
    ldd_bins : int or tuple of float
        Load duration distribution bins: a count (>= 1) of equal bins over each
        shaft's torque range, or increasing bin edges [N m] used for every shaft.
    rainflow_residue : {"half", "repeat"}
        Counting of the rainflow residue.
    contact_loss_threshold_n : float
        Contact force magnitude [N] below which a mesh counts as separated.
    spectrum : {"auto", "always", "never"}
        When to write the contact-force spectrum plot.

    Raises
    ------
    ScenarioError
        Naming ``analysis.<key>``.
    """

    woehler_exponents: tuple[float, ...] = DEFAULT_WOHLER_EXPONENTS
    reference_frequency_hz: float = DEFAULT_REFERENCE_FREQUENCY_HZ
    ldd_bins: int | tuple[float, ...] = 64
    rainflow_residue: str = "half"
    contact_loss_threshold_n: float = CONTACT_LOSS_THRESHOLD_N
    spectrum: str = "auto"

    def __post_init__(self) -> None:
        exps = self.woehler_exponents
        if (not isinstance(exps, (list, tuple)) or not exps or not all(_positive_number(m) for m in exps)):
            raise ScenarioError("analysis.woehler_exponents", exps, "a non-empty list of exponents > 0, e.g. [3, 5, 8, 10]")
        if len(set(float(m) for m in exps)) != len(exps):
            raise ScenarioError("analysis.woehler_exponents", list(exps), "distinct exponents")
        object.__setattr__(self, "woehler_exponents", tuple(float(m) for m in exps))
        if not _positive_number(self.reference_frequency_hz):
            raise ScenarioError("analysis.reference_frequency_hz", self.reference_frequency_hz, "a frequency > 0 [Hz]")
        object.__setattr__(self, "reference_frequency_hz", float(self.reference_frequency_hz))
        bins = self.ldd_bins
        if isinstance(bins, int) and not isinstance(bins, bool):
            if not 1 <= bins <= MAX_LDD_BINS:
                raise ScenarioError("analysis.ldd_bins", bins, f"a bin count within [1, {MAX_LDD_BINS}] or a list of "
                                    "increasing edges [N m]")
        else:
            ok = (isinstance(bins, (list, tuple)) and 2 <= len(bins) <= MAX_LDD_BINS + 1
                  and all(is_number(x) and math.isfinite(x) for x in bins)
                  and all(b > a for a, b in zip(bins[:-1], bins[1:])))
            if not ok:
                raise ScenarioError("analysis.ldd_bins", bins, f"a bin count >= 1 or a list of 2 to {MAX_LDD_BINS + 1} "
                                    "increasing edges [N m]")
            object.__setattr__(self, "ldd_bins", tuple(float(x) for x in bins))
        if self.rainflow_residue not in RESIDUE_METHODS:
            raise ScenarioError("analysis.rainflow_residue", self.rainflow_residue,
                                "one of " + ", ".join(repr(m) for m in RESIDUE_METHODS))
        if not _positive_number(self.contact_loss_threshold_n):
            raise ScenarioError("analysis.contact_loss_threshold_n", self.contact_loss_threshold_n, "a force > 0 [N]")
        object.__setattr__(self, "contact_loss_threshold_n", float(self.contact_loss_threshold_n))
        if self.spectrum not in SPECTRUM_MODES:
            raise ScenarioError("analysis.spectrum", self.spectrum, "one of " + ", ".join(repr(m) for m in SPECTRUM_MODES))

    def fatigue_settings(self) -> FatigueSettings:
        """The :class:`components.analysis.fatigue.FatigueSettings` these settings describe."""
        return FatigueSettings(
            wohler_exponents=self.woehler_exponents,
            reference_frequency_hz=self.reference_frequency_hz,
            residue=self.rainflow_residue,
            ldd_bins=self.ldd_bins,
        )

    def as_dict(self) -> dict[str, Any]:
        """JSON-ready, with the TOML key names."""
        return {
            "woehler_exponents": list(self.woehler_exponents),
            "reference_frequency_hz": self.reference_frequency_hz,
            "ldd_bins": self.ldd_bins if isinstance(self.ldd_bins, int) else list(self.ldd_bins),
            "rainflow_residue": self.rainflow_residue,
            "contact_loss_threshold_n": self.contact_loss_threshold_n,
            "spectrum": self.spectrum,
        }


class AnalysisTable(Table):
    """The ``[analysis]`` table of a scenario file (values checked by :class:`AnalysisSettings`)."""

    woehler_exponents: Any = None
    reference_frequency_hz: Any = None
    ldd_bins: Any = None
    rainflow_residue: Any = None
    contact_loss_threshold_n: Any = None
    spectrum: Any = None

    def settings(self) -> AnalysisSettings:
        """The checked settings (errors name ``analysis.<key>``)."""
        return AnalysisSettings(**{k: getattr(self, k) for k in self.model_fields_set})

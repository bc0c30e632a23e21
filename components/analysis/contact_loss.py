"""Contact-loss events of gear meshes: separations and time inside the backlash.

A mesh is *out of contact* (inside the backlash) while its contact force is smaller
in magnitude than a threshold (default
:data:`CONTACT_LOSS_THRESHOLD_N` = 1 N; the CFS force is exactly 0
once the flank-consistent clipping applies). Between samples the force is taken as
linear in time, so

* the *time inside the backlash* is the exact measure of ``|F(t)| < threshold`` for
  the piecewise-linear force (also when a force jumps from one flank to the other
  between two samples without a sample inside the band);
* a *separation* is a transition from contact (``|F| >= threshold``) to no contact; an
  episode already under way at the start of the analysed window (e.g. teeth starting
  centred in the backlash) is not a separation, but its time counts;
* a *flank change* is an episode after which contact resumes on the other flank
  (sign of the force), i.e. the teeth crossed the backlash: the impacts that
  drivetrain engineers worry about under load reversals.
"""

from __future__ import annotations

import csv
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import Mapping

import numpy as np

from ..errors import ParameterError
from ..model.contact import CONTACT_LOSS_THRESHOLD_N
from ..model.signals import CONTACT_FORCE
from ..reference.results import SimulationResult, select_window, series_and_time
from ..validation import positive


@dataclass(frozen=True)
class ContactLossStatistics:
    """Contact-loss events of one mesh over an analysed window.

    Attributes
    ----------
    name : str
        Force name, e.g. ``"stage3.F_mesh"``.
    separations : int
        Transitions from contact to no contact.
    flank_changes : int
        Episodes after which contact resumed on the opposite flank.
    time_in_backlash_s : float
        Total time with ``|F| < threshold`` [s].
    backlash_fraction : float
        ``time_in_backlash_s / analysed_time_s`` [-].
    longest_episode_s : float
        Longest single stay inside the backlash [s] (0 if none).
    analysed_time_s : float
        Length of the analysed window [s].
    threshold_n : float
        Force threshold [N].
    """

    name: str
    separations: int
    flank_changes: int
    time_in_backlash_s: float
    backlash_fraction: float
    longest_episode_s: float
    analysed_time_s: float
    threshold_n: float

    def as_dict(self) -> dict:
        """Plain dict (JSON-ready)."""
        return asdict(self)


def _inside_fraction(f0: np.ndarray, f1: np.ndarray, threshold: float) -> np.ndarray:
    """Fraction of each linear segment F0 -> F1 with ``|F| < threshold``."""
    df = f1 - f0
    flat = df == 0.0
    safe = np.where(flat, 1.0, df)
    s1 = (-threshold - f0) / safe
    s2 = (threshold - f0) / safe
    lo = np.clip(np.minimum(s1, s2), 0.0, 1.0)
    hi = np.clip(np.maximum(s1, s2), 0.0, 1.0)
    return np.where(flat, (np.abs(f0) < threshold).astype(float), hi - lo)


def contact_loss_events(
    time_s: np.ndarray,
    force_n: np.ndarray,
    threshold_n: float = CONTACT_LOSS_THRESHOLD_N,
    window: tuple[float, float] | None = None,
    name: str = "",
) -> ContactLossStatistics:
    """Count separations and time inside the backlash of one contact force.

    Parameters
    ----------
    time_s : ndarray, shape (N,)
        Strictly increasing sample times [s].
    force_n : ndarray, shape (N,)
        Contact force [N] (signed: the flank in contact).
    threshold_n : float
        ``|F|`` below which the teeth count as separated [N].
    window : (float, float), optional
        Analysed window [s]; default the whole record.
    name : str
        Force name carried into the result.

    Returns
    -------
    ContactLossStatistics
    """
    thr = positive("threshold_n", threshold_n)
    t, f = select_window(time_s, force_n, window)
    dt = np.diff(t)
    frac = _inside_fraction(f[:-1], f[1:], thr)
    inside_time = frac * dt
    # sample states: +1 / -1 in contact on that flank, 0 inside the band
    state = np.where(f >= thr, 1, np.where(f <= -thr, -1, 0))
    separations = flank_changes = 0
    longest = 0.0
    n = f.size
    # the samples after which the state changes: the walk below visits only those (state[k] is
    # always the state it holds, so between two changes there is nothing to count)
    changes = np.flatnonzero(state[1:] != state[:-1])

    def next_change(i: int) -> int:
        """The first k >= i with state[k + 1] != state[k] (n - 1: none)."""
        c = int(np.searchsorted(changes, i))
        return int(changes[c]) if c < changes.size else n - 1

    k = 0
    # episodes that are under way at the first sample: not a separation
    if state[0] == 0:
        j = next_change(0) + 1  # the first sample outside the band (n: none)
        longest = max(longest, float(inside_time[: min(j, n - 1)].sum()))
        k = j
    previous = state[k] if k < n else 0
    while k < n - 1:
        k = next_change(k)
        if k >= n - 1:
            break
        s_next = state[k + 1]
        if s_next == -previous:  # jumped through the band between two samples
            separations += 1
            flank_changes += 1
            longest = max(longest, float(inside_time[k]))
            previous = s_next
            k += 1
            continue
        # s_next == 0: an episode starts in interval k and lasts up to the next change
        j = next_change(k + 1) + 1
        separations += 1
        longest = max(longest, float(inside_time[k : min(j, n - 1)].sum()))
        if j < n:
            if state[j] == -previous:
                flank_changes += 1
            previous = state[j]
        k = j
    total = float(inside_time.sum())
    span = float(t[-1] - t[0])
    return ContactLossStatistics(
        name=name,
        separations=int(separations),
        flank_changes=int(flank_changes),
        time_in_backlash_s=total,
        backlash_fraction=total / span,
        longest_episode_s=longest,
        analysed_time_s=span,
        threshold_n=thr,
    )


def contact_loss_summary(
    result: SimulationResult | Mapping[str, np.ndarray],
    threshold_n: float = CONTACT_LOSS_THRESHOLD_N,
    window: tuple[float, float] | None = None,
    names: list[str] | None = None,
    time_s: np.ndarray | None = None,
) -> dict[str, ContactLossStatistics]:
    """Contact-loss statistics of every contact force of a run.

    Parameters
    ----------
    result : SimulationResult or mapping name -> ndarray
        A monolithic result, or any mapping of series (then ``time_s`` and ``names`` are
        required); FMU result columns with a ``gearbox.`` prefix work the same way.
    threshold_n : float
        Force threshold [N].
    window : (float, float), optional
        Analysed window [s].
    names : list of str, optional
        Forces to analyse, as declared (an FMU's record). Default: the series a
        :class:`SimulationResult` declares as contact forces.
    time_s : ndarray, optional
        Sample times [s] when ``result`` is a plain mapping.

    Returns
    -------
    dict of str -> ContactLossStatistics
        In the order of ``names``; ``as_dict()`` of each is JSON-ready.

    Raises
    ------
    ParameterError
        ``names`` missing for a plain mapping (it declares no kinds), or naming series it does not hold.
    """
    series, t = series_and_time(result, time_s)
    if names is None:
        if not isinstance(result, SimulationResult):
            raise ParameterError("names", None, "the contact forces of a plain mapping of series, as declared (a "
                                 "mapping declares no kinds; a SimulationResult does)")
        names = result.names_of(CONTACT_FORCE)
    missing = [n for n in names if n not in series]
    if missing:
        raise ParameterError("names", missing, "names of recorded contact forces")
    return {n: contact_loss_events(t, series[n], threshold_n, window, n) for n in names}


def write_contact_loss_csv(path: str | Path, statistics: Mapping[str, ContactLossStatistics]) -> Path:
    """Write one row per mesh (columns as :class:`ContactLossStatistics`) and return the path."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    fields = list(ContactLossStatistics.__dataclass_fields__)
    with path.open("w", newline="") as fh:
        w = csv.DictWriter(fh, fieldnames=fields)
        w.writeheader()
        for st in statistics.values():
            w.writerow(st.as_dict())
    return path

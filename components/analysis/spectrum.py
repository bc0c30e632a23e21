"""Amplitude spectra and spectral peaks of sampled signals.

* :func:`amplitude_spectrum` - one-sided amplitude spectrum of a real signal (mean
  removed, Hann window by default, amplitude-corrected so a sine of amplitude ``A``
  shows a peak of about ``A``).
* :func:`spectral_peak_hz` - frequency of the largest spectral peak, with
  zero-padding and parabolic interpolation of the log magnitude between bins. A
  complex signal (e.g. a modal coordinate ``eta(t) = eta0 exp(lambda t)``) is
  analysed two-sided and searched over positive frequencies: the magnitude of the
  transform of ``exp(lambda t)`` peaks exactly at ``Im(lambda) / (2 pi)``.
"""

from __future__ import annotations

import numpy as np

from ..errors import ParameterError
from ..validation import finite_series, positive

WINDOWS = ("hann", "rect")


def _window(name: str, n: int) -> np.ndarray:
    if name == "hann":
        return np.hanning(n)
    if name == "rect":
        return np.ones(n)
    raise ParameterError("window", name, "one of " + ", ".join(WINDOWS))


def amplitude_spectrum(
    signal: np.ndarray, sample_interval_s: float, window: str = "hann", pad_to: int | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """One-sided amplitude spectrum of a real signal.

    Parameters
    ----------
    signal : ndarray, shape (N,)
        Uniformly sampled values (any unit).
    sample_interval_s : float
        Sample interval [s].
    window : {"hann", "rect"}
        Taper applied after removing the mean.
    pad_to : int, optional
        FFT length (>= N) for zero-padding; default N.

    Returns
    -------
    frequency_hz : ndarray, shape (M,)
        Frequencies [Hz], bin width ``1 / (pad_to * dt)``.
    amplitude : ndarray, shape (M,)
        Amplitude [unit of the signal], corrected for the window's coherent gain.
    """
    x = finite_series("signal", signal, 4)
    dt = positive("sample_interval_s", sample_interval_s)
    w = _window(window, x.size)
    n_fft = x.size if pad_to is None else int(pad_to)
    if n_fft < x.size:
        raise ParameterError("pad_to", pad_to, f">= the number of samples {x.size}")
    spec = np.fft.rfft((x - x.mean()) * w, n_fft)
    amp = 2.0 * np.abs(spec) / w.sum()
    amp[0] *= 0.5
    return np.fft.rfftfreq(n_fft, dt), amp


def spectral_peak_hz(
    signal: np.ndarray,
    sample_interval_s: float,
    band_hz: tuple[float, float] | None = None,
    window: str = "rect",
    min_padded_length: int = 1 << 18,
) -> float:
    """Frequency [Hz] of the largest spectral peak, interpolated between bins.

    Parameters
    ----------
    signal : ndarray, shape (N,), real or complex
        Uniformly sampled signal. Real: mean removed, one-sided spectrum. Complex: the
        two-sided transform, searched over positive frequencies.
    sample_interval_s : float
        Sample interval [s].
    band_hz : (float, float), optional
        Search only within this band [Hz]; default all positive frequencies.
    window : {"rect", "hann"}
        Taper. ``"rect"`` suits a free decay recorded until it has died out.
    min_padded_length : int
        Zero-pad to at least this FFT length (and at least 8 N) for a fine grid.

    Returns
    -------
    float
        Peak frequency [Hz] from a parabola through the log magnitudes of the
        largest bin and its neighbours.
    """
    x = finite_series("signal", signal, 4, dtype=None)  # real or complex
    dt = positive("sample_interval_s", sample_interval_s)
    n_fft = 1 << int(np.ceil(np.log2(max(min_padded_length, 8 * x.size))))
    w = _window(window, x.size)
    if np.iscomplexobj(x):
        spec = np.abs(np.fft.fft(x * w, n_fft))
        freq = np.fft.fftfreq(n_fft, dt)
    else:
        spec = np.abs(np.fft.rfft((x - x.mean()) * w, n_fft))
        freq = np.fft.rfftfreq(n_fft, dt)
    lo, hi = (0.0, np.inf) if band_hz is None else band_hz
    sel = (freq > max(lo, 0.0)) & (freq <= hi)
    if not sel.any():
        raise ParameterError("band_hz", band_hz, "a band containing positive frequencies of the spectrum")
    masked = np.where(sel, spec, -np.inf)
    k = int(np.argmax(masked))
    df = freq[1] - freq[0]
    if 0 < k < spec.size - 1 and sel[k - 1] and sel[k + 1] and spec[k - 1] > 0 and spec[k + 1] > 0:
        y0, y1, y2 = np.log(spec[k - 1 : k + 2])
        denom = y0 - 2.0 * y1 + y2
        offset = 0.5 * (y0 - y2) / denom if denom < 0 else 0.0
        return float(freq[k] + offset * df)
    return float(freq[k])

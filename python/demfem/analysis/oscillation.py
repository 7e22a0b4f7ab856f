"""Period of an oscillating signal, so that claims like "the coordination number oscillates
with the gate's period T" (paper Figs. 6, 8) can be tested on a recording."""
from __future__ import annotations

import numpy as np

from demfem.errors import InvalidParameterError, ShapeError

__all__ = ["period_of_oscillation"]


def _parabolic_peak(values: np.ndarray, k: int) -> float:
    """Sub-sample position of the maximum at index k from the parabola through k-1, k, k+1."""
    if k <= 0 or k >= len(values) - 1:
        return float(k)
    a, b, c = values[k - 1], values[k], values[k + 1]
    denominator = a - 2.0 * b + c
    return float(k) if denominator == 0 else k + 0.5 * (a - c) / denominator


def period_of_oscillation(t: np.ndarray, signal: np.ndarray,
                          method: str = "autocorrelation") -> float:
    """Dominant period of ``signal`` sampled at uniformly spaced times ``t``.

    Methods:
        "autocorrelation": the lag of the highest peak of the autocorrelation after its first
            zero crossing (robust to non-sinusoidal shapes, such as bursts).
        "fft": the frequency of the largest peak of the power spectrum (mean removed, Hann
            window).
    Both refine the peak with a parabola through the three samples around it.

    Args:
        t: (n,) times, s, increasing with a constant step (NaN-free).
        signal: (n,) values in any unit; NaN values are replaced by the mean (gaps).
        method: "autocorrelation" or "fft".

    Returns:
        The period in s; NaN if the signal shows no oscillation inside the record (constant,
        or no autocorrelation peak after the first zero crossing).
    """
    t = np.asarray(t, float)
    x = np.asarray(signal, float)
    if t.ndim != 1 or x.shape != t.shape or len(t) < 4:
        raise ShapeError(f"shape mismatch for t/signal: expected two equal (n,) arrays, n >= 4; "
                         f"got {t.shape} and {x.shape}")
    dt = np.diff(t)
    if not (np.all(np.isfinite(t)) and np.all(dt > 0)
            and np.allclose(dt, dt[0], rtol=1e-6, atol=0.0)):
        raise InvalidParameterError("invalid t: must be finite, increasing and uniformly "
                                    "spaced (resample first)")
    step = float(dt.mean())
    finite = np.isfinite(x)
    if not finite.any():
        return float("nan")
    x = np.where(finite, x, x[finite].mean())
    x = x - x.mean()
    if not np.any(np.abs(x) > 1e-12 * max(1.0, float(np.abs(x).max()))):
        return float("nan")
    n = len(x)
    if method == "autocorrelation":
        size = 1 << int(np.ceil(np.log2(2 * n)))
        spectrum = np.fft.rfft(x, size)
        acf = np.fft.irfft(spectrum * np.conj(spectrum), size)[:n]
        # Normalise by the overlap length so that long lags are not penalised.
        acf = acf / (n - np.arange(n))
        # Only lags up to half the record: beyond, too few samples overlap to trust.
        acf = acf[: n // 2 + 1]
        negative = np.flatnonzero(acf < 0)
        if len(negative) == 0:
            return float("nan")
        start = negative[0]
        highest = float(acf[start:].max())
        if highest <= 0:
            return float("nan")
        # The highest point of the first lobe above half the highest value: the lobes at 2T,
        # 3T, ... of a clean signal are as high as the one at T, so a global argmax would pick
        # a multiple of the period by chance, and a first local maximum would pick noise.
        tail = acf[start:]
        above = tail >= 0.5 * highest
        first = int(np.argmax(above))
        below_again = np.flatnonzero(~above[first:])
        end = first + (int(below_again[0]) if len(below_again) else len(tail) - first)
        k = start + first + int(np.argmax(tail[first:end]))
        return _parabolic_peak(acf, k) * step
    if method == "fft":
        power = np.abs(np.fft.rfft(x * np.hanning(n))) ** 2
        k = 1 + int(np.argmax(power[1:]))
        frequency = _parabolic_peak(power, k) / (n * step)
        return 1.0 / frequency if frequency > 0 else float("nan")
    raise InvalidParameterError(f"invalid method = {method!r}: must be 'autocorrelation' or "
                                "'fft'")

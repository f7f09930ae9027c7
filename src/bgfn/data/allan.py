"""Allan deviation of an inertial sensor's output, with gaps, and the two error models it separates.

The Allan variance at averaging time ``tau`` is half the mean squared difference of adjacent ``tau``-averages of a
rate signal (IEEE Std 952, Annex C), here with overlapping clusters; a mask ``valid`` drops every pair of clusters
that touches an invalid sample, so short stops joined give one pooled estimate. The two error models of
:mod:`bgfn.data.imu_errors` in its conventions: white noise of density ``N`` (``avar = N^2 / tau``) and a
first-order Gauss-Markov bias of std ``sigma`` and correlation time ``T`` (IEEE Std 952's exponentially correlated
process, peaking near ``tau = 1.9 T`` at ``0.62 sigma``).
"""

from __future__ import annotations

import numpy as np

from bgfn.errors import DataError


def allan_deviation(x: np.ndarray, rate_hz: float, taus_s, valid: np.ndarray | None = None
                    ) -> tuple[np.ndarray, np.ndarray]:
    """Overlapping Allan deviation of the rate samples ``x``, skipping clusters that touch an invalid sample.

    Parameters
    ----------
    x : ndarray, shape (n,)
        Rate samples (each the mean rate over its interval; unit u, e.g. rad/s).
    rate_hz : float
        Sample rate, Hz.
    taus_s : sequence of float
        Averaging times, s (rounded to whole samples; at least one sample).
    valid : ndarray of bool, shape (n,), optional
        Samples that may be used (default: all).

    Returns
    -------
    adev : ndarray
        Allan deviation per ``tau`` (unit u; NaN where no pair of clusters is valid).
    n_pairs : ndarray of int
        Overlapping cluster pairs behind each value (they overlap: far fewer are independent).
    """
    x = np.asarray(x, float)
    if x.ndim != 1 or rate_hz <= 0:
        raise DataError("allan_deviation", "x", "a 1-D signal and a positive rate", f"shape {x.shape}, {rate_hz} Hz")
    ok = np.isfinite(x) if valid is None else (np.asarray(valid, bool) & np.isfinite(x))
    csum = np.concatenate([[0.0], np.cumsum(np.where(ok, x, 0.0))])
    cnt = np.concatenate([[0], np.cumsum(ok)])
    adev, pairs = [], []
    for tau in np.atleast_1d(np.asarray(taus_s, float)):
        m = max(1, int(round(tau * rate_hz)))
        n = x.size - 2 * m + 1
        if n <= 0:
            adev.append(np.nan)
            pairs.append(0)
            continue
        first = (csum[m:m + n] - csum[:n]) / m
        second = (csum[2 * m:2 * m + n] - csum[m:m + n]) / m
        both = ((cnt[m:m + n] - cnt[:n]) == m) & ((cnt[2 * m:2 * m + n] - cnt[m:m + n]) == m)
        pairs.append(int(both.sum()))
        adev.append(float(np.sqrt(0.5 * np.mean((second - first)[both] ** 2))) if both.any() else np.nan)
    return np.asarray(adev), np.asarray(pairs)


def white_avar(taus_s, noise_density: float) -> np.ndarray:
    """Allan variance of white noise of density ``noise_density`` (u/sqrt(Hz)): ``N^2 / tau`` (u^2)."""
    return noise_density ** 2 / np.asarray(taus_s, float)


def gauss_markov_avar(taus_s, sigma: float, corr_time_s: float) -> np.ndarray:
    """Allan variance of a first-order Gauss-Markov bias (stationary std ``sigma``, correlation time, s) (u^2)."""
    tau = np.asarray(taus_s, float)
    r = corr_time_s / tau
    q = 2.0 * sigma ** 2 / corr_time_s
    return q * corr_time_s ** 2 / tau * (1.0 - 0.5 * r * (3.0 - 4.0 * np.exp(-1.0 / r) + np.exp(-2.0 / r)))


def bias_change_var(separation_s, sigma: float, corr_time_s: float) -> np.ndarray:
    """Expected squared change of a Gauss-Markov bias over ``separation_s``: ``2 sigma^2 (1 - exp(-dt/T))``."""
    return 2.0 * sigma ** 2 * (1.0 - np.exp(-np.asarray(separation_s, float) / corr_time_s))

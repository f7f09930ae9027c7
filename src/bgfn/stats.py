"""Statistics of the outage sweep: bootstrap confidence intervals and paired comparisons.

- :func:`bootstrap_ci`: percentile bootstrap interval of a statistic (default the median), optionally a
  *cluster* bootstrap that resamples whole groups (e.g. outage starts, keeping all training seeds of a start
  together, since runs of the same start share the trajectory and are not independent).
- :func:`paired_comparison`: how often method A beats method B on paired runs, the median paired difference
  and the Wilcoxon signed-rank test (two-sided) of ``A - B``.
- :func:`too_few_for_statistics`: whether a comparison rests on one training seed or fewer than
  :data:`MIN_WINDOWS` outage windows (a page then says so instead of implying a result).
- :func:`holm_adjust`: Holm's step-down adjusted p-values of a family of tests, for a page that names the best of
  several candidates (the smallest of k raw p-values is small by chance alone).
- :func:`chi2_quantile`: the chi-square quantile of the filter's gates and consistency checks.

Every random draw takes a seed (``numpy.random.default_rng(seed)``).
"""

from __future__ import annotations

from typing import Callable

import numpy as np
from scipy import special

from bgfn.errors import DataError

#: Outage windows below which a comparison has no statistics: the exact two-sided signed-rank test's smallest p
#: with n pairs is 2 / 2^n (0.125 with 4 windows, whatever the errors), so fewer windows cannot tell a difference
#: from chance.
MIN_WINDOWS = 5


def bootstrap_ci(values, stat: Callable = np.median, n_boot: int = 2000, level: float = 0.95, seed: int = 0,
                 groups=None) -> tuple[float, float]:
    """Percentile bootstrap interval of ``stat(values)``.

    Parameters
    ----------
    values : array_like [n]
        Sample (NaNs are dropped, with their group labels).
    stat : callable
        Statistic with an ``axis`` keyword (``np.median``, ``np.mean``).
    n_boot : int
        Bootstrap replicates.
    level : float
        Coverage of the interval, in (0, 1).
    seed : int
        Seed of the resampling.
    groups : array_like [n], optional
        Cluster labels: with them whole clusters are resampled with replacement (cluster bootstrap).

    Returns
    -------
    (lo, hi) : tuple of float
        NaN, NaN for an empty sample.
    """
    x = np.asarray(values, dtype=float).ravel()
    if not 0.0 < level < 1.0:
        raise DataError("bootstrap_ci", "level", "a coverage in (0, 1)", repr(level))
    if n_boot < 1:
        raise DataError("bootstrap_ci", "n_boot", "a positive number of replicates", repr(n_boot))
    g = None if groups is None else np.asarray(groups).ravel()
    if g is not None and len(g) != len(x):
        raise DataError("bootstrap_ci", "groups", f"one label per value ({len(x)})", str(len(g)))
    ok = np.isfinite(x)
    x = x[ok]
    if g is not None:
        g = g[ok]
    if len(x) == 0:
        return float("nan"), float("nan")
    rng = np.random.default_rng(seed)
    alpha = 1.0 - level
    if g is None:
        idx = rng.integers(0, len(x), size=(n_boot, len(x)))           # [B, n]
        reps = stat(x[idx], axis=1)                                       # [B]
    else:
        labels, inverse = np.unique(g, return_inverse=True)
        members = [x[inverse == i] for i in range(len(labels))]
        pick = rng.integers(0, len(labels), size=(n_boot, len(labels)))  # [B, n_groups]
        reps = np.array([stat(np.concatenate([members[j] for j in row])) for row in pick])
    lo, hi = np.quantile(reps, [alpha / 2.0, 1.0 - alpha / 2.0])
    return float(lo), float(hi)


def wilcoxon_p(diff) -> float:
    """Two-sided p-value of the Wilcoxon signed-rank test that ``diff`` is symmetric about 0.

    Zero differences are dropped (Wilcox's convention); NaN when fewer than one non-zero difference.
    """
    d = np.asarray(diff, dtype=float)
    d = d[np.isfinite(d)]
    d = d[d != 0.0]
    if len(d) == 0:
        return float("nan")
    # imported here: scipy.stats takes about a second to import, in every process that runs a filter
    from scipy.stats import wilcoxon

    return float(wilcoxon(d, zero_method="wilcox", alternative="two-sided").pvalue)


def chi2_quantile(p, dof):
    """The chi-square distribution's ``p`` quantile with ``dof`` degrees of freedom (arrays broadcast):
    ``2 P^-1(dof / 2, p)``, ``P`` the regularized lower incomplete gamma function -- what
    ``scipy.stats.chi2.ppf`` computes, without importing ``scipy.stats`` into every filter process."""
    return 2.0 * special.gammaincinv(np.asarray(dof, dtype=float) / 2.0, p)


def paired_comparison(a, b) -> dict:
    """Compare paired errors ``a`` (method A) and ``b`` (method B): smaller is better.

    Parameters
    ----------
    a, b : array_like [n]
        Paired values (same outage start and seed at the same position); pairs with a NaN are dropped.

    Returns
    -------
    dict
        ``n`` pairs, ``wins`` (A < B), ``ties``, ``win_rate`` (wins / n), ``median_diff`` (median of A - B),
        ``median_ratio`` (median of A / B), ``p_value`` (Wilcoxon signed-rank, two-sided).
    """
    a, b = np.asarray(a, dtype=float).ravel(), np.asarray(b, dtype=float).ravel()
    if a.shape != b.shape:
        raise DataError("paired_comparison", "a/b", "two arrays of the same length", f"{a.shape} and {b.shape}")
    ok = np.isfinite(a) & np.isfinite(b)
    a, b = a[ok], b[ok]
    n = int(len(a))
    if n == 0:
        return {"n": 0, "wins": 0, "ties": 0, "win_rate": float("nan"), "median_diff": float("nan"),
                "median_ratio": float("nan"), "p_value": float("nan")}
    d = a - b
    with np.errstate(divide="ignore", invalid="ignore"):
        ratio = np.where(b != 0, a / b, np.nan)
    return {"n": n, "wins": int(np.sum(d < 0)), "ties": int(np.sum(d == 0)), "win_rate": float(np.mean(d < 0)),
            "median_diff": float(np.median(d)),
            "median_ratio": float(np.nanmedian(ratio)) if np.isfinite(ratio).any() else float("nan"),
            "p_value": wilcoxon_p(d)}


def too_few_for_statistics(n_seeds: int, n_windows: int) -> bool:
    """Whether a comparison rests on one training seed (or none) or fewer than :data:`MIN_WINDOWS` outage windows:
    its numbers are one draw, and the page says so beside them."""
    return int(n_seeds) < 2 or int(n_windows) < MIN_WINDOWS


def holm_adjust(p_values) -> np.ndarray:
    """Holm(-Bonferroni) adjusted p-values of one family of tests (Holm 1979).

    With the ``k`` finite p-values sorted ascending, ``p_(1) <= ... <= p_(k)``, the adjusted value of the ``i``-th
    (1-based) is ``max_{j <= i} min(1, (k - j + 1) p_(j))``: the running maximum keeps the adjusted values in the
    raw values' order, and the cap keeps them probabilities. Rejecting where the adjusted p is below ``alpha``
    controls the family-wise error rate at ``alpha`` under any dependence between the tests.

    Parameters
    ----------
    p_values : array_like [n]
        Raw p-values; NaN (a test not run) is no member of the family and stays NaN.

    Returns
    -------
    ndarray [n]
        The adjusted p-values in the input's order.
    """
    p = np.asarray(p_values, dtype=float).ravel()
    if np.any((p < 0) | (p > 1)):
        raise DataError("holm_adjust", "p_values", "p-values in [0, 1] (or NaN)", repr(p[(p < 0) | (p > 1)][:3]))
    out = np.full(p.shape, np.nan)
    ok = np.flatnonzero(np.isfinite(p))
    k = len(ok)
    if k == 0:
        return out
    order = ok[np.argsort(p[ok], kind="stable")]
    scaled = np.minimum(1.0, (k - np.arange(k)) * p[order])                # (k - j + 1) p_(j), j = 1..k
    out[order] = np.maximum.accumulate(scaled)
    return out


__all__ = ["MIN_WINDOWS", "bootstrap_ci", "holm_adjust", "too_few_for_statistics", "paired_comparison", "wilcoxon_p", "chi2_quantile"]

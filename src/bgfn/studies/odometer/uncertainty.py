"""Does a learned odometer know when it is wrong? Its predicted std against its speed error in the outages (beyond
the paper).

The filter weighs every speed by the network's own std (:mod:`bgfn.nav.odometer`); that helps only if the std ranks
the errors, which one calibration factor cannot repair. On notebook 07's honest speed series the epochs of each
odometer inside the outages are ranked by their predicted std and split into :data:`DEFAULT_GROUPS` groups of equal
size, each group's speed RMSE and share within +-2 sigma set side by side, with the correlation of the absolute
error and the std. An odometer whose std is the same at every epoch of a fold (``RIDGE-ODO``) is left out.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

#: Columns of ``tables/outage_odometer_uncertainty.csv`` (:func:`uncertainty_table`).
UNCERTAINTY_COLUMNS: tuple[str, ...] = ("dataset", "method", "group", "std_lo_mps", "std_hi_mps", "epochs",
                                        "speed_rmse_mps", "coverage_2sigma", "corr_abs_error_std")
#: Groups of epochs ranked by predicted std (4: quarters).
DEFAULT_GROUPS = 4


def uncertainty_table(dataset: str, series: dict | None, groups: int = DEFAULT_GROUPS) -> pd.DataFrame:
    """Per odometer of ``series`` whose std varies (module docstring): its epochs in the outages ranked by predicted
    std and split into ``groups`` equal groups (1: the smallest std), each group's std range, speed RMSE and +-2 sigma
    coverage against the reference's speed, and the correlation of |error| and std over all its epochs.

    Parameters
    ----------
    dataset : str
    series : dict or None
        ``{"truth": [K] m/s, "tracks": {label: (speed [K], std [K])}}``, NaN outside the outages.
    groups : int
        How many groups of equal size (the first ones one epoch larger where they do not divide).

    Returns
    -------
    DataFrame
        :data:`UNCERTAINTY_COLUMNS`, ``groups`` rows per odometer.
    """
    rows = []
    tracks = (series or {}).get("tracks") or {}
    truth = np.asarray(series["truth"], dtype=float) if tracks else None
    for label, (speed, std) in tracks.items():
        speed, std = np.asarray(speed, dtype=float), np.asarray(std, dtype=float)
        ok = np.isfinite(speed) & np.isfinite(std) & np.isfinite(truth)
        if np.unique(std[ok]).size <= groups:       # a std per fold, not per epoch: nothing to rank
            continue
        err, s = speed[ok] - truth[ok], std[ok]
        corr = float(np.corrcoef(np.abs(err), s)[0, 1])
        order = np.argsort(s, kind="stable")         # equal sizes by rank: ties cannot empty a group
        for g, idx in enumerate(np.array_split(order, groups), start=1):
            rows.append({"dataset": dataset, "method": label, "group": g, "std_lo_mps": float(s[idx].min()),
                         "std_hi_mps": float(s[idx].max()), "epochs": int(idx.size),
                         "speed_rmse_mps": float(np.sqrt(np.mean(err[idx] ** 2))),
                         "coverage_2sigma": float(np.mean(np.abs(err[idx]) <= 2.0 * s[idx])),
                         "corr_abs_error_std": corr})
    return pd.DataFrame(rows, columns=list(UNCERTAINTY_COLUMNS))


def ranks_errors(group_rows: pd.DataFrame) -> bool:
    """Whether an odometer's std ranks its errors: the smallest-std group has the smallest speed RMSE and the
    largest-std group the largest (``group_rows``: one odometer's rows of :func:`uncertainty_table`)."""
    g = group_rows.sort_values("group")
    rmse = g["speed_rmse_mps"].to_numpy(float)
    return bool(rmse.size >= 2 and rmse[0] == rmse.min() and rmse[-1] == rmse.max())

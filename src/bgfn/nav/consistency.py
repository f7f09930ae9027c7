"""Consistency of a GPS-aided run: the normalized innovation squared (NIS) of its GNSS fixes against chi-square.

For a filter whose ``Q`` and ``R`` describe its errors, the NIS of a fix with ``k`` used axes,
``dz^T (H P H^T + R)^-1 dz`` (Eq. eq4's innovation and its covariance, :func:`bgfn.nav.engine.measurement_nis`), is
chi-square with ``k`` degrees of freedom: mean ``k``, 5 % of the fixes above its 95 % quantile. A mean far above
``k`` is an *overconfident* filter (its covariance too small: IMU noise too low for the drive, GNSS stds too small),
far below an *underconfident* one. Notebook 02 prints the verdict of every GPS-aided run so that a user sees it.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from bgfn.stats import chi2_quantile

#: A mean NIS within a factor NIS_BAND of its degrees of freedom reads as consistent. The bound is deliberately
#: loose: real GNSS errors are time-correlated and no 15-state filter models them, so a mean of 4-5 for 3 axes is
#: an ordinary filter; 66 (a MEMS IMU with its datasheet noise in a car) is not.
NIS_BAND = 2.0
#: Columns of :func:`nis_table`.
NIS_COLUMNS = ("dataset", "run", "fixes", "dof", "mean_nis", "median_nis", "above_chi2_95", "verdict")


def verdict(mean_nis: float, dof: float) -> str:
    """``consistent``, ``overconfident`` or ``underconfident`` (mean NIS against ``dof`` and :data:`NIS_BAND`);
    ``no fixes`` when there is nothing to judge."""
    if not (np.isfinite(mean_nis) and np.isfinite(dof) and dof > 0):
        return "no fixes"
    if mean_nis > NIS_BAND * dof:
        return "overconfident"
    if mean_nis < dof / NIS_BAND:
        return "underconfident"
    return "consistent"


def nis_summary(updates: pd.DataFrame, kind: str = "gnss") -> dict:
    """NIS statistics of the fixes of one kind in a run (:attr:`bgfn.nav.filter.FilterResult.updates`).

    Returns
    -------
    dict
        ``fixes`` (count), ``dof`` (mean degrees of freedom), ``mean_nis``, ``median_nis``, ``above_chi2_95``
        (fraction of fixes above the 95 % quantile of chi-square with their dof; 0.05 when consistent) and
        ``verdict`` (:func:`verdict`).
    """
    u = updates[updates["kind"] == kind] if len(updates) else updates
    if not len(u):
        return {"fixes": 0, "dof": float("nan"), "mean_nis": float("nan"), "median_nis": float("nan"),
                "above_chi2_95": float("nan"), "verdict": verdict(float("nan"), float("nan"))}
    nis, dof = u["nis"].to_numpy(float), u["dof"].to_numpy(float)
    used = dof > 0
    above = float(np.mean(nis[used] > chi2_quantile(0.95, dof[used]))) if used.any() else float("nan")
    mean, mean_dof = float(np.mean(nis)), float(np.mean(dof))
    return {"fixes": int(len(u)), "dof": mean_dof, "mean_nis": mean, "median_nis": float(np.median(nis)),
            "above_chi2_95": above, "verdict": verdict(mean, mean_dof)}


def nis_table(runs: dict) -> pd.DataFrame:
    """One row per run: ``{(dataset, run label): FilterResult.updates}`` -> columns :data:`NIS_COLUMNS`."""
    rows = [{"dataset": d, "run": label, **nis_summary(upd)} for (d, label), upd in runs.items()]
    return pd.DataFrame(rows, columns=list(NIS_COLUMNS))

"""The verdict's figure: per drive, the median max horizontal error against the outage duration for every aid, with
its bootstrap interval over the outage sweep's starts (the learned odometers' rows in the same windows)."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from bgfn.evaluate.setup import COLORS
from bgfn.report.aid_words import aid_label
from bgfn.studies.odometer.bars import HOLD, RIDGE
from bgfn.studies.outage_sweep.sweep import sweep_summary

#: The sweep's rows the figure draws: the standalone INS, the learning-free aid, the paper's networks, BGFN with NHC.
SWEEP_AIDS: tuple[str, ...] = ("INS", "INS+NHC", "MLP", "AT-LSTM", "Transformer", "BGFN", "BGFN+NHC")
#: The odometer rows it adds (beyond the paper): the held speed, the ridge, the spiking network as an odometer.
ODOMETER_AIDS: tuple[str, ...] = (HOLD, RIDGE, "BGFN-ODO")
#: Columns of :func:`duration_curves`.
CURVE_COLUMNS: tuple[str, ...] = ("method", "duration_s", "median_m", "ci_lo_m", "ci_hi_m", "n_starts")
#: Colours of the odometer rows (the sweep's rows take the outage figures' colours).
_ODOMETER_COLORS = {HOLD: "tab:gray", RIDGE: "tab:orange", "BGFN-ODO": "tab:cyan"}


def duration_curves(dataset: str, sweep: pd.DataFrame | None, odometer: pd.DataFrame | None,
                    n_boot: int = 2000, level: float = 0.95, seed: int = 0) -> pd.DataFrame:
    """Median max horizontal error per aid and duration with its interval, one drive.

    Parameters
    ----------
    dataset : str
    sweep : DataFrame or None
        ``tables/outage_sweep_summary.csv`` (already medians and intervals per method and duration).
    odometer : DataFrame or None
        ``tables/outage_odometer.csv`` (one row per start, duration, method and seed): summarized here with the
        sweep's own statistic (:func:`bgfn.studies.outage_sweep.sweep.sweep_summary`, clustered by start).
    n_boot, level, seed
        The sweep's bootstrap settings (``evaluate.sweep``).

    Returns
    -------
    DataFrame
        :data:`CURVE_COLUMNS`, aids in the order of :data:`SWEEP_AIDS` then :data:`ODOMETER_AIDS`.
    """
    parts = []
    if sweep is not None and len(sweep):
        s = sweep[(sweep["dataset"] == dataset) & sweep["method"].isin(SWEEP_AIDS)]
        parts.append(s[list(CURVE_COLUMNS)])
    if odometer is not None and len(odometer):
        o = odometer[(odometer["dataset"] == dataset) & odometer["method"].isin(ODOMETER_AIDS)]
        if len(o):
            parts.append(sweep_summary(o, n_boot=n_boot, level=level, seed=seed)[list(CURVE_COLUMNS)])
    if not parts:
        return pd.DataFrame(columns=list(CURVE_COLUMNS))
    out = pd.concat(parts, ignore_index=True)
    order = {m: i for i, m in enumerate(SWEEP_AIDS + ODOMETER_AIDS)}
    return out.sort_values(["method", "duration_s"], key=lambda c: c.map(order) if c.name == "method" else c,
                           kind="stable").reset_index(drop=True)


def plot_duration_curves(curves: pd.DataFrame, title: str, platform: str = "car"):
    """One panel: every aid's median (line, dots) and interval (band) against the outage duration, log scale; the
    legend names the rows by the aids that ran on ``platform`` (:func:`bgfn.report.aid_words.aid_label`)."""
    fig, ax = plt.subplots(figsize=(7.6, 3.6))
    for method, g in curves.groupby("method", sort=False):
        g = g.sort_values("duration_s")
        colour = COLORS.get(method) or _ODOMETER_COLORS.get(method, "tab:brown")
        dashed = method.endswith("+NHC") or method in ODOMETER_AIDS
        ax.plot(g["duration_s"], g["median_m"], "o-" if not dashed else "o--", color=colour, lw=1.4, ms=3,
                label=aid_label(method, platform))
        ax.fill_between(g["duration_s"], g["ci_lo_m"], g["ci_hi_m"], color=colour, alpha=0.12, lw=0)
    ax.set_yscale("log")
    ax.set_xlabel("outage duration (s)")
    ax.set_ylabel("max horizontal error (m)")
    ax.set_title(title, fontsize=10)
    ax.grid(True, which="both", alpha=0.3)
    if len(curves):
        ax.legend(fontsize=7, ncol=2, loc="upper left", bbox_to_anchor=(1.01, 1.0), frameon=False)
        ticks = np.unique(curves["duration_s"].to_numpy(float))
        ax.set_xticks(ticks)
    fig.tight_layout()
    return fig


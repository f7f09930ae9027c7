"""Why a learned odometer loses where an oracle speed with as much white noise wins: its speed error in the outages
split into an offset that lasts the outage and a fluctuation around it (beyond the paper).

The filter averages a white error away, but not an offset shared by every epoch of an outage (an offset ``b`` moves
the solution ``b t`` along the track). On notebook 07's honest speed series (each sweep outage predicted by its own
fold's odometer) this module measures, per odometer and duration, the RMS of each outage's mean speed error
(``offset_rms_mps``), the fluctuation around it (``fluctuation_mps``) and the integrated autocorrelation of the
normalized error (``outage_correlation``, against the ``kappa`` the filter fused it with); :func:`offset_bar_mps`
is the offset that alone would move the car as far as INS+NHC's median max error.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from bgfn.learning.odometry import DEFAULT_MAX_LAG_S, error_correlation

#: Columns of ``tables/outage_odometer_errors.csv`` (:func:`error_parts_table`).
ERROR_COLUMNS: tuple[str, ...] = ("dataset", "method", "duration_s", "outages", "speed_rmse_mps", "offset_rms_mps",
                                  "fluctuation_mps", "outage_correlation")


def error_parts_table(dataset: str, series: dict | None, durations,
                      max_lag_s: float = DEFAULT_MAX_LAG_S) -> pd.DataFrame:
    """Per odometer of ``series`` and duration of ``durations`` (s): its speed error in the outages split into the
    offset per outage and the fluctuation around it, and its correlation there (module docstring).

    Parameters
    ----------
    dataset : str
    series : dict or None
        ``{"time": [K] s, "truth": [K] m/s, "outages": [(start, duration), ...], "tracks": {label: (speed [K],
        std [K])}}``, NaN outside the outages.
    durations : sequence of float
        Seconds from each outage's start; an outage shorter than a duration is scored over what it has.
    max_lag_s : float
        Longest lag of the correlation, s (``evaluate.odometer.correlation_max_lag_s``, as the fused ``kappa``).

    Returns
    -------
    DataFrame
        :data:`ERROR_COLUMNS`, a row per odometer and duration (none without tracks).
    """
    rows = []
    tracks = (series or {}).get("tracks") or {}
    if not tracks:
        return pd.DataFrame(columns=list(ERROR_COLUMNS))
    t, truth = np.asarray(series["time"], dtype=float), np.asarray(series["truth"], dtype=float)
    for label, (speed, std) in tracks.items():
        err_all, std_all = np.asarray(speed, dtype=float) - truth, np.asarray(std, dtype=float)
        for d in durations:
            offsets, spreads, kappas, errors = [], [], [], []
            for start, length in series["outages"]:
                m = (t > start) & (t <= start + min(float(d), float(length)) + 1e-6) & np.isfinite(err_all)
                if m.sum() < 2:
                    continue
                e = err_all[m]
                offsets.append(e.mean())
                spreads.append(e.std())
                kappas.append(error_correlation(t[m], e, std_all[m], max_lag_s=max_lag_s))
                errors.append(e)
            if not offsets:
                continue
            rows.append({"dataset": dataset, "method": label, "duration_s": float(d), "outages": len(offsets),
                         "speed_rmse_mps": float(np.sqrt(np.mean(np.concatenate(errors) ** 2))),
                         "offset_rms_mps": float(np.sqrt(np.mean(np.square(offsets)))),
                         "fluctuation_mps": float(np.sqrt(np.mean(np.square(spreads)))),
                         "outage_correlation": float(np.median(kappas))})
    return pd.DataFrame(rows, columns=list(ERROR_COLUMNS))


def offset_bar_mps(max_error_m: float, duration_s: float) -> float:
    """The speed offset (m/s) that alone moves the solution ``max_error_m`` along the track in ``duration_s``: an
    odometer off by more than INS+NHC's median max error over the outage's length loses to it."""
    return float(max_error_m) / float(duration_s)


def plot_error_parts(table: pd.DataFrame, dataset: str, bars: dict):
    """Per duration of ``table`` (one dataset's rows) a panel: each odometer's offset per outage (RMS) beside its
    fluctuation, m/s, and a dashed line at ``bars[duration]`` (:func:`offset_bar_mps` of INS+NHC's median max error
    there; absent: no line). An offset above the line alone costs more than INS+NHC's whole error."""
    durations = sorted(table["duration_s"].unique())
    fig, axes = plt.subplots(1, max(len(durations), 1), figsize=(3.2 * max(len(durations), 1), 3.4), sharey=True,
                             squeeze=False)
    for ax, d in zip(axes[0], durations):
        g = table[table["duration_s"] == d]
        x = np.arange(len(g))
        ax.bar(x - 0.2, g["offset_rms_mps"], 0.4, color="tab:red", label="offset per outage (RMS)")
        ax.bar(x + 0.2, g["fluctuation_mps"], 0.4, color="tab:gray", label="fluctuation around it")
        if np.isfinite(bars.get(d, np.nan)):
            ax.axhline(bars[d], color="black", ls="--", lw=1.0, label="INS+NHC's max error / duration")
        ax.set_xticks(x, g["method"], rotation=90, fontsize=7)
        ax.set_title(f"first {d:g} s of each outage", fontsize=9)
    axes[0][0].set_ylabel("speed error (m/s)")
    axes[0][0].legend(fontsize=6, loc="upper left")
    fig.suptitle(f"{dataset}: the learned speed's error in the outages, an offset the filter cannot average away "
                 "and a fluctuation it can", fontsize=9)
    fig.tight_layout()
    return fig

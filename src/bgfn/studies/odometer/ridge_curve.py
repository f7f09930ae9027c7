"""How the simple learned odometer's speed error falls with its training windows (beyond the paper).

On a short drive each fold of the sweep's starts holds out much of it, so a learned odometer learns from a few
minutes of driving. Is that why its speed is too coarse to help? The same starts split into more folds
(``evaluate.odometer.curve_folds``) hold out less each; ``RIDGE-ODO`` (closed form: seconds) is refitted on each
fold's honest split and predicts the starts of its own fold. The table (:data:`CURVE_COLUMNS`,
``tables/outage_odometer_curve.csv``) gives per number of folds the training windows, the validation std and the
speed RMSE and coverage in the outages: a speed RMSE that barely falls says the drive's length is not the limit.
"""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from bgfn.errors import DataError
from bgfn.learning import odometry as lo
from bgfn.nav import odometer as no

#: Columns of ``tables/outage_odometer_curve.csv`` (:func:`ridge_curve`).
CURVE_COLUMNS: tuple[str, ...] = ("dataset", "folds", "n_train", "val_std_mps", "duration_s",
                                  "outage_speed_rmse_mps", "outage_coverage_2sigma", "starts")


def ridge_curve(dataset: str, plans: dict[int, pd.DataFrame], ws: lo.SpeedWindows, all_windows: lo.SpeedWindows,
                truth: np.ndarray, duration_s: float, margin_s: float, val_fraction: float, val_blocks: int,
                alpha: float, rate_hz: float) -> pd.DataFrame:
    """``RIDGE-ODO``'s speed error against its training windows (module docstring).

    Parameters
    ----------
    dataset : str
    plans : dict
        Number of folds -> the sweep's starts split into that many folds (``start_s``, ``fold``;
        :func:`bgfn.studies.outage_sweep.sweep.sweep_plan`).
    ws : SpeedWindows
        The windows with the GPS-aided solution's forward speed (the training targets).
    all_windows : SpeedWindows
        Every aid epoch's window (what the odometer predicts).
    truth : ndarray
        The reference's speed at ``all_windows.t_end``, m/s.
    duration_s : float
        Each start's held-out outage (the sweep's longest), s; the speed errors are taken over it.
    margin_s, val_fraction, val_blocks, alpha, rate_hz
        As the odometer bars' (:func:`bgfn.learning.odometry.build_speed_data`, :class:`~bgfn.learning.odometry.
        RidgeOdometer`).

    Returns
    -------
    DataFrame
        :data:`CURVE_COLUMNS`, a row per number of folds: ``n_train`` the median training windows of a fold,
        ``val_std_mps`` the median of the folds' ridge std, ``outage_speed_rmse_mps`` the RMS over the starts (each
        holds the same epochs) and ``outage_coverage_2sigma`` the share of their epochs within +-2 sigma.
    """
    rows = []
    for n_folds, plan in sorted(plans.items()):
        if plan.empty:
            raise DataError("evaluate.odometer", "curve_folds", "folds of a sweep with starts", "no start")
        n_train, stds, errs = [], [], []
        for _, starts in plan.groupby("fold", sort=True):
            held = [(float(s), float(duration_s)) for s in starts["start_s"]]
            data = lo.build_speed_data(ws, held, margin_s, val_fraction, val_blocks)
            model = lo.RidgeOdometer.fit(data.train, data.val, rate_hz, alpha)
            track = model.track(all_windows)
            n_train.append(data.info["n_train"])
            stds.append(model.std_mps)
            errs += [no.speed_errors(track, all_windows.t_end, truth, s, d) for s, d in held]
        rmse = np.array([e["speed_rmse_mps"] for e in errs])
        cover = np.array([e["coverage_2sigma"] for e in errs])
        rows.append({"dataset": dataset, "folds": int(n_folds), "n_train": float(np.median(n_train)),
                     "val_std_mps": float(np.median(stds)), "duration_s": float(duration_s),
                     "outage_speed_rmse_mps": float(np.sqrt(np.nanmean(rmse ** 2))),
                     "outage_coverage_2sigma": float(np.nanmean(cover)), "starts": int(len(errs))})
    return pd.DataFrame(rows, columns=list(CURVE_COLUMNS))


def plot_curve(curve: pd.DataFrame):
    """RIDGE-ODO's speed RMSE in its outages (solid) and its validation std (dashed) against its training windows
    per fold, one colour per drive, each point labelled with its number of folds."""
    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    for ds, g in curve.groupby("dataset", sort=False):
        g = g.sort_values("n_train")
        line, = ax.plot(g["n_train"], g["outage_speed_rmse_mps"], marker="o", label=f"{ds}: in its outages")
        ax.plot(g["n_train"], g["val_std_mps"], ls="--", marker=".", color=line.get_color(),
                label=f"{ds}: validation std")
        for r in g.itertuples():
            ax.annotate(f"{r.folds}", (r.n_train, r.outage_speed_rmse_mps), textcoords="offset points",
                        xytext=(3, 4), fontsize=7)
    ax.set_xlabel("training windows per fold (median; the numbers: folds)")
    ax.set_ylabel("forward speed error (m/s)")
    ax.set_ylim(bottom=0.0)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=7)
    ax.set_title("RIDGE-ODO: speed error against its training windows", fontsize=10)
    fig.tight_layout()
    return fig

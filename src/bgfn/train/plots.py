"""Figures of notebook 03: training curves, predicted against true delta_p_gps on the validation block, and the
headings and speeds of the training, validation and outage windows."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np

from bgfn.learning import LearningData


def plot_training_curves(cards: list[dict], title: str = ""):
    """Training (dashed) and validation (solid) loss per epoch, one panel per method, one line per seed; epoch 0
    is the initial network (validation only), the dot each run's best epoch."""
    methods = list(dict.fromkeys(c["method"] for c in cards))
    fig, axes = plt.subplots(1, len(methods), figsize=(3.6 * len(methods), 3.2), squeeze=False, sharey=True)
    for ax, m in zip(axes[0], methods):
        for i, c in enumerate(c for c in cards if c["method"] == m):
            ep = [h["epoch"] for h in c["history"]]
            color = f"C{i}"
            train = [np.nan if h["train_loss"] is None else h["train_loss"] for h in c["history"]]
            ax.plot(ep, train, "--", color=color, lw=1)      # epoch 0 (the initial network) has none
            ax.plot(ep, [h["val_loss"] for h in c["history"]], "-", color=color, lw=1.5,
                    label=f"seed {c['seed']}")
            ax.plot(c["best_epoch"], c["best_val_loss"], "o", color=color, ms=4)
        ax.set_yscale("log")
        ax.set_title(m)
        ax.set_xlabel("epoch")
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel("MSE (normalized): -- train, - validation")
    axes[0, -1].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_val_predictions(data: LearningData, predictions: dict, title: str = "", segment_s: float = 120.0):
    """Predicted against true delta_p_gps on the validation windows: a time segment and scatter plots.

    Parameters
    ----------
    data : LearningData
    predictions : dict
        ``{method: [M, 2] array}`` (north, east, m) for ``data.val``.
    """
    val = data.val
    t = val.t_to
    seg = np.flatnonzero(t <= t[0] + segment_s)
    # break the lines where windows are missing (excluded outages, GNSS gaps)
    step = np.median(np.diff(t)) if len(t) > 1 else 1.0
    gap = np.concatenate([[False], np.diff(t[seg]) > 1.5 * step])

    def broken(a):
        a = np.asarray(a, dtype=float)[seg]
        return np.insert(a, np.flatnonzero(gap), np.nan)
    fig, axes = plt.subplots(2, 2, figsize=(12, 6.5), gridspec_kw={"width_ratios": [2.2, 1]})
    for row, (k, name) in enumerate(((0, "north"), (1, "east"))):
        ax = axes[row, 0]
        ax.plot(broken(t - t[0]), broken(val.y[:, k]), "k-", lw=2, label="GNSS (true)")
        for i, (m, p) in enumerate(predictions.items()):
            ax.plot(broken(t - t[0]), broken(p[:, k]), "-", color=f"C{i}", lw=1, label=m)
        ax.set_ylabel(f"delta_p_gps {name}, m")
        ax.grid(alpha=0.3)
        sc = axes[row, 1]
        lim = np.nanmax(np.abs(val.y[:, k])) * 1.1
        sc.plot([-lim, lim], [-lim, lim], "k-", lw=0.8)
        for i, (m, p) in enumerate(predictions.items()):
            sc.plot(val.y[:, k], p[:, k], ".", color=f"C{i}", ms=2, alpha=0.5, label=m)
        sc.set_xlabel(f"true {name}, m")
        sc.set_ylabel(f"predicted {name}, m")
        sc.set_aspect("equal")
        sc.grid(alpha=0.3)
    axes[1, 0].set_xlabel(f"time since {t[0]:.1f} s (validation block), s")
    axes[0, 0].legend(fontsize=8, ncol=3)
    fig.suptitle(title)
    fig.tight_layout()
    return fig


def plot_motion_coverage(sets: dict, title: str = ""):
    """Heading and speed histograms of the windows a network trains on, is validated on and meets in the
    outages. ``sets``: ``{label: DataFrame with heading_deg, speed_mps}`` (:func:`bgfn.learning.motion_of_windows`,
    :func:`bgfn.learning.motion_in_windows`)."""
    fig, axes = plt.subplots(1, 2, figsize=(11, 3.4))
    for i, (label, df) in enumerate(sets.items()):
        df = df.dropna()                                  # no heading where a reference has no attitude or motion
        if not len(df):
            continue
        axes[0].hist(df["heading_deg"], bins=np.arange(0, 361, 15), density=True, histtype="step", lw=1.5,
                     color=f"C{i}", label=f"{label} ({len(df)})")
        axes[1].hist(df["speed_mps"], bins=np.arange(0, max(25.0, float(df["speed_mps"].max()) + 1), 1.0),
                     density=True, histtype="step", lw=1.5, color=f"C{i}", label=label)
    axes[0].set_xlabel("heading (INS yaw), deg")
    axes[1].set_xlabel("speed over the increment, m/s")
    for ax in axes:
        ax.set_ylabel("density")
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig

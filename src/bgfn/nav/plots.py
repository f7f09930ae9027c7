"""Figures of notebook 02: navigation errors, estimated against simulated biases, outage error growth."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from ..paper import NHC_SUFFIX
from .earth import curvature_radii


def plot_navigation_errors(errors: pd.DataFrame, sd: pd.DataFrame | None = None, lat=None, title: str = ""):
    """Position (m), velocity (m/s) and attitude (deg) errors against time, with +-3 sd bands.

    Parameters
    ----------
    errors : DataFrame
        :func:`bgfn.nav.metrics.navigation_errors`.
    sd : DataFrame, optional
        ``FilterResult.sd`` (same rows); the band uses the std of ``dL`` and ``dlambda``.
    lat : array_like, optional
        Latitude of the rows (rad), to turn ``dL``/``dlambda`` std into metres (needed with ``sd``).
    title : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    t = errors["time"].to_numpy() - errors["time"].iloc[0]
    fig, axes = plt.subplots(3, 1, figsize=(9, 8), sharex=True)
    groups = [(("north", "east", "down"), "position error (m)", 1.0),
              (("v_n", "v_e", "v_d"), "velocity error (m/s)", 1.0),
              (("roll", "pitch", "yaw"), "attitude error (deg)", 180.0 / np.pi)]
    for ax, (cols, label, scale) in zip(axes, groups):
        for col in cols:
            ax.plot(t, errors[col] * scale, lw=0.8, label=col)
        ax.set_ylabel(label)
        ax.grid(alpha=0.3)
        ax.legend(loc="upper right", ncol=3, fontsize=8)
    if sd is not None:
        # Position std in metres from the (dL, dlambda) states.
        lat = np.asarray(lat, dtype=float)
        r_m, r_n = curvature_radii(lat)
        sn = sd["dL"].to_numpy() * r_m
        se = sd["dlambda"].to_numpy() * r_n * np.cos(lat)
        axes[0].fill_between(t, -3 * np.hypot(sn, se), 3 * np.hypot(sn, se), color="0.8", alpha=0.5,
                             label="+-3 sd (horizontal)")
    axes[-1].set_xlabel(f"time since {errors['time'].iloc[0]:.0f} s (GPS time of week)")
    if title:
        axes[0].set_title(title)
    fig.tight_layout()
    return fig


def plot_biases(bias: pd.DataFrame, true_bias: pd.DataFrame | None = None, title: str = ""):
    """Estimated accelerometer (m/s^2) and gyro (deg/h) biases, with the simulated ones dashed.

    Parameters
    ----------
    bias : DataFrame
        ``FilterResult.bias``.
    true_bias : DataFrame, optional
        ``Drive.imu_bias`` (simulated drives).
    title : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    fig, axes = plt.subplots(2, 1, figsize=(9, 6), sharex=True)
    t0 = bias["time"].iloc[0]
    for ax, sensor, scale, unit in ((axes[0], "accel", 1.0, "m/s^2"), (axes[1], "gyro", 180 / np.pi * 3600, "deg/h")):
        for i, axis in enumerate("xyz"):
            col = f"{sensor}_bias_{axis}"
            line, = ax.plot(bias["time"] - t0, bias[col] * scale, lw=1.0, label=f"{axis} estimated")
            if true_bias is not None and col in true_bias:
                ax.plot(true_bias["time"] - t0, true_bias[col] * scale, ls="--", lw=0.8, color=line.get_color(),
                        label=f"{axis} simulated")
        ax.set_ylabel(f"{sensor} bias ({unit})")
        ax.grid(alpha=0.3)
        # a fixed corner: "best" searches every point of a whole drive's traces, which matplotlib warns is slow
        ax.legend(ncol=3, fontsize=8, loc="upper right")
    axes[-1].set_xlabel(f"time since {t0:.0f} s")
    if title:
        axes[0].set_title(title)
    fig.tight_layout()
    return fig


def plot_outage_errors(outage_errors: dict, title: str = ""):
    """East and north error against time in each outage (the paper's Figs. out1/out2 layout).

    Parameters
    ----------
    outage_errors : dict
        ``{label: errors DataFrame with t_rel}``, e.g. ``Baseline.outage_errors``; with a ``method`` column,
        one line per method (``INS`` solid red, ``INS+NHC`` dashed).
    title : str

    Returns
    -------
    matplotlib.figure.Figure
    """
    n = len(outage_errors)
    fig, axes = plt.subplots(n, 2, figsize=(10, 3.2 * n), squeeze=False)
    for row, (label, e) in enumerate(outage_errors.items()):
        for col, comp in enumerate(("east", "north")):
            ax = axes[row, col]
            method = e["method"] if "method" in e.columns else pd.Series("INS", e.index)
            for m in dict.fromkeys(method):
                g = e[method == m]
                ax.plot(g["t_rel"], g[comp], color="tab:red", ls="--" if m.endswith(NHC_SUFFIX) else "-", label=m)
            ax.set_title(f"{label}: {comp} error")
            ax.set_xlabel("time in outage (s)")
            ax.set_ylabel(f"{comp} error (m)")
            ax.grid(alpha=0.3)
            ax.legend(fontsize=8)
    if title:
        fig.suptitle(title)
    fig.tight_layout()
    return fig

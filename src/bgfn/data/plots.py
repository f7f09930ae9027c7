"""Figures of notebook 01: the 3D trajectory with the outages in red (paper Fig. 3d), a map view, IMU channels."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from bgfn.nav.earth import lla_to_ned

_COLORS = {"turin-sim-ekinox": "tab:blue", "turin-sim-mpu6000": "tab:orange",
           "navego-ekinox": "tab:green", "navego-mpu6000": "tab:purple"}


def local_enu(table: pd.DataFrame, origin: pd.Series | None = None) -> np.ndarray:
    """East, north, up (m) of a table's ``lat, lon, h`` relative to ``origin`` (default: its first row).

    Returns
    -------
    ndarray, shape (n, 3)
    """
    o = table.iloc[0] if origin is None else origin
    ned = lla_to_ned(table["lat"].to_numpy(float), table["lon"].to_numpy(float), table["h"].to_numpy(float),
                     float(o["lat"]), float(o["lon"]), float(o["h"]))
    return np.column_stack([ned[:, 1], ned[:, 0], -ned[:, 2]])


def in_windows(t, windows) -> np.ndarray:
    """Mask of times inside any ``(start, duration)`` window (``start <= t < start + duration``)."""
    t = np.asarray(t, dtype=float)
    mask = np.zeros(t.shape, dtype=bool)
    for start, duration in windows:
        mask |= (t >= start) & (t < start + duration)
    return mask


def _segments(mask: np.ndarray):
    """(first, last) indices of each run of True in ``mask``."""
    edges = np.flatnonzero(np.diff(np.concatenate([[0], mask.astype(int), [0]])))
    return list(zip(edges[::2], edges[1::2] - 1))


def plot_trajectory_3d(reference: pd.DataFrame, windows, *, step: int = 10):
    """3D trajectory (east, north, up) in blue with the outage windows in red.

    Parameters
    ----------
    reference : DataFrame
        Truth (reference schema).
    windows : iterable of (start, duration)
        Outages, s (GPS time of week).
    step : int
        Plot every ``step``-th epoch.

    Returns
    -------
    matplotlib.figure.Figure
    """
    enu = local_enu(reference)
    mask = in_windows(reference["time"], windows)
    fig = plt.figure(figsize=(7.5, 6))
    ax = fig.add_subplot(projection="3d")
    ax.plot(enu[::step, 0], enu[::step, 1], enu[::step, 2], color="tab:blue", lw=1.0, label="trajectory")
    for i, (a, b) in enumerate(_segments(mask)):
        ax.plot(enu[a:b + 1, 0], enu[a:b + 1, 1], enu[a:b + 1, 2], color="red", lw=3.0,
                label="GPS outages" if i == 0 else None)
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    ax.set_zlabel("up (m)")
    ax.legend(loc="upper left")
    ax.set_title("Turin drive (NaveGo), truth")
    return fig


def plot_map(reference: pd.DataFrame, gnss: pd.DataFrame | None, windows, *, step: int = 10):
    """Map view (east vs north, equal axes): truth, GNSS fixes, outages in red with their start times.

    Returns
    -------
    matplotlib.figure.Figure
    """
    enu = local_enu(reference)
    mask = in_windows(reference["time"], windows)
    fig, ax = plt.subplots(figsize=(6.5, 8))
    if gnss is not None and len(gnss):
        g = local_enu(gnss, reference.iloc[0])
        ax.plot(g[:, 0], g[:, 1], ".", ms=1.5, color="0.6", label="GNSS fixes")
    ax.plot(enu[::step, 0], enu[::step, 1], color="tab:blue", lw=1.0, label="truth")
    t = reference["time"].to_numpy(float)
    for i, (a, b) in enumerate(_segments(mask)):
        ax.plot(enu[a:b + 1, 0], enu[a:b + 1, 1], color="red", lw=3.0, label="GPS outages" if i == 0 else None)
        ax.annotate(f"{t[a]:.0f} s", enu[a, :2], textcoords="offset points", xytext=(5, 5), color="red")
    ax.plot(*enu[0, :2], "k^", label="start")
    ax.set_aspect("equal")
    ax.set_xlabel("east (m)")
    ax.set_ylabel("north (m)")
    ax.grid(alpha=0.3)
    ax.legend(loc="upper left", bbox_to_anchor=(1.02, 1.0))  # outside: the drive fills the axes
    return fig


def plot_imu_channels(drives: dict, t_start: float, duration: float):
    """Gyro and accelerometer channels of several drives over ``[t_start, t_start + duration]``.

    Parameters
    ----------
    drives : dict of str to Drive
        Drives to overlay (e.g. the Ekinox-D and the MPU-6000 grade).
    t_start, duration : float
        Segment, s; when no drive has samples there, the first drive's first ``duration`` seconds.

    Returns
    -------
    matplotlib.figure.Figure
        3 x 2 panels: gyro x/y/z (deg/s) left, accel x/y/z (m/s^2) right.
    """
    fig, axes = plt.subplots(3, 2, figsize=(11, 7), sharex=True)
    if drives and not any(((d.imu["time"] >= t_start) & (d.imu["time"] <= t_start + duration)).any()
                          for d in drives.values()):
        t_start = float(next(iter(drives.values())).imu["time"].iloc[0])   # e.g. a user's drive on another clock
    for name, drive in drives.items():
        imu = drive.imu
        seg = imu.loc[(imu["time"] >= t_start) & (imu["time"] <= t_start + duration)]
        t = seg["time"].to_numpy(float) - t_start
        for i, a in enumerate("xyz"):
            axes[i, 0].plot(t, np.degrees(seg[f"gyro_{a}"]), lw=0.7, color=_COLORS.get(name), label=name)
            axes[i, 1].plot(t, seg[f"accel_{a}"], lw=0.7, color=_COLORS.get(name), label=name)
    for i, a in enumerate("xyz"):
        axes[i, 0].set_ylabel(f"gyro_{a} (deg/s)")
        axes[i, 1].set_ylabel(f"accel_{a} (m/s$^2$)")
    for ax in axes.ravel():
        ax.grid(alpha=0.3)
    axes[-1, 0].set_xlabel(f"time - {t_start:.0f} s (GPS time of week)")
    axes[-1, 1].set_xlabel(f"time - {t_start:.0f} s (GPS time of week)")
    axes[0, 0].legend(loc="upper right", fontsize=8)
    fig.tight_layout()
    return fig

"""The target of the learning problem, Eq. (eq8-1): the GPS position increment delta_p_gps between two GNSS
epochs, and what it is checked against.

``delta_p_gps`` = (north, east) change of the GNSS position between two consecutive GNSS epochs, in metres, from
the latitude/longitude differences and the WGS84 curvature radii at the mid-point::

    dN = (lat_b - lat_a) (R_M + h),   dE = (lon_b - lon_a) (R_N + h) cos(lat)

The INS increment (:func:`ins_increments`, the distance the GPS-aided INS travelled over the same interval)
screens GNSS jumps out of the targets (:func:`screen_increments`) and is one of the references
(:mod:`bgfn.learning.references`). The target frame (``train.target_frame``) is the frame the network outputs
in: north/east (the paper's) or the frame of the window's last INS yaw (:func:`to_target_frame`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from bgfn.errors import DataError
from bgfn.learning.inputs import check_table, wrap_angle
from bgfn.nav.earth import curvature_radii

#: The 2 outputs: north and east GPS position increment, m.
TARGETS: tuple[str, ...] = ("dn", "de")
#: ``train.target_frame`` values: north/east (the paper's Eq. eq21 output) or along/cross-track of the window's
#: last INS yaw (:func:`to_target_frame`).
TARGET_FRAMES = ("ned", "heading")


def position_increment(lat_a, lon_a, h_a, lat_b, lon_b, h_b) -> np.ndarray:
    """North/east position change a -> b, m (Eq. eq8-1's delta_p_gps; curvature radii at the mid-latitude,
    mid-height).

    Returns
    -------
    ndarray [..., 2]
        ``(dN, dE)``.
    """
    lat_a, lat_b = np.asarray(lat_a, float), np.asarray(lat_b, float)
    lat_m = 0.5 * (lat_a + lat_b)
    h_m = 0.5 * (np.asarray(h_a, float) + np.asarray(h_b, float))
    r_m, r_n = curvature_radii(lat_m)
    dn = (lat_b - lat_a) * (r_m + h_m)
    de = wrap_angle(np.asarray(lon_b, float) - np.asarray(lon_a, float)) * (r_n + h_m) * np.cos(lat_m)
    return np.stack([dn, de], axis=-1)


def gnss_increments(gnss: pd.DataFrame, max_gap_factor: float = 1.5) -> pd.DataFrame:
    """GPS position increments between consecutive GNSS epochs.

    Parameters
    ----------
    gnss : DataFrame
        ``time``, ``lat``, ``lon``, ``h`` (CONTRIBUTING.md schema); rows with NaN position are skipped.
    max_gap_factor : float
        Pairs further apart than this times the median epoch interval (a data gap) are dropped.

    Returns
    -------
    DataFrame
        ``t_from``, ``t_to`` (s), ``dn``, ``de`` (m), one row per consecutive pair.
    """
    check_table(gnss, "gnss", ("time", "lat", "lon", "h"))
    g = gnss.dropna(subset=["lat", "lon", "h"])
    t = g["time"].to_numpy(float)
    if len(t) < 2:
        raise DataError("gnss", "lat", "at least 2 GNSS epochs with a position")
    dt = np.diff(t)
    ok = dt <= max_gap_factor * np.median(dt)
    lat, lon, h = (g[c].to_numpy(float) for c in ("lat", "lon", "h"))
    d = position_increment(lat[:-1], lon[:-1], h[:-1], lat[1:], lon[1:], h[1:])
    return pd.DataFrame({"t_from": t[:-1][ok], "t_to": t[1:][ok], "dn": d[ok, 0], "de": d[ok, 1]})


def ins_increments(attitude: pd.DataFrame, t_from, t_to) -> np.ndarray:
    """North/east distance the INS/KF solution travels over each interval ``[t_from, t_to]``: its velocity
    ``v_n, v_e`` integrated (trapezoid), m, [M, 2]. The position columns are not used because the filter's
    position jumps at each GNSS update, by the very GNSS error being checked. NaN for an interval outside the
    solution's span (a filter that starts late, after its self-alignment: :mod:`bgfn.nav.alignment`)."""
    check_table(attitude, "attitude", ("time", "v_n", "v_e"))
    t = attitude["time"].to_numpy(float)
    out = np.empty((len(np.atleast_1d(t_from)), 2))
    for k, col in enumerate(("v_n", "v_e")):
        v = attitude[col].to_numpy(float)
        dist = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
        out[:, k] = (np.interp(t_to, t, dist, left=np.nan, right=np.nan)
                     - np.interp(t_from, t, dist, left=np.nan, right=np.nan))
    return out


def screen_increments(residual: np.ndarray, sigma: float | None) -> np.ndarray:
    """Flag GNSS increments that disagree with the INS: ``True`` where a component of ``residual`` (GNSS
    increment minus :func:`ins_increments`, [M, 2], m) lies more than ``sigma`` robust standard deviations
    (1.4826 x the median absolute deviation, per component) from its median. ``sigma`` None or 0: none.

    Real GNSS fixes jump now and then (multipath, satellite changes): the Ekinox fixes of the Turin drive
    move by up to 7 m against the reference within 0.2 s. Such an increment is no motion a network can learn
    from the IMU, and one of them outweighs thousands of ordinary ones in a squared loss.
    """
    residual = np.asarray(residual, float)
    if not sigma:
        return np.zeros(len(residual), bool)
    if sigma < 0:
        raise DataError("train", "target_screen_sigma", "a positive number of robust std, or null", repr(sigma))
    if not np.isfinite(residual).any():
        return np.zeros(len(residual), bool)
    # NaN residuals (no INS velocity there) are never flagged and do not enter the statistics
    dev = residual - np.nanmedian(residual, axis=0)
    robust_std = 1.4826 * np.nanmedian(np.abs(dev), axis=0)
    return np.any(np.abs(dev) > float(sigma) * np.maximum(robust_std, 1e-9), axis=1)


def to_target_frame(y: np.ndarray, yaw_ref: np.ndarray, target_frame: str) -> np.ndarray:
    """(dN, dE) [M, 2] -> the model's target frame: unchanged (``'ned'``) or rotated by -yaw (``'heading'``)."""
    if target_frame not in TARGET_FRAMES:
        raise DataError("train", "target_frame", f"one of {TARGET_FRAMES}", repr(target_frame))
    y = np.asarray(y, dtype=float)
    return y.copy() if target_frame == "ned" else _rotate(y, -np.asarray(yaw_ref, dtype=float))   # along, cross


def from_target_frame(z: np.ndarray, yaw_ref: np.ndarray, target_frame: str) -> np.ndarray:
    """Inverse of :func:`to_target_frame`: model-frame increments [M, 2] -> (dN, dE), m."""
    if target_frame not in TARGET_FRAMES:
        raise DataError("train", "target_frame", f"one of {TARGET_FRAMES}", repr(target_frame))
    z = np.asarray(z, dtype=float)
    return z.copy() if target_frame == "ned" else _rotate(z, np.asarray(yaw_ref, dtype=float))


def _rotate(v: np.ndarray, angle: np.ndarray) -> np.ndarray:
    """Horizontal vectors [M, 2] (first axis north or along) rotated by ``angle`` (rad, clockwise from north)."""
    c, s = np.cos(angle), np.sin(angle)
    return np.column_stack([c * v[:, 0] - s * v[:, 1], s * v[:, 0] + c * v[:, 1]])

"""The network input of Eq. (eq21): per IMU sample the attitude of the INS/KF solution and the raw IMU specific
force and angular rate, in the order of :data:`CHANNELS`.

The named slices (:data:`ATTITUDE_CHANNELS`, :data:`IMU_CHANNELS`, ...) are the one description of that layout;
the learning windows (:mod:`bgfn.learning.windows`) and the outage runs (:mod:`bgfn.evaluate.hybrid`) both
index a sample's channel vector with them. Extra channels (``train.extra_channels``; not the paper's input)
follow from :data:`EXTRA_START` on. The yaw wrap-around is handled by :func:`encode_yaw` (the package
docstring of :mod:`bgfn.learning` describes the encodings).
"""

from __future__ import annotations

from typing import Sequence

import numpy as np
import pandas as pd

from bgfn.errors import DataError

#: The 9 input channels of Eq. (eq21), in order.
CHANNELS: tuple[str, ...] = ("roll", "pitch", "yaw", "accel_x", "accel_y", "accel_z", "gyro_x", "gyro_y", "gyro_z")


def _span(names: Sequence[str]) -> slice:
    """The contiguous positions of ``names`` in :data:`CHANNELS`."""
    first = CHANNELS.index(names[0])
    assert CHANNELS[first:first + len(names)] == tuple(names), names
    return slice(first, first + len(names))


#: The network input layout, used by the learning windows and by the outage runs (bgfn.evaluate.hybrid):
#: where each group of Eq. (eq21) sits in a sample's channel vector; ``extra_channels`` follow from
#: :data:`EXTRA_START` on.
ATTITUDE_CHANNELS = _span(("roll", "pitch", "yaw"))                                         # rad
IMU_CHANNELS = _span(("accel_x", "accel_y", "accel_z", "gyro_x", "gyro_y", "gyro_z"))      # as in the IMU table
SPECIFIC_FORCE_CHANNELS = _span(("accel_x", "accel_y", "accel_z"))                          # m/s^2
ANGULAR_RATE_CHANNELS = _span(("gyro_x", "gyro_y", "gyro_z"))                               # rad/s
EXTRA_START = len(CHANNELS)
#: Extra input channels computed from the INS solution rather than read from it: the horizontal INS velocity
#: in the frame of the sample's own yaw (along-track, cross-track), m/s. Unlike ``v_n, v_e`` they do not
#: change when the vehicle drives the same manoeuvre in another direction.
DERIVED_CHANNELS: tuple[str, ...] = ("v_along", "v_cross")
#: ``train.yaw_encoding`` values (:func:`encode_yaw`).
YAW_ENCODINGS = ("unwrap", "relative", "raw")
#: Position of the yaw in a sample's channel vector (the heading every window is referred to).
YAW_CHANNEL = CHANNELS.index("yaw")


def wrap_angle(a):
    """Wrap angles to (-pi, pi]."""
    a = np.asarray(a, dtype=float)
    w = np.mod(a + np.pi, 2.0 * np.pi) - np.pi
    return np.where(w == -np.pi, np.pi, w)


def check_table(df: pd.DataFrame, name: str, columns: Sequence[str]) -> None:
    """Raise DataError unless ``df`` has ``columns`` and at least 2 rows with strictly increasing ``time``."""
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise DataError(name, missing[0], f"columns {', '.join(columns)}", f"missing {', '.join(missing)}")
    t = df["time"].to_numpy(float)
    if len(t) < 2 or not np.all(np.diff(t) > 0):
        raise DataError(name, "time", "at least 2 rows with strictly increasing time")


def heading_velocity(v_n, v_e, yaw) -> tuple[np.ndarray, np.ndarray]:
    """Horizontal velocity in the heading frame: ``(v_along, v_cross)``, m/s (yaw clockwise from north, rad)."""
    v_n, v_e, yaw = (np.asarray(a, dtype=float) for a in (v_n, v_e, yaw))
    c, s = np.cos(yaw), np.sin(yaw)
    return c * v_n + s * v_e, -s * v_n + c * v_e


def with_derived_channels(attitude: pd.DataFrame, channels: Sequence[str]) -> pd.DataFrame:
    """``attitude`` plus the :data:`DERIVED_CHANNELS` among ``channels`` (a copy; unchanged when none)."""
    wanted = [c for c in channels if c in DERIVED_CHANNELS and c not in attitude.columns]
    if not wanted:
        return attitude
    check_table(attitude, "attitude", ("v_n", "v_e", "yaw"))
    along, cross = heading_velocity(attitude["v_n"], attitude["v_e"], attitude["yaw"])
    out = attitude.copy()
    for c in wanted:
        out[c] = along if c == "v_along" else cross
    return out


def sample_features(imu: pd.DataFrame, attitude: pd.DataFrame,
                    extra_channels: Sequence[str] = ()) -> tuple[np.ndarray, np.ndarray, tuple[str, ...]]:
    """Per-IMU-sample features of Eq. (eq21) (plus optional extra columns of ``attitude``).

    Parameters
    ----------
    imu : DataFrame
        ``time``, ``gyro_*`` (rad/s), ``accel_*`` (m/s^2) (CONTRIBUTING.md schema).
    attitude : DataFrame
        INS/KF solution: ``time``, ``roll``, ``pitch``, ``yaw`` (rad) and any ``extra_channels`` columns;
        linearly interpolated to the IMU times (yaw through its unwrapped form). Must cover the IMU span
        where windows are built; IMU rows outside it get NaN (and no window uses them).
    extra_channels : sequence of str
        Additional ``attitude`` columns appended after the 9 channels (e.g. ``('v_n', 'v_e')``) or
        :data:`DERIVED_CHANNELS` (``v_along``, ``v_cross``); not the paper's input, off by default.

    Returns
    -------
    time : ndarray [K]
        IMU times, s.
    feats : ndarray [K, 9 + len(extra_channels)]
        Channels ``CHANNELS + extra_channels``; yaw wrapped to (-pi, pi].
    channels : tuple of str
    """
    attitude_names, imu_names = CHANNELS[ATTITUDE_CHANNELS], CHANNELS[IMU_CHANNELS]
    check_table(imu, "imu", ("time", *imu_names))
    attitude = with_derived_channels(attitude, extra_channels)
    check_table(attitude, "attitude", ("time", *attitude_names, *extra_channels))
    t = imu["time"].to_numpy(float)
    ta = attitude["time"].to_numpy(float)
    cols = []
    for name in (*attitude_names, *extra_channels):
        v = attitude[name].to_numpy(float)
        if name == "yaw":
            v = np.unwrap(v)
        if len(ta) == len(t) and np.array_equal(ta, t):
            c = v.copy()
        else:
            c = np.interp(t, ta, v, left=np.nan, right=np.nan)
        cols.append(wrap_angle(c) if name == "yaw" else c)
    n_att = len(attitude_names)                  # [K, C]: attitude, IMU, extras (the layout above)
    feats = np.column_stack(cols[:n_att] + [imu[c].to_numpy(float) for c in imu_names] + cols[n_att:])
    return t, feats, CHANNELS + tuple(extra_channels)


def encode_yaw(x: np.ndarray, yaw_encoding: str) -> np.ndarray:
    """Apply the yaw encoding to windows ``x`` [M, N, C] (yaw wrapped, in channel :data:`YAW_CHANNEL`), in place;
    returns ``x``."""
    if yaw_encoding not in YAW_ENCODINGS:
        raise DataError("train", "yaw_encoding", f"one of {YAW_ENCODINGS}", repr(yaw_encoding))
    if yaw_encoding == "raw" or len(x) == 0:
        return x
    yaw = x[..., YAW_CHANNEL].astype(float)                 # [M, N]
    last = yaw[:, -1:]                                      # [M, 1]
    rel = wrap_angle(yaw - last)                            # [M, N] wrapped relative yaw
    if yaw_encoding == "relative":
        x[..., YAW_CHANNEL] = rel
    else:  # 'unwrap': continuous along the window, last sample = wrapped yaw
        rel_unwrapped = np.unwrap(rel, axis=1)
        rel_unwrapped -= rel_unwrapped[:, -1:]
        x[..., YAW_CHANNEL] = rel_unwrapped + last
    return x

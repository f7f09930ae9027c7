"""The learning problem of BGFN: IMU/INS windows -> GPS position increment (paper's O_INS - Delta P_GPS model).

Inputs (Eq. eq21): per IMU sample the 9 channels ``[roll, pitch, yaw, fx, fy, fz, wx, wy, wz]`` -- the attitude
of the INS/KF solution (interpolated to the IMU times) and the raw IMU specific force and angular rate; a
window holds the ``N`` (paper: 200) most recent samples at 100 Hz, i.e. those with ``time <= t_end``.

Target (Eq. eq8-1): ``delta_p_gps`` = (north, east) change of the GNSS position between two consecutive GNSS
epochs, in metres, from the latitude/longitude differences and the WGS84 curvature radii at the mid-point::

    dN = (lat_b - lat_a) (R_M + h),   dE = (lon_b - lon_a) (R_N + h) cos(lat)

Alignment of window and target (``alignment``):

- ``'ending'`` (default): the window ends at GNSS epoch ``t_b`` and the target is the increment
  ``t_a -> t_b`` into that epoch. The IMU samples of the increment interval lie inside the window, as in
  Eq. (eq8-1) where Delta P_GPS is the double integral of the IMU output over the interval; the paper's
  "predicts Delta P^{k+1} from the preceding k IMU observations" with the IMU step k+1 being the GNSS epoch.
  It is causal: at a pseudo-GNSS epoch ``t_b`` of an outage the IMU data up to ``t_b`` exist.
- ``'next'``: the window ends at ``t_a`` and the target is ``t_a -> t_b`` (a forecast of the next interval).

Yaw wrap-around (``yaw_encoding``; all keep 9 channels):

- ``'unwrap'`` (default): yaw unwrapped along the window and anchored so that the window's last sample is the
  wrapped value in (-pi, pi]. A window never holds a 2 pi jump; the absolute heading (which the north/east
  target needs) is kept. Two windows at headings just either side of +-pi still differ by about 2 pi.
- ``'relative'``: yaw minus the window's last yaw, wrapped to (-pi, pi]: no jump at all, but the absolute
  heading is lost (only useful with a target in a heading-aligned frame; not the paper's).
- ``'raw'``: the wrapped yaw as given.

Target frame (``target_frame``):

- ``'ned'`` (default, the paper's Eq. eq21 output): the network outputs (dN, dE) directly.
- ``'heading'``: the network outputs the increment in the frame of the window's last INS yaw
  (along-track, cross-track), rotated back to (dN, dE) with that yaw after prediction. Not the paper's; it
  spares every model learning cos/sin of the heading. The reported errors are always in north/east metres.

Training data come only from GPS-available time (:func:`split_windows`): a window whose input span or
target interval touches an evaluation outage widened by ``margin_s`` is dropped; validation is one held-out
block of time (``val_fraction`` of the windows at ``val_position``) and training windows overlapping that block
are dropped too, so no training window shares an IMU sample or GNSS epoch with a validation window.
Normalization statistics (:class:`Normalizer`) come from the training windows only.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Sequence

import numpy as np
import pandas as pd

from bgfn.errors import DataError
from bgfn.nav.earth import curvature_radii

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
#: The 2 outputs: north and east GPS position increment, m.
TARGETS: tuple[str, ...] = ("dn", "de")
#: Extra input channels computed from the INS solution rather than read from it: the horizontal INS velocity
#: in the frame of the sample's own yaw (along-track, cross-track), m/s. Unlike ``v_n, v_e`` they do not
#: change when the vehicle drives the same manoeuvre in another direction.
DERIVED_CHANNELS: tuple[str, ...] = ("v_along", "v_cross")
YAW_ENCODINGS = ("unwrap", "relative", "raw")
TARGET_FRAMES = ("ned", "heading")
ALIGNMENTS = ("ending", "next")
_YAW = CHANNELS.index("yaw")


def wrap_angle(a):
    """Wrap angles to (-pi, pi]."""
    a = np.asarray(a, dtype=float)
    w = np.mod(a + np.pi, 2.0 * np.pi) - np.pi
    return np.where(w == -np.pi, np.pi, w)


def _check_table(df: pd.DataFrame, name: str, columns: Sequence[str]) -> None:
    missing = [c for c in columns if c not in df.columns]
    if missing:
        raise DataError(name, missing[0], f"columns {', '.join(columns)}", f"missing {', '.join(missing)}")
    t = df["time"].to_numpy(float)
    if len(t) < 2 or not np.all(np.diff(t) > 0):
        raise DataError(name, "time", "at least 2 rows with strictly increasing time")


# ----------------------------------------------------------------------------------------------- features
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
    _check_table(attitude, "attitude", ("v_n", "v_e", "yaw"))
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
    _check_table(imu, "imu", ("time", *imu_names))
    attitude = with_derived_channels(attitude, extra_channels)
    _check_table(attitude, "attitude", ("time", *attitude_names, *extra_channels))
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
    """Apply the yaw encoding to windows ``x`` [M, N, C] (yaw wrapped in channel 2), in place; returns ``x``."""
    if yaw_encoding not in YAW_ENCODINGS:
        raise DataError("train", "yaw_encoding", f"one of {YAW_ENCODINGS}", repr(yaw_encoding))
    if yaw_encoding == "raw" or len(x) == 0:
        return x
    yaw = x[..., _YAW].astype(float)                        # [M, N]
    last = yaw[:, -1:]                                      # [M, 1]
    rel = wrap_angle(yaw - last)                            # [M, N] wrapped relative yaw
    if yaw_encoding == "relative":
        x[..., _YAW] = rel
    else:  # 'unwrap': continuous along the window, last sample = wrapped yaw
        rel_unwrapped = np.unwrap(rel, axis=1)
        rel_unwrapped -= rel_unwrapped[:, -1:]
        x[..., _YAW] = rel_unwrapped + last
    return x


# ----------------------------------------------------------------------------------------------- targets
def position_increment(lat_a, lon_a, h_a, lat_b, lon_b, h_b) -> np.ndarray:
    """North/east position change a -> b, m (curvature radii at the mid-latitude, mid-height).

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
    _check_table(gnss, "gnss", ("time", "lat", "lon", "h"))
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
    position jumps at each GNSS update, by the very GNSS error being checked."""
    _check_table(attitude, "attitude", ("time", "v_n", "v_e"))
    t = attitude["time"].to_numpy(float)
    out = np.empty((len(np.atleast_1d(t_from)), 2))
    for k, col in enumerate(("v_n", "v_e")):
        v = attitude[col].to_numpy(float)
        dist = np.concatenate([[0.0], np.cumsum(0.5 * (v[1:] + v[:-1]) * np.diff(t))])
        out[:, k] = np.interp(t_to, t, dist) - np.interp(t_from, t, dist)
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


# ----------------------------------------------------------------------------------------------- windows
@dataclass
class WindowSet:
    """Input windows and their targets.

    Attributes
    ----------
    x : ndarray [M, N, C] float32
        Raw (unnormalized) input windows, yaw encoded.
    y : ndarray [M, 2]
        Target ``delta_p_gps`` (north, east), m; NaN when unknown (outage prediction).
    t_from, t_to : ndarray [M]
        The increment interval, s (GNSS epochs).
    t_end : ndarray [M]
        Time of the window's last IMU sample (<= the epoch it ends at), s.
    t_start : ndarray [M]
        Start of the window's first IMU sample interval (time of the sample before it), s.
    y_last : ndarray [M, 2]
        The GNSS increment of the interval just before ``t_from`` (the "repeat the last increment"
        reference); NaN when that interval is not available.
    yaw_ref : ndarray [M]
        INS yaw at the window's last sample (wrapped), rad: the rotation of ``target_frame='heading'``.
    channels : tuple of str
    n_screened : int
        GNSS increments dropped by :func:`screen_increments` when the set was made (0 for subsets).
    y_ins : ndarray [M, 2] or None
        The distance the GPS-aided INS travelled over the same interval (:func:`ins_increments`; the
        "INS increment" reference: what knowing the velocity is worth, which the inputs of Eq. eq21 do not
        carry); NaN where the attitude table has no velocity, None when not computed.
    """

    x: np.ndarray
    y: np.ndarray
    t_from: np.ndarray
    t_to: np.ndarray
    t_end: np.ndarray
    t_start: np.ndarray
    y_last: np.ndarray
    yaw_ref: np.ndarray
    channels: tuple[str, ...] = CHANNELS
    n_screened: int = 0
    y_ins: np.ndarray | None = None

    def __len__(self) -> int:
        return len(self.x)

    def subset(self, idx) -> "WindowSet":
        """The windows at integer/boolean index ``idx``."""
        return WindowSet(self.x[idx], self.y[idx], self.t_from[idx], self.t_to[idx], self.t_end[idx],
                         self.t_start[idx], self.y_last[idx], self.yaw_ref[idx], self.channels,
                         y_ins=None if self.y_ins is None else self.y_ins[idx])

    @property
    def span(self) -> tuple[np.ndarray, np.ndarray]:
        """Time span ``[lo, hi]`` touched by each window: its inputs and its target interval."""
        return np.minimum(self.t_start, self.t_from), np.maximum(self.t_end, self.t_to)


def _windows_ending_at(t: np.ndarray, feats: np.ndarray, t_ends: np.ndarray, window: int,
                       max_gap_factor: float = 1.5) -> tuple[np.ndarray, np.ndarray]:
    """Indices of the last IMU sample with time <= each ``t_end`` and a validity mask (N samples, no gap, no NaN)."""
    dt_nom = np.median(np.diff(t))
    tol = 1e-6 * dt_nom
    last = np.searchsorted(t, t_ends + tol, side="right") - 1         # [M]
    first = last - window + 1
    ok = first >= 1                                                    # need the sample before (t_start)
    # no time gap inside the window: its span must be (window - 1) nominal periods
    span = np.where(ok, t[np.clip(last, 0, None)] - t[np.clip(first, 0, None)], np.inf)
    ok &= span <= (window - 1) * dt_nom + (max_gap_factor - 1.0) * dt_nom
    # the last sample must be within one period of t_end (IMU present around the epoch)
    ok &= (t_ends - t[np.clip(last, 0, None)]) <= max_gap_factor * dt_nom
    if ok.any():
        bad = np.isnan(feats).any(axis=1).astype(np.int64)
        csum = np.concatenate([[0], np.cumsum(bad)])
        f, l_ = np.clip(first, 0, None), np.clip(last, 0, None)
        ok &= (csum[l_ + 1] - csum[f]) == 0
    return last, ok


def _gather(feats: np.ndarray, last: np.ndarray, window: int) -> np.ndarray:
    idx = last[:, None] - window + 1 + np.arange(window)[None, :]       # [M, N]
    return feats[idx].astype(np.float32)                                # [M, N, C]


def make_windows(imu: pd.DataFrame, attitude: pd.DataFrame, gnss: pd.DataFrame, window: int = 200,
                 alignment: str = "ending", yaw_encoding: str = "unwrap", extra_channels: Sequence[str] = (),
                 epoch_stride: int = 1, target_screen_sigma: float | None = None) -> WindowSet:
    """All windows of a drive with their GNSS increment targets (before any outage/validation split).

    Parameters
    ----------
    imu, attitude, gnss : DataFrame
        See :func:`sample_features` and :func:`gnss_increments`.
    window : int
        N, IMU samples per window (paper: 200 at 100 Hz).
    alignment : {'ending', 'next'}
        Window ending at the increment's end epoch, or at its start epoch (module docstring).
    yaw_encoding : {'unwrap', 'relative', 'raw'}
        See :func:`encode_yaw`.
    extra_channels : sequence of str
        Extra ``attitude`` columns (not the paper's input).
    epoch_stride : int
        Keep every ``epoch_stride``-th increment (fewer, less overlapping windows for small budgets).
    target_screen_sigma : float or None
        Drop every window whose target, or the previous increment (the "last increment" reference), is
        flagged by :func:`screen_increments` against the INS velocity of ``attitude`` (``v_n``, ``v_e``
        needed); None: keep all.

    Returns
    -------
    WindowSet
        Windows sorted by time.
    """
    if alignment not in ALIGNMENTS:
        raise DataError("train", "alignment", f"one of {ALIGNMENTS}", repr(alignment))
    if window < 1:
        raise DataError("train", "window", "a positive number of IMU samples", repr(window))
    t, feats, channels = sample_features(imu, attitude, extra_channels)
    inc = gnss_increments(gnss)
    t_from, t_to = inc["t_from"].to_numpy(), inc["t_to"].to_numpy()
    y = inc[["dn", "de"]].to_numpy(float)
    # previous increment (contiguous: its end is this one's start)
    y_last = np.full_like(y, np.nan)
    contiguous = np.isclose(t_to[:-1], t_from[1:], rtol=0.0, atol=1e-9)
    y_last[1:][contiguous] = y[:-1][contiguous]
    # the INS increment (a reference; the screening needs it, and ins_increments names a missing velocity)
    has_velocity = {"v_n", "v_e"} <= set(attitude.columns)
    y_ins = (ins_increments(attitude, t_from, t_to) if has_velocity or target_screen_sigma
             else np.full_like(y, np.nan))
    bad = np.zeros(len(y), bool)
    if target_screen_sigma:
        flagged = screen_increments(y - y_ins, target_screen_sigma)
        bad = flagged.copy()
        bad[1:] |= flagged[:-1] & contiguous
    keep = (np.arange(len(y)) % max(1, int(epoch_stride)) == 0) & ~bad
    t_from, t_to, y, y_last, y_ins = t_from[keep], t_to[keep], y[keep], y_last[keep], y_ins[keep]
    t_end_epoch = t_to if alignment == "ending" else t_from
    last, ok = _windows_ending_at(t, feats, t_end_epoch, window)
    last, t_from, t_to, y, y_last, y_ins = last[ok], t_from[ok], t_to[ok], y[ok], y_last[ok], y_ins[ok]
    yaw_ref = feats[last, _YAW]
    x = encode_yaw(_gather(feats, last, window), yaw_encoding)
    return WindowSet(x=x, y=y, t_from=t_from, t_to=t_to, t_end=t[last], t_start=t[last - window],
                     y_last=y_last, yaw_ref=yaw_ref, channels=channels, n_screened=int(bad.sum()), y_ins=y_ins)


def prediction_windows(imu: pd.DataFrame, attitude: pd.DataFrame, epochs, window: int = 200,
                       alignment: str = "ending", yaw_encoding: str = "unwrap",
                       extra_channels: Sequence[str] = ()) -> WindowSet:
    """Input windows for the pseudo-GNSS epochs of an outage (Eq. pred-gps), targets unknown (NaN).

    Parameters
    ----------
    imu, attitude : DataFrame
        As in :func:`make_windows`; ``attitude`` is the INS solution available during the outage.
    epochs : array_like [K + 1]
        ``t_0`` (last GNSS epoch before the outage, where ``P_GPS_0`` is known) followed by the K pseudo-GNSS
        epochs. Window ``i`` predicts the increment ``epochs[i] -> epochs[i + 1]``; it ends at
        ``epochs[i + 1]`` (``'ending'``) or ``epochs[i]`` (``'next'``).

    Returns
    -------
    WindowSet
        K windows (``y`` and ``y_last`` NaN). Raises DataError if the IMU does not cover a window.
    """
    epochs = np.asarray(epochs, dtype=float)
    if epochs.ndim != 1 or len(epochs) < 2 or not np.all(np.diff(epochs) > 0):
        raise DataError("outage", "epochs", "at least 2 strictly increasing epoch times")
    t, feats, channels = sample_features(imu, attitude, extra_channels)
    t_from, t_to = epochs[:-1], epochs[1:]
    last, ok = _windows_ending_at(t, feats, t_to if alignment == "ending" else t_from, window)
    if not ok.all():
        bad = (t_to if alignment == "ending" else t_from)[~ok][0]
        raise DataError("imu/attitude", "time", f"{window} gap-free IMU samples with attitude before each "
                        "pseudo-GNSS epoch", f"none ending at t = {bad:.3f} s")
    yaw_ref = feats[last, _YAW]
    x = encode_yaw(_gather(feats, last, window), yaw_encoding)
    nan = np.full((len(t_from), 2), np.nan)
    return WindowSet(x=x, y=nan, t_from=t_from, t_to=t_to, t_end=t[last], t_start=t[last - window],
                     y_last=nan.copy(), yaw_ref=yaw_ref, channels=channels)


# ----------------------------------------------------------------------------------------------- split
def forbidden_intervals(outage_windows, margin_s: float) -> np.ndarray:
    """``[start - margin, start + duration + margin]`` per outage, shape [K, 2]."""
    ow = np.asarray(list(outage_windows), dtype=float).reshape(-1, 2)
    if np.any(ow[:, 1] < 0) or margin_s < 0:
        raise DataError("train", "outage_windows/margin_s", "non-negative durations and margin")
    return np.column_stack([ow[:, 0] - margin_s, ow[:, 0] + ow[:, 1] + margin_s])


def overlaps(lo: np.ndarray, hi: np.ndarray, intervals: np.ndarray) -> np.ndarray:
    """Boolean [M]: span ``[lo, hi]`` of each window intersects any of ``intervals`` [K, 2] (closed)."""
    if len(intervals) == 0:
        return np.zeros(len(lo), dtype=bool)
    return ((lo[:, None] <= intervals[None, :, 1]) & (intervals[None, :, 0] <= hi[:, None])).any(axis=1)


def split_windows(ws: WindowSet, outage_windows=(), margin_s: float = 30.0, val_fraction: float = 0.2,
                  val_position="end") -> tuple[np.ndarray, np.ndarray, dict]:
    """Training and validation window indices from GPS-available time only.

    Parameters
    ----------
    ws : WindowSet
        From :func:`make_windows` (sorted by time).
    outage_windows : sequence of (start, duration)
        Evaluation outages, s (GPS time); windows touching ``[start - margin_s, start + duration + margin_s]``
        are excluded from both sets.
    margin_s : float
        Margin around each outage, s.
    val_fraction : float
        Fraction (0 < f < 1) of the remaining windows held out for validation, as one block of time.
    val_position : {'end', 'start', 'middle'} or float
        Where the block lies: a float p in [0, 1] puts it at fraction p of the remaining windows.

    Returns
    -------
    train_idx, val_idx : ndarray of int
    info : dict
        ``forbidden`` intervals, ``val_block`` ``[lo, hi]`` (s), counts of dropped windows.
    """
    if not 0.0 < val_fraction < 1.0:
        raise DataError("train", "val_fraction", "a fraction in (0, 1)", repr(val_fraction))
    pos = {"start": 0.0, "middle": 0.5, "end": 1.0}.get(val_position, val_position)
    if not isinstance(pos, (int, float)) or not 0.0 <= float(pos) <= 1.0:
        raise DataError("train", "val_position", "'start', 'middle', 'end' or a number in [0, 1]",
                        repr(val_position))
    lo, hi = ws.span
    forb = forbidden_intervals(outage_windows, margin_s)
    allowed = np.flatnonzero(~overlaps(lo, hi, forb))
    if len(allowed) < 2:
        raise DataError("train", "outage_windows", "GPS-available windows outside the outages", f"{len(allowed)}")
    n_val = max(1, int(round(val_fraction * len(allowed))))
    s = int(round(float(pos) * (len(allowed) - n_val)))
    val_idx = allowed[s:s + n_val]
    block = np.array([[lo[val_idx].min(), hi[val_idx].max()]])
    rest = np.setdiff1d(allowed, val_idx)
    train_idx = rest[~overlaps(lo[rest], hi[rest], block)]
    info = {"forbidden": forb.tolist(), "val_block": block[0].tolist(), "n_windows": int(len(ws)),
            "n_outage_excluded": int(len(ws) - len(allowed)), "n_purged": int(len(rest) - len(train_idx)),
            "n_train": int(len(train_idx)), "n_val": int(len(val_idx))}
    return train_idx, val_idx, info


# ----------------------------------------------------------------------------------------------- target frame
def to_target_frame(y: np.ndarray, yaw_ref: np.ndarray, target_frame: str) -> np.ndarray:
    """(dN, dE) [M, 2] -> the model's target frame: unchanged (``'ned'``) or rotated by -yaw (``'heading'``)."""
    if target_frame not in TARGET_FRAMES:
        raise DataError("train", "target_frame", f"one of {TARGET_FRAMES}", repr(target_frame))
    y = np.asarray(y, dtype=float)
    if target_frame == "ned":
        return y.copy()
    c, s = np.cos(yaw_ref), np.sin(yaw_ref)
    return np.column_stack([c * y[:, 0] + s * y[:, 1], -s * y[:, 0] + c * y[:, 1]])   # along, cross


def from_target_frame(z: np.ndarray, yaw_ref: np.ndarray, target_frame: str) -> np.ndarray:
    """Inverse of :func:`to_target_frame`: model-frame increments [M, 2] -> (dN, dE), m."""
    if target_frame not in TARGET_FRAMES:
        raise DataError("train", "target_frame", f"one of {TARGET_FRAMES}", repr(target_frame))
    z = np.asarray(z, dtype=float)
    if target_frame == "ned":
        return z.copy()
    c, s = np.cos(yaw_ref), np.sin(yaw_ref)
    return np.column_stack([c * z[:, 0] - s * z[:, 1], s * z[:, 0] + c * z[:, 1]])


# ----------------------------------------------------------------------------------------------- normalization
@dataclass
class Normalizer:
    """Per-channel input and per-component target standardization, fitted on training windows only."""

    x_mean: np.ndarray
    x_std: np.ndarray
    y_mean: np.ndarray
    y_std: np.ndarray

    @classmethod
    def fit(cls, ws: WindowSet, target_frame: str = "ned", eps: float = 1e-8) -> "Normalizer":
        """Statistics of all samples of the (training) windows ``ws`` (targets in ``target_frame``)."""
        if len(ws) == 0:
            raise DataError("train", "windows", "at least one training window")
        x = ws.x.reshape(-1, ws.x.shape[-1]).astype(np.float64)
        y = to_target_frame(ws.y, ws.yaw_ref, target_frame)
        return cls(x.mean(0), np.maximum(x.std(0), eps), y.mean(0), np.maximum(y.std(0), eps))

    def x(self, x: np.ndarray) -> np.ndarray:
        """Normalized inputs, float32."""
        return ((x - self.x_mean) / self.x_std).astype(np.float32)

    def y(self, y: np.ndarray) -> np.ndarray:
        """Normalized targets, float32."""
        return ((y - self.y_mean) / self.y_std).astype(np.float32)

    def y_inverse(self, yn: np.ndarray) -> np.ndarray:
        """Targets in metres from normalized model outputs."""
        return np.asarray(yn, dtype=np.float64) * self.y_std + self.y_mean

    def to_dict(self) -> dict:
        return {k: np.asarray(getattr(self, k)).tolist() for k in ("x_mean", "x_std", "y_mean", "y_std")}

    @classmethod
    def from_dict(cls, d: dict) -> "Normalizer":
        return cls(*(np.asarray(d[k], dtype=np.float64) for k in ("x_mean", "x_std", "y_mean", "y_std")))


# ----------------------------------------------------------------------------------------------- all together
#: Defaults of the learning-problem keys of a profile's ``train:`` section.
LEARNING_DEFAULTS = {"window": 200, "alignment": "ending", "yaw_encoding": "unwrap", "target_frame": "ned",
                     "extra_channels": [], "epoch_stride": 1, "margin_s": 30.0, "val_fraction": 0.2,
                     "val_position": "middle", "target_screen_sigma": None}

#: Validation-block positions compared by :func:`val_position_coverage` (notebook 03).
VAL_POSITIONS = ("start", 0.25, "middle", 0.75, "end")


@dataclass
class LearningData:
    """Training and validation windows of one drive, with the training-set normalization."""

    train: WindowSet
    val: WindowSet
    norm: Normalizer
    info: dict = field(default_factory=dict)
    options: dict = field(default_factory=dict)


def learning_options(cfg: dict | None) -> dict:
    """The learning-problem keys of a ``train:`` section, with defaults filled in."""
    cfg = cfg or {}
    return {k: cfg.get(k, v) for k, v in LEARNING_DEFAULTS.items()}


def all_windows(imu: pd.DataFrame, attitude: pd.DataFrame, gnss: pd.DataFrame, **options) -> WindowSet:
    """Every window of the drive with the learning options ``options`` (split not applied)."""
    opt = learning_options(options)
    return make_windows(imu, attitude, gnss, window=int(opt["window"]), alignment=opt["alignment"],
                        yaw_encoding=opt["yaw_encoding"], extra_channels=tuple(opt["extra_channels"]),
                        epoch_stride=int(opt["epoch_stride"]), target_screen_sigma=opt["target_screen_sigma"])


def build_learning_data(imu: pd.DataFrame, attitude: pd.DataFrame, gnss: pd.DataFrame, outage_windows=(),
                        **options) -> LearningData:
    """Windows, split and normalization in one call.

    Parameters
    ----------
    imu, attitude, gnss : DataFrame
        Drive tables (CONTRIBUTING.md schemas; ``attitude`` = INS/KF solution with ``time, roll, pitch, yaw``).
    outage_windows : sequence of (start, duration)
        Evaluation outages (s) excluded from training and validation.
    **options
        ``window``, ``alignment``, ``yaw_encoding``, ``target_frame``, ``extra_channels``, ``epoch_stride``,
        ``margin_s``, ``val_fraction``, ``val_position``, ``target_screen_sigma`` (defaults:
        :data:`LEARNING_DEFAULTS`).
    """
    unknown = set(options) - set(LEARNING_DEFAULTS)
    if unknown:
        raise DataError("train", sorted(unknown)[0], f"one of {', '.join(LEARNING_DEFAULTS)}")
    opt = learning_options(options)
    ws = all_windows(imu, attitude, gnss, **opt)
    tr, va, info = split_windows(ws, outage_windows, margin_s=float(opt["margin_s"]),
                                 val_fraction=float(opt["val_fraction"]), val_position=opt["val_position"])
    train, val = ws.subset(tr), ws.subset(va)
    info["outage_windows"] = [list(map(float, o)) for o in outage_windows]
    info["n_screened"] = int(ws.n_screened)
    if opt["target_frame"] not in TARGET_FRAMES:
        raise DataError("train", "target_frame", f"one of {TARGET_FRAMES}", repr(opt["target_frame"]))
    return LearningData(train=train, val=val, norm=Normalizer.fit(train, opt["target_frame"]), info=info,
                        options=opt)


def inner_split(data: LearningData, fraction: float = 0.2, position=None) -> LearningData:
    """A tuning split inside the training windows: a ``fraction`` of ``data.train`` (one block of time, at
    ``position``; default: the ``val_position`` of ``data.options``, as the validation block) becomes the
    validation set, training windows overlapping it are dropped, and the normalization is refit.

    Hyper-parameters chosen on it never see ``data.val``, the block every reported validation error comes from.
    """
    if position is None:
        position = data.options.get("val_position", LEARNING_DEFAULTS["val_position"])
    tr, va, info = split_windows(data.train, (), margin_s=0.0, val_fraction=fraction, val_position=position)
    train, val = data.train.subset(tr), data.train.subset(va)
    frame = data.options.get("target_frame", "ned")
    return LearningData(train=train, val=val, norm=Normalizer.fit(train, frame),
                        info={**info, "inner_of": data.info.get("val_block")}, options=dict(data.options))


def motion_of_windows(ws: WindowSet) -> pd.DataFrame:
    """Heading (INS yaw at the window end, deg in [0, 360)) and mean speed over the target interval
    (|delta_p_gps| / interval, m/s) of every window: the two quantities the increment depends on most."""
    dt = np.maximum(ws.t_to - ws.t_from, 1e-9)
    return pd.DataFrame({"heading_deg": np.degrees(ws.yaw_ref) % 360.0,
                         "speed_mps": np.hypot(ws.y[:, 0], ws.y[:, 1]) / dt})


def motion_in_windows(reference: pd.DataFrame, windows, step_s: float = 1.0) -> pd.DataFrame:
    """Heading (deg) and horizontal speed (m/s) of the ``reference`` every ``step_s`` inside ``windows``
    ((start, duration) pairs, s): what the networks meet in the evaluation outages."""
    t = reference["time"].to_numpy(float)
    rows = []
    for start, duration in windows:
        ts = np.arange(float(start), float(start) + float(duration), step_s)
        yaw = np.interp(ts, t, np.unwrap(reference["yaw"].to_numpy(float)))
        v = np.interp(ts, t, np.hypot(reference["v_n"].to_numpy(float), reference["v_e"].to_numpy(float)))
        rows.append(pd.DataFrame({"heading_deg": np.degrees(yaw) % 360.0, "speed_mps": v}))
    return pd.concat(rows, ignore_index=True) if rows else pd.DataFrame(columns=["heading_deg", "speed_mps"])


def unseen_fraction(train: pd.DataFrame, other: pd.DataFrame, heading_bin_deg: float = 30.0,
                    speed_bin_mps: float = 2.0) -> float:
    """Fraction of the rows of ``other`` whose (heading, speed) cell holds no training row (cells of
    ``heading_bin_deg`` x ``speed_bin_mps``): how much of it a network must extrapolate to."""
    if len(other) == 0:
        return float("nan")

    def cells(df):
        return set(zip((df["heading_deg"].to_numpy() // heading_bin_deg).astype(int),
                       (df["speed_mps"].to_numpy() // speed_bin_mps).astype(int)))
    seen = cells(train)
    hit = [c in seen for c in zip((other["heading_deg"].to_numpy() // heading_bin_deg).astype(int),
                                  (other["speed_mps"].to_numpy() // speed_bin_mps).astype(int))]
    return 1.0 - float(np.mean(hit))


def val_position_coverage(ws: WindowSet, outage_motion: pd.DataFrame, outage_windows=(), margin_s: float = 30.0,
                          val_fraction: float = 0.2, positions=VAL_POSITIONS, **cells) -> pd.DataFrame:
    """What each position of the validation block leaves to training.

    The paper does not say how it validated. One block of time is held out (:func:`split_windows`); where it
    lies decides which motions training sees. Computed from windows and the reference only, before any network
    is trained, so the choice of ``train.val_position`` cannot follow a network's score.

    Parameters
    ----------
    ws : WindowSet
        Every window of the drive (:func:`make_windows`).
    outage_motion : DataFrame
        Heading and speed inside the evaluation outages (:func:`motion_in_windows`).
    outage_windows, margin_s, val_fraction
        As for :func:`split_windows`.
    positions : sequence
        ``val_position`` values to compare.
    **cells
        ``heading_bin_deg``, ``speed_bin_mps`` of :func:`unseen_fraction`.

    Returns
    -------
    DataFrame
        One row per position: ``val_position``, ``val_block_s``, ``train``, ``val``, ``val_unseen_fraction``,
        ``outage_unseen_fraction`` (fractions of validation windows / outage seconds whose heading x speed
        cell holds no training window), ``train_speed_max_mps`` and the references of
        :func:`reference_rmse` on that block (``val_rmse_zero_m``, ``val_rmse_last_m``, ``val_rmse_ins_m``).
    """
    rows = []
    for pos in positions:
        tr, va, info = split_windows(ws, outage_windows, margin_s=margin_s, val_fraction=val_fraction,
                                     val_position=pos)
        train, val = motion_of_windows(ws.subset(tr)), motion_of_windows(ws.subset(va))
        refs = reference_rmse(ws.subset(va))
        rows.append({"val_position": str(pos),
                     "val_block_s": f"{info['val_block'][0]:.1f}..{info['val_block'][1]:.1f}",
                     "train": int(len(tr)), "val": int(len(va)),
                     "val_unseen_fraction": unseen_fraction(train, val, **cells),
                     "outage_unseen_fraction": unseen_fraction(train, outage_motion, **cells),
                     "train_speed_max_mps": float(train["speed_mps"].max()) if len(train) else float("nan"),
                     **reference_columns(refs)})
    return pd.DataFrame(rows)


def rmse(pred: np.ndarray, true: np.ndarray) -> float:
    """Root mean square of the horizontal error ``sqrt(mean(dN^2 + dE^2))``, m, over rows without NaN."""
    pred, true = np.asarray(pred, float), np.asarray(true, float)
    ok = ~(np.isnan(pred).any(axis=1) | np.isnan(true).any(axis=1))
    if not ok.any():
        return float("nan")
    return float(np.sqrt(np.mean(np.sum((pred[ok] - true[ok]) ** 2, axis=1))))


#: The references every network's validation RMSE is read against, and their column names in cards and tables.
REFERENCES: dict[str, str] = {"zero": "val_rmse_zero_m", "last": "val_rmse_last_m", "ins": "val_rmse_ins_m"}


def reference_rmse(ws: WindowSet) -> dict:
    """RMSE (m) of three predictors that need no training, on the windows ``ws``.

    - ``zero``: no motion;
    - ``last``: the GNSS increment of the interval before (uses GNSS, which the networks do not see);
    - ``ins``: the GPS-aided INS's own distance over the same interval (``ws.y_ins``; its velocity, which the
      inputs of Eq. eq21 do not carry, corrected by every fix up to the one closing the interval). NaN when
      ``ws`` has no ``y_ins``.

    A network that only sees attitude, specific force and angular rate cannot know the speed, the main part of
    an increment; ``ins`` shows how far the GNSS increment can be predicted when the speed is known.
    """
    ins = ws.y_ins if ws.y_ins is not None else np.full_like(ws.y, np.nan)
    return {"zero": rmse(np.zeros_like(ws.y), ws.y), "last": rmse(ws.y_last, ws.y), "ins": rmse(ins, ws.y)}


def reference_columns(refs: dict) -> dict:
    """:func:`reference_rmse` keyed by the column names of :data:`REFERENCES`."""
    return {col: refs[key] for key, col in REFERENCES.items()}


# ----------------------------------------------------------------------------------------------- toy drive
def synthetic_tables(duration_s: float = 120.0, imu_rate_hz: float = 100.0, gnss_rate_hz: float = 1.0,
                     t0: float = 1000.0, speed_mps: float = 10.0, radius_m: float = 150.0, noise: float = 0.0,
                     seed: int = 0, lat0: float = 0.7885, lon0: float = 0.1338, h0: float = 250.0):
    """A toy drive on a level circle (for tests and examples; not a navigation-grade simulation).

    The vehicle drives clockwise seen from above (yaw increasing through +-pi) with speed
    ``speed_mps * (1 + 0.3 sin(2 pi t / 60))``; the IMU reads the along-track and centripetal acceleration,
    ``accel_z = -9.81`` and the yaw rate; the attitude is level with the true heading and carries the true
    velocity (as the INS solution does); the GNSS positions are exact. Returns ``(imu, attitude, gnss)``
    DataFrames in the CONTRIBUTING.md schemas (attitude: ``time, roll, pitch, yaw, v_n, v_e``).
    """
    rng = np.random.default_rng(seed)
    n = int(round(duration_s * imu_rate_hz)) + 1
    t = t0 + np.arange(n) / imu_rate_hz
    tau = t - t0
    w = 2.0 * np.pi / 60.0
    v = speed_mps * (1.0 + 0.3 * np.sin(w * tau))
    dist = speed_mps * (tau - 0.3 / w * (np.cos(w * tau) - 1.0))        # integral of v
    psi = dist / radius_m                                                # heading, rad (unwrapped)
    acc_x = speed_mps * 0.3 * w * np.cos(w * tau)
    acc_y = v ** 2 / radius_m
    gyr_z = v / radius_m
    imu = pd.DataFrame({"time": t,
                        "gyro_x": rng.normal(0, noise * 0.01, n), "gyro_y": rng.normal(0, noise * 0.01, n),
                        "gyro_z": gyr_z + rng.normal(0, noise * 0.01, n),
                        "accel_x": acc_x + rng.normal(0, noise, n), "accel_y": acc_y + rng.normal(0, noise, n),
                        "accel_z": -9.81 + rng.normal(0, noise, n)})
    att = pd.DataFrame({"time": t, "roll": np.zeros(n), "pitch": np.zeros(n), "yaw": wrap_angle(psi),
                        "v_n": v * np.cos(psi), "v_e": v * np.sin(psi)})
    # circle: position from heading; centre so that start is at (0, 0)
    north = radius_m * np.sin(psi)
    east = radius_m * (1.0 - np.cos(psi))
    r_m, r_n = curvature_radii(lat0)
    step = int(round(imu_rate_hz / gnss_rate_hz))
    g = slice(0, n, step)
    lat = lat0 + north[g] / (r_m + h0)
    lon = lon0 + east[g] / ((r_n + h0) * np.cos(lat0))
    m = len(lat)
    gnss = pd.DataFrame({"time": t[g], "lat": lat, "lon": lon, "h": np.full(m, h0),
                         "v_n": (v * np.cos(psi))[g], "v_e": (v * np.sin(psi))[g], "v_d": np.zeros(m),
                         "std_n": np.full(m, 0.5), "std_e": np.full(m, 0.5), "std_d": np.full(m, 1.0)})
    return imu, att, gnss

"""Input windows and their delta_p_gps targets: :class:`WindowSet`, the windows of a whole drive
(:func:`make_windows`) and the windows of an outage's pseudo-GNSS epochs (:func:`prediction_windows`, Eq. pred-gps).

A window holds the ``N`` (paper: 200) most recent IMU samples at 100 Hz before the epoch it ends at (``time <=
t_end``). Alignment of window and target (``alignment``): ``'ending'`` (default) ends the window at the
increment's end epoch, ``'next'`` at its start epoch (the package docstring of :mod:`bgfn.learning`).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Sequence

import numpy as np
import pandas as pd

from bgfn.errors import DataError
from bgfn.learning.inputs import CHANNELS, YAW_CHANNEL, encode_yaw, sample_features
from bgfn.learning.targets import gnss_increments, ins_increments, screen_increments

#: ``train.alignment`` values: the window ends at the increment's end epoch, or at its start epoch.
ALIGNMENTS = ("ending", "next")


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


def windows_ending_at(t: np.ndarray, feats: np.ndarray, t_ends: np.ndarray, window: int,
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


def gather_windows(feats: np.ndarray, last: np.ndarray, window: int) -> np.ndarray:
    """The ``window`` samples of ``feats`` [n, C] ending at each row index ``last`` [M]: [M, N, C] float32."""
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
    last, ok = windows_ending_at(t, feats, t_end_epoch, window)
    last, t_from, t_to, y, y_last, y_ins = last[ok], t_from[ok], t_to[ok], y[ok], y_last[ok], y_ins[ok]
    yaw_ref = feats[last, YAW_CHANNEL]
    x = encode_yaw(gather_windows(feats, last, window), yaw_encoding)
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
    last, ok = windows_ending_at(t, feats, t_to if alignment == "ending" else t_from, window)
    if not ok.all():
        bad = (t_to if alignment == "ending" else t_from)[~ok][0]
        raise DataError("imu/attitude", "time", f"{window} gap-free IMU samples with attitude before each "
                        "pseudo-GNSS epoch", f"none ending at t = {bad:.3f} s")
    yaw_ref = feats[last, YAW_CHANNEL]
    x = encode_yaw(gather_windows(feats, last, window), yaw_encoding)
    nan = np.full((len(t_from), 2), np.nan)
    return WindowSet(x=x, y=nan, t_from=t_from, t_to=t_to, t_end=t[last], t_start=t[last - window],
                     y_last=nan.copy(), yaw_ref=yaw_ref, channels=channels)

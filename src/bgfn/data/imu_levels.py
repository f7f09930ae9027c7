"""IMU error levels measured on a drive's own data: at rest (noise, bias) and while driving (noise + vibration).

A recorded drive's reference tells when the vehicle stands and when it drives; the IMU rows of each state give:

- *at rest* (reference speed, averaged over ``smooth_s``, below ``rest_speed_mps`` for at least ``min_rest_s``,
  ``trim_s`` cut from both ends of each span): the std of each channel (white noise plus the idling engine's
  vibration), the equivalent noise density ``std * sqrt(dt)`` (rad/sqrt(s), m/s/sqrt(s); exact for white noise
  sampled at ``1 / dt``), and the mean gyro reading per rest span = the gyro bias (the Earth rate, below
  7.3e-5 rad/s, is not removed: the attitude is unknown) and the mean |specific force| (m/s^2, to compare with
  normal gravity: the accelerometers' scale and bias along gravity);
- *while driving* (speed above ``drive_speed_mps``): the std of each channel high-passed above ``highpass_hz``
  (4th-order Butterworth, zero phase), where a car's own motion has little power: noise plus vibration.

These levels feed an IMU error model of the same class (:mod:`bgfn.data.imu_errors`); nothing here is fitted
to the paper.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy import signal

from bgfn.errors import DataError
from bgfn.schema import ACCEL_COLUMNS, GYRO_COLUMNS

#: Rest: speed below this (m/s, averaged over SMOOTH_S) ...
REST_SPEED_MPS = 0.1
#: ... for at least this long, s; TRIM_S cut from both ends of each span (starting and stopping).
MIN_REST_S, TRIM_S, SMOOTH_S = 2.0, 0.5, 1.0
#: Driving: speed above this, m/s.
DRIVE_SPEED_MPS = 3.0
#: High-pass corner for the driving levels, Hz (a car's attitude and speed change below it).
HIGHPASS_HZ = 5.0


def _speed_at(imu_time: np.ndarray, reference: pd.DataFrame, smooth_s: float) -> np.ndarray:
    t = reference["time"].to_numpy(float)
    speed = np.hypot(reference["v_n"].to_numpy(float), reference["v_e"].to_numpy(float))
    n = max(1, int(round(smooth_s / float(np.median(np.diff(t))))))
    smooth = np.convolve(speed, np.ones(n) / n, mode="same")     # moving average over smooth_s
    return np.interp(imu_time, t, smooth)


def rest_spans(imu: pd.DataFrame, reference: pd.DataFrame, *, rest_speed_mps: float = REST_SPEED_MPS,
               min_rest_s: float = MIN_REST_S, trim_s: float = TRIM_S,
               smooth_s: float = SMOOTH_S) -> list[tuple[int, int]]:
    """IMU row ranges ``[i0, i1)`` where the vehicle stands (module docstring).

    Returns
    -------
    list of (int, int)
        Row ranges of ``imu``, trimmed, each at least ``min_rest_s - 2 trim_s`` long.
    """
    t = imu["time"].to_numpy(float)
    still = _speed_at(t, reference, smooth_s) < rest_speed_mps
    edges = np.flatnonzero(np.diff(np.concatenate([[0], still.astype(np.int8), [0]])))
    dt = float(np.median(np.diff(t)))
    trim = int(round(trim_s / dt))
    out = []
    for i0, i1 in zip(edges[::2], edges[1::2]):
        if t[i1 - 1] - t[i0] >= min_rest_s:
            out.append((int(i0 + trim), int(i1 - trim)))
    return out


def imu_levels(imu: pd.DataFrame, reference: pd.DataFrame, *, rest_speed_mps: float = REST_SPEED_MPS,
               min_rest_s: float = MIN_REST_S, trim_s: float = TRIM_S, smooth_s: float = SMOOTH_S,
               drive_speed_mps: float = DRIVE_SPEED_MPS, highpass_hz: float = HIGHPASS_HZ,
               source: str = "drive") -> dict:
    """Noise levels of an IMU at rest and while driving (module docstring).

    Parameters
    ----------
    imu : DataFrame
        IMU schema on a regular grid.
    reference : DataFrame
        Reference schema (``time``, ``v_n``, ``v_e`` are used).
    source : str
        Named in errors.

    Returns
    -------
    dict
        ``rest``: ``spans_s`` ([[t0, t1], ...]), ``duration_s``, ``gyro_std`` (rad/s), ``accel_std`` (m/s^2),
        ``gyro_noise_density`` (rad/sqrt(s)), ``accel_noise_density`` (m/s/sqrt(s)), ``gyro_bias`` (rad/s, one
        list of 3 per span), ``f_norm_mean`` (m/s^2, per span); ``driving``: ``duration_s``, ``highpass_hz``,
        ``gyro_std``, ``accel_std`` (high-passed); ``ratio_gyro``, ``ratio_accel`` (driving / rest std).
        Per-axis values are lists of 3 (x, y, z, body frame).

    Raises
    ------
    DataError
        No rest span, too little driving, or a high-pass corner above the Nyquist frequency.
    """
    t = imu["time"].to_numpy(float)
    dt = float(np.median(np.diff(t)))
    gyro = imu[list(GYRO_COLUMNS)].to_numpy(float)     # [K, 3] rad/s
    accel = imu[list(ACCEL_COLUMNS)].to_numpy(float)   # [K, 3] m/s^2
    spans = rest_spans(imu, reference, rest_speed_mps=rest_speed_mps, min_rest_s=min_rest_s, trim_s=trim_s,
                       smooth_s=smooth_s)
    if not spans:
        raise DataError(source, "reference", f"a rest of at least {min_rest_s:g} s (speed below "
                        f"{rest_speed_mps:g} m/s)", "none")
    # noise: deviations from each span's own mean (a bias differs between spans)
    dev_g = np.concatenate([gyro[a:b] - gyro[a:b].mean(axis=0) for a, b in spans])
    dev_a = np.concatenate([accel[a:b] - accel[a:b].mean(axis=0) for a, b in spans])
    g_std, a_std = dev_g.std(axis=0), dev_a.std(axis=0)
    rest = {"spans_s": [[float(t[a]), float(t[b - 1])] for a, b in spans],
            "duration_s": float(sum(b - a for a, b in spans) * dt),
            "gyro_std": g_std.tolist(), "accel_std": a_std.tolist(),
            "gyro_noise_density": (g_std * np.sqrt(dt)).tolist(),
            "accel_noise_density": (a_std * np.sqrt(dt)).tolist(),
            "gyro_bias": [gyro[a:b].mean(axis=0).tolist() for a, b in spans],
            "f_norm_mean": [float(np.linalg.norm(accel[a:b], axis=1).mean()) for a, b in spans]}
    nyquist = 0.5 / dt
    if not 0.0 < highpass_hz < nyquist:
        raise DataError(source, "highpass_hz", f"a corner inside (0, {nyquist:g}) Hz", f"{highpass_hz:g}")
    driving = _speed_at(t, reference, smooth_s) > drive_speed_mps
    if driving.sum() * dt < 10.0:
        raise DataError(source, "reference", f"at least 10 s of driving above {drive_speed_mps:g} m/s",
                        f"{driving.sum() * dt:.3g} s")
    sos = signal.butter(4, highpass_hz, btype="highpass", fs=1.0 / dt, output="sos")
    hp_g = signal.sosfiltfilt(sos, gyro, axis=0)[driving]
    hp_a = signal.sosfiltfilt(sos, accel, axis=0)[driving]
    drive = {"duration_s": float(driving.sum() * dt), "highpass_hz": float(highpass_hz),
             "gyro_std": hp_g.std(axis=0).tolist(), "accel_std": hp_a.std(axis=0).tolist()}
    return {"rest": rest, "driving": drive,
            "ratio_gyro": (hp_g.std(axis=0) / g_std).tolist(), "ratio_accel": (hp_a.std(axis=0) / a_std).tolist()}

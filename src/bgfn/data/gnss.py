"""GNSS fixes: decimation of real fixes, and a u-blox-like receiver simulated from the truth.

The simulated receiver gives positions only (the paper's KF measurement, Eq. 13): the antenna position
``p_ant = p_imu + C_bn @ lever_arm`` sampled at ``rate_hz`` and corrupted per axis by a first-order Gauss-Markov
error (``correlated_std_m``, ``correlated_tau_s``: multipath, atmosphere, ephemeris) and a white error
(``white_std_m``); the reported stds are their root sum of squares. :func:`degrade_fixes` applies the same errors
to given fixes (an RTK solution made into a consumer receiver's, ``rtklib-drive0708``). Without a reference
attitude the antenna is placed with a level body along the course over ground (:func:`body_to_nav`).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from bgfn.data.imu_errors import gauss_markov
from bgfn.errors import DataError
from bgfn.nav.earth import curvature_radii
from bgfn.nav.metrics import reference_rows
from bgfn.nav.transform import dcm_from_euler
from bgfn.schema import ATTITUDE_COLUMNS, GNSS_COLUMNS

#: Default u-blox-like (NEO-M8/M9 class, open sky, no SBAS) receiver errors, m (north, east, down).
UBLOX_DEFAULTS = {
    "rate_hz": 1.0,
    "white_std_m": [0.3, 0.3, 0.6],
    "correlated_std_m": [1.0, 1.0, 2.0],
    "correlated_tau_s": 60.0,
}


def decimate(gnss: pd.DataFrame, native_rate_hz: float, rate_hz: float) -> pd.DataFrame:
    """Keep every ``native / rate``-th fix (starting with the first), e.g. 5 Hz -> 1 Hz.

    Parameters
    ----------
    gnss : DataFrame
        GNSS table at ``native_rate_hz``.
    native_rate_hz, rate_hz : float
        Hz; ``native / rate`` must be an integer >= 1.

    Returns
    -------
    DataFrame
        Decimated copy, index reset. Fix times are kept as recorded (not moved to the IMU grid).
    """
    ratio = native_rate_hz / rate_hz
    step = int(round(ratio))
    if rate_hz <= 0 or step < 1 or abs(ratio - step) > 1e-6:
        raise DataError("gnss", "gnss_rate_hz", f"{native_rate_hz} Hz divided by an integer", f"{rate_hz} Hz")
    return gnss.iloc[::step].reset_index(drop=True)


#: Below this horizontal speed the course over ground is not trusted; the last trusted one is held, m/s.
COURSE_MIN_SPEED_MPS = 1.0


def course_over_ground(v_n, v_e, min_speed_mps: float = COURSE_MIN_SPEED_MPS) -> np.ndarray:
    """Direction of the horizontal velocity, clockwise from north (rad), held through slow epochs.

    Parameters
    ----------
    v_n, v_e : array_like
        North and east velocity, m/s.
    min_speed_mps : float
        Epochs slower than this take the course of the nearest earlier trusted epoch (the first trusted one
        before the first).

    Returns
    -------
    ndarray
        rad in (-pi, pi]; zeros when no epoch is fast enough.
    """
    v_n, v_e = np.asarray(v_n, dtype=float), np.asarray(v_e, dtype=float)
    course = np.arctan2(v_e, v_n)
    fast = np.hypot(v_n, v_e) >= min_speed_mps
    return hold_trusted(course, fast) if fast.any() else np.zeros_like(course)


def hold_trusted(values: np.ndarray, trusted: np.ndarray) -> np.ndarray:
    """``values`` with each untrusted epoch taking the nearest earlier trusted one (the first trusted one before the
    first); ``trusted`` must hold at least one True."""
    idx = np.maximum.accumulate(np.where(trusted, np.arange(len(values)), -1))   # last trusted at or before each
    idx[idx < 0] = int(np.argmax(trusted))
    return np.asarray(values)[idx]


def body_to_nav(truth: pd.DataFrame) -> np.ndarray:
    """``C_bn`` of each reference row (paper Eq. cnb); level along the course over ground when the reference
    has no attitude (all ``roll, pitch, yaw`` NaN; module docstring).

    Returns
    -------
    ndarray, shape (n, 3, 3)
    """
    att = truth[list(ATTITUDE_COLUMNS)].to_numpy(float)   # [n, 3] rad
    if np.isnan(att).all():
        zero = np.zeros(len(truth))
        return dcm_from_euler(zero, zero, course_over_ground(truth["v_n"], truth["v_e"]))
    return dcm_from_euler(att[:, 0], att[:, 1], att[:, 2])


def antenna_position(truth: pd.DataFrame, lever_arm_m) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Geodetic position of the GNSS antenna, ``p_imu + C_bn @ lever_arm``.

    Parameters
    ----------
    truth : DataFrame
        Reference table.
    lever_arm_m : array_like, shape (3,)
        Antenna position in the body frame (x forward, y right, z down), m.

    Returns
    -------
    lat, lon, h : ndarray
        rad, rad, m.
    """
    lat, lon, h = (truth[c].to_numpy(float) for c in ("lat", "lon", "h"))
    d_ned = body_to_nav(truth) @ np.asarray(lever_arm_m, dtype=float)  # [n, 3]
    return _offset(lat, lon, h, d_ned)


def imu_position(antenna: pd.DataFrame, lever_arm_m) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Geodetic position of the IMU from the antenna's, ``p_ant - C_bn @ lever_arm`` (inverse of
    :func:`antenna_position` for the same ``C_bn``).

    Parameters
    ----------
    antenna : DataFrame
        ``lat, lon, h, v_n, v_e`` and ``roll, pitch, yaw`` (all NaN: level along the course, :func:`body_to_nav`).
    lever_arm_m : array_like, shape (3,)
        Antenna position in the body frame, m.

    Returns
    -------
    lat, lon, h : ndarray
        rad, rad, m.
    """
    lat, lon, h = (antenna[c].to_numpy(float) for c in ("lat", "lon", "h"))
    d_ned = body_to_nav(antenna) @ np.asarray(lever_arm_m, dtype=float)  # [n, 3]
    return _offset(lat, lon, h, -d_ned)


def fix_errors(gnss: pd.DataFrame, truth: pd.DataFrame, lever_arm_m, excluded_s=()) -> pd.DataFrame:
    """Error of each GNSS fix against the true antenna position (:func:`antenna_position`), local NED, m.

    Parameters
    ----------
    gnss : DataFrame
        Fixes (``time, lat, lon, h``); those outside the span of ``truth`` are left out.
    truth : DataFrame
        Reference table (``time, lat, lon, h, roll, pitch, yaw``).
    lever_arm_m : array_like, shape (3,)
        Antenna position in the body frame, m.
    excluded_s : sequence of (t0, t1) or dict
        Spans where the reference is not trusted, or the drive's ``meta``: fixes inside are left out
        (:func:`bgfn.nav.metrics.reference_rows`).

    Returns
    -------
    DataFrame
        ``time, north_m, east_m, down_m``: fix minus truth.
    """
    t = truth["time"].to_numpy(float)
    tg_all = gnss["time"].to_numpy(float)
    g = gnss.loc[(tg_all >= t[0]) & (tg_all <= t[-1]) & reference_rows(tg_all, excluded_s)]
    lat, lon, h = antenna_position(truth, lever_arm_m)
    tg = g["time"].to_numpy(float)
    lat_i, lon_i, h_i = (np.interp(tg, t, x) for x in (lat, lon, h))
    r_m, r_n = curvature_radii(lat_i)
    return pd.DataFrame({"time": tg, "north_m": (g["lat"].to_numpy(float) - lat_i) * (r_m + h_i),
                         "east_m": (g["lon"].to_numpy(float) - lon_i) * (r_n + h_i) * np.cos(lat_i),
                         "down_m": -(g["h"].to_numpy(float) - h_i)})


def _offset(lat, lon, h, d_ned):
    r_m, r_n = curvature_radii(lat)
    return (lat + d_ned[:, 0] / (r_m + h), lon + d_ned[:, 1] / ((r_n + h) * np.cos(lat)), h - d_ned[:, 2])


def degrade_fixes(fixes: pd.DataFrame, seed: int, *, rate_hz: float = 1.0, white_std_m=(0.3, 0.3, 0.6),
                  correlated_std_m=(1.0, 1.0, 2.0), correlated_tau_s: float = 60.0) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Add a u-blox-like receiver's position errors (module docstring) to exact antenna fixes.

    Parameters
    ----------
    fixes : DataFrame
        ``time, lat, lon, h`` of the antenna, one fix every ``1 / rate_hz`` s; ``v_n, v_e, v_d`` are kept
        when present (NaN otherwise).
    seed : int
        Seed of the error draws.
    rate_hz : float
        Fix rate, Hz (the Gauss-Markov step).
    white_std_m, correlated_std_m : array_like, shape (3,)
        North, east, down std, m.
    correlated_tau_s : float
        Correlation time of the correlated part, s.

    Returns
    -------
    gnss : DataFrame
        GNSS table (``GNSS_COLUMNS``) with ``std_n/e/d = sqrt(white^2 + correlated^2)``.
    errors : DataFrame
        ``time``, ``err_n``, ``err_e``, ``err_d`` (m): the added error (fix - exact antenna position).
    """
    white = np.broadcast_to(np.asarray(white_std_m, dtype=float), (3,))
    corr = np.broadcast_to(np.asarray(correlated_std_m, dtype=float), (3,))
    if (white < 0).any() or (corr < 0).any() or correlated_tau_s <= 0 or rate_hz <= 0:
        raise DataError("gnss", "white_std_m/correlated_std_m/correlated_tau_s/rate_hz",
                        "non-negative std, positive correlation time and rate",
                        f"{white.tolist()}, {corr.tolist()}, {correlated_tau_s}, {rate_hz}")
    lat, lon, h = (fixes[c].to_numpy(float) for c in ("lat", "lon", "h"))
    n = lat.size
    rng = np.random.default_rng(seed)
    err = gauss_markov(n, 1.0 / rate_hz, corr, np.full(3, correlated_tau_s), rng) \
        + rng.standard_normal((n, 3)) * white  # [n, 3] north, east, down
    lat_f, lon_f, h_f = _offset(lat, lon, h, err)
    std = np.sqrt(white ** 2 + corr ** 2)
    nan = np.full(n, np.nan)
    vel = {c: fixes[c].to_numpy(float) if c in fixes.columns else nan for c in ("v_n", "v_e", "v_d")}
    gnss = pd.DataFrame({"time": fixes["time"].to_numpy(float), "lat": lat_f, "lon": lon_f, "h": h_f, **vel,
                         "std_n": np.full(n, std[0]), "std_e": np.full(n, std[1]), "std_d": np.full(n, std[2])},
                        columns=list(GNSS_COLUMNS))
    errors = pd.DataFrame({"time": gnss["time"], "err_n": err[:, 0], "err_e": err[:, 1], "err_d": err[:, 2]})
    return gnss, errors


def simulate_fixes(truth: pd.DataFrame, lever_arm_m, seed: int, *, rate_hz: float = 1.0,
                   white_std_m=(0.3, 0.3, 0.6), correlated_std_m=(1.0, 1.0, 2.0),
                   correlated_tau_s: float = 60.0) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Simulate GNSS position fixes from the truth (module docstring).

    Parameters
    ----------
    truth : DataFrame
        Reference table on a uniform grid whose rate is a multiple of ``rate_hz``.
    lever_arm_m : array_like, shape (3,)
        Antenna in the body frame, m.
    seed : int
        Seed of the error draws.
    rate_hz : float
        Fix rate, Hz (fixes at the truth epochs that are integer multiples of ``1 / rate_hz``).
    white_std_m, correlated_std_m, correlated_tau_s
        As :func:`degrade_fixes`, which adds the errors to the exact antenna positions.

    Returns
    -------
    gnss, errors : DataFrame
        As :func:`degrade_fixes` (velocities NaN).
    """
    t = truth["time"].to_numpy(float)
    k = t * rate_hz
    sel = np.abs(k - np.round(k)) < 1e-6
    if sel.sum() < 2:
        raise DataError("gnss", "gnss_rate_hz", f"at least 2 truth epochs at multiples of 1/{rate_hz} s",
                        f"{int(sel.sum())}")
    sub = truth.loc[sel]
    lat, lon, h = antenna_position(sub, lever_arm_m)
    antenna = pd.DataFrame({"time": sub["time"].to_numpy(float), "lat": lat, "lon": lon, "h": h})
    return degrade_fixes(antenna, seed, rate_hz=rate_hz, white_std_m=white_std_m,
                         correlated_std_m=correlated_std_m, correlated_tau_s=correlated_tau_s)

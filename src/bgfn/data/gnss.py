"""GNSS fixes: decimation of real fixes, and a u-blox-like receiver simulated from the truth.

Simulated receiver (position only, as the paper's KF measurement, Eq. 13, uses position): the antenna
position ``p_ant = p_imu + C_bn @ lever_arm`` (NED offset converted to lat/lon/h with the local radii) is
sampled at ``rate_hz`` on the truth's epochs that are multiples of ``1 / rate_hz`` and corrupted per axis
(north, east, down) by

- a time-correlated error: first-order Gauss-Markov, stationary std ``correlated_std_m``, correlation
  time ``correlated_tau_s`` (slowly varying multipath / atmosphere / ephemeris), and
- a white error of std ``white_std_m``.

The reported ``std_n/e/d`` are ``sqrt(correlated^2 + white^2)``; velocities are not simulated (NaN).
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from bgfn.data.imu_errors import gauss_markov
from bgfn.errors import DataError
from bgfn.nav.earth import curvature_radii
from bgfn.nav.transform import dcm_from_euler
from bgfn.schema import GNSS_COLUMNS

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
    c_bn = dcm_from_euler(truth["roll"].to_numpy(float), truth["pitch"].to_numpy(float),
                          truth["yaw"].to_numpy(float))  # [n, 3, 3]
    d_ned = c_bn @ np.asarray(lever_arm_m, dtype=float)  # [n, 3]
    return _offset(lat, lon, h, d_ned)


def fix_errors(gnss: pd.DataFrame, truth: pd.DataFrame, lever_arm_m) -> pd.DataFrame:
    """Error of each GNSS fix against the true antenna position (:func:`antenna_position`), local NED, m.

    Parameters
    ----------
    gnss : DataFrame
        Fixes (``time, lat, lon, h``); those outside the span of ``truth`` are left out.
    truth : DataFrame
        Reference table (``time, lat, lon, h, roll, pitch, yaw``).
    lever_arm_m : array_like, shape (3,)
        Antenna position in the body frame, m.

    Returns
    -------
    DataFrame
        ``time, north_m, east_m, down_m``: fix minus truth.
    """
    t = truth["time"].to_numpy(float)
    g = gnss.loc[(gnss["time"] >= t[0]) & (gnss["time"] <= t[-1])]
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
    white_std_m, correlated_std_m : array_like, shape (3,)
        North, east, down std, m.
    correlated_tau_s : float
        Correlation time of the correlated part, s.

    Returns
    -------
    gnss : DataFrame
        GNSS table (``GNSS_COLUMNS``), velocities NaN.
    errors : DataFrame
        ``time``, ``err_n``, ``err_e``, ``err_d`` (m): the simulated position error (fix - antenna truth).
    """
    white = np.broadcast_to(np.asarray(white_std_m, dtype=float), (3,))
    corr = np.broadcast_to(np.asarray(correlated_std_m, dtype=float), (3,))
    if (white < 0).any() or (corr < 0).any() or correlated_tau_s <= 0 or rate_hz <= 0:
        raise DataError("gnss", "white_std_m/correlated_std_m/correlated_tau_s/rate_hz",
                        "non-negative std, positive correlation time and rate",
                        f"{white.tolist()}, {corr.tolist()}, {correlated_tau_s}, {rate_hz}")
    t = truth["time"].to_numpy(float)
    k = t * rate_hz
    sel = np.abs(k - np.round(k)) < 1e-6
    if sel.sum() < 2:
        raise DataError("gnss", "gnss_rate_hz", f"at least 2 truth epochs at multiples of 1/{rate_hz} s",
                        f"{int(sel.sum())}")
    sub = truth.loc[sel]
    lat, lon, h = antenna_position(sub, lever_arm_m)
    n = lat.size
    rng = np.random.default_rng(seed)
    err = gauss_markov(n, 1.0 / rate_hz, corr, np.full(3, correlated_tau_s), rng) \
        + rng.standard_normal((n, 3)) * white  # [n, 3] north, east, down
    lat_f, lon_f, h_f = _offset(lat, lon, h, err)
    std = np.sqrt(white ** 2 + corr ** 2)
    nan = np.full(n, np.nan)
    gnss = pd.DataFrame({"time": sub["time"].to_numpy(float), "lat": lat_f, "lon": lon_f, "h": h_f,
                         "v_n": nan, "v_e": nan, "v_d": nan, "std_n": np.full(n, std[0]),
                         "std_e": np.full(n, std[1]), "std_d": np.full(n, std[2])}, columns=list(GNSS_COLUMNS))
    errors = pd.DataFrame({"time": gnss["time"], "err_n": err[:, 0], "err_e": err[:, 1], "err_d": err[:, 2]})
    return gnss, errors

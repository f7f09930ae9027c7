"""NED strapdown mechanization (paper Sec. 2): attitude, velocity and position from IMU mean rates.

One step goes from epoch ``k-1`` to ``k`` with the mean angular rate and specific force over the step (IMU row
``k``, CONTRIBUTING.md): attitude ``C_k = exp(-[zeta]) C_{k-1} exp([theta])`` (exact for a constant rate), velocity
with the rotation/sculling factor ``(I + [theta]/2)`` (exact to second order), position by the trapezoid rule.
Earth rate, transport rate and gravity are taken at the start of the step, which makes
:func:`bgfn.nav.sim.imu_from_trajectory` the exact inverse of :func:`propagate`. The inner loop is a numba kernel
(:func:`step_inplace`) that the Kalman filter reuses.
"""

from __future__ import annotations

import numba
import numpy as np
import pandas as pd

from ..errors import DataError
from ..schema import ACCEL_COLUMNS, GYRO_COLUMNS, IMU_COLUMNS
from . import transform
from .earth import E2, GAMMA_E, K_SOMIGLIANA, M_RATIO, OMEGA_IE, A, F

#: An IMU step longer than this many nominal (median) steps is a gap, not a sample.
MAX_GAP_SAMPLES = 5


# ---------------------------------------------------------------------------------------------------
# numba scalar kernels (same formulas as bgfn.nav.earth, which is the vectorized reference)
# ---------------------------------------------------------------------------------------------------
@numba.njit(cache=True)
def radii_nb(lat):
    """Meridian and prime-vertical radii (m) at latitude ``lat`` (rad); see earth.curvature_radii."""
    s = np.sin(lat)
    x = 1.0 - E2 * s * s
    r_n = A / np.sqrt(x)
    return r_n * (1.0 - E2) / x, r_n


@numba.njit(cache=True)
def gravity_nb(lat, h):
    """Normal gravity magnitude (m/s^2); see earth.normal_gravity."""
    s2 = np.sin(lat) ** 2
    g0 = GAMMA_E * (1.0 + K_SOMIGLIANA * s2) / np.sqrt(1.0 - E2 * s2)
    return g0 * (1.0 - 2.0 / A * (1.0 + F + M_RATIO - 2.0 * F * s2) * h + 3.0 / (A * A) * h * h)


@numba.njit(cache=True)
def rates_nb(lat, h, v, w_ie, w_en):
    """Fill Earth rate ``w_ie`` and transport rate ``w_en`` (NED, rad/s) in place."""
    r_m, r_n = radii_nb(lat)
    w_ie[0] = OMEGA_IE * np.cos(lat)
    w_ie[1] = 0.0
    w_ie[2] = -OMEGA_IE * np.sin(lat)
    w_en[0] = v[1] / (r_n + h)
    w_en[1] = -v[0] / (r_m + h)
    w_en[2] = -v[1] * np.tan(lat) / (r_n + h)


@numba.njit(cache=True)
def rotvec_to_dcm_nb(rv, out):
    """Rodrigues formula ``out = exp([rv])``, accurate for small angles."""
    n2 = rv[0] * rv[0] + rv[1] * rv[1] + rv[2] * rv[2]
    n = np.sqrt(n2)
    if n2 > 1e-8:
        k1 = np.sin(n) / n
        k2 = 2.0 * np.sin(0.5 * n) ** 2 / n2
    else:
        k1 = 1.0 - n2 / 6.0 + n2 * n2 / 120.0
        k2 = 0.5 - n2 / 24.0 + n2 * n2 / 720.0
    c = 1.0 - k2 * n2
    out[0, 0] = k2 * rv[0] * rv[0] + c
    out[0, 1] = k2 * rv[0] * rv[1] - k1 * rv[2]
    out[0, 2] = k2 * rv[0] * rv[2] + k1 * rv[1]
    out[1, 0] = k2 * rv[1] * rv[0] + k1 * rv[2]
    out[1, 1] = k2 * rv[1] * rv[1] + c
    out[1, 2] = k2 * rv[1] * rv[2] - k1 * rv[0]
    out[2, 0] = k2 * rv[2] * rv[0] - k1 * rv[1]
    out[2, 1] = k2 * rv[2] * rv[1] + k1 * rv[0]
    out[2, 2] = k2 * rv[2] * rv[2] + c


@numba.njit(cache=True)
def step_inplace(pos, v, c_bn, gyro, accel, dt):
    """One strapdown step from epoch k-1 to k, in place.

    Parameters
    ----------
    pos : ndarray, shape (3,)
        ``[lat, lon, h]`` (rad, rad, m), updated in place.
    v : ndarray, shape (3,)
        NED velocity (m/s), updated in place.
    c_bn : ndarray, shape (3, 3)
        Body-to-NED DCM, updated in place.
    gyro : ndarray, shape (3,)
        Mean angular rate over the step (rad/s).
    accel : ndarray, shape (3,)
        Mean specific force over the step (m/s^2).
    dt : float
        Step (s).
    """
    lat = pos[0]
    h = pos[2]
    w_ie = np.empty(3)
    w_en = np.empty(3)
    rates_nb(lat, h, v, w_ie, w_en)
    g = gravity_nb(lat, h)
    theta = gyro * dt
    zeta = (w_ie + w_en) * dt
    # Velocity increment in the body frame with the rotation (sculling) correction: (I + [theta]/2) f dt.
    fb = accel * dt
    dvb = np.empty(3)
    dvb[0] = fb[0] + 0.5 * (theta[1] * fb[2] - theta[2] * fb[1])
    dvb[1] = fb[1] + 0.5 * (theta[2] * fb[0] - theta[0] * fb[2])
    dvb[2] = fb[2] + 0.5 * (theta[0] * fb[1] - theta[1] * fb[0])
    u = c_bn @ dvb
    # (I - [zeta]/2): the NED frame turns during the step.
    dvn0 = u[0] - 0.5 * (zeta[1] * u[2] - zeta[2] * u[1])
    dvn1 = u[1] - 0.5 * (zeta[2] * u[0] - zeta[0] * u[2])
    dvn2 = u[2] - 0.5 * (zeta[0] * u[1] - zeta[1] * u[0])
    # Coriolis + gravity (start of step): g^n - (2 w_ie + w_en) x v.
    a0 = 2.0 * w_ie[0] + w_en[0]
    a1 = 2.0 * w_ie[1] + w_en[1]
    a2 = 2.0 * w_ie[2] + w_en[2]
    cor0 = a1 * v[2] - a2 * v[1]
    cor1 = a2 * v[0] - a0 * v[2]
    cor2 = a0 * v[1] - a1 * v[0]
    v_old0, v_old1, v_old2 = v[0], v[1], v[2]
    v[0] = v_old0 + dvn0 - cor0 * dt
    v[1] = v_old1 + dvn1 - cor1 * dt
    v[2] = v_old2 + dvn2 + (g - cor2) * dt
    # Attitude: C_k = exp(-[zeta]) C_{k-1} exp([theta]).
    cb = np.empty((3, 3))
    cn = np.empty((3, 3))
    rotvec_to_dcm_nb(theta, cb)
    rotvec_to_dcm_nb(-zeta, cn)
    c_new = cn @ (c_bn @ cb)
    c_bn[:, :] = c_new
    position_step_nb(pos, v_old0, v_old1, v_old2, v[0], v[1], v[2], dt)


@numba.njit(cache=True)
def position_step_nb(pos, vn0, ve0, vd0, vn1, ve1, vd1, dt):
    """Trapezoid-rule position update in place; height first so latitude/longitude use mid-step height."""
    lat = pos[0]
    h = pos[2]
    h_new = h - 0.5 * (vd0 + vd1) * dt
    h_mid = 0.5 * (h + h_new)
    r_m, _ = radii_nb(lat)
    lat_new = lat + 0.5 * (vn0 + vn1) * dt / (r_m + h_mid)
    lat_mid = 0.5 * (lat + lat_new)
    _, r_n_mid = radii_nb(lat_mid)
    pos[1] = pos[1] + 0.5 * (ve0 + ve1) * dt / ((r_n_mid + h_mid) * np.cos(lat_mid))
    pos[0] = lat_new
    pos[2] = h_new


@numba.njit(cache=True)
def integrate_nb(pos0, v0, c0, gyro, accel, dt, pos_out, v_out, c_out):
    """Integrate ``len(dt)`` steps; outputs row 0 = initial state, row k = after step k."""
    pos = pos0.copy()
    v = v0.copy()
    c = c0.copy()
    pos_out[0] = pos
    v_out[0] = v
    c_out[0] = c
    for k in range(dt.shape[0]):
        step_inplace(pos, v, c, gyro[k], accel[k], dt[k])
        pos_out[k + 1] = pos
        v_out[k + 1] = v
        c_out[k + 1] = c


# ---------------------------------------------------------------------------------------------------
# public API
# ---------------------------------------------------------------------------------------------------
def propagate(lat, lon, h, v_n, c_bn, gyro, accel, dt):
    """One strapdown step (see module docstring for the equations).

    Parameters
    ----------
    lat, lon : float
        Geodetic latitude and longitude at epoch k-1, rad.
    h : float
        Ellipsoidal height at epoch k-1, m.
    v_n : array_like, shape (3,)
        NED velocity at epoch k-1, m/s.
    c_bn : array_like, shape (3, 3)
        Body-to-NED DCM at epoch k-1.
    gyro : array_like, shape (3,)
        Mean angular rate over the step, rad/s.
    accel : array_like, shape (3,)
        Mean specific force over the step, m/s^2.
    dt : float
        Step, s.

    Returns
    -------
    lat, lon, h : float
        rad, rad, m at epoch k.
    v_n : ndarray, shape (3,)
        m/s.
    c_bn : ndarray, shape (3, 3)
    """
    pos = np.array([lat, lon, h], dtype=float)
    v = np.array(v_n, dtype=float)
    c = np.array(c_bn, dtype=float)
    step_inplace(pos, v, c, np.asarray(gyro, dtype=float), np.asarray(accel, dtype=float), float(dt))
    return pos[0], pos[1], pos[2], v, c


def imu_steps(imu, t0, source="imu"):
    """Select the IMU rows after ``t0`` and return their arrays and step lengths.

    Parameters
    ----------
    imu : DataFrame
        IMU table (CONTRIBUTING.md schema).
    t0 : float
        Time of the initial epoch, s.
    source : str
        Name used in error messages.

    Returns
    -------
    time : ndarray, shape (K,)
        Times of the used rows, s.
    gyro, accel : ndarray, shape (K, 3)
        rad/s, m/s^2.
    dt : ndarray, shape (K,)
        Step lengths (first one from ``t0``), s.

    Raises
    ------
    DataError
        Missing columns, non-increasing times, no rows after ``t0``, a first row not adjacent to ``t0``,
        or a gap longer than ``MAX_GAP_SAMPLES`` nominal steps.
    """
    missing = [c for c in IMU_COLUMNS if c not in imu.columns]
    if missing:
        raise DataError(source, ",".join(missing), "IMU columns " + ", ".join(IMU_COLUMNS), "missing")
    t_all = imu["time"].to_numpy(dtype=float)
    sel = t_all > t0
    time = t_all[sel]
    if time.size == 0:
        raise DataError(source, "time", f"IMU rows after the initial epoch t0={t0}", "none")
    dt = np.diff(np.concatenate([[t0], time]))
    check_steps(np.diff(t_all), source)
    nominal = float(np.median(np.diff(t_all))) if t_all.size > 1 else dt[0]
    if dt[0] > (MAX_GAP_SAMPLES + 0.5) * nominal:
        raise DataError(source, "time", f"an IMU row within {MAX_GAP_SAMPLES} samples after t0={t0}",
                        f"first row at {time[0]}")
    gyro = np.ascontiguousarray(imu.loc[sel, list(GYRO_COLUMNS)].to_numpy(dtype=float))
    accel = np.ascontiguousarray(imu.loc[sel, list(ACCEL_COLUMNS)].to_numpy(dtype=float))
    if not (np.all(np.isfinite(gyro)) and np.all(np.isfinite(accel))):
        raise DataError(source, "gyro/accel", "finite IMU readings", "NaN or inf")
    return time, gyro, accel, dt


def check_steps(steps, source="imu"):
    """Raise :class:`DataError` unless the time steps are positive and without gaps.

    Parameters
    ----------
    steps : ndarray
        Time differences, s.
    source : str
        Name used in error messages.
    """
    if steps.size == 0:
        return
    if not np.all(steps > 0):
        raise DataError(source, "time", "strictly increasing times", f"{int(np.sum(steps <= 0))} steps <= 0")
    nominal = float(np.median(steps))
    gaps = np.flatnonzero(steps > (MAX_GAP_SAMPLES + 0.5) * nominal)
    if gaps.size:
        raise DataError(source, "time", f"no gap longer than {MAX_GAP_SAMPLES} samples of {nominal:g} s",
                        f"{gaps.size} gaps, largest {steps[gaps].max():g} s")


def state_from_row(row):
    """Position, velocity and DCM arrays from a reference-schema row (Series or mapping).

    Returns
    -------
    pos : ndarray, shape (3,)
        ``[lat, lon, h]``.
    v : ndarray, shape (3,)
        NED velocity, m/s.
    c_bn : ndarray, shape (3, 3)
    """
    pos = np.array([row["lat"], row["lon"], row["h"]], dtype=float)
    v = np.array([row["v_n"], row["v_e"], row["v_d"]], dtype=float)
    c = transform.dcm_from_euler(row["roll"], row["pitch"], row["yaw"])
    return pos, v, np.ascontiguousarray(c)


def trajectory_frame(time, pos, v, c_bn):
    """Reference-schema DataFrame from arrays (Euler angles from the DCMs)."""
    roll, pitch, yaw = transform.euler_from_dcm(c_bn)
    return pd.DataFrame({"time": time, "lat": pos[:, 0], "lon": pos[:, 1], "h": pos[:, 2],
                         "v_n": v[:, 0], "v_e": v[:, 1], "v_d": v[:, 2],
                         "roll": roll, "pitch": pitch, "yaw": yaw})


def integrate(initial_row, imu, source="imu"):
    """Standalone INS: integrate an IMU table from an initial state.

    Parameters
    ----------
    initial_row : Series or mapping
        Initial state in the reference schema (``time``, ``lat``, ..., ``yaw``).
    imu : DataFrame
        IMU table; the rows with ``time > initial_row['time']`` are used, the first one must hold the
        mean rates over ``(t0, time]``.
    source : str
        Name used in error messages.

    Returns
    -------
    DataFrame
        Reference schema; row 0 is the initial state at ``t0``, row k the state after IMU row k.
    """
    t0 = float(initial_row["time"])
    time, gyro, accel, dt = imu_steps(imu, t0, source)
    pos0, v0, c0 = state_from_row(initial_row)
    n = dt.size + 1
    pos = np.empty((n, 3))
    v = np.empty((n, 3))
    c = np.empty((n, 3, 3))
    integrate_nb(pos0, v0, c0, gyro, accel, dt, pos, v, c)
    return trajectory_frame(np.concatenate([[t0], time]), pos, v, c)

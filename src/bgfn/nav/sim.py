"""IMU readings from a trajectory: the exact algebraic inverse of :func:`bgfn.nav.strapdown.propagate`.

For each pair of reference rows the step equations of :mod:`bgfn.nav.strapdown` are solved for the mean rates
(Earth rate, transport rate and gravity at the first row): the gyro from the attitude change, the accelerometer
from the velocity change (two 3x3 solves). Integrating the result reproduces the reference attitude and velocity to
rounding and the position to the trapezoid-rule error of the trajectory (zero for positions made with
:func:`positions_from_velocity`).
"""

from __future__ import annotations

import numba
import numpy as np
import pandas as pd

from ..errors import DataError
from ..schema import REFERENCE_COLUMNS
from . import earth, transform
from .strapdown import position_step_nb


def imu_from_trajectory(reference, source="reference"):
    """Error-free IMU mean rates that make the strapdown reproduce a trajectory.

    Parameters
    ----------
    reference : DataFrame
        Reference table (CONTRIBUTING.md schema), strictly increasing ``time``.
    source : str
        Name used in error messages.

    Returns
    -------
    DataFrame
        IMU table with rows for ``reference.time[1:]`` (row k = mean rates over ``(t[k-1], t[k]]``).
    """
    missing = [c for c in REFERENCE_COLUMNS if c not in reference.columns]
    if missing:
        raise DataError(source, ",".join(missing), "reference columns " + ", ".join(REFERENCE_COLUMNS),
                        "missing")
    t = reference["time"].to_numpy(dtype=float)
    if t.size < 2 or not np.all(np.diff(t) > 0):
        raise DataError(source, "time", "at least two strictly increasing times")
    lat = reference["lat"].to_numpy(dtype=float)[:-1]
    h = reference["h"].to_numpy(dtype=float)[:-1]
    v = reference[["v_n", "v_e", "v_d"]].to_numpy(dtype=float)
    c = transform.dcm_from_euler(reference["roll"].to_numpy(), reference["pitch"].to_numpy(),
                                 reference["yaw"].to_numpy())  # [T, 3, 3]
    dt = np.diff(t)[:, None]  # [T-1, 1]
    v0, v1 = v[:-1], v[1:]
    c0, c1 = c[:-1], c[1:]
    w_ie = earth.earth_rate_n(lat)
    w_en = earth.transport_rate_n(lat, h, v0)
    zeta = (w_ie + w_en) * dt  # [T-1, 3]
    c0_t = np.swapaxes(c0, -1, -2)
    # exp([theta]) = C_{k-1}^T exp([zeta]) C_k
    cb = c0_t @ transform.dcm_from_rotvec(zeta) @ c1
    theta = transform.rotvec_from_dcm(cb)
    gyro = theta / dt
    g_n = np.zeros_like(v0)
    g_n[:, 2] = earth.normal_gravity(lat, h)
    dv_sf = v1 - v0 - (g_n - np.cross(2.0 * w_ie + w_en, v0)) * dt
    eye = np.eye(3)
    u = np.linalg.solve(eye - 0.5 * transform.skew(zeta), dv_sf[..., None])  # C_{k-1} dv_b
    dvb = c0_t @ u
    fb = np.linalg.solve(eye + 0.5 * transform.skew(theta), dvb)[..., 0]
    accel = fb / dt
    return pd.DataFrame({"time": t[1:], "gyro_x": gyro[:, 0], "gyro_y": gyro[:, 1], "gyro_z": gyro[:, 2],
                         "accel_x": accel[:, 0], "accel_y": accel[:, 1], "accel_z": accel[:, 2]})


@numba.njit(cache=True)
def _positions_nb(t, v, lat0, lon0, h0, out):
    pos = np.array([lat0, lon0, h0])
    out[0] = pos
    for k in range(1, t.shape[0]):
        position_step_nb(pos, v[k - 1, 0], v[k - 1, 1], v[k - 1, 2], v[k, 0], v[k, 1], v[k, 2],
                         t[k] - t[k - 1])
        out[k] = pos


def positions_from_velocity(time, v_ned, lat0, lon0, h0):
    """Positions that the strapdown's trapezoid rule gives for a velocity history.

    Use it to make a trajectory's positions consistent with its velocities, so that
    integrating :func:`imu_from_trajectory` reproduces the positions to rounding as well.

    Parameters
    ----------
    time : array_like, shape (T,)
        s.
    v_ned : array_like, shape (T, 3)
        NED velocity, m/s.
    lat0, lon0, h0 : float
        Position at ``time[0]`` (rad, rad, m).

    Returns
    -------
    ndarray, shape (T, 3)
        ``[lat, lon, h]`` (rad, rad, m).
    """
    t = np.ascontiguousarray(time, dtype=float)
    v = np.ascontiguousarray(v_ned, dtype=float)
    out = np.empty((t.size, 3))
    _positions_nb(t, v, float(lat0), float(lon0), float(h0), out)
    return out


def demo_trajectory(duration_s=600.0, rate_hz=100.0, lat0=np.radians(45.06), lon0=np.radians(7.66),
                    h0=250.0, rest_s=0.0, start_s=10.0):
    """A smooth, deterministic, curvy 3D car-like trajectory (for tests and examples).

    Speed 8 +- 3 m/s, heading wandering over several turns, gentle climbs, roll and pitch following
    the motion. Positions come from :func:`positions_from_velocity`, so the table is consistent with
    the strapdown's position rule.

    Parameters
    ----------
    duration_s : float
        Length, s.
    rate_hz : float
        Sampling rate, Hz.
    lat0, lon0 : float
        Start position, rad.
    h0 : float
        Start height, m.
    rest_s : float
        Time the vehicle stands still at the start, s (0: it moves from the first row).
    start_s : float
        After a rest, the time over which the motion comes up to its full pace (smoothstep), s.

    Returns
    -------
    DataFrame
        Reference table starting at time 0.
    """
    t = np.arange(int(round(duration_s * rate_hz)) + 1) / rate_hz
    if rest_s > 0:
        # the motion's own clock tau stands still, then runs up to real time: a car that waits, then drives off
        x = np.clip((t - rest_s) / start_s, 0.0, 1.0)
        pace = x * x * (3.0 - 2.0 * x)                                 # d tau / dt
        tau = np.concatenate([[0.0], np.cumsum(0.5 * (pace[1:] + pace[:-1]) * np.diff(t))])
    else:
        pace, tau = 1.0, t
    speed_f = 8.0 + 3.0 * np.sin(0.05 * tau)
    speed = pace * speed_f
    yaw = 0.6 + 0.02 * tau + 1.2 * np.sin(0.03 * tau) + 0.3 * np.sin(0.11 * tau)
    yaw_rate = pace * (0.02 + 0.036 * np.cos(0.03 * tau) + 0.033 * np.cos(0.11 * tau))
    climb_f = 0.4 * np.sin(0.04 * tau) + 0.1 * np.sin(0.17 * tau)  # up, m/s
    climb = pace * climb_f
    v = np.stack([speed * np.cos(yaw), speed * np.sin(yaw), -climb], axis=-1)
    pitch = np.arctan2(climb_f, speed_f) + 0.01 * np.sin(0.3 * tau)  # the road's grade, also at rest
    roll = 0.04 * speed * yaw_rate + 0.02 * np.sin(0.23 * tau)
    pos = positions_from_velocity(t, v, lat0, lon0, h0)
    return pd.DataFrame({"time": t, "lat": pos[:, 0], "lon": pos[:, 1], "h": pos[:, 2],
                         "v_n": v[:, 0], "v_e": v[:, 1], "v_d": v[:, 2],
                         "roll": roll, "pitch": pitch, "yaw": transform.wrap_angle(yaw)})


def gnss_from_trajectory(reference, rate_hz=1.0, std_ne=1.0, std_d=2.0, lever_arm=(0.0, 0.0, 0.0),
                         seed=0):
    """Simple GNSS fixes (white Gaussian noise) of the antenna on a trajectory, for tests.

    Parameters
    ----------
    reference : DataFrame
        Reference table; fixes are taken at its rows whose time is a multiple of ``1/rate_hz``.
    rate_hz : float
        Fix rate, Hz.
    std_ne, std_d : float
        Horizontal (per axis) and vertical noise std, m.
    lever_arm : array_like, shape (3,)
        Antenna position in the body frame, m.
    seed : int
        Seed of the noise draws.

    Returns
    -------
    DataFrame
        GNSS table (CONTRIBUTING.md schema), velocities NaN.
    """
    t = reference["time"].to_numpy(dtype=float)
    phase = np.abs(t * rate_hz - np.round(t * rate_hz))
    ref = reference[phase < 1e-6].iloc[1:]
    n = len(ref)
    c = transform.dcm_from_euler(ref["roll"].to_numpy(), ref["pitch"].to_numpy(), ref["yaw"].to_numpy())
    rng = np.random.default_rng(seed)
    ned = c @ np.asarray(lever_arm, dtype=float) + rng.standard_normal((n, 3)) * [std_ne, std_ne, std_d]
    lat, lon, h = earth.ned_to_lla(ned, ref["lat"].to_numpy(), ref["lon"].to_numpy(), ref["h"].to_numpy())
    nan = np.full(n, np.nan)
    return pd.DataFrame({"time": ref["time"].to_numpy(), "lat": lat, "lon": lon, "h": h, "v_n": nan,
                         "v_e": nan, "v_d": nan, "std_n": np.full(n, std_ne), "std_e": np.full(n, std_ne),
                         "std_d": np.full(n, std_d)})

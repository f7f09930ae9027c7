"""A toy drive for tests and examples: a level circle with exact IMU readings and GNSS fixes."""

from __future__ import annotations

import numpy as np
import pandas as pd

from bgfn.learning.inputs import wrap_angle
from bgfn.nav.earth import curvature_radii


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

"""A synthetic fleet for the fleet study's tests: drives of one car whose forward speed is a known function of the
vibration spectrum, each drive's IMU remounted (tilted), rescaled and biased.

Imported by the tests (pytest puts ``tests/`` on ``sys.path``); not a test module itself.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.signal import butter, sosfilt

from bgfn.data import Drive
from bgfn.nav.transform import dcm_from_euler

G = 9.80665
#: Vibration amplitude (m/s^2, 5-40 Hz) at speed v: ``VIB0 exp(v / VIB_SCALE)``, so each band's log power is
#: linear in the speed.
VIB0, VIB_SCALE = 0.02, 8.0
EARTH_R = 6.371e6
#: Period of a weaving drive's yaw rate, s.
TURN_PERIOD_S = 20.0


def speed_profile(t: np.ndarray, v_lo: float, v_hi: float, seed: int) -> np.ndarray:
    """A smooth speed between ``v_lo`` and ``v_hi`` (m/s) after a 10 s standstill, with a 6 s stop in the middle."""
    rng = np.random.default_rng(seed)
    phases, periods = rng.uniform(0, 2 * np.pi, 3), rng.uniform(25, 70, 3)
    wave = sum(np.sin(2 * np.pi * t / p + f) for p, f in zip(periods, phases)) / 3.0
    v = v_lo + (v_hi - v_lo) * (0.5 + 0.5 * wave)
    ramp = np.clip((t - 10.0) / 8.0, 0.0, 1.0)
    mid = 0.5 * t[-1]
    stop = np.clip(np.abs(t - mid) / 6.0 - 0.5, 0.0, 1.0)          # 0 over [mid - 3, mid + 3], 1 beyond mid +- 9
    return v * ramp * stop


def fleet_drive(name: str, duration: float = 240.0, rate: float = 100.0, v_lo: float = 3.0, v_hi: float = 14.0,
                tilt_deg=(0.0, 0.0), scale: float = 1.0, gyro_bias=(0.0, 0.0, 0.0), seed: int = 0,
                gnss_offset: tuple | None = None, turn_dps: float = 0.0) -> Drive:
    """One drive heading north (module docstring); ``gnss_offset`` ``(t0, t1, dv)``: the GNSS speed off by ``dv``
    m/s over ``[t0, t1]`` (a reference that disagrees with it); ``turn_dps``: it weaves instead, its yaw rate a
    sine of that amplitude (deg/s, period :data:`TURN_PERIOD_S`) while it moves."""
    rng = np.random.default_rng(1000 + seed)
    t = np.arange(int(duration * rate) + 1) / rate
    v = speed_profile(t, v_lo, v_hi, seed)
    n = t.size
    yaw_rate = np.radians(turn_dps) * np.sin(2 * np.pi * t / TURN_PERIOD_S) * np.clip(v / 2.0, 0.0, 1.0)
    yaw = np.concatenate([[0.0], np.cumsum(0.5 * (yaw_rate[1:] + yaw_rate[:-1]) * np.diff(t))])
    sos = butter(4, [5.0, 40.0], btype="band", fs=rate, output="sos")
    amp = VIB0 * np.exp(v / VIB_SCALE)
    vib = sosfilt(sos, rng.standard_normal((n, 3)), axis=0)
    vib = vib / vib.std(axis=0) * amp[:, None]
    f_b = np.column_stack([np.gradient(v, t), v * yaw_rate, np.full(n, -G)]) + vib       # centripetal: v * yaw rate
    w_b = 1e-4 * rng.standard_normal((n, 3)) + 0.2 * vib
    w_b[:, 2] += yaw_rate
    c = dcm_from_euler(*np.radians([tilt_deg[0], tilt_deg[1]]), 0.0).reshape(3, 3)     # sensor tilted in the body
    f_s, w_s = scale * f_b @ c, w_b @ c + np.asarray(gyro_bias)                        # C^T x per row
    imu = pd.DataFrame({"time": t, "gyro_x": w_s[:, 0], "gyro_y": w_s[:, 1], "gyro_z": w_s[:, 2],
                        "accel_x": f_s[:, 0], "accel_y": f_s[:, 1], "accel_z": f_s[:, 2]})
    v_n, v_e = v * np.cos(yaw), v * np.sin(yaw)
    north = np.concatenate([[0.0], np.cumsum(0.5 * (v_n[1:] + v_n[:-1]) * np.diff(t))])
    east = np.concatenate([[0.0], np.cumsum(0.5 * (v_e[1:] + v_e[:-1]) * np.diff(t))])
    lat = np.radians(45.0) + north / EARTH_R
    ref = pd.DataFrame({"time": t, "lat": lat, "lon": np.radians(7.0) + east / (EARTH_R * np.cos(lat)), "h": 200.0,
                        "v_n": v_n, "v_e": v_e, "v_d": 0.0, "roll": 0.0, "pitch": 0.0, "yaw": yaw})
    g = ref.iloc[::int(rate)].reset_index(drop=True)
    gv = g["v_n"].to_numpy(float).copy()
    if gnss_offset is not None:
        t0, t1, dv = gnss_offset
        gv[(g["time"] >= t0) & (g["time"] <= t1)] += dv
    gnss = pd.DataFrame({"time": g["time"], "lat": g["lat"], "lon": g["lon"], "h": g["h"], "v_n": gv,
                         "v_e": g["v_e"], "v_d": 0.0, "std_n": 1.0, "std_e": 1.0, "std_d": 2.0})
    return Drive(name, ref, imu.iloc[1:].reset_index(drop=True), gnss,
                 {"imu_rate_hz": rate, "gnss_rate_hz": 1.0, "lever_arm_m": [0.0, 0.0, 0.0]})

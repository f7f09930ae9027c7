"""The small synthetic drive several test modules evaluate: the demo trajectory with a simulated IMU and GNSS.

Imported by the tests (pytest puts ``tests/`` on ``sys.path``); not a test module itself.
"""

from __future__ import annotations

import numpy as np

from bgfn.data import Drive
from bgfn.data import imu_errors as ie
from bgfn.nav import sim

#: GNSS antenna in the body frame, m.
LEVER = [0.4, -0.2, -1.0]
#: Large static biases on the tactical IMU (its ``*_bias_fixed``): something for the filter to estimate.
STATIC_BIASES = {"gyro_bias_fixed": [2e-4, -3e-4, 4e-4], "accel_bias_fixed": [0.03, -0.02, 0.02]}


def demo_drive(name: str = "synthetic", duration: float = 150.0, gnss_rate: float = 5.0, seed: int = 3,
               imu: str = "ekinox-d", overrides: dict | None = STATIC_BIASES) -> Drive:
    """:func:`bgfn.nav.sim.demo_trajectory` with the ``imu`` error profile (``overrides`` on it) and GNSS fixes
    of 1 m (horizontal) / 2 m (vertical) white noise at ``gnss_rate`` Hz; seeds ``seed`` and ``seed + 1``."""
    ref = sim.demo_trajectory(duration)
    params = ie.error_params(imu, overrides)
    speed = np.hypot(ref["v_n"], ref["v_e"]).to_numpy()[1:]
    imu_table, errs, _ = ie.apply_imu_errors(sim.imu_from_trajectory(ref), params, seed=seed, speed=speed)
    gnss = sim.gnss_from_trajectory(ref, gnss_rate, 1.0, 2.0, LEVER, seed=seed + 1)
    meta = {"lever_arm_m": LEVER, "imu_errors": errs, "gnss_rate_hz": gnss_rate, "imu_rate_hz": 100.0}
    return Drive(name, ref, imu_table, gnss, meta)


def exact_drive(duration: float = 60.0, **meta) -> Drive:
    """The demo trajectory with an error-free IMU and exact 1 Hz fixes at the IMU (lever arm 0; std 1 m / 3 m
    written); ``meta`` is added to the drive's ``meta``."""
    import pandas as pd

    ref = sim.demo_trajectory(duration_s=duration, rate_hz=100.0)
    g = ref.iloc[::100].reset_index(drop=True)
    gnss = pd.DataFrame({"time": g["time"], "lat": g["lat"], "lon": g["lon"], "h": g["h"], "v_n": g["v_n"],
                         "v_e": g["v_e"], "v_d": g["v_d"], "std_n": 1.0, "std_e": 1.0, "std_d": 3.0})
    return Drive("demo", ref, sim.imu_from_trajectory(ref), gnss, {"lever_arm_m": [0.0, 0.0, 0.0], **meta})

"""Our tables -> pyins (PyPI ``python-ins``), the independent implementation our filter is checked against.

Used only by the cross-check test (``tests/test_nav_filter.py``) and the benchmark (``benchmarks/bench_nav.py``):
pyins takes degrees, a ``heading`` in [0, 360), IMU *increments* indexed by time, and one position standard
deviation for all axes.
"""

from __future__ import annotations

import warnings
from typing import Callable

import numpy as np
import pandas as pd

from .state import FilterNoise, FilterState


def feedback_filter(init: FilterState, noise: FilterNoise, imu: pd.DataFrame, gnss: pd.DataFrame, lever_arm,
                    position_sd: float, velocity_sd: float, level_sd_deg: float, azimuth_sd_deg: float,
                    gnss_sd: float | None = None, time_step: float = 1.0) -> Callable[[], pd.DataFrame]:
    """Prepare ``pyins.filters.run_feedback_filter`` on our tables; the returned call runs it.

    Parameters
    ----------
    init : FilterState
        Initial navigation solution (its ``P`` is not used: pyins takes the ``*_sd`` below).
    noise : FilterNoise
        Sensor noise and bias model, the same our filter uses.
    imu, gnss : DataFrame
        IMU and GNSS tables (CONTRIBUTING.md schema); the GNSS fixes are used as given.
    lever_arm : array_like, shape (3,)
        GNSS antenna in the body frame, m.
    position_sd, velocity_sd : float
        Initial position (m) and velocity (m/s) standard deviation.
    level_sd_deg, azimuth_sd_deg : float
        Initial roll/pitch and heading standard deviation, deg.
    gnss_sd : float, optional
        Position fix standard deviation, m (default: the median of the table's ``std_*``).
    time_step : float
        pyins' filter step, s.

    Returns
    -------
    callable
        ``run() -> DataFrame`` in the reference schema (radians, ``yaw`` from pyins' heading).
    """
    # here, not at the top: pyins is optional (the test extra), used by the cross-check alone
    from pyins import filters, inertial_sensor, measurements, strapdown

    row = init.as_row()
    pva = pd.Series({"lat": np.degrees(row["lat"]), "lon": np.degrees(row["lon"]), "alt": row["h"],
                     "VN": row["v_n"], "VE": row["v_e"], "VD": row["v_d"], "roll": np.degrees(row["roll"]),
                     "pitch": np.degrees(row["pitch"]), "heading": np.degrees(row["yaw"]) % 360}, name=row["time"])
    t = np.concatenate([[row["time"]], imu["time"].to_numpy()])
    inc = np.column_stack([imu[["gyro_x", "gyro_y", "gyro_z"]].to_numpy(),
                           imu[["accel_x", "accel_y", "accel_z"]].to_numpy()]) * np.diff(t)[:, None]
    inc = pd.DataFrame(np.vstack([inc[:1], inc]), index=pd.Index(t, name="time"),
                       columns=["gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"])
    increments = strapdown.compute_increments_from_imu(inc, "increment")
    fixes = pd.DataFrame({"lat": np.degrees(gnss["lat"].to_numpy()), "lon": np.degrees(gnss["lon"].to_numpy()),
                          "alt": gnss["h"].to_numpy()}, index=pd.Index(gnss["time"].to_numpy(), name="time"))
    sd = float(np.median(gnss[["std_n", "std_e", "std_d"]].to_numpy())) if gnss_sd is None else gnss_sd
    lever = np.asarray(lever_arm, dtype=float)

    def run() -> pd.DataFrame:
        gyro = inertial_sensor.EstimationModel(bias_sd=noise.gyro_bias_std, noise=noise.gyro_noise,
                                               bias_walk=noise.gyro_bias_walk)
        accel = inertial_sensor.EstimationModel(bias_sd=noise.accel_bias_std, noise=noise.accel_noise,
                                                bias_walk=noise.accel_bias_walk)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            result = filters.run_feedback_filter(pva, position_sd, velocity_sd, level_sd_deg, azimuth_sd_deg,
                                                 increments, gyro, accel,
                                                 [measurements.Position(fixes, sd, lever)], time_step=time_step)
        tp = result.trajectory.reset_index()
        return pd.DataFrame({"time": tp["time"], "lat": np.radians(tp["lat"]), "lon": np.radians(tp["lon"]),
                             "h": tp["alt"], "v_n": tp["VN"], "v_e": tp["VE"], "v_d": tp["VD"],
                             "roll": np.radians(tp["roll"]), "pitch": np.radians(tp["pitch"]),
                             "yaw": np.radians(tp["heading"])})

    return run

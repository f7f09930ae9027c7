"""The registered datasets (the names a profile may give besides a CSV folder) and their default parameters.

The registry alone, apart from the builders of :mod:`bgfn.data.drives`, so that :mod:`bgfn.data.names` can tell a
registered name from a folder without importing the builders (which name their files by it).
"""

from __future__ import annotations

from bgfn.data.rtklib import IMU_TIME_OFFSET_S

#: Default dataset (the paper's dataset test).
DEFAULT_DATASET = "turin-sim-ekinox"
#: Antenna lever arm NaveGo uses with the MPU-6000 (body frame, m).
MPU_LEVER_ARM_M = [-0.369, 0.0, -0.219]

COMMON_PARAMS = {
    "seed": 0,                     # seed of every random draw
    "imu_rate_hz": 100.0,          # IMU / truth rate, Hz
    "smoothing_degree": 5,         # truth spline degree
    "position_sigma_m": 0.05,      # truth smoothing of north/east/up, m (s = n sigma^2)
    "attitude_sigma_rad": 0.002,   # truth smoothing of roll/pitch/yaw, rad
    "t_start": None,               # crop, s (GPS time of week); applied after the cache
    "t_end": None,
}

#: The simulated u-blox-like receiver (turin-sim-mpu6000), also the degraded copy of the RTK solution.
UBLOX_PARAMS = {"gnss_rate_hz": 1.0, "gnss_white_std_m": [0.3, 0.3, 0.6], "gnss_correlated_std_m": [1.0, 1.0, 2.0],
          "gnss_correlated_tau_s": 60.0}

#: Parameters of each dataset (defaults). ``imu_errors`` holds overrides of the error profile's keys.
DATASETS: dict[str, dict] = {
    "turin-sim-ekinox": {**COMMON_PARAMS, "gnss_rate_hz": 5.0, "imu_errors": {}},
    "turin-sim-mpu6000": {**COMMON_PARAMS, **UBLOX_PARAMS, "imu_errors": {}, "lever_arm_m": MPU_LEVER_ARM_M},
    "navego-ekinox": {**COMMON_PARAMS, "gnss_rate_hz": 5.0},
    "navego-mpu6000": {**COMMON_PARAMS, "gnss_rate_hz": 5.0, "lever_arm_m": MPU_LEVER_ARM_M},
    "rtklib-drive0708": {"seed": 0, "imu_rate_hz": 100.0, **UBLOX_PARAMS, "imu_errors": {},
                         "imu_time_offset_s": IMU_TIME_OFFSET_S, "t_start": None, "t_end": None},
}
#: The datasets whose IMU is simulated (from a smoothed reference): every other drive, a CSV folder included,
#: carries a recorded IMU, the decisive test of an outage aid (the results page shows those first).
SIMULATED_IMU: frozenset[str] = frozenset({"turin-sim-ekinox", "turin-sim-mpu6000"})


def recorded_first(datasets) -> list:
    """``datasets`` with the recorded-IMU drives first, each group in its given order."""
    datasets = list(datasets)
    return [d for d in datasets if d not in SIMULATED_IMU] + [d for d in datasets if d in SIMULATED_IMU]

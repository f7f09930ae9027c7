"""IMU error models: the Ekinox-D (tactical MEMS) and the InvenSense MPU-6000 (consumer MEMS).

Per IMU row ``k`` (the mean rate over ``(t[k-1], t[k]]``, CONTRIBUTING.md), for the gyro and the accelerometer::

    y_k = T @ x_k + b_fixed + b_turn_on + b_gm[k] + n_k + vib[k],    T = I + diag(scale_factor) + misalignment

with white noise ``n_k`` (std ``noise_density / sqrt(dt)``), a fixed and a run-to-run bias (less an optional boot
calibration), a first-order Gauss-Markov bias (``bias_instability``, ``bias_corr_time``), drawn scale factors and
misalignments, and a vibration band-passed around ``vibration_freq_hz`` that grows with the speed. The keys of
``meta['imu_errors']`` (SI units, 3 values per axis) are those of the profiles here; ``realized`` holds one run's
draws and ``p0_*_bias_std`` the prior std a filter's P0 takes for its bias states. The additive bias series is
returned as ``Drive.imu_bias``, to compare the estimated biases with the true ones.
"""

from __future__ import annotations

import copy

import numpy as np
import pandas as pd

from bgfn.errors import DataError

G0 = 9.80665  # standard gravity, m/s^2 (datasheet "g" and "mg")
DEG = np.pi / 180.0

_AXES = ("x", "y", "z")
#: Keys whose value is a 3-vector (per axis).
VECTOR_KEYS = (
    "gyro_noise_density", "accel_noise_density", "gyro_bias_fixed", "accel_bias_fixed",
    "gyro_turn_on_bias_std", "accel_turn_on_bias_std", "gyro_bias_instability", "accel_bias_instability",
    "gyro_bias_corr_time", "accel_bias_corr_time", "gyro_scale_factor_tol", "accel_scale_factor_tol",
    "gyro_misalignment_tol", "accel_misalignment_tol", "vibration_gyro_std", "vibration_accel_std",
)
#: 3-vector keys that may also be ``None`` (feature off).
OPTIONAL_VECTOR_KEYS = ("gyro_boot_calibration_residual_std", "accel_boot_calibration_residual_std")
#: Scalar keys.
SCALAR_KEYS = ("vibration_freq_hz", "vibration_bandwidth_hz", "vibration_speed_ref_mps",
               "vibration_idle_fraction")

_ZERO3 = [0.0, 0.0, 0.0]

#: Ekinox-D error profile as stored in NaveGo's ``ekinox_imu.mat`` (mirror README); static biases as in
#: NaveGo's ``noise_b_sta``: deterministic ``gb_sta``/``ab_sta`` plus a 10 % run-to-run part.
EKINOX_D: dict = {
    "model": "ekinox-d",
    "gyro_noise_density": [1.58e-4, 1.60e-4, 1.81e-4],       # arw, rad/sqrt(s)
    "accel_noise_density": [1.91e-4, 1.88e-4, 1.94e-4],      # vrw, m/s/sqrt(s)
    "gyro_bias_fixed": [-2.45e-4, 1.23e-4, -2.2e-5],         # gb_sta, rad/s
    "accel_bias_fixed": [1.6e-4, -2.40e-2, 3.79e-3],         # ab_sta, m/s^2
    "gyro_turn_on_bias_std": [2.45e-5, 1.23e-5, 2.2e-6],     # 10 % of gb_sta
    "accel_turn_on_bias_std": [1.6e-5, 2.40e-3, 3.79e-4],    # 10 % of ab_sta
    "gyro_bias_instability": [8.1e-6, 7.1e-6, 9.8e-6],       # gb_dyn, rad/s
    "accel_bias_instability": [8.4e-5, 6.7e-5, 7.4e-5],      # ab_dyn, m/s^2
    "gyro_bias_corr_time": [10.0, 10.0, 10.0],               # gb_corr, s
    "accel_bias_corr_time": [0.5, 2.0, 1.0],                 # ab_corr, s
    "gyro_scale_factor_tol": _ZERO3, "accel_scale_factor_tol": _ZERO3,
    "gyro_misalignment_tol": _ZERO3, "accel_misalignment_tol": _ZERO3,
    "vibration_gyro_std": _ZERO3, "vibration_accel_std": _ZERO3,
    "vibration_freq_hz": 20.0, "vibration_bandwidth_hz": 20.0, "vibration_speed_ref_mps": 10.0,
    "vibration_idle_fraction": 0.3,
}

#: InvenSense MPU-6000: paper's turn-on biases (5 deg/s, 60 mg), datasheet noise densities
#: (0.005 deg/s/sqrt(Hz), 400 ug/sqrt(Hz)), sensitivity tolerance +-3 %, cross-axis +-2 %; bias
#: instability (36 deg/h, 0.5 mg, 100 s) is our choice (not in the datasheet); vibration at the levels seen
#: in NaveGo's MPU-6000 log (0.3-1 m/s^2, 0.02 rad/s std with motion), band 10-30 Hz.
#: The gyro's turn-on bias is removed by a boot calibration at rest (as the Pixhawk autopilot does) that
#: leaves a residual of 1 deg/s: an uncalibrated 5 deg/s bias makes the heading diverge within seconds
#: in any position-only loosely coupled filter (ours and pyins' alike), because the drive starts moving.
MPU6000: dict = {
    "model": "mpu6000",
    "gyro_noise_density": [0.005 * DEG] * 3,
    "accel_noise_density": [400e-6 * G0] * 3,
    "gyro_bias_fixed": _ZERO3, "accel_bias_fixed": _ZERO3,
    "gyro_turn_on_bias_std": [5.0 * DEG] * 3,
    "accel_turn_on_bias_std": [60e-3 * G0] * 3,
    "gyro_boot_calibration_residual_std": [1.0 * DEG] * 3,
    "accel_boot_calibration_residual_std": None,
    "gyro_bias_instability": [0.01 * DEG] * 3,
    "accel_bias_instability": [0.5e-3 * G0] * 3,
    "gyro_bias_corr_time": [100.0] * 3,
    "accel_bias_corr_time": [100.0] * 3,
    "gyro_scale_factor_tol": [0.03] * 3, "accel_scale_factor_tol": [0.03] * 3,
    "gyro_misalignment_tol": [0.02] * 3, "accel_misalignment_tol": [0.02] * 3,
    "vibration_gyro_std": [0.015] * 3,
    "vibration_accel_std": [0.3, 0.3, 0.5],
    "vibration_freq_hz": 20.0, "vibration_bandwidth_hz": 20.0, "vibration_speed_ref_mps": 10.0,
    "vibration_idle_fraction": 0.3,
}

#: Error profiles by name.
PROFILES = {"ekinox-d": EKINOX_D, "mpu6000": MPU6000}


def error_params(profile: str | dict, overrides: dict | None = None) -> dict:
    """A validated copy of an error profile with ``overrides`` applied.

    Parameters
    ----------
    profile : str or dict
        ``"ekinox-d"``, ``"mpu6000"`` or a full parameter dict.
    overrides : dict, optional
        Keys of :data:`MPU6000` (the model: module docstring); a scalar given for a 3-vector key is broadcast.

    Returns
    -------
    dict
        All keys of ``VECTOR_KEYS`` (lists of 3 floats), ``SCALAR_KEYS`` (floats) and ``model``.

    Raises
    ------
    DataError
        Unknown profile/key, wrong size, negative std/tolerance, non-positive correlation time, or a
        vibration band outside (0, Nyquist) is checked in :func:`apply_imu_errors`.
    """
    if isinstance(profile, str):
        if profile not in PROFILES:
            raise DataError("imu_errors", "profile", f"one of {sorted(PROFILES)}", repr(profile))
        params = copy.deepcopy(PROFILES[profile])
    else:
        params = copy.deepcopy(dict(profile))
    for key, value in (overrides or {}).items():
        known = VECTOR_KEYS + OPTIONAL_VECTOR_KEYS + SCALAR_KEYS
        if key not in known and key != "model":
            raise DataError("imu_errors", key, f"a key of {known}", "unknown key")
        params[key] = value
    out = {"model": str(params.get("model", "custom"))}
    for key in VECTOR_KEYS:
        v = np.asarray(params.get(key, _ZERO3), dtype=float).ravel()
        if v.size == 1:
            v = np.repeat(v, 3)
        if v.size != 3 or not np.isfinite(v).all():
            raise DataError("imu_errors", key, "3 finite values (x, y, z)", str(v.tolist()))
        if key.endswith("corr_time"):
            if (v <= 0).any():
                raise DataError("imu_errors", key, "positive correlation times, s", str(v.tolist()))
        elif not key.endswith("bias_fixed") and (v < 0).any():
            raise DataError("imu_errors", key, "non-negative values", str(v.tolist()))
        out[key] = v.tolist()
    for key in OPTIONAL_VECTOR_KEYS:
        value = params.get(key)
        if value is None:
            out[key] = None
            continue
        v = np.broadcast_to(np.asarray(value, dtype=float).ravel(), (3,)) if np.size(value) in (1, 3) else None
        if v is None or not np.isfinite(v).all() or (v < 0).any():
            raise DataError("imu_errors", key, "None or 3 non-negative values (x, y, z)", str(value))
        out[key] = v.tolist()
    for key in SCALAR_KEYS:
        v = float(params.get(key, EKINOX_D[key]))
        if not np.isfinite(v) or v < 0:
            raise DataError("imu_errors", key, "a non-negative finite number", str(v))
        out[key] = v
    if not 0.0 <= out["vibration_idle_fraction"] <= 1.0:
        raise DataError("imu_errors", "vibration_idle_fraction", "a fraction in [0, 1]",
                        str(out["vibration_idle_fraction"]))
    return out


def gauss_markov(n: int, dt: float, sigma, tau, rng: np.random.Generator) -> np.ndarray:
    """First-order Gauss-Markov processes sampled every ``dt``, started in their stationary law.

    Parameters
    ----------
    n : int
        Number of samples.
    dt : float
        Sample interval, s.
    sigma : array_like, shape (m,)
        Stationary std per process.
    tau : array_like, shape (m,)
        Correlation time per process, s (> 0).
    rng : numpy.random.Generator

    Returns
    -------
    ndarray, shape (n, m)
        ``x[k] = a x[k-1] + sigma sqrt(1 - a^2) w[k]``, ``a = exp(-dt/tau)``, ``x[0] ~ N(0, sigma^2)``;
        autocorrelation ``sigma^2 exp(-|lag| / tau)``.
    """
    # imported here: scipy.signal imports scipy.stats, about a second in every process that loads a drive
    from scipy import signal
    sigma = np.atleast_1d(np.asarray(sigma, dtype=float))
    tau = np.atleast_1d(np.asarray(tau, dtype=float))
    w = rng.standard_normal((n, sigma.size))  # [n, m]
    out = np.empty((n, sigma.size))
    for i in range(sigma.size):
        a = np.exp(-dt / tau[i])
        e = sigma[i] * np.sqrt(1.0 - a * a) * w[:, i]
        e[0] = sigma[i] * w[0, i]
        out[:, i] = signal.lfilter([1.0], [1.0, -a], e)
    return out


def band_limited_noise(n: int, rate_hz: float, f_center: float, bandwidth: float,
                       rng: np.random.Generator, m: int = 3) -> np.ndarray:
    """Unit-variance Gaussian noise band-passed to ``f_center +- bandwidth/2`` (2nd-order Butterworth).

    Parameters
    ----------
    n : int
        Samples.
    rate_hz : float
        Sample rate, Hz.
    f_center, bandwidth : float
        Band, Hz; must lie within (0, rate_hz / 2).
    rng : numpy.random.Generator
    m : int
        Number of independent channels.

    Returns
    -------
    ndarray, shape (n, m)
        Stationary std 1 (normalized by the filter's exact noise gain, not by the sample std).
    """
    # imported here: scipy.signal imports scipy.stats, about a second in every process that loads a drive
    from scipy import signal
    lo, hi = f_center - bandwidth / 2.0, f_center + bandwidth / 2.0
    if not 0.0 < lo < hi < rate_hz / 2.0:
        raise DataError("imu_errors", "vibration_freq_hz/vibration_bandwidth_hz",
                        f"a band within (0, {rate_hz / 2} Hz)", f"[{lo}, {hi}] Hz")
    sos = signal.butter(2, [lo, hi], btype="bandpass", fs=rate_hz, output="sos")
    impulse = np.zeros(int(20 * rate_hz / max(bandwidth, 1e-3)) + 1000)
    impulse[0] = 1.0
    gain = np.sqrt(np.sum(signal.sosfilt(sos, impulse) ** 2))
    warm = int(10 * rate_hz / bandwidth) + 100  # discard the filter's start-up transient
    w = rng.standard_normal((n + warm, m))
    return signal.sosfilt(sos, w, axis=0)[warm:] / gain


def speed_envelope(speed, speed_ref: float, idle_fraction: float) -> np.ndarray:
    """Vibration level versus speed: ``idle + (1 - idle) min(1, speed / speed_ref)`` (dimensionless)."""
    speed = np.abs(np.asarray(speed, dtype=float))
    ratio = np.minimum(1.0, speed / speed_ref) if speed_ref > 0 else np.ones_like(speed)
    return idle_fraction + (1.0 - idle_fraction) * ratio


def _draw_matrix(rng, sf_tol, mis_tol):
    sf = rng.uniform(-1.0, 1.0, 3) * np.asarray(sf_tol) + 0.0  # + 0.0: no -0.0 in the recorded draws
    mis = rng.uniform(-1.0, 1.0, (3, 3)) * np.asarray(mis_tol)[:, None] + 0.0  # row i: cross-axis into axis i
    np.fill_diagonal(mis, 0.0)
    return sf, mis, np.eye(3) + np.diag(sf) + mis


def apply_imu_errors(imu: pd.DataFrame, params: dict, seed: int, speed=None) -> tuple[pd.DataFrame, dict, pd.DataFrame]:
    """Corrupt an error-free IMU table with the error model of the module docstring.

    Parameters
    ----------
    imu : DataFrame
        Error-free IMU table (CONTRIBUTING.md schema), uniform rate.
    params : dict
        Output of :func:`error_params`.
    seed : int
        Seed of every draw (``numpy.random.default_rng(seed)``); the draw order is fixed.
    speed : array_like, shape (len(imu),), optional
        Ground speed at the IMU epochs, m/s (vibration envelope); required when vibration is on.

    Returns
    -------
    imu_meas : DataFrame
        Measured IMU table.
    imu_errors : dict
        ``params`` plus ``seed``, ``realized`` and ``p0_*`` (module docstring).
    imu_bias : DataFrame
        ``time``, ``gyro_bias_x/y/z`` (rad/s), ``accel_bias_x/y/z`` (m/s^2): the additive bias
        ``b_fixed + b_turn_on + b_gm[k]``.
    """
    t = imu["time"].to_numpy(float)
    n = t.size
    dt = float(np.median(np.diff(t)))
    if n < 2 or np.abs(np.diff(t) - dt).max() > 1e-6 * max(dt, 1e-9) + 1e-9:
        raise DataError("imu", "time", "a uniform time grid", f"intervals {np.diff(t).min()}..{np.diff(t).max()}")
    rate = 1.0 / dt
    rng = np.random.default_rng(seed)
    out = {"time": t}
    bias_tab = {"time": t}
    realized = {}
    vib_on = any(np.any(np.asarray(params[f"vibration_{s}_std"]) > 0) for s in ("gyro", "accel"))
    if vib_on:
        if speed is None or np.asarray(speed).shape != (n,):
            raise DataError("imu_errors", "speed", f"ground speed at the {n} IMU epochs (vibration on)",
                            "nothing" if speed is None else f"shape {np.asarray(speed).shape}")
        env = speed_envelope(speed, params["vibration_speed_ref_mps"], params["vibration_idle_fraction"])
    for sensor in ("gyro", "accel"):
        x = imu[[f"{sensor}_{a}" for a in _AXES]].to_numpy(float)  # [n, 3]
        # Fixed draw order per sensor: turn-on bias, scale factor + misalignment, GM, white, vibration.
        turn_on = rng.standard_normal(3) * np.asarray(params[f"{sensor}_turn_on_bias_std"])
        sf, mis, mat = _draw_matrix(rng, params[f"{sensor}_scale_factor_tol"], params[f"{sensor}_misalignment_tol"])
        residual_std = params.get(f"{sensor}_boot_calibration_residual_std")
        boot = (turn_on + rng.standard_normal(3) * np.asarray(residual_std) if residual_std is not None
                else np.zeros(3))
        b_const = np.asarray(params[f"{sensor}_bias_fixed"]) + turn_on - boot
        b_gm = gauss_markov(n, dt, params[f"{sensor}_bias_instability"], params[f"{sensor}_bias_corr_time"], rng)
        white = rng.standard_normal((n, 3)) * (np.asarray(params[f"{sensor}_noise_density"]) / np.sqrt(dt))
        y = x @ mat.T + b_const + b_gm + white
        vstd = np.asarray(params[f"vibration_{sensor}_std"])
        if vib_on:
            vib = band_limited_noise(n, rate, params["vibration_freq_hz"], params["vibration_bandwidth_hz"], rng)
            y += vib * vstd * env[:, None]
        for i, a in enumerate(_AXES):
            out[f"{sensor}_{a}"] = y[:, i]
            bias_tab[f"{sensor}_bias_{a}"] = b_const[i] + b_gm[:, i]
        realized.update({
            f"{sensor}_turn_on_bias": turn_on.tolist(), f"{sensor}_boot_calibration": boot.tolist(),
            f"{sensor}_bias_constant": b_const.tolist(),
            f"{sensor}_scale_factor": sf.tolist(), f"{sensor}_misalignment": mis.tolist(),
            f"{sensor}_sensor_matrix": mat.tolist(),
        })
    errors = copy.deepcopy(params)
    errors["seed"] = int(seed)
    errors["realized"] = realized
    for sensor in ("gyro", "accel"):
        residual_std = params.get(f"{sensor}_boot_calibration_residual_std")
        constant_std = np.asarray(params[f"{sensor}_turn_on_bias_std"] if residual_std is None else residual_std)
        errors[f"p0_{sensor}_bias_std"] = np.sqrt(
            np.asarray(params[f"{sensor}_bias_fixed"]) ** 2 + constant_std ** 2
            + np.asarray(params[f"{sensor}_bias_instability"]) ** 2).tolist()
    return (pd.DataFrame(out, columns=list(imu.columns)), errors, pd.DataFrame(bias_tab))

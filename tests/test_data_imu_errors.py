"""IMU error models: statistics of each term, realized draws reproduce the output, determinism."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from bgfn.data.imu_errors import (DEG, EKINOX_D, G0, MPU6000, OPTIONAL_VECTOR_KEYS, VECTOR_KEYS, apply_imu_errors,
                                  band_limited_noise, error_params, gauss_markov, speed_envelope)
from bgfn.errors import DataError

RATE = 100.0
ZERO = {**{k: 0.0 for k in VECTOR_KEYS if not k.endswith("corr_time")}, **dict.fromkeys(OPTIONAL_VECTOR_KEYS)}


def still_imu(n, gyro=(0.0, 0.0, 0.0), accel=(0.0, 0.0, -9.81)):
    t = 1000.0 + np.arange(1, n + 1) / RATE
    cols = {"time": t}
    for i, a in enumerate("xyz"):
        cols[f"gyro_{a}"] = np.full(n, gyro[i])
    for i, a in enumerate("xyz"):
        cols[f"accel_{a}"] = np.full(n, accel[i])
    return pd.DataFrame(cols)


def test_profiles_hold_the_documented_values():
    ek, mpu = error_params("ekinox-d"), error_params("mpu6000")
    assert ek["gyro_noise_density"] == [1.58e-4, 1.60e-4, 1.81e-4] and ek["accel_bias_corr_time"] == [0.5, 2.0, 1.0]
    assert mpu["gyro_turn_on_bias_std"] == pytest.approx([np.radians(5.0)] * 3)
    assert mpu["accel_turn_on_bias_std"] == pytest.approx([0.060 * 9.80665] * 3)
    assert mpu["gyro_noise_density"] == pytest.approx([np.radians(0.005)] * 3)
    assert mpu["accel_noise_density"] == pytest.approx([400e-6 * 9.80665] * 3)
    assert mpu["gyro_scale_factor_tol"] == [0.03] * 3 and mpu["accel_misalignment_tol"] == [0.02] * 3


def test_white_noise_has_the_configured_std():
    n = 200_000
    params = error_params(EKINOX_D, {**ZERO, "gyro_noise_density": [1e-3, 2e-3, 3e-3], "accel_noise_density": 0.01})
    meas, _, _ = apply_imu_errors(still_imu(n), params, seed=3)
    g = meas[["gyro_x", "gyro_y", "gyro_z"]].to_numpy()
    a = meas[["accel_x", "accel_y", "accel_z"]].to_numpy() - [0.0, 0.0, -9.81]
    # mean rate over dt of white noise with density q: std q / sqrt(dt)
    np.testing.assert_allclose(g.std(axis=0), np.array([1e-3, 2e-3, 3e-3]) * np.sqrt(RATE), rtol=0.01)
    np.testing.assert_allclose(a.std(axis=0), 0.01 * np.sqrt(RATE), rtol=0.01)
    assert np.abs(g.mean(axis=0)).max() < 5 * 3e-3 * np.sqrt(RATE) / np.sqrt(n)
    assert abs(np.corrcoef(g[1:, 0], g[:-1, 0])[0, 1]) < 0.01  # white


def test_gauss_markov_stationary_std_and_correlation():
    sigma, tau, dt = np.array([2.0, 0.5]), np.array([1.0, 5.0]), 0.01
    x = gauss_markov(1_000_000, dt, sigma, tau, np.random.default_rng(7))
    np.testing.assert_allclose(x.std(axis=0), sigma, rtol=0.04)
    for i in range(2):
        lag = int(tau[i] / dt)
        rho = np.mean(x[lag:, i] * x[:-lag, i]) / np.var(x[:, i])
        assert rho == pytest.approx(np.exp(-1.0), abs=0.04)
    # started in the stationary law: the first samples already have std sigma (many short draws)
    starts = np.array([gauss_markov(2, dt, [1.0], [100.0], np.random.default_rng(s))[0, 0] for s in range(2000)])
    assert starts.std() == pytest.approx(1.0, rel=0.06)


def test_constant_terms_are_recorded_and_reproduce_the_output():
    x_gyro, x_acc = (0.1, -0.2, 0.3), (1.0, 2.0, -9.8)
    imu = still_imu(1000, x_gyro, x_acc)
    params = error_params(MPU6000, {"gyro_noise_density": 0.0, "accel_noise_density": 0.0,
                                    "gyro_bias_instability": 0.0, "accel_bias_instability": 0.0,
                                    "vibration_gyro_std": 0.0, "vibration_accel_std": 0.0})
    meas, errs, bias = apply_imu_errors(imu, params, seed=11)
    r = errs["realized"]
    for sensor, x in (("gyro", x_gyro), ("accel", x_acc)):
        mat = np.asarray(r[f"{sensor}_sensor_matrix"])
        expected = mat @ np.asarray(x) + np.asarray(r[f"{sensor}_bias_constant"])
        np.testing.assert_allclose(meas[[f"{sensor}_{a}" for a in "xyz"]].to_numpy(), np.tile(expected, (1000, 1)),
                                   atol=1e-12)
        assert np.all(np.abs(r[f"{sensor}_scale_factor"]) <= 0.03)
        mis = np.asarray(r[f"{sensor}_misalignment"])
        assert np.all(np.diag(mis) == 0) and np.all(np.abs(mis) <= 0.02) and np.any(mis != 0)
        b0 = bias[[f"{sensor}_bias_{a}" for a in "xyz"]].to_numpy()[0]
        np.testing.assert_allclose(b0, r[f"{sensor}_bias_constant"])
    # the gyro's 5 deg/s turn-on bias is boot-calibrated down to a 1 deg/s residual; the accel's is not
    assert errs["seed"] == 11 and errs["p0_gyro_bias_std"] == pytest.approx([np.radians(1.0)] * 3)
    assert errs["p0_accel_bias_std"] == pytest.approx([60e-3 * 9.80665] * 3)


def test_turn_on_biases_are_drawn_with_the_configured_spread():
    params = error_params(MPU6000)
    draws = np.array([apply_imu_errors(still_imu(10), params, seed=s, speed=np.zeros(10))[1]["realized"]
                      ["gyro_turn_on_bias"] for s in range(300)])
    assert draws.std() == pytest.approx(5.0 * DEG, rel=0.1)  # N(0, (5 deg/s)^2) per axis
    assert abs(draws.mean()) < 0.01


def test_boot_calibration_leaves_only_its_residual():
    params = error_params(MPU6000)
    real = [apply_imu_errors(still_imu(10), params, seed=s, speed=np.zeros(10))[1]["realized"] for s in range(300)]
    const = np.array([r["gyro_bias_constant"] for r in real])
    turn_on = np.array([r["gyro_turn_on_bias"] for r in real])
    boot = np.array([r["gyro_boot_calibration"] for r in real])
    np.testing.assert_allclose(const, turn_on - boot, atol=1e-15)
    assert const.std() == pytest.approx(1.0 * DEG, rel=0.1)  # residual N(0, (1 deg/s)^2), not 5 deg/s
    accel = np.array([r["accel_bias_constant"] for r in real])
    assert accel.std() == pytest.approx(60e-3 * 9.80665, rel=0.1)  # no accel calibration


def test_gm_bias_table_matches_configured_instability():
    params = error_params(EKINOX_D, {**ZERO, "accel_bias_instability": [0.01, 0.02, 0.03],
                                     "accel_bias_corr_time": [1.0, 1.0, 1.0]})
    meas, errs, bias = apply_imu_errors(still_imu(300_000), params, seed=5)
    b = bias[["accel_bias_x", "accel_bias_y", "accel_bias_z"]].to_numpy()
    np.testing.assert_allclose(b.std(axis=0), [0.01, 0.02, 0.03], rtol=0.05)
    np.testing.assert_allclose(meas["accel_z"].to_numpy() + 9.81, b[:, 2], atol=1e-12)  # bias is the only error


def test_vibration_level_band_and_speed_envelope():
    n = 100_000
    params = error_params(MPU6000, {**ZERO, "vibration_accel_std": [0.3, 0.3, 0.5], "vibration_gyro_std": 0.02})
    fast, _, _ = apply_imu_errors(still_imu(n), params, seed=1, speed=np.full(n, 20.0))
    stop, _, _ = apply_imu_errors(still_imu(n), params, seed=1, speed=np.zeros(n))
    a = fast[["accel_x", "accel_y", "accel_z"]].to_numpy() - [0.0, 0.0, -9.81]
    np.testing.assert_allclose(a.std(axis=0), [0.3, 0.3, 0.5], rtol=0.05)
    assert fast["gyro_y"].std() == pytest.approx(0.02, rel=0.05)
    assert stop["gyro_y"].std() == pytest.approx(0.02 * params["vibration_idle_fraction"], rel=0.05)
    # power in the 10-30 Hz band
    spec = np.abs(np.fft.rfft(a[:, 2])) ** 2
    f = np.fft.rfftfreq(n, 1 / RATE)
    assert spec[(f > 8) & (f < 32)].sum() / spec.sum() > 0.85
    assert speed_envelope([0.0, 5.0, 10.0, 30.0], 10.0, 0.3) == pytest.approx([0.3, 0.65, 1.0, 1.0])


def test_band_limited_noise_is_unit_variance_and_rejects_bad_band():
    x = band_limited_noise(200_000, RATE, 20.0, 10.0, np.random.default_rng(0))
    np.testing.assert_allclose(x.std(axis=0), 1.0, rtol=0.03)
    with pytest.raises(DataError, match="vibration_freq_hz"):
        band_limited_noise(100, RATE, 45.0, 20.0, np.random.default_rng(0))


def test_same_seed_same_output_different_seed_differs():
    imu = still_imu(5000)
    speed = np.full(5000, 8.0)
    a = apply_imu_errors(imu, error_params("mpu6000"), 42, speed)
    b = apply_imu_errors(imu, error_params("mpu6000"), 42, speed)
    c = apply_imu_errors(imu, error_params("mpu6000"), 43, speed)
    pd.testing.assert_frame_equal(a[0], b[0])
    pd.testing.assert_frame_equal(a[2], b[2])
    assert a[1] == b[1]
    assert not np.allclose(a[0]["gyro_x"], c[0]["gyro_x"])


def test_bad_parameters_raise():
    with pytest.raises(DataError, match="gyro_noise_density"):
        error_params("mpu6000", {"gyro_noise_density": -1.0})
    with pytest.raises(DataError, match="accel_bias_corr_time"):
        error_params("mpu6000", {"accel_bias_corr_time": [1.0, 0.0, 1.0]})
    with pytest.raises(DataError, match="gyro_bias_stability"):
        error_params("mpu6000", {"gyro_bias_stability": 1.0})
    with pytest.raises(DataError, match="profile"):
        error_params("adxl")
    with pytest.raises(DataError, match="speed"):
        apply_imu_errors(still_imu(10), error_params("mpu6000"), 0)  # vibration needs the speed
    assert G0 == 9.80665

"""IMU levels measured on a drive: white noise and vibration of known size are recovered."""

import numpy as np
import pandas as pd
import pytest

from bgfn.data.imu_errors import band_limited_noise
from bgfn.data.imu_levels import (imu_levels, imu_psd, level_summary, motion_states, vibration_overrides)
from bgfn.errors import DataError

RATE = 100.0


class _Drive:
    def __init__(self, name, imu, reference):
        self.name, self.imu, self.reference, self.meta = name, imu, reference, {"platform": "car"}


def _drive(n=60_000, gyro_nd=1e-3, accel_nd=4e-3, vib_gyro=0.02, vib_accel=0.4, idle=0.25, seed=0):
    """First third still, the rest driving at 10 m/s; white noise of density `nd` on every axis (std
    nd * sqrt(rate)) plus band-limited vibration (20 +- 10 Hz) of std `vib`, `idle` times that at rest."""
    rng = np.random.default_rng(seed)
    t = np.arange(1, n + 1) / RATE
    speed = np.where(t < t[-1] / 3, 0.0, 10.0)
    env = np.where(speed > 0, 1.0, idle)[:, None]
    cols = {"time": t}
    for sensor, nd, vib in (("gyro", gyro_nd, vib_gyro), ("accel", accel_nd, vib_accel)):
        white = rng.standard_normal((n, 3)) * nd * np.sqrt(RATE)
        v = band_limited_noise(n, RATE, 20.0, 20.0, rng) * vib * env
        for k, a in enumerate("xyz"):
            cols[f"{sensor}_{a}"] = white[:, k] + v[:, k]
    cols["accel_z"] = cols["accel_z"] - 9.81
    imu = pd.DataFrame(cols)
    ref = pd.DataFrame({"time": t, "v_n": speed, "v_e": 0.0 * speed})
    return _Drive("sim", imu, ref)


def test_states_from_reference_speed():
    d = _drive(n=3000)
    s = motion_states(d)
    assert (s.iloc[60:900] == "still").all() and (s.iloc[:40] == "").all()   # stops trimmed by TRIM_S
    assert (s.iloc[1100:] == "driving").all()


def test_white_noise_density_recovered_at_rest():
    d = _drive(vib_gyro=0.0, vib_accel=0.0)
    lv = imu_levels(d)
    still = lv[lv["state"] == "still"].set_index(["sensor", "axis"])["density"]
    assert np.allclose(still.loc["gyro"], 1e-3, rtol=0.05)
    assert np.allclose(still.loc["accel"], 4e-3, rtol=0.05)
    # gravity stays in the raw mean, not in the high-passed level
    az = lv[(lv["sensor"] == "accel") & (lv["axis"] == "z") & (lv["state"] == "still")]
    assert az["mean"].iloc[0] == pytest.approx(-9.81, abs=0.01)


def test_vibration_and_idle_fraction_recovered():
    d = _drive()
    lv = imu_levels(d)
    ov = vibration_overrides(lv, {"gyro": [1e-3] * 3, "accel": [4e-3] * 3})
    assert np.allclose(ov["vibration_gyro_std"], 0.02, rtol=0.08)
    assert np.allclose(ov["vibration_accel_std"], 0.4, rtol=0.08)
    assert ov["vibration_idle_fraction"] == pytest.approx(0.25, abs=0.04)
    summary = level_summary(lv).set_index("sensor")
    # driving level = sqrt(white^2 band + vib^2): by hand for the accelerometer
    expected = np.sqrt(4e-3 ** 2 * (100.0 - 2 * 5.0) + 0.4 ** 2)  # B about f_s - 2 f_hp
    assert summary.loc["accel", "driving"] == pytest.approx(expected, rel=0.08)
    assert summary.loc["accel", "ratio"] > 2.0


def test_psd_peaks_in_the_vibration_band():
    d = _drive(gyro_nd=1e-5, accel_nd=1e-5)
    psd = imu_psd(d, "driving")
    peak = psd.loc[psd["accel_x"].idxmax(), "freq_hz"]
    assert 10.0 <= peak <= 30.0


def test_overrides_need_one_drive_with_both_states():
    d = _drive(n=3000)
    lv = imu_levels(d)
    with pytest.raises(DataError, match="three axes"):
        vibration_overrides(lv[lv["state"] == "driving"], {"gyro": [0.0] * 3, "accel": [0.0] * 3})
    two = pd.concat([lv, lv.assign(dataset="other")])
    with pytest.raises(DataError, match="one drive"):
        vibration_overrides(two, {"gyro": [0.0] * 3, "accel": [0.0] * 3})


def test_stand_in_vibration_is_the_real_drives():
    """The profiles' field-test stand-in vibrates as the recorded car's IMU does (deviations page)."""
    from bgfn.profile_schema import load_profile
    from bgfn.data import load_drive
    from bgfn.data.acquire import MissingFileError
    from bgfn.data.imu_errors import MPU6000

    try:
        real = load_drive("rtklib-drive0708")
    except (MissingFileError, DataError) as exc:
        pytest.skip(f"real drive not available: {exc}")
    implied = vibration_overrides(imu_levels(real), {"gyro": MPU6000["gyro_noise_density"],
                                                     "accel": MPU6000["accel_noise_density"]})
    for profile in ("smoke", "quick", "paper"):
        set_ = load_profile(profile)["data"]["turin-sim-mpu6000"]["imu_errors"]
        for key in ("vibration_gyro_std", "vibration_accel_std"):
            assert np.allclose(set_[key], implied[key], rtol=0.03), (profile, key)
        assert set_["vibration_idle_fraction"] == pytest.approx(implied["vibration_idle_fraction"], abs=0.01)
        assert set_["vibration_speed_ref_mps"] == implied["vibration_speed_ref_mps"]

"""GNSS: lever arm geometry (hand-computed), simulated error statistics, decimation."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from bgfn.data.gnss import antenna_position, decimate, fix_errors, simulate_fixes
from bgfn.errors import DataError
from bgfn.nav.earth import curvature_radii

LAT0, LON0, H0 = np.radians(45.06), np.radians(7.66), 250.0


def still_truth(n, rate=1.0, yaw=0.0, roll=0.0):
    return pd.DataFrame({"time": 5000.0 + np.arange(n) / rate, "lat": LAT0, "lon": LON0, "h": H0,
                         "v_n": 0.0, "v_e": 0.0, "v_d": 0.0, "roll": roll, "pitch": 0.0, "yaw": yaw})


def ned_of(lat, lon, h):
    r_m, r_n = curvature_radii(LAT0)
    return np.column_stack([(lat - LAT0) * (r_m + H0), (lon - LON0) * (r_n + H0) * np.cos(LAT0), -(h - H0)])


@pytest.mark.parametrize("yaw,roll,arm,expected", [
    (0.0, 0.0, [1.0, 0.0, 0.0], [1.0, 0.0, 0.0]),             # forward = north
    (np.pi / 2, 0.0, [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]),       # heading east: forward = east
    (np.pi / 2, 0.0, [0.0, 1.0, 0.0], [-1.0, 0.0, 0.0]),      # right of an east-heading car = south
    (0.0, 0.0, [0.0, 0.0, -0.219], [0.0, 0.0, -0.219]),       # antenna above the IMU
    (0.0, np.pi / 2, [0.0, 0.0, -1.0], [0.0, 1.0, 0.0]),      # rolled 90 deg right: body -z points east
])
def test_antenna_lever_arm_geometry(yaw, roll, arm, expected):
    lat, lon, h = antenna_position(still_truth(1, yaw=yaw, roll=roll), arm)
    np.testing.assert_allclose(ned_of(lat, lon, h)[0], expected, atol=1e-6)


def test_noise_free_fixes_are_the_antenna_positions():
    truth = still_truth(1001, rate=100.0, yaw=0.3)
    gnss, err = simulate_fixes(truth, [-0.369, 0.0, -0.219], seed=0, rate_hz=1.0, white_std_m=0.0,
                               correlated_std_m=0.0)
    assert list(gnss["time"]) == [5000.0 + k for k in range(11)]  # 1 Hz epochs on the IMU grid
    lat, lon, h = antenna_position(truth.iloc[::100], [-0.369, 0.0, -0.219])
    np.testing.assert_allclose(gnss["lat"], lat, atol=1e-15)
    np.testing.assert_allclose(gnss["h"], h, atol=1e-9)
    assert gnss[["v_n", "v_e", "v_d"]].isna().all().all()
    assert np.all(err[["err_n", "err_e", "err_d"]].to_numpy() == 0.0)


def test_fix_errors_recover_the_simulated_errors_at_the_antenna():
    truth = still_truth(3001, rate=100.0, yaw=1.2)
    arm = [-0.369, 0.2, -0.219]
    gnss, err = simulate_fixes(truth, arm, seed=4, rate_hz=1.0, white_std_m=(0.3, 0.5, 0.6),
                               correlated_std_m=(1.0, 1.0, 2.0))
    got = fix_errors(gnss, truth, arm)
    assert list(got.columns) == ["time", "north_m", "east_m", "down_m"] and len(got) == 31
    np.testing.assert_allclose(got[["north_m", "east_m", "down_m"]], err[["err_n", "err_e", "err_d"]], atol=1e-6)
    # measured against the IMU instead of the antenna, the lever arm (rotated by the yaw) shows up
    at_imu = fix_errors(gnss, truth, [0.0, 0.0, 0.0])
    d = (at_imu[["north_m", "east_m"]] - got[["north_m", "east_m"]]).to_numpy()
    c, s_ = np.cos(1.2), np.sin(1.2)
    np.testing.assert_allclose(d, np.tile([c * arm[0] - s_ * arm[1], s_ * arm[0] + c * arm[1]], (31, 1)), atol=1e-6)
    # fixes outside the truth's span are left out
    assert len(fix_errors(gnss, truth.iloc[:1001], arm)) == 11


def test_simulated_errors_have_configured_statistics():
    truth = still_truth(200_000)
    gnss, err = simulate_fixes(truth, [0.0, 0.0, 0.0], seed=4, white_std_m=[0.3, 0.3, 0.6],
                               correlated_std_m=[1.0, 1.0, 2.0], correlated_tau_s=60.0)
    e = err[["err_n", "err_e", "err_d"]].to_numpy()
    total = np.sqrt(np.array([0.3, 0.3, 0.6]) ** 2 + np.array([1.0, 1.0, 2.0]) ** 2)
    np.testing.assert_allclose(e.std(axis=0), total, rtol=0.05)
    np.testing.assert_allclose(gnss[["std_n", "std_e", "std_d"]].iloc[0], total)
    # the fix really is displaced by the recorded error
    np.testing.assert_allclose(ned_of(gnss["lat"], gnss["lon"], gnss["h"]), e, atol=1e-6)
    # time correlation: lag 60 s keeps exp(-1) of the correlated variance, the white part decorrelates
    lag = 60
    rho = np.mean(e[lag:, 0] * e[:-lag, 0]) / np.var(e[:, 0])
    assert rho == pytest.approx(np.exp(-1) * 1.0 / (1.0 + 0.09), abs=0.05)
    d = np.diff(e[:, 0])  # increments: white part dominates at 1 s
    assert d.std() == pytest.approx(np.sqrt(2 * 0.09 + 2 * (1 - np.exp(-1 / 60))), rel=0.05)


def test_seeded():
    truth = still_truth(100)
    a = simulate_fixes(truth, [0, 0, 0], seed=1)[0]
    b = simulate_fixes(truth, [0, 0, 0], seed=1)[0]
    c = simulate_fixes(truth, [0, 0, 0], seed=2)[0]
    pd.testing.assert_frame_equal(a, b)
    assert np.abs(a["h"] - c["h"]).max() > 0.1  # metres apart


def test_decimate_5hz_to_1hz():
    g = pd.DataFrame({"time": 100.005 + np.arange(50) * 0.2, "lat": np.arange(50.0)})
    d = decimate(g, 5.0, 1.0)
    np.testing.assert_allclose(d["time"], 100.005 + np.arange(10), atol=1e-9)
    assert list(d["lat"]) == [0.0, 5.0, 10.0, 15.0, 20.0, 25.0, 30.0, 35.0, 40.0, 45.0]
    assert len(decimate(g, 5.0, 5.0)) == 50
    with pytest.raises(DataError, match="gnss_rate_hz"):
        decimate(g, 5.0, 2.0)

"""Strapdown mechanization: physics cases with analytic IMU readings, exact inverse, pyins cross-check."""

import warnings

import numpy as np
import pandas as pd
import pytest
from scipy.integrate import solve_ivp

from bgfn.errors import DataError
from bgfn import schema
from bgfn.nav import earth, sim, strapdown, transform

LAT0, LON0, H0 = np.radians(45.06), np.radians(7.66), 250.0


def _gauss_mean(fun, t0, t1, n=5):
    """Mean of fun(t) (vectorized, returns (T, 3)) over each interval [t0[k], t1[k]]."""
    x, w = np.polynomial.legendre.leggauss(n)
    mid, half = 0.5 * (t0 + t1), 0.5 * (t1 - t0)
    return sum(wi * fun(mid + half * xi) for xi, wi in zip(x, w)) / 2.0


def test_stationary_level_imu_stays_within_1mm_for_10_minutes():
    rate, duration = 100.0, 600.0
    t = np.arange(1, int(rate * duration) + 1) / rate
    yaw = 0.7
    c_bn = transform.dcm_from_euler(0.0, 0.0, yaw)
    gyro = c_bn.T @ earth.earth_rate_n(LAT0)  # perfect readings: Earth rate in body
    g = earth.normal_gravity(LAT0, H0)
    imu = pd.DataFrame({"time": t, "gyro_x": gyro[0], "gyro_y": gyro[1], "gyro_z": gyro[2],
                        "accel_x": 0.0, "accel_y": 0.0, "accel_z": -g})
    init = pd.Series({"time": 0.0, "lat": LAT0, "lon": LON0, "h": H0, "v_n": 0.0, "v_e": 0.0, "v_d": 0.0,
                      "roll": 0.0, "pitch": 0.0, "yaw": yaw})
    out = strapdown.integrate(init, imu)
    assert len(out) == t.size + 1 and out["time"].iloc[-1] == pytest.approx(duration)
    ned = earth.lla_to_ned(out["lat"].to_numpy(), out["lon"].to_numpy(), out["h"].to_numpy(), LAT0, LON0, H0)
    assert np.abs(ned).max() < 1e-3
    assert np.abs(out[["v_n", "v_e", "v_d"]].to_numpy()).max() < 1e-5
    assert np.abs(transform.wrap_angle(out["yaw"] - yaw)).max() < 1e-9


def test_constant_speed_level_circle_within_10cm_after_60s():
    """10 m/s on a 50 m radius, level, clockwise; IMU from the closed-form motion (not sim.py)."""
    speed, radius, rate, duration = 10.0, 50.0, 100.0, 60.0
    w = speed / radius  # yaw rate, rad/s

    def v_ned(t):
        return np.stack([speed * np.cos(w * t), speed * np.sin(w * t), np.zeros_like(t)], -1)

    def rhs(t, y):  # exact position ODE for the given NED velocity at constant height
        r_m, r_n = earth.curvature_radii(y[0])
        v = v_ned(np.atleast_1d(t))[0]
        return [v[0] / (r_m + H0), v[1] / ((r_n + H0) * np.cos(y[0]))]

    sol = solve_ivp(rhs, (0, duration), [LAT0, LON0], rtol=1e-13, atol=1e-16, dense_output=True,
                    method="DOP853")

    def gyro_true(t):  # omega_ib^b = psi_dot e_z + C_nb omega_in^n
        lat = sol.sol(t)[0]
        v = v_ned(t)
        w_in = earth.earth_rate_n(lat) + earth.transport_rate_n(lat, H0, v)
        c_nb = np.swapaxes(transform.dcm_from_euler(0.0, 0.0, w * t), -1, -2)
        return np.einsum("tij,tj->ti", c_nb, w_in) + np.array([0.0, 0.0, w])

    def accel_true(t):  # f^b = C_nb (v_dot + (2 w_ie + w_en) x v - g^n)
        lat = sol.sol(t)[0]
        v = v_ned(t)
        v_dot = np.stack([-speed * w * np.sin(w * t), speed * w * np.cos(w * t), np.zeros_like(t)], -1)
        cor = np.cross(2 * earth.earth_rate_n(lat) + earth.transport_rate_n(lat, H0, v), v)
        g_n = np.zeros_like(v)
        g_n[:, 2] = earth.normal_gravity(lat, H0)
        c_nb = np.swapaxes(transform.dcm_from_euler(0.0, 0.0, w * t), -1, -2)
        return np.einsum("tij,tj->ti", c_nb, v_dot + cor - g_n)

    t = np.arange(int(rate * duration) + 1) / rate
    gyro = _gauss_mean(gyro_true, t[:-1], t[1:])
    accel = _gauss_mean(accel_true, t[:-1], t[1:])
    imu = pd.DataFrame(np.column_stack([t[1:], gyro, accel]), columns=list(schema.IMU_COLUMNS))
    # Sanity of the analytic readings: centripetal acceleration to the right, yaw rate w.
    assert accel[:, 1].mean() == pytest.approx(speed * w, rel=1e-3)
    assert gyro[:, 2].mean() == pytest.approx(w, rel=1e-3)
    init = pd.Series({"time": 0.0, "lat": LAT0, "lon": LON0, "h": H0, "v_n": speed, "v_e": 0.0, "v_d": 0.0,
                      "roll": 0.0, "pitch": 0.0, "yaw": 0.0})
    out = strapdown.integrate(init, imu)
    lat_true, lon_true = sol.sol(t)
    err = earth.lla_to_ned(out["lat"].to_numpy(), out["lon"].to_numpy(), out["h"].to_numpy(),
                           lat_true, lon_true, H0)
    assert np.linalg.norm(err[-1]) < 0.1
    assert np.abs(err).max() < 0.1
    np.testing.assert_allclose(out[["v_n", "v_e", "v_d"]].to_numpy(), v_ned(t), atol=5e-3)
    # The vehicle went around 60*0.2/(2 pi) = 1.9 times: the check is not trivially short.
    assert w * duration > 2 * np.pi


def test_propagate_matches_integrate_kernel():
    ref = sim.demo_trajectory(2.0)
    imu = sim.imu_from_trajectory(ref)
    r0 = ref.iloc[0]
    pos, v, c = strapdown.state_from_row(r0)
    lat, lon, h, v1, c1 = strapdown.propagate(pos[0], pos[1], pos[2], v, c,
                                              imu.iloc[0][list(schema.GYRO_COLUMNS)].to_numpy(float),
                                              imu.iloc[0][list(schema.ACCEL_COLUMNS)].to_numpy(float), 0.01)
    out = strapdown.integrate(r0, imu.iloc[:1])
    assert out["lat"].iloc[1] == lat and out["lon"].iloc[1] == lon and out["h"].iloc[1] == h
    np.testing.assert_array_equal(out[["v_n", "v_e", "v_d"]].iloc[1].to_numpy(), v1)


@pytest.mark.parametrize("start", [0, 12345])
def test_sim_is_exact_inverse_on_curvy_3d_trajectory(start):
    ref = sim.demo_trajectory(300.0)
    imu = sim.imu_from_trajectory(ref)
    assert len(imu) == len(ref) - 1
    np.testing.assert_array_equal(imu["time"].to_numpy(), ref["time"].to_numpy()[1:])
    out = strapdown.integrate(ref.iloc[start], imu)
    sub = ref.iloc[start:].reset_index(drop=True)
    np.testing.assert_allclose(out[["v_n", "v_e", "v_d"]], sub[["v_n", "v_e", "v_d"]], atol=1e-9)
    for col in ("roll", "pitch", "yaw"):
        assert np.abs(transform.wrap_angle(out[col] - sub[col])).max() < 1e-12
    ned = earth.lla_to_ned(out["lat"].to_numpy(), out["lon"].to_numpy(), out["h"].to_numpy(),
                           sub["lat"].to_numpy(), sub["lon"].to_numpy(), sub["h"].to_numpy())
    assert np.abs(ned).max() < 1e-6
    # The trajectory is really 3D and curvy.
    assert np.ptp(ref["h"]) > 5.0 and np.ptp(np.unwrap(ref["yaw"])) > 3.0


def test_inverse_position_error_is_trapezoid_error():
    """Positions not made by the trapezoid rule: error stays at the trapezoid-rule level (well below 1 mm)."""
    ref = sim.demo_trajectory(120.0, rate_hz=100.0)
    # Replace positions by a 10x finer trapezoid integral of the same velocities (nearly exact).
    fine = sim.demo_trajectory(120.0, rate_hz=1000.0).iloc[::10].reset_index(drop=True)
    ref[["lat", "lon", "h"]] = fine[["lat", "lon", "h"]].to_numpy()
    out = strapdown.integrate(ref.iloc[0], sim.imu_from_trajectory(ref))
    ned = earth.lla_to_ned(out["lat"].to_numpy(), out["lon"].to_numpy(), out["h"].to_numpy(),
                           ref["lat"].to_numpy(), ref["lon"].to_numpy(), ref["h"].to_numpy())
    assert 1e-7 < np.abs(ned).max() < 1e-4


def test_against_pyins_generate_imu_and_integrator():
    pytest.importorskip("pyins")
    from pyins import sim as psim, strapdown as pstrap

    ref = sim.demo_trajectory(120.0)
    t = ref["time"].to_numpy()
    lla = np.column_stack([np.degrees(ref["lat"]), np.degrees(ref["lon"]), ref["h"]])
    rph = np.column_stack([np.degrees(ref["roll"]), np.degrees(ref["pitch"]), np.degrees(ref["yaw"])])
    vel = ref[["v_n", "v_e", "v_d"]].to_numpy()
    traj, inc = psim.generate_imu(t, lla, rph, vel, sensor_type="increment")
    dt = np.diff(t)[:, None]
    imu = pd.DataFrame(np.column_stack([t[1:], inc.to_numpy()[1:, :3] / dt, inc.to_numpy()[1:, 3:] / dt]),
                       columns=list(schema.IMU_COLUMNS))
    ours = sim.imu_from_trajectory(ref)
    # pyins (spline, with Earth rotation in inertial frame) and our inverse agree on the mean rates.
    np.testing.assert_allclose(imu[list(schema.GYRO_COLUMNS)], ours[list(schema.GYRO_COLUMNS)], atol=2e-6)
    np.testing.assert_allclose(imu[list(schema.ACCEL_COLUMNS)], ours[list(schema.ACCEL_COLUMNS)], atol=2e-3)
    # Our strapdown on pyins' increments and pyins' strapdown on the same: both follow the truth.
    out = strapdown.integrate(ref.iloc[0], imu)
    err_ours = earth.lla_to_ned(out["lat"].to_numpy(), out["lon"].to_numpy(), out["h"].to_numpy(),
                                ref["lat"].to_numpy(), ref["lon"].to_numpy(), ref["h"].to_numpy())
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # pandas deprecation inside pyins 1.0.1
        integ = pstrap.Integrator(traj.iloc[0])
        res = integ.integrate(pstrap.compute_increments_from_imu(inc, "increment"))
    err_py = earth.lla_to_ned(np.radians(res["lat"].to_numpy()), np.radians(res["lon"].to_numpy()),
                              res["alt"].to_numpy(), ref["lat"].to_numpy(), ref["lon"].to_numpy(),
                              ref["h"].to_numpy())
    h_ours = np.hypot(err_ours[:, 0], err_ours[:, 1]).max()
    h_py = np.hypot(err_py[:, 0], err_py[:, 1]).max()
    assert h_ours < 0.01 and h_py < 0.01


def test_bad_imu_input_raises():
    ref = sim.demo_trajectory(5.0)
    imu = sim.imu_from_trajectory(ref)
    gap = imu.drop(index=range(100, 107))  # 7 missing samples
    with pytest.raises(DataError, match="gap"):
        strapdown.integrate(ref.iloc[0], gap)
    with pytest.raises(DataError, match="accel_z"):
        strapdown.integrate(ref.iloc[0], imu.drop(columns="accel_z"))
    with pytest.raises(DataError, match="after the initial epoch"):
        strapdown.integrate(ref.iloc[-1], imu)
    nan = imu.copy()
    nan.loc[10, "gyro_x"] = np.nan
    with pytest.raises(DataError, match="finite"):
        strapdown.integrate(ref.iloc[0], nan)
    # Up to 5 missing samples is tolerated (treated as one longer step).
    strapdown.integrate(ref.iloc[0], imu.drop(index=range(100, 104)))

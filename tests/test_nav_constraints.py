"""The vehicle constraints (bgfn.nav.constraints): NHC and ZUPT measurements, the stillness detector, the vehicle
frame, and what they do to an unaided INS on simulated drives (bgfn.nav.sim)."""

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from bgfn.data import Drive
from bgfn.data import imu_errors as ie
from bgfn.errors import DataError
from bgfn.nav import baseline, metrics, sim, transform
from bgfn.nav import constraints as cn
from bgfn.nav import error_model as em
from bgfn.nav import state as st
from bgfn.nav.filter import run_filter, run_outage
from bgfn.report import aid_words

RATE = 100.0
#: Road azimuth of the straight drives, rad.
ROAD_YAW = 0.5
EKINOX = ie.error_params("ekinox-d")


def _road(speed, yaw=ROAD_YAW):
    """Level straight road at azimuth ``yaw`` with a speed history (m/s at 100 Hz from t = 0)."""
    t = np.arange(len(speed)) / RATE
    v = np.stack([speed * np.cos(yaw), speed * np.sin(yaw), np.zeros_like(t)], axis=-1)
    pos = sim.positions_from_velocity(t, v, np.radians(45.0), np.radians(7.6), 250.0)
    zero = np.zeros_like(t)
    return pd.DataFrame({"time": t, "lat": pos[:, 0], "lon": pos[:, 1], "h": pos[:, 2], "v_n": v[:, 0],
                         "v_e": v[:, 1], "v_d": v[:, 2], "roll": zero, "pitch": zero, "yaw": zero + yaw})


def _imu(ref, seed=0, noise=True, **bias):
    """Error-free IMU of ``ref`` plus the Ekinox-D white noise (seeded) and constant biases ``column=value``."""
    imu = sim.imu_from_trajectory(ref)
    rng = np.random.default_rng(seed)
    for s in ("gyro", "accel"):
        for i, a in enumerate("xyz"):
            if noise:
                imu[f"{s}_{a}"] += rng.standard_normal(len(imu)) * EKINOX[f"{s}_noise_density"][i] * np.sqrt(RATE)
    for col, value in bias.items():
        imu[col] += value
    return imu


def _start(ref):
    """The true state at the first row with a small P0 (the filter knows nothing of the injected biases)."""
    noise = st.noise_from_imu_errors(EKINOX)
    P0 = st.initial_covariance(ref.iloc[0][["lat", "lon", "h"]].to_numpy(float), noise, 0.1, 0.1, 0.02,
                               np.radians(0.05), np.radians(0.1))
    return st.initial_state(ref.iloc[0], P0), noise


def _cross_along(res, ref):
    e = metrics.navigation_errors(res.trajectory, ref)
    cross = -e["north"] * np.sin(ROAD_YAW) + e["east"] * np.cos(ROAD_YAW)
    along = e["north"] * np.cos(ROAD_YAW) + e["east"] * np.sin(ROAD_YAW)
    return cross.to_numpy(), along.to_numpy(), e


def _body_frame(**kw):
    """Constraints in the IMU body frame (the simulated vehicle's), defaults otherwise."""
    return cn.ConstraintConfig(mounting="none", **kw)


# ----------------------------------------------------------------------------------------------- measurements
@pytest.mark.parametrize("tangents", [(0.0, 0.0), (0.02, -0.015)])
def test_nhc_jacobian_is_the_linearized_measurement(tangents):
    """dz(computed) - dz(true) = H x for small errors x with the filter's conventions (error_model docstring)."""
    rng = np.random.default_rng(1)
    r_vb = cn.vehicle_rotation(tangents)
    for _ in range(5):
        c_t = transform.dcm_from_euler(*rng.uniform(-0.2, 0.2, 2), rng.uniform(-3, 3))
        v_t = rng.normal(0.0, 8.0, 3)
        x = np.zeros(em.N_STATES)
        phi, dv = rng.normal(0, 1e-5, 3), rng.normal(0, 1e-4, 3)
        x[em.PHI_NED], x[em.DV_NED] = phi, dv
        c_c = transform.dcm_from_rotvec(-phi) @ c_t              # C_computed = (I - [phi]) C_true
        out = []
        for c, v in ((c_c, v_t + dv), (c_t, v_t)):
            dz, H = np.empty(2), np.empty((2, em.N_STATES))
            cn.nhc_measurement(v, c, r_vb, dz, H)
            out.append((dz, H))
        np.testing.assert_allclose(out[0][0] - out[1][0], out[0][1] @ x, rtol=0, atol=1e-8)
        # the true vehicle-frame velocity of the measurement rows
        np.testing.assert_allclose(out[1][0], (r_vb @ c_t.T @ v_t)[list(cn.NHC_AXES)], rtol=1e-12)
    dz, H = np.empty(3), np.empty((3, em.N_STATES))
    cn.zupt_measurement(np.array([0.1, -0.2, 0.3]), dz, H)
    np.testing.assert_array_equal(dz, [0.1, -0.2, 0.3])
    np.testing.assert_array_equal(H[:, em.DV_NED], np.eye(3))
    assert np.count_nonzero(H) == 3


def test_vehicle_rotation_maps_the_estimated_direction_to_the_x_axis():
    r = cn.vehicle_rotation((np.tan(np.radians(1.0)), np.tan(np.radians(-2.0))))
    np.testing.assert_allclose(r @ r.T, np.eye(3), atol=1e-15)
    assert np.linalg.det(r) == pytest.approx(1.0)
    u = np.array([1.0, np.tan(np.radians(1.0)), np.tan(np.radians(-2.0))])
    np.testing.assert_allclose(r @ u, [np.linalg.norm(u), 0.0, 0.0], atol=1e-15)
    out = np.empty((3, 3))
    cn.vehicle_rotation_nb(u[1], u[2], out)
    np.testing.assert_allclose(out, r, atol=1e-15)
    np.testing.assert_allclose(cn.vehicle_rotation((0.0, 0.0)), np.eye(3), atol=0)


def test_mounting_track_recovers_an_imu_mounted_off_the_direction_of_travel():
    """A body frame turned by 1 deg yaw and -0.8 deg pitch from the vehicle: the running estimate converges to it,
    and it is causal (a value after t uses only epochs up to t)."""
    ref = sim.demo_trajectory(300.0)
    c_v = transform.dcm_from_euler(ref["roll"].to_numpy(), ref["pitch"].to_numpy(), ref["yaw"].to_numpy())
    r_bv = transform.dcm_from_euler(0.0, np.radians(-0.8), np.radians(1.0))      # body -> vehicle
    roll, pitch, yaw = transform.euler_from_dcm(c_v @ r_bv)                      # C_bn = C_vn R_bv
    body = ref.assign(roll=roll, pitch=pitch, yaw=yaw)
    t, tangents = cn.mounting_track(body, cn.ConstraintConfig(mounting_min_speed_mps=5.0))
    # the vehicle's x axis in the body frame: R_bv^T e_x
    x_v = r_bv.T @ [1.0, 0.0, 0.0]
    np.testing.assert_allclose(tangents[-1], x_v[1:] / x_v[0], atol=2e-4)       # < 0.012 deg
    half = len(body) // 2
    _, early = cn.mounting_track(body.iloc[:half], cn.ConstraintConfig(mounting_min_speed_mps=5.0))
    np.testing.assert_array_equal(early, tangents[:half])
    # no epoch above the speed: the body frame
    assert np.all(cn.mounting_track(body, cn.ConstraintConfig(mounting_min_speed_mps=100.0))[1] == 0.0)
    assert cn.mounting_track(body, cn.ConstraintConfig(mounting="none"))[1].size == 0


def test_mounting_weighted_by_heading_variance_ignores_a_heading_still_converging():
    """A solution whose heading is 15 deg off for its first minute (a self-aligned filter finding its heading, std
    20 deg) and right afterwards (std 0.5 deg): the heading error enters v^b_y / v^b_x one for one, so the equal
    mean still holds a share of the 15 deg at the end, while the inverse-variance weights leave the true 1 deg."""
    ref = sim.demo_trajectory(300.0)
    t = ref["time"].to_numpy(float)
    early = t < t[0] + 60.0
    c_v = transform.dcm_from_euler(ref["roll"].to_numpy(), ref["pitch"].to_numpy(), ref["yaw"].to_numpy())
    r_bv = transform.dcm_from_euler(0.0, 0.0, np.radians(1.0))                   # body -> vehicle: 1 deg yaw
    roll, pitch, yaw = transform.euler_from_dcm(c_v @ r_bv)
    body = ref.assign(roll=roll, pitch=pitch, yaw=yaw + np.where(early, np.radians(15.0), 0.0))
    std = np.where(early, np.radians(20.0), np.radians(0.5))
    truth = np.tan(np.radians(-1.0))                                             # vehicle x in the body frame
    heading = cn.ConstraintConfig(mounting_min_speed_mps=5.0)                    # mounting_weight: heading
    equal = cn.ConstraintConfig(mounting_min_speed_mps=5.0, mounting_weight="equal")
    weighted = cn.mounting_track(body, heading, std)[1][-1, 0]
    plain = cn.mounting_track(body, equal, std)[1][-1, 0]
    assert abs(np.degrees(np.arctan(weighted) - np.arctan(truth))) < 0.05
    assert abs(np.degrees(np.arctan(plain) - np.arctan(truth))) > 1.0
    np.testing.assert_array_equal(cn.mounting_track(body, heading)[1], cn.mounting_track(body, equal, std)[1])
    with pytest.raises(DataError, match="heading_std"):
        cn.mounting_track(body, heading, std[:-1])
    with pytest.raises(DataError, match="mounting_weight"):
        cn.constraint_config({"nhc": {"mounting_weight": "speed"}})


# ----------------------------------------------------------------------------------------------- detector
@pytest.mark.parametrize("model", ["ekinox-d", "mpu6000"])
def test_detector_fires_on_a_still_span_and_not_while_driving(model):
    params = ie.error_params(model)
    ref = sim.demo_trajectory(300.0)
    imu, errs, _ = ie.apply_imu_errors(sim.imu_from_trajectory(ref), params, seed=1,
                                       speed=np.hypot(ref["v_n"], ref["v_e"]).to_numpy()[1:])
    driving, _, _ = cn.stillness(imu, errs, cn.ConstraintConfig())
    n = 6001
    rest = pd.DataFrame({"time": np.arange(n) / RATE, "lat": 0.78, "lon": 0.13, "h": 250.0, "v_n": 0.0, "v_e": 0.0,
                         "v_d": 0.0, "roll": 0.02, "pitch": -0.01, "yaw": 1.0})
    imu_rest, errs_rest, _ = ie.apply_imu_errors(sim.imu_from_trajectory(rest), params, seed=2, speed=np.zeros(n - 1))
    still, t_f, t_w = cn.stillness(imu_rest, errs_rest, cn.ConstraintConfig(window_s=2.0))
    assert driving.mean() < 0.02                                  # the curvy drive is never still
    assert not still[:199].any() and np.isnan(t_f[:199]).all()   # no decision before a full window
    assert still[199:].mean() > 0.99
    # at rest the statistics are ~1 (the at-rest std is the sensor description's)
    assert abs(np.median(t_f[199:]) - 1.0) < 0.1 and abs(np.median(t_w[199:]) - 1.0) < 0.1
    assert not cn.stillness(imu_rest, errs_rest, cn.ConstraintConfig(accel_ratio=0.0))[0].any()


def test_aid_epochs_follow_the_time_of_week():
    t = 138000.0 + np.arange(1, 351) / RATE
    e = cn.aid_epochs(t, 1.0)
    np.testing.assert_allclose(t[e], [138001.0, 138002.0, 138003.0])
    assert cn.aid_epochs(t, 10.0).sum() == 35


def test_rest_noise_and_bad_settings():
    sf, sw = cn.rest_noise({"accel_noise_density": [0.01] * 3, "gyro_noise_density": 0.001,
                            "vibration_accel_std": [0.3, 0.3, 0.5], "vibration_idle_fraction": 0.3}, 100.0)
    np.testing.assert_allclose(sf, np.hypot(0.1, [0.09, 0.09, 0.15]))
    np.testing.assert_allclose(sw, [0.01] * 3)
    with pytest.raises(DataError, match="noise_density"):
        cn.rest_noise({"gyro_noise_density": 0.001}, 100.0)
    with pytest.raises(DataError, match="nhc_std_mps"):
        cn.ConstraintConfig(nhc_std_mps=0.0)
    with pytest.raises(DataError, match="mounting"):
        cn.constraint_config({"nhc": {"mounting": "roof"}})
    with pytest.raises(DataError, match="unknown key"):
        baseline.nav_config({"zupt": {"treshold": 1.0}})
    cfg = cn.constraint_config(baseline.nav_config({"nhc": {"std_mps": 0.3}, "zupt": {"max_speed_mps": 1.0}}))
    assert cfg.nhc_std_mps == 0.3 and cfg.zupt_max_speed_mps == 1.0 and cfg.window_s == cn.ZUPT_DEFAULTS["window_s"]


# ----------------------------------------------------------------------------------------------- physics
@pytest.mark.parametrize("bias", [{"gyro_x": 1e-4}, {"accel_y": 0.02}])
def test_nhc_bounds_the_cross_track_drift_of_a_lateral_tilt(bias):
    """Straight road at 12 m/s for 60 s; an unknown roll-gyro or lateral accelerometer bias tilts the INS sideways:
    its cross-track error grows with t^3 (t^2) without bound, the NHC observes the lateral velocity and holds it."""
    ref = _road(np.full(6001, 12.0))
    imu = _imu(ref, **bias)
    init, noise = _start(ref)
    con = cn.build_constraints(imu, EKINOX, _body_frame())
    ins = _cross_along(run_filter(imu, init, noise), ref)[0]
    aided = _cross_along(run_filter(imu, init, noise, aids=[con]), ref)[0]
    assert np.abs(ins).max() > 15.0 and abs(ins[-1]) > 15.0
    assert np.abs(aided).max() < 2.0


def test_nhc_turns_the_velocity_with_a_heading_drift():
    """A gyro z bias b on a straight road at constant speed v: the unaided INS keeps its velocity (no horizontal
    specific force to misproject) and stays on the road; the NHC ties the velocity to the drifting heading, so its
    cross-track error is the dead-reckoning one, v b t^2 / 2 (the NHC is no heading aid)."""
    v, b, t_end = 12.0, 1e-3, 60.0
    ref = _road(np.full(int(t_end * RATE) + 1, v))
    imu = _imu(ref, noise=False, gyro_z=b)
    init, noise = _start(ref)
    con = cn.build_constraints(imu, EKINOX, _body_frame())
    cross_ins, _, e_ins = _cross_along(run_filter(imu, init, noise), ref)
    cross_nhc, _, e_nhc = _cross_along(run_filter(imu, init, noise, aids=[con]), ref)
    assert np.abs(cross_ins).max() < 0.5
    assert abs(e_ins["yaw"].iloc[-1]) == pytest.approx(b * t_end, rel=0.05)       # the INS heading drifts, too
    assert abs(cross_nhc[-1]) == pytest.approx(v * b * t_end ** 2 / 2, rel=0.15)
    assert abs(e_nhc["yaw"].iloc[-1]) == pytest.approx(b * t_end, rel=0.1)


def test_zupt_holds_the_position_at_a_stop_where_the_ins_drifts():
    """10 m/s, a stop of 40 s, then off again, without GNSS from the start and with a lateral accelerometer bias
    the filter does not know yet. While the car stands, ZUPT keeps the solution still; the INS alone runs away."""
    t = np.arange(7001) / RATE
    ramp = lambda a, b: np.clip((t - a) / (b - a), 0, 1)
    speed = 10.0 * (1 - 0.5 * (1 - np.cos(np.pi * ramp(15, 20)))) + 10.0 * 0.5 * (1 - np.cos(np.pi * ramp(60, 65)))
    ref = _road(speed)
    imu = _imu(ref, accel_y=-0.02)                                # inside the filter's bias prior
    init, noise = _start(ref)
    con = cn.build_constraints(imu, EKINOX, _body_frame())
    standing = (t >= 22.0) & (t <= 60.0)                         # after the detector's window has filled
    assert con.still[standing[1:]].all()                          # IMU rows are the reference rows after the first
    assert (con.aid[standing[1:]] == cn.AID_ZUPT).sum() == 39     # one per second, 22 s .. 60 s
    drift = {}
    for name, aids in (("INS", []), ("ZUPT", [con])):
        res = run_filter(imu, init, noise, aids=aids)
        p = res.trajectory[["lat", "lon"]].to_numpy()[standing]
        ned = np.column_stack([(p[:, 0] - p[0, 0]) * 6.37e6, (p[:, 1] - p[0, 1]) * 6.37e6 * np.cos(p[0, 0])])
        drift[name] = np.hypot(*ned.T).max()
        speed_est = np.hypot(res.trajectory["v_n"], res.trajectory["v_e"]).to_numpy()[standing]
        if name == "ZUPT":
            assert speed_est[200:].max() < 0.05
    assert drift["INS"] > 20.0 and drift["ZUPT"] < 0.5


def test_zupt_is_refused_at_speed():
    """A vibration-free IMU on a smooth straight road reads like a stop: the detector fires, the speed gate keeps
    the ZUPT out (NHC only), and the solution stays on the road."""
    ref = _road(np.full(3001, 12.0))
    imu = _imu(ref)
    init, noise = _start(ref)
    con = cn.build_constraints(imu, EKINOX, _body_frame())
    assert con.still[300:].all()                                  # the detector is fooled
    _, along, _ = _cross_along(run_filter(imu, init, noise, aids=[con]), ref)
    assert np.abs(along).max() < 5.0                              # no ZUPT: no stop forced on a moving car
    ungated = cn.build_constraints(imu, EKINOX, _body_frame(zupt_max_speed_mps=100.0))
    _, along_bad, _ = _cross_along(run_filter(imu, init, noise, aids=[ungated]), ref)
    assert np.abs(along_bad).max() > 100.0


# ----------------------------------------------------------------------------------------------- plumbing
def test_constraints_without_epochs_change_nothing():
    """The constrained path with no aid epoch is the plain filter, bit for bit (and no aid is the default)."""
    ref = sim.demo_trajectory(60.0)
    imu = _imu(ref, gyro_z=1e-4)
    init, noise = _start(ref)
    gnss = sim.gnss_from_trajectory(ref, 1.0, 1.0, 2.0, seed=3)
    con = cn.build_constraints(imu, EKINOX, _body_frame())
    idle = cn.Constraints(con.config, con.imu_time, np.zeros_like(con.aid), con.still, con.mount_time, con.mount)
    a = run_filter(imu, init, noise, gnss, outage_windows=[(20.0, 20.0)])
    b = run_filter(imu, init, noise, gnss, outage_windows=[(20.0, 20.0)], aids=[idle])
    for x, y in ((a.trajectory, b.trajectory), (a.bias, b.bias), (a.sd, b.sd), (a.updates, b.updates)):
        pd.testing.assert_frame_equal(x, y, check_exact=True)
    np.testing.assert_array_equal(a.P_updates, b.P_updates)
    c = run_filter(imu, init, noise, gnss, outage_windows=[(20.0, 20.0)], aids=[con])
    assert not np.allclose(c.trajectory["lat"], a.trajectory["lat"], rtol=0, atol=1e-12)
    # the bias table follows the constraints' updates too: it changes at the aid epochs
    jumps = np.flatnonzero(np.any(np.diff(c.bias.iloc[:, 1:].to_numpy(), axis=0) != 0, axis=1)) + 1
    aided = np.flatnonzero(con.aid) + 1
    assert set(aided) <= set(jumps)
    with pytest.raises(DataError, match="IMU epochs"):
        con.steps(np.array([0.005]))


def test_outage_holds_the_vehicle_frame_at_its_start():
    c = cn.Constraints(cn.ConstraintConfig(), np.arange(5.0), np.ones(5, np.int8), np.zeros(5, bool),
                       np.arange(5.0), np.arange(10.0).reshape(5, 2))
    np.testing.assert_array_equal(c.mounting_at([0.5, 3.0]), [[0, 1], [6, 7]])
    np.testing.assert_array_equal(c.frozen(1.2).mounting_at([0.5, 3.0, 4.0]), [[0, 1], [2, 3], [2, 3]])


def _synthetic_drive(duration=150.0, seed=3):
    ref = sim.demo_trajectory(duration)
    params = ie.error_params("ekinox-d", {"gyro_bias_fixed": [2e-4, -3e-4, 4e-4]})
    imu, errs, _ = ie.apply_imu_errors(sim.imu_from_trajectory(ref), params, seed=seed,
                                       speed=np.hypot(ref["v_n"], ref["v_e"]).to_numpy()[1:])
    gnss = sim.gnss_from_trajectory(ref, 1.0, 1.0, 2.0, [0.4, -0.2, -1.0], seed=seed + 1)
    return Drive("synthetic", ref, imu, gnss, {"lever_arm_m": [0.4, -0.2, -1.0], "imu_errors": errs,
                                                "gnss_rate_hz": 1.0, "imu_rate_hz": 100.0})


def test_baseline_has_the_ins_nhc_row_beside_the_ins_row():
    drive = _synthetic_drive()
    windows = [(60.0, 30.0), (110.0, 30.0)]
    cfg = baseline.nav_config({})
    b = baseline.run_baseline(drive, cfg, windows)
    assert list(b.outage_table["method"]) == ["INS", "INS", "INS+NHC", "INS+NHC"]
    con = baseline.outage_constraints(drive, cfg, b.full)
    again = run_outage(drive.imu, b.states["outage_2"], windows[1], b.noise, drive.meta["lever_arm_m"],
                       aids=[con])
    e = b.outage_errors["outage_2"]
    np.testing.assert_array_equal(e.loc[e["method"] == "INS+NHC", "north"].to_numpy(),
                                  metrics.navigation_errors(again.trajectory, drive.reference)["north"].to_numpy())
    lay = baseline.ins_layout(b.outage_table, "turin-sim-ekinox")
    assert lay.loc["Outage 1", ("ours", "INS+NHC", "East")] == pytest.approx(b.outage_table["max_abs_east"].iloc[2])
    assert ("paper", "INS+NHC", "East") not in lay.columns and ("paper", "INS", "East") in lay.columns
    assert list(baseline.ins_max_error_file(b.outage_table).columns) == [
        "outage", "INS_east_m", "INS_north_m", "INS+NHC_east_m", "INS+NHC_north_m"]
    assert b.constraints["aid_epochs"] == int(np.count_nonzero(con.aid))
    # the GPS-aided run is the paper's filter unless the profile asks: its states do not move
    plain = run_filter(drive.imu, *baseline.initial_and_noise(drive, cfg), drive.gnss, drive.meta["lever_arm_m"])
    pd.testing.assert_frame_equal(plain.trajectory, b.full.trajectory, check_exact=True)
    with_gps = baseline.run_baseline(drive, baseline.nav_config({"constraints_in_gps_run": True}), windows)
    assert not np.allclose(with_gps.full.trajectory["lat"], b.full.trajectory["lat"], rtol=0, atol=1e-12)


def test_the_platform_decides_which_aids_run():
    """The stop-and-go drive above: a car gets NHC while moving and ZUPT at the stop, a walker only the ZUPT (it
    steps sideways), anything else neither; the lines say so."""
    t = np.arange(7001) / RATE
    ramp = lambda a, b: np.clip((t - a) / (b - a), 0, 1)
    speed = 10.0 * (1 - 0.5 * (1 - np.cos(np.pi * ramp(15, 20)))) + 10.0 * 0.5 * (1 - np.cos(np.pi * ramp(60, 65)))
    imu = _imu(_road(speed))
    kinds = {p: np.bincount(cn.build_constraints(imu, EKINOX, _body_frame(), platform=p).aid, minlength=3)
             for p in ("car", "walker", "other")}
    assert kinds["car"][cn.AID_NHC] > 0 and kinds["car"][cn.AID_ZUPT] >= 39            # the stop and the start
    assert kinds["walker"][cn.AID_NHC] == 0 and kinds["walker"][cn.AID_ZUPT] == kinds["car"][cn.AID_ZUPT]
    assert kinds["other"][cn.AID_NHC] == 0 and kinds["other"][cn.AID_ZUPT] == 0
    walker = cn.build_constraints(imu, EKINOX, _body_frame(), platform="walker")
    assert walker.summary()["platform"] == "walker" and aid_words.constraint_words(walker.config).startswith("platform walker: ZUPT")
    # a still epoch at speed (the detector fooled): a car gets the NHC instead, a walker no aid at all
    for platform, expect in (("walker", None), ("car", 2)):
        t = imu["time"].to_numpy(float)
        sched = cn.build_constraints(imu, EKINOX, _body_frame(), platform=platform).schedule(np.r_[t[0] - 0.01, t])
        i = int(np.flatnonzero(sched.aid[sched.rows - 1] == cn.AID_ZUPT)[0])
        m = sched.measurement(i, SimpleNamespace(v=np.array([5.0, 0.0, 0.0]), c=np.eye(3)))
        assert (m is None) if expect is None else (len(m.dz) == expect)
    with pytest.raises(DataError, match="platform"):
        cn.build_constraints(imu, EKINOX, _body_frame(), platform="boat")


def test_the_aided_rows_words_name_exactly_the_platforms_aids():
    for platform in cn.PLATFORM_AIDS:
        words = aid_words.aided_ins_words(platform)
        assert [a for a in aid_words.AID_WORDS if aid_words.AID_WORDS[a] in words] == list(cn.platform_aids(platform))
    assert aid_words.aided_ins_words("car") == "INS with non-holonomic constraints and zero-velocity updates"
    assert aid_words.aided_ins_words("a unicycle") == aid_words.aided_ins_words("car")   # unknown: the default platform

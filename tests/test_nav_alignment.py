"""Self-alignment without a reference attitude (bgfn.nav.alignment) and what a late filter start means downstream.

Simulated drives (demo trajectory, Ekinox-grade IMU, 1 Hz GNSS with 0.5 m noise) whose reference attitude is removed;
the IMU sits tilted in the car (roll +1.7 deg, pitch -1.1 deg) so that the level is no trivial zero.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from bgfn.data import Drive
from bgfn.data import imu_errors as ie
from bgfn.errors import DataError
from bgfn.nav import alignment as al
from bgfn.nav import baseline, earth, metrics, sim, transform
from bgfn.nav.state import noise_from_imu_errors

LEVER = [0.5, -0.3, -1.2]
TILT = (0.03, -0.02)                      # IMU mounting roll, pitch, rad
REST_S = 30.0
GNSS_STD = 0.5                            # m per horizontal axis (1.0 vertical)
#: Tolerances of the aligned attitude against the truth at the alignment epoch, deg. Heading: 10 s of driving at
#: 5-11 m/s with 0.5 m fixes give a course noise of about 0.7 m over 60-100 m (0.5 deg); level after rest: the
#: accelerometer bias over g (Ekinox-D: 0.14 deg); level while moving: the GNSS velocity noise over g T.
HEADING_TOL_DEG = 2.0
LEVEL_REST_TOL_DEG = 0.3
LEVEL_MOVING_TOL_DEG = 2.5
NAV = {"init": {"position_std_m": 1.0, "height_std_m": 2.0, "velocity_std_mps": 0.1, "level_std_deg": 0.5,
                "azimuth_std_deg": 2.0}}


def _truth(rest_s: float, duration: float = 240.0) -> pd.DataFrame:
    ref = sim.demo_trajectory(duration, rest_s=rest_s)
    ref["roll"] += TILT[0]
    ref["pitch"] += TILT[1]
    return ref


def _drive(rest_s: float, seed: int = 7, overrides: dict | None = None, velocities: bool = False,
           duration: float = 240.0, name: str = "aligned") -> tuple[Drive, pd.DataFrame]:
    """(drive without attitude, truth) for a car that waits ``rest_s`` then drives."""
    ref = _truth(rest_s, duration)
    params = ie.error_params("ekinox-d", overrides)
    speed = np.hypot(ref["v_n"], ref["v_e"]).to_numpy()[1:]
    imu, errs, bias = ie.apply_imu_errors(sim.imu_from_trajectory(ref), params, seed=seed, speed=speed)
    gnss = sim.gnss_from_trajectory(ref, 1.0, GNSS_STD, 2 * GNSS_STD, LEVER, seed=seed + 1)
    if velocities:   # the antenna's velocity with 0.05 m/s noise (the IMU's; the lever arm adds < 0.1 m/s)
        at = ref.set_index("time").loc[gnss["time"], ["v_n", "v_e", "v_d"]].to_numpy()
        gnss[["v_n", "v_e", "v_d"]] = at + np.random.default_rng(seed + 2).normal(0.0, 0.05, at.shape)
    blind = ref.copy()
    blind[["roll", "pitch", "yaw"]] = np.nan
    meta = {"lever_arm_m": LEVER, "imu_errors": errs, "gnss_rate_hz": 1.0, "imu_rate_hz": 100.0}
    return Drive(name, blind, imu, gnss, meta, bias), ref


@pytest.fixture(scope="module")
def rest_drive():
    return _drive(REST_S)


@pytest.fixture(scope="module")
def moving_drive():
    return _drive(0.0)


def _errors_deg(a: al.Alignment, ref: pd.DataFrame) -> np.ndarray:
    r = ref.set_index("time").loc[a.state.time]
    return np.degrees([a.roll - r["roll"], a.pitch - r["pitch"], transform.wrap_angle(a.yaw - r["yaw"])])


def _align(drive, **options):
    return al.align(drive.imu, drive.gnss, LEVER, noise_from_imu_errors(drive.meta["imu_errors"]), options, drive.name)


# ----------------------------------------------------------------------------------------------- the formulas
@pytest.mark.parametrize("roll,pitch", [(0.0, 0.0), (0.1, -0.05), (-0.4, 0.3), (2.5, 0.2)])
def test_level_from_gravity_inverts_the_dcm(roll, pitch):
    g = 9.8
    f = transform.dcm_from_euler(roll, pitch, 1.3).T @ np.array([0.0, 0.0, -g])
    assert al.level_from_specific_force(f) == pytest.approx((roll, pitch), abs=1e-12)


def test_an_accelerometer_bias_tilts_the_level_by_bias_over_g():
    g, b = 9.8, 0.05
    f = np.array([0.0, 0.0, -g])
    roll, pitch = al.level_from_specific_force(f + [0.0, b, 0.0])
    assert roll == pytest.approx(-b / g, rel=1e-3) and pitch == pytest.approx(0.0, abs=1e-12)
    roll, pitch = al.level_from_specific_force(f + [b, 0.0, 0.0])
    assert pitch == pytest.approx(b / g, rel=1e-3) and roll == pytest.approx(0.0, abs=1e-12)


@pytest.mark.parametrize("accel", [[0.0, 0.0, 0.0], [1.5, -0.8, 0.2], [-2.0, 2.5, 0.0]])
def test_velocity_matching_recovers_the_level_under_acceleration(accel):
    roll, pitch, yaw, g = 0.05, -0.08, 2.0, 9.81
    f = transform.dcm_from_euler(roll, pitch, yaw).T @ (np.asarray(accel) - [0.0, 0.0, g])
    assert al.level_by_velocity_matching(f, accel, yaw) == pytest.approx((roll, pitch), abs=1e-9)
    # ignoring the acceleration would tilt the level by about |a| / g
    if np.any(accel):
        assert abs(al.level_from_specific_force(f)[1] - pitch) > 0.05


# ------------------------------------------------------------------------------------------------ stillness
def test_rest_is_found_from_the_imu_even_with_engine_vibration(rest_drive, moving_drive):
    drive, _ = rest_drive
    opts = al.ALIGNMENT_DEFAULTS
    args = (opts["still_window_s"], opts["still_accel_std_mps2"], np.radians(opts["still_gyro_std_dps"]))
    end = al.rest_end(drive.imu, *args)
    assert REST_S - 2.0 <= end <= REST_S + 0.5
    # an IMU cannot tell steady straight driving (a vibration-free simulation) from rest: the GNSS speed ends it
    assert al.rest_end(moving_drive[0].imu, *args) < 10.0 and _align(moving_drive[0]).rest_end is None
    # idle vibration (0.1 m/s^2, 2 deg/s white noise) is not motion; driving with it is
    rng = np.random.default_rng(0)
    shaken = drive.imu.copy()
    shaken[["accel_x", "accel_y", "accel_z"]] += rng.normal(0.0, 0.1, (len(shaken), 3))
    shaken[["gyro_x", "gyro_y", "gyro_z"]] += rng.normal(0.0, np.radians(2.0), (len(shaken), 3))
    assert REST_S - 2.0 <= al.rest_end(shaken, *args) <= REST_S + 0.5


# ------------------------------------------------------------------------------------------------ alignment
def test_alignment_after_rest_matches_the_truth(rest_drive):
    drive, ref = rest_drive
    a = _align(drive)
    assert a.level_source == "rest" and a.course_source == "gnss_positions"
    # the filter waits for heading_time_s above the speed threshold after the rest
    assert REST_S + al.ALIGNMENT_DEFAULTS["heading_time_s"] <= a.state.time <= REST_S + 20.0
    err = _errors_deg(a, ref)
    assert np.all(np.abs(err[:2]) < LEVEL_REST_TOL_DEG), err
    assert abs(err[2]) < HEADING_TOL_DEG, err
    # the IMU's position and velocity from the fix, within their P0 std (3 sigma)
    row = ref.set_index("time").loc[[a.state.time]].reset_index()
    e = metrics.navigation_errors(pd.DataFrame([a.state.as_row()]), row).iloc[0]
    sd_pos = np.sqrt([a.state.P[k, k] for k in (6, 7, 8)]) * [earth.curvature_radii(a.state.pos[0])[0], 1, 1]
    assert abs(e["north"]) < 3 * sd_pos[0] and abs(e["down"]) < 3 * sd_pos[2]
    assert np.all(np.abs([e["v_n"], e["v_e"], e["v_d"]]) < 3 * a.velocity_std)
    assert a.state.time == pytest.approx(a.gnss_time)                 # 1 Hz fixes fall on IMU epochs here


def test_alignment_of_a_drive_that_starts_moving(moving_drive):
    drive, ref = moving_drive
    a = _align(drive)
    assert a.level_source == "gnss_acceleration" and a.rest_end is None
    assert a.state.time <= ref["time"].iloc[0] + al.ALIGNMENT_DEFAULTS["heading_time_s"] + 2.0
    err = _errors_deg(a, ref)
    assert np.all(np.abs(err[:2]) < LEVEL_MOVING_TOL_DEG), err
    assert abs(err[2]) < HEADING_TOL_DEG, err
    assert np.all(np.abs(np.radians(err[:2])) < 3 * a.level_std)     # the level std covers the error


def test_gnss_velocities_give_the_course_when_the_fixes_carry_them():
    drive, ref = _drive(REST_S, velocities=True)
    a = _align(drive)
    assert a.course_source == "gnss_velocity"
    assert abs(_errors_deg(a, ref)[2]) < 0.5 * HEADING_TOL_DEG


def test_level_error_after_rest_is_the_accelerometer_bias_over_g():
    b = 0.1                                            # m/s^2 on the y axis: a tilt of b/g = 0.58 deg at rest
    drive, ref = _drive(REST_S, overrides={"accel_bias_fixed": [0.0, b, 0.0], "accel_turn_on_bias_std": [0.0] * 3})
    a = _align(drive)
    # the tilt error lies in the navigation frame (about the heading at rest) and the gyros carry it unchanged to
    # the alignment epoch, where the car has turned: compare its horizontal size, not the roll alone
    r = ref.set_index("time").loc[a.state.time]
    phi = transform.rotvec_from_dcm(a.state.c_bn @ transform.dcm_from_euler(r["roll"], r["pitch"], r["yaw"]).T)
    assert np.hypot(phi[0], phi[1]) == pytest.approx(b / 9.8, abs=np.radians(0.1))


def test_the_filter_waits_for_a_speed_run_long_enough():
    drive, _ = _drive(REST_S)
    with pytest.raises(DataError, match="heading_time_s"):
        _align(drive, speed_threshold_mps=50.0)
    later = _align(drive, heading_time_s=30.0)
    assert later.state.time > _align(drive).state.time + 15.0


# -------------------------------------------------------------------------------------- in the GPS-aided run
def test_gps_aided_run_after_alignment_converges_like_a_reference_start(rest_drive):
    drive, ref = rest_drive
    sighted = Drive(drive.name, ref, drive.imu, drive.gnss, drive.meta)
    assert not drive.has_attitude and sighted.has_attitude
    aligned = baseline.run_drive(drive, NAV)                          # mode auto: no attitude -> gnss
    started = baseline.run_drive(sighted, NAV)                        # mode auto: attitude -> reference row
    t_a = aligned.trajectory["time"].iloc[0]
    assert t_a > REST_S and started.trajectory["time"].iloc[0] == ref["time"].iloc[0]
    settle = t_a + 60.0
    rms = {}
    for label, run in (("aligned", aligned), ("reference", started)):
        e = metrics.navigation_errors(run.trajectory, ref)
        e = e[e["time"] > settle]
        rms[label] = {k: float(np.sqrt(np.mean(e[k] ** 2))) for k in ("horizontal", "yaw", "roll", "pitch")}
    assert rms["aligned"]["horizontal"] < 1.3 * rms["reference"]["horizontal"]
    assert np.degrees(rms["aligned"]["yaw"]) < 1.0 and np.degrees(max(rms["aligned"]["roll"],
                                                                      rms["aligned"]["pitch"])) < 0.2
    assert 2.0 < aligned.updates["nis"].mean() < 4.0


def test_alignment_mode_reference_auto_gnss(rest_drive):
    drive, ref = rest_drive
    sighted = Drive(drive.name, ref, drive.imu, drive.gnss, drive.meta)
    with pytest.raises(DataError, match="nav.alignment.mode"):
        baseline.run_drive(drive, {**NAV, "alignment": {"mode": "reference"}})
    auto = baseline.run_drive(sighted, NAV).trajectory
    refmode = baseline.run_drive(sighted, {**NAV, "alignment": {"mode": "reference"}}).trajectory
    pd.testing.assert_frame_equal(auto, refmode)                      # auto = today's start when there is an attitude
    forced = baseline.prepare_filter(sighted, baseline.nav_config({**NAV, "alignment": {"mode": "gnss"}}))
    assert forced.alignment is not None and forced.initial.time > REST_S
    assert baseline.filter_start(sighted, NAV) == ref["time"].iloc[0]
    assert baseline.filter_start(drive, NAV) == forced.initial.time
    with pytest.raises(DataError, match="mode"):
        baseline.nav_config({"alignment": {"mode": "compass"}})
    with pytest.raises(DataError, match="heading_tim"):
        baseline.nav_config({"alignment": {"heading_tim": 3.0}})


# ------------------------------------------------------------------------------------- a late start downstream
def test_baseline_metrics_and_outages_use_only_the_time_after_the_start(rest_drive):
    drive, ref = rest_drive
    cfg = baseline.nav_config(NAV)
    t_a = baseline.filter_start(drive, NAV)
    b = baseline.run_baseline(drive, cfg, [(120.0, 20.0)])
    assert b.errors["time"].iloc[0] == pytest.approx(t_a) and len(b.errors) == int(round((240.0 - t_a) * 100)) + 1
    assert np.isfinite(b.rms.loc["horizontal", "rms"]) and b.setup.alignment is not None
    assert b.setup.record()["alignment"]["level_source"] == "rest"
    with pytest.raises(DataError, match="filter start"):
        baseline.run_baseline(drive, cfg, [(20.0, 10.0)])            # the outage lies before the alignment


def test_learning_windows_start_after_the_filter(rest_drive):
    from bgfn.learning import ins_increments, make_windows

    drive, ref = rest_drive
    att = baseline.run_drive(drive, NAV).trajectory
    t_a = float(att["time"].iloc[0])
    inc = ins_increments(att, np.array([t_a - 2.0, t_a + 1.0]), np.array([t_a - 1.0, t_a + 2.0]))
    assert np.isnan(inc[0]).all() and np.isfinite(inc[1]).all()       # no INS distance before the filter runs
    late = make_windows(drive.imu, att, drive.gnss, window=50, target_screen_sigma=10.0)
    assert late.t_start.min() >= t_a - 1e-9 and len(late) > 0
    # the same windows as with an attitude from the first row, minus those that touch the time before the start
    full = make_windows(drive.imu, ref, drive.gnss, window=50)
    assert set(np.round(late.t_to, 6)) == set(np.round(full.t_to[full.t_start >= t_a - 1e-9], 6))


def test_sweep_plan_and_outage_evaluation_wait_for_the_filter(rest_drive):
    from bgfn.evaluate import navigation_context
    from bgfn.studies.outage_sweep import sweep_plan

    drive, _ = rest_drive
    t_a = baseline.filter_start(drive, NAV)
    sweep = {"warmup_s": 20.0, "durations_s": [10.0], "n_starts": 4, "folds": 2}
    plan = sweep_plan(drive, sweep, 50, t_first=t_a)
    assert plan["start_s"].min() >= t_a + 20.0 - 0.05
    assert sweep_plan(drive, sweep, 50)["start_s"].min() < t_a         # the reference's first row is earlier
    with pytest.raises(DataError, match="filter's start"):
        navigation_context(drive, NAV, [t_a - 5.0])
    ctx = navigation_context(drive, NAV, [t_a + 30.0])
    assert ctx.state_at(t_a + 30.0).time < t_a + 30.0

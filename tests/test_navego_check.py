"""tools/navego_check.py's export to NaveGo's structs (no Octave needed): what NaveGo is given is what we use."""

from __future__ import annotations

import importlib.util

import numpy as np
import pandas as pd
import scipy.io
import pytest

from bgfn.config import PROJECT_ROOT
from bgfn.data import Drive
from bgfn.data.imu_errors import error_params
from bgfn.nav.baseline import nav_config
from synthetic_drive import exact_drive

spec = importlib.util.spec_from_file_location("navego_check", PROJECT_ROOT / "tools" / "navego_check.py")
navego_check = importlib.util.module_from_spec(spec)
spec.loader.exec_module(navego_check)


def test_the_export_gives_navego_our_imu_errors_our_outages_and_position_only_fixes():
    drive = exact_drive(120.0, imu_errors=error_params("mpu6000"), lever_arm_m=[0.1, 0.0, -0.2])
    t0 = float(drive.gnss["time"].iloc[0])
    windows = [(t0 + 40.0, 30.0)]
    imu, gnss, setting = navego_check.export(drive, windows, nav_config({}), fuse_velocity=False)
    assert setting == "position only" and (gnss["stdv"] == navego_check.NO_VELOCITY_STD).all()
    t = gnss["t"][:, 0]
    assert not ((t > t0 + 40.0) & (t < t0 + 70.0)).any() and len(t) == len(drive.gnss) - 29   # 29 fixes removed
    assert imu["t"][0, 0] >= t0 and imu["fb"].shape == (len(imu["t"]), 3)                    # from the first fix
    e = error_params("mpu6000")
    np.testing.assert_allclose(imu["gb_psd"], np.asarray(e["gyro_bias_instability"]) /
                               np.sqrt(e["gyro_bias_corr_time"]))                           # imu_si_errors.m
    assert gnss["eps"] == pytest.approx(0.005) and gnss["zupt_th"] == 0.0                     # half an IMU step
    # the velocity from the fixes follows the reference's (exact fixes of a smooth drive)
    ref_v = np.interp(t, drive.reference["time"], drive.reference["v_n"])
    assert np.abs(gnss["vel"][5:-5, 0] - ref_v[5:-5]).max() < 0.2
    assert gnss["larm"].shape == (3, 1) and gnss["larm"][0, 0] == 0.1


def test_the_structs_written_for_octave_read_back_equal_the_drive(tmp_path):
    drive = exact_drive(60.0, imu_errors=error_params("mpu6000"))
    imu, gnss, _ = navego_check.export(drive, [], nav_config({}), fuse_velocity=True)
    scipy.io.savemat(tmp_path / "in.mat", {"imu": imu, "gnss": gnss, "att_mode": "quaternion"})
    back = scipy.io.loadmat(tmp_path / "in.mat", squeeze_me=True, struct_as_record=False)
    i, g = back["imu"], back["gnss"]
    rows = drive.imu["time"] >= drive.gnss["time"].iloc[0] - 1e-9
    np.testing.assert_array_equal(i.t, drive.imu["time"][rows].to_numpy())
    np.testing.assert_array_equal(i.wb, drive.imu.loc[rows, ["gyro_x", "gyro_y", "gyro_z"]].to_numpy())
    np.testing.assert_array_equal(i.fb, drive.imu.loc[rows, ["accel_x", "accel_y", "accel_z"]].to_numpy())
    np.testing.assert_array_equal(g.lat, drive.gnss["lat"].to_numpy())
    np.testing.assert_array_equal(g.vel, drive.gnss[["v_n", "v_e", "v_d"]].to_numpy())       # the file's own
    assert str(back["att_mode"]) == "quaternion" and i.ini_align.shape == (3,)


def test_the_diagnostic_copy_changes_navegos_bias_feedback_and_nothing_else(tmp_path):
    # a stand-in for NaveGo's tree: the three lines of ins_gnss.m Version 011 the diagnostic changes, and another file
    src = tmp_path / "navego"
    (src / "ins-gnss").mkdir(parents=True)
    lines = ["kf.xp(1:9) = 0.0;           % states 1 to 9", "gb_dyn   = -kf.xp(10:12);", "ab_dyn   = -kf.xp(13:15);"]
    (src / navego_check.PATCHED_FILE).write_text("\n".join(["x = 1;", *lines, "y = 2;"]) + "\n")
    (src / "ins-gnss" / "F_update.m").write_text("F = 0;\n")
    out = navego_check.patched_navego(src, tmp_path / "run")
    got = (out / navego_check.PATCHED_FILE).read_text().splitlines()
    assert got == ["x = 1;", "kf.xp(1:15) = 0.0;           % states 1 to 9", "gb_dyn   = gb_dyn - kf.xp(10:12);",
                   "ab_dyn   = ab_dyn + kf.xp(13:15);", "y = 2;"]
    assert (out / "ins-gnss" / "F_update.m").read_text() == "F = 0;\n"
    assert (src / navego_check.PATCHED_FILE).read_text().splitlines()[1:4] == lines      # the source untouched
    # another NaveGo version (a line not there): one error naming the file and the line, no run
    (src / navego_check.PATCHED_FILE).write_text("gb_dyn = 0;\n")
    with pytest.raises(ValueError, match=r"ins_gnss.m: expected the line `kf.xp\(1:9\) = 0.0;` exactly once"):
        navego_check.patched_navego(src, tmp_path / "again")


def test_the_bias_trace_holds_navegos_estimates_ours_and_the_truth_at_the_same_fixes(tmp_path):
    # NaveGo's nav_e.b at its fixes (rad/s, m/s^2) -> deg/s and m/s^2 from the first fix, the first trace_s seconds
    tg = np.arange(1000.0, 1010.0)
    b = np.column_stack([np.full(10, np.radians(1.5)), np.zeros((10, 4)), np.linspace(0.0, 0.9, 10)])
    scipy.io.savemat(tmp_path / "out.mat", {"tg": tg[:, None], "b": b})
    rows = navego_check.navego_trace(tmp_path / "out.mat", "d", "as released", trace_s=4.0)
    assert [r["time_s"] for r in rows] == [0.0, 1.0, 2.0, 3.0, 4.0]
    assert rows[0]["source"] == "NaveGo, as released" and rows[0]["gyro_bias_x_dps"] == pytest.approx(1.5)
    assert rows[4]["accel_bias_z_mps2"] == pytest.approx(0.4)
    # ours under NaveGo's setup and the simulated truth, at the same fixes
    drive = exact_drive(60.0, imu_errors=error_params("mpu6000"))
    assert [r["source"] for r in navego_check.our_trace(drive, {}, drive.gnss["time"].to_numpy(float)[:2])] == [
        navego_check.OURS] * 2                                                  # a drive without a truth
    t_imu = drive.imu["time"].to_numpy(float)
    truth = pd.DataFrame({"time": t_imu, **{c: 1e-3 * (k + 1) + 1e-5 * (t_imu - t_imu[0]) for k, c in
                                            enumerate(navego_check._BIAS)}})
    drive = Drive(drive.name, drive.reference, drive.imu, drive.gnss, drive.meta, truth)
    t = drive.gnss["time"].to_numpy(float)[:5]
    ours = navego_check.our_trace(drive, {}, t)
    assert [r["source"] for r in ours] == [navego_check.OURS] * 5 + [navego_check.TRUTH] * 5
    assert [r["time_s"] for r in ours[:5]] == list(t - t[0])
    assert ours[7]["gyro_bias_y_dps"] == pytest.approx(np.degrees(2e-3 + 1e-5 * (t[2] - t_imu[0])))
    assert ours[9]["accel_bias_z_mps2"] == pytest.approx(6e-3 + 1e-5 * (t[4] - t_imu[0]))
    assert abs(ours[0]["gyro_bias_x_dps"]) < 1.0                               # ours: an estimate, in deg/s
    # a run of some drives keeps the other drives' rows
    path = tmp_path / "trace.csv"
    pd.DataFrame({"dataset": ["a", "b"], "x": [1, 2]}).to_csv(path, index=False)
    both = navego_check.merged(path, pd.DataFrame({"dataset": ["b"], "x": [3]}), ["b"])
    assert both.values.tolist() == [["a", 1], ["b", 3]]

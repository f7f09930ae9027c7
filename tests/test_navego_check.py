"""tools/navego_check.py's export to NaveGo's structs (no Octave needed): what NaveGo is given is what we use."""

from __future__ import annotations

import importlib.util

import numpy as np
import scipy.io
import pytest

from bgfn.config import PROJECT_ROOT
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

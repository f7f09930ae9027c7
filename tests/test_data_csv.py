"""A user's drive in the CSV schema: round trip, and one clear error per defect (file + column)."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from bgfn.data import Drive, load_csv_drive, load_drive, write_csv_drive
from bgfn.data.imu_errors import error_params
from bgfn.errors import DataError
from bgfn.nav.sim import demo_trajectory, imu_from_trajectory

pytestmark = pytest.mark.usefixtures("repo_untouched")


@pytest.fixture(scope="module")
def drive():
    ref = demo_trajectory(duration_s=20.0, rate_hz=100.0)
    imu = imu_from_trajectory(ref)
    g = ref.iloc[::100].reset_index(drop=True)
    gnss = pd.DataFrame({"time": g["time"], "lat": g["lat"], "lon": g["lon"], "h": g["h"],
                         "v_n": g["v_n"], "v_e": g["v_e"], "v_d": g["v_d"], "std_n": 1.0, "std_e": 1.0, "std_d": 3.0})
    meta = {"lever_arm_m": [-0.369, 0.0, -0.219], "imu_errors": error_params("mpu6000"), "source": "demo"}
    return Drive("demo", ref, imu, gnss, meta)


def files_of(folder):
    return sorted(p.name for p in folder.iterdir())


def test_round_trip_is_exact(tmp_path, drive):
    write_csv_drive(drive, tmp_path / "d")
    assert files_of(tmp_path / "d") == ["gnss.csv", "imu.csv", "meta.yaml", "reference.csv"]
    back = load_drive(tmp_path / "d")
    assert back.name == "demo"
    pd.testing.assert_frame_equal(back.reference, drive.reference)
    pd.testing.assert_frame_equal(back.imu, drive.imu)
    pd.testing.assert_frame_equal(back.gnss, drive.gnss)
    assert back.meta["lever_arm_m"] == [-0.369, 0.0, -0.219]
    assert back.meta["imu_rate_hz"] == pytest.approx(100.0) and back.meta["gnss_rate_hz"] == pytest.approx(1.0)
    expected = drive.meta["imu_errors"]["gyro_noise_density"]
    assert back.meta["imu_errors"]["gyro_noise_density"] == pytest.approx(expected)
    assert load_drive(str(tmp_path / "d")).name == "demo"  # a str path works too


def test_optional_velocity_and_meta(tmp_path, drive):
    folder = write_csv_drive(drive, tmp_path / "d")
    drive.gnss.drop(columns=["v_n", "v_e", "v_d"]).to_csv(folder / "gnss.csv", index=False)
    (folder / "meta.yaml").unlink()
    back = load_csv_drive(folder)
    assert back.gnss[["v_n", "v_e", "v_d"]].isna().all().all()
    # no meta.yaml: the documented defaults, the consumer-MEMS profile for the filter
    assert back.meta["lever_arm_m"] == [0.0, 0.0, 0.0] and back.meta["imu_errors"] == error_params("mpu6000")
    assert "default" in back.meta["imu_errors_source"]
    assert back.name == "d"


def test_resampling_on_load(tmp_path, drive):
    folder = write_csv_drive(drive, tmp_path / "d")
    back = load_drive(folder, imu_rate_hz=50.0)
    assert len(back.imu) == len(drive.imu) // 2
    np.testing.assert_allclose(back.imu["gyro_z"].to_numpy(),
                               drive.imu["gyro_z"].to_numpy().reshape(-1, 2).mean(axis=1), atol=1e-9)


def _damage(folder, case):
    if case == "missing_column":
        df = pd.read_csv(folder / "imu.csv").drop(columns=["accel_z"])
        df.to_csv(folder / "imu.csv", index=False)
        return "imu.csv", "accel_z"
    if case == "nan_imu":
        df = pd.read_csv(folder / "imu.csv")
        df.loc[17, "gyro_y"] = np.nan
        df.to_csv(folder / "imu.csv", index=False)
        return "imu.csv", "gyro_y"
    if case == "non_increasing_time":
        df = pd.read_csv(folder / "gnss.csv")
        df.loc[5, "time"] = df.loc[3, "time"]
        df.to_csv(folder / "gnss.csv", index=False)
        return "gnss.csv", "time"
    if case == "missing_file":
        (folder / "reference.csv").unlink()
        return "reference.csv", "file"
    if case == "degrees":
        df = pd.read_csv(folder / "reference.csv")
        df["lat"] = np.degrees(df["lat"])
        df.to_csv(folder / "reference.csv", index=False)
        return "reference.csv", "lat"
    if case == "bad_std":
        df = pd.read_csv(folder / "gnss.csv")
        df.loc[2, "std_e"] = 0.0
        df.to_csv(folder / "gnss.csv", index=False)
        return "gnss.csv", "std_n/std_e/std_d"
    if case == "text_in_number":
        df = pd.read_csv(folder / "reference.csv")
        df["yaw"] = df["yaw"].astype(object)
        df.loc[4, "yaw"] = "north"
        df.to_csv(folder / "reference.csv", index=False)
        return "reference.csv", "yaw"
    if case == "bad_lever_arm":
        (folder / "meta.yaml").write_text("lever_arm_m: [1.0, 2.0]\n")
        return "meta.yaml", "lever_arm_m"
    if case == "bad_noise":
        (folder / "meta.yaml").write_text("imu_errors:\n  gyro_noise_density: -1\n")
        return "meta.yaml", "imu_errors.gyro_noise_density"
    raise AssertionError(case)


@pytest.mark.parametrize("case", ["missing_column", "nan_imu", "non_increasing_time", "missing_file", "degrees",
                                  "bad_std", "text_in_number", "bad_lever_arm", "bad_noise"])
def test_bad_csv_gives_one_clear_error(tmp_path, drive, case):
    folder = write_csv_drive(drive, tmp_path / "d")
    fname, field = _damage(folder, case)
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    with pytest.raises(DataError) as exc:
        load_drive(folder)
    assert exc.value.field == field
    assert str(folder / fname) in str(exc.value)
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before  # nothing written or removed


def test_not_a_folder_nor_a_dataset(tmp_path):
    with pytest.raises(DataError, match="name"):
        load_drive("turin-sim-nothing")
    with pytest.raises(DataError, match="folder"):
        load_csv_drive(tmp_path / "absent")

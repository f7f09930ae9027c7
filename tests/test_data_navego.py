"""NaveGo .mat readers: schema, validation errors naming file and field, increment-preserving resampling."""

from __future__ import annotations

import numpy as np
import pytest
import scipy.io

from bgfn.data.navego import read_gnss, read_imu, read_reference, resample_imu
from bgfn.errors import DataError
from bgfn.schema import GNSS_COLUMNS, IMU_COLUMNS, REFERENCE_COLUMNS

pytestmark = pytest.mark.usefixtures("repo_untouched")


def imu_struct(n=400, rate=200.0, t0=138001.0, seed=0):
    rng = np.random.default_rng(seed)
    t = t0 + np.arange(n) / rate
    return {"t": t, "wb": rng.normal(0, 0.1, (n, 3)), "fb": rng.normal([0, 0, -9.8], 0.5, (n, 3)),
            "arw": np.array([1.58e-4, 1.60e-4, 1.81e-4]), "gb_corr": np.array([10.0, 10, 10])}


def write_mat(path, name, struct):
    scipy.io.savemat(path, {name: struct})
    return path


def test_real_reference_and_gnss(mirror):
    ref = read_reference(mirror / "ref.mat")
    assert list(ref.columns) == list(REFERENCE_COLUMNS) and len(ref) == 1260
    assert ref["time"].iloc[0] == 138001.0 and ref["time"].iloc[-1] == 139260.0
    assert np.all(np.diff(ref["time"]) == 1.0) and np.abs(ref["yaw"]).max() <= np.pi
    assert np.degrees(ref["lat"].iloc[0]) == pytest.approx(45.06, abs=0.05)  # Turin
    gnss, info = read_gnss(mirror / "ekinox_gnss.mat")
    assert list(gnss.columns) == list(GNSS_COLUMNS) and len(gnss) == 6295
    assert info["rate_hz"] == 5.0 and info["lever_arm_m"] == [0.0, 0.0, -0.219]
    assert (gnss["std_n"] == 1.0).all() and (gnss["std_d"] == 3.0).all()  # from stdm = [1 1 3]


def test_imu_reader_on_synthetic_mat(tmp_path):
    s = imu_struct()
    imu, profile = read_imu(write_mat(tmp_path / "ekinox_imu.mat", "ekinox_imu", s))
    assert list(imu.columns) == list(IMU_COLUMNS)
    np.testing.assert_array_equal(imu[["gyro_x", "gyro_y", "gyro_z"]].to_numpy(), s["wb"])
    np.testing.assert_array_equal(imu["accel_z"].to_numpy(), s["fb"][:, 2])
    assert profile["arw"] == pytest.approx([1.58e-4, 1.60e-4, 1.81e-4]) and "vrw" not in profile


def test_resample_preserves_increments(tmp_path):
    s = imu_struct(n=401)
    imu, _ = read_imu(write_mat(tmp_path / "ekinox_imu.mat", "ekinox_imu", s))
    out = resample_imu(imu, 100.0)
    # 200 Hz -> 100 Hz on aligned grids: each output row is the mean of two input rows (hand-computed).
    np.testing.assert_allclose(out["gyro_x"].to_numpy(), 0.5 * (s["wb"][1::2, 0] + s["wb"][2::2, 0]), atol=1e-8)
    np.testing.assert_allclose(out["time"].to_numpy(), 138001.0 + np.arange(1, 201) / 100.0, atol=1e-9)
    # Non-aligned ~250 Hz input: the total increment over the common span is preserved.
    t = 138001.0 + np.cumsum(np.full(1000, 0.004) + np.random.default_rng(1).uniform(-1e-4, 1e-4, 1000))
    s2 = dict(s, t=t, wb=np.random.default_rng(2).normal(0, 1, (1000, 3)), fb=np.ones((1000, 3)))
    imu2, _ = read_imu(write_mat(tmp_path / "mpu6000_imu.mat", "mpu6000_imu", s2))
    out2 = resample_imu(imu2, 100.0)
    t0, t1 = out2["time"].iloc[0] - 0.01, out2["time"].iloc[-1]
    # row k covers (t[k-1], t[k]]; row 0 covers one interval before t[0]
    tt = np.concatenate([[2 * t[0] - t[1]], t])
    cum = np.concatenate([[0], np.cumsum(s2["wb"][:, 1] * np.diff(tt))])
    assert t0 < t[0]  # the first row's interval is used
    expected = np.interp(t1, tt, cum) - np.interp(t0, tt, cum)
    assert np.sum(out2["gyro_y"]) * 0.01 == pytest.approx(expected, abs=1e-9)
    np.testing.assert_allclose(out2["accel_x"], 1.0, atol=1e-12)


@pytest.mark.parametrize("case,field", [
    ("missing_field", "fb"),
    ("non_increasing_time", "t"),
    ("nan_imu", "wb"),
    ("wrong_shape", "fb"),
])
def test_bad_imu_struct_names_file_and_field(tmp_path, case, field):
    s = imu_struct()
    if case == "missing_field":
        del s["fb"]
    elif case == "non_increasing_time":
        s["t"][100] = s["t"][99]
    elif case == "nan_imu":
        s["wb"][57, 1] = np.nan
    elif case == "wrong_shape":
        s["fb"] = s["fb"][:-1]
    path = write_mat(tmp_path / "ekinox_imu.mat", "ekinox_imu", s)
    with pytest.raises(DataError) as exc:
        read_imu(path)
    assert exc.value.field == field and str(path) in str(exc.value)
    if case == "nan_imu":
        assert "57" in str(exc.value)
    if case == "non_increasing_time":
        assert "t[99]" in str(exc.value)


def test_truncated_or_garbage_mat_is_a_data_error(tmp_path, mirror):
    data = (mirror / "ref.mat").read_bytes()
    trunc = tmp_path / "ref.mat"
    trunc.write_bytes(data[: len(data) // 3])
    with pytest.raises(DataError) as exc:
        read_reference(trunc)
    assert exc.value.field in ("file", "t", "lat", "lon", "h", "vel", "roll", "pitch", "yaw")
    assert str(trunc) in str(exc.value)
    garbage = tmp_path / "g.mat"
    garbage.write_bytes(b"not a mat file at all" * 10)
    with pytest.raises(DataError, match="field 'file'"):
        read_reference(garbage)


def test_reference_missing_field_and_bad_units(tmp_path, mirror):
    ref = scipy.io.loadmat(mirror / "ref.mat", squeeze_me=True, struct_as_record=False)["ref"]
    s = {f: getattr(ref, f) for f in ref._fieldnames}
    del s["vel"]
    path = write_mat(tmp_path / "ref.mat", "ref", s)
    with pytest.raises(DataError) as exc:
        read_reference(path)
    assert exc.value.field == "vel" and str(path) in str(exc.value)
    s = {f: getattr(ref, f) for f in ref._fieldnames}
    s["lat"] = np.degrees(s["lat"])  # degrees instead of rad
    with pytest.raises(DataError, match="lat"):
        read_reference(write_mat(tmp_path / "ref2.mat", "ref", s))

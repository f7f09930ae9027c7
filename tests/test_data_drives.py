"""Datasets: load_drive registry, determinism, cache, real-IMU datasets, bad input leaves data/ alone."""

from __future__ import annotations

import hashlib

import numpy as np
import pandas as pd
import pytest
import scipy.io

from bgfn.data import DATASETS, acquire, drives, load_drive
from bgfn.data.imu_errors import OPTIONAL_VECTOR_KEYS, VECTOR_KEYS
from bgfn.errors import ChecksumError, DataError
from bgfn.nav.sim import imu_from_trajectory
from conftest import REQUIRED
from bgfn.profile_schema import load_profile

pytestmark = pytest.mark.usefixtures("repo_untouched")

NO_ERRORS = {**{k: 0.0 for k in VECTOR_KEYS if not k.endswith("corr_time")}, **dict.fromkeys(OPTIONAL_VECTOR_KEYS)}


@pytest.fixture()
def env(tmp_path, mirror):
    return {"data_dir": tmp_path / "data", "mirror": mirror}


def test_registry_and_defaults():
    assert list(DATASETS) == ["turin-sim-ekinox", "turin-sim-mpu6000", "navego-ekinox", "navego-mpu6000",
                              "rtklib-drive0708"]
    assert drives.DEFAULT_DATASET == "turin-sim-ekinox"
    assert DATASETS["turin-sim-mpu6000"]["lever_arm_m"] == [-0.369, 0.0, -0.219]
    with pytest.raises(DataError, match="gnss_rate"):
        drives.dataset_params("turin-sim-mpu6000", {"gnss_rate": 1.0})


def test_sim_ekinox_dataset(env):
    d = load_drive(**env)
    assert d.name == "turin-sim-ekinox" and len(d.reference) == 125901 and len(d.imu) == 125900
    np.testing.assert_array_equal(d.imu["time"].to_numpy(), d.reference["time"].to_numpy()[1:])
    assert len(d.gnss) == 6295 and d.meta["gnss_rate_hz"] == 5.0 and d.meta["lever_arm_m"] == [0.0, 0.0, -0.219]
    errs = d.meta["imu_errors"]
    assert errs["model"] == "ekinox-d" and errs["gyro_bias_corr_time"] == [10.0, 10.0, 10.0]
    assert set(errs["realized"]) >= {"gyro_turn_on_bias", "accel_turn_on_bias", "gyro_bias_constant",
                                     "gyro_scale_factor", "accel_sensor_matrix"}
    # the bias table is the truth notebook 02 compares against: its mean is near the constant part
    np.testing.assert_allclose(d.imu_bias[["gyro_bias_x", "gyro_bias_y", "gyro_bias_z"]].mean(),
                               errs["realized"]["gyro_bias_constant"], atol=3e-6)
    # IMU at rest: specific force -g on z (within the accel biases)
    still = np.hypot(d.reference["v_n"], d.reference["v_e"]).to_numpy()[1:] < 0.01
    assert d.imu.loc[still, "accel_z"].mean() == pytest.approx(-9.805, abs=0.02)


def test_error_free_dataset_is_the_inverse_strapdown(env):
    d = load_drive("turin-sim-mpu6000", imu_errors=NO_ERRORS, cache=False, **env)
    pd.testing.assert_frame_equal(d.imu, imu_from_trajectory(d.reference), check_exact=False, atol=1e-12)
    assert np.all(d.imu_bias.drop(columns="time").to_numpy() == 0.0)


def test_same_seed_identical_different_seed_differs(env):
    a = load_drive("turin-sim-mpu6000", seed=7, cache=False, **env)
    b = load_drive("turin-sim-mpu6000", seed=7, cache=False, **env)
    c = load_drive("turin-sim-mpu6000", seed=8, cache=False, **env)
    for table in ("reference", "imu", "gnss", "imu_bias"):
        pd.testing.assert_frame_equal(getattr(a, table), getattr(b, table), check_exact=True)
    assert a.meta["imu_errors"] == b.meta["imu_errors"]
    pd.testing.assert_frame_equal(a.reference, c.reference)  # the truth has no randomness
    assert np.abs(a.imu["gyro_x"] - c.imu["gyro_x"]).max() > 1e-3
    assert np.abs(a.gnss["h"] - c.gnss["h"]).max() > 0.1
    assert a.meta["imu_errors"]["realized"] != c.meta["imu_errors"]["realized"]


def test_mpu_dataset_contents(env):
    d = load_drive("turin-sim-mpu6000", **env)
    assert d.meta["gnss_rate_hz"] == 1.0 and np.all(np.diff(d.gnss["time"]) == 1.0)
    assert d.meta["lever_arm_m"] == [-0.369, 0.0, -0.219]
    assert d.gnss[["v_n", "v_e", "v_d"]].isna().all().all()
    r = d.meta["imu_errors"]["realized"]
    assert np.all(np.abs(r["gyro_scale_factor"]) <= 0.03) and np.linalg.norm(r["gyro_turn_on_bias"]) > 0.01
    # residual of fixes against the true antenna: about the configured error (std sqrt(0.3^2 + 1^2))
    assert np.array(d.meta["gnss_residual_std_m"][:2]) == pytest.approx([1.04, 1.04], rel=0.4)
    # vibration present while moving: high-pass accel_z std of order the configured 0.5 m/s^2
    moving = np.hypot(d.reference["v_n"], d.reference["v_e"]).to_numpy()[1:] > 10.0
    hp = np.diff(d.imu["accel_z"].to_numpy())[moving[1:]]
    assert 0.3 < hp.std() / np.sqrt(2) < 1.0


def test_cache_is_written_atomically_and_reused(env, monkeypatch):
    d1 = load_drive("turin-sim-ekinox", gnss_rate_hz=1.0, **env)
    folder = env["data_dir"] / "processed" / "turin-sim-ekinox"
    files = sorted(p.name for p in folder.iterdir())
    assert len(files) == 2 and files[0].endswith(".json") and files[1].endswith(".npz")  # no temporaries
    assert np.allclose(np.diff(d1.gnss["time"]), 1.0)

    def no_build(*args, **kwargs):
        raise AssertionError("rebuilt although cached")

    monkeypatch.setitem(drives._BUILDERS, "turin-sim-ekinox", (REQUIRED, no_build))
    d2 = load_drive("turin-sim-ekinox", gnss_rate_hz=1.0, **env)     # read back: the builder is never called
    for table in ("reference", "imu", "gnss", "imu_bias"):
        pd.testing.assert_frame_equal(getattr(d1, table), getattr(d2, table), check_exact=True)
    assert d2.meta["imu_errors"]["realized"] == d1.meta["imu_errors"]["realized"]
    with pytest.raises(AssertionError, match="rebuilt"):
        load_drive("turin-sim-ekinox", gnss_rate_hz=1.0, seed=1, **env)  # other parameters: other key


def test_a_truncated_cache_entry_is_rebuilt_with_a_line_saying_so(env, caplog):
    d1 = load_drive("turin-sim-ekinox", gnss_rate_hz=1.0, **env)
    folder = env["data_dir"] / "processed" / "turin-sim-ekinox"
    npz = next(folder.glob("*.npz"))
    npz.write_bytes(npz.read_bytes()[:1000])                     # an interrupted copy: not a zip any more
    with caplog.at_level("WARNING"):
        d2 = load_drive("turin-sim-ekinox", gnss_rate_hz=1.0, **env)
    assert "unreadable" in caplog.text and npz.name in caplog.text
    pd.testing.assert_frame_equal(d1.imu, d2.imu, check_exact=True)
    assert npz.stat().st_size > 1000                              # rewritten whole
    caplog.clear()
    load_drive("turin-sim-ekinox", gnss_rate_hz=1.0, **env)
    assert "unreadable" not in caplog.text                        # and read back from now on


def test_a_new_entry_removes_the_entries_of_other_code(env):
    folder = env["data_dir"] / "processed" / "turin-sim-mpu6000"
    folder.mkdir(parents=True)
    for stem, code in (("old", "other code"), ("broken", None)):
        (folder / f"{stem}.npz").write_bytes(b"x")
    (folder / "old.json").write_text('{"key": "k", "code": "other code"}')
    (folder / "broken.json").write_text("{not json")
    (folder / "writing.npz").write_bytes(b"x")                   # no JSON yet: maybe being written
    load_drive("turin-sim-mpu6000", gnss_rate_hz=1.0, seed=3, **env)
    load_drive("turin-sim-mpu6000", gnss_rate_hz=1.0, seed=4, **env)   # same code, other key: both kept
    names = sorted(p.name for p in folder.iterdir())
    assert "old.json" not in names and "old.npz" not in names and "broken.json" not in names
    assert "writing.npz" in names
    assert sum(n.endswith(".json") for n in names) == 2 and sum(n.endswith(".npz") for n in names) == 3


def test_crop_keeps_the_imu_intervals_inside(env):
    d = load_drive("turin-sim-ekinox", t_start=138906.0, t_end=138936.0, **env)
    assert d.reference["time"].iloc[0] == 138906.0 and d.reference["time"].iloc[-1] == 138936.0
    assert d.imu["time"].iloc[0] == pytest.approx(138906.01) and len(d.imu) == 3000
    assert d.gnss["time"].between(138906.0, 138936.0).all() and len(d.gnss) == 150
    assert len(d.imu_bias) == 3000


def test_corrupted_raw_file_is_a_checksum_error_and_writes_nothing(tmp_path, mirror):
    raw = tmp_path / "data" / "raw"
    raw.mkdir(parents=True)
    (raw / "ref.mat").write_bytes((mirror / "ref.mat").read_bytes()[:100_000])  # truncated
    with pytest.raises(ChecksumError) as exc:
        load_drive("turin-sim-ekinox", data_dir=tmp_path / "data", mirror=mirror)
    assert str(raw / "ref.mat") in str(exc.value)
    assert not (tmp_path / "data" / "processed").exists()
    assert sorted(p.name for p in raw.iterdir()) == ["ref.mat"]


def test_missing_real_imu_says_which_file_and_what_stands_in(env):
    with pytest.raises(acquire.MissingFileError) as exc:
        load_drive("navego-mpu6000", **env)
    msg = str(exc.value)
    assert "mpu6000_imu.mat" in msg and "turin-sim-mpu6000" in msg and "stand in" in msg


def test_navego_ekinox_from_a_synthetic_real_file(tmp_path, mirror, monkeypatch):
    """The real-IMU path on a small .mat written here: 200 Hz increments resampled to 100 Hz."""
    truth200 = load_drive("turin-sim-ekinox", data_dir=tmp_path / "d0", mirror=mirror, imu_rate_hz=200.0,
                          cache=False, t_end=138061.0).reference
    imu200 = imu_from_trajectory(truth200)
    path = tmp_path / "ekinox_imu.mat"
    scipy.io.savemat(path, {"ekinox_imu": {
        "t": imu200["time"].to_numpy(), "wb": imu200[["gyro_x", "gyro_y", "gyro_z"]].to_numpy(),
        "fb": imu200[["accel_x", "accel_y", "accel_z"]].to_numpy(), "arw": np.full(3, 1e-4),
        "gb_corr": np.full(3, 20.0)}})
    data = path.read_bytes()
    monkeypatch.setitem(acquire.NAVEGO_FILES, "ekinox_imu.mat",
                        acquire.RawFile("ekinox_imu.mat", hashlib.sha256(data).hexdigest(), "0" * 40, False))
    mirror2 = tmp_path / "mirror"
    mirror2.mkdir()
    for f in REQUIRED:
        (mirror2 / f).write_bytes((mirror / f).read_bytes())
    (mirror2 / "ekinox_imu.mat").write_bytes(data)
    d = load_drive("navego-ekinox", data_dir=tmp_path / "d1", mirror=mirror2)
    assert d.meta["native_imu_rate_hz"] == pytest.approx(200.0)
    assert d.reference["time"].iloc[0] == 138001.0 and d.reference["time"].iloc[-1] == 138061.0
    imu100 = imu_from_trajectory(d.reference)
    np.testing.assert_array_equal(d.imu["time"].to_numpy(), imu100["time"].to_numpy())
    # two 5 ms mean rates average to the 10 ms one up to second-order rotation (sculling) terms
    gyro = ["gyro_x", "gyro_y", "gyro_z"]
    accel = ["accel_x", "accel_y", "accel_z"]
    assert np.abs(d.imu[gyro].to_numpy() - imu100[gyro].to_numpy()).max() < 1e-6
    assert np.abs(d.imu[accel].to_numpy() - imu100[accel].to_numpy()).max() < 1e-4
    assert d.meta["imu_errors"]["gyro_noise_density"] == [1e-4] * 3
    assert d.meta["imu_errors"]["gyro_bias_corr_time"] == [20.0] * 3
    assert d.meta["imu_errors"]["realized"] is None
    # a corrupted copy of that file is refused
    (tmp_path / "d2" / "raw").mkdir(parents=True)
    (tmp_path / "d2" / "raw" / "ekinox_imu.mat").write_bytes(data[:-5])
    with pytest.raises(ChecksumError, match="ekinox_imu.mat"):
        load_drive("navego-ekinox", data_dir=tmp_path / "d2", mirror=mirror2)


def test_profile_data_section_sets_the_parameters(env, tmp_path, monkeypatch):
    from bgfn import config

    d = load_drive("turin-sim-mpu6000", profile="smoke", cache=False, **env)
    smoke = load_profile("smoke")["data"]
    assert smoke["seed"] is None and d.meta["params"]["seed"] == load_profile("smoke")["seed"]   # null: the profile's
    assert d.reference["time"].iloc[0] == smoke["t_start"] and d.reference["time"].iloc[-1] == smoke["t_end"]
    assert d.meta["params"]["gnss_correlated_tau_s"] == smoke["turin-sim-mpu6000"]["gnss_correlated_tau_s"]
    # explicit overrides win over the profile
    assert load_drive("turin-sim-mpu6000", profile="smoke", t_start=139000.0, cache=False,
                      **env).reference["time"].iloc[0] == 139000.0
    # a misspelt key in a profile names the file and the key
    monkeypatch.setattr(config, "PARAMS_DIR", tmp_path)
    (tmp_path / "mine.yaml").write_text(
        "profile: mine\ndescription: d\nseed: 1\noutage_windows: [[139000.0, 30.0]]\nnav: {}\ntrain: {}\nevaluate: {}\nenergy: {}\n"
        "data:\n  turin-sim-ekinox:\n    gnss_rate: 1.0\n")
    with pytest.raises(DataError) as exc:
        load_drive("turin-sim-ekinox", profile="mine", **env)
    assert exc.value.field == "data.turin-sim-ekinox.gnss_rate" and "mine.yaml" in str(exc.value)

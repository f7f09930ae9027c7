"""A user's own log, end to end: a CSV folder named by path in a four-line profile runs
through notebooks 01-04's library path; outputs only under results/<profile>/, the data folder untouched.

The drive is written by the test as a logger would: IMU times that jitter (7.5-12.5 ms steps around 10 ms), a
reference at 5 Hz (not at the IMU epochs), a 1 Hz GNSS with a lever arm, times in GPS time of week.
"""

from __future__ import annotations

import importlib.util
import os
import shutil

import numpy as np
import pandas as pd
import pytest
import yaml

from bgfn import config
from bgfn.data import load_drive, write_csv_drive
from bgfn.data import imu_errors as ie
from bgfn.data.csv_meta import DEFAULT_IMU_PROFILE, META_KEYS, read_meta
from bgfn.data.names import (data_fingerprint, dataset_folder, dataset_id, drive_fingerprints, profile_datasets,
                             profile_entries, unique_ids, with_dataset_ids)
from bgfn.data.regrid import GAP_SAMPLES, interpolate_reference
from bgfn.errors import DataError
from bgfn.nav import earth, sim
from bgfn.nav.transform import dcm_from_euler
from bgfn.profile_schema import check_with_drives, load_profile
from bgfn.report import evaluation_words

pytestmark = pytest.mark.usefixtures("repo_untouched")
_spec = importlib.util.spec_from_file_location("demo_log", config.PROJECT_ROOT / "tools" / "demo_log.py")
demo_log = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(demo_log)        # the example own log CI runs end to end (tools/, not the package)

T0 = 243000.0                   # GPS time of week of the first epoch, s
FINE_HZ = 400.0                 # truth rate the jittery IMU intervals are cut from
DURATION_S = 240.0
LEVER = [-0.4, 0.0, -1.0]       # antenna in the body frame, m
OUTAGE = [T0 + 150.0, 30.0]     # one 30 s outage: 120 s of GPS time before it, 60 s after
REF_EVERY = 80                  # a reference row every 80 fine steps: 5 Hz


@pytest.fixture(scope="module")
def truth():
    ref = sim.demo_trajectory(DURATION_S, FINE_HZ)
    ref["time"] = ref["time"] + T0
    return ref


def _write_log(folder, truth, attitude=True, meta=True):
    """The drive as a logger writes it (tools/demo_log.py: jittery IMU, 5 Hz reference, 1 Hz GNSS, the ``truth``
    of this module); returns the folder."""
    demo_log.demo_log(folder, name="my-car", source="test")
    if not attitude:
        pd.read_csv(folder / "reference.csv").drop(columns=["roll", "pitch", "yaw"]).to_csv(
            folder / "reference.csv", index=False)
    if not meta:
        (folder / "meta.yaml").unlink()
    return folder


def _tree(folder):
    return {p.relative_to(folder).as_posix(): p.read_bytes() for p in sorted(folder.rglob("*")) if p.is_file()}


# ------------------------------------------------------------------------------------------- the whole path
def test_a_csv_log_named_by_its_path_runs_notebooks_01_to_04(tmp_path, monkeypatch, truth):
    from bgfn import evaluate as ev
    from bgfn import train
    from bgfn.data.summary import summary_table
    from bgfn.io import atomic_write_csv
    from bgfn.nav import baseline
    from bgfn.nav.outages import outage_windows

    log = _write_log(tmp_path / "logs" / "2024-05-01 run 3", truth)
    before = _tree(log)
    params = tmp_path / "params"
    params.mkdir()
    shutil.copy(config.PARAMS_DIR / "quick.yaml", params / "quick.yaml")
    # the README's three lines, then what keeps this test under a minute (tiny networks, one epoch, no sweep)
    (params / "mine.yaml").write_text(
        f"base: quick\ndatasets: [{log}]\noutage_windows: [{OUTAGE}]\n"
        "train: {methods: [bgfn, mlp], seeds: [0], size: smoke, lr_search: {grid: null},\n"
        "        optimizer: {epochs: 1, max_train_windows: 64, max_val_windows: 32}}\n"
        "evaluate: {methods: [bgfn, mlp], sweep: {datasets: []}}\n")
    monkeypatch.setattr(config, "PARAMS_DIR", params)
    results = tmp_path / "results"
    monkeypatch.setattr(config, "RESULTS_ROOT", results)
    monkeypatch.chdir(tmp_path)

    cfg = load_profile("mine")
    assert cfg["profile"] == "mine"                               # the file's name
    assert cfg["description"] == "profile 'mine': 'quick' with its own settings"     # none written
    did = dataset_id(str(log))
    assert did == "my-car"                                        # meta.yaml's name
    assert any(line.startswith(f"{did}: {T0:.2f}..") for line in check_with_drives("mine"))    # make's check step
    name = did                                                    # the loaded profile names the folder by its id
    assert [cfg[s]["datasets"] for s in ("data", "nav", "train", "evaluate")] == [[name]] * 4
    assert cfg["evaluate"]["sweep"]["datasets"] == []             # the file's own section wins
    out = config.results_dir("mine")

    # notebook 01
    drive = load_drive(name, profile="mine")
    assert drive.name == did and drive.has_attitude
    assert drive.meta["imu_resampled"] and drive.meta["reference_interpolated"]
    assert drive.meta["imu_rate_hz"] == 100.0 and drive.meta["reference_rate_hz"] == 5.0
    t = drive.imu["time"].to_numpy()
    np.testing.assert_allclose(np.diff(t), 0.01, atol=1e-9)      # the regular grid the outages and windows need
    atomic_write_csv(out / "tables" / f"dataset_{dataset_id(name)}.csv", summary_table(drive))
    # notebook 02
    windows = outage_windows(cfg)
    b = baseline.run_baseline(drive, baseline.nav_config(cfg["nav"]), windows)
    rec = baseline.save_baseline(b, out, did)
    assert rec["states_file"] == f"nav_states_{did}.npz"
    assert b.rms.loc["horizontal", "rms"] < 2.0                   # GPS-aided: near the 0.5 m fixes
    # notebook 03
    plan = train.TrainingPlan.of(load_profile("mine"))
    prepared = train.prepare_datasets(plan)
    cards = [c for n, d in prepared.items() for c in train.train_dataset(plan, n, d.data)]
    assert {c["method"] for c in cards} == {"bgfn", "mlp"}
    # notebook 04, with make's run cache
    monkeypatch.setenv("BGFN_CACHE_DIR", str(out / "cache"))
    setup = ev.evaluation_setup(cfg)
    res, _ = ev.run_tables(cfg, "mine", setup.datasets, setup.config, out)
    # notebook 06 builds on the same runs: read back, bit for bit, not computed again; a retrained network's are
    from bgfn.evaluate import tables
    from bgfn.train.checkpoints import card_path, checkpoint_path

    evaluate, computed = tables._evaluate, []
    monkeypatch.setattr(tables, "_evaluate", lambda dataset, *a: computed.append(dataset) or evaluate(dataset, *a))
    again = ev.outage_results(cfg, "mine", setup.datasets, setup.config)
    assert computed == [] and list(again) == [name]
    pd.testing.assert_frame_equal(again[name].per_seed, res[name].per_seed, check_exact=True)
    assert again[name].drive.name == name and set(again[name].models) == set(res[name].models)
    card = card_path(checkpoint_path("mine", name, "mlp", 0))
    card.write_text(card.read_text(encoding="utf-8") + "\n", encoding="utf-8")
    ev.outage_results(cfg, "mine", setup.datasets, setup.config)
    assert computed == [name]
    table = res[name].table
    assert set(table["method"]) == {"INS", "GPS", "BGFN", "MLP", "INS+NHC", "BGFN+NHC", "MLP+NHC"}
    assert np.isfinite(table[list(ev.METRIC_COLUMNS)].to_numpy(float)).all()
    assert res[name].test == did
    # notebook 04's displays beside the paper: a drive that stands for none of its tests has no paper values
    lay = ev.ours_above_paper(res[name])
    assert lay.xs("paper", level="source").isna().all().all() and lay.xs("ours", level="source").notna().any().any()
    red = ev.reduction_table(res[name])
    assert red["paper east_%"].isna().all() and red["paper east_%"].dtype == float
    assert set(red["method"]) == {"GPS", "BGFN", "MLP", "INS+NHC", "BGFN+NHC", "MLP+NHC"}   # each against INS
    assert evaluation_words.paper_table_title(did) == f"no table of the paper ({did})"

    written = [p.relative_to(tmp_path).as_posix() for p in tmp_path.rglob("*") if p.is_file()]
    outside = [p for p in written if not p.startswith(("results/mine/", "logs/", "params/"))]
    assert outside == []
    assert _tree(log) == before                                   # the data folder untouched
    files = [p.name for p in results.rglob("*")]
    assert f"kf_rms_{did}.csv" in files and "outage_my-car.csv" in files and "bgfn_seed0.pt" in files
    assert (out / "models" / did / "mlp_seed0.pt").is_file()
    assert not any("logs" in p or " " in p for p in written if p.startswith("results/"))
    # no machine path in a table, a record or a file name: the folder's path (and its name) appear nowhere
    texts = {p: p.read_text(encoding="utf-8") for p in results.rglob("*") if p.suffix in (".csv", ".json")}
    assert len([p for p in texts if p.suffix == ".csv"]) >= 3 and any(p.suffix == ".json" for p in texts)
    assert [p for p, text in texts.items() if str(log) in text or str(tmp_path) in text or log.name in text] == []
    assert [p for p in results.rglob("*") if log.name in p.name or "/" in p.name] == []
    assert all(did in set(pd.read_csv(p)["dataset"]) for p in texts if p.suffix == ".csv"
               and "dataset" in pd.read_csv(p, nrows=0).columns)


# ------------------------------------------------------------------------------------ regrid and reference
def test_jittery_imu_keeps_its_increments_and_the_reference_follows_the_truth(tmp_path, truth):
    log = _write_log(tmp_path / "d", truth, attitude=False, meta=False)
    drive = load_drive(log)
    assert not drive.has_attitude and drive.reference[["roll", "pitch", "yaw"]].isna().all().all()
    assert drive.name == "d" and drive.meta["imu_errors"] == ie.error_params(DEFAULT_IMU_PROFILE)
    raw = pd.read_csv(log / "imu.csv")
    # the integral of the rates over the common span is the same (resample_imu preserves increments)
    t_raw, t = raw["time"].to_numpy(), drive.imu["time"].to_numpy()
    inside = (t_raw > t[0] - 0.01 + 1e-9) & (t_raw <= t[-1])
    for c in ("gyro_z", "accel_x"):
        grid_sum = float(np.sum(drive.imu[c].to_numpy() * 0.01))
        raw_dt = np.diff(np.concatenate([[t_raw[0] - 0.01], t_raw]))
        raw_sum = float(np.sum((raw[c].to_numpy() * raw_dt)[inside]))
        assert grid_sum == pytest.approx(raw_sum, abs=0.02 * 0.01 * 10)   # up to the ends' partial intervals
    # the 5 Hz reference at the 100 Hz epochs: Hermite with the velocities as slopes, centimetres from the truth
    truth_at = truth.set_index(np.round(truth["time"].to_numpy() * 400).astype(int))
    idx = np.round(drive.reference["time"].to_numpy() * 400).astype(int)
    tr = truth_at.loc[idx]
    ned = earth.lla_to_ned(drive.reference["lat"].to_numpy(), drive.reference["lon"].to_numpy(),
                           drive.reference["h"].to_numpy(), tr["lat"].to_numpy(), tr["lon"].to_numpy(),
                           tr["h"].to_numpy())
    assert np.abs(ned).max() < 0.02
    assert np.abs(drive.reference["v_n"].to_numpy() - tr["v_n"].to_numpy()).max() < 0.05


def test_interpolated_yaw_crosses_pi_without_a_full_turn():
    ref = pd.DataFrame({"time": [0.0, 1.0], "lat": 0.8, "lon": 0.1, "h": 200.0, "v_n": 0.0, "v_e": 0.0,
                        "v_d": 0.0, "roll": 0.0, "pitch": 0.0, "yaw": [np.pi - 0.1, -np.pi + 0.1]})
    out = interpolate_reference(ref, np.array([0.0, 0.25, 0.5, 1.0]))
    np.testing.assert_allclose(np.abs(out["yaw"].to_numpy()[:3]), [np.pi - 0.1, np.pi - 0.05, np.pi], atol=1e-12)
    assert out["lat"].tolist() == pytest.approx([0.8] * 4) and out["time"].tolist() == [0.0, 0.25, 0.5, 1.0]


def test_a_gap_in_the_imu_log_names_the_file_and_the_time(tmp_path, truth):
    log = _write_log(tmp_path / "d", truth)
    imu = pd.read_csv(log / "imu.csv")
    imu = imu.drop(index=range(1000, 1000 + int(GAP_SAMPLES) + 2)).reset_index(drop=True)
    imu.to_csv(log / "imu.csv", index=False)
    with pytest.raises(DataError, match="gap") as err:
        load_drive(log)
    assert err.value.source == str(log / "imu.csv") and err.value.field == "time"
    assert f"{imu['time'].iloc[999]:.3f}" in str(err.value)


# -------------------------------------------------------------------------------- units and axes, by file
@pytest.mark.parametrize("case,file,field,words", [
    ("accel_in_g", "imu.csv", "accel_x/accel_y/accel_z", "in g"),
    ("rates_in_deg", "imu.csv", "gyro_x/gyro_y/gyro_z", "deg/s"),
    ("z_up", "imu.csv", "accel_z", "points up"),
    ("axes_unrotated", "imu.csv", "accel_z", "not rotated"),
    ("lat_in_degrees", "reference.csv", "lat", "degrees"),
    ("lon_in_degrees_gnss", "gnss.csv", "lon", "degrees"),
    ("time_in_ms", "imu.csv", "time", "milliseconds"),
])
def test_implausible_units_and_axes_name_the_csv_file_and_column(tmp_path, truth, case, file, field, words):
    log = _write_log(tmp_path / "d", truth)
    df = pd.read_csv(log / file)
    if case == "accel_in_g":
        df[["accel_x", "accel_y", "accel_z"]] /= 9.80665
    elif case == "rates_in_deg":
        df[["gyro_x", "gyro_y", "gyro_z"]] = np.degrees(df[["gyro_x", "gyro_y", "gyro_z"]])
    elif case == "z_up":
        df[["accel_z", "gyro_z"]] *= -1
    elif case == "axes_unrotated":                              # sensor x down: gravity along x
        df["accel_x"], df["accel_z"] = df["accel_z"].copy(), df["accel_x"].copy()
    elif case == "lat_in_degrees":
        df["lat"] = np.degrees(df["lat"])
    elif case == "lon_in_degrees_gnss":
        df["lon"] = np.degrees(df["lon"])
    elif case == "time_in_ms":
        df["time"] *= 1000.0
    df.to_csv(log / file, index=False)
    with pytest.raises(DataError) as err:
        load_drive(log)
    assert err.value.source == str(log / file) and err.value.field == field
    assert words in str(err.value)


# ---------------------------------------------------------------------------------------------- meta.yaml
@pytest.mark.parametrize("text,field,words", [
    ("gyro_noise_densty: 1e-4\n", "gyro_noise_densty", "did you mean imu_errors.gyro_noise_density?"),
    ("nmae: x\n", "nmae", "did you mean name?"),
    ("imu_errors:\n  gyro_noise_densty: 1e-4\n", "imu_errors.gyro_noise_densty",
     "did you mean imu_errors.gyro_noise_density?"),
    ("imu_errors:\n  accel_bias_instabilty: 1e-3\n", "imu_errors.accel_bias_instabilty",
     "imu_errors.accel_bias_instability"),
    ("imu_errors:\n  gyro_noise_density: -1\n", "imu_errors.gyro_noise_density", "non-negative"),
    ("imu_errors:\n  gyro_noise_density: [1, 2]\n", "imu_errors.gyro_noise_density", "3 finite values"),
    ("imu_errors:\n  gyro_noise_density: fast\n", "imu_errors", "numbers"),
    ("imu_errors:\n  base: bosch\n", "imu_errors.base", "mpu6000"),
    ("imu_errors: [1, 2]\n", "imu_errors", "a mapping"),
    ("lever_arm_m: [1.0, 2.0]\n", "lever_arm_m", "3 finite numbers"),
    ("name: my drive/2\n", "name", "dataset id"),
    ("- a\n- b\n", "<top level>", "a mapping"),
    ("name: [unclosed\n", "<yaml>", "valid YAML"),
    # the keys of real logs
    ("platform: boat\n", "platform", "car, walker, other"),
    ("gnss_latency_s: 18.0\n", "gnss_latency_s", "18 s between GPS time and UTC"),
    ("gnss_latency_s: -0.1\n", "gnss_latency_s", ">= 0"),
    ("imu_mounting_deg: [0, 0]\n", "imu_mounting_deg", "[roll, pitch, yaw]"),
    ("gnss_std_m: [0.5, 0, 1]\n", "gnss_std_m", "positive"),
])
def test_a_bad_meta_yaml_gives_one_clear_error(tmp_path, text, field, words):
    path = tmp_path / "meta.yaml"
    path.write_text(text)
    with pytest.raises(DataError) as err:
        read_meta(path)
    assert err.value.source == str(path) and err.value.field == field
    assert words in str(err.value)


@pytest.mark.parametrize("text,expect", [
    (None, {"gyro_noise_density": ie.MPU6000["gyro_noise_density"]}),                  # no file
    ("", {"gyro_noise_density": ie.MPU6000["gyro_noise_density"]}),                    # empty file
    ("name: car\nimu_errors:\n", {"gyro_noise_density": ie.MPU6000["gyro_noise_density"]}),
    ("imu_errors: {gyro_noise_density: 1.0e-3}\n",
     {"gyro_noise_density": [1e-3] * 3, "accel_noise_density": ie.MPU6000["accel_noise_density"]}),
    ("imu_errors: {base: ekinox-d, accel_noise_density: [1, 2, 3]}\n",
     {"accel_noise_density": [1.0, 2.0, 3.0], "gyro_noise_density": ie.EKINOX_D["gyro_noise_density"]}),
])
def test_meta_defaults_and_overrides(tmp_path, text, expect):
    path = tmp_path / "meta.yaml"
    if text is not None:
        path.write_text(text)
    meta = read_meta(path)
    for key, value in expect.items():
        assert meta["imu_errors"][key] == pytest.approx(value)
    assert meta["lever_arm_m"] == [0.0, 0.0, 0.0] and meta["source"] is None
    assert set(yaml.safe_load(path.read_text()) or {}) <= set(META_KEYS) if text is not None else True


# --------------------------------------------------------------------------------------------- dataset ids
def test_dataset_ids_are_safe_and_keep_the_shipped_names(tmp_path, monkeypatch):
    assert dataset_id("turin-sim-ekinox") == "turin-sim-ekinox" and dataset_id("my-car") == "my-car"
    a = tmp_path / "Drive 1 (rain)"
    a.mkdir()
    assert dataset_id(a) == "Drive-1-rain-" and dataset_id(str(a) + "/") == "Drive-1-rain-"
    assert dataset_id(dataset_id(a)) == dataset_id(a)             # idempotent on ids
    (a / "meta.yaml").write_text("name: rainy\n")
    assert dataset_id(a) == "rainy"
    monkeypatch.chdir(tmp_path)
    assert dataset_folder("Drive 1 (rain)") == a.resolve() and dataset_id("Drive 1 (rain)") == "rainy"
    assert dataset_id("/no/such/folder/x y") == "x-y"
    b = tmp_path / "other"
    b.mkdir()
    (b / "meta.yaml").write_text("name: rainy\n")
    with pytest.raises(DataError, match="both have the id 'rainy'"):
        unique_ids([str(a), str(b)])
    assert unique_ids(["turin-sim-ekinox", str(a)]) == {"turin-sim-ekinox": "turin-sim-ekinox", str(a): "rainy"}


def test_a_loaded_profile_names_its_folders_by_id_and_refuses_two_of_one_id(tmp_path, monkeypatch):
    params = tmp_path / "params"
    params.mkdir()
    shutil.copy(config.PARAMS_DIR / "quick.yaml", params / "quick.yaml")
    monkeypatch.setattr(config, "PARAMS_DIR", params)
    a, b = tmp_path / "logs" / "Drive 1", tmp_path / "other" / "Drive 1"    # two folders of one name
    for folder in (a, b):
        folder.mkdir(parents=True)
    (params / "two.yaml").write_text(f"base: quick\ndatasets: ['{a}', '{b}']\n"
                                     f"outage_windows: {{'{a}': [[1.0, 2.0]], default: [[3.0, 4.0]]}}\n")
    with pytest.raises(DataError, match="both have the id 'Drive-1'") as err:
        load_profile("two")                                       # before any drive is loaded
    assert err.value.source == str(params / "two.yaml")
    (b / "meta.yaml").write_text("name: second\n")              # meta.yaml's name tells them apart
    cfg = load_profile("two")
    assert [cfg[s]["datasets"] for s in ("data", "nav", "train", "evaluate")] == [["Drive-1", "second"]] * 4
    ow = cfg["outage_windows"]
    assert ow["Drive-1"] == [[1.0, 2.0]] and ow["default"] == [[3.0, 4.0]] and not any("/" in k for k in ow)
    assert dataset_folder("second", "two") == b.resolve() and dataset_folder("second") is None
    assert dataset_folder("Drive-1", "two") == a.resolve()
    from bgfn.profile_schema import _typed
    assert _typed("two", "outage_windows.Drive-1") and not _typed("two", "outage_windows.second")   # kept as typed
    quick = config.read_profile("quick")
    assert with_dataset_ids(quick) == quick                       # the shipped drives keep their keys
    (params / "gone.yaml").write_text(f"base: quick\ndatasets: ['{tmp_path / 'absent' / 'run 9'}']\n")
    assert load_profile("gone")["data"]["datasets"] == ["run-9"]
    with pytest.raises(DataError) as err:                         # the missing folder named as the file names it
        load_drive("run-9", profile="gone")
    assert err.value.field == "folder" and str(tmp_path / "absent" / "run 9") in str(err.value)


def test_an_id_that_would_load_another_drive_or_merge_two_keys_is_refused(tmp_path, monkeypatch):
    params = tmp_path / "params"
    params.mkdir()
    shutil.copy(config.PARAMS_DIR / "quick.yaml", params / "quick.yaml")
    monkeypatch.setattr(config, "PARAMS_DIR", params)
    copy, odo = tmp_path / "copy", tmp_path / "odo run"
    for folder in (copy, odo):
        folder.mkdir()
    (copy / "meta.yaml").write_text("name: rtklib-drive0708\n")   # a copy of the shipped drive, its name kept
    (params / "copy.yaml").write_text(f"base: quick\ndatasets: ['{copy}']\n")
    with pytest.raises(DataError, match="has the id 'rtklib-drive0708'"):
        load_profile("copy")                                      # it would have loaded the built-in drive
    (copy / "meta.yaml").write_text("name: default\n")
    with pytest.raises(DataError, match="has the id 'default'"):
        load_profile("copy")                                      # it would read as every drive's default
    # a folder named only in the odometer's list is found again by its id
    (params / "odo.yaml").write_text(f"base: quick\nevaluate: {{odometer: {{datasets: ['{odo}']}}}}\n")
    assert load_profile("odo")["evaluate"]["odometer"]["datasets"] == ["odo-run"]
    assert dataset_folder("odo-run", "odo") == odo.resolve()
    # two keys of one drive (its path and its id) in a per-drive mapping: refused, not one silently dropped
    (params / "twice.yaml").write_text(f"base: quick\ndatasets: ['{odo}']\n"
                                       f"outage_windows: {{'{odo}': [[1.0, 2.0]], odo-run: [[3.0, 4.0]]}}\n")
    with pytest.raises(DataError, match="two keys with the id 'odo-run'"):
        load_profile("twice")


def test_attitude_all_three_or_none(tmp_path, monkeypatch, truth):
    log = _write_log(tmp_path / "d", truth)
    pd.read_csv(log / "reference.csv").drop(columns=["yaw"]).to_csv(log / "reference.csv", index=False)
    with pytest.raises(DataError) as err:
        load_drive(log)
    assert err.value.source == str(log / "reference.csv") and err.value.field == "yaw"
    _write_log(tmp_path / "e", truth, attitude=False)
    monkeypatch.chdir(tmp_path)
    drive = load_drive("e")                                              # a relative folder path
    assert not drive.has_attitude and drive.validate() is drive        # all NaN: a drive without attitude
    drive.reference.loc[3, ["roll", "pitch", "yaw"]] = 0.0               # some NaN: a broken reference
    with pytest.raises(DataError) as err:
        drive.validate()
    assert err.value.field == "roll"


def test_the_imu_plot_shows_a_drive_on_another_clock(tmp_path, truth):
    import matplotlib

    matplotlib.use("Agg")
    from bgfn.data.plots import plot_imu_channels

    drive = load_drive(_write_log(tmp_path / "d", truth))
    fig = plot_imu_channels({"d": drive}, 138840.0, 20.0)      # quick's plot span lies on the Turin clock
    x = fig.axes[0].lines[0].get_xdata()
    assert len(x) == 2001 and x[0] == pytest.approx(0.0) and x[-1] == pytest.approx(20.0)   # its first 20 s
    matplotlib.pyplot.close(fig)


def test_a_missing_folder_is_named(tmp_path):
    with pytest.raises(DataError) as err:
        load_drive(str(tmp_path / "absent"))
    assert err.value.field == "folder" and str(tmp_path / "absent") in str(err.value)


def test_top_level_datasets_reach_every_notebook_and_a_section_still_wins(tmp_path, monkeypatch):
    params = tmp_path / "params"
    params.mkdir()
    shutil.copy(config.PARAMS_DIR / "quick.yaml", params / "quick.yaml")
    monkeypatch.setattr(config, "PARAMS_DIR", params)
    (params / "mine.yaml").write_text("base: quick\ndescription: d\ndatasets: [a/b]\n")
    (params / "again.yaml").write_text("base: mine\ndescription: e\nnav: {datasets: [c]}\n")
    (params / "bad.yaml").write_text("base: quick\ndescription: d\ndatasets: []\n")
    mine, again = load_profile("mine"), load_profile("again")
    quick = load_profile("quick")
    for section in ("data", "nav", "train", "evaluate"):                  # a folder by its id (dataset_id)
        assert mine[section]["datasets"] == ["b"]
    assert mine["evaluate"]["sweep"]["datasets"] == ["b"] and mine["profile"] == "mine"
    assert again["nav"]["datasets"] == ["c"] and again["train"]["datasets"] == ["b"]
    assert {k: v for k, v in mine["train"].items() if k != "datasets"} == {
        k: v for k, v in quick["train"].items() if k != "datasets"}
    with pytest.raises(DataError) as err:
        load_profile("bad")
    assert err.value.field == "datasets" and err.value.source == str(params / "bad.yaml")


def test_the_data_fingerprint_changes_when_a_drive_file_is_touched_and_only_then(tmp_path, truth):
    log = _write_log(tmp_path / "run", truth)
    cfg = {"data": {"datasets": [str(log), "turin-sim-ekinox"]}, "evaluate": {"sweep": {"datasets": [str(log)]}}}
    assert profile_datasets(cfg) == [str(log), "turin-sim-ekinox"]
    first = data_fingerprint(profile_datasets(cfg))
    assert data_fingerprint(profile_datasets(cfg)) == first                     # nothing changed: same stamp
    assert data_fingerprint(["turin-sim-ekinox"]) == data_fingerprint([])       # checksummed elsewhere
    st = (log / "imu.csv").stat()
    os.utime(log / "imu.csv", ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))   # `touch imu.csv`
    assert data_fingerprint(profile_datasets(cfg)) != first
    # a folder named only in the odometer's lists is fingerprinted too (every entry of the profile); one named only
    # in a fleet is the fleet's fingerprint's (notebook 11 alone reads it), unless another list names it by its id
    other = _write_log(tmp_path / "fleet drive", truth)
    meta = other / "meta.yaml"                                   # another drive: another id
    meta.write_text(meta.read_text(encoding="utf-8").replace("my-car", "fleet-car"), encoding="utf-8")
    assert dataset_id(other) == "fleet-car"

    def touch_other():
        st = (other / "gnss.csv").stat()
        os.utime(other / "gnss.csv", ns=(st.st_atime_ns, st.st_mtime_ns + 1_000_000_000))

    odometer = {**cfg, "evaluate": {"odometer": {"datasets": [str(other)]}}}
    assert str(other) in profile_entries(odometer) and str(other) not in profile_datasets(odometer)
    before = drive_fingerprints(odometer)
    touch_other()
    assert drive_fingerprints(odometer)[0] != before[0]
    fleet = {**cfg, "fleet": {"drives": [str(other)]}}
    assert str(other) in profile_entries(fleet) and str(other) not in profile_entries(fleet, fleet=False)
    before = drive_fingerprints(fleet)
    touch_other()
    after = drive_fingerprints(fleet)
    assert after[0] == before[0] and after[1] != before[1]
    by_id = {"data": {"datasets": [dataset_id(other)]}, "fleet": {"drives": [str(other)]}}   # one drive
    before = drive_fingerprints(by_id)
    touch_other()
    after = drive_fingerprints(by_id)
    assert after[0] != before[0] and after[1] != before[1]


# ------------------------------------------------------------------------ meta.yaml: platform, mounting, clocks
def test_meta_states_platform_mounting_clock_shifts_and_a_default_fix_std(tmp_path, truth):
    log = _write_log(tmp_path / "run", truth)
    plain = load_drive(log)
    assert plain.meta["platform"] == "car" and plain.meta["time_shifts_s"] == {"imu_time_offset_s": 0.0,
                                                                               "gnss_latency_s": 0.0}
    # the IMU mounted yawed by 90 deg (its x axis along the body's y): the log holds sensor-frame rows
    imu = pd.read_csv(log / "imu.csv")
    turned = imu.assign(gyro_x=imu["gyro_y"], gyro_y=-imu["gyro_x"], accel_x=imu["accel_y"], accel_y=-imu["accel_x"])
    turned.to_csv(log / "imu.csv", index=False)
    gnss = pd.read_csv(log / "gnss.csv")
    gnss.drop(columns=["std_n", "std_e", "std_d"]).assign(time=gnss["time"] + 0.2).to_csv(log / "gnss.csv",
                                                                                           index=False)
    meta = yaml.safe_load((log / "meta.yaml").read_text())
    with pytest.raises(DataError, match="gnss_std_m"):              # no std column and no default: one error
        load_drive(log)
    meta.update(platform="walker", imu_mounting_deg=[0, 0, 90], gnss_latency_s=0.2, gnss_std_m=[0.5, 0.5, 1.0])
    (log / "meta.yaml").write_text(yaml.safe_dump(meta))
    d = load_drive(log)
    assert d.meta["platform"] == "walker"
    np.testing.assert_allclose(d.imu[["gyro_x", "accel_x", "accel_y"]], plain.imu[["gyro_x", "accel_x", "accel_y"]],
                               atol=1e-9)                           # rotated back into the body frame
    np.testing.assert_allclose(d.gnss["time"], plain.gnss["time"], atol=1e-9)          # the latency taken off
    assert (d.gnss["std_n"] == 0.5).all() and (d.gnss["std_d"] == 1.0).all()


def test_gnss_on_another_clock_is_one_error_naming_both_files_or_is_estimated_when_asked(tmp_path):
    """The real drive through the CSV path: its GNSS 18 s late (UTC against GPS time) fails at load naming the
    leap seconds; 0.8 s late with ``gnss_latency_s: auto`` is found and taken off."""
    mirror = next((f for f in (config.PROJECT_ROOT / "data" / "raw",
                               config.PROJECT_ROOT.parent / "shared" / "data" / "rtklib-drive0708")
                   if (f / "imu_1934.csv").is_file()), None)
    if mirror is None:
        pytest.skip("the rtklib-drive0708 files are not available (data/raw or ../shared/data/rtklib-drive0708)")
    drive = load_drive("rtklib-drive0708", data_dir=tmp_path / "data", mirror=mirror, download=False)
    folder = write_csv_drive(drive, tmp_path / "car")
    gnss = pd.read_csv(folder / "gnss.csv")
    gnss.assign(time=gnss["time"] + 18.0).to_csv(folder / "gnss.csv", index=False)
    with pytest.raises(DataError) as err:
        load_drive(folder)
    assert err.value.source == str(folder / "gnss.csv") and "imu.csv" in str(err.value)
    assert "18 s apart" in str(err.value)
    gnss.assign(time=gnss["time"] + 0.8).to_csv(folder / "gnss.csv", index=False)
    meta = yaml.safe_load((folder / "meta.yaml").read_text())
    (folder / "meta.yaml").write_text(yaml.safe_dump({**meta, "gnss_latency_s": "auto"}))
    d = load_drive(folder)
    assert d.meta["gnss_offset"]["applied_latency_s"] == pytest.approx(0.8, abs=0.15)   # 0.8 s + the drive's own
    assert d.meta["gnss_offset"]["status"] == "applied"                                  # the reference agrees
    assert abs(d.meta["gnss_offset"]["reference_lag_s"] - 0.8) <= 3 * d.meta["gnss_offset"]["reference_std_s"]


def test_a_margin_too_long_for_a_short_log_is_named_as_the_cause(tmp_path, monkeypatch, truth):
    log = _write_log(tmp_path / "run", truth)
    params = tmp_path / "params"
    params.mkdir()
    shutil.copy(config.PARAMS_DIR / "quick.yaml", params / "quick.yaml")
    (params / "mine.yaml").write_text(f"base: quick\ndatasets: [{log}]\noutage_windows: [{OUTAGE}]\n"
                                      "train: {margin_s: 120.0}\n")
    monkeypatch.setattr(config, "PARAMS_DIR", params)
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path / "results")
    with pytest.raises(DataError) as err:
        check_with_drives("mine")
    assert err.value.field == "train.margin_s" and "set train.margin_s to at most" in str(err.value)


def test_jittery_gnss_stamps_go_onto_their_grid_or_fail_at_load(tmp_path, truth):
    log = _write_log(tmp_path / "run", truth)
    plain = load_drive(log)
    gnss = pd.read_csv(log / "gnss.csv")
    rng = np.random.default_rng(1)
    gnss.assign(time=gnss["time"] + rng.uniform(0.0, 0.06, len(gnss))).to_csv(log / "gnss.csv", index=False)
    d = load_drive(log)                                           # arrival jitter of up to 60 ms at 1 Hz
    assert 0.0 < d.meta["gnss_regridded_max_s"] <= 0.1
    steps = np.diff(d.gnss["time"].to_numpy())
    np.testing.assert_allclose(steps, 1.0, atol=1e-9)            # a rate that divides: 1 Hz exactly
    n = min(len(d.gnss), len(plain.gnss))                        # a fix moved past the IMU's end is cropped
    assert np.abs(d.gnss["time"].to_numpy()[:n] - plain.gnss["time"].to_numpy()[:n]).max() < 0.06
    gnss.assign(time=gnss["time"] + rng.uniform(0.0, 0.4, len(gnss))).to_csv(log / "gnss.csv", index=False)
    with pytest.raises(DataError) as err:
        load_drive(log)
    assert err.value.source == str(log / "gnss.csv") and "arrival jitter" in str(err.value)


def test_a_reference_given_at_an_antenna_is_moved_to_the_imu(tmp_path, truth):
    """The reference written 1 m ahead and 1.5 m above the IMU (the body frame's x and -z): with
    ``reference_lever_arm_m`` it comes back to the IMU's track (at the reference's attitude)."""
    log = _write_log(tmp_path / "run", truth)
    plain = load_drive(log)
    lever = np.array([1.0, 0.0, -1.5])
    ref = pd.read_csv(log / "reference.csv")
    c = dcm_from_euler(ref["roll"].to_numpy(), ref["pitch"].to_numpy(), ref["yaw"].to_numpy()).reshape(-1, 3, 3)
    ned = c @ lever
    r_m, r_n = earth.curvature_radii(ref["lat"].to_numpy())
    moved = ref.assign(lat=ref["lat"] + ned[:, 0] / (r_m + ref["h"]),
                       lon=ref["lon"] + ned[:, 1] / ((r_n + ref["h"]) * np.cos(ref["lat"])), h=ref["h"] - ned[:, 2])
    moved.to_csv(log / "reference.csv", index=False)
    meta = yaml.safe_load((log / "meta.yaml").read_text())
    (log / "meta.yaml").write_text(yaml.safe_dump({**meta, "reference_lever_arm_m": lever.tolist()}))
    back = load_drive(log)
    dn = (back.reference["lat"] - plain.reference["lat"]).to_numpy() * 6.37e6
    assert np.abs(dn).max() < 0.01 and np.abs(back.reference["h"] - plain.reference["h"]).max() < 0.01

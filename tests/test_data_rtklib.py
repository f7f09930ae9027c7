"""The real car drive rtklib-drive0708: RTKLIB readers on hand-made files, and the dataset on the real files."""

from __future__ import annotations

import datetime
import hashlib
import os
import struct

import numpy as np
import pandas as pd
import pytest

from bgfn.data import Drive, acquire, load_drive, rtklib
from bgfn.data.drives import DATASETS, dataset_params, profile_overrides
from bgfn.data.gnss import antenna_position, course_over_ground, fix_errors, imu_position
from bgfn.data.imu_errors import G0
from bgfn.data.imu_levels import imu_levels, level_summary, rest_biases, rest_spans
from bgfn.data.physics import check_drive
from bgfn.errors import ChecksumError, DataError
from bgfn.nav import metrics
from bgfn.nav.earth import normal_gravity
from synthetic_drive import exact_drive

pytestmark = pytest.mark.usefixtures("repo_untouched")

#: 2025-07-08 19:34:21 GPST as RTKLIB's gtime_t (seconds since 1970 in the GPS time scale): GPS week 2374,
#: Tuesday, so second of the week 2 * 86400 + 19 * 3600 + 34 * 60 + 21.
START_S, START_FRAC = 1752003261, 0.854
WEEK, START_TOW = 2374, 2 * 86400 + 19 * 3600 + 34 * 60 + 21 + 0.854


def _tag_bytes(pairs, header=b"TIMETAG RTKLIB demo5", start=START_S, frac=START_FRAC, tick0=1234):
    head = header.ljust(rtklib.TAG_HEADER_BYTES, b"\0")
    body = b"".join(struct.pack("<II", t, p) for t, p in pairs)
    return head + struct.pack("<II", tick0, start) + struct.pack("<d", frac) + body


# ------------------------------------------------------------------------------------------------ time tags
def test_gps_week_and_second_of_week_by_hand():
    days = (datetime.date(2025, 7, 8) - datetime.date(1980, 1, 6)).days
    assert days // 7 == WEEK and days % 7 == 2   # a Tuesday
    week, tow = rtklib.week_and_tow(START_S - rtklib.GPS_EPOCH_UNIX_S, START_FRAC)
    assert week == WEEK and tow[0] == pytest.approx(START_TOW, abs=1e-9)
    # a drive over the week's end keeps counting from the first week
    week, tow = rtklib.week_and_tow([(WEEK + 1) * rtklib.SECONDS_PER_WEEK - 1, (WEEK + 1) * rtklib.SECONDS_PER_WEEK])
    assert week == WEEK and tow.tolist() == [rtklib.SECONDS_PER_WEEK - 1.0, rtklib.SECONDS_PER_WEEK]


def test_tag_reader_on_a_hand_made_file(tmp_path):
    path = tmp_path / "imu.csv.tag"
    path.write_bytes(_tag_bytes([(131, 37), (146, 99), (5000, 4000)]))
    tags = rtklib.read_tag(path)
    assert tags.start_gps_whole_s == START_S - rtklib.GPS_EPOCH_UNIX_S and tags.start_frac_s == START_FRAC
    assert tags.start_tick_ms == 1234 and tags.tick_ms.tolist() == [131, 146, 5000]
    assert tags.file_pos.tolist() == [37, 99, 4000] and tags.span_s == 5.0


@pytest.mark.parametrize("damage, field", [
    (lambda b: b"NOT A TAG FILE" + b[14:], "header"),
    (lambda b: b[:-3], "records"),
    (lambda b: _tag_bytes([(200, 1), (100, 2)]), "tick"),
])
def test_tag_reader_names_the_defect(tmp_path, damage, field):
    path = tmp_path / "bad.tag"
    path.write_bytes(damage(_tag_bytes([(131, 37), (146, 99)])))
    with pytest.raises(DataError) as err:
        rtklib.read_tag(path)
    assert err.value.field == field and str(path) in str(err.value)


# ------------------------------------------------------------------------------------------------- IMU CSV
def _csv(tmp_path, rows, first="garbage,first", last="0.1,0.2"):
    path = tmp_path / "imu.csv"
    path.write_text("\n".join([first] + [",".join(str(v) for v in r) for r in rows] + [last]) + "\n")
    tag = tmp_path / "imu.csv.tag"
    tag.write_bytes(_tag_bytes([(100, 10), (2000, 200)]))
    return path, rtklib.read_tag(tag)


def test_counter_gives_the_gps_time_of_each_sample(tmp_path):
    path, tags = _csv(tmp_path, [[0, 0, 1, 0, 0, 0, c] for c in (261916, 261926, 261937, 261945)])
    imu, info = rtklib.read_imu_csv(path, tags)
    # start + elapsed counter + offset; the first and the last line are not samples
    expected = START_TOW + np.array([0.0, 0.010, 0.021, 0.029]) + rtklib.IMU_TIME_OFFSET_S
    np.testing.assert_allclose(imu["time"], expected, atol=1e-9)
    assert info["week"] == WEEK and info["n_samples"] == 4 and not info["stretched"]
    assert info["step_s"] == pytest.approx([0.008, 0.010, 0.011])
    # the source's mapping stretches the counter to the tags' span (2.0 s here)
    stretched, info = rtklib.read_imu_csv(path, tags, stretch_to_tags=True, time_offset_s=0.0)
    np.testing.assert_allclose(stretched["time"] - START_TOW, [0.0, 2.0 * 10 / 29, 2.0 * 21 / 29, 2.0], atol=1e-9)
    assert info["tag_span_ratio"] == pytest.approx(2.0 / 0.029)
    # times in the seconds of another week
    later, _ = rtklib.read_imu_csv(path, tags, week=WEEK - 1)
    np.testing.assert_allclose(later["time"] - imu["time"], rtklib.SECONDS_PER_WEEK)


def _groves_euler_to_ctm(r, p, y):
    """Groves (2013) Eq. 2.22, coordinate transformation of the Euler rotation (the source's Euler_to_CTM)."""
    sr, cr, sp, cp, sy, cy = np.sin(r), np.cos(r), np.sin(p), np.cos(p), np.sin(y), np.cos(y)
    return np.array([[cp * cy, cp * sy, -sp],
                     [-cr * sy + sr * sp * cy, cr * cy + sr * sp * sy, sr * cp],
                     [sr * sy + cr * sp * cy, -sr * cy + cr * sp * sy, cr * cp]])


def test_axis_rotation_is_the_sources_and_keeps_lengths():
    angles = np.array(rtklib.MOUNTING_DEG) + np.array(rtklib.MISALIGNMENT_DEG)
    c = rtklib.imu_to_body_dcm()
    np.testing.assert_allclose(c, _groves_euler_to_ctm(*np.radians(angles)), atol=1e-15)
    np.testing.assert_allclose(c @ c.T, np.eye(3), atol=1e-15)
    # the mounting alone: sensor (x, y, z) -> body (-x, y, -z)
    np.testing.assert_allclose(rtklib.imu_to_body_dcm(rtklib.MOUNTING_DEG, (0, 0, 0)), np.diag([-1.0, 1.0, -1.0]),
                               atol=1e-15)


def test_units_and_axes_of_a_level_imu_at_rest(tmp_path):
    # the mounted sensor's z axis points up: at rest it reads +1 g there, and a 10 deg/s turn to the right
    # (clockwise seen from above) about the sensor's up axis
    rows = [[0.0, 0.0, 1.0, 0.0, 0.0, -10.0, 1000 + 10 * k] for k in range(5)]
    path, tags = _csv(tmp_path, rows)
    imu, _ = rtklib.read_imu_csv(path, tags, misalignment_deg=(0, 0, 0))
    np.testing.assert_allclose(imu[["accel_x", "accel_y", "accel_z"]].to_numpy(), [[0.0, 0.0, -G0]] * 5, atol=1e-12)
    np.testing.assert_allclose(imu[["gyro_x", "gyro_y", "gyro_z"]].to_numpy(), [[0.0, 0.0, np.radians(10.0)]] * 5,
                               atol=1e-15)
    # with the measured misalignment gravity stays g long and mostly along body z (the project's sign: -g)
    imu, _ = rtklib.read_imu_csv(path, tags)
    f = imu[["accel_x", "accel_y", "accel_z"]].to_numpy()
    np.testing.assert_allclose(np.linalg.norm(f, axis=1), G0, rtol=1e-12)
    assert (f[:, 2] < -0.99 * G0).all() and (f[:, 2] > -G0).all()


@pytest.mark.parametrize("rows, field", [
    ([[0, 0, 1, 0, 0, 0, 5], [0, 0, 1, 0, 0, 0, 5]], "counter"),
    ([[0, 0, 1, 0, 0, 0], [0, 0, 1, 0, 0, 0]], "columns"),
    ([[0, 0, "x", 0, 0, 0, 5], [0, 0, 1, 0, 0, 0, 15]], "values"),
])
def test_bad_imu_lines_are_named(tmp_path, rows, field):
    path, tags = _csv(tmp_path, rows)
    with pytest.raises(DataError) as err:
        rtklib.read_imu_csv(path, tags)
    assert err.value.field == field


# ------------------------------------------------------------------------------------------------- .pos file
POS_LINES = """% program   : RTKLIB ver.demo5
%  GPST            latitude(deg) longitude(deg) height(m) Q  ns  sdn(m) sde(m) sdu(m) sdne sdeu sdun age ratio vn(m/s) ve(m/s) vu(m/s) sdvn sdve sdvu sdvne sdveu sdvun
2025/07/08 19:34:21.999 40.0 -105.0 1601.5 1.0 21.0 0.01 0.02 0.03 0 0 0 0 0 1.5 -2.0 0.25 0.05 0.06 0.07 0 0 0
2025/07/08 19:34:22.249 40.5 -105.5 1602.5 2.0 20.0 0.11 0.12 0.13 0 0 0 0 0 0.0 0.0 -0.5 0.05 0.06 0.07 0 0 0
2025/07/08 19:34:22.499 41.0 -106.0 1603.5 1.0 21.0 0.01 0.02 0.03 0 0 0 0 0 0.0 0.0 0.0 0.05 0.06 0.07 0 0 0
"""


def test_pos_reader_on_hand_written_lines(tmp_path):
    path = tmp_path / "sol.pos"
    path.write_text(POS_LINES)
    pos, week = rtklib.read_pos(path)
    assert week == WEEK and list(pos.columns) == list(rtklib.POS_COLUMNS)
    np.testing.assert_allclose(pos["time"], START_TOW - 0.854 + np.array([0.999, 1.249, 1.499]), atol=1e-9)
    np.testing.assert_allclose(pos["lat"], np.radians([40.0, 40.5, 41.0]), rtol=1e-15)
    np.testing.assert_allclose(pos["lon"], np.radians([-105.0, -105.5, -106.0]), rtol=1e-15)
    assert pos["q"].tolist() == [1.0, 2.0, 1.0] and pos["ns"].tolist() == [21.0, 20.0, 21.0]
    assert pos.loc[0, ["std_n", "std_e", "std_d"]].tolist() == [0.01, 0.02, 0.03]
    assert pos.loc[0, ["v_n", "v_e", "v_d"]].tolist() == [1.5, -2.0, -0.25]    # up 0.25 = down -0.25
    assert pos["v_d"].tolist()[1] == 0.5
    assert rtklib.quality_spans(pos) == [[pos["time"][0], pos["time"][2]]]


@pytest.mark.parametrize("edit, field", [
    (lambda s: s.replace(" 0.05 0.06 0.07 0 0 0\n", "\n"), "columns"),          # no velocity columns
    (lambda s: s.replace("40.0 -105.0", "1278000.0 -4710000.0"), "latitude/longitude"),  # ECEF output
    (lambda s: s.replace("19:34:22.249", "19:34:21.000"), "time"),
    (lambda s: s.replace("2025/07/08 19:34:22.249", "2025/07/08 nonsense"), "date/values"),
])
def test_pos_reader_names_the_defect(tmp_path, edit, field):
    path = tmp_path / "sol.pos"
    path.write_text(edit(POS_LINES))
    with pytest.raises(DataError) as err:
        rtklib.read_pos(path)
    assert err.value.field == field and str(path) in str(err.value)


def test_quality_spans_bracket_each_run_of_other_epochs():
    pos = pd.DataFrame({"time": np.arange(8.0), "q": [2, 1, 1, 2, 2, 1, 1, 5]})
    assert rtklib.quality_spans(pos) == [[0.0, 1.0], [2.0, 5.0], [6.0, 7.0]]
    assert rtklib.quality_spans(pos.assign(q=1)) == []


# ------------------------------------------------------------------------- references without attitude
@pytest.fixture(scope="module")
def demo():
    return exact_drive(60.0)


def test_a_reference_without_attitude_is_accepted_but_not_a_partial_one(demo):
    assert demo.has_attitude
    bare = Drive("bare", demo.reference.assign(roll=np.nan, pitch=np.nan, yaw=np.nan), demo.imu, demo.gnss,
                 demo.meta)
    assert not bare.validate().has_attitude
    assert check_drive(bare)["reference_attitude"] is False and check_drive(demo)["reference_attitude"] is True
    yaw = demo.reference["yaw"].to_numpy(copy=True)
    yaw[7] = np.nan
    partial = Drive("partial", demo.reference.assign(yaw=yaw), demo.imu, demo.gnss, demo.meta)
    with pytest.raises(DataError) as err:
        partial.validate()
    assert err.value.field == "yaw" and "row 7" in str(err.value)
    with pytest.raises(DataError, match="roll"):
        Drive("half", demo.reference.assign(roll=np.nan), demo.imu, demo.gnss, demo.meta).validate()


def test_course_over_ground_holds_through_slow_epochs():
    v_n = np.array([0.0, 0.1, 2.0, 0.0, 0.2, -3.0])
    v_e = np.array([0.0, 0.0, 2.0, 0.5, 0.0, 0.0])
    np.testing.assert_allclose(course_over_ground(v_n, v_e, 1.0), [np.pi / 4] * 5 + [np.pi])
    assert course_over_ground([0.0], [0.0]).tolist() == [0.0]


def test_imu_position_inverts_antenna_position_without_attitude(demo):
    bare = demo.reference.assign(roll=np.nan, pitch=np.nan, yaw=np.nan)
    lever = [0.3, -0.05, -1.2]
    lat, lon, h = antenna_position(bare, lever)
    back = imu_position(bare.assign(lat=lat, lon=lon, h=h), lever)
    for x, c in zip(back, ("lat", "lon", "h")):
        np.testing.assert_allclose(x, bare[c], atol=1e-12 if c != "h" else 1e-6)
    # level along the course: the lateral arm moves the antenna perpendicular to the velocity, by the arm
    v = bare[["v_n", "v_e"]].to_numpy()
    moving = np.hypot(*v.T) > 1.0
    lat2, lon2, _ = antenna_position(bare, [0.0, 1.0, 0.0])
    ned = metrics.earth.lla_to_ned(lat2, lon2, bare["h"].to_numpy(), bare["lat"].to_numpy(), bare["lon"].to_numpy(),
                                   bare["h"].to_numpy())
    np.testing.assert_allclose(np.hypot(ned[:, 0], ned[:, 1]), 1.0, atol=1e-6)
    np.testing.assert_allclose((ned[:, :2] * v).sum(axis=1)[moving], 0.0, atol=1e-6)   # right of the track


# ------------------------------------------------------------------------ excluded spans in the metrics
def test_metrics_skip_the_excluded_reference_spans(demo):
    ref = demo.reference
    traj = ref.iloc[::10].reset_index(drop=True)
    traj = traj.assign(lat=traj["lat"] + 1e-6)            # about 6.4 m north everywhere
    spans = [[10.0, 12.0], [30.05, 30.05]]
    meta = {metrics.REFERENCE_EXCLUDED_KEY: spans}
    keep = metrics.reference_rows(traj["time"], meta)
    t = traj["time"].to_numpy()
    assert not keep[(t >= 10.0) & (t <= 12.0)].any() and keep[(t < 10.0) | (t > 12.0)].all()
    e = metrics.navigation_errors(traj, ref, meta)
    assert len(e) == len(traj) - int(((t >= 10.0) & (t <= 12.0)).sum())
    assert not ((e["time"] >= 10.0) & (e["time"] <= 12.0)).any()
    np.testing.assert_allclose(e["north"], e["north"].iloc[0], rtol=1e-5)
    assert len(metrics.navigation_errors(traj, ref)) == len(traj)
    assert metrics.excluded_spans({}) == [] and metrics.excluded_spans(None) == []
    with pytest.raises(DataError, match=metrics.REFERENCE_EXCLUDED_KEY):
        metrics.excluded_spans({metrics.REFERENCE_EXCLUDED_KEY: [[2.0, 1.0]]})
    fixes = fix_errors(demo.gnss, ref, [0.0, 0.0, 0.0], spans)
    assert not ((fixes["time"] >= 10.0) & (fixes["time"] <= 12.0)).any() and len(fixes) == len(demo.gnss) - 3


# --------------------------------------------------------------------------------------------- IMU levels
def test_rest_spans_and_biases_recover_simulated_bias():
    rate, n = 100.0, 6000
    t = np.arange(1, n + 1) / rate
    speed = np.where(t < 20.0, 0.0, 10.0)                     # 20 s at rest, then driving
    ref = pd.DataFrame({"time": np.concatenate([[0.0], t]), "v_n": np.concatenate([[0.0], speed]), "v_e": 0.0})
    rng = np.random.default_rng(0)
    bias = np.array([0.01, -0.02, 0.03])
    gyro = bias + 0.002 * rng.standard_normal((n, 3))
    accel = np.array([0.0, 0.0, -9.8]) + 0.05 * rng.standard_normal((n, 3))
    imu = pd.DataFrame(np.column_stack([t, gyro, accel]),
                       columns=["time", "gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"])
    drive = Drive("sim", ref, imu, pd.DataFrame())
    spans = rest_spans(imu, ref)
    assert len(spans) == 1 and t[spans[0][0]] == pytest.approx(0.5, abs=0.02)   # trimmed start
    stops = rest_biases(drive)
    np.testing.assert_allclose(stops[["gyro_bias_x", "gyro_bias_y", "gyro_bias_z"]].to_numpy()[0], bias,
                               atol=0.002 / np.sqrt(1500) * 5)
    assert stops["f_norm_mean"].iloc[0] == pytest.approx(9.8, rel=1e-3)


# ------------------------------------------------------------------------------------ registry, profiles
def test_parameters_and_profile_sections():
    p = dataset_params("rtklib-drive0708")
    sim = DATASETS["turin-sim-mpu6000"]
    for k in ("gnss_rate_hz", "gnss_white_std_m", "gnss_correlated_std_m", "gnss_correlated_tau_s"):
        assert p[k] == sim[k]                                  # the simulated u-blox receiver's levels
    assert p["imu_time_offset_s"] == rtklib.IMU_TIME_OFFSET_S and p["seed"] == 0
    with pytest.raises(DataError, match="smoothing_degree"):
        dataset_params("rtklib-drive0708", {"smoothing_degree": 5})
    smoke = profile_overrides("rtklib-drive0708", "smoke")
    assert "t_start" not in smoke and "smoothing_degree" not in smoke     # the Turin crop does not apply
    assert smoke["gnss_rate_hz"] == 1.0 and smoke["imu_time_offset_s"] == rtklib.IMU_TIME_OFFSET_S
    assert profile_overrides("turin-sim-mpu6000", "smoke")["t_start"] == 138700.0


def test_pinned_files_follow_the_mirror_readme():
    specs = acquire.RTKLIB_FILES
    assert sorted(specs) == ["gnss_1934_sf.pos", "imu_1934.csv", "imu_1934.csv.tag"]
    assert all(s.required for s in specs.values())           # the quick profile uses the drive
    assert specs["imu_1934.csv"].sha256 == "f1126bf3b36efc4bef2dd2c7d93bb2a0e1b4ce714005cbea00a9218ad0b3b7a9"
    assert specs["imu_1934.csv"].url.format(file="imu_1934.csv") == (
        "https://raw.githubusercontent.com/rtklibexplorer/GNSS_IMU/8235ee6c5f349db529bf43ad556a3769b346b5a1/"
        "data/drive_0708/imu_1934.csv")
    assert set(acquire.raw_files()) == set(acquire.NAVEGO_FILES) | set(specs)


def test_resolve_order_and_checksum(tmp_path, monkeypatch):
    urls = []

    def fake_download(url, timeout_s):
        urls.append(url)
        return b"not the file"

    monkeypatch.setattr(acquire, "_download", fake_download)
    monkeypatch.delenv("BGFN_RTKLIB_MIRROR", raising=False)
    mirror = tmp_path / "mirror"
    mirror.mkdir()
    data = b"x" * 10
    spec = acquire.RawFile("imu_1934.csv", hashlib.sha256(data).hexdigest(), "0" * 40, False,
                           **{k: getattr(acquire.RTKLIB_FILES["imu_1934.csv"], k)
                              for k in ("url", "mirror_folder", "mirror_env", "source", "when_missing")})
    monkeypatch.setitem(acquire.RTKLIB_FILES, "imu_1934.csv", spec)
    (mirror / "imu_1934.csv").write_bytes(data)
    res = acquire.resolve("imu_1934.csv", data_dir=tmp_path / "d", mirror=mirror)
    assert res.origin == "mirror" and res.path.read_bytes() == data and urls == []
    monkeypatch.setenv("BGFN_RTKLIB_MIRROR", str(tmp_path / "empty"))
    assert acquire.mirror_dir(None, spec) == tmp_path / "empty"
    with pytest.raises(ChecksumError, match="rtklibexplorer/GNSS_IMU"):       # the download is verified too
        acquire.resolve("imu_1934.csv", data_dir=tmp_path / "e")
    assert urls == [spec.url.format(file="imu_1934.csv")] and not (tmp_path / "e" / "raw" / "imu_1934.csv").exists()


# --------------------------------------------------------------------------------------- the real files
def _real_folder():
    for folder in (acquire.REPO_ROOT / "data" / "raw", os.environ.get("BGFN_RTKLIB_MIRROR"),
                   acquire.REPO_ROOT.parent / "shared" / "data" / "rtklib-drive0708"):
        if folder and all((acquire.Path(folder) / f).is_file() for f in acquire.RTKLIB_FILES):
            return acquire.Path(folder)
    return None


@pytest.fixture(scope="module")
def real(tmp_path_factory):
    folder = _real_folder()
    if folder is None:
        pytest.skip("the rtklib-drive0708 files are not available (data/raw or ../shared/data/rtklib-drive0708)")
    data_dir = tmp_path_factory.mktemp("rtklib-data")
    drive = load_drive("rtklib-drive0708", data_dir=data_dir, mirror=folder, download=False)
    return {"folder": folder, "data_dir": data_dir, "drive": drive}


def test_real_files_parse(real):
    f = real["folder"]
    pos, week = rtklib.read_pos(f / "gnss_1934_sf.pos")
    imu, info = rtklib.read_imu_csv(f / "imu_1934.csv", rtklib.read_tag(f / "imu_1934.csv.tag"), week=week)
    t = imu["time"].to_numpy()
    assert week == WEEK and t[-1] - t[0] == pytest.approx(548.0, abs=2.0)
    assert info["step_s"][0] > 0.007 and info["step_s"][2] < 0.012      # the jitter: 8-11 ms steps
    assert len(pos) == 2197 and int((pos["q"] == rtklib.Q_FIX).sum()) == 2189
    f_norm = np.linalg.norm(imu[["accel_x", "accel_y", "accel_z"]].to_numpy(), axis=1)
    g = normal_gravity(pos["lat"].iloc[0], pos["h"].iloc[0])
    assert np.median(f_norm) == pytest.approx(g, rel=0.03)
    assert np.median(imu["accel_z"]) < -0.95 * g            # body z down


def test_real_drive_dataset(real):
    d = real["drive"]
    assert d.validate() is d and not d.has_attitude
    t = d.reference["time"].to_numpy()
    assert 540.0 < t[-1] - t[0] < 550.0 and np.allclose(np.diff(t), 0.01)
    np.testing.assert_array_equal(d.imu["time"].to_numpy(), t[1:])
    speed = np.hypot(d.reference["v_n"], d.reference["v_e"])
    assert speed.max() < 20.0 and speed.mean() > 3.0
    spans = d.meta[metrics.REFERENCE_EXCLUDED_KEY]
    assert len(spans) == 1 and spans[0][1] - spans[0][0] == pytest.approx(2.25)    # 8 float epochs at 4 Hz
    assert d.meta["lever_arm_m"] == list(rtklib.LEVER_ARM_M) and d.meta["imu_errors"]["model"] == "mpu6000"
    assert "BSD 3-Clause" in d.meta["source"] and d.meta["imu_time"]["stretched"] is False
    # the reference is the IMU, the solution's antenna lies at the lever arm from it
    pos, _ = rtklib.read_pos(real["folder"] / "gnss_1934_sf.pos")
    fx = pos.loc[(pos["q"] == rtklib.Q_FIX) & (pos["time"] >= t[0]) & (pos["time"] <= t[-1])]
    lat, lon, h = antenna_position(d.reference, d.meta["lever_arm_m"])
    ned = metrics.earth.lla_to_ned(*(np.interp(fx["time"], t, x) for x in (lat, lon, h)),
                                   fx["lat"].to_numpy(), fx["lon"].to_numpy(), fx["h"].to_numpy())
    assert np.abs(ned).max() < 1e-3
    imu_to_ant = metrics.earth.lla_to_ned(lat, lon, h, d.reference["lat"], d.reference["lon"], d.reference["h"])
    np.testing.assert_allclose(np.linalg.norm(imu_to_ant, axis=1), np.linalg.norm(rtklib.LEVER_ARM_M), atol=1e-6)
    # the velocity is the positions' own derivative: it integrates back to the track
    north = metrics.earth.lla_to_ned(d.reference["lat"], d.reference["lon"], d.reference["h"],
                                     d.reference["lat"][0], d.reference["lon"][0], d.reference["h"][0])[:, 0]
    v_int = np.concatenate([[0.0], np.cumsum(0.5 * (d.reference["v_n"][1:].to_numpy() +
                                                     d.reference["v_n"][:-1].to_numpy()) * 0.01)])
    assert np.abs(north - v_int).max() < 0.5


def test_real_drive_gnss_is_a_degraded_copy_with_the_configured_errors(real):
    d = real["drive"]
    p = d.meta["params"]
    white, corr = np.array(p["gnss_white_std_m"]), np.array(p["gnss_correlated_std_m"])
    assert d.meta["gnss_rate_hz"] == 1.0 and np.allclose(np.diff(d.gnss["time"]), 1.0)
    np.testing.assert_allclose(d.gnss[["std_n", "std_e", "std_d"]].iloc[0], np.hypot(white, corr))
    err = fix_errors(d.gnss, d.reference, d.meta["lever_arm_m"], d.meta)
    e = err[["north_m", "east_m", "down_m"]].to_numpy()
    # about nine correlation times of a Gauss-Markov error: its sample std lies within a factor 1.5
    assert ((e.std(axis=0) > np.hypot(white, corr) / 1.5) & (e.std(axis=0) < np.hypot(white, corr) * 1.5)).all()
    # the white part shows in the differences of successive fixes (the correlated part moves little in 1 s)
    a = np.exp(-1.0 / p["gnss_correlated_tau_s"])
    expected = np.sqrt(2 * white ** 2 + 2 * (1 - a) * corr ** 2)
    np.testing.assert_allclose(np.diff(e, axis=0).std(axis=0), expected, rtol=0.2)
    # seeded: another seed, another copy; the same seed, the same copy
    again = load_drive("rtklib-drive0708", data_dir=real["data_dir"], mirror=real["folder"], download=False)
    pd.testing.assert_frame_equal(again.gnss, d.gnss)
    other = load_drive("rtklib-drive0708", data_dir=real["data_dir"], mirror=real["folder"], download=False,
                       seed=1)
    assert np.abs(other.gnss["lat"] - d.gnss["lat"]).max() * 6.4e6 > 0.1      # metres apart
    pd.testing.assert_frame_equal(other.imu, d.imu)


def _yaw_rate_lag(imu: pd.DataFrame, pos: pd.DataFrame, part, min_speed=3.0) -> float:
    """Lag (s) to add to the IMU times so that its yaw rate best matches the rate of the course over ground of
    the RTK positions (symmetric differences at 4 Hz; IMU integrated over the same +-0.5 s)."""
    tp = pos["time"].to_numpy()
    ned = metrics.earth.lla_to_ned(pos["lat"], pos["lon"], pos["h"], pos["lat"][0], pos["lon"][0], pos["h"][0])
    v = (ned[2:, :2] - ned[:-2, :2]) / (tp[2:] - tp[:-2])[:, None]
    tv = tp[1:-1]
    course = np.unwrap(np.arctan2(v[:, 1], v[:, 0]))
    rate, tm = (course[2:] - course[:-2]) / (tv[2:] - tv[:-2]), tv[1:-1]
    fast = np.hypot(*v.T) > min_speed
    m = fast[1:-1] & fast[2:] & fast[:-2] & part(tm)
    t = imu["time"].to_numpy()
    yaw = np.concatenate([[0.0], np.cumsum(imu["gyro_z"].to_numpy()[1:] * np.diff(t))])
    lags = np.arange(-0.3, 0.3, 0.0025)
    cost = [np.mean(((np.interp(tm[m] + 0.5, t + lag, yaw) - np.interp(tm[m] - 0.5, t + lag, yaw)) - rate[m]) ** 2)
            for lag in lags]
    return float(lags[int(np.argmin(cost))])


def test_real_imu_time_keeps_step_with_the_rtk_track(real):
    # the yaw rate (body z down: clockwise positive, like the course) lags the RTK course rate by the same small
    # amount in every third of the drive with the unstretched counter; the source's stretch makes it drift
    f = real["folder"]
    pos, week = rtklib.read_pos(f / "gnss_1934_sf.pos")
    tags = rtklib.read_tag(f / "imu_1934.csv.tag")
    t0, t1 = pos["time"].iloc[0], pos["time"].iloc[-1]
    thirds = [lambda t, k=k: (t >= t0 + k * (t1 - t0) / 3) & (t < t0 + (k + 1) * (t1 - t0) / 3) for k in range(3)]
    imu, _ = rtklib.read_imu_csv(f / "imu_1934.csv", tags, week=week)
    lags = [_yaw_rate_lag(imu, pos, part) for part in thirds]
    assert max(abs(x) for x in lags) < 0.05 and max(lags) - min(lags) < 0.03
    stretched, _ = rtklib.read_imu_csv(f / "imu_1934.csv", tags, week=week, stretch_to_tags=True)
    drift = [_yaw_rate_lag(stretched, pos, part) for part in thirds]
    assert drift[0] - drift[2] > 0.06


def test_real_imu_levels(real):
    d = real["drive"]
    stops = rest_biases(d)
    assert (stops["t1"] - stops["t0"]).sum() > 30.0
    biases = stops[["gyro_bias_x", "gyro_bias_y", "gyro_bias_z"]].to_numpy()   # [stops, 3] rad/s
    assert len(biases) >= 2 and np.abs(biases).max() < np.radians(1.0)
    assert np.ptp(biases, axis=0).max() < np.radians(0.05)    # the same bias at every stop
    summary = level_summary(imu_levels(d)).set_index("sensor")
    assert (summary["ratio"] > 1.0).all()                     # driving shakes the IMU more than idling

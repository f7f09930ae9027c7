"""The learning problem (bgfn.learning): windows, GNSS increment targets, outage-free split, normalization."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from bgfn import learning as L
from bgfn import schema
from bgfn.errors import DataError
from bgfn.nav.earth import curvature_radii


@pytest.fixture(scope="module")
def tables():
    return L.synthetic_tables(duration_s=200.0, noise=0.1, seed=3)


def test_position_increment_hand_computed():
    lat, h = np.deg2rad(45.0), 300.0
    r_m, r_n = curvature_radii(lat)
    d = L.position_increment(lat, 0.2, h, lat + 1e-6, 0.2 + 2e-6, h)
    assert d[0] == pytest.approx(1e-6 * (r_m + h), rel=1e-6)                  # ~6.37 m north
    assert d[1] == pytest.approx(2e-6 * (r_n + h) * np.cos(lat), rel=1e-5)    # ~9.0 m east
    assert 6.3 < d[0] < 6.4 and 8.9 < d[1] < 9.1
    # across the +-180 deg meridian the longitude difference is wrapped
    d = L.position_increment(lat, np.pi - 1e-6, h, lat, -np.pi + 1e-6, h)
    assert d[1] == pytest.approx(2e-6 * (r_n + h) * np.cos(lat), rel=1e-5)


def test_windows_inputs_and_targets(tables):
    imu, att, gnss = tables
    ws = L.make_windows(imu, att, gnss, window=200)
    assert ws.x.shape[1:] == (200, 9) and ws.x.dtype == np.float32
    assert ws.channels == L.CHANNELS
    t = imu["time"].to_numpy()
    # 'ending': the window's last sample is the GNSS epoch t_to itself (causal: nothing after it)
    assert np.all(ws.t_end <= ws.t_to + 1e-9) and np.allclose(ws.t_end, ws.t_to)
    # the first usable epoch needs 200 samples (+ the one before) of history
    assert ws.t_to.min() >= t[200]
    # inputs are the raw IMU rows
    k = int(np.searchsorted(t, ws.t_end[5]))
    assert np.allclose(ws.x[5, -1, 3:6], imu.loc[k, ["accel_x", "accel_y", "accel_z"]].to_numpy(), atol=1e-5)
    assert np.allclose(ws.x[5, -1, 6:9], imu.loc[k, ["gyro_x", "gyro_y", "gyro_z"]].to_numpy(), atol=1e-6)
    assert np.allclose(ws.x[5, 0, 3], imu.loc[k - 199, "accel_x"], atol=1e-5)
    # targets: GNSS increments; on the toy circle, chord from the true heading
    inc = L.gnss_increments(gnss)
    row = inc.index[np.isclose(inc["t_to"], ws.t_to[5])][0]
    assert np.allclose(ws.y[5], inc.loc[row, ["dn", "de"]].to_numpy())
    assert np.allclose(ws.y_last[6], ws.y[5])                     # previous increment
    speed = np.hypot(*ws.y.T)
    assert 6.0 < speed.min() and speed.max() < 14.0               # 10 m/s +- 30 % over 1 s
    nxt = L.make_windows(imu, att, gnss, window=200, alignment="next")
    assert np.allclose(nxt.t_end, nxt.t_from)
    common = np.isin(nxt.t_from, ws.t_from)
    assert np.allclose(nxt.y[common], ws.y[np.isin(ws.t_from, nxt.t_from)])


def test_yaw_encodings_handle_the_wrap(tables):
    imu, att, gnss = tables
    raw = L.make_windows(imu, att, gnss, window=200, yaw_encoding="raw")
    unw = L.make_windows(imu, att, gnss, window=200, yaw_encoding="unwrap")
    rel = L.make_windows(imu, att, gnss, window=200, yaw_encoding="relative")
    jumps_raw = np.abs(np.diff(raw.x[..., 2], axis=1)).max(axis=1)
    crossing = jumps_raw > np.pi                                   # windows that hold the +-pi wrap
    assert crossing.any()
    assert np.abs(np.diff(unw.x[..., 2], axis=1)).max() < 0.1      # yaw rate ~0.07 rad/s * 0.01 s
    assert np.allclose(unw.x[:, -1, 2], raw.x[:, -1, 2])           # absolute heading kept at the last sample
    assert np.all(np.abs(unw.x[:, -1, 2]) <= np.pi)
    assert np.allclose(rel.x[:, -1, 2], 0.0)
    assert np.abs(np.diff(rel.x[..., 2], axis=1)).max() < 0.1
    assert raw.x.shape == unw.x.shape == rel.x.shape               # 9 channels in every encoding
    with pytest.raises(DataError):
        L.make_windows(imu, att, gnss, yaw_encoding="sincos")


def test_no_window_touches_an_outage(tables):
    imu, att, gnss = tables
    outages = [(1080.0, 30.0), (1150.0, 10.0)]
    margin = 5.0
    data = L.build_learning_data(imu, att, gnss, outages, window=200, margin_s=margin, val_fraction=0.25,
                                 val_position="middle")
    forb = np.array([[s - margin, s + d + margin] for s, d in outages])
    for ws in (data.train, data.val):
        assert len(ws) > 0
        lo, hi = ws.span
        # inputs: first sample interval starts at t_start; target interval [t_from, t_to]
        for a, b in forb:
            assert np.all((hi < a) | (lo > b)), "a window overlaps an outage"
            assert np.all((ws.t_to < a) | (ws.t_from > b))
            assert np.all((ws.t_end < a) | (ws.t_start > b))
    # training and validation windows share no time (inputs or targets)
    vlo, vhi = data.val.span
    tlo, thi = data.train.span
    assert np.all((thi < vlo.min()) | (tlo > vhi.max()))
    # the validation block is one contiguous block in the middle
    assert data.train.t_to.min() < data.val.t_to.min() and data.train.t_to.max() > data.val.t_to.max()
    assert data.info["n_outage_excluded"] > 0 and data.info["n_purged"] > 0
    # without the outages, windows inside them would exist
    all_ws = L.make_windows(imu, att, gnss, window=200)
    assert np.any((all_ws.t_to > 1080.0) & (all_ws.t_to < 1110.0))


def test_normalization_uses_training_windows_only(tables):
    imu, att, gnss = tables
    data = L.build_learning_data(imu, att, gnss, [], window=100, val_fraction=0.3, target_screen_sigma=None)
    x = data.train.x.reshape(-1, 9).astype(float)
    assert np.allclose(data.norm.x_mean, x.mean(0)) and np.allclose(data.norm.x_std[3:6], x.std(0)[3:6])
    assert np.allclose(data.norm.y_mean, data.train.y.mean(0))
    # corrupting the validation inputs does not change the statistics
    gnss2 = gnss.copy()
    lo, hi = data.info["val_block"]
    inside = (gnss2["time"] > lo + 5) & (gnss2["time"] < hi - 5)
    assert inside.sum() > 5
    gnss2.loc[inside, "lat"] += 1e-3
    data2 = L.build_learning_data(imu, att, gnss2, [], window=100, val_fraction=0.3, target_screen_sigma=None)
    assert np.allclose(data2.norm.y_mean, data.norm.y_mean) and np.allclose(data2.norm.y_std, data.norm.y_std)
    z = data.norm.x(data.train.x)
    assert np.allclose(z.reshape(-1, 9).mean(0)[3:], 0.0, atol=1e-3)
    assert np.allclose(data.norm.y_inverse(data.norm.y(data.val.y)), data.val.y, atol=1e-4)
    assert L.Normalizer.from_dict(data.norm.to_dict()).y_std.tolist() == data.norm.y_std.tolist()


def test_prediction_windows_match_training_windows(tables):
    imu, att, gnss = tables
    ws = L.make_windows(imu, att, gnss, window=150)
    epochs = np.concatenate([ws.t_from[20:21], ws.t_to[20:50]])   # last fix, then 30 pseudo-GNSS epochs
    pw = L.prediction_windows(imu, att, epochs, window=150)
    assert len(pw) == 30 and np.isnan(pw.y).all()
    assert np.array_equal(pw.x, ws.x[20:50])                      # same inputs as in training
    assert np.allclose(pw.t_from, ws.t_from[20:50]) and np.allclose(pw.t_to, ws.t_to[20:50])
    with pytest.raises(DataError):
        L.prediction_windows(imu, att, [imu["time"].iloc[10], imu["time"].iloc[20]], window=150)


def test_gaps_and_bad_tables_are_rejected(tables):
    imu, att, gnss = tables
    holed = imu.drop(index=range(5000, 5003)).reset_index(drop=True)   # 30 ms IMU gap
    ws = L.make_windows(holed, att, gnss, window=200)
    t_gap = imu["time"].iloc[5001]
    assert not np.any((ws.t_start < t_gap) & (ws.t_end > t_gap))
    with pytest.raises(DataError, match="gyro_z"):
        L.make_windows(imu.drop(columns="gyro_z"), att, gnss)
    with pytest.raises(DataError):
        L.split_windows(ws, [], val_fraction=1.5)


def test_reference_predictors(tables):
    imu, att, gnss = tables
    ws = L.make_windows(imu, att, gnss, window=200)
    ref = L.reference_rmse(ws)
    assert ref["zero"] == pytest.approx(np.sqrt(np.mean(np.sum(ws.y ** 2, axis=1))))
    assert ref["last"] < 0.2 * ref["zero"]                         # smooth toy motion: last increment is good


def test_heading_target_frame(tables):
    imu, att, gnss = tables
    ws = L.make_windows(imu, att, gnss, window=100)
    assert np.allclose(ws.yaw_ref, att.set_index("time").loc[ws.t_end, "yaw"].to_numpy())
    z = L.to_target_frame(ws.y, ws.yaw_ref, "heading")
    # on the toy circle the 1 s chord points ahead, slightly to the right (half the heading change)
    assert np.all(z[:, 0] > 5.0)
    assert np.all(np.abs(z[:, 1]) < 0.1 * z[:, 0])
    assert np.allclose(L.from_target_frame(z, ws.yaw_ref, "heading"), ws.y)
    assert np.allclose(np.hypot(*z.T), np.hypot(*ws.y.T))
    assert np.array_equal(L.to_target_frame(ws.y, ws.yaw_ref, "ned"), ws.y)
    data = L.build_learning_data(imu, att, gnss, [], window=100, target_frame="heading")
    assert data.norm.y_mean[0] > 5.0                                # statistics of the along-track target
    with pytest.raises(DataError):
        L.build_learning_data(imu, att, gnss, [], window=100, target_frame="body")


def test_heading_velocity_is_the_velocity_in_the_yaw_frame():
    # due east at 10 m/s with yaw 90 deg: all along-track; a 2 m/s side slip to the south is cross-track -2
    along, cross = L.heading_velocity([0.0, -2.0], [10.0, 10.0], [np.pi / 2, np.pi / 2])
    np.testing.assert_allclose(along, [10.0, 10.0], atol=1e-12)
    np.testing.assert_allclose(cross, [0.0, 2.0], atol=1e-12)
    # rotating velocity and yaw together leaves both unchanged (the point of the channels)
    rng = np.random.default_rng(0)
    v_n, v_e, yaw = rng.normal(size=50), rng.normal(size=50), rng.uniform(-np.pi, np.pi, 50)
    a0, c0 = L.heading_velocity(v_n, v_e, yaw)
    rot = 1.3
    a1, c1 = L.heading_velocity(np.cos(rot) * v_n - np.sin(rot) * v_e, np.sin(rot) * v_n + np.cos(rot) * v_e,
                                yaw + rot)
    np.testing.assert_allclose(a1, a0, atol=1e-12)
    np.testing.assert_allclose(c1, c0, atol=1e-12)


def test_derived_channels_need_velocity_and_yaw():
    imu = pd.DataFrame({"time": [0.0, 0.01], **{c: 0.0 for c in L.CHANNELS[3:]}})
    att = pd.DataFrame({"time": [0.0, 0.01], "roll": 0.0, "pitch": 0.0, "yaw": 0.0})
    with pytest.raises(DataError, match="v_n"):
        L.sample_features(imu, att, ("v_along",))
    t, x, ch = L.sample_features(imu, att.assign(v_n=3.0, v_e=4.0), ("v_along", "v_cross"))
    assert ch[-2:] == ("v_along", "v_cross")
    np.testing.assert_allclose(x[:, -2:], [[3.0, 4.0], [3.0, 4.0]])


def test_motion_coverage_of_windows_and_outages():
    # a window whose 1 s increment is 3 m north, 4 m east at yaw 90 deg: speed 5 m/s, heading 90
    ws = L.WindowSet(x=np.zeros((2, 3, 9), np.float32), y=np.array([[3.0, 4.0], [0.0, -10.0]]),
                     t_from=np.array([0.0, 1.0]), t_to=np.array([1.0, 2.0]), t_end=np.array([1.0, 2.0]),
                     t_start=np.array([-1.0, 0.0]), y_last=np.full((2, 2), np.nan),
                     yaw_ref=np.array([np.pi / 2, -np.pi / 2]))
    m = L.motion_of_windows(ws)
    np.testing.assert_allclose(m["speed_mps"], [5.0, 10.0])
    np.testing.assert_allclose(m["heading_deg"], [90.0, 270.0])
    ref = pd.DataFrame({"time": [0.0, 100.0], "yaw": [0.0, 0.0], "v_n": [10.0, 10.0], "v_e": [0.0, 0.0]})
    o = L.motion_in_windows(ref, [(10.0, 5.0)])
    assert len(o) == 5 and np.allclose(o["speed_mps"], 10.0) and np.allclose(o["heading_deg"], 0.0)
    # training saw (90 deg, 5 m/s) and (270 deg, 10 m/s); the outage drives north at 10 m/s: all unseen
    assert L.unseen_fraction(m, o) == 1.0
    assert L.unseen_fraction(m, m) == 0.0
    assert L.unseen_fraction(m, pd.concat([m.iloc[:1], o.iloc[:1]])) == 0.5


def _slow_then_fast_windows(n: int = 100, n_slow: int = 60) -> L.WindowSet:
    """n one-second windows heading north: 2 m/s for the first n_slow, then 15 m/s."""
    t = np.arange(n, dtype=float)
    speed = np.where(t < n_slow, 2.0, 15.0)
    return L.WindowSet(x=np.zeros((n, 3, 9), np.float32), y=np.c_[speed, np.zeros(n)], t_from=t, t_to=t + 1.0,
                       t_end=t + 1.0, t_start=t - 0.5, y_last=np.c_[speed, np.zeros(n)], yaw_ref=np.zeros(n))


def test_val_position_coverage_shows_what_an_end_block_takes_from_training():
    ws = _slow_then_fast_windows()
    # the outage lies in the fast part, as the Turin drive's outages lie in its fast last 400 s
    outage = [(80.0, 5.0)]
    outage_motion = pd.DataFrame({"heading_deg": np.zeros(5), "speed_mps": np.full(5, 15.0)})
    cov = L.val_position_coverage(ws, outage_motion, outage, margin_s=2.0, val_fraction=0.4,
                                  positions=("start", "end")).set_index("val_position")
    # a block at the end holds every fast window left: training never sees 15 m/s
    assert cov.loc["end", "outage_unseen_fraction"] == 1.0
    assert cov.loc["end", "train_speed_max_mps"] == pytest.approx(2.0)
    assert cov.loc["end", "val_unseen_fraction"] > 0.5
    # a block at the start leaves the fast windows around the outage to training
    assert cov.loc["start", "outage_unseen_fraction"] == 0.0
    assert cov.loc["start", "train_speed_max_mps"] == pytest.approx(15.0)
    assert cov.loc["start", "val_unseen_fraction"] == 0.0
    # the references are those of the block: repeating the last increment is exact here
    assert cov.loc["start", "val_rmse_last_m"] == 0.0
    assert cov.loc["start", "val_rmse_zero_m"] == pytest.approx(2.0)


def _with_velocity_and_noisy_fixes(tables, noise_m: float = 0.05, seed: int = 7):
    """The toy drive's attitude with the exact velocity (the INS/KF columns screening reads) and GNSS fixes
    with white noise of ``noise_m`` per axis."""
    imu, att, gnss = tables
    att = att.assign(v_n=np.interp(att["time"], gnss["time"], gnss["v_n"]),
                     v_e=np.interp(att["time"], gnss["time"], gnss["v_e"]))
    r_m, r_n = curvature_radii(gnss["lat"].to_numpy())
    rng = np.random.default_rng(seed)
    g = gnss.copy()
    g["lat"] += rng.normal(0.0, noise_m, len(g)) / (r_m + g["h"])
    g["lon"] += rng.normal(0.0, noise_m, len(g)) / ((r_n + g["h"]) * np.cos(g["lat"]))
    return imu, att, g


def test_ins_increments_integrate_the_velocity():
    att = pd.DataFrame({"time": np.arange(0.0, 10.01, 0.01), "v_n": 3.0, "v_e": -4.0})
    att["v_e"] = -4.0 + 0.5 * att["time"]            # east speed ramps: distance = -4 t + t^2 / 4
    d = L.ins_increments(att, np.array([0.0, 2.0]), np.array([1.0, 6.0]))
    np.testing.assert_allclose(d[:, 0], [3.0, 12.0], atol=1e-9)
    np.testing.assert_allclose(d[:, 1], [-4.0 + 0.25, -16.0 + (36.0 - 4.0) / 4.0], atol=1e-9)


def test_screening_drops_the_windows_of_a_gnss_jump(tables):
    imu, att, gnss = _with_velocity_and_noisy_fixes(tables)
    clean = L.make_windows(imu, att, gnss, window=100, target_screen_sigma=5.0)
    assert clean.n_screened == 0          # white noise of 5 cm: nothing beyond 5 robust std
    # one fix jumps 4 m north (as the real Ekinox fixes do): its two increments are flagged, and the window
    # after them, whose "last increment" reference is the jump, goes too
    k = 120
    jumped = gnss.copy()
    jumped.loc[k, "lat"] += 4.0 / (curvature_radii(jumped.loc[k, "lat"])[0] + jumped.loc[k, "h"])
    every = L.make_windows(imu, att, jumped, window=100)
    screened = L.make_windows(imu, att, jumped, window=100, target_screen_sigma=5.0)
    assert every.n_screened == 0 and screened.n_screened == 3
    t_jump = jumped.loc[k, "time"]
    gone = np.setdiff1d(every.t_to, screened.t_to)
    np.testing.assert_allclose(gone, t_jump + np.array([0.0, 1.0, 2.0]))
    def worst_residual(ws):
        return np.abs(ws.y - L.ins_increments(att, ws.t_from, ws.t_to)).max()
    assert worst_residual(every) > 3.0 and worst_residual(screened) < 0.5
    # screening needs the INS velocity
    with pytest.raises(DataError, match="v_n"):
        L.make_windows(imu, att.drop(columns="v_n"), jumped, window=100, target_screen_sigma=5.0)
    with pytest.raises(DataError, match="target_screen_sigma"):
        L.screen_increments(np.zeros((3, 2)), -1.0)
    # residuals without an INS velocity (NaN) are never flagged and leave the others' statistics alone
    r = np.r_[np.random.default_rng(0).normal(0.0, 0.1, (200, 2)), [[5.0, 0.0]], [[np.nan, np.nan]]]
    flags = L.screen_increments(r, 10.0)
    assert flags.tolist() == [False] * 200 + [True, False]
    assert not L.screen_increments(np.full((4, 2), np.nan), 10.0).any()


def test_ins_increment_reference_is_the_distance_travelled(tables):
    imu, att, gnss = tables                     # exact GNSS fixes, attitude with the true velocity
    ws = L.make_windows(imu, att, gnss, window=50)
    refs = L.reference_rmse(ws)
    # the velocity integrated over each 1 s interval is the chord between exact fixes (trapezoid at 100 Hz)
    assert np.all(np.isfinite(ws.y_ins)) and refs["ins"] < 1e-2
    assert refs["last"] > 20 * refs["ins"] and refs["zero"] > 6.0      # 10 m/s +- 30 %
    assert L.reference_columns(refs) == {"val_rmse_zero_m": refs["zero"], "val_rmse_last_m": refs["last"],
                                         "val_rmse_ins_m": refs["ins"]}
    sub = ws.subset(np.array([4, 2]))
    assert np.array_equal(sub.y_ins, ws.y_ins[[4, 2]])
    # an attitude table without velocity: the reference is unknown (NaN), not an error
    blind = L.make_windows(imu, att.drop(columns=["v_n", "v_e"]), gnss, window=50)
    assert np.isnan(blind.y_ins).all() and np.isnan(L.reference_rmse(blind)["ins"])
    assert np.array_equal(blind.y, ws.y)
    with pytest.raises(DataError, match="v_n"):                        # screening needs the velocity
        L.make_windows(imu, att.drop(columns=["v_n", "v_e"]), gnss, window=50, target_screen_sigma=10.0)


def test_input_layout_places_each_group_of_eq21_where_its_slice_says():
    t = np.arange(5) * 0.01
    imu = pd.DataFrame({"time": t, **{c: np.full(5, k + 1.0) for k, c in enumerate(schema.IMU_COLUMNS[1:])}})
    att = pd.DataFrame({"time": t, "roll": 0.1, "pitch": 0.2, "yaw": 0.3, "v_n": 7.0})
    _, feats, channels = L.sample_features(imu, att, extra_channels=("v_n",))
    np.testing.assert_allclose(feats[:, L.ATTITUDE_CHANNELS], np.tile([0.1, 0.2, 0.3], (5, 1)), atol=1e-15)  # yaw wrapped
    np.testing.assert_array_equal(feats[:, L.ANGULAR_RATE_CHANNELS], imu[list(schema.GYRO_COLUMNS)].to_numpy())
    np.testing.assert_array_equal(feats[:, L.SPECIFIC_FORCE_CHANNELS], imu[list(schema.ACCEL_COLUMNS)].to_numpy())
    assert channels[L.EXTRA_START] == "v_n" and np.all(feats[:, L.EXTRA_START] == 7.0)


def test_split_summary_accounts_for_every_window(tables):
    imu, att, gnss = tables
    outage = [(1080.0, 20.0)]
    data = L.build_learning_data(imu, att, gnss, outage, window=100, margin_s=5.0, val_fraction=0.25,
                                 val_position="middle")
    s = L.split_summary(data)
    assert list(s) == ["windows", "excluded_outages", "purged_near_val", "screened", "train", "val", "val_block_s",
                       *L.REFERENCES.values()]
    # every window is in exactly one of: near an outage, validation, purged beside the block, training
    assert s["windows"] == s["excluded_outages"] + s["val"] + s["purged_near_val"] + s["train"]
    assert s["excluded_outages"] > 0 and s["purged_near_val"] > 0 and s["screened"] == 0
    assert (s["train"], s["val"]) == (len(data.train), len(data.val))
    lo, hi = (float(v) for v in s["val_block_s"].split(".."))
    assert lo == pytest.approx(data.val.span[0].min(), abs=0.05)
    assert hi == pytest.approx(data.val.span[1].max(), abs=0.05)
    assert s["val_rmse_zero_m"] == L.reference_rmse(data.val)["zero"]
    assert L.block_label([1.04, 2.96]) == "1.0..3.0"


def test_motion_sets_hold_training_validation_and_outage_motion(tables):
    imu, att, gnss = tables
    data = L.build_learning_data(imu, att, gnss, [(1100.0, 10.0)], window=100, margin_s=5.0)
    ref = att.assign(v_n=np.interp(att["time"], gnss["time"], gnss["v_n"]),
                     v_e=np.interp(att["time"], gnss["time"], gnss["v_e"]))
    sets = L.motion_sets(data, ref, [(1100.0, 10.0)])
    assert list(sets) == ["training", "validation", "evaluation outages"]
    assert len(sets["training"]) == len(data.train) and len(sets["validation"]) == len(data.val)
    assert len(sets["evaluation outages"]) == 10                   # one row per second of the outage
    # the toy drive's speed is 10 m/s +- 30 %, in the windows as in the outage
    for df in sets.values():
        assert df["speed_mps"].between(6.9, 13.1).all()

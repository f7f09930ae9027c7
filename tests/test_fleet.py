"""The fleet study (beyond the paper): drives made comparable, leave-one-drive-out, coverage flags, Holm.

A synthetic fleet (:mod:`synthetic_fleet`): the speed is a known function of the vibration spectrum, and every drive's
IMU is tilted, rescaled and biased differently; only the speed path is run here (no filter), so the file stays fast.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from bgfn.errors import DataError
from bgfn.settings import defaults
from bgfn.stats import holm_adjust
from bgfn.studies.fleet import drives as fd
from bgfn.studies.fleet import protocol as fp
from bgfn.studies.fleet.coverage import outage_flags, speed_range, turn_range, turn_rate_at
from bgfn.studies.odometer.errors import error_parts_table
from synthetic_fleet import fleet_drive

FLEET = defaults("fleet")
PARAMS = {"window_s": 2.0, "ridge_alpha": 1.0, "max_lag_s": 10.0, "correlation": True, "val_fraction": 0.2,
          "val_blocks": 2, "calibration_blocks": True, "aid_rate_hz": 1.0}
MOUNTS = [((3.6, -2.0), 0.99, (0.002, -0.001, 0.003)), ((-5.0, 9.1), 1.06, (-0.002, 0.001, 0.0)),
          ((1.0, 4.0), 1.03, (0.0, 0.002, -0.002)), ((-7.0, -3.0), 0.97, (0.001, 0.0, 0.001))]


@pytest.fixture(scope="module")
def fleet():
    """Four remounted drives of 3-14 m/s and one faster (18-25 m/s) drive, prepared together."""
    drives = [fleet_drive(f"drive {i + 1}", tilt_deg=m, scale=s, gyro_bias=b, seed=i)
              for i, (m, s, b) in enumerate(MOUNTS)]
    drives.append(fleet_drive("fast drive", v_lo=18.0, v_hi=25.0, tilt_deg=(2.0, 2.0), scale=1.02, seed=9))
    return drives, fd.prepare_fleet(drives, FLEET)


def test_levelling_scale_and_bias_recover_the_mount(fleet):
    _, prepared = fleet
    for p, (tilt, scale, bias) in zip(prepared, MOUNTS):
        f = p.facts
        assert f["standstill_s"] > 10.0                              # the first 10 s and the middle stop
        assert f["tilt_roll_deg"] == pytest.approx(tilt[0], abs=0.05)
        assert f["tilt_pitch_deg"] == pytest.approx(tilt[1], abs=0.05)
        assert f["accel_scale"] == pytest.approx(1.0 / scale, rel=1e-3)
        np.testing.assert_allclose([f[f"gyro_bias_{a}_dps"] for a in "xyz"], np.degrees(bias), atol=0.02)
        still = p.imu["time"].to_numpy() < 9.0                       # levelled: gravity along -z at rest
        np.testing.assert_allclose(p.imu.loc[still, ["accel_x", "accel_y", "accel_z"]].mean().to_numpy(),
                                   [0.0, 0.0, -9.80665], atol=0.02)


def test_resampled_to_the_lowest_rate_and_one_bandwidth():
    slow = fleet_drive("slow", duration=60.0, rate=100.0, seed=1)
    fast = fleet_drive("fast", duration=60.0, rate=200.0, seed=2)
    t = fast.imu["time"].to_numpy()
    fast.imu["accel_y"] += np.sin(2 * np.pi * 10.0 * t) + np.sin(2 * np.pi * 80.0 * t)   # 80 Hz: above 50 Hz
    prepared = fd.prepare_fleet([slow, fast], FLEET)
    assert [p.rate_hz for p in prepared] == [100.0, 100.0]
    assert prepared[1].facts["native_rate_hz"] == pytest.approx(200.0)
    assert prepared[1].facts["cutoff_hz"] == pytest.approx(0.8 * 50.0)
    y = prepared[1].imu["accel_y"].to_numpy()[500:-500]
    spec = np.abs(np.fft.rfft(y - y.mean())) * 2 / y.size
    freq = np.fft.rfftfreq(y.size, 1 / 100.0)
    amp = {f: spec[np.argmin(np.abs(freq - f))] for f in (10.0, 20.0)}
    assert amp[10.0] == pytest.approx(1.0, abs=0.05)                 # kept
    assert amp[20.0] < 0.02                                          # 80 Hz not aliased to 20 Hz


def test_a_gap_in_the_imu_stays_a_gap():
    d = fleet_drive("gappy", duration=60.0, seed=5)
    t = d.imu["time"].to_numpy()
    d.imu = d.imu[(t < 30.0) | (t > 31.0)].reset_index(drop=True)      # one second missing
    (p,) = fd.prepare_fleet([d], FLEET)
    assert p.facts["imu_gaps"] == 1
    ti = p.imu["time"].to_numpy()
    assert not ((ti > 30.0 + 1e-9) & (ti < 31.0 - 1e-9)).any()          # nothing made up inside it
    w = fp.drive_windows(p, np.arange(20.0, 45.0), 2.0)
    assert not ((w.t_end > 30.0) & (w.t_end < 33.0)).any()              # no window reaches across it
    assert ((w.t_end >= 33.0) & (w.t_end < 45.0)).sum() == 12


def test_label_left_out_where_gnss_disagrees():
    d = fleet_drive("odd", duration=120.0, gnss_offset=(40.0, 60.0, 2.0), seed=3)
    t, label, facts = fd.speed_label(d, 0.5, "drop", 2.0)
    assert facts["label_checked"]
    assert facts["label_disagree_s"] == pytest.approx(20.0, abs=2.0)
    assert np.isnan(label[(t > 42) & (t < 58)]).all() and np.isfinite(label[(t < 35) | (t > 66)]).all()
    _, relabel, _ = fd.speed_label(d, 0.5, "gnss", 2.0)
    inside = (t > 42) & (t < 58)
    np.testing.assert_allclose(relabel[inside] - d.reference["v_n"].to_numpy()[inside], 2.0, atol=0.05)  # 1 Hz GNSS


def lodo_offsets(prepared, test_index, train_index, durations=(30.0,)):
    """The ridge trained on ``train_index`` drives, its and the held speed's offsets in the test drive's outages."""
    test, train = prepared[test_index], [prepared[i] for i in train_index]
    model = fp.fit_ridge(fp.pooled_speed_data(train, PARAMS), test.rate_hz, PARAMS)
    windows = fp.drive_windows(test, fp.aid_epochs(test.label_time[0], test.label_time[-1], 1.0), 2.0, False)
    truth = fd.reference_speed_at(test.drive, windows.t_end)
    starts = np.arange(20.0, 200.0, 30.0)
    held = fp.held_track(windows.t_end, starts, 30.0, lambda s: float(test.label_at([s])[0]), 1.0)
    series = fp.speed_series(windows.t_end, truth, [(s, 30.0) for s in starts],
                             {"RIDGE-ODO": fp.ridge_track(model, windows, PARAMS), "HOLD": held})
    table = error_parts_table(test.name, series, durations).set_index("method")
    return table, windows, truth, starts, train


def test_leave_one_drive_out_recovers_the_speed(fleet):
    _, prepared = fleet
    for k in range(4):
        table, *_ = lodo_offsets(prepared, k, [i for i in range(4) if i != k])
        ridge, hold = table.loc["RIDGE-ODO"], table.loc["HOLD"]
        assert ridge["offset_rms_mps"] < 0.5                         # the speed came back on a drive never seen
        assert ridge["offset_rms_mps"] < 0.3 * hold["offset_rms_mps"]
        assert ridge["speed_rmse_mps"] < 0.4 * hold["speed_rmse_mps"]


def test_a_faster_test_drive_is_flagged_out_of_range(fleet):
    _, prepared = fleet
    _, windows, truth, starts, train = lodo_offsets(prepared, 4, [0, 1, 2, 3])
    lo, hi = speed_range(train)
    assert hi < 15.0
    flags = outage_flags("fast drive", windows.t_end, truth, starts, [30.0], lo, hi, 0.1)
    moving = starts > 30.0
    assert flags["out_of_range"].to_numpy()[moving].all()
    _, w_in, t_in, s_in, tr_in = lodo_offsets(prepared, 0, [1, 2, 3])
    inside = outage_flags("drive 1", w_in.t_end, t_in, s_in, [30.0], *speed_range(tr_in), 0.1,
                          turn_rate_at(prepared[0], w_in.t_end, 2.0), *turn_range(tr_in, 2.0))
    assert not inside["out_of_range"].any()              # the same speeds and (no) turns as its training drives


def test_a_weaving_test_drive_is_flagged_for_its_turn_rates_not_its_speeds(fleet):
    """A drive at the training drives' speeds whose yaw rate swings +-15 deg/s, where they drove straight: its
    outages are out of range by turn rate only; the window mean of the turn rate is the weave's, within 1 deg/s."""
    _, prepared = fleet
    weave = fd.prepare_fleet([fleet_drive("weaving drive", turn_dps=15.0, tilt_deg=(1.0, -2.0), seed=5)], FLEET)[0]
    train = prepared[:4]
    lo_w, hi_w = turn_range(train, 2.0)
    assert max(abs(lo_w), abs(hi_w)) < 1.0                           # straight drives: vibration averages out
    t = fp.aid_epochs(weave.label_time[0] + 2.0, weave.label_time[-1], 1.0)
    w = turn_rate_at(weave, t, 2.0)
    v = fd.reference_speed_at(weave.drive, t)
    # the reference's yaw rate averaged over the same 2 s (its yaw's change over them)
    ref = weave.drive.reference
    yaw = np.unwrap(ref["yaw"].to_numpy(float))
    expect = np.degrees(np.interp(t, ref["time"], yaw) - np.interp(t - 2.0, ref["time"], yaw)) / 2.0
    np.testing.assert_allclose(w, expect, atol=1.0)
    starts = np.arange(20.0, 200.0, 30.0)
    flags = outage_flags("weaving drive", t, v, starts, [30.0], *speed_range(train), 0.1, w, lo_w, hi_w)
    moving = starts > 30.0
    assert flags["turn_out_of_range"].to_numpy()[moving].all() and flags["out_of_range"].to_numpy()[moving].all()
    assert not flags["speed_out_of_range"].any()
    assert (flags["turn_max_dps"].to_numpy()[moving] > 10.0).all()


def test_protocol_splits():
    names = ["a", "b", "c"]
    assert fp.fleet_splits(names, FLEET) == [("a", ["b", "c"]), ("b", ["a", "c"]), ("c", ["a", "b"])]
    named = {**FLEET, "protocol": "named", "train": ["a", "b"], "test": ["c"]}
    assert fp.fleet_splits(names, named) == [("c", ["a", "b"])]
    with pytest.raises(DataError, match="d"):
        fp.fleet_splits(names, {**named, "test": ["d"]})
    with pytest.raises(DataError, match="disjoint"):
        fp.fleet_splits(names, {**named, "test": ["b"]})


def test_pieces_are_contiguous_and_labelled():
    d = fleet_drive("one", duration=90.0, seed=4)
    pieces = fd.drive_pieces(d, 3)
    assert [p.name for p in pieces] == ["one piece 1 of 3", "one piece 2 of 3", "one piece 3 of 3"]
    ends = [(p.reference["time"].iloc[0], p.reference["time"].iloc[-1]) for p in pieces]
    assert ends[0][0] == 0.0 and ends[-1][1] == pytest.approx(90.0)
    assert all(b[0] - a[1] <= 0.01 + 1e-9 for a, b in zip(ends, ends[1:]))


def test_holm_on_a_hand_example():
    # sorted 0.01, 0.02, 0.04 (k = 3): 3 * 0.01 = 0.03, 2 * 0.02 = 0.04, 1 * 0.04 = 0.04; NaN stays out
    np.testing.assert_allclose(holm_adjust([0.04, np.nan, 0.01, 0.02]), [0.04, np.nan, 0.03, 0.04])



def test_fleet_summary_pools_drives_and_adjusts_per_family():
    """Hand-made rows of two test drives whose starts share their times: pooled, each start stays its own drive's;
    two learned odometers form the Holm family; the out-of-range outages are summarized apart."""
    from bgfn.stats import wilcoxon_p
    from bgfn.studies.fleet.summary import fleet_summary

    rng = np.random.default_rng(0)
    rows, flags = [], []
    for drive, shift in (("a", 0.0), ("b", 3.0)):
        for k, start in enumerate(np.arange(100.0, 1000.0, 100.0)):
            nhc = 20.0 + rng.uniform(0, 5)
            for method, err in (("INS+NHC", nhc), ("RIDGE-ODO", nhc - 2.0 - shift), ("MLP-ODO", nhc + rng.normal())):
                rows.append({"dataset": drive, "start_s": start, "duration_s": 60.0, "method": method,
                             "sigma_mps": np.nan, "seed": 0, "fold": 0, "max_h_m": err, "rmse_h_m": err,
                             "final_h_m": err, "speed_rmse_mps": 1.0, "coverage_2sigma": 0.9})
            flags.append({"dataset": drive, "start_s": start, "duration_s": 60.0, "out_of_range": drive == "b" and k < 3})
    s = fleet_summary(pd.DataFrame(rows), pd.DataFrame(flags)).set_index(["speed_range", "dataset", "method"])
    assert s.loc[("all", "pooled", "RIDGE-ODO"), "runs"] == 18                  # 9 starts of each drive, none merged
    p = [wilcoxon_p(np.full(18, -1.0) - np.r_[np.zeros(9), np.full(9, 3.0)]),
         s.loc[("all", "pooled", "MLP-ODO"), "p_vs_nhc"]]
    assert s.loc[("all", "pooled", "RIDGE-ODO"), "p_vs_nhc"] == pytest.approx(p[0])
    np.testing.assert_allclose([s.loc[("all", "pooled", m), "p_vs_nhc_holm"] for m in ("RIDGE-ODO", "MLP-ODO")],
                               holm_adjust(p))
    assert np.isnan(s.loc[("all", "pooled", "INS+NHC"), "p_vs_nhc_holm"])       # the baseline is no candidate
    assert s.loc[("out", "b", "RIDGE-ODO"), "runs"] == 3 and ("out", "a", "RIDGE-ODO") not in s.index
    assert s.loc[("in", "pooled", "RIDGE-ODO"), "runs"] == 15
    assert s.loc[("out", "b", "RIDGE-ODO"), "ratio_to_nhc"] < s.loc[("in", "a", "RIDGE-ODO"), "ratio_to_nhc"]


def test_preparation_is_said_per_drive(fleet):
    from bgfn.report.fleet_words import preparation_lines

    _, prepared = fleet
    lines = preparation_lines(fd.preparation_table(prepared[:2]))
    assert "levelled by roll +3.60 deg and pitch -1.9" in lines[0] and "scaled by 1.010" in lines[0]   # 1 / 0.99
    d = fleet_drive("rolling", duration=60.0, seed=6)
    d = d.crop(12.0, 25.0)                                              # after the first standstill, before the stop
    (p,) = fd.prepare_fleet([d], FLEET)
    assert np.isnan(p.facts["accel_scale"]) and "not levelled" in preparation_lines(fd.preparation_table([p]))[0]


def test_a_fleet_section_that_cannot_run_is_one_error_naming_the_key(params):
    from bgfn.profile_schema import load_profile

    for name, body, key in (
            ("two", "fleet: {drives: [a, b], pieces: 3}", "fleet.drives"),
            ("one", "fleet: {drives: [a]}", "fleet.drives"),
            ("named", "fleet: {drives: [a, b, c], protocol: named, train: [a, b]}", "fleet.test"),
            ("long", "fleet: {drives: [a, b], curve_duration_s: 500.0}", "fleet.curve_duration_s"),
            ("curve", "fleet: {drives: [a, b], curve: false, curve_networks: true}", "fleet.curve_networks"),
            ("inputs", "fleet: {drives: [a, b], curve: false, networks: true, inputs: {at_lstm: imu}}",
             "fleet.inputs")):
        (params / f"{name}.yaml").write_text(f"profile: {name}\nbase: smoke\ndescription: x\n{body}\n")
        with pytest.raises(DataError, match=key.replace(".", r"\.")):
            load_profile(name)


def curve_config(networks: bool) -> dict:
    """The smoke profile's budgets with one tiny MLP odometer, and the fleet's curve with or without networks."""
    from bgfn.profile_schema import load_profile

    cfg = load_profile("smoke")
    oc = {**cfg["evaluate"]["odometer"], "methods": ["mlp"], "network_seeds": [0], "network_datasets": None,
          "lr_search": False, "inputs": "band_frames"}
    return {**cfg, "evaluate": {**cfg["evaluate"], "odometer": oc},
            "fleet": {**FLEET, "networks": networks, "curve_networks": networks}}


def curve_test_drive(p):
    """What the curve's speed rows read of a test drive, without its filter: windows, truth, outages of 30 s."""
    from types import SimpleNamespace

    windows = fp.drive_windows(p, fp.aid_epochs(p.label_time[0], p.label_time[-1], 1.0), 2.0, False)
    return SimpleNamespace(name=p.name, prepared=p, windows=windows,
                           truth=fd.reference_speed_at(p.drive, windows.t_end),
                           outages=[(float(s), 30.0) for s in np.arange(50.0, 200.0, 30.0)])


def test_the_learning_curve_trains_the_networks_per_training_set(fleet, monkeypatch, tmp_path):
    """Training sets {1}, {2}, {1, 2} for test drive 3: RIDGE-ODO and MLP-ODO per set, the MLP trained per set
    (a checkpoint folder each) except the full set, whose tracks the split already has (reused as given); the
    minutes double with the drives; without curve_networks only the ridge, and nothing trained."""
    from bgfn import config

    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    _, prepared = fleet
    by_name = {p.name: p for p in prepared[:3]}
    test, train = curve_test_drive(prepared[2]), [prepared[0].name, prepared[1].name]
    cfg = curve_config(True)
    model = fp.fit_ridge(fp.pooled_speed_data(prepared[:2], PARAMS), 100.0, PARAMS)
    given = fp.ridge_track(model, test.windows, PARAMS)
    full = {("RIDGE-ODO", 0): given, ("MLP-ODO", 0): given}         # the split's own tracks, stand-ins here
    sets = fp.curve_tracks(cfg, "p", "fleet-test3", test, by_name, train, PARAMS, None, full)
    assert [len(c) for c, _, _ in sets] == [1, 1, 2]
    assert all(set(learned) == {("RIDGE-ODO", 0), ("MLP-ODO", 0)} for _, _, learned in sets)
    assert sets[2][2][("MLP-ODO", 0)] is given                        # the full set: taken as given, not retrained
    trained = sorted(p.name for p in tmp_path.glob("p/models/*") if p.is_dir())
    assert len(trained) == 2 and all("curve" in n for n in trained), trained
    rows = pd.DataFrame(fp.curve_speed_rows(test, sets, 30.0, 1.0))
    assert len(rows) == 6 and set(rows["method"]) == {"RIDGE-ODO", "MLP-ODO"}
    one, two = rows.loc[rows["n_train"] == 1, "train_min"], rows.loc[rows["n_train"] == 2, "train_min"]
    assert two.iloc[0] == pytest.approx(one.iloc[0] + one.iloc[2], rel=0.05)    # drives 1 and 2: their minutes add
    assert rows["offset_rms_mps"].notna().all() and rows["speed_rmse_mps"].notna().all()
    ridge = rows[rows["method"] == "RIDGE-ODO"]
    assert (ridge["offset_rms_mps"] < 1.0).all()                      # the speed comes back from either drive
    plain = fp.curve_tracks(curve_config(False), "q", "fleet-test3", test, by_name, train, PARAMS, None, full)
    assert all(set(learned) == {("RIDGE-ODO", 0)} for _, _, learned in plain)
    assert not (tmp_path / "q").exists()


def test_sigma_judged_on_epochs_and_on_outage_means():
    """Two hundred 60 s outages at 1 Hz, every std 1 m/s. White errors of std 1: 95 % of epochs and of outage means
    within 2 sigma (the mean's sigma 1/sqrt(60)). An offset per outage of std 1: the epochs still look calibrated (95 %),
    the means do not (|b| < 0.26 m/s: about 20 %), unless the track's correlation says the 60 epochs are one
    (kappa 60: the mean's sigma 1 m/s, 95 % again)."""
    from bgfn.nav.odometer import SpeedTrack
    from bgfn.studies.fleet.summary import sigma_table

    rng = np.random.default_rng(3)
    t = np.arange(20000.0)
    truth = np.full(t.size, 10.0)
    outages = [(100.0 * k, 60.0) for k in range(200)]
    offsets = np.repeat(rng.standard_normal(200), 100)
    tracks = {"white": SpeedTrack(t, truth + rng.standard_normal(t.size), np.ones(t.size)),
              "offset": SpeedTrack(t, truth + offsets, np.ones(t.size)),
              "offset, kappa 60": SpeedTrack(t, truth + offsets, np.ones(t.size), 60.0)}
    s = sigma_table("d", fp.speed_series(t, truth, outages, tracks), [60.0]).set_index("method")
    assert s.loc["white", "epoch_within_2sigma"] == pytest.approx(0.95, abs=0.02)
    assert s.loc["white", "mean_within_2sigma"] >= 0.85
    assert s.loc["offset", "epoch_within_2sigma"] == pytest.approx(0.95, abs=0.04)
    assert s.loc["offset", "mean_within_2sigma"] <= 0.35
    assert s.loc["offset, kappa 60", "mean_within_2sigma"] >= 0.85


def test_each_network_reads_its_own_inputs_with_one_budget(fleet, monkeypatch):
    """fleet.inputs {bgfn: imu}: BGFN is trained on the raw IMU windows, its ANN twin on band frames (the default),
    both under the same odometer budget; each test track comes back under its own network's label."""
    from bgfn.nav.odometer import SpeedTrack
    from bgfn.studies.odometer import bars

    calls = []

    def fake(cfg, profile, key, ecfg, data, windows, runner=None):
        oc = ecfg["odometer"]
        calls.append((tuple(oc["methods"]), oc["inputs"], data[0].options["inputs"], windows.x.ndim,
                      windows.x.shape[-1], bars.odometer_train_config(cfg["train"], ecfg)))
        code = {"bgfn": 1.0, "transformer": 2.0}
        return {(bars.odometer_label(m), 0, 0): (SpeedTrack(windows.t_end, np.full(len(windows), code[m]),
                                                            np.ones(len(windows))), {}) for m in oc["methods"]}

    monkeypatch.setattr(bars, "network_odometers", fake)
    _, prepared = fleet
    cfg = curve_config(True)
    cfg = {**cfg, "evaluate": {**cfg["evaluate"], "odometer": {**cfg["evaluate"]["odometer"],
                                                                "methods": ["bgfn", "transformer"]}},
           "fleet": {**cfg["fleet"], "inputs": {"bgfn": "imu"}}}
    assert fp.network_inputs(cfg) == {"bgfn": "imu", "transformer": "band_frames"}
    tracks = fp.network_tracks(cfg, "p", "k", fp.pooled_speed_data(prepared[:2], PARAMS), curve_test_drive(prepared[2]),
                               None)
    test = curve_test_drive(prepared[2])
    assert {k: float(np.unique(t.speed)[0]) for k, t in tracks.items()} == {
        ("BGFN-ODO", 0): 1.0, (bars.odometer_label("transformer"), 0): 2.0}
    assert all(np.array_equal(t.time, test.windows.t_end) for t in tracks.values())   # back on the test's clock
    (m_imu, in_imu, opt_imu, _, ch_imu, budget_imu), (m_band, in_band, opt_band, _, ch_band, budget_band) = calls
    assert (m_imu, in_imu, opt_imu, ch_imu) == (("bgfn",), "imu", "imu", 6)                  # six raw channels
    assert (m_band, in_band, opt_band) == (("transformer",), "band_frames", "band_frames") and ch_band != 6
    assert budget_imu == budget_band                                                           # one budget


def test_the_book_has_a_fleet_page_for_every_profile(tmp_path):
    """The table of contents lists notebook 11 under "Beyond the paper"; make book copies it where it ran and
    otherwise writes a page under the notebook's own title saying that the study did not run (and why)."""
    import json

    from bgfn.config import PROJECT_ROOT
    from bgfn.report import book_notebooks, fleet_page

    toc = (PROJECT_ROOT / "book" / "_toc.yml").read_text()
    beyond = toc.split("caption: Beyond the paper")[1].split("caption:")[0]
    assert "file: notebooks/11_fleet" in beyond
    make = (PROJECT_ROOT / "Makefile").read_text()
    assert "cp $(1) book/notebooks/" in make and "$(call book_pages,$(EXEC)," in make and "--absent book/notebooks" in make
    nb = json.loads((PROJECT_ROOT / "notebooks" / "11_fleet.ipynb").read_text())
    assert "".join(nb["cells"][0]["source"]).splitlines()[0] == f"# {fleet_page.FLEET_PAGE_TITLE}"
    written = book_notebooks.absent_pages(tmp_path, "quick")
    assert written == [tmp_path / "11_fleet.md"]
    page = written[0].read_text()
    assert page.startswith(f"# {fleet_page.FLEET_PAGE_TITLE}\n") and "`quick`" in page and "did not run" in page
    ran = tmp_path / "ran"
    ran.mkdir()
    (ran / "11_fleet.ipynb").write_text("{}")
    assert book_notebooks.absent_pages(ran, "fleet") == [] and not (ran / "11_fleet.md").exists()


def test_the_verdict_names_every_learned_odometer_with_its_offset_and_sigma():
    """One test drive with RIDGE-ODO and BGFN-ODO in the table: a line each, with its own numbers."""
    from bgfn.report.fleet_words import verdict_lines
    from bgfn.studies.fleet.summary import FLEET_SUMMARY_COLUMNS, OFFSET_COLUMNS

    base = {c: np.nan for c in FLEET_SUMMARY_COLUMNS}
    summary = pd.DataFrame([{**base, "speed_range": "all", "dataset": "d", "method": m, "duration_s": 60.0,
                             "runs": 6, "max_h_m": e, "ratio_to_nhc": e / 50.0, "p_vs_nhc": p, "p_vs_nhc_holm": q}
                            for m, e, p, q in (("INS+NHC", 50.0, np.nan, np.nan), ("RIDGE-ODO", 40.0, 0.03, 0.06),
                                               ("BGFN-ODO", 60.0, 0.5, 0.5))])
    offsets = pd.DataFrame([{**{c: np.nan for c in OFFSET_COLUMNS}, "speed_range": "all", "dataset": "d",
                             "method": m, "duration_s": 60.0, "offset_rms_mps": off, "epoch_within_2sigma": ep,
                             "mean_within_2sigma": mn}
                            for m, off, ep, mn in (("RIDGE-ODO", 0.8, 0.9, 0.5), ("BGFN-ODO", 1.6, 0.95, 1 / 3),
                                                   ("INS+NHC+HOLD", 3.0, 0.5, 0.0))])
    ridge, bgfn = verdict_lines(summary, offsets)
    assert ridge.startswith("d, 60 s outages (6): RIDGE-ODO 40.0 m against INS+NHC 50.0 m")
    assert "p 0.03, Holm-adjusted 0.06" in ridge and "0.80 m/s RMS against the held speed's 3.00" in ridge
    assert "BGFN-ODO 60.0 m" in bgfn and "1.60 m/s RMS" in bgfn and "95 % of the epochs" in bgfn and "33 % of" in bgfn


def test_a_network_ensemble_on_a_drive_never_seen(fleet, monkeypatch, tmp_path):
    """Two seeds of a tiny MLP trained on drives 1-2: each member's track and their ensemble come back on test drive
    3's clock, the ensemble's speed the members' mean, its std calibrated on the training drives' held-out windows
    (the test drive has none) and at least each member's spread around that mean."""
    from bgfn import config
    from bgfn.studies.odometer import bars

    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    _, prepared = fleet
    cfg = curve_config(True)
    cfg = {**cfg, "evaluate": {**cfg["evaluate"], "odometer": {**cfg["evaluate"]["odometer"], "network_seeds": [0, 1],
                                                                "ensemble": True}}}
    test = curve_test_drive(prepared[2])
    tracks = fp.network_tracks(cfg, "p", "k", fp.pooled_speed_data(prepared[:2], PARAMS), test, None)
    mlp, ens = bars.odometer_label("mlp"), bars.ensemble_label(bars.odometer_label("mlp"))
    assert set(tracks) == {(mlp, 0), (mlp, 1), (ens, 0)}
    for track in tracks.values():
        np.testing.assert_array_equal(track.time, test.windows.t_end)
        assert np.isfinite(track.speed).all() and (track.std > 0).all()
    members = np.stack([tracks[(mlp, s)].speed for s in (0, 1)])
    np.testing.assert_allclose(tracks[(ens, 0)].speed, members.mean(axis=0), rtol=1e-6)
    assert (tracks[(ens, 0)].std >= np.abs(members - members.mean(axis=0)).max(axis=0) - 1e-9).all()

"""The odometer bars (bgfn.studies.odometer.bars): the oracle speed's noise, the speed errors and the summary
checked by hand, and the rows of a synthetic drive laid out as the table says."""

import numpy as np
import pandas as pd
import pytest

from bgfn import evaluate as ev
from bgfn.studies.odometer import bars as O, section as OS
from bgfn.nav import odometer as no
from bgfn.profile_schema import load_profile
from bgfn.report import odometer_words
from synthetic_drive import demo_drive

NAV = {"init": {"position_std_m": 1.0, "height_std_m": 2.0, "velocity_std_mps": 0.1, "level_std_deg": 0.2,
                "azimuth_std_deg": 1.0}}


def test_oracle_speed_is_the_truth_plus_seeded_white_noise_and_a_walk():
    t = np.arange(20000.0)
    truth = np.full(t.size, 10.0)
    a = O.oracle_track(t, truth, 0.3, 0.0, seed=1, rate_hz=1.0)
    assert np.std(a.speed - truth) == pytest.approx(0.3, rel=0.03) and (a.std == 0.3).all()
    assert np.array_equal(a.speed, O.oracle_track(t, truth, 0.3, 0.0, seed=1, rate_hz=1.0).speed)
    assert not np.array_equal(a.speed, O.oracle_track(t, truth, 0.3, 0.0, seed=2, rate_hz=1.0).speed)
    walk = O.oracle_track(t, truth, 1e-9, 0.1, seed=1, rate_hz=1.0)
    assert np.std(np.diff(walk.speed)) == pytest.approx(0.1, rel=0.03)       # 0.1 m/s per sqrt(s) at 1 Hz


#: The odometer settings these small cases run with: the defaults' walk rows, ensembles, error correlation, ridge
#: curve and the evaluation outages as one more fold would add rows and runs that they do not test.
PLAIN = {"datasets": None, "paper_outages": False, "walk_mps_per_sqrt_s": 0.0, "curve_folds": [], "ensemble": False,
         "correlation": False, "calibration_blocks": False, "train": None}


def test_the_odometers_budget_lies_over_the_sweeps_key_by_key():
    ev_cfg = {"sweep": {"train": {"size": "smoke", "optimizer": {"epochs": 20, "patience": 5}}},
              "odometer": {"train": {"optimizer": {"epochs": 60}}}}
    tc = O.odometer_train_config({"optimizer": {"epochs": 25, "batch_size": 32, "patience": 6}}, ev_cfg)
    assert tc["size"] == "smoke" and tc["optimizer"] == {"epochs": 60, "batch_size": 32, "patience": 5}
    ev_cfg["odometer"]["train"] = None                     # null: the sweep's budget as it is
    tc = O.odometer_train_config({"optimizer": {"epochs": 25, "batch_size": 32, "patience": 6}}, ev_cfg)
    assert tc["optimizer"] == {"epochs": 20, "batch_size": 32, "patience": 5}


def test_speed_errors_by_hand():
    t = np.arange(0.0, 11.0)
    truth = np.full(t.size, 10.0)
    track = no.SpeedTrack(t, truth + np.array([0, 1, -1, 1, -1, 3, 0, 0, 0, 0, 0.0]), np.full(t.size, 0.6))
    e = no.speed_errors(track, t, truth, start=0.0, duration=5.0)            # epochs 1..5: errors 1,-1,1,-1,3
    assert e["speed_rmse_mps"] == pytest.approx(np.sqrt((4 + 9) / 5))
    assert e["coverage_2sigma"] == pytest.approx(4 / 5)                       # |3| > 1.2
    assert np.isnan(no.speed_errors(None, t, truth, 0.0, 5.0)["speed_rmse_mps"])


def test_summary_takes_the_median_ratio_to_ins_nhc_start_by_start():
    rows = pd.DataFrame([
        {"dataset": "d", "start_s": s, "duration_s": 30.0, "method": m, "sigma_mps": np.nan, "seed": 0, "fold": 0,
         "max_h_m": v, "rmse_h_m": 0.0, "final_h_m": 0.0, "speed_rmse_mps": np.nan, "coverage_2sigma": np.nan}
        for s, nhc, ridge in ((1.0, 10.0, 5.0), (2.0, 20.0, 30.0), (3.0, 40.0, 20.0))
        for m, v in (("INS+NHC", nhc), ("RIDGE-ODO", ridge))])
    s = O.odometer_summary(rows).set_index("method")
    assert s.loc["RIDGE-ODO", "max_h_m"] == 20.0 and s.loc["INS+NHC", "max_h_m"] == 20.0
    assert s.loc["RIDGE-ODO", "ratio_to_nhc"] == pytest.approx(0.5)          # ratios 0.5, 1.5, 0.5
    assert s.loc["INS+NHC", "runs"] == 3
    # differences -5, +10, -20: ranks 1, 2, 3, W+ = 2; exact two-sided p = 2 P(W+ <= 2) = 2 * 3/8
    assert s.loc["RIDGE-ODO", "p_vs_nhc"] == pytest.approx(0.75)
    assert np.isnan(s.loc["INS+NHC", "p_vs_nhc"])                            # no non-zero difference


def test_summary_holm_adjusts_the_learned_odometers_together():
    # three learned odometers against INS+NHC over 6 starts: every difference negative gives the smallest exact
    # two-sided Wilcoxon p, 2 / 2^6 = 0.03125; RIDGE-ODO's differences alternate in sign (W+ = 12 of 21: p large).
    # Holm over the k = 3: 0.03125 x 3 = 0.09375, 0.03125 x 2 = 0.0625 lifted to 0.09375 by the running maximum.
    rows = []
    for i, s in enumerate(range(1, 7)):
        nhc = 10.0 + s
        for m, v in (("INS+NHC", nhc), ("INS+NHC+HOLD", nhc - s), ("BGFN-ODO", nhc - s), ("MLP-ODO", nhc - 2 * s),
                     ("RIDGE-ODO", nhc + (s if i % 2 else -s))):
            rows.append({"dataset": "d", "start_s": float(s), "duration_s": 30.0, "method": m, "sigma_mps": np.nan,
                         "seed": 0, "fold": 0, "max_h_m": v, "rmse_h_m": 0.0, "final_h_m": 0.0,
                         "speed_rmse_mps": np.nan, "coverage_2sigma": np.nan})
    s = O.odometer_summary(pd.DataFrame(rows)).set_index("method")
    assert s.loc["BGFN-ODO", "p_vs_nhc"] == pytest.approx(0.03125)
    assert s.loc["MLP-ODO", "p_vs_nhc"] == pytest.approx(0.03125)
    ridge = s.loc["RIDGE-ODO", "p_vs_nhc"]                    # differences -1, +2, -3, +4, -5, +6
    assert ridge > 0.5
    assert s.loc["BGFN-ODO", "p_vs_nhc_holm"] == pytest.approx(0.09375)
    assert s.loc["MLP-ODO", "p_vs_nhc_holm"] == pytest.approx(0.09375)
    assert s.loc["RIDGE-ODO", "p_vs_nhc_holm"] == pytest.approx(max(ridge, 0.09375))
    # the held speed is no learned odometer: no member of the family, no adjusted p
    assert np.isfinite(s.loc["INS+NHC+HOLD", "p_vs_nhc"]) and np.isnan(s.loc["INS+NHC+HOLD", "p_vs_nhc_holm"])
    assert list(O.odometer_summary(pd.DataFrame(rows)).columns) == list(O.SUMMARY_COLUMNS)
    line = odometer_words.odometer_lines(O.odometer_summary(pd.DataFrame(rows)))[0]
    assert "BGFN-ODO 10.0 m (0.74 of INS+NHC per start, Wilcoxon p = 0.031, Holm-corrected over the learned " \
           "odometers 0.094" in line
    assert "INS+NHC+HOLD 10.0 m (0.74 of INS+NHC per start, Wilcoxon p = 0.031)" in line     # no learned odometer


def test_summary_coverage_is_the_share_of_all_the_outages_epochs():
    # five outages of one duration (the same epochs each): four wholly inside 2 sigma, one with none inside. The
    # median of the shares would read 100 %; 4 of every 5 epochs were inside.
    rows = pd.DataFrame([
        {"dataset": "d", "start_s": float(s), "duration_s": 30.0, "method": m, "sigma_mps": np.nan, "seed": 0,
         "fold": 0, "max_h_m": 1.0, "rmse_h_m": 0.0, "final_h_m": 0.0, "speed_rmse_mps": np.nan if m == "INS+NHC"
         else 1.0, "coverage_2sigma": np.nan if m == "INS+NHC" else (0.0 if s == 4 else 1.0)}
        for s in range(5) for m in ("INS+NHC", "BGFN-ODO")])
    s = O.odometer_summary(rows).set_index("method")
    assert s.loc["BGFN-ODO", "coverage_2sigma"] == pytest.approx(0.8)
    assert np.isnan(s.loc["INS+NHC", "coverage_2sigma"])
    paper = O.paper_outage_table(rows.assign(start_s=0.0, seed=range(10)), {"d": [(0.0, 30.0)]})
    assert paper.set_index("method").loc["BGFN-ODO", "coverage_2sigma"] == pytest.approx(0.8)   # over the seeds


def test_rows_of_a_synthetic_drive(monkeypatch, tmp_path):
    from bgfn import config

    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)            # the network odometers' checkpoints
    drive = demo_drive("synthetic", 150.0, 5.0, 3)
    cfg = load_profile("smoke")
    cfg = {**cfg, "nav": NAV, "train": {**cfg["train"], "window": 50, "margin_s": 5.0}}
    ecfg = ev.evaluate_config({"sweep": {"n_starts": 2, "folds": 2, "durations_s": [10.0, 30.0], "warmup_s": 30.0},
                               "odometer": {**PLAIN, "sigmas_mps": [0.1, 1.0], "seeds": [0, 1], "methods": ["mlp"]}},
                              cfg["train"])
    rows, facts = O.odometer_rows(cfg, "t", "synthetic", ecfg, drive=drive)
    assert list(rows.columns) == list(O.ODOMETER_COLUMNS)
    n = rows.groupby(["method", "duration_s"]).size()
    # 2 starts: INS+NHC, HOLD and RIDGE one row each per start; the oracle 2 sigmas x 2 seeds per start
    assert n.xs(10.0, level="duration_s").to_dict() == {"INS+NHC": 2, "INS+NHC+HOLD": 2, "RIDGE-ODO": 2,
                                                         "MLP-ODO": 2, "ORACLE-SPEED": 8}
    assert rows.loc[rows["method"] == "INS+NHC", "speed_rmse_mps"].isna().all()
    oracle = rows[rows["method"] == "ORACLE-SPEED"].groupby("sigma_mps")["speed_rmse_mps"].median()
    assert oracle[0.1] < 0.2 and 0.5 < oracle[1.0] < 1.6
    assert set(facts["ridge_std_mps"]) == {0, 1} and all(v > 0 for v in facts["ridge_std_mps"].values())
    # one network odometer per fold, its std calibrated on its own validation windows
    assert sorted(facts["networks"]) == ["MLP-ODO fold 0 seed 0", "MLP-ODO fold 1 seed 0"]
    assert all(f["calibration"] > 0 for f in facts["networks"].values())
    assert rows.loc[rows["method"] == "MLP-ODO", "speed_rmse_mps"].notna().all()
    assert (tmp_path / "t").exists()


def test_the_speed_figure_draws_each_outage_from_its_own_fold():
    t = np.arange(0.0, 200.0)
    series = {"time": t, "truth": np.full(t.size, 10.0), "outages": [(60.0, 30.0), (100.0, 30.0), (140.0, 30.0)],
              "tracks": {"RIDGE-ODO": (np.where(t > 50, 11.0, np.nan), np.full(t.size, 0.5)),
                         "BGFN-ODO": (np.where(t > 50, 9.0, np.nan), np.full(t.size, 1.5)),
                         "BGFN-ODO-ENS": (np.where(t > 50, 9.5, np.nan), np.full(t.size, 1.0))}}   # not drawn
    fig = OS.plot_speed_series(series, "d", n_outages=2)
    axes = fig.axes
    assert len(axes) == 2 and axes[0].get_title() == "start 60 s" and axes[1].get_title() == "start 140 s"
    assert axes[0].get_ylabel() == "forward speed (m/s)"
    # both odometers and the reference, each a line over the 31 epochs of its outage
    lines = {ln.get_label(): ln.get_ydata() for ln in axes[0].get_lines()}
    assert set(lines) == {"RIDGE-ODO (+- 2 sigma)", "BGFN-ODO (+- 2 sigma)", "reference"}
    assert np.allclose(lines["BGFN-ODO (+- 2 sigma)"], 9.0) and len(lines["reference"]) == 31


def test_the_error_growth_figure_has_one_line_per_row_and_the_oracle_at_its_grid_ends():
    rows = [{"method": m, "sigma_mps": np.nan, "duration_s": d, "max_h_m": e * d}
            for m, e in (("INS+NHC", 1.0), ("RIDGE-ODO", 0.8), ("BGFN-ODO", 0.9)) for d in (10.0, 30.0, 60.0)]
    rows += [{"method": "ORACLE-SPEED", "sigma_mps": s, "duration_s": d, "max_h_m": s * d}
             for s in (0.05, 0.5, 2.0) for d in (10.0, 30.0, 60.0)]
    fig = OS.plot_error_growth(pd.DataFrame(rows), "d")
    lines = {ln.get_label(): ln.get_ydata() for ln in fig.axes[0].get_lines()}
    assert set(lines) == {"INS+NHC", "RIDGE-ODO", "BGFN-ODO", "ORACLE-SPEED 0.05 m/s", "ORACLE-SPEED 2 m/s"}
    assert np.allclose(lines["RIDGE-ODO"], [8.0, 24.0, 48.0])


def test_the_two_evaluation_outages_are_one_more_fold_at_their_own_duration(monkeypatch, tmp_path):
    from bgfn import config

    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    drive = demo_drive("synthetic", 150.0, 5.0, 3)
    cfg = load_profile("smoke")
    cfg = {**cfg, "nav": NAV, "train": {**cfg["train"], "window": 50, "margin_s": 5.0},
           "outage_windows": [[110.0, 20.0], [70.0, 15.0]]}           # outage 1 is the later one
    ecfg = ev.evaluate_config({"sweep": {"n_starts": 2, "folds": 2, "durations_s": [10.0, 30.0], "warmup_s": 30.0},
                               "odometer": {**PLAIN, "sigmas_mps": [0.5], "seeds": [0], "methods": ["mlp"],
                                            "paper_outages": True}}, cfg["train"])
    rows, facts = O.odometer_rows(cfg, "t", "synthetic", ecfg, drive=drive)
    paper = rows[rows["fold"] == O.PAPER_FOLD]
    assert facts["paper_windows"] == [(110.0, 20.0), (70.0, 15.0)]
    # one row per outage and method, at the outage's own duration (not the sweep's 10 and 30 s)
    assert sorted(zip(paper["start_s"], paper["duration_s"])) == sorted([(70.0, 15.0), (110.0, 20.0)] * 5)
    assert set(paper["method"]) == {"INS+NHC", "INS+NHC+HOLD", "RIDGE-ODO", "MLP-ODO", "ORACLE-SPEED"}
    assert "MLP-ODO fold -1 seed 0" in facts["networks"]              # its own network, those outages held out
    table = O.paper_outage_table(paper, {"synthetic": facts["paper_windows"]})
    assert list(table.columns) == list(O.PAPER_COLUMNS)
    first = table[table["outage"] == 1]
    assert (first["start_s"] == 110.0).all() and (first["duration_s"] == 20.0).all()
    assert first["method"].iloc[0] == "INS+NHC" and (table["runs"] == 1).all()
    # the sweep's statistics never see them
    assert not (O.odometer_summary(rows[rows["fold"] != O.PAPER_FOLD])["duration_s"].isin([15.0, 20.0])).any()


def test_a_drive_left_out_of_network_datasets_gets_the_bars_but_no_network(monkeypatch, tmp_path):
    from bgfn import config

    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    drive = demo_drive("synthetic", 150.0, 5.0, 3)
    cfg = load_profile("smoke")
    cfg = {**cfg, "nav": NAV, "train": {**cfg["train"], "window": 50, "margin_s": 5.0}}
    ecfg = ev.evaluate_config({"sweep": {"n_starts": 2, "folds": 2, "durations_s": [10.0], "warmup_s": 30.0},
                               "odometer": {**PLAIN, "sigmas_mps": [0.5], "seeds": [0], "methods": ["mlp"],
                                            "network_datasets": ["another-drive"]}}, cfg["train"])
    rows, facts = O.odometer_rows(cfg, "t", "synthetic", ecfg, drive=drive)
    assert set(rows["method"]) == {"INS+NHC", "INS+NHC+HOLD", "RIDGE-ODO", "ORACLE-SPEED"}
    assert facts["networks"] == {} and not (tmp_path / "t").exists()     # nothing trained, nothing written


def test_a_walker_gets_no_odometer_bars():
    """The learned odometer is a car's forward speed fused with the NHC rows: a walker's drive is skipped, saying so."""
    drive = demo_drive("synthetic", 150.0, 5.0, 3)
    drive.meta["platform"] = "walker"
    cfg = load_profile("smoke")
    ecfg = ev.evaluate_config({"sweep": {"n_starts": 2, "folds": 2, "durations_s": [10.0], "warmup_s": 30.0}},
                              cfg["train"])
    rows, facts = O.odometer_rows(cfg, "t", "synthetic", ecfg, drive=drive)
    assert rows.empty and list(rows.columns) == list(O.ODOMETER_COLUMNS) and facts["skipped"] == "walker"


def test_network_table_sets_each_networks_validation_beside_its_own_folds_outages():
    # one network of fold 0, seed 1: its outages at the longest duration (60 s) have speed RMSE 3 and 4 m/s
    rows = pd.DataFrame([
        {"dataset": "d", "start_s": s, "duration_s": du, "method": "BGFN-ODO", "sigma_mps": np.nan, "seed": seed,
         "fold": fold, "max_h_m": 1.0, "rmse_h_m": 0.0, "final_h_m": 0.0, "speed_rmse_mps": v, "coverage_2sigma": c}
        for s, du, seed, fold, v, c in ((1.0, 60.0, 1, 0, 3.0, 0.5), (2.0, 60.0, 1, 0, 4.0, 1.0),
                                       (1.0, 30.0, 1, 0, 9.0, 0.0),            # a shorter duration: not read
                                       (1.0, 60.0, 0, 0, 9.0, 0.0),            # another seed
                                       (3.0, 60.0, 1, 1, 9.0, 0.0))])          # another fold
    net = {"method": "BGFN-ODO", "fold": 0, "seed": 1, "lr": 1e-3, "epochs": 20, "val_rmse_mps": 0.8,
           "calibration": 1.5}
    paper = {**net, "fold": O.PAPER_FOLD}
    t = O.network_table(rows, {"d": {"networks": {"a": net, "b": paper}}, "walker": {"skipped": "walker"}})
    assert list(t.columns) == list(O.NETWORK_COLUMNS) and len(t) == 1          # the paper fold is not a sweep fold
    row = t.iloc[0]
    assert row["outage_speed_rmse_mps"] == pytest.approx(np.sqrt((9 + 16) / 2))  # RMS over the starts
    assert row["outage_coverage_2sigma"] == pytest.approx(0.75) and row["val_rmse_mps"] == 0.8
    line, = odometer_words.network_lines(t)
    assert line.startswith("d, fold 0:") and "BGFN-ODO 0.80, then 3.54 m/s (75 % of outage epochs within" in line
    assert odometer_words.network_lines(None) == [] and odometer_words.network_lines(t.iloc[:0]) == []


def test_the_ensemble_of_two_oppositely_biased_seeds_is_unbiased_with_the_mixtures_std():
    from bgfn.learning import odometry as lo
    t = np.arange(0.0, 100.0)
    truth = 10.0 + np.sin(t / 10.0)
    tracks = {("NET-ODO", 0, 0): (no.SpeedTrack(t, truth + 1.0, np.full(t.size, 0.2)), {}),
              ("NET-ODO", 0, 1): (no.SpeedTrack(t, truth - 1.0, np.full(t.size, 0.2)), {}),
              ("ONE-ODO", 0, 0): (no.SpeedTrack(t, truth, np.full(t.size, 0.2)), {})}   # one seed: no ensemble
    val_t = t[40:60]
    val = lo.SpeedWindows(np.zeros((val_t.size, 2, 6), np.float32), truth[40:60] + 0.3, val_t, val_t - 2.0)
    data = {0: lo.SpeedData(val, val, None, {}, {})}
    out = O.ensemble_tracks(tracks, data)
    assert list(out) == [("NET-ODO-ENS", 0, 0)]
    track, facts = out[("NET-ODO-ENS", 0, 0)]
    assert track.speed == pytest.approx(truth)                       # the biases cancel
    # the mixture's std sqrt(0.2^2 + 1^2) as it is; on validation the residuals (0.3 m/s) give NIS 0.09 / 1.04
    assert track.std == pytest.approx(np.full(t.size, np.sqrt(1.04))) and facts["calibration"] == 1.0
    assert facts["val_nis"] == pytest.approx(0.09 / 1.04)
    assert facts["val_rmse_mps"] == pytest.approx(0.3) and facts["members"] == 2
    # the validation errors are one shared offset (0.3 m/s): rho = 1 at lags 1 ... 10 s (20 windows leave >= 10
    # pairs), so kappa = 21; a fact always, fused only with correlation
    assert facts["correlation"] == pytest.approx(21.0) and track.correlation == 1.0
    lasting, _ = O.ensemble_tracks(tracks, data, correlation=True)[("NET-ODO-ENS", 0, 0)]
    assert lasting.correlation == pytest.approx(21.0) and np.array_equal(lasting.std, track.std)
    # recalibrated: scaled so that the validation residuals have NIS = 1
    track, facts = O.ensemble_tracks(tracks, data, recalibrate=True)[("NET-ODO-ENS", 0, 0)]
    assert facts["calibration"] == pytest.approx(0.3 / np.sqrt(1.04))
    assert track.std == pytest.approx(np.full(t.size, 0.3))


def test_a_drive_without_odometer_bars_is_said_on_the_page_with_its_platform():
    import pandas as pd

    from bgfn.report.odometer_words import odometer_markdown
    from bgfn.studies.odometer.section import OdometerSection
    section = OdometerSection(pd.DataFrame(), pd.DataFrame(), {"my-walk": {"skipped": "walker"}, "car": {}})
    text = odometer_markdown(section)
    assert "my-walk: no odometer bars (platform walker" in text
    assert "car:" not in text


def test_each_odometer_network_reads_its_own_inputs_with_a_default_for_the_others():
    from bgfn.config import odometer_inputs
    from bgfn.profile_schema import load_profile
    from bgfn.settings_check import ProfileError, complete

    oc = {"inputs": {"default": "band_frames", "bgfn": "imu"}, "methods": ["bgfn", "transformer"]}
    assert [odometer_inputs(oc, m) for m in oc["methods"]] == ["imu", "band_frames"]
    assert odometer_inputs({"inputs": "imu"}, "mlp") == "imu"
    cfg = load_profile("smoke")
    cfg["evaluate"]["odometer"]["inputs"] = {"bgfn": "imu"}
    with pytest.raises(ProfileError, match="default"):
        complete(cfg)
    cfg["evaluate"]["odometer"]["inputs"] = {"default": "imu", "lstm": "imu"}
    with pytest.raises(ProfileError, match="inputs.lstm"):
        complete(cfg)


def test_two_networks_on_two_front_ends_train_side_by_side(monkeypatch, tmp_path):
    from bgfn import config

    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    seen = []
    with_inputs = O.lo.with_inputs
    monkeypatch.setattr(O.lo, "with_inputs", lambda d, inputs, rate: seen.append(inputs) or with_inputs(d, inputs, rate))
    drive = demo_drive("synthetic", 150.0, 5.0, 3)
    cfg = load_profile("smoke")
    cfg = {**cfg, "nav": NAV, "train": {**cfg["train"], "window": 50, "margin_s": 5.0}}
    ecfg = ev.evaluate_config({"sweep": {"n_starts": 2, "folds": 2, "durations_s": [10.0], "warmup_s": 30.0},
                               "odometer": {**PLAIN, "sigmas_mps": [0.5], "seeds": [0], "methods": ["mlp", "at_lstm"],
                                            "inputs": {"default": "band_frames", "mlp": "imu"}}}, cfg["train"])
    rows, facts = O.odometer_rows(cfg, "t", "synthetic", ecfg, drive=drive)
    assert seen == ["imu", "imu", "band_frames", "band_frames"]          # per front end, each fold once
    assert sorted(facts["networks"]) == ["AT-LSTM-ODO fold 0 seed 0", "AT-LSTM-ODO fold 1 seed 0",
                                         "MLP-ODO fold 0 seed 0", "MLP-ODO fold 1 seed 0"]
    assert rows.loc[rows["method"].isin(["MLP-ODO", "AT-LSTM-ODO"]), "speed_rmse_mps"].notna().all()

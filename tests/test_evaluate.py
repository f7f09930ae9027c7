"""Outage evaluation (bgfn.evaluate) and its statistics (bgfn.stats).

A small synthetic drive (demo trajectory, Ekinox-grade IMU errors, 5 Hz GNSS) keeps every test fast.
"""

from __future__ import annotations

import copy

import numpy as np
import pandas as pd
import pytest

from bgfn import evaluate as ev, studies
from bgfn import paper
from bgfn import learning as L
from bgfn import stats
from bgfn.config import PROFILES
from bgfn.profile_schema import load_profile
from bgfn.data import Drive
from bgfn.data.gnss import fix_errors
from bgfn.errors import DataError
from bgfn.nav import earth, metrics
from bgfn.nav.filter import run_filter, run_outage
from bgfn.nav.outages import OutageWindow, TablePseudoGps
from synthetic_drive import demo_drive
from bgfn.profile_schema import with_overrides
from bgfn.report import evaluation_words, ins_fidelity_words, sweep_words

WINDOWS = [(60.0, 20.0), (110.0, 20.0)]
NAV = {"init": {"position_std_m": 1.0, "height_std_m": 2.0, "velocity_std_mps": 0.1, "level_std_deg": 0.2,
                "azimuth_std_deg": 1.0}}


def _drive(gnss_rate=5.0, duration=150.0, seed=3) -> Drive:
    return demo_drive("synthetic", duration, gnss_rate, seed)


class Heading:
    """Fake network: dead reckoning at a fixed speed along the input yaw; records its inputs."""

    def __init__(self, window=20, speed=8.0, interval=0.2, zero=False, extra=()):
        self.options = {"window": window, "alignment": "ending", "yaw_encoding": "unwrap",
                        "extra_channels": list(extra), "target_frame": "ned"}
        self.speed, self.interval, self.zero = speed, interval, zero
        self.seen = []

    def predict_windows(self, ws):
        self.seen.append(ws)
        d = self.speed * self.interval * np.column_stack([np.cos(ws.yaw_ref), np.sin(ws.yaw_ref)])
        return np.zeros_like(d) if self.zero else d


@pytest.fixture(scope="module")
def drive5():
    return _drive(5.0)


@pytest.fixture(scope="module")
def ctx5(drive5):
    return ev.navigation_context(drive5, NAV, [s for s, _ in WINDOWS])


# ----------------------------------------------------------------------------------------------- Eq. pred-gps
def test_pseudo_gps_accumulates_known_increments():
    p0 = np.array([np.radians(45.06), np.radians(7.66), 250.0])
    inc = np.tile([1.0, 2.0], (10, 1))                        # 1 m north, 2 m east per epoch
    inc[4] = [-3.0, 0.5]
    p = ev.pseudo_gps_positions(p0, inc)
    ned = earth.lla_to_ned(p[:, 0], p[:, 1], p[:, 2], *p0)
    expect = np.cumsum(inc, axis=0)                            # P_GPS(k) - P_GPS0 = sum_{i<=k} dP_i
    np.testing.assert_allclose(ned[:, :2], expect, atol=1e-6)
    assert expect[-1].tolist() == [6.0, 18.5]                  # 9*1 - 3 ; 9*2 + 0.5
    assert np.all(np.abs(p[:, 2] - 250.0) < 1e-3)              # height is not moved by 2-D increments


def test_fused_fixes_follow_eq_pred_gps(ctx5):
    f = Heading(window=20)
    run = ev.run_outages(ctx5, [WINDOWS[0]], f, "BGFN", 0, {"std_m": 1.0, "fusion_rate_hz": 1.0})[0]
    # 5 Hz GNSS: five 0.2 s increments per 1 Hz fusion epoch, 20 fusion epochs
    assert len(run.increments) == 100 and len(run.pseudo) == 20
    np.testing.assert_allclose(np.diff(run.increments["time"]), 0.2, atol=1e-9)
    cum = np.cumsum(run.increments[["dn", "de"]].to_numpy(), axis=0)[4::5]
    np.testing.assert_allclose(run.pseudo[["cum_dn", "cum_de"]].to_numpy(), cum, atol=1e-9)
    p0 = ctx5.state_at(WINDOWS[0][0]).antenna_position(ctx5.lever)
    ned = earth.lla_to_ned(run.pseudo["lat"].to_numpy(), run.pseudo["lon"].to_numpy(), run.pseudo["h"].to_numpy(),
                           *p0)
    np.testing.assert_allclose(ned[:, :2], cum, atol=1e-6)
    # each increment is 8 m/s * 0.2 s long
    np.testing.assert_allclose(np.hypot(run.increments["dn"], run.increments["de"]), 1.6, atol=1e-9)


# ----------------------------------------------------------------------------------------------- filter runs
def test_ins_run_is_the_filters_standalone_ins(ctx5):
    run = ev.run_outages(ctx5, [WINDOWS[1]], None)[0]
    s, d = WINDOWS[1]
    ref = run_outage(ctx5.drive.imu, ctx5.state_at(s), OutageWindow(s, d), ctx5.noise, ctx5.lever)
    np.testing.assert_allclose(run.trajectory[["lat", "lon"]].to_numpy(), ref.trajectory[["lat", "lon"]].to_numpy(),
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(run.trajectory[["v_n", "v_e", "yaw"]].to_numpy(),
                               ref.trajectory[["v_n", "v_e", "yaw"]].to_numpy(), rtol=0, atol=1e-9)
    # INS errors grow through the outage
    e = run.errors
    assert e["horizontal"].iloc[-1] > 3 * e["horizontal"].iloc[:50].max()


def test_hybrid_equals_run_filter_fed_with_the_same_fixes(ctx5):
    f = Heading(window=20)
    run = ev.run_outages(ctx5, [WINDOWS[0]], f, "BGFN", 0, {"std_m": 1.5, "fusion_rate_hz": 1.0})[0]
    fx = run.pseudo.rename(columns={"std_m": "std_n"}).assign(std_e=lambda d: d["std_n"], std_d=np.nan)
    s, d = WINDOWS[0]
    ref = run_filter(ctx5.drive.imu, ctx5.state_at(s), ctx5.noise, None, ctx5.lever, [(s, d)],
                     pseudo_gps=TablePseudoGps(fx), t_end=s + d, pseudo_rate_hz=1.0)
    assert (ref.updates["kind"] == "pseudo").sum() == 20
    np.testing.assert_allclose(run.trajectory[["lat", "lon", "h"]].to_numpy(),
                               ref.trajectory[["lat", "lon", "h"]].to_numpy(), rtol=0, atol=1e-11)
    np.testing.assert_allclose(run.trajectory[["v_n", "v_e", "roll", "yaw"]].to_numpy(),
                               ref.trajectory[["v_n", "v_e", "roll", "yaw"]].to_numpy(), rtol=0, atol=1e-8)


def test_constrained_runs_equal_the_filters_with_the_same_constraints(ctx5):
    """INS+NHC and a network's +NHC run (the engine stepped by bgfn.evaluate) are run_outage / run_filter
    with the same constraints and fixes; the vehicle frame is the GPS-aided run's estimate at the start."""
    s, d = WINDOWS[1]
    con = ctx5.constraints
    assert con is not None and np.count_nonzero(con.aid) > 0
    run = ev.run_outages(ctx5, [(s, d)], None, "INS+NHC", None, aids=[con])[0]
    ref = run_outage(ctx5.drive.imu, ctx5.state_at(s), OutageWindow(s, d), ctx5.noise, ctx5.lever, aids=[con])
    np.testing.assert_allclose(run.trajectory[["lat", "lon"]].to_numpy(), ref.trajectory[["lat", "lon"]].to_numpy(),
                               rtol=0, atol=1e-12)
    np.testing.assert_allclose(run.trajectory[["v_n", "v_e", "yaw"]].to_numpy(),
                               ref.trajectory[["v_n", "v_e", "yaw"]].to_numpy(), rtol=0, atol=1e-9)
    ins = ev.run_outages(ctx5, [(s, d)], None)[0]
    assert not np.allclose(ins.trajectory["lat"], run.trajectory["lat"], rtol=0, atol=1e-12)
    f = Heading(window=20)
    hyb = ev.run_outages(ctx5, [(s, d)], f, "BGFN+NHC", 0, {"std_m": 1.5, "fusion_rate_hz": 1.0}, aids=[con])[0]
    fx = hyb.pseudo.rename(columns={"std_m": "std_n"}).assign(std_e=lambda x: x["std_n"], std_d=np.nan)
    ref = run_filter(ctx5.drive.imu, ctx5.state_at(s), ctx5.noise, None, ctx5.lever, [(s, d)],
                     pseudo_gps=TablePseudoGps(fx), t_end=s + d, pseudo_rate_hz=1.0,
                     aids=[con.frozen(ctx5.state_at(s).time)])
    np.testing.assert_allclose(hyb.trajectory[["lat", "lon", "h"]].to_numpy(),
                               ref.trajectory[["lat", "lon", "h"]].to_numpy(), rtol=0, atol=1e-11)
    np.testing.assert_allclose(hyb.trajectory[["v_n", "v_e", "roll", "yaw"]].to_numpy(),
                               ref.trajectory[["v_n", "v_e", "roll", "yaw"]].to_numpy(), rtol=0, atol=1e-8)


def test_tables_have_the_nhc_rows_of_every_method(drive5):
    cfg = {"outage_windows": [list(w) for w in WINDOWS], "nav": NAV}
    ecfg = ev.evaluate_config({"methods": ["bgfn"], "seeds": [0, 1], "pseudo_gps": {"std_m": 1.5}})
    models = {("bgfn", 0): Heading(window=20), ("bgfn", 1): Heading(window=20, speed=7.0)}
    res = ev.evaluate_dataset(cfg, "none", drive5.name, drive=drive5, ecfg=ecfg, models=models)
    assert list(res.table.loc[res.table["outage"] == 1, "method"]) == ["INS", "BGFN", "INS+NHC", "BGFN+NHC", "GPS"]
    assert len(res.runs) == 2 * (2 + 2 * 2 + 1)
    assert res.constraints["aid_epochs"] > 0
    ins_nhc = [r for r in res.runs if r.method == "INS+NHC" and r.start == WINDOWS[0][0]][0]
    ctx = ev.navigation_context(drive5, NAV, [s for s, _ in WINDOWS])
    again = ev.run_outages(ctx, [WINDOWS[0]], None, "INS+NHC", None, ecfg["pseudo_gps"], aids=[ctx.constraints])
    pd.testing.assert_frame_equal(ins_nhc.trajectory, again[0].trajectory, check_exact=True)
    (line, _) = evaluation_words.describe_tables([res])
    assert "INS+NHC" in line and "BGFN+NHC" in line and "INS+NHC)" in line
    lay = ev.ours_above_paper(ev.TableResult("turin-sim-ekinox", "dataset", res.per_seed, res.table, []))
    assert ("BGFN+NHC", "East") in lay.columns and np.isnan(lay.loc[("Outage 1", "paper"), ("BGFN+NHC", "East")])
    without = ev.evaluate_dataset(cfg, "none", drive5.name, drive=drive5, ecfg={**ecfg, "nhc_rows": False},
                                  models=models)
    assert set(without.table["method"]) == {"INS", "BGFN", "GPS"} and without.constraints is None
    pd.testing.assert_frame_equal(without.table, res.table[res.table["method"].isin(["INS", "BGFN", "GPS"])]
                                  .reset_index(drop=True), check_exact=True)


def test_inputs_use_the_runs_own_attitude(ctx5, drive5):
    """Windows = Eq. eq21 inputs from the solution being computed (pre-outage: GPS-aided run), no truth."""
    f = Heading(window=20, zero=True)
    run = ev.run_outages(ctx5, [WINDOWS[0]], f, "BGFN", 0, {"std_m": 1e9, "fusion_rate_hz": 1.0})[0]
    s = WINDOWS[0][0]
    full = ctx5.full.trajectory
    t0 = run.trajectory["time"].iloc[0]                        # state: last IMU epoch before the start
    assert s - 0.011 < t0 < s
    pre = full[(full["time"] <= t0 + 1e-9) & (full["time"] > s - 1.0)]
    att = pd.concat([pre[["time", "roll", "pitch", "yaw"]], run.trajectory[["time", "roll", "pitch", "yaw"]].iloc[1:]])
    epochs = np.concatenate([[s], run.increments["time"].to_numpy()])
    expect = L.prediction_windows(drive5.imu, att, epochs, window=20)
    got = np.concatenate([w.x for w in f.seen])
    np.testing.assert_allclose(got, expect.x, rtol=0, atol=2e-6)
    np.testing.assert_allclose(np.concatenate([w.yaw_ref for w in f.seen]), expect.yaw_ref, atol=1e-9)
    # the attitude inside the outage is the INS solution's, not the truth
    truth = drive5.reference.set_index("time").loc[run.increments["time"].round(6), "yaw"].to_numpy()
    assert np.max(np.abs(L.wrap_angle(expect.yaw_ref - truth))) > 1e-5


def test_heading_frame_velocity_inputs_match_training_features(ctx5, drive5):
    """v_along, v_cross inside an outage are computed from the run's own solution as in training."""
    f = Heading(window=20, zero=True, extra=("v_along", "v_cross"))
    run = ev.run_outages(ctx5, [WINDOWS[0]], f, "BGFN", 0, {"std_m": 1e9, "fusion_rate_hz": 1.0})[0]
    s = WINDOWS[0][0]
    t0 = run.trajectory["time"].iloc[0]
    full = ctx5.full.trajectory
    cols = ["time", "roll", "pitch", "yaw", "v_n", "v_e"]
    pre = full[(full["time"] <= t0 + 1e-9) & (full["time"] > s - 1.0)]
    sol = pd.concat([pre[cols], run.trajectory[cols].iloc[1:]])
    epochs = np.concatenate([[s], run.increments["time"].to_numpy()])
    expect = L.prediction_windows(drive5.imu, sol, epochs, window=20, extra_channels=("v_along", "v_cross"))
    got = np.concatenate([w.x for w in f.seen])
    assert got.shape[-1] == 11
    np.testing.assert_allclose(got, expect.x, rtol=0, atol=2e-5)
    # the demo drive moves forward: along-track speed is the horizontal speed, cross-track is near zero
    speed = np.hypot(sol["v_n"], sol["v_e"]).to_numpy()
    assert np.max(np.abs(got[..., 9])) <= speed.max() + 1e-6 and np.median(got[..., 9]) > 1.0
    assert np.max(np.abs(got[..., 10])) < 0.05 * np.max(np.abs(got[..., 9]))


def test_evaluation_never_reads_gnss_inside_an_outage(drive5):
    """NaN GNSS inside an outage changes nothing of that outage's INS and hybrid runs (only the GPS row)."""
    for s, d in WINDOWS:
        g = drive5.gnss.copy()
        inside = OutageWindow(s, d).contains(g["time"])
        assert inside.sum() == 100 and np.isclose(g["time"][inside].min(), s)     # a fix at t = start too
        g.loc[inside, ["lat", "lon", "h", "std_n", "std_e", "std_d"]] = np.nan
        blind = Drive(drive5.name, drive5.reference, drive5.imu, g, drive5.meta)
        out = {}
        for name, drv in (("with", drive5), ("nan", blind)):
            ctx = ev.navigation_context(drv, NAV, [s])
            runs = ev.run_outages(ctx, [(s, d)], None) + ev.run_outages(ctx, [(s, d)], Heading(), "BGFN", 0)
            runs += (ev.run_outages(ctx, [(s, d)], None, "INS+NHC", aids=[ctx.constraints])       # the vehicle
                     + ev.run_outages(ctx, [(s, d)], Heading(), "BGFN+NHC", 0, aids=[ctx.constraints]))  # frame too
            out[name] = [r.trajectory for r in runs] + [r.pseudo for r in runs[1:]], ev.gps_run(ctx, s, d).trajectory
        for a, b in zip(out["with"][0], out["nan"][0]):
            pd.testing.assert_frame_equal(a, b, check_exact=True)
        # the GPS row (the lower bound) does use them: it changes
        assert not np.allclose(out["with"][1]["lat"].to_numpy(), out["nan"][1]["lat"].to_numpy(), rtol=0,
                               atol=1e-12)


def test_window_metrics_match_nav_metrics(ctx5):
    run = ev.run_outages(ctx5, [WINDOWS[0]], None)[0]
    s, d = WINDOWS[0]
    m = ev.window_metrics(run.errors, s, d)
    ref = metrics.outage_metrics(run.errors, OutageWindow(s, d))
    assert m["max_east_m"] == pytest.approx(ref["max_abs_east"])
    assert m["max_north_m"] == pytest.approx(ref["max_abs_north"])
    assert m["rmse_h_m"] == pytest.approx(ref["rmse_horizontal"])
    assert m["final_h_m"] == pytest.approx(ref["end_horizontal"])
    assert m["max_h_m"] == pytest.approx(ref["max_horizontal"])
    # a prefix of a long run is the short outage (causal): same numbers as a 5 s run, NEES included
    short = ev.run_outages(ctx5, [(s, 5.0)], None)[0]
    assert ev.window_metrics(run.errors, s, 5.0, run.sd) == pytest.approx(
        ev.window_metrics(short.errors, s, 5.0, short.sd))
    # NEES by hand: the last epoch's north/east error over the filter's own std there, squared and summed
    e, sd = run.errors.iloc[-1], run.sd.iloc[-1]
    nees = (e["north"] / sd["sd_north_m"]) ** 2 + (e["east"] / sd["sd_east_m"]) ** 2
    assert ev.window_metrics(run.errors, s, d, run.sd)["nees_h"] == pytest.approx(nees)
    assert np.isnan(m["nees_h"]) and 0.0 < sd["sd_north_m"] < 100.0                    # no sd: not measured
    # the std grows through the outage (no fix), from the GPS-aided level at the start
    assert run.sd["sd_north_m"].iloc[-1] > run.sd["sd_north_m"].iloc[0] > 0.0


def test_prefix_of_a_hybrid_run_is_the_shorter_outage(ctx5):
    s = WINDOWS[0][0]
    long = ev.run_outages(ctx5, [(s, 20.0)], Heading(), "BGFN", 0)[0]
    short = ev.run_outages(ctx5, [(s, 7.0)], Heading(), "BGFN", 0)[0]
    assert ev.window_metrics(long.errors, s, 7.0, long.sd) == pytest.approx(
        ev.window_metrics(short.errors, s, 7.0, short.sd), abs=1e-9)


def test_gps_row_is_the_smallest_and_fusion_rate_must_divide_gnss_rate(ctx5):
    s, d = WINDOWS[0]
    gps = ev.window_metrics(ev.gps_run(ctx5, s, d).errors, s, d)
    ins = ev.window_metrics(ev.run_outages(ctx5, [(s, d)], None)[0].errors, s, d)
    assert gps["max_h_m"] < ins["max_h_m"]
    with pytest.raises(DataError):
        ev.run_outages(ctx5, [(s, d)], Heading(), "BGFN", 0, {"fusion_rate_hz": 2.0 / 3.0})


# ----------------------------------------------------------------------------------------------- tables
def test_aggregate_seeds_reduction_and_layout():
    rows = []
    for seed, val in ((0, 1.0), (1, 3.0), (2, 2.0)):
        rows.append({"outage": 1, "method": "BGFN", "seed": seed, "max_east_m": val, "max_north_m": 2 * val,
                     "rmse_h_m": val, "final_h_m": val, "max_h_m": val})
    rows.append({"outage": 1, "method": "INS", "seed": None, "max_east_m": 10.0, "max_north_m": 8.0,
                 "rmse_h_m": 5.0, "final_h_m": 9.0, "max_h_m": 11.0})
    t = ev.aggregate_seeds(pd.DataFrame(rows))
    assert list(t.columns) == list(ev.TABLE_COLUMNS) and list(t["method"]) == ["INS", "BGFN"]
    assert t.loc[t["method"] == "BGFN", "max_east_m"].item() == 2.0          # median of 1, 3, 2
    red = ev.error_reduction(t)
    assert red["east_pct"].item() == pytest.approx(80.0) and red["north_pct"].item() == pytest.approx(50.0)
    assert ev.aggregate_seeds(pd.DataFrame(rows), "first").loc[1, "max_east_m"] == 1.0
    lay = paper.layout(t, paper.outage_table("dataset"), methods=ev.TABLE_METHODS)
    assert lay.loc["Outage 1", ("paper", "BGFN", "East")] == 4.7
    assert lay.loc["Outage 1", ("ours", "INS", "North")] == 8.0
    # the paper's quoted reduction (claims.yaml) is its Table 1 arithmetic
    p = ev.error_reduction(paper.outage_table("dataset"))
    c = paper.claims()["bgfn_reduction_vs_ins_pct"]["dataset_outage1"]
    got = p[(p["outage"] == 1) & (p["method"] == "BGFN")]
    assert got["east_pct"].item() == pytest.approx(c["east"], abs=0.1)


@pytest.mark.parametrize("profile", PROFILES)
def test_profiles_have_a_valid_evaluate_section(profile):
    cfg = load_profile(profile)
    e = ev.evaluate_config(cfg["evaluate"], cfg["train"])
    assert set(cfg["evaluate"]) == set(ev.EVALUATE_DEFAULTS)
    assert e["sweep"]["n_starts"] >= 1 and e["seeds"]
    if profile == "quick":
        assert e["sweep"]["n_starts"] >= 20 and len(e["sweep"]["seeds"]) >= 3 and len(e["sweep"]["durations_s"]) >= 4
    if profile == "paper":
        assert len(e["sweep"]["seeds"]) >= 5


def test_evaluate_config_rejects_unknown_keys():
    with pytest.raises(DataError):
        ev.evaluate_config({"no_such_key": 1})
    with pytest.raises(DataError):
        ev.evaluate_config({"sweep": {"n_starts": 2, "folds": 3}})


def test_sweep_plan_spreads_starts_in_contiguous_folds(drive5):
    sw = {"n_starts": 7, "folds": 3, "durations_s": [10.0, 30.0], "warmup_s": 20.0}
    plan = studies.outage_sweep.sweep_plan(drive5, sw, window_samples=50)
    assert len(plan) == 7 and plan["start_s"].is_monotonic_increasing
    assert plan["start_s"].min() >= 20.0 and plan["start_s"].max() + 30.0 <= drive5.imu["time"].iloc[-1]
    assert plan["fold"].tolist() == [0, 0, 0, 1, 1, 2, 2]
    # a recorded drive's IMU may run on past its reference: the last outage still ends inside the reference
    ref_end = float(drive5.reference["time"].iloc[-1]) - 7.05
    short = copy.copy(drive5)
    short.reference = drive5.reference[drive5.reference["time"] <= ref_end].reset_index(drop=True)
    cut = studies.outage_sweep.sweep_plan(short, sw, window_samples=50)
    assert cut["start_s"].max() + 30.0 <= ref_end < plan["start_s"].max() + 30.0


# ----------------------------------------------------------------------------------------------- statistics
def test_bootstrap_interval_covers_the_known_median():
    rng = np.random.default_rng(0)
    x = 3.0 + rng.standard_normal(400)                    # true median 3
    lo, hi = stats.bootstrap_ci(x, n_boot=1000, seed=1)
    assert lo < 3.0 < hi and hi - lo < 0.4
    # coverage over repeated samples is close to 95 %
    hits = 0
    for i in range(200):
        y = rng.exponential(2.0, 40)                      # true median 2 ln 2
        lo, hi = stats.bootstrap_ci(y, n_boot=400, seed=i)
        hits += lo <= 2.0 * np.log(2.0) <= hi
    assert 0.88 <= hits / 200 <= 0.99


def test_cluster_bootstrap_is_wider_with_correlated_clusters():
    rng = np.random.default_rng(2)
    centres = rng.standard_normal(20)                     # 20 starts, 5 nearly equal seeds each
    x = np.repeat(centres, 5) + 0.01 * rng.standard_normal(100)
    g = np.repeat(np.arange(20), 5)
    lo_i, hi_i = stats.bootstrap_ci(x, n_boot=1000, seed=0)
    lo_c, hi_c = stats.bootstrap_ci(x, n_boot=1000, seed=0, groups=g)
    assert (hi_c - lo_c) > 1.5 * (hi_i - lo_i)


def test_paired_test_detects_a_shift_and_not_a_null():
    rng = np.random.default_rng(4)
    b = rng.lognormal(1.0, 0.5, 60)
    a = b - 0.5 + 0.3 * rng.standard_normal(60)           # A better by 0.5 m on average
    r = stats.paired_comparison(a, b)
    assert r["p_value"] < 1e-6 and r["win_rate"] > 0.8 and r["median_diff"] < 0
    rejections = 0
    for i in range(200):
        b = rng.lognormal(1.0, 0.5, 60)
        a = b + 0.3 * rng.standard_normal(60)             # no shift
        rejections += stats.paired_comparison(a, b)["p_value"] < 0.05
    assert rejections / 200 < 0.10
    assert np.isnan(stats.paired_comparison([1.0, 2.0], [1.0, 2.0])["p_value"])


def test_holm_adjusts_a_hand_computed_family():
    # k = 4 finite p-values (the NaN is no test): sorted 0.005, 0.01, 0.03, 0.04 -> times 4, 3, 2, 1 =
    # 0.02, 0.03, 0.06, 0.04; the running maximum lifts the last to 0.06 (the adjusted keep the raw order)
    got = stats.holm_adjust([0.01, 0.04, 0.03, 0.005, np.nan])
    np.testing.assert_allclose(got[:4], [0.03, 0.06, 0.06, 0.02])
    assert np.isnan(got[4])
    # capped at 1: 0.02 * 3 = 0.06, 0.5 * 2 = 1.0, 0.7 * 1 -> lifted to 1.0 by the running maximum
    np.testing.assert_allclose(stats.holm_adjust([0.5, 0.02, 0.7]), [1.0, 0.06, 1.0])
    # one test: unchanged; none: empty; never below the raw p
    assert stats.holm_adjust([0.014]).tolist() == [0.014] and stats.holm_adjust([]).size == 0
    raw = np.random.default_rng(0).random(9)
    assert np.all(stats.holm_adjust(raw) >= raw)
    with pytest.raises(DataError, match="p_values"):
        stats.holm_adjust([0.5, 1.5])


def test_sweep_summary_and_comparisons():
    rows = []
    rng = np.random.default_rng(1)
    for start in range(12):
        ins = 10.0 + rng.random()
        for seed in range(3):
            for m, v in (("INS", ins), ("BGFN", 0.5 * ins + 0.1 * rng.random()), ("MLP", ins + 1.0)):
                rows.append({"dataset": "d", "start_s": float(start), "duration_s": 30.0, "method": m,
                             "seed": seed, "fold": 0, "max_h_m": v})
    df = pd.DataFrame(rows)
    s = studies.outage_sweep.sweep_summary(df, n_boot=300)
    ins = s[s["method"] == "INS"].iloc[0]
    assert ins["n"] == 12 and ins["ci_lo_m"] <= ins["median_m"] <= ins["ci_hi_m"]
    c = studies.outage_sweep.sweep_comparisons(df).set_index("baseline")
    assert c.loc["INS", "win_rate"] == 1.0 and c.loc["MLP", "wins"] == 36 and c.loc["INS", "p_value"] < 1e-6
    assert c.loc["INS", "n_starts"] == 12 and c.loc["INS", "p_value_by_start"] < 1e-2
    assert set(c["method"]) == {"BGFN"}
    # with the constraints' rows: BGFN against them too, and BGFN+NHC against INS+NHC (does it add to the free aid?)
    nhc = df[df["method"] != "MLP"].assign(method=lambda x: x["method"] + "+NHC",
                                           max_h_m=lambda x: np.where(x["method"] == "INS", 0.5, 0.3) * x["max_h_m"])
    both = pd.concat([df, nhc], ignore_index=True)
    s = studies.outage_sweep.sweep_summary(both, n_boot=100)
    assert s.loc[s["method"] == "INS+NHC", "n"].item() == 12                 # one value per start, like INS
    c = studies.outage_sweep.sweep_comparisons(both)
    assert set(c.loc[c["method"] == "BGFN", "baseline"]) == {"INS", "MLP", "INS+NHC", "BGFN+NHC"}
    pair = c[(c["method"] == "BGFN+NHC")].set_index("baseline")
    assert list(pair.index) == ["INS+NHC"] and pair.loc["INS+NHC", "wins"] == 36
    (line,) = sweep_words.describe_sweep(s, c)
    assert "BGFN vs INS: wins 36/36" in line and "BGFN+NHC vs INS+NHC: wins 36/36" in line
    # a pairs table of older runs (no method column) still reads
    (old,) = sweep_words.describe_sweep(studies.outage_sweep.sweep_summary(df, n_boot=100), studies.outage_sweep.sweep_comparisons(df).drop(columns="method"))
    assert "BGFN vs INS: wins 36/36" in old


def test_validation_std_grows_with_the_accumulated_increments(ctx5):
    f = Heading(window=20)
    f.val_rmse_m = 0.5 * np.sqrt(2.0)                          # 0.5 m per axis and increment
    run = ev.run_outages(ctx5, [WINDOWS[0]], f, "BGFN", 0, {"std_m": "validation", "fusion_rate_hz": 1.0})[0]
    k = np.arange(1, 21)
    np.testing.assert_allclose(run.pseudo["std_m"], 0.5 * np.sqrt(5 * k))   # 5 increments per fix
    with pytest.raises(DataError):
        ev.run_outages(ctx5, [WINDOWS[0]], Heading(), "BGFN", 0, {"std_m": "validation"})


def test_saved_tables_have_the_schema(ctx5, tmp_path):
    runs = ev.run_outages(ctx5, WINDOWS, None) + [ev.gps_run(ctx5, s, d) for s, d in WINDOWS]
    runs += ev.run_outages(ctx5, WINDOWS, Heading(), "BGFN", 0)
    per_seed = pd.DataFrame([{"outage": 1 + WINDOWS.index((r.start, r.duration)), "start_s": r.start,
                              "method": r.method, "seed": r.seed, **ev.window_metrics(r.errors, r.start, r.duration)}
                             for r in runs])
    res = ev.TableResult("synthetic", "dataset", per_seed, ev.aggregate_seeds(per_seed), runs)
    paths = ev.save_table_result(tmp_path, res, series_rate_hz=5.0)
    t = pd.read_csv(paths["table"])
    assert list(t.columns) == list(ev.TABLE_COLUMNS) and paths["table"].name == "outage_dataset.csv"
    assert t.groupby("outage")["method"].apply(list).tolist() == [["INS", "BGFN", "GPS"]] * 2
    assert np.all(np.isfinite(t[list(ev.METRIC_COLUMNS)].to_numpy())) and (t[list(ev.METRIC_COLUMNS)] > 0).all().all()
    s = pd.read_csv(paths["series"])
    ins = s[(s["method"] == "INS") & (s["outage"] == 1)]
    assert np.allclose(np.diff(ins["t_rel"]), 0.2) and ins["h_m"].iloc[-1] > ins["h_m"].iloc[0]


def test_real_imu_switch_falls_back_to_the_simulated_datasets(monkeypatch, tmp_path):
    from bgfn.data import acquire

    present = {"ekinox_imu.mat"}

    def fake_resolve(name, **kw):
        path = tmp_path / name if name in present else None
        return acquire.Resolved(name, path, "raw" if path else "missing", None, "test")

    monkeypatch.setattr(acquire, "resolve", fake_resolve)
    names, choices = ev.choose_datasets(["turin-sim-ekinox", "turin-sim-mpu6000"], real_imu=True)
    assert names == ["navego-ekinox", "turin-sim-mpu6000"]
    assert choices[0] == ev.RealImuChoice("turin-sim-ekinox", "navego-ekinox", "ekinox_imu.mat", "raw")
    assert choices[1].origin is None and choices[1].twin == "navego-mpu6000"           # absent: the simulated one
    assert evaluation_words.real_imu_words(choices[1]) == (
        "mpu6000_imu.mat absent (the recorded NaveGo IMU is not available here): turin-sim-mpu6000 (simulated IMU) "
        "stands in for navego-mpu6000")
    assert ev.choose_datasets(["turin-sim-ekinox"], real_imu=False) == (["turin-sim-ekinox"], [])
    assert paper.test_of("navego-ekinox") == "dataset" and paper.test_of("navego-mpu6000") == "field"


def test_fix_error_table_takes_the_largest_fix_error_inside_each_window():
    ref = pd.DataFrame({"time": np.arange(0.0, 100.01, 0.01), "lat": 0.7, "lon": 0.13, "h": 200.0,
                        "roll": 0.0, "pitch": 0.0, "yaw": 0.0})
    r_m, r_n = earth.curvature_radii(0.7)
    t = np.arange(0.0, 101.0, 1.0)
    north = np.where((t >= 10) & (t <= 40), 0.1 * (t - 10), 0.0)       # grows to 3 m inside window 1
    east = np.where(t == 41, 9.0, -0.5)                                # a 9 m jump just after window 1
    fixes = pd.DataFrame({"time": t, "lat": 0.7 + north / (r_m + 200.0),
                          "lon": 0.13 + east / ((r_n + 200.0) * np.cos(0.7)), "h": 200.0})
    err = fix_errors(fixes, ref, [0.0, 0.0, 0.0])
    tab = ev.fix_error_table(err, [(10.0, 30.0), (60.0, 30.0), (200.0, 5.0)])
    assert tab["n_fixes"].tolist() == [31, 31, 0]
    assert tab.loc[0, "max_north_m"] == pytest.approx(3.0, abs=1e-6)
    assert tab.loc[0, "max_east_m"] == pytest.approx(0.5, abs=1e-6)   # the jump at 41 s is outside
    assert tab.loc[1, "max_north_m"] == pytest.approx(0.0, abs=1e-6) and np.isnan(tab.loc[2, "max_east_m"])


def test_describe_tables_says_where_gps_is_not_the_lower_bound():
    rows = []
    for m, e in (("INS", 0.8), ("BGFN", 30.0), ("GPS", 1.6)):
        rows.append({"outage": 2, "method": m, "max_east_m": e, "max_north_m": 11.0 if m != "GPS" else 1.0,
                     "rmse_h_m": 6.0 if m != "GPS" else 1.5, "final_h_m": 11.0 if m != "GPS" else 1.7})
    res = ev.TableResult("turin-sim-ekinox", "dataset", pd.DataFrame(), pd.DataFrame(rows), [], {})
    (line,) = evaluation_words.describe_tables([res])
    assert "not the lower bound" in line and "INS max east 0.8 < GPS 1.6 m" in line
    assert "BGFN max east" not in line                       # only cells below the GPS row are named
    assert "fixes in this window" not in line               # their errors unknown: not claimed
    fixes = pd.DataFrame({"outage": [1, 2], "start_s": [0.0, 100.0], "n_fixes": [150, 150],
                          "max_east_m": [2.9, 1.64], "max_north_m": [1.9, 1.1]})
    res.gnss_errors = fixes
    (line,) = evaluation_words.describe_tables([res])
    assert line.endswith("the fixes in this window are off by up to 1.6 m east and 1.1 m north.")
    rows[0]["max_east_m"] = 2.0
    (line,) = evaluation_words.describe_tables([ev.TableResult("x", "dataset", pd.DataFrame(), pd.DataFrame(rows), [], {})])
    assert "lower bound" not in line


def test_innovation_gate_reaches_the_gps_aided_runs(drive5):
    from bgfn.nav import baseline

    g = drive5.gnss.copy()
    k = int(np.argmin(np.abs(g["time"].to_numpy() - (g["time"].iloc[0] + 40.0))))
    r_m, _ = earth.curvature_radii(g.loc[k, "lat"])
    g.loc[k, "lat"] += 25.0 / (r_m + g.loc[k, "h"])                 # one fix 25 m north
    jumped = Drive(drive5.name, drive5.reference, drive5.imu, g, drive5.meta)
    cfg = baseline.nav_config(NAV)
    table = baseline.gate_comparison(jumped, cfg, WINDOWS, 0.999)
    assert table["innovation_gate"].tolist() == ["none", "0.999"]
    assert table.loc[0, "gnss_rejected"] == 0 and table.loc[1, "gnss_rejected"] >= 1
    assert table.loc[1, "max_h_m"] < 0.5 * table.loc[0, "max_h_m"]    # the jump no longer pulls the solution
    (line,) = ins_fidelity_words.gate_lines(table)                  # notebook 08's sentence, from report
    off, on = table.iloc[0], table.iloc[1]
    assert line == (f"{drive5.name}: the gate (0.999) rejects {on['gnss_rejected']} of {on['gnss_fixes']} fixes; "
                    f"horizontal RMS {off['rms_h_m']:.2f} -> {on['rms_h_m']:.2f} m, max {off['max_h_m']:.2f} -> "
                    f"{on['max_h_m']:.2f} m")
    # notebook 02's own run is reused for the setting it was made with, giving the same table
    reused = baseline.gate_comparison(jumped, cfg, WINDOWS, 0.999, baseline=baseline.run_baseline(jumped, cfg, WINDOWS))
    pd.testing.assert_frame_equal(reused, table)
    # the evaluation's GPS-aided run reads the same nav: key
    ctx = ev.navigation_context(jumped, {**NAV, "innovation_gate": 0.999}, [WINDOWS[0][0]])
    rejected = ctx.full.updates.loc[~ctx.full.updates["accepted"], "time"].to_numpy()
    assert np.any(np.isclose(rejected, g.loc[k, "time"]))


def test_plot_gps_row_shows_the_fixes_inside_the_window_beside_gps_and_ins():
    import matplotlib
    matplotlib.use("Agg")
    t_rel = np.arange(0.0, 10.01, 0.5)
    runs = [ev.OutageRun(m, None, 100.0, 10.0, pd.DataFrame(),
                         errors=pd.DataFrame({"t_rel": t_rel, "east": k * t_rel, "north": -k * t_rel}))
            for m, k in (("GPS", 0.1), ("INS", 0.3))]
    per_seed = pd.DataFrame({"outage": [1, 1], "start_s": [100.0, 100.0], "method": ["GPS", "INS"],
                             "seed": [None, None]})
    fixes = pd.DataFrame({"time": np.arange(95.0, 116.0), "north_m": 0.0, "east_m": np.arange(95.0, 116.0) - 100})
    res = ev.TableResult("x", "dataset", per_seed, pd.DataFrame(), runs, fix_errors=fixes)
    fig = ev.plot_gps_row(res, 1)
    ax_e = fig.axes[0]
    lines = {ln.get_label(): ln for ln in ax_e.get_lines()}
    assert {"GNSS fixes", "GPS", "INS"} <= set(lines)
    np.testing.assert_allclose(lines["GNSS fixes"].get_xdata(), np.arange(0.0, 11.0))   # 100..110 s only
    np.testing.assert_allclose(lines["GNSS fixes"].get_ydata(), np.arange(0.0, 11.0))
    np.testing.assert_allclose(lines["INS"].get_ydata(), 0.3 * t_rel)
    np.testing.assert_allclose(fig.axes[1].get_lines()[1].get_ydata(), -0.1 * t_rel)     # north, GPS


# ----------------------------------------------------------------------------------------------- notebook 04's calls
def _table_result(dataset="turin-sim-ekinox", bgfn=(2.0, 4.0), seeds=(0,)):
    """Seed aggregate of INS (10/8 m), BGFN and Transformer in two outages (max east/north errors, m); the runs
    (``per_seed``) of the networks' ``seeds`` (INS: one)."""
    rows, runs = [], []
    for o in (1, 2):
        for m, (e, n) in (("INS", (10.0, 8.0)), ("BGFN", bgfn), ("Transformer", (20.0, 4.0))):
            rows.append({"outage": o, "method": m, "max_east_m": e, "max_north_m": n, "rmse_h_m": 1.0,
                         "final_h_m": 1.0})
            runs += [{"outage": o, "method": m, "seed": s} for s in (seeds if m != "INS" else (0,))]
    return ev.TableResult(dataset, paper.test_of(dataset), pd.DataFrame(runs), pd.DataFrame(rows), [], {})


def test_the_per_outage_lines_say_how_many_seeds_and_windows_they_rest_on():
    """Notebook 04's sentence of each outage names the networks' seeds and the table's outages when too few for
    statistics (report.sample_words.sample_clause); with the runs not kept nothing is claimed of them."""
    def with_gps(res):
        gps = pd.DataFrame([{"outage": o, "method": "GPS", "max_east_m": 1.0, "max_north_m": 1.0, "rmse_h_m": 0.5,
                             "final_h_m": 0.5} for o in (1, 2)])
        res.table = pd.concat([res.table, gps], ignore_index=True)
        return res
    one = evaluation_words.describe_tables([with_gps(_table_result())])
    assert [ln.split("): ")[0] for ln in one] == [
        f"turin-sim-ekinox (dataset test), outage {o} (one seed, 2 windows: no statistics" for o in (1, 2)]
    three = evaluation_words.describe_tables([with_gps(_table_result(seeds=(0, 1, 2)))])
    assert three[0].startswith("turin-sim-ekinox (dataset test), outage 1 (3 seeds, 2 windows: no statistics): ")
    kept_not = with_gps(_table_result())
    kept_not.per_seed = pd.DataFrame()
    assert evaluation_words.describe_tables([kept_not])[0].startswith("turin-sim-ekinox (dataset test), outage 1: ")

def test_evaluation_setup_applies_the_notebook_parameters_over_the_profile(monkeypatch):
    from bgfn.data import acquire
    from bgfn.nav.outages import outage_windows

    cfg = load_profile("smoke")
    section = cfg["evaluate"]
    before = repr(section)
    setup = ev.evaluation_setup(with_overrides(cfg, {"evaluate.seeds": [3, 4], "evaluate.sweep.datasets": []}))
    assert setup.config["seeds"] == [3, 4] and setup.config["sweep"]["datasets"] == []
    assert setup.config["sweep"]["n_starts"] == section["sweep"]["n_starts"]       # the other sweep keys stay
    assert setup.config["methods"] == section["methods"] and setup.datasets == section["datasets"]
    assert setup.windows == outage_windows(cfg) and repr(section) == before         # the profile is not modified
    lines = evaluation_words.setup_lines(setup)
    assert lines[0].startswith("profile 'smoke': ") and "seeds: [3, 4]" in lines[2]
    assert lines[3].startswith(f"outages (start, duration) s: {[list(w) for w in outage_windows(cfg)]}")
    # the recorded drive's outages come from the profile's rule, said beside the default list
    assert lines[3].endswith("; rtklib-drive0708: rule cruise_and_manoeuvre (picked from the drive)")
    with pytest.raises(DataError):
        with_overrides(cfg, {"evaluate.methods": ["no_such_network"]})
    # real_imu: one line per note, the tables' and the sweep's, said once
    monkeypatch.setattr(acquire, "resolve", lambda name, **kw: acquire.Resolved(name, None, "missing", None, "t"))
    real = ev.evaluation_setup(with_overrides(cfg, {"evaluate.real_imu": True,
                                                 "evaluate.sweep.datasets": ["turin-sim-mpu6000"]}))
    assert real.datasets == section["datasets"] and len(real.choices) == 2 and real.sweep_choices == real.choices[1:]
    assert [ln for ln in evaluation_words.setup_lines(real) if ln.startswith("real_imu:")] == [
        f"real_imu: {evaluation_words.real_imu_words(c)}" for c in real.choices]


def test_reductions_beside_the_paper_and_its_quoted_claims():
    res = _table_result()
    red = ev.reduction_table(res)
    assert list(red.columns) == list(ev.REDUCTION_COLUMNS)
    row = red[(red["outage"] == 1) & (red["method"] == "BGFN")].iloc[0]
    assert row["east_%"] == pytest.approx(80.0) and row["north_%"] == pytest.approx(50.0)   # 100 (10-2)/10, (8-4)/8
    assert row["paper east_%"] == pytest.approx(100 * (23.1 - 4.7) / 23.1)                   # its Table 1
    assert red.loc[red["method"] == "Transformer", "paper east_%"].isna().all()             # not in the paper
    lines = evaluation_words.claim_lines({"turin-sim-ekinox": red})
    c = paper.claims()["bgfn_reduction_vs_ins_pct"]
    # one seed in the two outages: the line says it rests on too little for statistics (n_seeds, n_windows)
    assert row["n_seeds"] == 1 and row["n_windows"] == 2
    assert lines == [f"BGFN vs INS, dataset test, outage 1: paper quotes {c['dataset_outage1']['east']} % east / "
                     f"{c['dataset_outage1']['north']} % north; ours 80.0 % east / 50.0 % north (one seed, 2 windows: "
                     "no statistics)",
                     f"BGFN vs INS, field test, outage 2: paper quotes {c['field_outage2']['east']} % east / "
                     f"{c['field_outage2']['north']} % north; not evaluated"]
    # a test's first dataset answers for it
    other = ev.reduction_table(_table_result("navego-ekinox", bgfn=(5.0, 4.0)))
    assert evaluation_words.claim_lines({"turin-sim-ekinox": red, "navego-ekinox": other})[0].endswith(
        "ours 80.0 % east / 50.0 % north (one seed, 2 windows: no statistics)")
    assert evaluation_words.claim_lines({"navego-ekinox": other})[0].endswith("ours 50.0 % east / 50.0 % north (one seed, 2 windows: "
                                                                "no statistics)")
    # three seeds, still in two windows: too few windows; runs not kept (no per_seed): nothing said of them
    three = ev.reduction_table(_table_result(seeds=(0, 1, 2)))
    assert evaluation_words.claim_lines({"turin-sim-ekinox": three})[0].endswith("(3 seeds, 2 windows: no statistics)")
    bare = ev.TableResult("turin-sim-ekinox", "dataset", pd.DataFrame(), res.table, [], {})
    assert evaluation_words.claim_lines({"turin-sim-ekinox": ev.reduction_table(bare)})[0].endswith("ours 80.0 % east / 50.0 % north")
    lay = ev.ours_above_paper(res)
    assert lay.loc[("Outage 1", "paper"), ("BGFN", "East")] == 4.7
    assert lay.loc[("Outage 2", "ours"), ("INS", "North")] == 8.0
    assert np.isnan(lay.loc[("Outage 1", "paper"), ("Transformer", "East")])
    title = evaluation_words.paper_table_title
    assert (title("dataset"), title("field")) == ("Table 1 (dataset test)", "Table 2 (field test)")


def test_pseudo_std_sensitivity_runs_the_first_seeds_networks_with_their_validation_std(drive5, tmp_path):
    cfg = {"outage_windows": [list(w) for w in WINDOWS], "nav": NAV}
    ecfg = ev.evaluate_config({"methods": ["bgfn"], "seeds": [1, 0]})
    models = {}
    for seed, speed in ((1, 8.0), (0, 6.0)):
        models[("bgfn", seed)] = Heading(window=20, speed=speed)
        models[("bgfn", seed)].val_rmse_m = 0.5
    res = ev.evaluate_dataset(cfg, "none", "turin-sim-ekinox", drive=drive5, ecfg=ecfg, models=models)
    assert res.drive is drive5
    sens = ev.pseudo_std_sensitivity(cfg, "none", res, ecfg)
    assert sens.seed == 1 and list(sens.alternative.models) == [("bgfn", 1)]       # the first seed only
    t = sens.table.set_index(["outage", "method"])
    assert list(sens.table.columns) == list(ev.SENSITIVITY_COLUMNS)
    seed1 = res.per_seed[res.per_seed["seed"] == 1].set_index(["outage", "method"])
    # the left side is seed 1's own run, not the median over seeds
    assert t.loc[(1, "BGFN"), "max_east_m"] == seed1.loc[(1, "BGFN"), "max_east_m"]
    assert t.loc[(1, "BGFN"), "max_east_m"] != res.table.set_index(["outage", "method"]).loc[(1, "BGFN"), "max_east_m"]
    # INS and GPS fuse no pseudo fix: unchanged; the network's run is not
    for m in ("INS", "GPS"):
        assert t.loc[(1, m), "max_east_m"] == t.loc[(1, m), "max_east_m (validation std)"]
    assert t.loc[(1, "BGFN"), "max_east_m"] != t.loc[(1, "BGFN"), "max_east_m (validation std)"]
    path = ev.save_sensitivity(tmp_path, sens)
    assert path.name == "outage_dataset_std_validation.csv"
    assert list(pd.read_csv(path).columns) == list(ev.TABLE_COLUMNS)


def test_run_tables_evaluates_writes_and_times_every_dataset(monkeypatch, tmp_path):
    from bgfn.evaluate import tables

    seen = []

    def fake_evaluate(cfg, profile, name, ecfg):
        seen.append(name)
        res = _table_result(name)
        res.per_seed = res.table.assign(start_s=100.0 * res.table["outage"], seed=None)
        res.runs = [ev.OutageRun("INS", None, 100.0, 1.0, pd.DataFrame(),
                                 errors=pd.DataFrame({"t_rel": [0.0, 1.0], "east": 0.0, "north": 0.0,
                                                      "horizontal": 0.0}))]
        return res

    monkeypatch.setattr(tables, "outage_result", fake_evaluate)
    lines = []
    results, timings = ev.run_tables({}, "none", ["turin-sim-ekinox", "turin-sim-mpu6000"],
                                     {"series_rate_hz": 10.0}, tmp_path, report=lines.append)
    assert seen == list(results) == ["turin-sim-ekinox", "turin-sim-mpu6000"]
    assert list(timings) == ["tables_turin-sim-ekinox_s", "tables_turin-sim-mpu6000_s"]
    assert lines[1].startswith("turin-sim-mpu6000 (field test): 1 runs in ")
    assert lines[1].endswith("-> tables/outage_field.csv, tables/outage_field_seeds.csv, tables/outage_errors_field.csv")
    assert (tmp_path / "tables" / "outage_dataset.csv").exists()


def test_sweep_tables_and_lines():
    summary = pd.DataFrame({"dataset": "d", "duration_s": [10.0, 10.0, 30.0, 30.0],
                            "method": ["BGFN", "INS", "BGFN", "INS"], "n": 4, "n_starts": 4,
                            "median_m": [1.25, 3.0, 2.0, 9.0], "ci_lo_m": [1.0, 2.0, 1.5, 8.0],
                            "ci_hi_m": [1.5, 4.0, 2.5, 10.0]})
    wide = studies.outage_sweep.sweep_interval_table(summary)
    assert list(wide.columns) == ["10 s", "30 s"] and list(wide.index) == [("d", "INS"), ("d", "BGFN")]
    assert wide.loc[("d", "BGFN"), "30 s"] == "2.0 [1.5, 2.5]" and wide.loc[("d", "INS"), "10 s"] == "3.0 [2.0, 4.0]"
    sweep = pd.DataFrame({"start_s": [1.0, 1.0, 2.0, 2.0], "duration_s": 10.0, "method": ["INS", "BGFN"] * 2,
                          "seed": 0})
    assert sweep_words.describe_sweep_size(sweep) == "4 rows, 2 starts x 1 durations x 2 methods x 1 seeds"
    # the fold networks are described with the sweep's train overrides over the train: section
    cfg = load_profile("smoke")
    ecfg = ev.evaluate_config({"methods": ["mlp"], "sweep": {"train": {"optimizer": {"epochs": 7}}}}, cfg["train"])
    lines = sweep_words.describe_sweep_setup(cfg["train"], ecfg, ["d"])
    assert lines[0].startswith("datasets ['d']: ") and lines[0].endswith("x methods ['MLP'] + INS + GPS")
    assert f"'epochs': 7, 'batch_size': {cfg['train']['optimizer']['batch_size']}" in lines[1]
    assert lines[2] == f"  {'MLP':>12}: {cfg['train']['sizes']['mlp'][cfg['train']['size']]}"
    rows, info, timings = studies.outage_sweep.run_sweeps(cfg, "smoke", [], ecfg)
    assert list(rows.columns) == list(ev.SWEEP_COLUMNS) and rows.empty and info == {} and timings == {}


def test_evaluation_record_is_what_the_results_page_reads(tmp_path):
    import json

    from bgfn.report import page as report

    cfg = load_profile("smoke")
    setup = ev.evaluation_setup(with_overrides(cfg, {"evaluate.sweep.datasets": []}))
    results = {"turin-sim-ekinox": _table_result("turin-sim-ekinox"),
               "turin-sim-mpu6000": _table_result("turin-sim-mpu6000")}
    reductions = {n: ev.reduction_table(r) for n, r in results.items()}
    path = ev.write_evaluation_record(tmp_path, setup, results, reductions, {"tables_x_s": 1.0})
    rec = json.loads(path.read_text())
    assert path.name == ev.RECORD_FILE and rec["meta"]["profile"] == "smoke" and rec["profile"] == "smoke"
    assert rec["outage_windows"] == [list(w) for w in setup.windows] and rec["evaluate"]["seeds"] == [0]
    assert set(rec["tables"]) == set(rec["reduction_vs_ins_pct"]) == {"dataset", "field"}
    bgfn1 = [r for r in rec["reduction_vs_ins_pct"]["dataset"] if r["outage"] == 1 and r["method"] == "BGFN"][0]
    assert bgfn1["east_%"] == pytest.approx(80.0)
    assert rec["paper_claims"] == paper.claims()["bgfn_reduction_vs_ins_pct"]
    assert "sweep" not in rec and rec["timings_s"] == {"tables_x_s": 1.0}
    assert report.outage_datasets(rec) == {"dataset": "turin-sim-ekinox", "field": "turin-sim-mpu6000",
                                           "real": "rtklib-drive0708"}

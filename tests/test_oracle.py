"""The oracle rows (bgfn.studies.outage_sweep.oracle) and the true increments they are built from (bgfn.studies.outage_sweep.increments).

A small synthetic drive (demo trajectory, Ekinox-grade IMU with fixed biases, 5 Hz GNSS, lever arm) keeps every
test fast; its standalone INS drifts several metres in a 30 s outage.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from bgfn import evaluate as ev, studies
from bgfn.profile_schema import load_profile
from bgfn.data import Drive
from bgfn.errors import DataError
from bgfn.studies.outage_sweep import oracle as orc
from bgfn.nav import sim
from bgfn.profile_schema import ProfileError, validate
from bgfn.report import sweep_words
from synthetic_drive import LEVER, demo_drive

NAV = {"init": {"position_std_m": 1.0, "height_std_m": 2.0, "velocity_std_mps": 0.1, "level_std_deg": 0.2,
                "azimuth_std_deg": 1.0}}
#: (outage, start, duration): three 30 s windows of the synthetic drive.
WINDOWS = [("1", 40.0, 30.0), ("2", 75.0, 30.0), ("3", 110.0, 30.0)]


def _drive(seed=3) -> Drive:
    return demo_drive("synthetic", 150.0, 5.0, seed)


@pytest.fixture(scope="module")
def drive():
    return _drive()


@pytest.fixture(scope="module")
def ctx(drive):
    return ev.navigation_context(drive, NAV, [s for _, s, _ in WINDOWS])


def _oracle(sigmas, seeds=(0,), durations=(30.0,)):
    return {"sigmas_m": list(sigmas), "seeds": list(seeds), "durations_s": list(durations)}


def _medians(runs: pd.DataFrame) -> pd.Series:
    o = runs[runs["method"] == orc.ORACLE_METHOD]
    return o.groupby("sigma_m")["max_h_m"].median()


# ----------------------------------------------------------------------------------------------- true increments
def test_true_increments_are_the_noise_free_fix_increments_of_the_antenna(drive):
    # noise-free fixes at the lever arm: their consecutive differences are delta_p_gps (Eq. eq8-1)
    fixes = sim.gnss_from_trajectory(drive.reference, 5.0, 0.0, 0.0, LEVER, seed=0)
    from bgfn.learning.targets import gnss_increments

    inc = gnss_increments(fixes)
    truth = studies.outage_sweep.AntennaTruth(drive.reference, LEVER, "synthetic")
    d = truth.increments(inc["t_from"], inc["t_to"])
    assert np.abs(d - inc[["dn", "de"]].to_numpy()).max() < 1e-6
    # the lever arm matters in turns: the IMU's own increments differ from the antenna's
    imu = studies.outage_sweep.AntennaTruth(drive.reference, [0.0, 0.0, 0.0]).increments(inc["t_from"], inc["t_to"])
    assert np.abs(imu - d).max() > 1e-3
    with pytest.raises(DataError):
        truth.increments([drive.reference["time"].iloc[-1]], [drive.reference["time"].iloc[-1] + 1.0])


def test_exact_oracle_sums_to_the_antenna_displacement_and_has_no_increment_error(ctx):
    truth = studies.outage_sweep.AntennaTruth.of(ctx)
    noise = orc.oracle_noise("synthetic", 0, 2000)
    t0 = float(ctx.drive.reference["time"].iloc[0])
    run = ev.run_outages(ctx, [(40.0, 30.0)], orc.OracleIncrements(truth, ctx.gnss_interval_s, 0.0, noise, t0),
                         "oracle", None)[0]
    # Eq. (pred-gps): the running sum of exact increments is the antenna's displacement since the start
    last = run.pseudo.iloc[-1]
    moved = truth.increments([40.0], [last["time"]])[0]
    assert np.hypot(last["cum_dn"] - moved[0], last["cum_de"] - moved[1]) < 0.01
    assert len(run.increments) == 150 and len(run.pseudo) == 30       # 5 Hz increments fused at 1 Hz
    assert studies.outage_sweep.increment_rmse(run, truth, ctx.gnss_interval_s) == pytest.approx(0.0, abs=1e-9)


def test_increment_rmse_of_white_noise_is_its_sigma_per_axis(ctx):
    truth = studies.outage_sweep.AntennaTruth.of(ctx)
    t0 = float(ctx.drive.reference["time"].iloc[0])
    runs = ev.run_outages(ctx, [(s, d) for _, s, d in WINDOWS],
                          orc.OracleIncrements(truth, ctx.gnss_interval_s, 0.5, orc.oracle_noise("x", 1, 2000), t0),
                          "oracle", 1)
    e = np.concatenate([studies.outage_sweep.increment_errors(r, truth, ctx.gnss_interval_s) for r in runs])     # 450 x 2 draws
    assert np.sqrt(np.mean(e ** 2)) == pytest.approx(0.5, rel=0.1)
    assert abs(e.mean()) < 0.1
    # a prefix keeps only the increments that end inside it
    assert len(studies.outage_sweep.increment_errors(runs[0], truth, ctx.gnss_interval_s, 10.0)) == 50
    ins = ev.run_outages(ctx, [(40.0, 30.0)], None)[0]
    assert np.isnan(studies.outage_sweep.increment_rmse(ins, truth, ctx.gnss_interval_s))


# ----------------------------------------------------------------------------------------------- oracle runs
def test_exact_increments_keep_the_aided_error_far_below_the_ins(ctx):
    runs = orc.oracle_runs(ctx, WINDOWS, _oracle([0.0]))
    ins = runs[runs["method"] == "INS"].set_index("start_s")["max_h_m"]
    exact = runs[runs["method"] == orc.ORACLE_METHOD].set_index("start_s")["max_h_m"]
    assert (ins > 3.0).all()                     # the biased IMU drifts metres in 30 s
    # the error stays at the start error (the GPS-aided filter's, ~ the 1 m GNSS noise): no drift at all
    assert (exact < 1.5).all() and (exact < 0.25 * ins).all()
    assert runs.loc[runs["method"] == orc.ORACLE_METHOD, "seed"].isna().all()    # sigma = 0 runs once


def test_aided_error_grows_with_sigma(ctx):
    runs = orc.oracle_runs(ctx, WINDOWS, _oracle([0.0, 0.3, 3.0], seeds=[0, 1, 2]))
    med = _medians(runs)
    assert list(med.index) == [0.0, 0.3, 3.0]
    # summed increments random-walk: 150 increments of std sigma are off by ~12 sigma per axis after 30 s
    assert med[0.0] < med[0.3] < med[3.0]
    assert med[3.0] > 3.0 * med[0.3] and med[0.3] > 1.5 * med[0.0]
    assert len(runs[(runs["method"] == orc.ORACLE_METHOD) & (runs["sigma_m"] == 3.0)]) == 3 * len(WINDOWS)


def test_same_seed_same_rows_other_seed_other_rows(ctx):
    a = orc.oracle_runs(ctx, WINDOWS[:2], _oracle([0.0, 1.0], seeds=[4]))
    b = orc.oracle_runs(ctx, WINDOWS[:2], _oracle([0.0, 1.0], seeds=[4]))
    c = orc.oracle_runs(ctx, WINDOWS[:2], _oracle([0.0, 1.0], seeds=[5]))
    pd.testing.assert_frame_equal(a, b)
    noisy = a["sigma_m"] == 1.0
    assert not np.allclose(a.loc[noisy, "max_h_m"], c.loc[noisy, "max_h_m"])
    # a run's noise depends on the intervals it crosses, not on the other windows computed with it
    alone = orc.oracle_runs(ctx, WINDOWS[1:2], _oracle([1.0], seeds=[4]))
    both = a[(a["start_s"] == WINDOWS[1][1]) & noisy]
    assert alone.loc[alone["sigma_m"] == 1.0, "max_h_m"].to_numpy() == pytest.approx(both["max_h_m"].to_numpy())


# ----------------------------------------------------------------------------------------------- break-even
def test_crossing_sigma_interpolates_a_hand_made_curve():
    sig, err = [0.5, 0.0, 0.2, 0.1], [10.0, 1.0, 4.0, 2.0]          # unsorted on purpose
    assert orc.crossing_sigma(sig, err, 3.0) == (pytest.approx(0.15), orc.CROSSED)
    assert orc.crossing_sigma(sig, err, 7.0) == (pytest.approx(0.35), orc.CROSSED)
    assert orc.crossing_sigma(sig, err, 2.0) == (pytest.approx(0.1), orc.CROSSED)
    s, status = orc.crossing_sigma(sig, err, 0.5)
    assert np.isnan(s) and status == orc.NEVER_BELOW
    s, status = orc.crossing_sigma(sig, err, 20.0)
    assert np.isnan(s) and status == orc.BEYOND_GRID


def _hand_table():
    sig = [0.0, 0.1, 0.2, 0.5]
    med = [1.0, 2.0, 4.0, 10.0]
    rows = [{"dataset": "d", "test": "field", "outage": "sweep", "duration_s": 30.0, "method": "INS",
             "sigma_m": np.nan, "increment_s": 1.0, "n": 4, "n_starts": 4, "median_m": 3.0, "ci_lo_m": 2.0,
             "ci_hi_m": 4.0}]
    rows += [{"dataset": "d", "test": "field", "outage": "sweep", "duration_s": 30.0, "method": orc.ORACLE_METHOD,
              "sigma_m": s, "increment_s": 1.0, "n": 4, "n_starts": 4, "median_m": m, "ci_lo_m": m * 0.8,
              "ci_hi_m": m * 1.2} for s, m in zip(sig, med)]
    levels = pd.DataFrame({"dataset": "d", "outage": "sweep", "duration_s": 30.0,
                           "method": ["INS", "INS+NHC", "BGFN", "MLP", "GPS"], "n": 4,
                           "median_m": [3.0, 1.5, 7.0, 50.0, 0.5],
                           "increment_rmse_m": [np.nan, np.nan, 0.35, 2.0, np.nan]})
    return pd.DataFrame(rows, columns=list(orc.ORACLE_COLUMNS)), levels


def test_breakeven_table_against_ins_and_an_extra_baseline():
    table, levels = _hand_table()
    be = orc.breakeven_table(table, levels)
    assert list(be.columns) == list(orc.BREAKEVEN_COLUMNS)
    assert sorted(set(be["baseline"])) == ["INS", "INS+NHC"] and set(be["method"]) == {"BGFN", "MLP"}
    ins = be[be["baseline"] == "INS"].set_index("method")
    assert ins.loc["BGFN", "breakeven_sigma_m"] == pytest.approx(0.15)
    assert ins.loc["BGFN", "rmse_to_breakeven"] == pytest.approx(0.35 / 0.15)
    assert ins.loc["BGFN", "equivalent_sigma_m"] == pytest.approx(0.35)     # 7 m is the oracle's at 0.35 m
    assert ins.loc["BGFN", "oracle_at_rmse_m"] == pytest.approx(7.0)        # white errors of 0.35 m: 7 m
    assert np.isnan(ins.loc["MLP", "oracle_at_rmse_m"])                     # 2 m: beyond the grid
    assert np.isnan(ins.loc["MLP", "equivalent_sigma_m"]) and ins.loc["MLP", "equivalent_crossing"] == orc.BEYOND_GRID
    nhc = be[be["baseline"] == "INS+NHC"]
    assert nhc["breakeven_sigma_m"].iloc[0] == pytest.approx(0.05)
    lines = sweep_words.describe_oracle(be)
    assert len(lines) == 2 and lines[0].startswith("d (field test), sweep, 30 s outages: ")
    assert "below 0.15 m per axis and 1 s increment (break-even)" in lines[0]
    assert "BGFN 0.35 m (2.3 times the break-even" in lines[0]
    assert ("MLP 2.0 m (13.3 times the break-even; its aided error (50.0 m) exceeds the oracle's at every "
            "sigma") in lines[0]
    # exact increments worse than the baseline: said so, no break-even
    never = orc.breakeven_table(table, levels.assign(median_m=[3.0, 0.5, 7.0, 50.0, 0.5]))
    row = never[never["baseline"] == "INS+NHC"].iloc[0]
    assert row["crossing"] == orc.NEVER_BELOW and np.isnan(row["breakeven_sigma_m"])
    assert "even the exact increments do not beat INS+NHC" in sweep_words.describe_oracle(never)[1]


def test_oracle_interval_table_layout():
    table, _ = _hand_table()
    wide = orc.oracle_interval_table(table)
    assert list(wide.columns) == ["INS", "sigma 0 m", "sigma 0.1 m", "sigma 0.2 m", "sigma 0.5 m"]
    assert wide.loc[("d", "sweep", 30.0), "sigma 0.1 m"] == "2.0 [1.6, 2.4]"


def test_is_network():
    assert orc.is_network("BGFN") and orc.is_network("BGFN+NHC") and orc.is_network("AT-LSTM")
    assert not orc.is_network("INS") and not orc.is_network("INS+NHC") and not orc.is_network("GPS")


# ----------------------------------------------------------------------------------------------- notebook 06
class _Speed:
    """Fake network: dead reckoning at a fixed speed along the input yaw (a poor increment predictor)."""

    options = {"window": 20, "alignment": "ending", "yaw_encoding": "unwrap", "extra_channels": [],
               "target_frame": "ned"}

    def predict_windows(self, ws):
        return 8.0 * 0.2 * np.column_stack([np.cos(ws.yaw_ref), np.sin(ws.yaw_ref)])


def test_run_oracle_writes_its_tables_and_figure(drive, ctx, tmp_path):
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    from bgfn.config import SHARED_TABLES

    windows = [(40.0, 30.0)]
    ecfg = ev.evaluate_config({"sweep": {"n_starts": 3, "durations_s": [20.0], "warmup_s": 30.0, "n_boot": 50},
                               "oracle": _oracle([0.0, 0.5, 2.0], durations=[20.0])}, {"seeds": [0]})
    cfg = {"nav": NAV, "train": {"window": 20}, "evaluate": {}}
    setup = ev.EvaluationSetup("t", "", ecfg, ["synthetic"], [], [], [], windows)
    runs = ev.run_outages(ctx, windows, None, "INS") + ev.run_outages(ctx, windows, _Speed(), "BGFN", 0)
    per_seed = pd.DataFrame([{"outage": 1, "start_s": r.start, "method": r.method, "seed": r.seed,
                              **ev.window_metrics(r.errors, r.start, r.duration)} for r in runs])
    res = ev.TableResult("synthetic", "synthetic", per_seed, per_seed, runs, drive=drive)
    plan = studies.outage_sweep.sweep_plan(drive, ecfg["sweep"], 20)
    sweep = pd.DataFrame({"dataset": "synthetic", "start_s": plan["start_s"], "duration_s": 20.0,
                          "method": "INS+NHC", "seed": 0, "fold": 0, "max_h_m": 0.05, "increment_rmse_m": np.nan})
    lines = []
    o = studies.outage_sweep.run_oracle(cfg, "t", setup, tmp_path, {"synthetic": res}, sweep, report=lines.append)
    assert lines[0].startswith("synthetic: ") and list(o.timings) == ["oracle_synthetic_s"]
    for key in ("oracle", "oracle_breakeven", "oracle_runs"):
        assert (tmp_path / "tables" / SHARED_TABLES[key]).exists()
    assert (tmp_path / "figures" / orc.FIGURE_FILE.format(dataset="synthetic")).exists()
    back = pd.read_csv(tmp_path / "tables" / SHARED_TABLES["oracle"], dtype={"outage": str})
    assert set(back["outage"]) == {"1", orc.SWEEP_OUTAGE} and list(back.columns) == list(orc.ORACLE_COLUMNS)
    sw = back[back["outage"] == orc.SWEEP_OUTAGE]
    assert set(sw["n_starts"]) == {3} and set(sw["duration_s"]) == {20.0}
    # the paper outage: the network's increment error measured in it; INS+NHC of the sweep is a baseline there
    bgfn = o.breakeven[(o.breakeven["outage"] == "1") & (o.breakeven["method"] == "BGFN")].iloc[0]
    assert bgfn["increment_rmse_m"] > 0.1 and bgfn["baseline"] == "INS"
    assert set(o.breakeven.loc[o.breakeven["outage"] == orc.SWEEP_OUTAGE, "baseline"]) == {"INS", "INS+NHC"}
    assert any("INS+NHC" in s for s in sweep_words.oracle_lines(o))
    labels = [t.get_text() for t in o.figures["synthetic"].axes[0].get_legend().get_texts()]
    assert "INS+NHC" in labels and "INS" in labels
    plt.close("all")
    # an empty grid: no oracle, nothing run
    ecfg0 = {**ecfg, "oracle": _oracle([])}
    empty = studies.outage_sweep.run_oracle(cfg, "t", ev.EvaluationSetup("t", "", ecfg0, ["synthetic"], [], [], [], windows))
    assert empty.table.empty and sweep_words.oracle_lines(empty) == []


def test_a_drive_without_sweep_starts_is_a_record_and_report_words_it(drive):
    """A sweep whose warm-up outlasts the drive: the oracle keeps the paper's outages and says why, as a
    record (the plan's refusal); the sentence is made in report."""
    ecfg = ev.evaluate_config({"sweep": {"n_starts": 3, "durations_s": [20.0], "warmup_s": 1.0e5},
                               "oracle": _oracle([0.0, 0.5], durations=[20.0])}, {"seeds": [0]})
    cfg = {"nav": NAV, "train": {"window": 20}, "evaluate": {}}
    wins, no = orc.oracle_windows(cfg, drive, ecfg, [(40.0, 30.0)])
    assert wins == [("1", 40.0, 30.0)] and isinstance(no, orc.NoSweepStarts) and no.dataset == drive.name
    assert sweep_words.no_sweep_starts_words(no) == (f"{drive.name}: no sweep starts ({no.expected}; found "
                                                     f"{no.found}): the paper's outages only")
    ok = ev.evaluate_config({"sweep": {"n_starts": 3, "durations_s": [20.0], "warmup_s": 30.0},
                             "oracle": _oracle([0.0, 0.5], durations=[20.0])}, {"seeds": [0]})
    wins, no = orc.oracle_windows(cfg, drive, ok, [(40.0, 30.0)])
    assert no is None and [w[0] for w in wins] == ["1"] + [orc.SWEEP_OUTAGE] * 3

def test_profiles_define_the_oracle_and_its_durations_fit_the_sweep():
    for name in ("smoke", "quick", "paper"):
        cfg = load_profile(name)
        oc = ev.evaluate_config(cfg["evaluate"], cfg["train"])["oracle"]
        assert oc["sigmas_m"][0] == 0.0 and max(oc["durations_s"]) <= max(cfg["evaluate"]["sweep"]["durations_s"])
    cfg = load_profile("smoke")
    cfg["evaluate"]["oracle"]["durations_s"] = [1000.0]
    with pytest.raises(ProfileError, match="evaluate.oracle.durations_s"):
        validate(cfg)
    del cfg["evaluate"]["oracle"]["durations_s"]              # the default durations must fit too
    cfg["evaluate"]["sweep"]["durations_s"] = [10.0]
    with pytest.raises(ProfileError, match="evaluate.oracle.durations_s"):
        validate(cfg)
    with pytest.raises(DataError, match="durations_s"):
        orc.oracle_windows(cfg, None, ev.evaluate_config(cfg["evaluate"], cfg["train"]), [])


def test_sweep_rows_carry_each_networks_increment_error(drive, monkeypatch, tmp_path):
    # the sweep with stand-in networks (no training): exact increments score 0, white noise its sigma
    from bgfn import config, train
    from bgfn.studies.outage_sweep import sweep as sweep_module

    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path)
    truth = studies.outage_sweep.AntennaTruth(drive.reference, LEVER)
    t0 = float(drive.reference["time"].iloc[0])
    noise = orc.oracle_noise("synthetic", 0, 1000)
    stand_in = {"mlp": orc.OracleIncrements(truth, 0.2, 0.0, noise, t0),
                "bgfn": orc.OracleIncrements(truth, 0.2, 0.5, noise, t0)}

    def fake_train(run):
        return {"method": run.method, "seed": run.seed, "fold": run.extra_card["fold"], "epochs_run": 1,
                "best_val_loss": 1.0, "best_epoch": 1, "val_rmse_m": 1.0}

    monkeypatch.setattr(train, "train_run", fake_train)
    monkeypatch.setattr(sweep_module, "load_model", lambda path: stand_in[path.name.split("_seed")[0]])
    cfg = load_profile("smoke")
    cfg = {**cfg, "nav": NAV, "train": {**cfg["train"], "window": 20, "margin_s": 5.0}}
    ecfg = ev.evaluate_config({"methods": ["bgfn", "mlp"], "sweep": {
        "n_starts": 2, "folds": 2, "durations_s": [10.0, 30.0], "warmup_s": 30.0, "seeds": [0]},
        "oracle": _oracle([0.0], durations=[30.0])}, cfg["train"])
    rows, _ = studies.outage_sweep.run_sweep(cfg, "t", "synthetic", drive=drive, ecfg=ecfg)
    assert list(rows.columns) == list(ev.SWEEP_COLUMNS)
    inc = rows.groupby(["method", "duration_s"])["increment_rmse_m"]
    assert rows.loc[rows["method"].isin(["INS", "GPS"]), "increment_rmse_m"].isna().all()
    assert inc.max()["MLP"].max() == pytest.approx(0.0, abs=1e-9)
    assert inc.median()[("BGFN", 30.0)] == pytest.approx(0.5, rel=0.2)


def test_increments_past_the_reference_are_left_out():
    """A window at a drive's end: its last GNSS epoch may lie past the last reference row; it is not scored."""
    from types import SimpleNamespace

    from bgfn.studies.outage_sweep.increments import AntennaTruth, increment_errors

    t = np.arange(0.0, 10.001, 0.01)
    ref = pd.DataFrame({"time": t, "lat": 0.7 + 1e-7 * t, "lon": 0.1 + 0 * t, "h": 100.0 + 0 * t,
                        "roll": 0 * t, "pitch": 0 * t, "yaw": 0 * t})
    truth = AntennaTruth(ref, [0.0, 0.0, 0.0], "sim")
    run = SimpleNamespace(start=7.0, increments=pd.DataFrame({"time": [8.0, 9.0, 10.0, 10.5], "dn": 0.0, "de": 0.0}))
    e = increment_errors(run, truth, 1.0)
    assert e.shape == (3, 2)                                   # the increment ending at 10.5 s is left out
    assert np.allclose(e[:, 0], -1e-7 * 6.37e6, rtol=0.01)     # north: minus the true 0.64 m per second

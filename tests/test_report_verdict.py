"""The verdict (results page, first section): its table and the six answers from hand-made tables."""

import numpy as np
import pandas as pd
import pytest

from bgfn.report.odometer_verdict import ORACLE_ODO_ROW, OdometerInputs
from bgfn.report.verdict import (ORACLE_ROW, VerdictInputs, answer_accuracy, answer_free_aids, answer_protocol,
                                 answer_speed, headline, verdict_sentences, verdict_table)


def _seeds():
    rows = []
    for method, vals in {"INS": [10.0], "INS+NHC": [4.0], "BGFN": [30.0, 50.0, 40.0], "BGFN+NHC": [20.0, 22.0, 24.0],
                         "MLP": [60.0, 60.0, 60.0]}.items():
        for outage in (1, 2):
            for seed, v in enumerate(vals):
                rows.append({"outage": outage, "method": method, "seed": seed, "max_h_m": v * outage,
                             "dataset": "d"})
    return pd.DataFrame(rows)


def _inputs(**kw):
    summary = pd.DataFrame([{"dataset": "d", "duration_s": du, "method": m, "median_m": v * du / 30}
                            for du in (30.0, 60.0) for m, v in
                            {"INS": 19.0, "INS+NHC": 5.0, "BGFN": 85.0, "BGFN+NHC": 76.0}.items()])
    pairs = pd.DataFrame([{"dataset": "d", "duration_s": 30.0, "method": "BGFN", "baseline": "INS", "p_value": 1e-9},
                          {"dataset": "d", "duration_s": 30.0, "method": "BGFN+NHC", "baseline": "INS+NHC",
                           "p_value": 2e-10}])
    be = pd.DataFrame([{"dataset": "d", "test": "field", "outage": "sweep", "duration_s": 30.0, "increment_s": 1.0,
                        "baseline": "INS", "baseline_m": 19.0, "breakeven_sigma_m": 1.9, "crossing": "crossed",
                        "method": "BGFN", "method_m": 85.0, "increment_rmse_m": 2.5, "rmse_to_breakeven": 1.3,
                        "oracle_at_rmse_m": 24.0, "equivalent_sigma_m": 7.0, "equivalent_crossing": "crossed"}])
    variants = pd.DataFrame([
        {"dataset": "d", "outage": o, "variant": v, "inputs": i, "protocol": p, "method": "BGFN", "max_h_m": x * o,
         "n_runs": 1}
        for v, i, p, x in (("main", "eq21", "honest", 40.0), ("velocity", "eq21+v_along+v_cross", "honest", 8.0),
                           ("leaky", "eq21", "leaky", 2.0))
        for o in (1, 2)])
    base = dict(dataset="d", test="field", seeds=_seeds(), sweep_summary=summary, sweep_pairs=pairs, breakeven=be,
                variants=variants, ins_tuning=None)
    base.update(kw)
    return VerdictInputs(**base)


def test_table_takes_medians_p_values_oracle_and_variants():
    inp = _inputs()
    t = verdict_table(inp).set_index("row")
    assert t.loc["BGFN", "outage 1"] == 40.0 and t.loc["BGFN", "outage 2"] == 80.0       # median of 3 seeds
    assert t.loc["INS", "sweep 60 s"] == pytest.approx(38.0)
    assert t.loc["INS", "p 30 s"] == pytest.approx(1e-9)                               # BGFN against INS
    assert np.isnan(t.loc["BGFN", "p 30 s"])                                           # not against itself
    assert t.loc["BGFN+NHC", "p 30 s"] == pytest.approx(2e-10)                         # BGFN+NHC against INS+NHC
    assert np.isnan(t.loc["INS+NHC", "p 30 s"])                                        # BGFN vs INS+NHC not run
    assert t.loc[ORACLE_ROW, "sweep 30 s"] == 24.0 and np.isnan(t.loc[ORACLE_ROW, "outage 1"])
    assert t.loc["BGFN (velocity)", "outage 2"] == 16.0 and t.loc["BGFN (velocity)", "runs"] == 1
    assert np.isnan(t.loc["AT-LSTM", "outage 1"])                                      # not run: empty, not 0
    assert list(t.index[:3]) == ["INS", "INS+NHC", ORACLE_ROW]
    assert t.loc["BGFN", "inputs"] == "Eq. (eq21)" and t.loc["INS", "inputs"] == "-"
    # a profile whose main networks take other inputs (quick-heading) is labelled with them
    heading = inp.variants.assign(inputs=lambda v: v["inputs"].where(v["variant"] != "main", "eq21+v_along"))
    assert verdict_table(_inputs(variants=heading)).set_index("row").loc["MLP", "inputs"] == "eq21+v_along"


def test_answers_say_the_measured_numbers():
    inp = _inputs()
    t = verdict_table(inp)
    acc = answer_accuracy(inp)
    assert "below 1.9 m per increment of 1 s" in acc and "2.5 m (misses the bar)" in acc
    assert "white noise of 7.0 m" in acc
    free = answer_free_aids(t)
    assert "5.0 m for INS+NHC" in free and "does not add" in free and "p 2e-10" in free
    speed = answer_speed(t)
    assert "averages 60.0 m" in speed and "velocity 12.0 m" in speed
    prot = answer_protocol(t, {"bgfn_reduction_vs_ins_pct": {"a": {"east": 79.7}, "b": {"north": 90.0}}})
    assert "leaky: 3.0 m, 80 % below INS" in prot and "79.7-90 %" in prot            # (15 - 3) / 15
    assert "main), honest: 60.0 m, 4.0 times INS" in prot
    assert headline(inp, t).endswith("INS with non-holonomic constraints and zero-velocity updates 5.0 m.")
    # a walker's constraint row is its ZUPT alone: the headline says so (the platform from kf_baseline.json)
    walker = _inputs(platform="walker")
    assert headline(walker, verdict_table(walker)).endswith(
        "INS with zero-velocity updates (no NHC: a walker steps sideways) 5.0 m.")


def test_a_comparison_of_one_seed_and_two_windows_says_so():
    # the case: BGFN below INS from one seed in the profile's two outages, no sweep
    one = _seeds()
    one = one[one["seed"] == 0]
    inp = _inputs(seeds=one, sweep_summary=None, sweep_pairs=None)
    t = verdict_table(inp)
    head = headline(inp, t)
    assert "mean max error in the paper's two outages (BGFN: one seed, 2 windows: no statistics): BGFN 45.0 m" in head
    assert "(one seed, 2 windows: no statistics)." in answer_free_aids(t)
    assert "(INS 15.0 m; each from one seed, 2 windows: no statistics)." in answer_protocol(t)
    from bgfn.report.verdict_page import short_answers
    assert "in the paper's two outages (one seed, 2 windows: no statistics) INS+NHC" in short_answers(inp, t)["free_aids"]
    # three seeds in two windows: still too few windows
    three = _inputs(sweep_summary=None, sweep_pairs=None)
    assert "(BGFN: 3 seeds, 2 windows: no statistics)" in headline(three, verdict_table(three))
    # the sweep: 20 starts of one seed each (n / n_starts), then 20 starts of 3 seeds (nothing to say)
    summary = _inputs().sweep_summary.assign(n=20, n_starts=20)
    sweep = _inputs(sweep_summary=summary)
    assert ("median max error over the 30 s sweep (BGFN: one seed, 20 windows: no spread between training seeds): "
            in headline(sweep, verdict_table(sweep)))
    sweep = _inputs(sweep_summary=summary.assign(n=60))
    assert "over the 30 s sweep: BGFN" in headline(sweep, verdict_table(sweep))


def test_the_sample_clause_by_hand():
    from bgfn.report.sample_words import sample_clause

    assert sample_clause(1, 2) == "one seed, 2 windows: no statistics"
    assert sample_clause(3, 1) == "3 seeds, one window: no statistics"
    assert sample_clause(5, 4) == "5 seeds, 4 windows: no statistics"              # 4 windows: p >= 0.125
    assert sample_clause(1, 5) == "one seed, 5 windows: no spread between training seeds"
    assert sample_clause(2, 5) == ""


def test_a_walkers_rows_are_labelled_with_the_zupt_that_ran():
    from bgfn.report.aid_words import aid_label
    from bgfn.report.verdict import format_table
    from bgfn.report.verdict_page import short_answers, short_table

    assert aid_label("INS+NHC", "walker") == "INS+ZUPT" and aid_label("BGFN+NHC", "walker") == "BGFN+ZUPT"
    assert aid_label("INS+NHC", "car") == "INS+NHC" and aid_label("INS+NHC+HOLD", "walker") == "INS+ZUPT+HOLD"
    assert aid_label("INS+NHC", "other") == "INS+no aid" and aid_label("INS", "walker") == "INS"
    assert aid_label("the `+NHC` rows", "walker") == "the `+NHC` rows"        # a bare suffix is no row's label
    walker = _inputs(platform="walker")
    t = verdict_table(walker)
    shown = list(format_table(t, walker.platform).data["row"])
    assert "INS+ZUPT" in shown and "BGFN+ZUPT" in shown and not any("NHC" in r for r in shown)
    assert list(short_table(t, "walker").data["row"]) == ["INS", "INS+ZUPT", "MLP", "AT-LSTM", "Transformer", "BGFN",
                                                          "BGFN+ZUPT"]
    text = " ".join([headline(walker, t), *verdict_sentences(walker, t), *short_answers(walker, t).values()])
    assert "INS+ZUPT" in text and "BGFN+ZUPT" in text and "+NHC" not in text
    assert "fused with ZUPT it is worse than ZUPT alone" in verdict_sentences(walker, t)[1]
    # a car's page as it was: its labels byte for byte
    car = _inputs()
    assert list(format_table(verdict_table(car)).data["row"]) == list(verdict_table(car)["row"])
    assert "BGFN+NHC against INS+NHC" in verdict_sentences(car, verdict_table(car))[1]


def test_the_platform_comes_from_notebook_02s_record(tmp_path):
    import json

    from bgfn.report.verdict import _platform
    (tmp_path / "kf_baseline.json").write_text(json.dumps(
        {"datasets": {"/data/my walk": {"constraints": {"platform": "walker"}}, "car": {"constraints": None}}}))
    assert _platform(tmp_path, "/data/my walk") == "walker" and _platform(tmp_path, "car") == "car"
    assert _platform(tmp_path / "nowhere", "x") == "car"


def test_missing_tables_say_not_measured():
    inp = _inputs(breakeven=None, variants=None, sweep_summary=None, sweep_pairs=None, ins_tuning=None)
    t = verdict_table(inp)
    lines = verdict_sentences(inp, t)
    assert lines[0].endswith("oracle has not run for this drive.")
    assert "Not measured" in lines[2] and "Not measured" in lines[3] and "Not measured" in lines[4]
    assert "paper's two outages" in lines[1]                                           # falls back to them


def test_speed_answer_says_which_networks_learned_with_and_without_velocity():
    main = pd.DataFrame({"dataset": "d", "method": ["bgfn", "mlp", "at_lstm", "bgfn"], "seed": [0, 0, 0, 1],
                         "best_epoch": [0, 3, 0, 1], "val_rmse_m": [4.0, 3.0, 5.0, 4.5],
                         "val_rmse_zero_m": 5.5})
    variants = pd.DataFrame({"dataset": "d", "variant": ["velocity", "velocity", "leaky", "velocity-leaky"],
                             "inputs": ["eq21+v_along+v_cross", "eq21+v_along+v_cross", "eq21", "eq21+v_along"],
                             "protocol": ["honest", "honest", "leaky", "leaky"], "method": ["bgfn", "mlp"] * 2,
                             "best_epoch": [4, 2, 0, 0], "val_rmse_m": [0.8, 1.0, 4.0, 0.7]})
    inp = _inputs(training=main, training_variants=variants)
    speed = answer_speed(verdict_table(inp), inp)
    # 2 of the 4 main runs have a best epoch >= 1; the leaky rows are not the velocity reading's
    assert ("2 of 4 networks with Eq. (eq21)'s inputs improved on their initial weights (median RMSE per "
            "increment 4.25 m; predicting zero: 5.50 m); given the INS velocity 2 of 2 did (median 0.90 m).") in speed
    assert verdict_sentences(inp, verdict_table(inp))[2] == speed
    assert "initial weights" not in answer_speed(verdict_table(_inputs()), _inputs())      # no training tables
    assert "training loss" not in speed                                                  # no train_loss_min column
    # why the two that never improved did not: they fitted their training windows (median of 0.3 and 0.5) ...
    fitted = _inputs(training=main.assign(train_loss_min=[0.3, 0.2, 0.5, 0.9]), training_variants=variants)
    assert answer_speed(verdict_table(fitted), fitted).endswith(
        " The 2 that never improved did fit their training windows (median lowest training loss 0.40; predicting "
        "the training mean: about 1): what they learned there does not carry over to the validation block.")
    # trained again on all windows (bgfn.train.recheck): how many of the capped runs then improved
    recheck = pd.DataFrame({"dataset": "d", "method": ["bgfn", "at_lstm"], "seed": 0, "n_train": 1000,
                            "best_epoch": 0, "n_train_all": 4187, "best_epoch_all": [0, 3]})
    again = _inputs(training=main.assign(train_loss_min=[0.3, 0.2, 0.5, 0.9]), training_variants=variants,
                    training_all_windows=recheck)
    assert answer_speed(verdict_table(again), again).endswith(
        "does not carry over to the validation block. The 2 of them whose training windows had been capped were "
        "trained again on all of them (1000 -> 4187): 1 then improved.")
    # ... or they did not fit them either
    unfit = _inputs(training=main.assign(train_loss_min=[0.95, 0.2, 1.1, 0.9]), training_variants=variants)
    assert answer_speed(verdict_table(unfit), unfit).endswith(
        " The 2 that never improved did not fit their training windows either (median lowest training loss 1.02; "
        "predicting the training mean: about 1).")


def _odometer(twin_offset: float = 0.0, coverage: float = 0.95):
    """Hand-made odometer tables of dataset d: 10 starts x 2 durations; INS+NHC 10 m per 30 s, RIDGE-ODO 8 m,
    BGFN-ODO 6 m (+ a start-dependent wiggle), its twin BGFN-ODO + ``twin_offset``; the oracle at 0.1 / 1 m/s."""
    rows, starts = [], np.arange(10) * 100.0
    for du in (30.0, 60.0):
        k = du / 30.0
        for i, s in enumerate(starts):
            wiggle = 0.1 * ((i * 7) % 5)
            for method, v in (("INS+NHC", 10.0), ("INS+NHC+HOLD", 12.0), ("RIDGE-ODO", 8.0),
                              ("BGFN-ODO", 6.0 + wiggle), ("Transformer-ODO", 6.0 + wiggle + twin_offset)):
                rows.append({"dataset": "d", "start_s": s, "duration_s": du, "method": method, "sigma_mps": np.nan,
                             "seed": 0, "max_h_m": v * k + 0.01 * i})
    rows = pd.DataFrame(rows)
    summary = []
    for (du, m), g in rows.groupby(["duration_s", "method"]):
        nhc = rows[(rows["method"] == "INS+NHC") & (rows["duration_s"] == du)]["max_h_m"].to_numpy()
        summary.append({"dataset": "d", "duration_s": du, "method": m, "sigma_mps": np.nan,
                        "max_h_m": g["max_h_m"].median(), "ratio_to_nhc": float(np.median(g["max_h_m"] / nhc)),
                        "speed_rmse_mps": 0.5 if m.endswith("-ODO") else np.nan,
                        "coverage_2sigma": coverage if m.endswith("-ODO") else np.nan,
                        "p_vs_nhc": 0.002 if m != "INS+NHC" else np.nan})
    for du in (30.0, 60.0):
        for sigma, v in ((0.1, 2.0), (1.0, 20.0)):
            summary.append({"dataset": "d", "duration_s": du, "method": "ORACLE-SPEED", "sigma_mps": sigma,
                            "max_h_m": v * du / 30.0, "ratio_to_nhc": np.nan, "speed_rmse_mps": sigma,
                            "coverage_2sigma": 0.95, "p_vs_nhc": 0.001})
    energy = pd.DataFrame({"dataset": "d", "model": ["BGFN-ODO", "Transformer-ODO"], "layer": "total",
                           "energy_uj": [0.5, 2.0]})
    return OdometerInputs(rows, pd.DataFrame(summary), energy)


def test_odometer_rows_answer_and_headline_read_the_odometer_tables():
    inp = _inputs(odometer=_odometer())
    t = verdict_table(inp).set_index("row")
    # after BGFN+NHC: the held speed, the learned odometers, the oracle at BGFN-ODO's speed error
    rows = list(t.index)
    assert rows[rows.index("BGFN+NHC") + 1:rows.index("BGFN+NHC") + 6] == [
        "INS+NHC+HOLD", "RIDGE-ODO", "BGFN-ODO", "Transformer-ODO", ORACLE_ODO_ROW]
    assert t.loc["RIDGE-ODO", "sweep 60 s"] == pytest.approx(16.045) and np.isnan(t.loc["RIDGE-ODO", "outage 1"])
    assert t.loc["BGFN-ODO", "p 30 s"] == 0.002 and t.loc["BGFN-ODO", "runs"] == 1
    assert t.loc["BGFN-ODO", "Holm p 30 s"] == pytest.approx(0.006)                # 3 learned odometers
    assert np.isnan(t.loc["INS+NHC+HOLD", "Holm p 30 s"]) and np.isnan(t.loc["BGFN", "Holm p 30 s"])
    # log-log between (0.1 m/s, 4 m) and (1 m/s, 40 m) at 0.5 m/s: 4 * 10^log10(5) = 20 m at 60 s
    assert t.loc[ORACLE_ODO_ROW, "sweep 60 s"] == pytest.approx(20.0)
    answer = verdict_sentences(inp, verdict_table(inp))[5]
    assert answer.startswith("Does a learned odometer help? In the sweep's windows (10 starts")
    # 3 learned odometers at p 0.002 each: Holm 0.002 x 3 = 0.006 for the smallest, the running maximum for all
    assert ("else among all) is BGFN-ODO: it beats INS+NHC at 30 s and 60 s (best of 3, Holm-corrected p 0.006, "
            "raw 0.002 at 60 s; significant below 0.05).") in answer
    assert "no different from its ANN twin" in answer                      # identical per start: no difference
    assert "0.5 µJ per prediction against the twin's 2 µJ (75 % less)" in answer
    assert "95 % of epochs within its +-2 sigma (calibrated" in answer
    assert "beats INS+NHC at 60 s up to a noise of 0.1 m/s; at BGFN-ODO's speed error it reaches 20.0 m" in answer
    head = headline(inp, verdict_table(inp))
    assert head.startswith("field test (d): A learned odometer beats INS+NHC at 60 s: BGFN-ODO ")
    assert "The paper's design, median max error over the 30 s sweep: BGFN 85.0 m" in head
    # a twin that is 2 m worse at every start: BGFN-ODO is better than it; an overconfident std is named
    worse = _inputs(odometer=_odometer(twin_offset=2.0, coverage=0.7))
    answer = verdict_sentences(worse, verdict_table(worse))[5]
    assert "better than its ANN twin" in answer and "(overconfident" in answer


def test_an_untrained_odometer_claims_no_energy_saving():
    odo = _odometer()
    odo.energy = odo.energy.assign(improved=[False, True])                # BGFN-ODO's best epoch 0
    inp = _inputs(odometer=odo)
    answer = verdict_sentences(inp, verdict_table(inp))[5]
    assert "% less" not in answer and "the BGFN-ODO measured did not train (best epoch 0), so no saving" in answer
    assert "% less" not in headline(inp, verdict_table(inp))
    odo.energy = odo.energy.assign(improved=[True, True])
    assert "(75 % less)" in verdict_sentences(inp, verdict_table(inp))[5]


def test_the_odometer_answer_gives_the_ensembles_error_calibration_and_energy():
    odo = _odometer()
    assert "as one ensemble" not in verdict_sentences(_inputs(odometer=odo), verdict_table(_inputs(odometer=odo)))[5]
    ens = odo.summary[odo.summary["method"] == "BGFN-ODO"].assign(method="BGFN-ODO-ENS", max_h_m=[5.0, 9.0],
                                                                  coverage_2sigma=0.8)
    rows = odo.rows[odo.rows["method"] == "BGFN-ODO"].assign(method="BGFN-ODO-ENS")
    odo.summary, odo.rows = pd.concat([odo.summary, ens]), pd.concat([odo.rows, rows])
    inp = _inputs(odometer=odo)
    assert "BGFN-ODO-ENS" in list(verdict_table(inp)["row"])
    answer = verdict_sentences(inp, verdict_table(inp))[5]
    # one seed per start here: an ensemble of 1 costs 1 time BGFN-ODO's 0.5 µJ
    assert ("BGFN-ODO's 1 seeds as one ensemble (BGFN-ODO-ENS: the mean speed, the std of the members' mixture): 9.0 m at "
            "60 s, speed RMSE 0.50 m/s, 80 % within +-2 sigma (overconfident), at 1 times the energy per prediction "
            "(0.5 µJ).") in answer


def test_the_odometer_answer_says_whether_more_training_windows_made_the_speed_finer():
    odo = _odometer()
    assert "Would more of this drive help?" not in verdict_sentences(_inputs(odometer=odo),
                                                                      verdict_table(_inputs(odometer=odo)))[5]
    odo.curve = pd.DataFrame({"dataset": "d", "folds": [20, 2, 4], "n_train": [250.0, 125.0, 180.0],
                              "val_std_mps": 2.0, "duration_s": 120.0, "outage_speed_rmse_mps": [2.2, 2.3, 2.4],
                              "outage_coverage_2sigma": 0.9, "starts": 20})
    inp = _inputs(odometer=odo)
    assert verdict_sentences(inp, verdict_table(inp))[5].endswith(
        " Would more of this drive help? RIDGE-ODO refitted with the starts in 20 folds instead of 2 learns from 250 "
        "windows per fold instead of 125 (2.0 times as many), and its speed RMSE in its 120 s outages goes from 2.30 "
        "to 2.20 m/s (notebook 07's learning curve).")


def test_the_odometer_answer_says_whether_bgfn_odos_std_ranks_its_errors():
    from bgfn.studies.odometer.uncertainty import UNCERTAINTY_COLUMNS

    odo = _odometer()
    assert "Does it know when it is wrong?" not in verdict_sentences(_inputs(odometer=odo),
                                                                     verdict_table(_inputs(odometer=odo)))[5]
    odo.uncertainty = pd.DataFrame([("d", "BGFN-ODO", g, lo, lo + 0.4, 100, rmse, cov, -0.2)
                                    for g, lo, rmse, cov in ((1, 0.8, 3.6, 0.45), (2, 1.2, 1.9, 0.75),
                                                             (3, 1.6, 1.7, 0.9), (4, 2.0, 1.7, 0.98))],
                                   columns=list(UNCERTAINTY_COLUMNS))
    inp = _inputs(odometer=odo)
    assert (" Does it know when it is wrong? Its predicted std does not rank its errors in the outages (correlation "
            "of |error| and std -0.20): the quarter of its epochs with the smallest std (0.80-1.20 m/s) has a speed "
            "RMSE of 3.60 m/s (45 % within 2 sigma), the one with the largest (2.00-2.40 m/s) 1.70 m/s (98 %).") \
        in verdict_sentences(inp, verdict_table(inp))[5]


def test_odometer_answer_without_its_tables_says_not_measured():
    inp = _inputs()
    assert verdict_sentences(inp, verdict_table(inp))[5].endswith("have not run for this drive (`evaluate.odometer`).")
    assert "odometer" not in headline(inp, verdict_table(inp))


def test_the_best_learned_odometer_is_one_that_beats_ins_nhc_when_one_does():
    odo = _odometer()
    # BGFN-ODO lowest median but not significant; RIDGE-ODO higher but significant: RIDGE-ODO is named
    s = odo.summary
    s.loc[s["method"] == "BGFN-ODO", "p_vs_nhc"] = 0.3
    s.loc[s["method"] == "Transformer-ODO", "p_vs_nhc"] = 0.3
    inp = _inputs(odometer=odo)
    # Holm over the 3: 0.002 x 3 = 0.006, 0.3 x 2 = 0.6, 0.3 lifted to 0.6
    assert ("A learned odometer beats INS+NHC at 60 s: RIDGE-ODO 16.0 m against 20.0 m (best of 3, Holm-corrected p "
            "0.006, raw 0.002)") in headline(inp, verdict_table(inp))


def test_the_best_of_nine_is_named_with_its_holm_corrected_p():
    # the case: the best of 9 learned odometers at a raw p of 0.014 beats INS+NHC uncorrected; over 9
    # candidates (the others at p 0.5) its Holm-adjusted p is 9 x 0.014 = 0.126: no learned odometer beats it
    odo = _odometer()
    s = odo.summary
    extra = [s[s["method"] == "RIDGE-ODO"].assign(method=m) for m in
             ("MLP-ODO", "AT-LSTM-ODO", "BGFN-ODO-ENS", "Transformer-ODO-ENS", "MLP-ODO-ENS", "AT-LSTM-ODO-ENS")]
    s = pd.concat([s, *extra], ignore_index=True)
    learned = s["method"].str.contains("-ODO")
    s.loc[learned, "p_vs_nhc"] = 0.5
    s.loc[s["method"] == "BGFN-ODO", "p_vs_nhc"] = 0.014
    s.loc[learned, "max_h_m"] = s.loc[learned, "max_h_m"] + 5.0                   # all above BGFN-ODO's
    s.loc[s["method"] == "BGFN-ODO", "max_h_m"] -= 5.0
    odo.summary = s
    assert odo.family_size(60.0) == 9 and odo.holm_p("BGFN-ODO", 60.0) == pytest.approx(0.126)
    inp = _inputs(odometer=odo)
    head = headline(inp, verdict_table(inp))
    assert "No learned odometer beats INS+NHC significantly at 60 s" in head
    assert "best of 9, Holm-corrected p 0.13, raw 0.014" in head
    # the same table with its adjusted column written by notebook 07 reads the column
    odo.summary = s.assign(p_vs_nhc_holm=np.where(s["method"] == "BGFN-ODO", 0.126, np.nan))
    assert odo.holm_p("BGFN-ODO", 60.0) == pytest.approx(0.126)


def test_the_ins_rows_carry_the_filters_consistency_and_question_five_says_it():
    nees = pd.DataFrame([
        {"dataset": "d", "window": "sweep", "duration_s": 60.0, "method": "INS", "runs": 20, "median_nees": 40.0,
         "inside_95": 0.3, "verdict": "overconfident"},
        {"dataset": "d", "window": "sweep", "duration_s": 30.0, "method": "INS", "runs": 20, "median_nees": 1.2,
         "inside_95": 0.95, "verdict": "consistent"},
        {"dataset": "d", "window": "outage 1", "duration_s": 30.0, "method": "INS+NHC", "runs": 1, "median_nees": 1.0,
         "inside_95": 1.0, "verdict": "consistent"}])
    inp = _inputs(nees=nees)
    t = verdict_table(inp).set_index("row")
    assert t.loc["INS", "covariance"] == "overconfident"          # the sweep's 60 s speaks for the row
    assert t.loc["INS+NHC", "covariance"] == "consistent"         # no sweep row: the paper's outage
    assert t.loc["BGFN", "covariance"] == "-"
    five = verdict_sentences(inp, verdict_table(inp))[4]
    assert ("the filter is overconfident: the INS row's median NEES of the horizontal position in the 60 s sweep is "
            "40 (30 % of the runs inside the 95 % bound") in five and "weighted too little" in five


def test_the_oracle_speed_row_says_when_the_networks_speed_error_is_beyond_its_grid():
    odo = _odometer()
    odo.summary.loc[odo.summary["method"] == "BGFN-ODO", "speed_rmse_mps"] = 3.0       # the grid ends at 1 m/s
    t = verdict_table(_inputs(odometer=odo)).set_index("row")
    assert np.isnan(t.loc[ORACLE_ODO_ROW, "sweep 60 s"])
    assert t.loc[ORACLE_ODO_ROW, "inputs"] == "speed RMSE 3/3 m/s: beyond the oracle's grid where empty"
    assert verdict_table(_inputs(odometer=_odometer())).set_index("row").loc[ORACLE_ODO_ROW, "inputs"] == \
        "speed RMSE 0.5/0.5 m/s"


def test_the_ins_answer_puts_navego_itself_beside_our_setup_of_it():
    from bgfn.studies.ins_fidelity import ins_setups
    from bgfn.report.verdict import answer_ins_tuning

    rows = [("turin-sim-mpu6000", "field", o, s, e, e, 1.0, 0.1, 1.7, 0.05, 0.8)
            for s, e in (("shipped", 20.0), ("navego", 40.0), (ins_setups.NAVEGO_RUN, 400.0),
                         (ins_setups.NAVEGO_CONSISTENT, 42.0), ("paper", 300.0)) for o in (1, 2)]
    table = pd.DataFrame(rows, columns=list(ins_setups.COLUMNS))
    line = answer_ins_tuning(_inputs(ins_tuning=table))
    assert ("20.0 m with our filter, 40.0 m with NaveGo v1.4's bias modelling, 400.0 m with NaveGo v1.4 itself under "
            "Octave (42.0 m with its bias feedback made consistent), 300.0 m in the paper") in line
    # without make navego-check's rows: our two setups and the paper's only
    line = answer_ins_tuning(_inputs(ins_tuning=table[~table["setup"].str.contains("Octave")]))
    assert "40.0 m with NaveGo v1.4's bias modelling, 300.0 m in the paper" in line


def test_headline_says_when_the_two_outages_rank_the_aided_ins_behind_ins_but_the_drives_starts_do_not():
    seeds = _seeds()
    seeds.loc[seeds["method"] == "INS+NHC", "max_h_m"] *= 5.0           # 20 m and 40 m against INS's 10 and 20 m
    drift = pd.DataFrame([{"dataset": "d", "test": "field", "duration_s": du, "method": m, "n_starts": 20,
                           "median_max_h_m": v, "q25_max_h_m": v, "q75_max_h_m": v}
                          for du, m, v in ((30.0, "INS", 70.4), (30.0, "INS+NHC", 6.5), (60.0, "INS", 300.0),
                                           (60.0, "INS+NHC", 12.0))])
    inp = _inputs(seeds=seeds, sweep_summary=None, sweep_pairs=None, breakeven=None, ins_drift=drift)
    line = headline(inp, verdict_table(inp))
    assert "zero-velocity updates 30.0 m, worse than standalone INS in these two outages though not over" in line
    assert "from notebook 08's 20 starts it is 6.5 m against INS's 70.4 m (median max error, 30 s)." in line
    # where the starts agree with the two outages, or the aid is the better one there, nothing is added
    worse = drift.assign(median_max_h_m=lambda d: np.where(d["method"] == "INS+NHC", 99.0, d["median_max_h_m"]))
    assert headline(_inputs(seeds=seeds, sweep_summary=None, sweep_pairs=None, breakeven=None, ins_drift=worse),
                    verdict_table(inp)).endswith("zero-velocity updates 30.0 m.")
    better = _inputs(sweep_summary=None, sweep_pairs=None, breakeven=None, ins_drift=drift)   # 4 m against 10 m
    assert headline(better, verdict_table(better)).endswith("zero-velocity updates 6.0 m.")
    free = answer_free_aids(verdict_table(inp), drift)
    assert "INS+NHC 30.0 m, worse than standalone INS in these two outages though not over the drive" in free
    assert "(median max error, 30 s); BGFN 60.0 m" in free


# ----------------------------------------------------------------------------------------------- the first screen
def test_short_answers_say_the_verdict_in_three_lines_with_the_numbers_of_the_long_ones():
    from bgfn.report.verdict_page import MAX_BULLET_CHARS, QUESTIONS, answer_bullets, short_answers

    inp = _inputs(odometer=_odometer())
    table = verdict_table(inp)
    short = short_answers(inp, table)
    assert [k for k, _ in QUESTIONS] == list(short)
    # BGFN's 2.5 m per increment misses the 1.9 m break-even; BGFN+NHC (76 m at 30 s) does not beat INS+NHC (5 m)
    assert short["accuracy"].startswith("no") and "2.5 m" in short["accuracy"] and "1.9 m" in short["accuracy"]
    assert short["free_aids"].startswith("no") and "5.0 m" in short["free_aids"] and "76.0 m" in short["free_aids"]
    assert "2e-10" in short["free_aids"]
    # velocity: the honest velocity variant 8 and 16 m in the two outages (mean 12) against the main 40 and 80 (60)
    assert "60.0 m to 12.0 m" in short["speed"]
    html = answer_bullets(short)
    items = html.split("<li>")[1:]
    assert len(items) == 6 and all('href="0' in i for i in items)
    assert all(len(i) <= MAX_BULLET_CHARS + 60 for i in items), [len(i) for i in items]   # + the link's markup


def test_the_better_aid_reads_yes():
    from bgfn.report.verdict_page import short_accuracy, short_free_aids

    summary = pd.DataFrame([{"dataset": "d", "duration_s": du, "method": m, "median_m": v}
                            for du in (30.0, 60.0) for m, v in
                            {"INS": 19.0, "INS+NHC": 5.0, "BGFN": 85.0, "BGFN+NHC": 4.0}.items()])
    inp = _inputs(sweep_summary=summary)
    assert short_free_aids(verdict_table(inp)).startswith("yes")
    be = inp.breakeven.assign(increment_rmse_m=1.0)                                    # below the 1.9 m bar
    assert short_accuracy(_inputs(breakeven=be)).startswith("yes")
    never = short_accuracy(_inputs(breakeven=be.assign(crossing="never_below")))   # the oracle never beats INS
    assert never.startswith("no") and "at no noise level" in never and "n/a" not in never


def test_duration_curves_take_the_sweeps_intervals_and_bootstrap_the_odometers_by_start():
    from bgfn.report.duration_curves import CURVE_COLUMNS, duration_curves, plot_duration_curves

    sweep = pd.DataFrame([{"dataset": "d", "duration_s": du, "method": m, "n": 6, "n_starts": 3,
                           "median_m": v * du, "ci_lo_m": v * du * 0.8, "ci_hi_m": v * du * 1.2}
                          for du in (30.0, 60.0) for m, v in {"INS": 2.0, "INS+NHC": 0.5, "GPS": 0.1}.items()]
                         + [{"dataset": "other", "duration_s": 30.0, "method": "INS", "n": 1, "n_starts": 1,
                             "median_m": 1.0, "ci_lo_m": 1.0, "ci_hi_m": 1.0}])
    odo = pd.DataFrame([{"dataset": "d", "start_s": s, "duration_s": du, "method": "RIDGE-ODO", "seed": 0,
                         "max_h_m": s / 10 + du} for s in (100.0, 200.0, 300.0) for du in (30.0, 60.0)])
    c = duration_curves("d", sweep, odo, n_boot=200, seed=1)
    assert list(c.columns) == list(CURVE_COLUMNS)
    assert list(dict.fromkeys(c["method"])) == ["INS", "INS+NHC", "RIDGE-ODO"]          # no GPS, no other drive
    r = c[(c["method"] == "RIDGE-ODO") & (c["duration_s"] == 30.0)].iloc[0]
    assert r["median_m"] == pytest.approx(50.0) and r["ci_lo_m"] <= 50.0 <= r["ci_hi_m"] and r["n_starts"] == 3
    assert plot_duration_curves(c, "d").axes[0].get_yscale() == "log"
    assert duration_curves("d", None, None).empty

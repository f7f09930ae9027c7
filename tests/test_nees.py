"""The filter's consistency in outages (bgfn.studies.ins_fidelity.nees): NEES summaries and words from hand-made rows."""

from __future__ import annotations

import dataclasses
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from bgfn.studies.ins_fidelity import nees as N
from bgfn.evaluate.hybrid import navigation_context, run_outages, window_metrics
from bgfn.parallel import Runner
from bgfn.profile_schema import load_profile
from bgfn.report import ins_fidelity_words as words
from synthetic_drive import demo_drive

NAV = {"init": {"position_std_m": 1.0, "height_std_m": 2.0, "velocity_std_mps": 0.1, "level_std_deg": 0.2,
                "azimuth_std_deg": 1.0}}


def _sweep():
    rng = np.random.default_rng(0)
    rows = []
    for du in (30.0, 60.0):
        for start in range(200):
            # a consistent filter: the NEES is chi-square(2) = 2 x Exp(1) ...
            rows.append({"dataset": "d", "start_s": float(start), "duration_s": du, "method": "INS",
                         "nees_h": 2.0 * rng.exponential()})
            # ... an overconfident one: errors 4 times its std
            rows.append({"dataset": "d", "start_s": float(start), "duration_s": du, "method": "INS+NHC",
                         "nees_h": 16.0 * 2.0 * rng.exponential()})
            rows.append({"dataset": "d", "start_s": float(start), "duration_s": du, "method": "GPS", "nees_h": np.nan})
    return pd.DataFrame(rows)


def test_chi_square_constants_and_words():
    assert N.CHI2_MEDIAN == pytest.approx(1.3863, abs=1e-4) and N.CHI2_95 == pytest.approx(5.9915, abs=1e-4)
    assert N.verdict(1.4) == "consistent" and N.verdict(30.0) == "overconfident"
    assert N.verdict(0.1) == "underconfident" and N.verdict(float("nan")) == "not measured"


def test_the_summary_finds_the_consistent_and_the_overconfident_filter(tmp_path):
    per_seed = pd.DataFrame({"outage": [1, 1, 2], "method": ["INS", "INS", "INS"], "nees_h": [1.0, 3.0, 100.0]})
    results = {"d": SimpleNamespace(per_seed=per_seed, windows=[(10.0, 30.0), (50.0, 30.0)])}
    s = N.nees_summary(_sweep(), results)
    assert list(s.columns) == list(N.NEES_COLUMNS)
    sw = s[s["window"] == "sweep"].set_index(["method", "duration_s"])
    assert ("GPS", 30.0) not in sw.index                               # no covariance: no row
    assert sw.loc[("INS", 30.0), "verdict"] == "consistent" and sw.loc[("INS", 30.0), "inside_95"] == pytest.approx(
        0.95, abs=0.04)
    assert sw.loc[("INS+NHC", 60.0), "verdict"] == "overconfident" and sw.loc[("INS+NHC", 60.0), "inside_95"] < 0.3
    paper = s[s["window"] != "sweep"].set_index("window")
    assert paper.loc["outage 1", "median_nees"] == 2.0 and paper.loc["outage 1", "duration_s"] == 30.0
    assert paper.loc["outage 2", "verdict"] == "overconfident"
    lines = words.nees_lines(s)
    assert lines[0].startswith("d, NEES of the horizontal position") and "INS 30 s: median" in lines[0]
    assert N.nees_section(tmp_path, results, _sweep()).equals(s)
    assert (tmp_path / "tables" / "outage_nees.csv").is_file() and (tmp_path / "figures" / "outage_nees_d.png").is_file()


def test_the_scan_finds_a_larger_gyro_bias_instability_less_confident(monkeypatch):
    """A synthetic drive with biased gyros the filter's error model under-states: the larger the bias
    instability the filter is told, the smaller its NEES; the profile's value is marked; simulated drives skipped."""
    drive = demo_drive("synthetic", 150.0, 5.0, 3)
    cfg = load_profile("smoke")
    cfg = {**cfg, "nav": NAV, "evaluate": {**cfg["evaluate"], "sweep": {**cfg["evaluate"]["sweep"], "n_starts": 3,
                                                                        "warmup_s": 30.0, "durations_s": [10.0]}}}
    scan = N.consistency_scan(cfg, [drive], durations=(10.0,), values_dps=(0.01, 1.0))
    assert list(scan.columns) == list(N.SCAN_COLUMNS) and scan["profile"].sum() == 1
    grid = scan[~scan["profile"]].set_index("gyro_bias_instability_dps")
    assert grid.loc[1.0, "median_nees"] < grid.loc[0.01, "median_nees"]
    assert words.scan_lines(scan)[0].startswith("synthetic: with the profile's gyro bias instability")
    assert N.consistency_scan(cfg, [dataclasses.replace(drive, name="turin-sim-mpu6000")]).empty
    # the points are independent runs: spread over 2 processes, the same table, row for row
    monkeypatch.delenv("BGFN_PROGRESS_LOG", raising=False)      # the progress lines come to `report`
    lines = []
    spread = N.consistency_scan(cfg, [drive], durations=(10.0,), values_dps=(0.01, 1.0), report=lines.append,
                                runner=Runner(jobs=2))
    pd.testing.assert_frame_equal(spread, scan)
    assert len(lines) == 3 and all(line.startswith("[NEES scan] synthetic gyro bias instability") for line in lines)


# ------------------------------------------------------------------------------- the check on a filter's own model
#: Error terms the filter's model has no state for, switched off so that the drive's errors come from its model.
UNMODELLED = {k: [0.0, 0.0, 0.0] for k in ("gyro_scale_factor_tol", "accel_scale_factor_tol", "gyro_misalignment_tol",
                                          "accel_misalignment_tol", "vibration_gyro_std", "vibration_accel_std")}
BIG_ACCEL_BIAS = {"accel_turn_on_bias_std": [0.05] * 3}


def _nees(seeds, overrides=None, told=None):
    """The horizontal NEES at the end of 20 s outages from two starts of synthetic drives (one per seed) whose IMU
    errors are drawn from the Ekinox-D model; ``told``: what the filter is told instead (its ``meta``)."""
    out = []
    for seed in seeds:
        d = demo_drive("syn", 200.0, 5.0, seed, imu="ekinox-d", overrides={**UNMODELLED, **(overrides or {})})
        if told:
            d = dataclasses.replace(d, meta={**d.meta, "imu_errors": {**d.meta["imu_errors"], **told}})
        t0 = float(d.reference["time"].iloc[0])
        ctx = navigation_context(d, NAV, [t0 + 100.0, t0 + 140.0])
        runs = run_outages(ctx, [(t0 + 100.0, 20.0), (t0 + 140.0, 20.0)], None, "INS", None, {})
        out += [window_metrics(r.errors, r.start, 20.0, r.sd)["nees_h"] for r in runs]
    return np.array(out)


def test_nees_of_a_drive_drawn_from_the_filters_own_model_averages_two():
    nees = _nees(range(30))                               # 60 outages; chi-square(2): mean 2, std 2
    sem = 2.0 / np.sqrt(nees.size)
    assert abs(nees.mean() - 2.0) < 3.0 * sem, (nees.mean(), sem)
    assert N.verdict(float(np.median(nees))) == "consistent"


def test_an_underestimated_accelerometer_bias_makes_the_check_fail():
    honest = _nees(range(12), BIG_ACCEL_BIAS)
    told_small = _nees(range(12), BIG_ACCEL_BIAS, told={"p0_accel_bias_std": [5e-4] * 3,
                                                        "accel_bias_instability": [1e-6] * 3})
    assert N.verdict(float(np.median(honest))) == "consistent"
    assert N.verdict(float(np.median(told_small))) == "overconfident" and told_small.mean() > 5 * honest.mean()


def test_the_scan_runs_only_durations_the_sweep_ran():
    """A short log's sweep of 10 and 30 s: the scan speaks of 30 s, not of 60 s it never ran."""
    assert N.scan_durations({"durations_s": [10.0, 30.0, 60.0, 120.0]}) == [30.0, 60.0]
    assert N.scan_durations({"durations_s": [10.0, 30.0]}) == [30.0]
    assert N.scan_durations({"durations_s": [10.0, 20.0]}) == [20.0]


def test_a_profile_grid_that_misses_the_crossing_is_scanned_again_widened():
    """quick scans a narrow grid around the crossing; a drive whose scan (the profile's own value included) never
    gets consistent on it (this synthetic drive crosses between 5 and 10 deg/s) is scanned again on the grid widened
    by the default one, so its effective instability is not clipped at the grid's edge; a grid that brackets the
    crossing is kept as it is."""
    drive = demo_drive("synthetic", 150.0, 5.0, 3)
    cfg = load_profile("smoke")
    sweep = {**cfg["evaluate"]["sweep"], "n_starts": 2, "warmup_s": 30.0, "durations_s": [10.0]}

    def grid(values):
        c = {**cfg, "nav": NAV, "evaluate": {**cfg["evaluate"], "nees_scan": {"gyro_bias_dps": values}, "sweep": sweep}}
        scan = N.consistency_scan(c, [drive], durations=(10.0,))
        return set(scan.loc[~scan["profile"], "gyro_bias_instability_dps"])

    assert grid([5.0, 10.0]) == {5.0, 10.0}                                    # brackets: kept
    assert grid([0.001, 0.002]) == {0.001, 0.002, 0.005, 0.01, 0.02, 0.03, 0.05, 0.1, 0.2, 0.3}   # widened

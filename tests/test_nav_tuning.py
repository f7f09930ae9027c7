"""The filter's noise from the data (bgfn.nav.tuning) and the NIS verdicts (bgfn.nav.consistency)."""

from __future__ import annotations

import math

import numpy as np
import pandas as pd
import pytest
from scipy.stats import chi2

from bgfn.data import Drive
from bgfn.data import imu_errors as ie
from bgfn.errors import DataError
from bgfn.nav import baseline, consistency, sim
from bgfn.nav.tuning import NOISE_SEARCH_DEFAULTS, search_noise_scale
from bgfn.report import nav_words

LEVER = [0.5, -0.3, -1.2]
TRUE_SCALE = 10.0
#: The factor found on a 300 s drive: the mean NIS of 300 fixes has a sampling std of about 5 % and falls as about
#: s^-0.4..-0.7 near the root, so the factor is known to about +-15 %; the band allows twice that.
SCALE_BAND = (TRUE_SCALE / 1.4, TRUE_SCALE * 1.4)


def _model(root: float, floor: float = 0.0):
    """A mean-NIS curve falling with the factor, equal to 3 at ``root`` (and never below ``floor``)."""
    def mean_nis(s):
        return 3.0 * (floor + (1.0 - floor / 3.0) * (root / s) ** 1.2), 3.0
    return mean_nis


# ------------------------------------------------------------------------------------------------- the search
@pytest.mark.parametrize("root", [0.3, 1.0, 7.0, 40.0, 250.0])
def test_search_finds_the_root_in_a_few_runs(root):
    t = search_noise_scale(_model(root))
    assert abs(math.log(t.mean_nis / 3.0)) <= math.log1p(NOISE_SEARCH_DEFAULTS["tolerance"])
    assert t.scale == pytest.approx(root, rel=0.1) and not t.at_bound
    assert len(t.runs) <= NOISE_SEARCH_DEFAULTS["max_runs"] and t.runs[0][0] == 1.0
    assert t.mean_nis_at_one == pytest.approx(_model(root)(1.0)[0])
    assert len(t.runs) == 1 if root == 1.0 else len(t.runs) <= 5


@pytest.mark.parametrize("root,bound", [(5000.0, 1000.0), (0.01, 0.1)])
def test_search_stops_at_the_range_and_says_so(root, bound):
    t = search_noise_scale(_model(root))
    assert t.at_bound and t.scale == pytest.approx(bound)
    assert "bound" in nav_words.tuning_line(t, "x")


def test_search_respects_its_run_budget():
    t = search_noise_scale(_model(37.0), {"max_runs": 2})
    assert len(t.runs) == 2 and t.scale == max(r[0] for r in t.runs)    # the better of the two tried


# ------------------------------------------------------------------------------------- on a simulated drive
@pytest.fixture(scope="module")
def quiet_drive():
    """A MEMS drive whose IMU noise is TRUE_SCALE times what its meta says (the filter is overconfident).

    No vibration, scale-factor or misalignment errors and slow biases, so that white noise is what the filter
    misjudges; 0.1 m fixes at 1 Hz make the innovations sensitive to it.
    """
    ref = sim.demo_trajectory(300.0)
    base = {"gyro_bias_corr_time": 3600.0, "accel_bias_corr_time": 3600.0, "gyro_scale_factor_tol": [0.0] * 3,
            "accel_scale_factor_tol": [0.0] * 3, "gyro_misalignment_tol": [0.0] * 3,
            "accel_misalignment_tol": [0.0] * 3, "vibration_gyro_std": [0.0] * 3, "vibration_accel_std": [0.0] * 3}
    stated = ie.error_params("mpu6000", base)
    true = ie.error_params("mpu6000", {**base, **{k: [TRUE_SCALE * x for x in stated[k]]
                                                  for k in ("gyro_noise_density", "accel_noise_density")}})
    imu, errs, bias = ie.apply_imu_errors(sim.imu_from_trajectory(ref), true, seed=3)
    for k in ("gyro_noise_density", "accel_noise_density"):
        errs[k] = stated[k]                                   # what the datasheet says
    gnss = sim.gnss_from_trajectory(ref, 1.0, 0.1, 0.1, LEVER, seed=4)
    meta = {"lever_arm_m": LEVER, "imu_errors": errs, "gnss_rate_hz": 1.0, "imu_rate_hz": 100.0}
    return Drive("quiet", ref, imu, gnss, meta, bias)


NAV = {"init": {"position_std_m": 0.5, "height_std_m": 1.0, "velocity_std_mps": 0.1, "level_std_deg": 0.5,
                "azimuth_std_deg": 2.0}}


def test_auto_finds_the_true_noise_factor_and_makes_the_nis_consistent(quiet_drive, tmp_path):
    cfg = baseline.nav_config({**NAV, "noise_scale": "auto"})
    setup = baseline.prepare_filter(quiet_drive, cfg)
    t = setup.tuning
    assert SCALE_BAND[0] < t.scale < SCALE_BAND[1], t.runs
    assert consistency.verdict(t.mean_nis_at_one, t.dof) == "overconfident" and t.mean_nis_at_one > 2 * t.dof
    assert t.dof == 3.0 and abs(t.mean_nis - 3.0) < 0.3 * 3.0
    assert len(t.runs) <= NOISE_SEARCH_DEFAULTS["max_runs"]
    assert setup.noise_scale == t.scale and np.allclose(setup.noise.accel_noise, t.scale * np.asarray(
        quiet_drive.meta["imu_errors"]["accel_noise_density"]))
    # the baseline runs with the factor found; its record holds the factor and the NIS before and after
    b = baseline.run_baseline(quiet_drive, cfg, [(150.0, 20.0)])
    s = consistency.nis_summary(b.full.updates)
    assert s["verdict"] == "consistent" and s["mean_nis"] == pytest.approx(t.mean_nis)
    rec = baseline.save_baseline(b, tmp_path, "sim")
    assert rec["noise_scale"] == t.scale and rec["noise_tuning"]["mean_nis_at_one"] == t.mean_nis_at_one
    assert rec["alignment"] is None and rec["start_time"] == quiet_drive.reference["time"].iloc[0]
    # the gate comparison reuses the factor found instead of searching again
    table = baseline.gate_comparison(quiet_drive, cfg, [(150.0, 20.0)], 0.999, baseline=b)
    assert table.loc[0, "mean_nis"] == pytest.approx(t.mean_nis)


def test_a_numeric_factor_runs_no_search(quiet_drive):
    setup = baseline.prepare_filter(quiet_drive, baseline.nav_config({**NAV, "noise_scale": 3.0}))
    assert setup.tuning is None and setup.noise_scale == 3.0 and nav_words.setup_lines(setup, "quiet") == []
    walk = baseline.prepare_filter(quiet_drive, baseline.nav_config(
        {**NAV, "noise_scale": 3.0, "noise_search": {"bias_walk": True}}))
    assert np.allclose(walk.noise.gyro_bias_walk, 3.0 * setup.noise.gyro_bias_walk)
    for bad in ("fast", -1.0, 0.0, True):
        with pytest.raises(DataError, match="noise_scale"):
            baseline.nav_config({"noise_scale": bad})


# ------------------------------------------------------------------------------------------- the NIS verdict
def _updates(nis, dof=3, kind="gnss"):
    return pd.DataFrame({"time": np.arange(len(nis), dtype=float), "kind": kind, "innov_n": 0.0, "innov_e": 0.0,
                         "innov_d": 0.0, "nis": nis, "dof": dof, "accepted": True})


def test_nis_summary_of_chi_square_fixes_is_consistent_and_scaled_ones_are_not():
    nis = chi2.rvs(3, size=4000, random_state=np.random.default_rng(0))
    s = consistency.nis_summary(_updates(nis))
    assert s["mean_nis"] == pytest.approx(3.0, rel=0.05) and s["above_chi2_95"] == pytest.approx(0.05, abs=0.01)
    assert s["verdict"] == "consistent" and s["fixes"] == 4000 and s["dof"] == 3.0
    over = consistency.nis_summary(_updates(22.0 * nis))              # a real MEMS drive with datasheet noise
    assert over["verdict"] == "overconfident" and over["above_chi2_95"] > 0.5
    assert "overconfident" in nav_words.nis_line("d", over) and "noise_scale: auto" in nav_words.nis_line("d", over)
    assert consistency.nis_summary(_updates(0.1 * nis))["verdict"] == "underconfident"
    # pseudo fixes are not GNSS fixes
    assert consistency.nis_summary(_updates(nis, kind="pseudo"))["verdict"] == "no fixes"


def test_nis_table_has_one_row_per_run():
    nis = chi2.rvs(3, size=100, random_state=np.random.default_rng(1))
    table = consistency.nis_table({("a", "baseline"): _updates(nis), ("b", "baseline"): _updates(9 * nis)})
    assert list(table.columns) == list(consistency.NIS_COLUMNS)
    assert table["verdict"].tolist() == ["consistent", "overconfident"]

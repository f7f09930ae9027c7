"""The roughness measurements on drives whose truth is known: stop biases less the Earth rate, the bias
instability from their changes, the trajectory twin, and the effective instability of the twin check."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest
from synthetic_drive import demo_drive

from bgfn.data import Drive
from bgfn.studies.ins_fidelity import imu_roughness as R
from bgfn.studies.ins_fidelity import imu_twin as T
from bgfn.nav.earth import earth_rate_n
from bgfn.report import ins_fidelity_words as words

RATE = 100.0


def _stop_and_go(stop_biases: np.ndarray, noise: float = 1e-4, stop_s: float = 20.0, go_s: float = 10.0,
                 seed: int = 0) -> Drive:
    """Stops of ``stop_s`` (one gyro bias each, rad/s) joined by ``go_s`` of driving north at 5 m/s; the gyro reads
    the Earth rate of a level IMU heading north plus the stop's bias plus white noise (rad/s per sample)."""
    rng = np.random.default_rng(seed)
    n_stop, n_go = int(stop_s * RATE), int(go_s * RATE)
    speed = np.concatenate([np.r_[np.zeros(n_stop), np.full(n_go, 5.0)] for _ in stop_biases])
    bias = np.concatenate([np.full(n_stop + n_go, b) for b in stop_biases])
    t = np.arange(speed.size) / RATE
    lat = np.radians(45.0)
    ref = pd.DataFrame({"time": t, "lat": lat, "lon": 0.0, "h": 0.0, "v_n": speed, "v_e": 0.0, "v_d": 0.0,
                        "roll": np.nan, "pitch": np.nan, "yaw": np.nan})
    w = earth_rate_n(lat)                                    # heading north: body = NED
    gyro = w[None, :] + bias[:, None] + rng.normal(0.0, noise, (t.size, 3))
    imu = pd.DataFrame({"time": t, "gyro_x": gyro[:, 0], "gyro_y": gyro[:, 1], "gyro_z": gyro[:, 2],
                        "accel_x": 0.0, "accel_y": 0.0, "accel_z": -9.81})
    imu[["accel_x", "accel_y", "accel_z"]] += rng.normal(0.0, 1e-3, (t.size, 3))
    return Drive("stop-and-go", ref, imu, ref.iloc[::100].reset_index(drop=True), {})


def test_stop_biases_remove_the_earth_rate_and_read_each_stops_bias():
    biases = np.array([1e-3, -2e-3, 5e-4])
    stops = R.stop_biases(_stop_and_go(biases))
    assert len(stops) == 3 and (stops["duration_s"] > 15.0).all()
    for axis in "xyz":                                       # the Earth rate (up to 7e-5 rad/s) is gone
        assert stops[f"gyro_bias_{axis}"].to_numpy() == pytest.approx(biases, abs=2e-5)


def test_bias_instability_is_zero_for_a_constant_bias_and_finds_a_wandering_one():
    steady = R.bias_instability(_stop_and_go(np.full(12, 1e-3)), corr_time_s=100.0)
    assert (steady["sigma"] < 2e-5).all() and (steady["n_pairs"] == 66).all()
    sigma = 4e-4                                             # independent draws per stop: T << 30 s between stops
    draws = np.random.default_rng(5).normal(0.0, sigma, 40)
    found = R.bias_instability(_stop_and_go(draws, seed=1), corr_time_s=1.0)
    assert found["sigma"].to_numpy() == pytest.approx(np.std(draws), rel=0.05)


def test_the_trajectory_twin_changes_only_the_imu_and_follows_the_road():
    drive = demo_drive(duration=60.0)
    ref = drive.reference.copy()
    ref[["roll", "pitch", "yaw"]] = np.nan                   # a recorded drive without attitude
    recorded = Drive("road", ref, drive.imu, drive.gnss, drive.meta)
    zero = {k: (0.0 if not isinstance(v, list) else [0.0] * len(v)) for k, v in drive.meta["imu_errors"].items()
            if k not in ("model", "realized", "seed", "p0_gyro_bias_std", "p0_accel_bias_std")}
    zero.update(gyro_bias_corr_time=[100.0] * 3, accel_bias_corr_time=[100.0] * 3, vibration_freq_hz=20.0,
                vibration_bandwidth_hz=20.0, vibration_speed_ref_mps=10.0,
                gyro_boot_calibration_residual_std=None, accel_boot_calibration_residual_std=None)
    twin = R.trajectory_twin(recorded, zero, seed=0)
    assert twin.gnss is recorded.gnss and twin.reference["yaw"].isna().all() and twin.meta["twin_of"] == "road"
    # the demo car's heading is its course: the twin's error-free yaw rate is the true one, and its specific
    # force carries gravity (the demo's small roll and pitch are the only differences)
    moving = np.hypot(ref["v_n"], ref["v_e"]).to_numpy()[1:] > 2.0
    assert np.sqrt(np.mean((twin.imu["gyro_z"].to_numpy()[moving] - drive.imu["gyro_z"].to_numpy()[moving]) ** 2)) < 0.01
    assert twin.imu["accel_z"].mean() == pytest.approx(-9.8, abs=0.1)


def _scan(name, values, nees, own):
    return pd.DataFrame({"dataset": name, "gyro_bias_instability_dps": values, "profile": [v == own for v in values],
                         "duration_s": 30.0, "runs": 20, "median_nees": nees, "inside_95": 0.5,
                         "median_max_h_m": [10.0 * (k + 1) for k in range(len(values))], "verdict": ""})


def test_the_effective_instability_is_the_log_log_crossing_of_the_chi_square_median():
    scan = _scan("d", [0.01, 0.03, 0.1], [4.0, 1.0, 0.2], 0.01)
    # ln(4 / 1.386) / ln(4 / 1) = 0.7645 of the way from 0.01 to 0.03 in log: 0.01 * 3^0.7645
    assert T.effective_instability(scan)["effective_dps"].iloc[0] == pytest.approx(0.01 * 3 ** 0.7645, rel=1e-3)
    assert T.effective_instability(_scan("d", [0.01, 0.03], [9.0, 5.0], 0.01))["effective_dps"].isna().all()
    assert T.effective_instability(_scan("d", [0.01, 0.03], [1.0, 0.5], 0.01))["effective_dps"].iloc[0] == 0.01


def test_the_implied_setting_takes_the_unmodelled_terms_in_quadrature_and_the_lines_say_whether_it_holds():
    table = pd.DataFrame({"dataset": "d", "imu": ["recorded", "sim model", "sim model"], "seed": [None, 1, 2],
                          "duration_s": 30.0, "effective_dps": [0.08, 0.03, 0.03], "model_dps": [0.1, 0.01, 0.01],
                          "median_max_h_m": [50.0, 20.0, 22.0]})
    # the twin's unmodelled part: 0.03^2 - 0.01^2 = 0.0008; the setting: sqrt(0.08^2 - 0.0008)
    assert T.implied_setting(table) == pytest.approx(np.sqrt(0.0064 - 0.0008))
    lines = words.twin_lines(table)
    assert "ratio 2.67" in lines[0] and "does not hold" in lines[1] and "smoother" in lines[1]
    table.loc[0, "effective_dps"] = 0.033
    assert "holds" in words.twin_lines(table)[1] and "not" not in words.twin_lines(table)[1]


def test_a_twin_scan_that_brackets_the_crossing_gives_the_whole_grids_value_and_one_that_does_not_is_rescanned(
        monkeypatch):
    """evaluate.nees_scan.twin_gyro_bias_dps: a shorter twin grid that brackets the NEES crossing gives the effective
    instability of the whole grid (the same two points are interpolated); where it does not, the whole grid runs."""
    whole = [0.005, 0.01, 0.02, 0.03, 0.05, 0.1, 0.2, 0.3]
    short = [0.02, 0.03, 0.05, 0.1, 0.2]

    def nees(values, level):              # NEES falls as the square of the told instability: 1.39 at `level`
        return [T.CHI2_MEDIAN * (level / v) ** 2 for v in values]

    full_value = T.effective_instability(_scan("d", whole, nees(whole, 0.07), 0.1))["effective_dps"].iloc[0]
    short_scan = _scan("d", short, nees(short, 0.07), 0.1)
    assert T.brackets_crossing(short_scan)
    assert T.effective_instability(short_scan)["effective_dps"].iloc[0] == pytest.approx(full_value, rel=1e-12)
    assert full_value == pytest.approx(0.07, rel=1e-9)            # a power law: the log-log line is exact
    assert not T.brackets_crossing(_scan("d", short, nees(short, 0.01), 0.1))     # consistent at its first point
    assert not T.brackets_crossing(_scan("d", short, nees(short, 0.5), 0.1))      # never consistent

    grids = []

    def fake_scan(cfg, drives, durations=None, values_dps=None, report=None, runner=None):
        values = list(values_dps or cfg["evaluate"]["nees_scan"]["gyro_bias_dps"])
        grids.append(values)
        return pd.concat([_scan("road", values, nees(values, d.level), 0.1) for d in drives], ignore_index=True)

    monkeypatch.setattr(T, "consistency_scan", fake_scan)
    monkeypatch.setattr(T, "trajectory_twin", lambda recorded, errors, seed: SimpleNamespace(level=0.02 + 0.01 * seed))
    recorded, stand_in = SimpleNamespace(name="road"), SimpleNamespace(name="sim", meta={"imu_errors": {}})
    cfg = {"evaluate": {"nees_scan": {"gyro_bias_dps": whole, "twin_gyro_bias_dps": short, "twin_seeds": [1, 2]}}}
    scan = _scan("road", whole, nees(whole, 0.08), 0.1)
    table = T.twin_check(cfg, recorded, stand_in, scan=scan)
    assert grids == [short]                                             # 0.03 and 0.04: inside the bracket
    assert table.loc[table["imu"] != "recorded", "effective_dps"].tolist() == pytest.approx([0.03, 0.04])
    grids.clear()
    monkeypatch.setattr(T, "trajectory_twin", lambda recorded, errors, seed: SimpleNamespace(level=0.01 * seed))
    table = T.twin_check(cfg, recorded, stand_in, scan=scan)
    assert grids == [short, whole]                                       # 0.01 is below the short grid: rescanned
    assert table.loc[table["imu"] != "recorded", "effective_dps"].tolist() == pytest.approx([0.01, 0.02])

"""The filter set up as NaveGo v1.4 does (bgfn.nav.navego_setup) and the INS row under each setup
(bgfn.studies.ins_fidelity.ins_setups): NaveGo's Q and P0 from the error profile, the shipped setup untouched, the physics of
removing a static bias, and the table beside the paper's INS row."""

from __future__ import annotations

from dataclasses import replace
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from bgfn import evaluate as ev
from bgfn import paper
from bgfn.data import Drive
from bgfn.data import imu_errors as ie
from bgfn.errors import DataError
from bgfn.nav import baseline, metrics, sim
from bgfn.report import ins_fidelity_words
from bgfn.studies.ins_fidelity import ins_setups
from bgfn.nav import error_model as em
from bgfn.nav import navego_setup as ns
from bgfn.nav import state as st
from bgfn.nav.engine import noise_arrays
from bgfn.nav.filter import run_filter, run_outage
from bgfn.nav.outages import OutageWindow
from synthetic_drive import demo_drive

WINDOWS = [(60.0, 20.0), (110.0, 20.0)]
NAV = {"init": {"position_std_m": 1.0, "height_std_m": 2.0, "velocity_std_mps": 0.1, "level_std_deg": 0.2,
                "azimuth_std_deg": 1.0}}
DEG = np.pi / 180.0


def _drive(name="turin-sim-ekinox", duration=150.0, seed=3) -> Drive:
    """A short synthetic drive with Ekinox-grade errors and large static biases (their ``bias_fixed``)."""
    return demo_drive(name, duration, 5.0, seed)


@pytest.fixture(scope="module")
def drive():
    return _drive()


# ----------------------------------------------------------------------------------------------- Q and P0
def test_navego_q_and_p0_are_the_profiles_dynamic_biases():
    errs = ie.error_params("ekinox-d")
    noise = ns.navego_noise(errs)
    q_g, q_a, q_bg, q_ba, inv_tau_a, inv_tau_g, decay_a, decay_g = noise_arrays(noise)
    # NaveGo's Ekinox profile: gb_dyn [8.1e-6, 7.1e-6, 9.8e-6] rad/s, gb_corr 10 s; ab_dyn [8.4e-5, 6.7e-5,
    # 7.4e-5] m/s^2, ab_corr [0.5, 2, 1] s; Q = (gb_dyn / sqrt(gb_corr))^2 (imu_si_errors.m).
    np.testing.assert_allclose(q_bg, [6.561e-12, 5.041e-12, 9.604e-12], rtol=1e-12)
    np.testing.assert_allclose(q_ba, [1.4112e-8, 2.2445e-9, 5.476e-9], rtol=1e-12)
    np.testing.assert_allclose(inv_tau_g, [0.1, 0.1, 0.1], rtol=1e-15)
    np.testing.assert_allclose(inv_tau_a, [2.0, 0.5, 1.0], rtol=1e-15)
    np.testing.assert_allclose(q_g, np.square([1.58e-4, 1.60e-4, 1.81e-4]), rtol=1e-15)   # arw^2
    np.testing.assert_allclose(q_a, np.square([1.91e-4, 1.88e-4, 1.94e-4]), rtol=1e-15)   # vrw^2
    # the discrete Q of one 0.01 s step holds q dt on the bias states
    Q = np.empty((em.N_STATES, em.N_STATES))
    em.process_noise_nb(np.eye(3), q_g, q_a, q_bg, q_ba, 0.01, Q)
    assert Q[em.BG_X, em.BG_X] == pytest.approx(6.561e-14, rel=1e-12)
    assert Q[em.BA_Y, em.BA_Y] == pytest.approx(2.2445e-11, rel=1e-12)
    # half the PSD 2 sigma^2 / tau that keeps a Gauss-Markov bias at its std (the shipped filter's)
    shipped = noise_arrays(st.noise_from_imu_errors(errs, "gauss_markov"))
    np.testing.assert_allclose(shipped[2], 2 * q_bg, rtol=1e-12)
    np.testing.assert_allclose(shipped[3], 2 * q_ba, rtol=1e-12)
    # NaveGo holds its bias estimates between updates (F keeps -1/tau); the shipped filter relaxes them with it
    assert not decay_a.any() and not decay_g.any()
    np.testing.assert_array_equal(shipped[6:], shipped[4:6])
    # F: the bias states decay with -1/tau
    F = em.system_matrix([0.78, 0.13, 250.0], [5.0, 2.0, 0.0], np.eye(3), [0.0, 0.0, -9.8],
                         noise.accel_bias_tau, noise.gyro_bias_tau)
    np.testing.assert_allclose(np.diag(F)[em.BG], -0.1, rtol=1e-15)
    np.testing.assert_allclose(np.diag(F)[em.BA], [-2.0, -0.5, -1.0], rtol=1e-15)
    # P0 of the bias states: gb_dyn^2, ab_dyn^2 (ins_gnss.m), not the static part's spread
    P0 = st.initial_covariance([0.78, 0.13, 250.0], noise, 1.0, 3.0, 0.1, 0.01, 0.03)
    np.testing.assert_allclose(np.diag(P0)[em.BG], np.square([8.1e-6, 7.1e-6, 9.8e-6]), rtol=1e-12)
    np.testing.assert_allclose(np.diag(P0)[em.BA], np.square([8.4e-5, 6.7e-5, 7.4e-5]), rtol=1e-12)


def test_navego_noise_of_the_mpu6000_and_its_bad_input():
    noise = ns.navego_noise(ie.error_params("mpu6000"), noise_scale=2.0)
    # 0.01 deg/s over sqrt(100 s); 0.5 mg over sqrt(100 s); white densities doubled
    np.testing.assert_allclose(noise.gyro_bias_walk, 0.01 * DEG / 10.0, rtol=1e-12)
    np.testing.assert_allclose(noise.accel_bias_walk, 0.5e-3 * ie.G0 / 10.0, rtol=1e-12)
    np.testing.assert_allclose(noise.gyro_noise, 2 * 0.005 * DEG, rtol=1e-12)
    with pytest.raises(DataError, match="gyro_bias_corr_time"):
        ns.navego_noise({**ie.error_params("ekinox-d"), "gyro_bias_corr_time": [10.0, 0.0, 10.0]})
    with pytest.raises(DataError, match="accel_bias_instability"):
        ns.navego_noise({k: v for k, v in ie.error_params("ekinox-d").items() if k != "accel_bias_instability"})
    with pytest.raises(DataError, match="ins_tuning"):
        baseline.nav_config({"ins_tuning": "pyins"})


# ----------------------------------------------------------------------------------------------- the two setups
def test_shipped_setup_is_the_filter_as_it_was(drive):
    cfg = baseline.nav_config(NAV)
    assert cfg["ins_tuning"] == "shipped"
    assert baseline.filter_imu(drive, cfg) is drive.imu
    initial, noise = baseline.initial_and_noise(drive, cfg)
    expected = st.noise_from_imu_errors(drive.meta["imu_errors"], "random_walk", 1.0)
    for f in ("gyro_noise", "accel_noise", "gyro_bias_walk", "accel_bias_walk", "gyro_bias_tau", "accel_bias_tau",
              "gyro_bias_std", "accel_bias_std"):
        np.testing.assert_array_equal(getattr(noise, f), getattr(expected, f), err_msg=f)
    assert not initial.gyro_bias.any() and not initial.accel_bias.any()
    ctx = ev.navigation_context(drive, NAV, [WINDOWS[0][0]])
    assert ctx.imu_static is None


def test_navego_setup_removes_the_static_biases_and_starts_at_the_dynamic_ones(drive):
    cfg = baseline.nav_config({**NAV, "ins_tuning": "navego"})
    errs = drive.meta["imu_errors"]
    imu = baseline.filter_imu(drive, cfg)
    for s in ("gyro", "accel"):
        for i, a in enumerate("xyz"):
            np.testing.assert_array_equal(imu[f"{s}_{a}"], drive.imu[f"{s}_{a}"] - errs[f"{s}_bias_fixed"][i])
    np.testing.assert_array_equal(imu["time"], drive.imu["time"])
    initial, noise = baseline.initial_and_noise(drive, cfg)
    np.testing.assert_array_equal(initial.gyro_bias, errs["gyro_bias_instability"])
    np.testing.assert_array_equal(initial.accel_bias, errs["accel_bias_instability"])
    np.testing.assert_allclose(np.sqrt(np.diag(initial.P)[em.BG]), errs["gyro_bias_instability"], rtol=1e-12)
    # nothing to remove: the same table back
    assert ns.remove_static_biases(drive.imu, np.zeros(3), np.zeros(3)) is drive.imu


def test_removing_a_static_bias_stops_the_drift_of_a_stationary_ins():
    # A level IMU standing still for 30 s with only static biases: accelerometer x (north) 0.02, y (east)
    # -0.03 m/s^2, gyro z 1e-4 rad/s.
    t = np.arange(0.0, 30.0 + 1e-9, 0.01)
    ref = pd.DataFrame({"time": t, "lat": 0.78, "lon": 0.13, "h": 250.0, "v_n": 0.0, "v_e": 0.0, "v_d": 0.0,
                        "roll": 0.0, "pitch": 0.0, "yaw": 0.0})
    zero = [0.0] * 3
    params = ie.error_params("ekinox-d", {
        "gyro_noise_density": zero, "accel_noise_density": zero, "gyro_turn_on_bias_std": zero,
        "accel_turn_on_bias_std": zero, "gyro_bias_instability": zero, "accel_bias_instability": zero,
        "gyro_bias_fixed": [0.0, 0.0, 1e-4], "accel_bias_fixed": [0.02, -0.03, 0.0]})
    imu, errs, _ = ie.apply_imu_errors(sim.imu_from_trajectory(ref), params, seed=0)
    drive = SimpleNamespace(name="still", reference=ref, imu=imu, meta={"imu_errors": errs})
    window = OutageWindow(0.0, 30.0)
    end = {}
    for tuning in ns.INS_TUNINGS:
        cfg = baseline.nav_config({**NAV, "ins_tuning": tuning})
        initial, noise = baseline.initial_and_noise(drive, cfg)
        res = run_outage(baseline.filter_imu(drive, cfg), initial, window, noise)
        end[tuning] = metrics.navigation_errors(res.trajectory, ref).iloc[-1]
    # shipped: the bias is not known, the position runs off as b t^2 / 2 (9 m north, -13.5 m east)
    assert end["shipped"]["north"] == pytest.approx(0.5 * 0.02 * 30.0 ** 2, rel=0.02)
    assert end["shipped"]["east"] == pytest.approx(-0.5 * 0.03 * 30.0 ** 2, rel=0.02)
    assert end["shipped"]["yaw"] == pytest.approx(1e-4 * 30.0, rel=0.02)
    # navego: the profile's static biases are removed, the INS stays where it is
    assert abs(end["navego"]["north"]) < 1e-3 and abs(end["navego"]["east"]) < 1e-3
    assert abs(end["navego"]["yaw"]) < 1e-7


def test_the_evaluation_reads_the_same_setup(drive):
    nav = {**NAV, "ins_tuning": "navego"}
    cfg = baseline.nav_config(nav)
    ctx = ev.navigation_context(drive, nav, [s for s, _ in WINDOWS])
    errs = drive.meta["imu_errors"]
    np.testing.assert_array_equal(ctx.imu_static[3:6], errs["accel_bias_fixed"])    # CHANNELS order
    np.testing.assert_array_equal(ctx.imu_static[6:9], errs["gyro_bias_fixed"])
    np.testing.assert_array_equal(ctx.imu[:, 0], drive.imu["accel_x"])               # network inputs: raw IMU
    s, d = WINDOWS[1]
    run = ev.run_outages(ctx, [WINDOWS[1]], None)[0]
    ref = run_outage(baseline.filter_imu(drive, cfg), ctx.state_at(s), OutageWindow(s, d), ctx.noise, ctx.lever)
    np.testing.assert_allclose(run.trajectory[["lat", "lon"]].to_numpy(), ref.trajectory[["lat", "lon"]].to_numpy(),
                               rtol=0, atol=1e-12)
    # ... and the INS row of notebook 02's baseline with the same key
    b = baseline.run_baseline(drive, cfg, WINDOWS)
    assert run.errors["east"].abs().max() == pytest.approx(b.outage_table["max_abs_east"].iloc[1], abs=1e-9)


def test_navegos_bias_estimates_are_held_through_an_outage_where_the_shipped_ones_relax(drive):
    # NaveGo corrects every IMU sample with its last estimate (ins_gnss.m lines 251-252): 60 s of standalone INS
    # end with the estimate it started with; a Gauss-Markov estimate relaxes as exp(-t / tau) toward zero
    noise = ns.navego_noise(drive.meta["imu_errors"])
    row = drive.reference.iloc[0]
    start = st.initial_state(row, st.initial_covariance(row[["lat", "lon", "h"]].to_numpy(float), noise, 1.0, 2.0,
                                                        0.1, 0.003, 0.01))
    start.gyro_bias[:], start.accel_bias[:] = [1e-3, -2e-3, 3e-3], [0.05, -0.02, 0.01]
    imu = drive.imu[drive.imu["time"] <= float(row["time"]) + 60.0]
    held = run_filter(imu, start, noise).bias.iloc[-1]
    relaxed = run_filter(imu, start, replace(noise, hold_bias_estimates=False)).bias.iloc[-1]
    t = float(held["time"]) - float(row["time"])
    for sensor, b0, tau in (("gyro", start.gyro_bias, noise.gyro_bias_tau), ("accel", start.accel_bias,
                                                                           noise.accel_bias_tau)):
        cols = [f"{sensor}_bias_{a}" for a in "xyz"]
        np.testing.assert_array_equal(held[cols].to_numpy(float), b0)
        np.testing.assert_allclose(relaxed[cols].to_numpy(float), b0 * np.exp(-t / tau), rtol=1e-9)


# ----------------------------------------------------------------------------------------------- the table
def test_ins_tuning_table_runs_every_setup_beside_the_papers_row(drive, tmp_path):
    cfg = baseline.nav_config(NAV)
    shipped = baseline.run_baseline(drive, cfg, WINDOWS)
    table = ins_setups.ins_tuning_table(drive, cfg, WINDOWS, baseline=shipped)
    assert list(table.columns) == list(ins_setups.COLUMNS)
    # NaveGo's own run (make navego-check) has no row for this synthetic drive
    assert table["setup"].tolist() == [s for s in ins_setups.SETUPS if "Octave" not in s for _ in (1, 2)]
    assert set(table["test"]) == {"dataset"}
    rows = table.set_index(["setup", "outage"])
    navego = baseline.run_baseline(drive, {**cfg, "ins_tuning": "navego"}, WINDOWS)
    for k in (1, 2):
        assert rows.loc[("shipped", k), "max_east_m"] == shipped.outage_table["max_abs_east"].iloc[k - 1]
        assert rows.loc[("navego", k), "max_north_m"] == navego.outage_table["max_abs_north"].iloc[k - 1]
        p = paper.outage_table("dataset").query("method == 'INS' and outage == @k").iloc[0]
        assert (rows.loc[("paper", k), "max_east_m"], rows.loc[("paper", k), "max_north_m"]) == (
            p["max_east_m"], p["max_north_m"])
    # the run without the reuse gives the same table
    pd.testing.assert_frame_equal(ins_setups.ins_tuning_table(drive, cfg, WINDOWS), table)
    # a tactical IMU's dynamic-bias estimates are small: clearing them at the start changes little
    reset, nav = (table[table["setup"] == s][["max_east_m", "max_north_m"]].to_numpy() for s in ("navego-reset", "navego"))
    np.testing.assert_allclose(reset, nav, rtol=0.05, atol=0.05)
    lay = ins_setups.layout(table, drive.name)
    assert list(lay.index) == ["Outage 1", "Outage 2"]
    assert lay[("paper", "North")].tolist() == [23.2, 19.6]
    assert lay[("navego-reset", "East")].iloc[0] == rows.loc[("navego-reset", 1), "max_east_m"]
    # several drives at once, from a profile's nav: section, reusing notebook 02's runs
    both = ins_setups.ins_tuning_tables([drive], NAV, WINDOWS, baselines={drive.name: shipped})
    pd.testing.assert_frame_equal(both, table)
    stacked = ins_setups.layouts(both)
    assert stacked.index.get_level_values("dataset").unique().tolist() == [drive.name]
    pd.testing.assert_frame_equal(stacked.loc[drive.name], lay)
    path = ins_setups.save_table(tmp_path, table)
    assert path.name == "kf_ins_tuning.csv"
    back = ins_setups.read_table(tmp_path)
    np.testing.assert_allclose(back[["max_east_m", "max_north_m"]].to_numpy(),
                               table[["max_east_m", "max_north_m"]].to_numpy(), rtol=1e-5)
    assert ins_setups.read_table(tmp_path / "missing") is None


def test_the_navego_row_does_not_depend_on_the_static_bias_it_removes():
    # Two drives that differ only in their static biases (same seed, so the same noise and dynamic biases):
    # NaveGo's setup removes them exactly, the shipped filter has to estimate them.
    small = _drive(seed=7)
    big = _drive(seed=7)
    errs = {**big.meta["imu_errors"], "gyro_bias_fixed": [1e-3, -1.5e-3, 2e-3],
            "accel_bias_fixed": [0.15, -0.1, 0.1]}
    imu = big.imu.copy()
    for s in ("gyro", "accel"):
        for i, a in enumerate("xyz"):
            imu[f"{s}_{a}"] += errs[f"{s}_bias_fixed"][i] - small.meta["imu_errors"][f"{s}_bias_fixed"][i]
    big = Drive(big.name, big.reference, imu, big.gnss, {**big.meta, "imu_errors": errs})
    cfg = baseline.nav_config(NAV)
    a, b = (ins_setups.ins_tuning_table(d, cfg, WINDOWS).set_index(["setup", "outage"]) for d in (small, big))
    cols = ["max_east_m", "max_north_m"]
    np.testing.assert_allclose(a.loc["navego", cols].to_numpy(), b.loc["navego", cols].to_numpy(), atol=1e-6)
    assert np.abs(a.loc["shipped", cols].to_numpy() - b.loc["shipped", cols].to_numpy()).max() > 0.01


def _table(values):
    rows = [("turin-sim-ekinox", "dataset", o, s, e, n, 1.0, 0.1, 1.7, 0.05, 0.8) for s, o, e, n in values]
    return pd.DataFrame(rows, columns=list(ins_setups.COLUMNS))


def test_gap_explained_and_its_sentences():
    table = _table([("shipped", 1, 2.0, 4.0), ("shipped", 2, 2.0, 4.0), ("navego", 1, 6.0, 8.0),
                    ("navego", 2, 6.0, 8.0), ("navego-reset", 1, 1.0, 1.0), ("navego-reset", 2, 1.0, 1.0),
                    ("paper", 1, 12.0, 14.0), ("paper", 2, 12.0, 14.0)])
    gap = ins_setups.gap_explained(table).set_index("setup")
    # sizes: shipped 3 m, navego 7 m, reset 1 m, paper 13 m -> (7 - 3) / (13 - 3), (1 - 3) / (13 - 3)
    assert gap.loc["navego", "explained_pct"] == pytest.approx(40.0)
    assert gap.loc["navego-reset", "explained_pct"] == pytest.approx(-20.0)
    assert gap.loc["navego", ["shipped_m", "setup_m", "paper_m"]].tolist() == [3.0, 7.0, 13.0]
    (line,) = ins_fidelity_words.ins_setup_sentences(table)
    assert "3.0 m with the shipped filter against the paper's 13.0 m" in line
    assert "7.0 m, so it explains 40 % of the gap" in line
    assert "moves away from the paper's row (-20 % of the gap)" in line
    over = _table([("shipped", 1, 2.0, 2.0), ("navego", 1, 30.0, 30.0), ("paper", 1, 12.0, 12.0)])
    assert "overshoots the paper's row (280 % of the gap)" in ins_fidelity_words.ins_setup_sentences(over)[0]
    # NaveGo's own run beside our setup of it: the ratio, and both GPS-aided solutions (NaveGo's far off here)
    own = _table([("shipped", 1, 2.0, 2.0), ("navego", 1, 30.0, 30.0), ("NaveGo (Octave)", 1, 60.0, 60.0),
                  ("paper", 1, 12.0, 12.0)])
    own.loc[own["setup"] == "NaveGo (Octave)", ["aided_rms_h_m", "max_gyro_bias_est_dps",
                                                "max_accel_bias_est_mps2"]] = [190.0, 44.0, 3.1]
    line = ins_fidelity_words.ins_setup_sentences(own)[0]
    assert ("the largest gyro-bias estimate over the drive is 44 deg/s in NaveGo, 0.1 deg/s in our setup of it, "
            "against the drive's largest true gyro bias of 1.7 deg/s") in line
    assert ("the largest accelerometer-bias estimate over the drive is 3.1 m/s^2 in NaveGo, 0.05 m/s^2 in our setup "
            "of it, against the drive's largest true accelerometer bias of 0.8 m/s^2") in line
    assert "Our setup of NaveGo gives 0.50 times NaveGo's own INS error (more than 30 % apart" in line
    assert "190.0 m horizontal RMS for NaveGo, 1.0 m for our setup of it (NaveGo's own filter loses" in line
    assert "bias feedback made consistent" not in line          # that run is not in this table
    # ... and NaveGo with its bias feedback made consistent (make navego-check's diagnostic run): 30 / 25 = 1.2
    fixed = pd.concat([own, _table([(ins_setups.NAVEGO_CONSISTENT, 1, 25.0, 25.0)])], ignore_index=True)
    fixed.loc[fixed["setup"] == ins_setups.NAVEGO_CONSISTENT, "aided_rms_h_m"] = 4.2
    line = ins_fidelity_words.ins_setup_sentences(fixed)[0]
    assert "With NaveGo's bias feedback made consistent" in line
    assert "our setup gives 1.20 times its INS error (within 30 %); its GPS-aided RMS is 4.2 m" in line
    assert ins_setups.gap_explained(fixed).set_index("setup").loc[ins_setups.NAVEGO_CONSISTENT, "setup_m"] == 25.0
    # a dataset that stands for no paper test has no gap to explain
    assert ins_setups.gap_explained(over.assign(dataset="synthetic").query("setup != 'paper'")).empty


def test_navegos_own_rows_are_read_for_the_profiles_outages_only(tmp_path):
    path = tmp_path / "navego_check.csv"
    pd.DataFrame([{"dataset": "d", "outage": 1, "start_s": 100.0, "duration_s": 30.0, "max_east_m": 5.0,
                   "max_north_m": 6.0, "aided_rms_h_m": 0.5, "setting": "position only", "navego": "v1.4",
                   "octave": "8", "date": "2026-11-25", "commit": "abc"},
                  {"dataset": "d", "outage": 2, "start_s": 300.0, "duration_s": 30.0, "max_east_m": 7.0,
                   "max_north_m": 8.0, "aided_rms_h_m": 0.5, "setting": "position only", "navego": "v1.4",
                   "octave": "8", "date": "2026-11-25", "commit": "abc"}]).to_csv(path, index=False)
    # the profile's outages: the second one measured (now its Outage 1), the first one not
    got = ins_setups.navego_measured("d", [(300.0, 30.0), (500.0, 30.0)], path)
    assert got[["outage", "max_east_m"]].values.tolist() == [[1, 7.0]]
    assert ins_setups.navego_measured("other", [(300.0, 30.0)], path).empty
    assert ins_setups.navego_measured("d", [(300.0, 30.0)], tmp_path / "missing.csv").empty
    # a file with both of make navego-check's runs: each variant reads its own rows (no column: the released one)
    both = pd.read_csv(path).assign(variant="as released")
    both = pd.concat([both, both.assign(variant="bias feedback consistent", max_east_m=[1.0, 2.0])])
    both.to_csv(path, index=False)
    assert ins_setups.navego_measured("d", [(300.0, 30.0)], path)["max_east_m"].tolist() == [7.0]
    assert ins_setups.navego_measured("d", [(300.0, 30.0)], path,
                                      variant="bias feedback consistent")["max_east_m"].tolist() == [2.0]

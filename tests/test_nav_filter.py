"""The 15-state loosely coupled filter: consistency, pyins cross-check, outages, pseudo-GPS, bad input."""


import numpy as np
import pandas as pd
import pytest
from scipy.stats import chi2

from bgfn.data import imu_errors as ie
from bgfn.errors import DataError
from bgfn.nav import error_model as em
from bgfn.nav import earth, metrics, sim, transform
from bgfn.nav import state as st
from bgfn.nav.filter import run_filter, run_outage
from bgfn.nav.outages import IncrementPseudoGps, OutageWindow, TablePseudoGps

LEVER = np.array([0.5, -0.3, -1.2])
WINDOWS = [(90.0, 30.0), (210.0, 30.0)]


def _drive(duration, seed, overrides=None, std=(1.0, 1.0, 2.0)):
    ref = sim.demo_trajectory(duration)
    imu_true = sim.imu_from_trajectory(ref)
    params = ie.error_params("ekinox-d", overrides)
    speed = np.hypot(ref["v_n"], ref["v_e"]).to_numpy()[1:]
    imu, errs, bias = ie.apply_imu_errors(imu_true, params, seed=seed, speed=speed)
    gnss = sim.gnss_from_trajectory(ref, 1.0, std[0], std[2], LEVER, seed=seed + 1)
    return ref, imu_true, imu, errs, bias, gnss


def _setup(ref, errs, seed=None, pos_std=1.0):
    noise = st.noise_from_imu_errors(errs)
    P0 = st.initial_covariance(ref.iloc[0][["lat", "lon", "h"]].to_numpy(float), noise, pos_std, 2.0, 0.1,
                               np.radians(0.2), np.radians(1.0))
    rng = None if seed is None else np.random.default_rng(seed)
    return st.initial_state(ref.iloc[0], P0, rng), noise


@pytest.fixture(scope="module")
def drive300():
    return _drive(300.0, seed=11)


def test_nees_of_position_inside_95_band_with_matched_model():
    # Gauss-Markov biases with long correlation times: the filter's random-walk model is then exact.
    ref, _, imu, errs, _, gnss = _drive(600.0, seed=21, overrides={"gyro_bias_corr_time": 3600.0,
                                                                   "accel_bias_corr_time": 3600.0})
    init, noise = _setup(ref, errs, seed=5)
    res = run_filter(imu, init, noise, gnss, LEVER)
    assert len(res.updates) == 600 and (res.updates["kind"] == "gnss").all()
    rows = np.searchsorted(res.trajectory["time"].to_numpy(), res.updates["time"].to_numpy() - 1e-9)
    tr = res.trajectory.iloc[rows]
    rf = metrics.align(tr, ref)
    e = tr[["lat", "lon", "h"]].to_numpy() - rf[["lat", "lon", "h"]].to_numpy()
    p = res.P_updates[:, em.POS][:, :, em.POS]
    nees = np.einsum("ni,nij,nj->n", e, np.linalg.inv(p), e)
    lo, hi = chi2.ppf([0.025, 0.975], 3)
    assert np.mean((nees > lo) & (nees < hi)) >= 0.90
    assert 2.0 < nees.mean() < 4.0
    assert 2.5 < res.updates["nis"].mean() < 3.5  # NIS ~ chi2(3)


def test_perfect_imu_and_gnss_keep_the_truth(drive300):
    ref, imu_true, *_ = drive300
    errs = ie.error_params("ekinox-d")
    init, noise = _setup(ref, errs)
    gnss = sim.gnss_from_trajectory(ref, 1.0, 0.0, 0.0, LEVER)
    gnss[["std_n", "std_e", "std_d"]] = 0.5
    res = run_filter(imu_true, init, noise, gnss, LEVER)
    e = metrics.navigation_errors(res.trajectory, ref)
    assert e["horizontal"].max() < 0.01 and np.abs(e["down"]).max() < 0.01
    assert np.abs(e[["roll", "pitch", "yaw"]].to_numpy()).max() < 1e-4
    assert np.abs(res.bias.iloc[-1, 1:].to_numpy()).max() < 1e-4


def test_biases_are_estimated_within_their_sd():
    ref, _, imu, errs, bias, gnss = _drive(300.0, seed=31, overrides={
        "accel_bias_fixed": [0.02, -0.03, 0.05], "gyro_bias_fixed": [2e-4, -3e-4, 5e-4],
        "gyro_bias_corr_time": 3600.0, "accel_bias_corr_time": 3600.0})
    init, noise = _setup(ref, errs)
    res = run_filter(imu, init, noise, gnss, LEVER)
    est = res.bias.iloc[-1]
    sd = res.sd.iloc[-1]
    true = bias.iloc[-1]
    for axis in "xyz":
        for sensor, state in (("accel", "nabla"), ("gyro", "eps")):
            err = est[f"{sensor}_bias_{axis}"] - true[f"{sensor}_bias_{axis}"]
            assert abs(err) < 4 * sd[f"{state}_{axis}"] + 1e-12, (sensor, axis)
    # Vertical accelerometer bias and heading gyro bias are well observed: close to the truth.
    assert abs(est["accel_bias_z"] / true["accel_bias_z"] - 1) < 0.1
    assert abs(est["gyro_bias_z"] / true["gyro_bias_z"] - 1) < 0.25


def test_agrees_with_pyins_feedback_filter(drive300):
    pytest.importorskip("pyins")
    from bgfn.nav.pyins_bridge import feedback_filter

    ref, _, imu, errs, _, _ = drive300
    gnss = sim.gnss_from_trajectory(ref, 1.0, 1.0, 1.0, LEVER, seed=3)  # pyins: one sd for all axes
    init, noise = _setup(ref, errs, seed=4)
    ours = run_filter(imu, init, noise, gnss, LEVER, outage_windows=WINDOWS)
    g = gnss[~np.any([OutageWindow(*w).contains(gnss["time"]) for w in WINDOWS], axis=0)]
    tp = feedback_filter(init, noise, imu, g, LEVER, 1.0, 0.1, 0.2, 1.0, gnss_sd=1.0)()
    e_ours = metrics.navigation_errors(ours.trajectory, ref)
    e_theirs = metrics.navigation_errors(tp, ref)
    t_ = e_ours["time"].to_numpy()
    with_gps = ~np.any([(t_ >= s) & (t_ < s + d + 30.0) for s, d in WINDOWS], axis=0)  # 30 s to reconverge
    rms = [np.sqrt(np.mean(e["horizontal"].to_numpy()[with_gps] ** 2)) for e in (e_ours, e_theirs)]
    assert abs(rms[0] / rms[1] - 1) < 0.25
    for s, d in WINDOWS:
        m = [metrics.outage_metrics(e, OutageWindow(s, d))["max_horizontal"] for e in (e_ours, e_theirs)]
        assert abs(m[0] / m[1] - 1) < 0.5, (s, m)


def test_outage_from_saved_state_equals_full_run(drive300, tmp_path):
    ref, _, imu, errs, _, gnss = drive300
    init, noise = _setup(ref, errs, seed=6)
    full = run_filter(imu, init, noise, gnss, LEVER, outage_windows=WINDOWS,
                      snapshots={"outage_1": WINDOWS[0][0], "outage_2": WINDOWS[1][0]})
    path = st.save_states(tmp_path / "states.npz", full.states)
    states = st.load_states(path)
    assert list(states) == ["outage_1", "outage_2"]
    for name, (s, d) in zip(states, WINDOWS):
        np.testing.assert_array_equal(states[name].P, full.states[name].P)
        assert states[name].time == pytest.approx(s)
        out = run_outage(imu, states[name], (s, d), noise, LEVER)
        assert out.trajectory["time"].iloc[0] == pytest.approx(s)
        assert out.trajectory["time"].iloc[-1] == pytest.approx(s + d)
        assert len(out.trajectory) == int(round(d * 100)) + 1  # only the window's own IMU rows
        # Same numbers as the full run inside the window (before its first GNSS update at the window end).
        seg = full.trajectory[(full.trajectory["time"] >= s - 1e-6) & (full.trajectory["time"] < s + d - 1e-6)]
        cols = ["lat", "lon", "h", "v_n", "v_e", "v_d"]
        np.testing.assert_allclose(out.trajectory[cols].to_numpy()[:-1], seg[cols].to_numpy(), rtol=0, atol=1e-12)
        assert out.updates.empty
        # Prediction only: the covariance grows, biases are held.
        assert out.sd["dL"].iloc[-1] > out.sd["dL"].iloc[0]
        np.testing.assert_array_equal(out.bias.iloc[-1, 1:].to_numpy(), out.bias.iloc[0, 1:].to_numpy())


def test_pseudo_gps_hook_bounds_the_outage_error(drive300):
    ref, _, imu, errs, _, gnss = drive300
    init, noise = _setup(ref, errs, seed=7)
    s, d = WINDOWS[0]
    full = run_filter(imu, init, noise, gnss, LEVER, snapshots={"o": s})
    start = full.states["o"]
    ins = metrics.outage_metrics(metrics.navigation_errors(run_outage(imu, start, (s, d), noise, LEVER).trajectory,
                                                           ref), OutageWindow(s, d))
    # Eq. (pred-gps) with the true antenna increments (north/east) every second.
    t = np.arange(s, s + d + 0.5, 1.0)
    rows = metrics.align(pd.DataFrame({"time": t}), ref)
    ant = np.array([st.FilterState(0, r[["lat", "lon", "h"]].to_numpy(float), np.zeros(3),
                                   transform.dcm_from_euler(r["roll"], r["pitch"], r["yaw"])).antenna_position(LEVER)
                    for _, r in rows.iterrows()])
    ned = earth.lla_to_ned(ant[:, 0], ant[:, 1], ant[:, 2], *ant[0])
    inc = pd.DataFrame({"time": t[1:], "delta_p_n": np.diff(ned[:, 0]), "delta_p_e": np.diff(ned[:, 1])})
    hook = IncrementPseudoGps(inc, std_n=0.3, std_e=0.3)
    aided = run_outage(imu, start, (s, d), noise, LEVER, pseudo_gps=hook)
    assert len(aided.updates) == 30 and (aided.updates["kind"] == "pseudo").all()
    assert (aided.updates["dof"] == 2).all()  # height not fused (2-D increments, Eq. eq21)
    m = metrics.outage_metrics(metrics.navigation_errors(aided.trajectory, ref), OutageWindow(s, d))
    assert m["max_horizontal"] < 0.5 * ins["max_horizontal"]
    # A table source with fixes equal to the GNSS fixes behaves like GNSS (small error).
    table = run_outage(imu, start, (s, d), noise, LEVER, pseudo_gps=TablePseudoGps(gnss))
    mt = metrics.outage_metrics(metrics.navigation_errors(table.trajectory, ref), OutageWindow(s, d))
    assert mt["max_horizontal"] < 3.0 and len(table.updates) == 30


@pytest.mark.parametrize("windows,match", [
    ([(-50.0, 30.0)], "inside the data"),
    ([(290.0, 30.0)], "inside the data"),
    ([(50.0, 30.0), (70.0, 30.0)], "non-overlapping"),
    ([(50.0, 0.0)], "positive duration"),
    ([(50.0, -5.0)], "positive duration"),
    ([(np.nan, 5.0)], "finite"),
])
def test_bad_outage_windows_raise(drive300, windows, match):
    ref, _, imu, errs, _, gnss = drive300
    init, noise = _setup(ref, errs)
    with pytest.raises(DataError, match=match):
        run_filter(imu, init, noise, gnss, LEVER, outage_windows=windows, t_end=100.0)


def test_imu_gap_and_bad_tables_raise(drive300):
    ref, _, imu, errs, _, gnss = drive300
    init, noise = _setup(ref, errs)
    with pytest.raises(DataError, match="gap"):
        run_filter(imu.drop(index=range(500, 506)), init, noise, gnss, LEVER, t_end=20.0)
    with pytest.raises(DataError, match="std_d"):
        run_filter(imu, init, noise, gnss.drop(columns="std_d"), LEVER, t_end=20.0)
    with pytest.raises(DataError, match="gyro_noise_density"):
        st.noise_from_imu_errors({k: v for k, v in errs.items() if k != "gyro_noise_density"})
    with pytest.raises(DataError, match="snapshots"):
        run_filter(imu, init, noise, gnss, LEVER, t_end=20.0, snapshots={"x": 1000.0})


def test_innovation_gate_rejects_a_jump_as_if_the_fix_were_missing(drive300):
    ref, _, imu, errs, _, gnss = drive300
    init, noise = _setup(ref, errs)
    jumped = gnss.copy()
    k = 150                                                     # a 20 m jump north at t = 150 s
    r_m, _ = earth.curvature_radii(jumped.loc[k, "lat"])
    jumped.loc[k, "lat"] += 20.0 / (r_m + jumped.loc[k, "h"])
    gated = run_filter(imu, init, noise, jumped, LEVER, gate_probability=0.999)
    assert gated.updates["accepted"].sum() == len(gnss) - 1
    (bad,) = np.flatnonzero(~gated.updates["accepted"].to_numpy())
    assert gated.updates.loc[bad, "time"] == pytest.approx(gnss.loc[k, "time"])
    assert gated.updates.loc[bad, "nis"] > chi2.ppf(0.999, 3)
    # rejecting the fix is exactly not having it
    without = run_filter(imu, init, noise, gnss.drop(index=k), LEVER)
    np.testing.assert_array_equal(gated.trajectory[["lat", "lon", "h"]].to_numpy(),
                                  without.trajectory[["lat", "lon", "h"]].to_numpy())
    # the paper's filter (no gate) fuses it and is pulled north by metres
    fused = run_filter(imu, init, noise, jumped, LEVER)
    assert fused.updates["accepted"].all()
    e_fused = metrics.navigation_errors(fused.trajectory, ref)
    e_gated = metrics.navigation_errors(gated.trajectory, ref)
    at = np.argmin(np.abs(e_fused["time"].to_numpy() - gnss.loc[k, "time"]))
    assert e_fused["north"].iloc[at] > 3.0 > abs(e_gated["north"].iloc[at])


def test_gate_nis_is_the_sum_of_the_sequential_nis(drive300):
    from bgfn.nav.engine import fuse, measurement_nis
    from bgfn.nav.gnss_aid import position_measurement

    ref, _, imu, errs, _, gnss = drive300
    init, noise = _setup(ref, errs)
    state = run_filter(imu, init, noise, gnss, LEVER, t_end=100.4).final   # P after 100 fixes
    fix = gnss.loc[100, ["lat", "lon", "h"]].to_numpy(float) + np.array([3e-7, -2e-7, 1.5])
    std = np.array([1.0, 1.0, 2.0])
    dz, H = np.empty(3), np.empty((3, 15))
    position_measurement(state.pos, state.v, state.c_bn, LEVER, fix, 0.0, dz, H)
    batch, dof = measurement_nis(state.P, H, dz, std)
    S = H @ state.P @ H.T + np.diag(std ** 2)
    assert dof == 3 and batch == pytest.approx(dz @ np.linalg.solve(S, dz), rel=1e-12)
    args = [a.copy() for a in (state.pos, state.v, state.c_bn, state.accel_bias, state.gyro_bias, state.P)]
    sequential, accepted = fuse(*args, H, dz, std, 0.0, np.empty(3))
    assert accepted and sequential == pytest.approx(batch, rel=1e-9)
    # a gate below it rejects the fix and leaves the state untouched
    args = [a.copy() for a in (state.pos, state.v, state.c_bn, state.accel_bias, state.gyro_bias, state.P)]
    nis, accepted = fuse(*args, H, dz, std, 0.5 * batch, np.empty(3))
    assert not accepted and nis == pytest.approx(batch)
    np.testing.assert_array_equal(args[0], state.pos)
    np.testing.assert_array_equal(args[5], state.P)


@pytest.mark.parametrize("bad", [1.0, 1.5, -0.1, "high"])
def test_gate_probability_must_be_a_probability(bad):
    from bgfn.nav.baseline import nav_config

    with pytest.raises(DataError, match="innovation_gate"):
        nav_config({"innovation_gate": bad})
    assert nav_config({"innovation_gate": None})["innovation_gate"] is None

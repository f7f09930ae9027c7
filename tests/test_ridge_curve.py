"""RIDGE-ODO's learning curve (bgfn.studies.odometer.ridge_curve) on synthetic windows whose vibration power says the speed:
more folds hold out less and so train on more windows, every start is predicted by a ridge that never saw it, and
a speed the band energies determine is learned at every number of folds."""

import numpy as np
import pandas as pd
import pytest

from bgfn.studies.odometer import ridge_curve as RC
from bgfn.learning import odometry as lo
from bgfn.report import odometer_words

RATE, WINDOW = 100.0, 200                                  # 2 s windows at 100 Hz, one per second
STARTS = [100.0 + 40.0 * k for k in range(10)]             # ten 30 s outages, 40 s apart


def windows(speed_fn, seed=0, n=600):
    """One window per second; axis x vibrates with an amplitude exp(speed / 10), so its log band power is linear
    in the speed (what the ridge fits); the other axes are unit noise."""
    rng = np.random.default_rng(seed)
    t_end = np.arange(WINDOW / RATE, n + WINDOW / RATE)
    speed = speed_fn(t_end)
    x = rng.standard_normal((t_end.size, WINDOW, 6)).astype(np.float32)
    x[:, :, 0] *= np.exp(speed / 10.0)[:, None]
    return lo.SpeedWindows(x, speed, t_end, t_end - WINDOW / RATE)


def plans(*counts):
    return {n: pd.DataFrame({"start_s": STARTS,
                             "fold": np.concatenate([np.full(len(b), k) for k, b in
                                                     enumerate(np.array_split(np.arange(len(STARTS)), n))])})
            for n in counts}


def curve(train_ws, all_ws, truth, *counts):
    return RC.ridge_curve("synthetic", plans(*counts), train_ws, all_ws, truth, 30.0, margin_s=5.0,
                          val_fraction=0.2, val_blocks=2, alpha=1.0, rate_hz=RATE).set_index("folds")


def speed(t):
    return 8.0 + 5.0 * np.sin(2 * np.pi * t / 97.0)


def test_more_folds_train_on_more_windows_and_every_start_is_scored_once():
    ws = windows(speed)
    c = curve(ws, ws, ws.speed, 1, 2, 5, 10)
    assert list(c.index) == [1, 2, 5, 10]
    assert np.all(np.diff(c["n_train"].to_numpy()) > 0)                  # each fold holds out fewer outages
    assert (c["starts"] == len(STARTS)).all() and (c["duration_s"] == 30.0).all()


def test_a_speed_the_band_energies_determine_is_learned_at_every_number_of_folds():
    ws = windows(speed)
    c = curve(ws, ws, ws.speed, 2, 10)
    assert (c["outage_speed_rmse_mps"] < 0.6).all()                      # the speed spans 3 to 13 m/s
    assert (c["val_std_mps"] < 0.6).all() and (c["outage_coverage_2sigma"] > 0.8).all()


def test_the_held_out_outages_never_train_their_own_ridge():
    clean = windows(speed)
    # the training targets inside every outage (+- the margin) are wild; a ridge that learned from them would miss
    inside = np.zeros(clean.speed.size, bool)
    for s in STARTS:
        inside |= (clean.t_end > s - 5.0) & (clean.t_start < s + 35.0)
    poisoned = lo.SpeedWindows(clean.x, np.where(inside, 100.0, clean.speed), clean.t_end, clean.t_start)
    c = curve(poisoned, clean, clean.speed, 1)
    # one fold holds out every outage: none of the wild targets trains it
    assert c.loc[1, "outage_speed_rmse_mps"] < 1.0
    # with two folds each ridge trains on the other fold's outages, wild there: the held-out starts see the harm
    assert curve(poisoned, clean, clean.speed, 2).loc[2, "outage_speed_rmse_mps"] > 5.0


def test_lines_name_the_folds_and_windows():
    ws = windows(speed)
    line = odometer_words.curve_lines(curve(ws, ws, ws.speed, 2, 5).reset_index())[0]
    assert line.startswith("synthetic: RIDGE-ODO's speed RMSE") and "2 folds" in line and "5 folds" in line
    with pytest.raises(Exception):
        RC.ridge_curve("synthetic", {2: pd.DataFrame(columns=["start_s", "fold"])}, ws, ws, ws.speed, 30.0, 5.0,
                       0.2, 2, 1.0, RATE)


def test_the_curve_figure_draws_each_drive_against_its_training_windows():
    curve = pd.DataFrame({"dataset": ["a", "a", "b", "b"], "folds": [20, 2, 2, 20], "n_train": [250.0, 125.0, 400, 800],
                          "val_std_mps": [2.0, 1.9, 3.0, 3.1], "duration_s": 120.0,
                          "outage_speed_rmse_mps": [2.2, 2.3, 3.5, 2.9], "outage_coverage_2sigma": 0.9, "starts": 20})
    fig = RC.plot_curve(curve)
    lines = fig.axes[0].get_lines()
    assert len(lines) == 4                                               # per drive: outages and validation std
    np.testing.assert_array_equal(lines[0].get_xdata(), [125.0, 250.0])  # sorted by training windows
    np.testing.assert_array_equal(lines[0].get_ydata(), [2.3, 2.2])
    np.testing.assert_array_equal(lines[3].get_ydata(), [3.0, 3.1])

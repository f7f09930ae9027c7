"""The odometer learning problem (bgfn.learning.odometry): the forward-speed target, IMU-only windows, band
energies checked on sines, and the ridge odometer on a drive whose vibration grows with speed."""

import numpy as np
import pandas as pd
import pytest

from bgfn.errors import DataError
from bgfn.learning import odometry as od

RATE = 100.0


def test_forward_speed_is_the_body_x_velocity_turned_into_the_vehicle_frame():
    # heading 30 deg, moving along it at 10 m/s, level: forward speed 10
    sol = pd.DataFrame({"roll": [0.0, 0.1], "pitch": [0.0, 0.0], "yaw": np.radians([30.0, 30.0]),
                        "v_n": 10 * np.cos(np.radians([30.0, 30.0])), "v_e": 10 * np.sin(np.radians([30.0, 30.0])),
                        "v_d": [0.0, 0.0]})
    assert od.forward_speed(sol) == pytest.approx([10.0, 10.0])
    # the body is turned 2 deg in yaw against the direction of travel: the body x axis sees cos(2 deg) of it, the
    # vehicle frame with the matching mounting tangent all of it
    sol2 = sol.assign(yaw=np.radians(32.0))
    assert od.forward_speed(sol2)[0] == pytest.approx(10 * np.cos(np.radians(2.0)))
    assert od.forward_speed(sol2, np.array([np.tan(np.radians(-2.0)), 0.0]))[0] == pytest.approx(10.0)
    with pytest.raises(DataError, match="v_d"):
        od.forward_speed(sol.drop(columns="v_d"))


def test_band_energies_put_a_sine_in_its_band():
    t = np.arange(200) / RATE
    x = np.zeros((2, 200, 6))
    x[0, :, 0] = np.sin(2 * np.pi * 10.0 * t)            # 10 Hz on accel_x: band 3 (7.9-19.9 Hz)
    x[1, :, 0] = np.sin(2 * np.pi * 1.0 * t)             # 1 Hz: band 0 (0.5-1.26 Hz)
    f = od.band_energies(x, RATE).reshape(2, 6, len(od.BANDS_HZ))
    assert np.argmax(f[0, 0]) == 3 and np.argmax(f[1, 0]) == 0
    assert f[0, 1].max() < -20                             # a silent axis: log of ~0
    with pytest.raises(DataError, match="bands"):
        od.band_energies(x[:, :20], RATE)                  # 0.2 s: no bin below 5 Hz


def test_band_frames_follow_a_sine_that_starts_mid_window_and_keep_each_axis_mean():
    t = np.arange(200) / RATE
    x = np.zeros((1, 200, 6))
    x[0, 100:, 0] = np.sin(2 * np.pi * 15.0 * t[100:])    # 15 Hz on accel_x from 1 s on: band 2 (11.2-23.6 Hz)
    x[0, :, 2] = -9.81                                     # gravity on accel_z: a mean, no power
    f = od.band_frames(x, RATE)
    bands = od.frame_bands(RATE)
    assert bands[0][0] == pytest.approx(2.5) and bands[-1][1] == pytest.approx(50.0) and len(bands) == 4
    assert f.shape == (1, 9, 6 * (1 + 4)) and f.dtype == np.float32   # 0.4 s frames every 0.2 s of 2 s
    power = f[0, :, 6:].reshape(9, 4, 6)                   # [T, B, C]
    # frames 0-2 end before 1 s: silent; frames 5-8 lie wholly after it: the power sits in band 2
    assert power[:3, :, 0].max() < -20 and (power[5:, :, 0].argmax(axis=1) == 2).all()
    assert f[0, :, 2] == pytest.approx(np.full(9, -9.81))  # the mean column of accel_z
    assert power[:, :, 2].max() < -20
    with pytest.raises(DataError, match="inputs"):
        od.band_frames(x[:, :30], RATE)                    # 0.3 s: shorter than one frame


def test_network_inputs_keep_the_windows_and_name_a_bad_choice():
    imu, t, speed = _vibrating_drive(duration=30.0)
    ws = od.speed_windows(imu, [5.0, 6.0], 200, [1.0, 2.0])
    assert od.network_inputs(ws, "imu", RATE) is ws
    fr = od.network_inputs(ws, "band_frames", RATE)
    assert fr.x.shape == (2, 9, 30) and fr.speed.tolist() == [1.0, 2.0] and fr.t_end.tolist() == [5.0, 6.0]
    with pytest.raises(DataError, match="inputs"):
        od.network_inputs(ws, "spectrogram", RATE)


def _vibrating_drive(seed=0, duration=600.0):
    """IMU whose vibration (10-30 Hz) grows in amplitude with a slowly varying speed, and that speed."""
    rng = np.random.default_rng(seed)
    t = np.arange(int(duration * RATE)) / RATE
    speed = 10 + 8 * np.sin(2 * np.pi * t / 150.0)
    imu = pd.DataFrame({"time": t})
    for c in od.ODOMETER_CHANNELS:
        carrier = np.sin(2 * np.pi * rng.uniform(10, 30) * t + rng.uniform(0, 6))
        imu[c] = 0.05 * speed * carrier + 0.01 * rng.standard_normal(t.size)
    return imu, t, speed


def test_the_ridge_odometer_learns_speed_from_vibration_and_says_how_well():
    imu, t, speed = _vibrating_drive()
    epochs = np.arange(5.0, 595.0, 1.0)
    ws = od.speed_windows(imu, epochs, 200, np.interp(epochs, t, speed))
    assert ws.x.shape == (len(epochs), 200, 6) and np.all(ws.t_start < ws.t_end)
    train, val = ws.subset(slice(0, 400)), ws.subset(slice(450, None))
    model = od.RidgeOdometer.fit(train, val, RATE)
    err = model.predict(val) - val.speed
    assert np.sqrt(np.mean(err ** 2)) == pytest.approx(model.std_mps)
    assert model.std_mps < 0.25 * np.std(val.speed)        # far better than the mean speed (log energy ~ 2 log v)
    assert (model.predict(val) >= 0).all()
    # its residuals' correlation, from the same validation windows, travels with its track to the filter
    assert model.correlation == od.error_correlation(val.t_end, err, np.full(err.size, model.std_mps))
    assert model.track(ws).correlation == model.correlation >= 1.0
    with pytest.raises(DataError, match="windows"):
        od.RidgeOdometer.fit(train.subset(slice(0, 1)), val, RATE)


def test_error_correlation_of_white_and_ar1_errors_and_of_a_shared_offset():
    rng = np.random.default_rng(0)
    t = np.arange(20000.0)
    ones = np.ones(t.size)
    assert od.error_correlation(t, rng.standard_normal(t.size), ones) < 1.2       # white: about 1
    phi, e = 0.6, np.zeros(t.size)
    for i, w in enumerate(rng.standard_normal(t.size)[1:], start=1):
        e[i] = phi * e[i - 1] + w
    # AR(1): 1 + 2 sum phi^k = (1 + phi) / (1 - phi) = 4 (3.98 up to 10 s); normalized: the std's size is no matter
    assert od.error_correlation(t, e, 3.0 * ones) == pytest.approx(4.0, rel=0.1)
    # a shared offset is an error no averaging removes: rho about 1 at every lag up to max_lag_s (10 s)
    offset = 1.0 + 0.05 * rng.standard_normal(t.size)
    assert od.error_correlation(t, offset, ones) == pytest.approx(21.0, rel=0.02)
    # lags need min_pairs pairs: 12 epochs give lags 1 and 2 only (11 and 10 pairs)
    assert od.error_correlation(t[:12], offset[:12], ones[:12]) == pytest.approx(5.0, rel=0.02)
    # lags are multiples of step_s (the aid epochs' spacing): 2 s epochs, lags 2 ... 10 s
    assert od.error_correlation(t[::2], offset[::2], ones[::2], step_s=2.0) == pytest.approx(11.0, rel=0.02)
    # NaN residuals are left out; nothing to pair: 1 (fused as white)
    nan = offset.copy()
    nan[100:200] = np.nan
    assert od.error_correlation(t, nan, ones) == pytest.approx(21.0, rel=0.02)
    assert od.error_correlation([1.0], [0.3], [1.0]) == 1.0


def test_speed_windows_skip_epochs_without_a_full_window():
    imu, t, speed = _vibrating_drive(duration=30.0)
    ws = od.speed_windows(imu, [1.0, 2.5, 29.9, 40.0], 200)
    assert ws.t_end.tolist() == [2.5, 29.9] and np.isnan(ws.speed).all()


def test_beta_nll_by_hand_and_its_weight():
    import torch

    mean, log_var, y = torch.tensor([0.0, 1.0]), torch.tensor([0.0, np.log(4.0)]), torch.tensor([1.0, 3.0])
    # plain NLL: 0.5 (log var + r^2 / var) = 0.5 (0 + 1) and 0.5 (log 4 + 4 / 4)
    plain = 0.5 * ((0 + 1) + (np.log(4.0) + 1)) / 2
    assert float(od.beta_nll(mean, log_var, y, beta=0.0)) == pytest.approx(plain)
    # beta 0.5: each term times its std (1 and 2)
    assert float(od.beta_nll(mean, log_var, y, beta=0.5)) == pytest.approx((0.5 * 1 + 0.5 * (np.log(4.0) + 1) * 2) / 2)
    # the weight is detached: with beta = 1 the mean's gradient is the MSE's, -(y - mean) / 2 per sample here
    m = mean.clone().requires_grad_(True)
    od.beta_nll(m, log_var, y, beta=1.0).backward()
    assert m.grad.tolist() == pytest.approx([-0.5, -1.0])


def test_calibration_factor_makes_the_normalized_residuals_unit():
    rng = np.random.default_rng(0)
    r = rng.normal(0, 2.0, 100000)
    k = od.calibration_factor(r, np.full(r.size, 1.0))          # the std said 1, the errors are 2
    assert k == pytest.approx(2.0, rel=0.01)
    assert od.calibration_factor(r, np.full(r.size, k)) == pytest.approx(1.0, rel=1e-9)
    with pytest.raises(DataError, match="calibration"):
        od.calibration_factor([np.nan], [1.0])


def test_speed_data_split_is_honest():
    imu, t, speed = _vibrating_drive()
    epochs = np.arange(5.0, 595.0, 1.0)
    ws = od.speed_windows(imu, epochs, 200, np.interp(epochs, t, speed))
    data = od.build_speed_data(ws, [(300.0, 30.0)], margin_s=10.0, val_fraction=0.2)
    for part in (data.train, data.val):                     # nothing touches the outage +- margin
        assert not ((part.t_end > 290.0) & (part.t_start < 340.0)).any()
    assert data.val.t_start.min() > data.train.t_end.max() or data.val.t_end.max() < data.train.t_start.min() or \
        not ((data.train.t_end >= data.val.t_start.min()) & (data.train.t_start <= data.val.t_end.max())).any()
    assert data.norm.y_mean[0] == pytest.approx(data.train.speed.mean())
    assert data.options["objective"] == "speed" and data.train.y.shape == (len(data.train), 1)


def test_validation_blocks_spread_over_the_drive_and_keep_away_from_training():
    imu, t, speed = _vibrating_drive()
    epochs = np.arange(5.0, 595.0, 1.0)
    ws = od.speed_windows(imu, epochs, 200, np.interp(epochs, t, speed))
    one = od.build_speed_data(ws, [(300.0, 30.0)], margin_s=10.0, val_fraction=0.2)
    four = od.build_speed_data(ws, [(300.0, 30.0)], margin_s=10.0, val_fraction=0.2, val_blocks=4)
    assert len(four.val) == len(one.val)                   # the same share of the windows
    # four runs of consecutive epochs, one in each quarter of the remaining windows (the outage splits none)
    runs = np.split(four.val.t_end, np.flatnonzero(np.diff(four.val.t_end) > 1.5) + 1)
    assert len(runs) == 4 and [round(float(np.mean(r)) // 150) for r in runs] == [0, 1, 2, 3]
    # one block: the middle of the drive only (around the outage, which it skips)
    assert one.val.t_end.min() > 150 and one.val.t_end.max() < 450
    for data in (one, four):                               # no training window touches a validation window
        lo_, hi_ = data.val.t_start, data.val.t_end
        assert not ((data.train.t_start[:, None] <= hi_[None]) & (lo_[None] <= data.train.t_end[:, None])).any()
        assert not ((data.val.t_end > 290.0) & (data.val.t_start < 340.0)).any()
    assert one.calibration is None and one.calibration_windows is one.val and one.info["n_calibration"] == 0


def _quarters(ws):
    """The quarter of a 600 s drive each run of consecutive windows of ``ws`` lies in."""
    runs = np.split(ws.t_end, np.flatnonzero(np.diff(ws.t_end) > 1.5) + 1)
    return [round(float(np.mean(r)) // 150) for r in runs]


def test_calibration_blocks_are_every_other_validation_block_and_no_training_window_touches_them():
    imu, t, speed = _vibrating_drive()
    epochs = np.arange(5.0, 595.0, 1.0)
    ws = od.speed_windows(imu, epochs, 200, np.interp(epochs, t, speed))
    four = od.build_speed_data(ws, [(300.0, 30.0)], margin_s=10.0, val_fraction=0.2, val_blocks=4)
    split = od.build_speed_data(ws, [(300.0, 30.0)], margin_s=10.0, val_fraction=0.2, val_blocks=4,
                                calibration_blocks=True)
    # the 1st and 3rd blocks stop the training, the 2nd and 4th calibrate
    assert _quarters(split.val) == [0, 2] and _quarters(split.calibration) == [1, 3]
    assert sorted([*split.val.t_end, *split.calibration.t_end]) == list(four.val.t_end)
    assert split.calibration_windows is split.calibration and split.info["n_calibration"] == len(split.calibration)
    assert np.array_equal(split.train.t_end, four.train.t_end)                      # the same training windows
    # through the networks' front end the calibration windows travel with the split
    framed = od.with_inputs(split, "band_frames", RATE)
    assert np.array_equal(framed.calibration.t_end, split.calibration.t_end) and framed.calibration.x.ndim == 3
    # one block has nothing to alternate: it does both
    one = od.build_speed_data(ws, [(300.0, 30.0)], margin_s=10.0, val_fraction=0.2, calibration_blocks=True)
    assert one.calibration is None


def test_a_network_odometer_learns_speed_and_its_uncertainty(tmp_path):
    from bgfn import train as T

    imu, t, speed = _vibrating_drive()
    epochs = np.arange(5.0, 595.0, 1.0)
    data = od.build_speed_data(od.speed_windows(imu, epochs, 200, np.interp(epochs, t, speed)), [(300.0, 30.0)],
                               margin_s=10.0)
    cfg = {"optimizer": {"epochs": 15, "batch_size": 16, "lr": 3e-3, "patience": 50}}
    card = T.train_model("mlp", data, {"n_recent": 200, "hidden": 32}, cfg, seed=0, out_dir=tmp_path)
    assert "val_rmse_mps" in card and "val_rmse_m" not in card
    assert card["val_rmse_mps"] < 0.5 * card["val_rmse_mean_mps"]        # far better than the mean speed
    assert card["best_epoch"] >= 1 and card["history"][0]["val_rmse_mps"] > card["val_rmse_mps"]


def test_the_odometers_learning_rate_search_tunes_inside_the_training_windows(tmp_path):
    from bgfn import train as T

    imu, t, speed = _vibrating_drive()
    epochs = np.arange(5.0, 595.0, 1.0)
    data = od.build_speed_data(od.speed_windows(imu, epochs, 200, np.interp(epochs, t, speed)), [(300.0, 30.0)],
                               margin_s=10.0)
    inner = od.inner_speed_split(data, 0.25)
    # the tuning split lies inside the training windows: the calibration block (data.val) chooses nothing
    assert set(inner.train.t_end) | set(inner.val.t_end) <= set(data.train.t_end)
    assert not set(inner.val.t_end) & set(data.val.t_end)
    assert len(inner.val) == round(0.25 * len(data.train)) and inner.options["objective"] == "speed"
    assert inner.norm.y_mean[0] == pytest.approx(inner.train.speed.mean())       # refit on the inner windows
    # the search of the increments, on the speed objective: the same grid and budget, its error in m/s
    cfg = {"optimizer": {"epochs": 6, "batch_size": 16, "patience": 50},
           "lr_search": {"grid": [1e-5, 3e-3], "fraction": 0.25, "seed": 0, "extend": 0},
           "sizes": {"mlp": {"smoke": {"n_recent": 200, "hidden": 16}}}, "size": "smoke"}
    table = T.search_profile_rates({"drive fold 0": (data, tmp_path)}, ["mlp"], cfg, split=od.inner_speed_split)
    assert table["lr"].tolist() == [1e-5, 3e-3] and table["dataset"].eq("drive fold 0").all()
    assert table.loc[table["selected"], "lr"].tolist() == [3e-3]       # 6 epochs at 1e-5 barely move the network
    assert (table["tuning_rmse_m"] > 0).all() and table["tuning_rmse_m"].iloc[1] < table["tuning_rmse_m"].iloc[0]


def test_the_ensemble_std_adds_the_members_disagreement_to_their_own_uncertainty():
    from bgfn.learning.odometry import ensemble_speed
    speeds = np.array([[9.0, 10.0], [11.0, 10.0]])           # disagree by 2 m/s at the first epoch, agree at the second
    stds = np.array([[0.5, 0.5], [0.5, 1.5]])
    mean, std = ensemble_speed(speeds, stds)
    assert mean == pytest.approx([10.0, 10.0])
    # mixture: sqrt(mean(std^2) + var(speed)) = sqrt(0.25 + 1) and sqrt((0.25 + 2.25) / 2 + 0)
    assert std == pytest.approx([np.sqrt(1.25), np.sqrt(1.25)])
    with pytest.raises(DataError, match="at least 2 members"):
        ensemble_speed(speeds[:1], stds[:1])

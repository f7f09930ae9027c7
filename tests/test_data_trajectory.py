"""Smooth 100 Hz truth: consistency with the strapdown (the simulation bar), smoothness, fit."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from bgfn.data import acquire
from bgfn.data.navego import read_reference
from bgfn.data.trajectory import smooth_reference, time_grid
from bgfn.errors import DataError
from bgfn.nav.earth import curvature_radii
from bgfn.nav.sim import imu_from_trajectory
from bgfn.nav.strapdown import integrate


@pytest.fixture(scope="module")
def ref():
    for folder in (acquire.raw_dir(), acquire.mirror_dir()):
        if folder is not None and (folder / "ref.mat").is_file():
            return read_reference(folder / "ref.mat")
    pytest.skip("NaveGo mirror not available (set BGFN_DATA_MIRROR)")


@pytest.fixture(scope="module")
def truth(ref):
    return smooth_reference(ref)


def horizontal_error(a, b):
    r_m, r_n = curvature_radii(b["lat"])
    return np.hypot((a["lat"] - b["lat"]) * (r_m + b["h"]), (a["lon"] - b["lon"]) * (r_n + b["h"]) * np.cos(b["lat"]))


def test_error_free_imu_reproduces_truth_over_30s_windows(truth):
    """Bar: from the true state at the start of any 30 s window the synthesized IMU stays within 0.3 m."""
    tr, _ = truth
    imu = imu_from_trajectory(tr)
    n_win = 3000  # 30 s at 100 Hz
    starts = range(0, len(tr) - n_win - 1, 700)  # 7 s apart: 175 windows over the whole drive
    errors = []
    for k in starts:
        out = integrate(tr.iloc[k], imu.iloc[k:k + n_win])
        assert out["time"].iloc[-1] == pytest.approx(tr["time"].iloc[k + n_win])
        errors.append(horizontal_error(out.iloc[-1], tr.iloc[k + n_win]))
    assert len(errors) > 150
    assert max(errors) < 0.3
    assert max(errors) < 1e-3  # in fact the inverse is exact to rounding (documented margin)


def test_truth_grid_rate_and_span(ref, truth):
    tr, _ = truth
    assert len(tr) == 125901 and tr["time"].iloc[0] == 138001.0 and tr["time"].iloc[-1] == 139260.0
    np.testing.assert_allclose(np.diff(tr["time"]), 0.01, atol=1e-9)
    np.testing.assert_array_equal(tr["time"].to_numpy(), time_grid(138001.0, 139260.0, 100.0))
    assert tr["yaw"].between(-np.pi, np.pi).all()


def test_velocity_is_the_derivative_of_position(truth):
    tr, _ = truth
    t = tr["time"].to_numpy()
    lat, lon, h = tr["lat"].to_numpy(), tr["lon"].to_numpy(), tr["h"].to_numpy()
    r_m, r_n = curvature_radii(lat)
    # central differences of the smooth position (error ~ dt^2/6 * jerk < 1e-4 m/s)
    v_n = (lat[2:] - lat[:-2]) / (t[2:] - t[:-2]) * (r_m[1:-1] + h[1:-1])
    v_e = (lon[2:] - lon[:-2]) / (t[2:] - t[:-2]) * (r_n[1:-1] + h[1:-1]) * np.cos(lat[1:-1])
    v_d = -(h[2:] - h[:-2]) / (t[2:] - t[:-2])
    assert np.abs(v_n - tr["v_n"].to_numpy()[1:-1]).max() < 1e-3
    assert np.abs(v_e - tr["v_e"].to_numpy()[1:-1]).max() < 1e-3
    assert np.abs(v_d - tr["v_d"].to_numpy()[1:-1]).max() < 1e-3


def test_truth_is_smooth_and_close_to_the_samples(ref, truth):
    tr, fit = truth
    acc = np.diff(tr[["v_n", "v_e", "v_d"]].to_numpy(), axis=0) / 0.01
    assert np.abs(acc).max() < 8.0  # a car: no spikes
    assert np.abs(np.diff(acc, axis=0)).max() < 0.2  # continuous acceleration (jerk * dt)
    assert fit["pos_rms_m"] == pytest.approx([0.05] * 3, rel=0.05)  # s = n sigma^2
    assert fit["att_rms_rad"] == pytest.approx([0.002] * 3, rel=0.05)
    assert max(fit["vel_rms_mps"]) < 0.2  # against the file's own velocity (it is 0.1 m/s off its positions)
    at_samples = tr.iloc[::100].reset_index(drop=True)
    assert np.median(horizontal_error(at_samples, ref)) < 0.1


def test_straight_line_is_reproduced_exactly():
    t = np.arange(100.0)
    lat0, h0 = np.radians(45.0), 250.0
    r_m, _ = curvature_radii(lat0)
    ref = pd.DataFrame({"time": t, "lat": lat0 + 10.0 * t / (r_m + h0), "lon": np.radians(7.0), "h": h0,
                        "v_n": 10.0, "v_e": 0.0, "v_d": 0.0, "roll": 0.0, "pitch": 0.0, "yaw": 0.0})
    tr, fit = smooth_reference(ref, position_sigma_m=0.01)
    # lat advances by 10 m per s at the origin's radius; R_M grows 1.6 ppm over the 1 km
    np.testing.assert_allclose(tr["v_n"], 10.0, rtol=3e-6)
    np.testing.assert_allclose(tr[["v_e", "v_d", "roll", "yaw"]].to_numpy(), 0.0, atol=1e-9)
    assert max(fit["pos_rms_m"]) < 1e-6


def test_bad_parameters_and_time(ref):
    with pytest.raises(DataError, match="degree"):
        smooth_reference(ref, degree=4)
    bad = ref.copy()
    bad.loc[10, "time"] = bad.loc[9, "time"]
    with pytest.raises(DataError, match="time"):
        smooth_reference(bad)

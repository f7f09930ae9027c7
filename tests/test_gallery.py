"""The gallery's own logs (notebook 09): written as a user has them, read back through the CSV path to the same
drive, a walk that walks, and each platform's aids in the rows."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest
from synthetic_drive import demo_drive

from bgfn.data import Drive, load_drive
from bgfn.studies.gallery import logs as G
from bgfn.data import imu_levels
from bgfn.studies.gallery import runs as EG
from bgfn.nav import sim
from bgfn.profile_schema import load_profile
from bgfn.report.gallery_words import gallery_decisions


@pytest.fixture(scope="module")
def recorded():
    """A car drive like the recorded one: no reference attitude, 1 Hz fixes, a stop at the start."""
    d = demo_drive(duration=300.0, gnss_rate=1.0, imu="mpu6000", overrides={"vibration_gyro_std": [0.0] * 3,
                                                                            "vibration_accel_std": [0.0] * 3})
    gnss = sim.gnss_from_trajectory(d.reference, 1.0, 0.05, 0.1, d.meta["lever_arm_m"], seed=1)   # RTK-like
    ref = d.reference.assign(roll=np.nan, pitch=np.nan, yaw=np.nan)
    return Drive("recorded", ref, d.imu, gnss, d.meta)


def test_the_phone_log_reads_back_as_the_car_drive_it_came_from(recorded, tmp_path):
    folder = G.phone_log(recorded, tmp_path / "phone")
    back = load_drive(folder)
    assert back.meta["platform"] == "car" and back.meta["imu_mounting_deg"] == G.PHONE_MOUNTING_DEG
    # the mounting and the IMU clock in meta.yaml undo what the phone did: the same rows on the same times
    tick = lambda df: np.round(df["time"].to_numpy() * 100).astype(int)     # noqa: E731  (10 ms rows)
    orig = recorded.imu.set_index(tick(recorded.imu)).loc[tick(back.imu)]
    for col in ("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y", "accel_z"):
        assert back.imu[col].to_numpy() == pytest.approx(orig[col].to_numpy(), abs=1e-9)
    # written turned: the phone's x is the car's y (a quarter turn about z)
    raw = pd.read_csv(folder / "imu.csv")
    assert not np.allclose(raw["accel_x"].to_numpy()[:100], recorded.imu["accel_x"].to_numpy()[:100])
    # no accuracy column in the file: meta.yaml's std is used; the latency is estimated and applied
    assert "std_n" not in pd.read_csv(folder / "gnss.csv").columns
    assert back.gnss["std_n"].eq(2.0).all()
    # (a late stamp is found and taken off; how precisely, on this smooth synthetic trajectory with its gentle turns,
    # is a matter of the estimator: tenths of a second; tests/test_own_log.py checks it on the recorded drive)
    assert 0.1 < back.meta["gnss_offset"]["applied_latency_s"] < 1.0


def test_the_walk_walks_stops_and_bounces():
    walk = G.walk_trajectory()
    t = walk["time"].to_numpy() - walk["time"].iloc[0]
    speed = np.hypot(walk["v_n"], walk["v_e"]).to_numpy()
    for start, length in G.WALK_STOPS_S:
        assert speed[(t > start + 0.1) & (t < start + length - 0.1)].max() < 1e-9      # standing
    walking = (t > 30.0) & (t < 140.0)
    assert speed[walking].mean() == pytest.approx(G.WALK_SPEED_MPS, rel=0.02)
    # the step bounce: +-0.4 m/s vertical at 1.8 Hz is +-0.4 / (2 pi 1.8) = 3.5 cm of height
    h = walk["h"].to_numpy()[walking]
    bounce = h - np.convolve(h, np.ones(56) / 56, mode="same")
    assert np.percentile(np.abs(bounce[100:-100]), 99) == pytest.approx(0.4 / (2 * np.pi * G.STEP_HZ), rel=0.2)


def test_a_walker_runs_with_zupt_alone_and_its_rows_say_so(tmp_path):
    folder = G.walker_log(tmp_path / "walk")
    log = next(g for g in G.GALLERY if g.kind == "walker")
    run = EG.run_log(log, folder, load_profile(log.base))
    assert set(run.rows["method"]) == {"INS", "INS+ZUPT"} and (run.rows["platform"] == "walker").all()
    assert any("no NHC" in line for line in gallery_decisions(run))
    assert f"base: {log.base}" in run.profile_text and str(folder.resolve()) in run.profile_text
    wide = EG.gallery_pivot(run.rows)
    assert wide["aided row"].iloc[0] == "INS+ZUPT" and "outage 2: aided (m)" in wide.columns
    assert EG._aided_label("other") == "INS (no aid)" and EG._aided_label("car") == "INS+NHC"


def test_a_walker_is_moving_at_a_walkers_pace_for_notebook_01(tmp_path):
    """Notebook 01's levels and spectra of a walker: *driving* is the platform's own pace, not a car's 3 m/s."""
    walk = load_drive(G.walker_log(tmp_path / "walk"))
    assert imu_levels.moving_speed(walk) < G.WALK_SPEED_MPS < imu_levels.DRIVING_MPS
    states = imu_levels.motion_states(walk).value_counts()
    assert states["driving"] > 0.7 * len(walk.imu) and states["still"] > 0
    assert len(imu_levels.imu_psd(walk)) > 100


def test_a_gallery_logs_profile_names_its_folder_without_the_machine_path(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)                      # the notebooks run in the repository's root
    log = next(g for g in G.GALLERY if not g.own)
    text = log.profile_text(tmp_path / "results" / "p" / "gallery" / log.name)
    assert f"results/p/gallery/{log.name}" in text and str(tmp_path) not in text

"""Outage windows on the data's own grid: a window the rule picks or a user types is moved onto the IMU epochs,
the same in the profile check and in every notebook (bgfn.nav.outages.snap_windows)."""

from __future__ import annotations

import importlib.util
import shutil
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from bgfn import config
from bgfn.data import load_drive
from bgfn.nav import outages
from bgfn.profile_schema import check_with_drives

pytestmark = pytest.mark.usefixtures("repo_untouched")
_spec = importlib.util.spec_from_file_location("demo_log", config.PROJECT_ROOT / "tools" / "demo_log.py")
demo_log = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(demo_log)

T0 = 23100.001                          # a logger whose IMU stamps lie at .xx1 s


def _grid(t0=T0, n=6001, step=0.01):
    return t0 + np.arange(n) * step


def test_edges_go_to_the_nearest_imu_epoch_and_the_end_stays_inside_the_data():
    t = _grid()                                             # 23100.001 .. 23160.001 s
    (a, b, c) = outages.snap_windows([(23110.0, 30.0), (23130.0, 30.0), (23110.001, 10.0)], t)
    # whole seconds lie 1 ms after an epoch: both edges move back onto it
    assert a.moved and a.window[0] == pytest.approx(23109.991) and a.window[1] == pytest.approx(30.0)
    # an end 1 ms before the last epoch: onto the epoch before it
    assert b.window[0] == pytest.approx(23129.991) and b.window[0] + b.window[1] == pytest.approx(23159.991)
    # already on the grid: kept to the bit
    assert not c.moved and c.window == (23110.001, 10.0)
    over = outages.snap_windows([(23140.0, 20.005)], t)[0]   # ends 4 ms after the data: onto the last epoch
    assert over.window[0] + over.window[1] == pytest.approx(t[-1])
    far = outages.snap_windows([(23140.0, 30.0)], t)[0]      # 10 s after it: not shrunk, the check names it
    assert sum(far.window) == pytest.approx(23170.0)
    # every edge is an epoch
    for w in (a, b, over):
        assert np.min(np.abs(t - w.window[0])) < 1e-9 and np.min(np.abs(t - sum(w.window))) < 1e-9


def test_the_reader_returns_the_snapped_windows_and_the_shipped_grid_is_unchanged():
    t = _grid()
    drive = SimpleNamespace(name="log", imu=_Frame(time=t), reference=_Frame(time=t))
    prof = {"profile": "p", "outage_windows": [[23130.0, 30.0]], "train": {"margin_s": 0.0}}
    # asked 23130 + 30 = 23160.0, the last epoch is 23160.001 - 0.001 ... the window ends inside the data, on it
    (w,) = outages.outage_windows(prof, drive)
    assert w[0] == pytest.approx(23129.991) and w[0] + w[1] <= t[-1]
    # whole-hundredth stamps (the shipped drives): the asked windows come back as they were
    t2 = _grid(23100.0)
    drive2 = SimpleNamespace(name="log", imu=_Frame(time=t2), reference=_Frame(time=t2))
    assert outages.outage_windows(prof, drive2) == [(23130.0, 30.0)]


class _Frame(dict):
    """The columns a reader takes from a drive's tables (``frame["time"].to_numpy()`` / ``.iloc``)."""

    def __getitem__(self, key):
        return _Column(dict.__getitem__(self, key))


class _Column:
    def __init__(self, values):
        self.values = np.asarray(values, float)

    def to_numpy(self, dtype=float):
        return self.values.astype(dtype)

    @property
    def iloc(self):
        return self.values


def test_a_log_stamped_at_xx1_passes_the_check_with_windows_on_its_epochs(tmp_path, monkeypatch):
    log = demo_log.demo_log(tmp_path / "logs" / "xx1", name="xx1-car", source="test")
    regular = load_drive(log).imu                          # a logger at a steady 100 Hz, stamped at .xx1 s
    regular.assign(time=regular["time"] + 0.001).to_csv(log / "imu.csv", index=False, float_format="%.9g")
    params = tmp_path / "params"
    params.mkdir()
    shutil.copy(config.PARAMS_DIR / "quick.yaml", params / "quick.yaml")
    # whole-second windows, the second ending on 243240.0 s, after the last IMU epoch 243239.991 s
    (params / "mine.yaml").write_text(f"base: quick\ndatasets: [{log}]\n"
                                      "outage_windows: [[243150.0, 30.0], [243210.0, 30.0]]\n"
                                      "train: {margin_s: 5.0}\nevaluate: {sweep: {datasets: []}}\n")
    monkeypatch.setattr(config, "PARAMS_DIR", params)
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path / "results")
    monkeypatch.chdir(tmp_path)
    drive = load_drive(str(log), profile="mine")
    t = drive.imu["time"].to_numpy()
    assert abs(t[0] * 100 - round(t[0] * 100)) > 0.05        # the stamps lie off the whole hundredths
    check_with_drives("mine")                                # passes ...
    from bgfn.profile_schema import load_profile
    windows = outages.outage_windows(load_profile("mine"), drive, str(log))   # ... with what the notebooks use
    for s, d in windows:
        assert np.min(np.abs(t - s)) < 1e-9 and np.min(np.abs(t - (s + d))) < 1e-9 and s + d <= t[-1]
    assert windows[0][0] == pytest.approx(243149.991) or windows[0][0] == pytest.approx(243150.001)

"""Results computed once and kept on disk (bgfn.io.cached): a GPS-aided run read back is bit for bit the run
computed again, and any change of its inputs (the drive's data, a nav: setting, the outages) misses the cache."""

from __future__ import annotations

import dataclasses

import numpy as np
import pandas as pd
import pytest

from bgfn.data import Drive
from bgfn.io import CACHE_DIR_ENV, cached, content_hash
from bgfn.nav import baseline
from synthetic_drive import demo_drive

NAV = {"alignment": {"mode": "reference"}, "noise_scale": {"default": 1.0}}
WINDOWS = [(60.0, 20.0), (110.0, 20.0)]


def _same(a, b, where: str = "result") -> None:
    """Equal bit for bit, field by field: every array and frame value (NaN where NaN), every number, every string."""
    assert type(a) is type(b), where
    if dataclasses.is_dataclass(a):
        for f in dataclasses.fields(a):
            _same(getattr(a, f.name), getattr(b, f.name), f"{where}.{f.name}")
    elif isinstance(a, pd.DataFrame):
        assert list(a.columns) == list(b.columns) and list(a.dtypes) == list(b.dtypes), where
        pd.testing.assert_index_equal(a.index, b.index, exact=True)
        for col in a.columns:
            _same(a[col].to_numpy(), b[col].to_numpy(), f"{where}[{col}]")
    elif isinstance(a, pd.Series):
        _same(a.to_frame(), b.to_frame(), where)
    elif isinstance(a, np.ndarray):
        assert a.dtype == b.dtype and a.shape == b.shape, where
        if a.dtype.kind in "fc":
            assert a.tobytes() == b.tobytes(), where           # the same bits (NaN payloads included)
        else:
            assert a.tolist() == b.tolist(), where
    elif isinstance(a, dict):
        assert list(a) == list(b), where
        for k in a:
            _same(a[k], b[k], f"{where}[{k!r}]")
    elif isinstance(a, (list, tuple)):
        assert len(a) == len(b), where
        for i, (x, y) in enumerate(zip(a, b)):
            _same(x, y, f"{where}[{i}]")
    elif isinstance(a, (float, np.floating)):
        assert np.float64(a).tobytes() == np.float64(b).tobytes(), where
    elif hasattr(a, "__dict__") and not isinstance(a, type):
        _same(vars(a), vars(b), where)
    else:
        assert a == b, where


@pytest.fixture(scope="module")
def drive():
    return demo_drive(duration=150.0)


def test_a_cached_gps_aided_run_is_the_run_computed_again(drive, tmp_path, monkeypatch):
    cfg = baseline.nav_config(NAV)
    fresh = baseline.run_baseline(drive, cfg, WINDOWS)            # no cache folder: computed
    monkeypatch.setenv(CACHE_DIR_ENV, str(tmp_path))
    first = baseline.run_baseline(drive, cfg, WINDOWS)            # computed and kept
    assert len(list((tmp_path / "baseline").glob("*.pkl"))) == 1
    again = baseline.run_baseline(drive, cfg, WINDOWS)            # read back
    _same(fresh, first)
    _same(fresh, again)
    np.testing.assert_array_equal(again.full.trajectory["lat"].to_numpy(), fresh.full.trajectory["lat"].to_numpy())
    pd.testing.assert_frame_equal(again.outage_table, fresh.outage_table, check_exact=True)

    run = baseline.run_drive(drive, NAV)
    _same(run, baseline.run_drive(drive, NAV))
    monkeypatch.delenv(CACHE_DIR_ENV)
    _same(run, baseline.run_drive(drive, NAV))


def test_a_changed_input_is_computed_again(drive, tmp_path, monkeypatch):
    monkeypatch.setenv(CACHE_DIR_ENV, str(tmp_path))
    cfg = baseline.nav_config(NAV)
    baseline.run_baseline(drive, cfg, WINDOWS)
    baseline.run_baseline(drive, baseline.nav_config({**NAV, "bias_model": "gauss_markov"}), WINDOWS)
    baseline.run_baseline(drive, cfg, WINDOWS[:1])
    gnss = drive.gnss.copy()
    gnss.loc[5, "lat"] += 1e-9                                     # one fix, a millimetre off
    moved = baseline.run_baseline(Drive(drive.name, drive.reference, drive.imu, gnss, drive.meta), cfg, WINDOWS)
    assert len(list((tmp_path / "baseline").glob("*.pkl"))) == 4   # four inputs, four entries
    baseline.run_baseline(drive, cfg, WINDOWS[1:], keep=False)     # another setup, read once: not kept
    assert len(list((tmp_path / "baseline").glob("*.pkl"))) == 4
    _same(moved, baseline.run_baseline(Drive(drive.name, drive.reference, drive.imu, gnss, drive.meta), cfg, WINDOWS))


def test_the_noise_scale_search_is_kept_once_per_drive_and_settings(drive, tmp_path, monkeypatch):
    """nav.noise_scale auto: its search (several GPS-aided runs) is read back for the next context of the same drive
    and settings, the same factor bit for bit; a drive with other IMU errors searches again."""
    from bgfn.nav import tuning

    cfg = baseline.nav_config({**NAV, "noise_scale": {"default": "auto"}})
    fresh = baseline.prepare_filter(drive, cfg)                   # no cache folder: searched
    searches = []
    real = baseline.search_noise_scale
    monkeypatch.setattr(baseline, "search_noise_scale", lambda *a, **k: searches.append(1) or real(*a, **k))
    monkeypatch.setenv(CACHE_DIR_ENV, str(tmp_path))
    first, again = baseline.prepare_filter(drive, cfg), baseline.prepare_filter(drive, cfg)
    assert len(searches) == 1 and len(list((tmp_path / "noise_scale").glob("*.pkl"))) == 1
    assert isinstance(again.tuning, tuning.NoiseTuning) and fresh.tuning.runs
    _same(fresh, first)
    _same(fresh, again)
    errors = {**drive.meta["imu_errors"], "gyro_bias_instability": [1e-3, 1e-3, 1e-3]}
    baseline.prepare_filter(dataclasses.replace(drive, meta={**drive.meta, "imu_errors": errors}), cfg)
    assert len(searches) == 2


def test_a_damaged_entry_is_computed_again_and_replaced(tmp_path, monkeypatch):
    monkeypatch.setenv(CACHE_DIR_ENV, str(tmp_path))
    calls = []
    assert cached("kind", {"a": 1}, lambda: calls.append(1) or np.arange(3.0)).tolist() == [0.0, 1.0, 2.0]
    (entry,) = (tmp_path / "kind").glob("*.pkl")
    entry.write_bytes(b"not a pickle")
    assert cached("kind", {"a": 1}, lambda: calls.append(1) or np.arange(3.0)).tolist() == [0.0, 1.0, 2.0]
    assert cached("kind", {"a": 1}, lambda: calls.append(1) or np.arange(3.0)).tolist() == [0.0, 1.0, 2.0]
    assert len(calls) == 2                                         # the damaged entry once, then read back


def test_the_content_hash_sees_every_value_and_not_the_key_order():
    frame = pd.DataFrame({"t": [0.0, 1.0], "x": [1.0, 2.0]})
    other = frame.copy()
    other.loc[1, "x"] = np.nextafter(2.0, 3.0)                     # one ulp
    assert content_hash({"a": frame, "b": 1}) == content_hash({"b": 1, "a": frame.copy()})
    assert content_hash(frame) != content_hash(other)
    assert content_hash([1.0, 2.0]) != content_hash([2.0, 1.0])
    assert content_hash(np.zeros(3)) != content_hash(np.zeros(3, dtype=np.float32))


def test_cached_windows_are_the_windows_built_again(tmp_path, monkeypatch):
    from bgfn import learning as L

    imu, att, gnss = L.synthetic_tables(duration_s=200.0, noise=0.1, seed=3)
    options = {"window": 50, "val_fraction": 0.2}
    fresh = L.build_learning_data(imu, att, gnss, [(1100.0, 20.0)], keep=True, **options)
    monkeypatch.setenv(CACHE_DIR_ENV, str(tmp_path))
    L.build_learning_data(imu, att, gnss, [(1100.0, 20.0)], **options)      # a sweep fold's: not kept
    assert not (tmp_path / "learning_data").exists()
    first = L.build_learning_data(imu, att, gnss, [(1100.0, 20.0)], keep=True, **options)
    again = L.build_learning_data(imu, att, gnss, [(1100.0, 20.0)], keep=True, **options)
    assert len(list((tmp_path / "learning_data").glob("*.pkl"))) == 1
    _same(fresh, first)
    _same(fresh, again)
    other = L.build_learning_data(imu, att, gnss, [(1100.0, 20.0)], keep=True, **{**options, "window": 40})
    assert other.train.x.shape[1] == 40 and len(list((tmp_path / "learning_data").glob("*.pkl"))) == 2


def _slow_entry(args):
    """In a process of its own: wait until both processes are there (a file each), then ask for one cache entry whose
    computation takes a while and leaves a mark; returns the entry and this process's id."""
    root, marks, me = args
    import os
    import time
    from pathlib import Path

    os.environ[CACHE_DIR_ENV] = root
    Path(root, f"ready-{me}").parent.mkdir(parents=True, exist_ok=True)
    Path(root, f"ready-{me}").touch()
    deadline = time.monotonic() + 60.0
    while len(list(Path(root).glob("ready-*"))) < 2:        # both processes ask at once, not one after the other
        assert time.monotonic() < deadline, "the other process never came"
        time.sleep(0.01)

    def compute():
        with open(marks, "a") as f:
            f.write("computed\n")
        time.sleep(1.0)
        return {"value": 42}

    return cached("slow", {"k": 1}, compute), os.getpid()


def test_two_processes_asking_for_one_entry_at_once_compute_it_once(tmp_path):
    # notebooks side by side under make -j: the second waits for the first's result instead of computing it again
    import multiprocessing

    marks = tmp_path / "marks.txt"
    with multiprocessing.get_context("spawn").Pool(2) as pool:
        got = pool.map(_slow_entry, [(str(tmp_path / "cache"), str(marks), i) for i in range(2)], chunksize=1)
    assert [v for v, _ in got] == [{"value": 42}, {"value": 42}] and got[0][1] != got[1][1]   # two processes
    assert marks.read_text().splitlines() == ["computed"]

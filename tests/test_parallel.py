"""The runner of independent runs (bgfn.parallel): where the runs go, results in the runs' order whatever order
they finish in, one progress line per run, and the same tables with 1 job, 2 loky processes and a Dask cluster."""

from __future__ import annotations

import os
import time

import pytest

from bgfn import learning as L, train as T
from bgfn.errors import DataError
from bgfn.parallel import PROGRESS_ENV, Runner, RunProgress, dispatch_order
from bgfn.profile_schema import load_profile
from processes import alive


# ----------------------------------------------------------------------------------------------- settings
def test_the_profile_says_where_the_runs_go_and_the_environment_wins():
    # imported here, not at the top: the pool's workers import this module, and the report layer is heavy to import
    from bgfn.report.run_words import runner_words

    assert Runner.of({"parallel": {"jobs": 3}}, environ={}) == Runner(3, "loky", None)
    assert Runner.of({}, environ={}).jobs >= 1                                  # null: the cores here
    assert Runner.of({"parallel": {"jobs": 3}}, environ={"BGFN_JOBS": "1"}).jobs == 1
    assert Runner.of({"parallel": {"jobs": 3}}, environ={"BGFN_JOBS": ""}).jobs == 3   # make's empty JOBS=
    dask = Runner.of({}, environ={"DASK_SCHEDULER": "tcp://10.0.0.1:8786"})
    assert (dask.backend, dask.scheduler) == ("dask", "tcp://10.0.0.1:8786")
    assert "10.0.0.1" in runner_words(dask) and "2 processes" in runner_words(Runner(2))


@pytest.mark.parametrize("section, environ, key", [
    ({"backend": "threads"}, {}, "backend"),
    ({"backend": "dask"}, {}, "scheduler"),
    ({}, {"BGFN_JOBS": "0"}, "jobs"),
    ({}, {"BGFN_JOBS": "two"}, "jobs"),
])
def test_bad_settings_fail_naming_the_key(section, environ, key):
    with pytest.raises(DataError) as e:
        Runner.of({"parallel": section}, environ=environ)
    assert key in str(e.value)


def test_the_profile_check_refuses_dask_without_a_scheduler(monkeypatch):
    from bgfn.profile_schema import ProfileError, validate

    monkeypatch.delenv("DASK_SCHEDULER", raising=False)
    cfg = load_profile("smoke")
    validate({**cfg, "parallel": {"jobs": 2, "backend": "loky", "scheduler": None}})
    with pytest.raises(ProfileError, match="parallel.scheduler"):
        validate({**cfg, "parallel": {"backend": "dask"}})
    with pytest.raises(ProfileError, match="parallel.jobs"):
        validate({**cfg, "parallel": {"jobs": 0}})


# ----------------------------------------------------------------------------------------------- order and lines
def _slow_square(x: int, delay: float) -> int:
    time.sleep(delay)
    return x * x


def _square_when(x: int, mark: str, wait_for: tuple[str, ...]) -> int:
    # a barrier through files: the run waits (30 s at most) until the runs it names have finished, so the order in
    # which runs finish is fixed whatever the load on the machine, then leaves its own mark
    deadline = time.time() + 30.0
    while not all(os.path.exists(f) for f in wait_for) and time.time() < deadline:
        time.sleep(0.02)
    open(mark, "w").close()
    return x * x


@pytest.mark.parametrize("jobs", [1, 2])
def test_results_come_back_in_the_order_of_the_runs(jobs, tmp_path):
    # the first run finishes last (with 2 processes it waits for the other two), and its result still comes first
    a, b, c = (str(tmp_path / name) for name in "abc")
    runs = [(3, a, (b, c) if jobs == 2 else ()), (1, b, ()), (2, c, ())]
    lines = []
    out = Runner(jobs).map(_square_when, runs, labels=["a", "b", "c"],
                           summary=lambda r: f"got {r}", desc="squares", echo=lines.append, bar=False)
    assert out == [9, 1, 4]
    assert len(lines) == 3 and all(line.startswith("[squares] ") for line in lines)
    if jobs == 2:
        assert lines[-1].startswith("[squares] a | got 9")
    assert [line.split(" | ")[3] for line in lines[:2]] == ["2 left", "1 left"]
    assert lines[-1].split(" | ")[-1].startswith("all 3 in ")


def _start_time(x: int, delay: float) -> tuple[int, float]:
    t = time.time()
    time.sleep(delay)
    return x, t


def test_the_costliest_runs_start_first_and_the_results_keep_their_order():
    assert dispatch_order([1.0, 3.0, 2.0, 3.0], 4) == [1, 3, 2, 0]          # costliest first, ties in task order
    assert dispatch_order(None, 3) == [0, 1, 2]
    with pytest.raises(ValueError, match="2 entries for 3 tasks"):
        dispatch_order([1.0, 2.0], 3)
    # the last task is the long one: with its cost given, a 2-process pool starts it among the first two
    tasks = [(0, 0.3), (1, 0.3), (2, 0.3), (3, 1.0)]
    out = Runner(2).map(_start_time, tasks, cost=[0.3, 0.3, 0.3, 1.0], bar=False, echo=lambda line: None)
    assert [x for x, _ in out] == [0, 1, 2, 3]
    started = sorted(range(4), key=lambda i: out[i][1])
    assert 3 in started[:2]


def _pid_and_module(x: int) -> tuple[int, int, bool]:
    import os
    import sys
    return x, os.getpid(), "colorsys" in sys.modules


def test_workers_started_ahead_are_the_ones_the_runs_use():
    import os
    from bgfn import parallel
    runner = Runner(2)
    # this module too: loky restarts a worker whose memory grew by 300 MB after its first task (torch's import)
    assert runner.start("colorsys", __name__) is runner and parallel._STARTING   # returns at once, starts behind
    out = runner.map(_pid_and_module, [(i,) for i in range(6)], bar=False, echo=lambda line: None)
    assert not parallel._STARTING                                           # the map waited for it
    assert [x for x, _, _ in out] == list(range(6))
    assert all(pid != os.getpid() for _, pid, _ in out)
    assert all(imported for _, _, imported in out)                          # the started workers imported it
    assert Runner(1).start("colorsys") is not None and not parallel._STARTING   # one job: no pool to start


_HELD: list = []


def _hold_memory(mb: int) -> int:
    import os

    import numpy as np
    _HELD[:] = [np.ones(mb * 2**20, dtype=np.uint8)]          # data a run keeps on purpose (a drive, networks)
    time.sleep(1.1)                                          # loky checks a worker's memory at most once a second
    return os.getpid()


def test_a_started_worker_is_not_replaced_when_its_runs_hold_memory():
    # loky replaces a worker grown 300 MB past its memory after its first task; after a start task that is the bare
    # imports, so without Runner.start's care every run holding a drive would cost a new worker and a warning
    import warnings
    runner = Runner(2).start(__name__)
    with warnings.catch_warnings(record=True) as caught:     # loky warns from its manager thread
        warnings.simplefilter("always")
        pids = runner.map(_hold_memory, [(320,)] * 6, bar=False, echo=lambda line: None)
    assert not [w for w in caught if "worker stopped" in str(w.message)]
    assert len(set(pids)) <= 2


def test_progress_lines_carry_the_seconds_runs_left_and_an_eta():
    p = RunProgress(4, "training", echo=lambda line: None, bar=False)
    p.t0 -= 10.0                                    # 10 s ago
    p.left = 2                                      # two of four done: 5 s each -> 10 s to go
    line = p.line("quick bgfn seed 0", 3.25, "12 epochs")
    assert line.startswith("[training] quick bgfn seed 0 | 12 epochs | 3.2 s | 2 left | ETA 0:1")
    p.close()


def test_under_make_the_lines_go_to_the_progress_log(tmp_path, monkeypatch):
    log = tmp_path / "03.log"
    monkeypatch.setenv(PROGRESS_ENV, str(log))
    printed = []
    Runner(1).map(_slow_square, [(2, 0.0), (3, 0.0)], desc="x", echo=printed.append, bar=False)
    assert printed == []
    assert [line.split(" | ")[0] for line in log.read_text().splitlines()] == ["[x] x 1", "[x] x 2"]


# ----------------------------------------------------------------------------------------------- same tables
@pytest.fixture(scope="module")
def smoke_runs(tmp_path_factory):
    """Every method of the smoke profile (its sizes and budget), two seeds, on a small synthetic drive."""
    cfg = load_profile("smoke")
    tc = {**cfg["train"], "optimizer": {**cfg["train"]["optimizer"], "epochs": 2}}
    imu, att, gnss = L.synthetic_tables(duration_s=240.0, noise=0.05, seed=4)
    data = L.build_learning_data(imu, att, gnss, [(1100.0, 20.0)], window=50, margin_s=2.0, val_fraction=0.25,
                                 val_position="end")

    def runs(folder: str):
        out = tmp_path_factory.mktemp(folder)
        return [T.TrainingRun(f"{m} seed {s}", m, data, T.size_config(tc, m), tc, s, out, "cpu", {"dataset": "toy"})
                for m in tc["methods"] for s in (0, 1)]
    return runs


def _table(cards) -> str:
    return T.without_timing(T.cards_table(cards)).to_csv(index=False)


def test_the_tables_are_the_same_with_one_job_and_with_two(smoke_runs):
    one = T.train_runs(smoke_runs("one"), Runner(1))
    two = T.train_runs(smoke_runs("two"), Runner(2))
    assert [c["method"] for c in one] == [c["method"] for c in two]
    assert _table(one) == _table(two)
    assert len({c["best_val_loss"] for c in one}) > 1                # the runs differ from each other


def test_a_dask_cluster_gives_the_table_loky_gives(smoke_runs):
    distributed = pytest.importorskip("distributed")
    with distributed.LocalCluster(n_workers=2, threads_per_worker=1, processes=True, dashboard_address=None,
                                  silence_logs=40) as cluster:
        dask = T.train_runs(smoke_runs("dask"), Runner(2, "dask", cluster.scheduler_address))
    loky = T.train_runs(smoke_runs("loky"), Runner(2))
    assert _table(dask) == _table(loky)


# ----------------------------------------------------------------------------------------------- make bench
def test_interleaved_timing_alternates_and_discards_the_warm_up():
    from bgfn.train.speed import interleaved_times

    calls = []
    times = interleaved_times({"a": lambda: calls.append("a"), "b": lambda: calls.append("b")}, repeats=3, warmup=1)
    assert calls == ["a", "b"] * 4                       # one warm-up round, then three timed rounds, in turn
    assert [len(t) for t in times.values()] == [3, 3]


def test_a_paired_ratio_is_unreliable_when_its_spread_exceeds_the_difference():
    from bgfn.report.training_words import ratio_text
    from bgfn.train.speed import paired_ratio, quartiles

    assert quartiles([1, 2, 3, 4, 5]) == {"median": 3.0, "q25": 2.0, "q75": 4.0}
    clear = paired_ratio([1.0, 1.0, 1.0, 1.0, 1.0], [2.0, 2.1, 1.9, 2.0, 2.2])    # ~0.5, spread ~0.02
    assert clear["median"] == pytest.approx(0.5) and not clear["unreliable"]
    assert "unreliable" not in ratio_text(clear) and "5 rounds" in ratio_text(clear)
    noisy = paired_ratio([1.0] * 4, [0.7, 1.0, 1.3, 1.6])                          # ratios 1.43 .. 0.63
    assert noisy["iqr"] > abs(noisy["median"] - 1.0) and noisy["unreliable"]
    assert ratio_text(noisy).endswith("unreliable: the spread is wider than the difference")
    with pytest.raises(ValueError):
        paired_ratio([1.0], [1.0, 2.0])


# ----------------------------------------------------------------------------------------------- the sweep, the oracle
@pytest.fixture(scope="module")
def synthetic_sweep_setup(tmp_path_factory):
    from synthetic_drive import demo_drive

    from bgfn import evaluate as ev, studies

    cfg = load_profile("smoke")
    nav = {"init": {"position_std_m": 1.0, "height_std_m": 2.0, "velocity_std_mps": 0.1, "level_std_deg": 0.2,
                    "azimuth_std_deg": 1.0}}
    cfg = {**cfg, "nav": nav, "train": {**cfg["train"], "window": 20, "margin_s": 5.0}}
    ecfg = ev.evaluate_config({"methods": ["mlp"], "sweep": {
        "n_starts": 2, "folds": 2, "durations_s": [10.0], "warmup_s": 30.0, "seeds": [0, 1],
        "train": {"optimizer": {"epochs": 1, "max_train_windows": 64, "max_val_windows": 32}}}}, cfg["train"])
    return demo_drive("synthetic", 150.0, 5.0, 3), cfg, ecfg


def test_the_sweep_gives_the_same_rows_with_one_job_and_with_two(synthetic_sweep_setup, tmp_path, monkeypatch):
    from bgfn import config, evaluate as ev, studies

    drive, cfg, ecfg = synthetic_sweep_setup
    tables = {}
    for jobs in (1, 2):
        monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path / f"jobs{jobs}")    # networks trained anew each time
        rows, info = studies.outage_sweep.run_sweep(cfg, "t", "synthetic", drive=drive, ecfg=ecfg, runner=Runner(jobs))
        tables[jobs] = rows.to_csv(index=False)
        assert (tmp_path / f"jobs{jobs}").exists()                              # the workers wrote there
    assert tables[1] == tables[2] and "MLP" in tables[1]


def test_the_oracle_grid_gives_the_same_rows_with_one_job_and_with_two(synthetic_sweep_setup):
    from bgfn import evaluate as ev, studies
    from bgfn.studies.outage_sweep import oracle as orc

    drive, cfg, _ = synthetic_sweep_setup
    windows = [("1", 40.0, 30.0), ("2", 75.0, 30.0)]
    ctx = ev.navigation_context(drive, cfg["nav"], [s for _, s, _ in windows])
    grid = {"sigmas_m": [0.0, 0.5, 2.0], "seeds": [0, 1], "durations_s": [30.0]}
    one, two = (orc.oracle_runs(ctx, windows, grid, runner=Runner(j)) for j in (1, 2))
    assert one.to_csv(index=False) == two.to_csv(index=False) and len(one) == 2 * (1 + 1 + 2 * 2)


# ----------------------------------------------------------------------------------------------- workers
_HOLDER = """
import os, sys, time
from bgfn.parallel import Runner

def hold(folder):
    open(os.path.join(folder, str(os.getpid())), "w").close()
    time.sleep(300)                      # a long run: only its owner's end can stop it early
    return 0

if __name__ == "__main__":
    runner = Runner(jobs=2)
    if sys.argv[2] == "start":
        runner.start("bgfn.parallel")    # the pool started from a thread that ends at once (Runner.start)
    runner.map(hold, [(sys.argv[1],), (sys.argv[1],)], bar=False)
"""




@pytest.mark.parametrize("how", ["map", "start"])
def test_a_killed_owner_leaves_no_pool_worker_behind(tmp_path, how):
    import os
    import signal
    import subprocess
    import sys

    script = tmp_path / "holder.py"
    script.write_text(_HOLDER)
    folder = tmp_path / "pids"
    folder.mkdir()
    owner = subprocess.Popen([sys.executable, str(script), str(folder), how], cwd=tmp_path, env=os.environ.copy())
    try:
        deadline = time.monotonic() + 120
        while len(list(folder.iterdir())) < 2:
            assert time.monotonic() < deadline and owner.poll() is None, "the workers never started"
            time.sleep(0.2)
        workers = [int(p.name) for p in folder.iterdir()]
        assert all(alive(p) for p in workers) and owner.pid not in workers
        time.sleep(1.0)                              # the start thread (how == "start") has ended: still alive
        assert all(alive(p) for p in workers)
        owner.send_signal(signal.SIGKILL)            # as a notebook's kernel killed
        owner.wait(timeout=10)
        deadline = time.monotonic() + 10
        while any(alive(p) for p in workers) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not any(alive(p) for p in workers), "a pool worker outlived the process that started it"
    finally:
        if owner.poll() is None:
            owner.kill()
        for p in folder.iterdir():
            if alive(int(p.name)):
                os.kill(int(p.name), signal.SIGKILL)

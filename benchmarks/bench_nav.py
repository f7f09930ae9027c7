"""Speed of the 15-state GPS/INS filter on the full Turin drive, and of pyins on the same data.

Adds to ``results/bench.json``:

- ``kf_full_drive_s``: median wall time (s) of :func:`bgfn.nav.filter.run_filter` over the whole drive
  (about 126,000 IMU samples at 100 Hz, covariance propagated at every sample) with GNSS updates at 1 Hz;
- ``kf_full_drive_5hz_s``: the same with all 5 Hz GNSS fixes of ``turin-sim-ekinox``;
- ``pyins_full_drive_s``: median wall time of ``pyins.filters.run_feedback_filter`` on the same IMU data,
  the same 1 Hz fixes, the same noise settings (``time_step=1.0``: pyins propagates its covariance once
  per second, its cheapest sensible setting);
- ``kf_speedup_vs_pyins``: pyins's time over ours, measured interleaved (ours, pyins, ours, pyins, ... in one
  process after a warm-up of each) and taken round by round; ``kf_speedup_spread``: its median, quartiles,
  rounds and ``unreliable`` (the interquartile range wider than its distance from 1);
- ``nav_bench``: what ran (dataset, sizes, repeats, pyins settings).

Both filters get one warm-up (numba compilation) before the timed runs. Repeats: ``BENCH_NAV_REPEATS``
(default 5) for ours, ``BENCH_PYINS_REPEATS`` (default 3) for pyins, whose run takes about a minute.
"""

from __future__ import annotations

import os
import statistics
import sys
import time

import numpy as np
import pandas as pd

from bgfn.io import update_json
from bgfn.nav.baseline import initial_and_noise, nav_config
from bgfn.nav.filter import run_filter
from bgfn.report.training_words import ratio_text
from bgfn.train.speed import bench_file, interleaved_times, paired_ratio

DATASET = "turin-sim-ekinox"


def _load():
    """The full drive (cached dataset), or a simulated drive of the same size when it is not available."""
    try:
        from bgfn.data import load_drive

        d = load_drive(DATASET)
        return d.name, d.imu, d.gnss, d.meta, d
    except Exception as exc:  # data not fetched: same size, simulated
        print(f"({DATASET} unavailable: {exc}; using a simulated drive of the same size)", file=sys.stderr)
        from bgfn.data.imu_errors import apply_imu_errors, error_params
        from bgfn.nav import sim

        ref = sim.demo_trajectory(1259.0)
        imu, errs, _ = apply_imu_errors(sim.imu_from_trajectory(ref), error_params("ekinox-d"), seed=0,
                                        speed=np.hypot(ref["v_n"], ref["v_e"]).to_numpy()[1:])
        gnss = sim.gnss_from_trajectory(ref, 5.0, 1.0, 3.0, seed=1)

        class _D:
            name, reference, meta = "simulated", ref, {"imu_errors": errs, "lever_arm_m": [0.0, 0.0, 0.0]}

        return "simulated", imu, gnss, _D.meta, _D


def _median_time(fn, n):
    times = []
    for _ in range(n):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times), times


def _pyins_runner(imu, gnss, init, noise, lever, time_step):
    from bgfn.nav.pyins_bridge import feedback_filter

    return feedback_filter(init, noise, imu, gnss, lever, 1.0, 0.1, 0.5, 2.0, time_step=time_step)


def main() -> int:
    n_ours = int(os.environ.get("BENCH_NAV_REPEATS", 5))
    n_pyins = int(os.environ.get("BENCH_PYINS_REPEATS", 3))
    name, imu, gnss5, meta, drive = _load()
    gnss1 = gnss5.iloc[::max(1, int(round(len(gnss5) / (imu["time"].iloc[-1] - imu["time"].iloc[0]))))]
    init, noise = initial_and_noise(drive, nav_config({}))
    lever = meta.get("lever_arm_m", [0.0, 0.0, 0.0])

    def ours(g):
        return lambda: run_filter(imu, init, noise, g, lever)

    ours(gnss1)()  # warm-up (numba cache load / compilation)
    t_ours, runs_ours = _median_time(ours(gnss1), n_ours)
    t_ours5, _ = _median_time(ours(gnss5), max(1, n_ours // 2))
    res = {"kf_full_drive_s": round(t_ours, 4), "kf_full_drive_5hz_s": round(t_ours5, 4)}
    info = {"dataset": name, "n_imu": int(len(imu)), "n_gnss_1hz": int(len(gnss1)), "n_gnss_5hz": int(len(gnss5)),
            "repeats": n_ours, "kf_runs_s": [round(x, 4) for x in runs_ours], "cpu_count": os.cpu_count(),
            "covariance_propagation": "every IMU sample (100 Hz)"}
    try:
        import pyins  # noqa: F401

        time_step = 1.0
        warm = imu[imu["time"] <= imu["time"].iloc[0] + 20.0]
        _pyins_runner(warm, gnss1[gnss1["time"] <= warm["time"].iloc[-1]], init, noise, lever, time_step)()
        pair = interleaved_times({"ours": ours(gnss1), "pyins": _pyins_runner(imu, gnss1, init, noise, lever,
                                                                               time_step)}, n_pyins, warmup=0)
        runs_py, spread = pair["pyins"], paired_ratio(pair["pyins"], pair["ours"])
        t_py = statistics.median(runs_py)
        res.update(pyins_full_drive_s=round(t_py, 3), kf_speedup_vs_pyins=round(spread["median"], 1),
                   kf_speedup_spread=spread)
        info.update(pyins_time_step_s=time_step, pyins_repeats=n_pyins, pyins_runs_s=[round(x, 3) for x in runs_py],
                    pyins_version=__import__("importlib.metadata").metadata.version("python-ins"))
    except ImportError:
        info["pyins"] = "not installed"
    res["nav_bench"] = info
    update_json(bench_file(), res)
    print(f"nav: full drive {info['n_imu']} IMU samples, {info['n_gnss_1hz']} fixes: {t_ours:.2f} s median"
          + (f"; pyins {res['pyins_full_drive_s']:.1f} s; speedup {ratio_text(res['kf_speedup_spread'])}"
             if "pyins_full_drive_s" in res else ""))
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Inference throughput and real-time capability of BGFN and the baselines at the quick and paper sizes.

Adds to ``results/bench.json`` (merged; ``bench_models.py`` runs first under ``make bench`` and writes the
batch-1 latency ``infer_ms.<model>.<size>``, which this script reads instead of timing it again):

- ``throughput_windows_per_s.<model>.<size>``: windows predicted per second in batches of 64 (eval mode, no
  autograd, 1 CPU thread), window N = the profile's window;
- ``realtime_imu_100hz.<model>.<size>``: one prediction (batch 1, 1 thread) takes <= 10 ms, i.e. the model
  could predict at every sample of the 100 Hz IMU;
- ``realtime_gnss_1hz.<model>.<size>``: it takes <= 1 s, i.e. it keeps up with 1 Hz GNSS epochs (one
  pseudo-GNSS increment per epoch during an outage);
- ``speed_bench``: what ran (threads, batch, windows, repeats, the latency used and where it came from).

If ``infer_ms.<model>.<size>`` is missing (``bench_models.py`` not run), the latency is measured here with the
same protocol (batch 1, 1 thread, median after a warm-up) and recorded only under ``speed_bench``.

Usage: ``python benchmarks/bench_speed.py [quick] [paper]`` (default: both).
"""

from __future__ import annotations

import json
import sys

import torch

from bgfn.profile_schema import load_profile
from bgfn.io import update_json
from bgfn.models import METHODS, build_model
from bgfn.train.speed import GNSS_RATE_HZ, IMU_RATE_HZ, bench_file, latency_ms, realtime_flags, throughput

SIZES = ("quick", "paper")
BATCH = 64
THREADS = 1
#: (throughput repeats, fallback latency repeats) per size, after one warm-up each.
REPEATS = {"quick": (5, 20), "paper": (2, 5)}
BENCH = bench_file()


def main(sizes=SIZES, methods=METHODS) -> dict:
    old = json.loads(BENCH.read_text()) if BENCH.exists() else {}
    rate: dict = {m: {} for m in methods}
    imu: dict = {m: {} for m in methods}
    gnss: dict = {m: {} for m in methods}
    info: dict = {"threads": THREADS, "batch": BATCH, "device": "cpu", "torch": torch.__version__,
                  "imu_rate_hz": IMU_RATE_HZ, "gnss_rate_hz": GNSS_RATE_HZ,
                  "budget_ms": {"imu": 1e3 / IMU_RATE_HZ, "gnss": 1e3 / GNSS_RATE_HZ},
                  "latency_ms": {m: {} for m in methods}, "latency_source": {m: {} for m in methods},
                  "window": {}, "repeats": {}}
    for size in sizes:
        cfg = load_profile(size)["train"]
        window = int(cfg["window"])
        n_tp, n_lat = REPEATS[size]
        info["window"][size], info["repeats"][size] = window, [n_tp, n_lat]
        for m in methods:
            torch.manual_seed(0)
            model = build_model(m, dict(cfg["sizes"][m][size]))
            rate[m][size] = throughput(model, window, batch=BATCH, repeats=n_tp, threads=THREADS)
            lat = (old.get("infer_ms") or {}).get(m, {}).get(size)
            if lat is None:
                lat, src = latency_ms(model, window, repeats=n_lat, threads=THREADS), "bench_speed.py"
            else:
                src = "infer_ms (bench_models.py)"
            flags = realtime_flags(lat)
            imu[m][size], gnss[m][size] = flags["imu"], flags["gnss"]
            info["latency_ms"][m][size], info["latency_source"][m][size] = float(lat), src
            print(f"{m:>12} {size:>6}: {rate[m][size]:9.1f} windows/s (batch {BATCH}), {lat:8.2f} ms/window "
                  f"(batch 1) -> 100 Hz IMU: {'yes' if flags['imu'] else 'no'}, "
                  f"1 Hz GNSS: {'yes' if flags['gnss'] else 'no'}", flush=True)
    update_json(BENCH, {"throughput_windows_per_s": rate, "realtime_imu_100hz": imu, "realtime_gnss_1hz": gnss,
                        "speed_bench": info})
    return {"throughput_windows_per_s": rate, "realtime_imu_100hz": imu, "realtime_gnss_1hz": gnss}


if __name__ == "__main__":
    main(sizes=tuple(sys.argv[1:]) or SIZES)

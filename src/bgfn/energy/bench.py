"""Measured CPU speed beside the energy estimate: the figures of ``results/bench.json`` (``make bench``).

The paper argues for BGFN's efficiency in energy only; notebook 05 adds the latency (batch 1) and throughput
(batch 64) measured on this machine by ``benchmarks/bench_models.py`` and ``benchmarks/bench_speed.py``, and
whether each model keeps up with the 100 Hz IMU and the 1 Hz GNSS (:func:`bgfn.speed.realtime_flags`).
"""

from __future__ import annotations

import pandas as pd

#: Keys of ``bench.json`` (method -> size -> value) shown in the table.
SPEED_KEYS = ("infer_ms", "throughput_windows_per_s", "realtime_imu_100hz", "realtime_gnss_1hz")
#: Columns of :func:`speed_table` after ``model`` and ``size``, by ``bench.json`` key.
SPEED_COLUMNS = {"throughput_windows_per_s": "throughput (windows/s, batch 64)",
                 "realtime_imu_100hz": "keeps up with 100 Hz IMU",
                 "realtime_gnss_1hz": "keeps up with 1 Hz GNSS"}


def speed_table(bench: dict, methods=("bgfn", "transformer", "at_lstm", "mlp"),
                sizes=("quick", "paper")) -> pd.DataFrame:
    """One row per method and size that has a speed figure in ``bench`` (the parsed ``bench.json``).

    The latency is ``infer_ms`` (bench_models.py), else bench_speed.py's own ``speed_bench.latency_ms``.

    Returns
    -------
    DataFrame
        ``model, size, latency (ms, batch 1), throughput (windows/s, batch 64), keeps up with 100 Hz IMU,
        keeps up with 1 Hz GNSS`` (None where not measured); empty when ``bench`` has no speed figure.
    """
    if not any(k in bench for k in SPEED_KEYS):
        return pd.DataFrame()
    fallback = (bench.get("speed_bench") or {}).get("latency_ms") or {}
    recs = []
    for m in methods:
        for size in sizes:
            def get(key):
                return (bench.get(key) or {}).get(m, {}).get(size)
            lat = get("infer_ms") if get("infer_ms") is not None else fallback.get(m, {}).get(size)
            rec = {"model": m, "size": size, "latency (ms, batch 1)": lat,
                   **{col: get(key) for key, col in SPEED_COLUMNS.items()}}
            if any(v is not None for k, v in rec.items() if k not in ("model", "size")):
                recs.append(rec)
    return pd.DataFrame(recs)


def speed_notes(bench: dict, path: str = "results/bench.json") -> list[str]:
    """What the table cannot say: no figures yet, the settings they were recorded with, missing keys."""
    if not any(k in bench for k in SPEED_KEYS):
        return [f"{path} has no speed figures yet: `make bench` produces them."]
    info = bench.get("speed_bench") or bench.get("models_bench") or {}
    settings = {k: info.get(k) for k in ("threads", "threads_infer", "batch", "device", "torch") if k in info}
    notes = [f"recorded with: {settings}"]
    missing = [k for k in SPEED_KEYS if k not in bench]
    if missing:
        notes.append(f"missing in {path}: {', '.join(missing)} -- run `make bench`")
    return notes


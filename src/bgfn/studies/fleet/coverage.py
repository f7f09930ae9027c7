"""What the training drives covered, said for each test drive (beyond the paper): its speed and turn-rate
distribution against the training fleet's (:func:`motion_table`), and each outage flagged when more than
``fleet.out_of_range_share`` of its epochs have a reference speed outside the training drives' labelled speeds
(:func:`outage_flags`); the results are then given for the outages in range and out of range apart
(:mod:`bgfn.studies.fleet.summary`)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from bgfn.studies.fleet.drives import PreparedDrive

#: Columns of ``tables/fleet_motion.csv`` (:func:`motion_table`).
MOTION_COLUMNS: tuple[str, ...] = ("test_drive", "role", "minutes", "speed_p05_mps", "speed_p50_mps", "speed_p95_mps",
                                   "speed_max_mps", "turn_p50_dps", "turn_p95_dps", "turn_max_dps")
#: Columns of ``tables/fleet_coverage.csv`` (:func:`outage_flags`).
FLAG_COLUMNS: tuple[str, ...] = ("dataset", "start_s", "duration_s", "speed_max_mps", "train_lo_mps", "train_hi_mps",
                                 "share_outside", "out_of_range")
#: The motion table's roles: the test drive and its training drives together.
ROLES: tuple[str, ...] = ("test", "training")


def speed_range(train: list[PreparedDrive]) -> tuple[float, float]:
    """The lowest and highest labelled speed of the training drives, m/s."""
    v = np.concatenate([p.label_speed[np.isfinite(p.label_speed)] for p in train])
    return float(v.min()), float(v.max())


def motion(drives: list[PreparedDrive]) -> dict:
    """Speed (the label, m/s) and turn-rate (the levelled IMU's |gyro z|, deg/s) quantiles of ``drives`` together."""
    v = np.concatenate([p.label_speed[np.isfinite(p.label_speed)] for p in drives])
    w = np.degrees(np.abs(np.concatenate([p.imu["gyro_z"].to_numpy(float) for p in drives])))
    minutes = sum(float(p.label_time[-1] - p.label_time[0]) for p in drives) / 60.0
    qv, qw = np.percentile(v, [5, 50, 95]), np.percentile(w, [50, 95])
    return {"minutes": minutes, "speed_p05_mps": qv[0], "speed_p50_mps": qv[1], "speed_p95_mps": qv[2],
            "speed_max_mps": float(v.max()), "turn_p50_dps": qw[0], "turn_p95_dps": qw[1], "turn_max_dps": float(w.max())}


def motion_table(splits, by_name: dict) -> pd.DataFrame:
    """Per split ``(test, [training])``: the test drive's motion beside its training fleet's (:data:`MOTION_COLUMNS`)."""
    rows = []
    for test, train in splits:
        rows.append({"test_drive": test, "role": "test", **motion([by_name[test]])})
        rows.append({"test_drive": test, "role": "training", **motion([by_name[n] for n in train])})
    return pd.DataFrame(rows, columns=list(MOTION_COLUMNS))


def outage_flags(name: str, t, truth, starts, durations, lo: float, hi: float, share: float) -> pd.DataFrame:
    """Per outage ``(start, duration)`` of a test drive (epochs ``t`` s, reference speed ``truth`` m/s): the share of
    its epochs whose speed lies outside ``[lo, hi]`` (the training drives' speeds) and whether it exceeds ``share``
    (:data:`FLAG_COLUMNS`)."""
    t, truth = np.asarray(t, dtype=float), np.asarray(truth, dtype=float)
    rows = []
    for s in starts:
        for d in durations:
            m = (t > s) & (t <= s + d + 1e-6) & np.isfinite(truth)
            v = truth[m]
            out = float(np.mean((v < lo) | (v > hi))) if v.size else np.nan
            rows.append({"dataset": name, "start_s": float(s), "duration_s": float(d),
                         "speed_max_mps": float(v.max()) if v.size else np.nan, "train_lo_mps": lo, "train_hi_mps": hi,
                         "share_outside": out, "out_of_range": bool(out > share) if v.size else False})
    return pd.DataFrame(rows, columns=list(FLAG_COLUMNS))

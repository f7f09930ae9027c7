"""What the training drives covered, said for each test drive (beyond the paper): its speed and turn-rate
distribution against the training fleet's (:func:`motion_table`), and each outage flagged when more than
``fleet.out_of_range_share`` of its epochs have a reference speed outside the training drives' labelled speeds, or
a turn rate outside theirs (:func:`outage_flags`); the results are then given for the outages in range and out of
range apart (:mod:`bgfn.studies.fleet.summary`). The turn rate is the levelled IMU's yaw rate averaged over the
odometer's window before each epoch (:func:`turn_rate_at`): what one window shows the odometer, not the vibration
of single samples."""

from __future__ import annotations

import numpy as np
import pandas as pd

from bgfn.studies.fleet.drives import PreparedDrive

#: Columns of ``tables/fleet_motion.csv`` (:func:`motion_table`).
MOTION_COLUMNS: tuple[str, ...] = ("test_drive", "role", "minutes", "speed_p05_mps", "speed_p50_mps", "speed_p95_mps",
                                   "speed_max_mps", "turn_p50_dps", "turn_p95_dps", "turn_max_dps")
#: Columns of ``tables/fleet_coverage.csv`` (:func:`outage_flags`): the speed's share outside the training range
#: and flag, the turn rate's, and ``out_of_range``: either.
FLAG_COLUMNS: tuple[str, ...] = ("dataset", "start_s", "duration_s", "speed_max_mps", "train_lo_mps", "train_hi_mps",
                                 "share_outside", "speed_out_of_range", "turn_max_dps", "turn_train_lo_dps",
                                 "turn_train_hi_dps", "turn_share_outside", "turn_out_of_range", "out_of_range")
#: The motion table's roles: the test drive and its training drives together.
ROLES: tuple[str, ...] = ("test", "training")


def speed_range(train: list[PreparedDrive]) -> tuple[float, float]:
    """The lowest and highest labelled speed of the training drives, m/s."""
    v = np.concatenate([p.label_speed[np.isfinite(p.label_speed)] for p in train])
    return float(v.min()), float(v.max())


def turn_rate_at(p: PreparedDrive, t, window_s: float) -> np.ndarray:
    """The levelled IMU's yaw rate (gyro z, body down: positive turning right) averaged over the samples in
    ``(t - window_s, t]``, deg/s (NaN where the window holds none: a gap)."""
    t = np.asarray(t, dtype=float)
    ti, w = p.imu["time"].to_numpy(float), p.imu["gyro_z"].to_numpy(float)
    csum = np.concatenate([[0.0], np.cumsum(w)])
    i1, i0 = np.searchsorted(ti, t, side="right"), np.searchsorted(ti, t - float(window_s), side="right")
    n = i1 - i0
    out = np.full(t.shape, np.nan)
    out[n > 0] = np.degrees((csum[i1] - csum[i0])[n > 0] / n[n > 0])
    return out


def labelled_turn(p: PreparedDrive, window_s: float) -> np.ndarray:
    """The turn rate (:func:`turn_rate_at`) at the drive's labelled epochs (the windows a training drive gives)."""
    return turn_rate_at(p, p.label_time[np.isfinite(p.label_speed)], window_s)


def turn_range(train: list[PreparedDrive], window_s: float) -> tuple[float, float]:
    """The lowest and highest turn rate of the training drives' labelled windows, deg/s (signed: a fleet that only
    turned left has not seen a right turn)."""
    w = np.concatenate([labelled_turn(p, window_s) for p in train])
    w = w[np.isfinite(w)]
    return float(w.min()), float(w.max())


def motion(drives: list[PreparedDrive], window_s: float) -> dict:
    """Speed (the label, m/s) and turn-rate (:func:`labelled_turn`'s magnitude, deg/s) quantiles of ``drives``
    together."""
    v = np.concatenate([p.label_speed[np.isfinite(p.label_speed)] for p in drives])
    w = np.abs(np.concatenate([labelled_turn(p, window_s) for p in drives]))
    w = w[np.isfinite(w)]
    minutes = sum(float(p.label_time[-1] - p.label_time[0]) for p in drives) / 60.0
    qv, qw = np.percentile(v, [5, 50, 95]), np.percentile(w, [50, 95])
    return {"minutes": minutes, "speed_p05_mps": qv[0], "speed_p50_mps": qv[1], "speed_p95_mps": qv[2],
            "speed_max_mps": float(v.max()), "turn_p50_dps": qw[0], "turn_p95_dps": qw[1], "turn_max_dps": float(w.max())}


def motion_table(splits, by_name: dict, window_s: float) -> pd.DataFrame:
    """Per split ``(test, [training])``: the test drive's motion beside its training fleet's (:data:`MOTION_COLUMNS`),
    turn rates over windows of ``window_s``."""
    rows = []
    for test, train in splits:
        rows.append({"test_drive": test, "role": "test", **motion([by_name[test]], window_s)})
        rows.append({"test_drive": test, "role": "training", **motion([by_name[n] for n in train], window_s)})
    return pd.DataFrame(rows, columns=list(MOTION_COLUMNS))


def share_outside(x: np.ndarray, lo: float, hi: float) -> float:
    """The share of the finite ``x`` outside ``[lo, hi]`` (NaN when none is finite)."""
    x = x[np.isfinite(x)]
    return float(np.mean((x < lo) | (x > hi))) if x.size else np.nan


def outage_flags(name: str, t, truth, starts, durations, lo: float, hi: float, share: float, turn=None,
                 turn_lo: float = -np.inf, turn_hi: float = np.inf) -> pd.DataFrame:
    """Per outage ``(start, duration)`` of a test drive (epochs ``t`` s, reference speed ``truth`` m/s, turn rate
    ``turn`` deg/s or None): the share of its epochs whose speed lies outside ``[lo, hi]`` (the training drives'
    speeds), whether it exceeds ``share``; the same for the turn rate against ``[turn_lo, turn_hi]``; and
    ``out_of_range``: either (:data:`FLAG_COLUMNS`)."""
    t, truth = np.asarray(t, dtype=float), np.asarray(truth, dtype=float)
    turn = np.full(t.shape, np.nan) if turn is None else np.asarray(turn, dtype=float)
    rows = []
    for s in starts:
        for d in durations:
            m = (t > s) & (t <= s + d + 1e-6)
            v, w = truth[m], turn[m]
            sv, sw = share_outside(v, lo, hi), share_outside(w, turn_lo, turn_hi)
            fast, turning = bool(sv > share), bool(sw > share)          # NaN > share is False: nothing to flag
            rows.append({"dataset": name, "start_s": float(s), "duration_s": float(d),
                         "speed_max_mps": float(np.nanmax(v)) if np.isfinite(v).any() else np.nan,
                         "train_lo_mps": lo, "train_hi_mps": hi, "share_outside": sv, "speed_out_of_range": fast,
                         "turn_max_dps": float(np.nanmax(np.abs(w))) if np.isfinite(w).any() else np.nan,
                         "turn_train_lo_dps": turn_lo, "turn_train_hi_dps": turn_hi, "turn_share_outside": sw,
                         "turn_out_of_range": turning, "out_of_range": fast or turning})
    return pd.DataFrame(rows, columns=list(FLAG_COLUMNS))

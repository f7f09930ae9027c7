"""Which headings and speeds training sees: the motion of windows and of the evaluation outages, the fraction a
network must extrapolate to, and what each place of the validation block leaves to training (notebook 03)."""

from __future__ import annotations

import numpy as np
import pandas as pd

from bgfn.learning.references import reference_columns, reference_rmse
from bgfn.learning.split import block_label, split_windows
from bgfn.learning.windows import WindowSet

#: Validation-block positions compared by :func:`val_position_coverage` (notebook 03).
VAL_POSITIONS = ("start", 0.25, "middle", 0.75, "end")


def motion_of_windows(ws: WindowSet) -> pd.DataFrame:
    """Heading (INS yaw at the window end, deg in [0, 360)) and mean speed over the target interval
    (|delta_p_gps| / interval, m/s) of every window: the two quantities the increment depends on most."""
    dt = np.maximum(ws.t_to - ws.t_from, 1e-9)
    return pd.DataFrame({"heading_deg": np.degrees(ws.yaw_ref) % 360.0,
                         "speed_mps": np.hypot(ws.y[:, 0], ws.y[:, 1]) / dt})


def motion_in_windows(reference: pd.DataFrame, windows, step_s: float = 1.0) -> pd.DataFrame:
    """Heading (deg) and horizontal speed (m/s) of the ``reference`` every ``step_s`` inside ``windows``
    ((start, duration) pairs, s): what the networks meet in the evaluation outages. A reference without attitude
    (an RTK solution) gives the course of its velocity instead of the yaw (a car's heading while it moves)."""
    t = reference["time"].to_numpy(float)
    heading = reference["yaw"].to_numpy(float)
    if not np.isfinite(heading).all():
        heading = np.arctan2(reference["v_e"].to_numpy(float), reference["v_n"].to_numpy(float))
    rows = []
    for start, duration in windows:
        ts = np.arange(float(start), float(start) + float(duration), step_s)
        yaw = np.interp(ts, t, np.unwrap(heading))
        v = np.interp(ts, t, np.hypot(reference["v_n"].to_numpy(float), reference["v_e"].to_numpy(float)))
        rows.append(pd.DataFrame({"heading_deg": np.degrees(yaw) % 360.0, "speed_mps": v}))
    return pd.concat(rows, ignore_index=True) if rows else pd.DataFrame(columns=["heading_deg", "speed_mps"])



def motion_sets(data, reference: pd.DataFrame, outage_windows) -> dict[str, pd.DataFrame]:
    """Heading and speed of the training and validation windows of ``data`` (a :class:`bgfn.learning.LearningData`)
    and of the ``reference`` inside the evaluation outages, keyed ``training``, ``validation``, ``evaluation
    outages`` (:func:`bgfn.train.plot_motion_coverage` draws them)."""
    return {"training": motion_of_windows(data.train), "validation": motion_of_windows(data.val),
            "evaluation outages": motion_in_windows(reference, outage_windows)}

def unseen_fraction(train: pd.DataFrame, other: pd.DataFrame, heading_bin_deg: float = 30.0,
                    speed_bin_mps: float = 2.0) -> float:
    """Fraction of the rows of ``other`` whose (heading, speed) cell holds no training row (cells of
    ``heading_bin_deg`` x ``speed_bin_mps``): how much of it a network must extrapolate to."""
    if len(other) == 0:
        return float("nan")

    def cells(df):
        return set(zip((df["heading_deg"].to_numpy() // heading_bin_deg).astype(int),
                       (df["speed_mps"].to_numpy() // speed_bin_mps).astype(int)))
    train, other = train.dropna(), other.dropna()
    if len(other) == 0:
        return float("nan")
    seen = cells(train)
    hit = [c in seen for c in zip((other["heading_deg"].to_numpy() // heading_bin_deg).astype(int),
                                  (other["speed_mps"].to_numpy() // speed_bin_mps).astype(int))]
    return 1.0 - float(np.mean(hit))


def val_position_coverage(ws: WindowSet, outage_motion: pd.DataFrame, outage_windows=(), margin_s: float = 30.0,
                          val_fraction: float = 0.2, positions=VAL_POSITIONS, **cells) -> pd.DataFrame:
    """What each position of the validation block leaves to training.

    The paper does not say how it validated. One block of time is held out (:func:`split_windows`); where it
    lies decides which motions training sees. Computed from windows and the reference only, before any network
    is trained, so the choice of ``train.val_position`` cannot follow a network's score.

    Parameters
    ----------
    ws : WindowSet
        Every window of the drive (:func:`bgfn.learning.windows.make_windows`).
    outage_motion : DataFrame
        Heading and speed inside the evaluation outages (:func:`motion_in_windows`).
    outage_windows, margin_s, val_fraction
        As for :func:`split_windows`.
    positions : sequence
        ``val_position`` values to compare.
    **cells
        ``heading_bin_deg``, ``speed_bin_mps`` of :func:`unseen_fraction`.

    Returns
    -------
    DataFrame
        One row per position: ``val_position``, ``val_block_s``, ``train``, ``val``, ``val_unseen_fraction``,
        ``outage_unseen_fraction`` (fractions of validation windows / outage seconds whose heading x speed
        cell holds no training window), ``train_speed_max_mps`` and the references of
        :func:`reference_rmse` on that block (``val_rmse_zero_m``, ``val_rmse_last_m``, ``val_rmse_ins_m``).
    """
    rows = []
    for pos in positions:
        tr, va, info = split_windows(ws, outage_windows, margin_s=margin_s, val_fraction=val_fraction,
                                     val_position=pos)
        train, val = motion_of_windows(ws.subset(tr)), motion_of_windows(ws.subset(va))
        refs = reference_rmse(ws.subset(va))
        rows.append({"val_position": str(pos),
                     "val_block_s": block_label(info["val_block"]),
                     "train": int(len(tr)), "val": int(len(va)),
                     "val_unseen_fraction": unseen_fraction(train, val, **cells),
                     "outage_unseen_fraction": unseen_fraction(train, outage_motion, **cells),
                     "train_speed_max_mps": float(train["speed_mps"].max()) if len(train) else float("nan"),
                     **reference_columns(refs)})
    return pd.DataFrame(rows)

"""Training and validation windows, and the protocol that decides whether the evaluation outages are among them.

``protocol='honest'`` (ours): a window whose input span or target interval touches an evaluation outage widened
by ``margin_s`` is dropped (:func:`forbidden_intervals`); validation is one held-out block of time
(``val_fraction`` of the remaining windows at ``val_position``), and training windows overlapping that block are
dropped too, so no training window shares an IMU sample or GNSS epoch with a validation window
(:func:`split_windows`).

``protocol='leaky'`` (what the paper may have done: it does not say that its test outages were kept out of
training): the same validation windows, but nothing else is excluded, so the windows of the test outages and of
their margin are training windows. The two protocols share their validation windows; the leaky training set is
the honest one plus the windows the honest protocol excludes (those sharing time with a validation window aside).
"""

from __future__ import annotations

import numpy as np

from bgfn.errors import DataError
from bgfn.learning.windows import WindowSet

#: ``train.protocol``: ``honest`` keeps the evaluation outages (+- ``margin_s``) out of training, ``leaky`` does not.
PROTOCOLS: tuple[str, ...] = ("honest", "leaky")


def forbidden_intervals(outage_windows, margin_s: float) -> np.ndarray:
    """``[start - margin, start + duration + margin]`` per outage, shape [K, 2]."""
    ow = np.asarray(list(outage_windows), dtype=float).reshape(-1, 2)
    if np.any(ow[:, 1] < 0) or margin_s < 0:
        raise DataError("train", "outage_windows/margin_s", "non-negative durations and margin")
    return np.column_stack([ow[:, 0] - margin_s, ow[:, 0] + ow[:, 1] + margin_s])


def overlaps(lo: np.ndarray, hi: np.ndarray, intervals: np.ndarray) -> np.ndarray:
    """Boolean [M]: span ``[lo, hi]`` of each window intersects any of ``intervals`` [K, 2] (closed)."""
    if len(intervals) == 0:
        return np.zeros(len(lo), dtype=bool)
    return ((lo[:, None] <= intervals[None, :, 1]) & (intervals[None, :, 0] <= hi[:, None])).any(axis=1)


def split_windows(ws: WindowSet, outage_windows=(), margin_s: float = 30.0, val_fraction: float = 0.2,
                  val_position="end", protocol: str = "honest") -> tuple[np.ndarray, np.ndarray, dict]:
    """Training and validation window indices (from GPS-available time only, unless ``protocol='leaky'``).

    Parameters
    ----------
    ws : WindowSet
        From :func:`bgfn.learning.windows.make_windows` (sorted by time).
    outage_windows : sequence of (start, duration)
        Evaluation outages, s (GPS time); windows touching ``[start - margin_s, start + duration + margin_s]``
        are excluded from both sets.
    margin_s : float
        Margin around each outage, s.
    val_fraction : float
        Fraction (0 < f < 1) of the remaining windows held out for validation, as one block of time.
    val_position : {'end', 'start', 'middle'} or float
        Where the block lies: a float p in [0, 1] puts it at fraction p of the remaining windows.
    protocol : {'honest', 'leaky'}
        ``'leaky'``: the windows touching the outages and their margin are training windows too (the validation
        block is placed as with ``'honest'``, outside them, so both protocols validate on the same windows;
        training windows sharing time with a validation window are dropped).

    Returns
    -------
    train_idx, val_idx : ndarray of int
    info : dict
        ``forbidden`` intervals, ``val_block`` ``[lo, hi]`` (s), counts of dropped windows
        (``n_outage_excluded``: windows kept out of both sets because they touch the forbidden intervals) and
        ``n_outage_in_train`` (training windows that touch them: 0 unless ``'leaky'``), ``protocol``.
    """
    if protocol not in PROTOCOLS:
        raise DataError("train", "protocol", f"one of {', '.join(PROTOCOLS)}", repr(protocol))
    if not 0.0 < val_fraction < 1.0:
        raise DataError("train", "val_fraction", "a fraction in (0, 1)", repr(val_fraction))
    pos = {"start": 0.0, "middle": 0.5, "end": 1.0}.get(val_position, val_position)
    if not isinstance(pos, (int, float)) or not 0.0 <= float(pos) <= 1.0:
        raise DataError("train", "val_position", "'start', 'middle', 'end' or a number in [0, 1]",
                        repr(val_position))
    lo, hi = ws.span
    forb = forbidden_intervals(outage_windows, margin_s)
    touching = overlaps(lo, hi, forb)
    allowed = np.flatnonzero(~touching)
    if len(allowed) < 2:
        raise DataError("train", "outage_windows", "GPS-available windows outside the outages", f"{len(allowed)}")
    n_val = max(1, int(round(val_fraction * len(allowed))))
    s = int(round(float(pos) * (len(allowed) - n_val)))
    val_idx = allowed[s:s + n_val]
    block = np.array([[lo[val_idx].min(), hi[val_idx].max()]])
    if protocol == "honest":
        rest = np.setdiff1d(allowed, val_idx)
        train_idx = rest[~overlaps(lo[rest], hi[rest], block)]
    else:
        # leaky: every other window trains, the outages' own included; purged are those sharing time with a
        # validation window (not the block's hull, which may span an outage lying between two of its parts)
        rest = np.setdiff1d(np.arange(len(ws)), val_idx)
        train_idx = rest[~overlaps(lo[rest], hi[rest], merged_spans(lo[val_idx], hi[val_idx]))]
    info = {"forbidden": forb.tolist(), "val_block": block[0].tolist(), "n_windows": int(len(ws)),
            "n_outage_excluded": int(len(ws) - len(allowed)) if protocol == "honest" else 0,
            "n_outage_in_train": int(touching[train_idx].sum()), "protocol": protocol,
            "n_purged": int(len(rest) - len(train_idx)), "n_train": int(len(train_idx)), "n_val": int(len(val_idx))}
    return train_idx, val_idx, info


def merged_spans(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The union of the closed spans ``[lo_i, hi_i]`` as disjoint intervals, shape [K, 2], sorted."""
    order = np.argsort(lo, kind="stable")
    out: list[list[float]] = []
    for a, b in zip(lo[order], hi[order]):
        if out and a <= out[-1][1]:
            out[-1][1] = max(out[-1][1], float(b))
        else:
            out.append([float(a), float(b)])
    return np.array(out, dtype=float).reshape(-1, 2)


def block_label(block) -> str:
    """``'<lo>..<hi>'`` (s, one decimal) of a time block ``[lo, hi]``, as the tables show ``val_block_s``."""
    return f"{block[0]:.1f}..{block[1]:.1f}"

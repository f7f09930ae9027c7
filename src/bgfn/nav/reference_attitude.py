"""May the filter start from the reference's attitude? Checked against the course and the IMU's own levelling.

A reference attitude that belongs to another IMU (or to the vehicle, with this IMU mounted otherwise) would start the
filter with a heading or a level error the linearized filter cannot remove. Two checks, each with the tolerance
``nav.alignment.reference_tolerance_deg``:

- **yaw against the course** (a land vehicle moves along its x axis): over the epochs where the reference drives
  straight (yaw rate below :data:`STRAIGHT_MAX_DPS`) and fast (above :data:`STRAIGHT_MIN_SPEED_MPS`), the median of
  ``yaw - course`` beyond the tolerance, or its 5th or 95th percentile beyond twice the tolerance;
- **roll and pitch against the IMU** at rest at the start (:func:`bgfn.nav.alignment.rest_end`): the levelling of the
  mean specific force (:func:`bgfn.nav.alignment.level_from_specific_force`) against the reference's mean roll and
  pitch there (an accelerometer bias of 60 mg tilts the levelling by 3.4 deg: the tolerance is wider).

Numbers and codes only (``bgfn.report`` words them); :func:`bgfn.nav.baseline.prepare_filter` falls back to the
self-alignment (:mod:`bgfn.nav.alignment`) when the attitude is not usable.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from .. import settings
from .alignment import level_from_specific_force, rest_end

#: Straight and fast for the yaw check: yaw rate below (deg/s), speed above (m/s); fewer epochs: no yaw check.
STRAIGHT_MAX_DPS, STRAIGHT_MIN_SPEED_MPS, MIN_STRAIGHT_EPOCHS = 2.0, 5.0, 100
#: Defaults of the ``nav.alignment`` section (rest detection, tolerance; their home: :class:`bgfn.settings.Alignment`).
_ALIGN = settings.defaults("nav.alignment")


def _wrap_deg(x) -> np.ndarray:
    return (np.asarray(x, float) + 180.0) % 360.0 - 180.0


def check_attitude(reference: pd.DataFrame, imu: pd.DataFrame, options: dict | None = None) -> dict | None:
    """The reference attitude against the course and the IMU's levelling (module docstring); None without one.

    Parameters
    ----------
    reference, imu : DataFrame
        The drive's tables (CONTRIBUTING.md schemas).
    options : dict, optional
        The ``nav.alignment`` section (defaults fill the missing keys).

    Returns
    -------
    dict or None
        ``usable`` (bool), ``reason`` (``None``, ``yaw_vs_course`` or ``level_vs_imu``), ``tolerance_deg``,
        ``straight_epochs``, ``yaw_minus_course_deg`` ([median, p05, p95]; None: too few straight epochs),
        ``level_minus_imu_deg`` ([roll, pitch], reference minus IMU levelling; None: no rest at the start).
    """
    cols = ["roll", "pitch", "yaw"]
    if not set(cols) <= set(reference.columns):
        return None
    att = reference[cols].to_numpy(float)
    if not np.isfinite(att).all():
        return None
    o = {**_ALIGN, **(options or {})}
    tol = float(o["reference_tolerance_deg"])
    t = reference["time"].to_numpy(float)
    v_n, v_e = reference["v_n"].to_numpy(float), reference["v_e"].to_numpy(float)
    rate = np.degrees(np.abs(np.gradient(np.unwrap(att[:, 2]), t)))
    straight = (np.hypot(v_n, v_e) > STRAIGHT_MIN_SPEED_MPS) & (rate < STRAIGHT_MAX_DPS)
    out = {"usable": True, "reason": None, "tolerance_deg": tol, "straight_epochs": int(straight.sum()),
           "yaw_minus_course_deg": None, "level_minus_imu_deg": None}
    if straight.sum() >= MIN_STRAIGHT_EPOCHS:
        diff = _wrap_deg(np.degrees(att[straight, 2] - np.arctan2(v_e[straight], v_n[straight])))
        med, p05, p95 = (float(np.percentile(diff, p)) for p in (50, 5, 95))
        out["yaw_minus_course_deg"] = [med, p05, p95]
        if abs(med) > tol or max(abs(p05), abs(p95)) > 2 * tol:
            out.update(usable=False, reason="yaw_vs_course")
    if not {"accel_x", "accel_y", "accel_z", "gyro_x", "gyro_y", "gyro_z"} <= set(imu.columns):
        return out                      # no specific force to level with: the course alone is checked
    t_rest = rest_end(imu, o["still_window_s"], o["still_accel_std_mps2"], np.radians(o["still_gyro_std_dps"]))
    ti = imu["time"].to_numpy(float)
    if t_rest is not None and t_rest - ti[0] >= o["still_min_s"] and (t <= t_rest).any():
        roll, pitch = level_from_specific_force(imu.loc[ti <= t_rest, ["accel_x", "accel_y", "accel_z"]]
                                                .to_numpy(float).mean(axis=0))
        at = t <= t_rest
        diff = _wrap_deg(np.degrees([np.mean(att[at, 0]) - roll, np.mean(att[at, 1]) - pitch]))
        out["level_minus_imu_deg"] = [float(x) for x in diff]
        if out["usable"] and np.max(np.abs(diff)) > tol:
            out.update(usable=False, reason="level_vs_imu")
    return out

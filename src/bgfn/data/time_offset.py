"""Do the GNSS and the IMU of a log share one clock? The offset between them estimated from the data.

A receiver stamps a fix when it arrives (latency, tens to hundreds of ms), a logger may tag the IMU late, and a log
converted by hand may hold GNSS times in UTC against IMU times in GPS time (18 s apart since 2017). Any of these
moves every GNSS update against the inertial solution, and the filter then blames its noise settings (a large
mean NIS) for a clock mistake.

The turn rate is seen by both: the gyros measure it directly, the GNSS course (the direction of the velocity
from successive fixes) changes with it while the platform moves. :func:`estimate_gnss_offset` cross-correlates
the magnitude of the course rate from the fixes with the magnitude of the IMU's angular rate about the vertical
(the direction of the log's mean specific force: the IMU's own, so a mounting or an axis convention does not
matter; the roll and pitch rates, which lead or lag the turn in a car's body, would shift the match) over lags of
+- ``max_lag_s`` and returns the
lag of the best match: the time by which the GNSS stamps are late against the IMU's (positive: the fixes are
stamped after the motion the IMU saw at that time).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from bgfn.nav.earth import lla_to_ned
from bgfn.schema import ACCEL_COLUMNS, GYRO_COLUMNS

#: Lags searched, s (more than the 18 s between GPS time and UTC), and their step, s.
MAX_LAG_S, LAG_STEP_S = 30.0, 0.05
#: The course is a heading only above this horizontal speed, m/s.
MIN_SPEED_MPS = 2.0
#: Below this correlation at the best lag, or with fewer moving fixes, the offset is not estimable.
MIN_CORRELATION, MIN_FIXES = 0.5, 30
#: Offsets beyond this are an error at load (unless meta.yaml states the delay), s.
TOLERANCE_S = 0.5


@dataclass(frozen=True)
class OffsetEstimate:
    """The GNSS-IMU clock offset of a log.

    Attributes
    ----------
    offset_s : float
        How late the GNSS stamps are against the IMU's, s (NaN when not estimable).
    correlation : float
        Correlation of the two turn-rate magnitudes at that lag.
    fixes : int
        Moving fixes the estimate used.
    """

    offset_s: float
    correlation: float
    fixes: int

    @property
    def estimable(self) -> bool:
        return bool(np.isfinite(self.offset_s))

    def line(self) -> str:
        """One sentence for notebook 01."""
        if not self.estimable:
            return (f"GNSS-IMU clock offset: not estimable ({self.fixes} moving fixes, best correlation "
                    f"{self.correlation:.2f} of the turn rates)")
        return (f"GNSS-IMU clock offset: the fixes' stamps are {self.offset_s:+.2f} s late against the IMU's "
                f"(turn rates correlate {self.correlation:.2f} over {self.fixes} moving fixes)")


def course_rate(gnss: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """``(time, |course rate|)`` at the midpoints between successive fixes where the platform moves (rad/s)."""
    t = gnss["time"].to_numpy(float)
    lat, lon, h = (gnss[c].to_numpy(float) for c in ("lat", "lon", "h"))
    north, east, _ = lla_to_ned(lat, lon, h, lat[0], lon[0], h[0]).T
    dt = np.diff(t)
    v_n, v_e = np.diff(north) / dt, np.diff(east) / dt                 # velocity over each interval
    course = np.unwrap(np.arctan2(v_e, v_n))
    moving = np.hypot(v_n, v_e) > MIN_SPEED_MPS
    tm = 0.5 * (t[1:] + t[:-1])                                        # the velocities' times
    rate = np.abs(np.diff(course) / np.diff(tm))
    ok = moving[1:] & moving[:-1]
    return 0.5 * (tm[1:] + tm[:-1])[ok], rate[ok]


def estimate_gnss_offset(imu: pd.DataFrame, gnss: pd.DataFrame, max_lag_s: float = MAX_LAG_S) -> OffsetEstimate:
    """The lag that best aligns the GNSS course rate with the IMU's angular rate (module docstring)."""
    tg, rg = course_rate(gnss)
    if tg.size < MIN_FIXES:
        return OffsetEstimate(float("nan"), float("nan"), int(tg.size))
    ti = imu["time"].to_numpy(float)
    f = imu[list(ACCEL_COLUMNS)].to_numpy(float).mean(axis=0)             # -g on average: the vertical, body frame
    w = np.abs(imu[list(GYRO_COLUMNS)].to_numpy(float) @ (f / np.linalg.norm(f)))
    # the IMU's rate averaged over one GNSS interval (what a course difference sees), as a running mean
    dt_g = float(np.median(np.diff(gnss["time"].to_numpy(float))))
    n = max(1, int(round(dt_g / float(np.median(np.diff(ti))))))
    c = np.concatenate([[0.0], np.cumsum(w)])
    w_mean = (c[n:] - c[:-n]) / n
    t_mean = 0.5 * (ti[n - 1:] + ti[:len(ti) - n + 1])
    lags = np.arange(-max_lag_s, max_lag_s + LAG_STEP_S / 2, LAG_STEP_S)
    best = (float("nan"), -np.inf)
    for lag in lags:
        ts = tg - lag                                                   # the IMU time a fix's motion belongs to
        inside = (ts >= t_mean[0]) & (ts <= t_mean[-1])
        if inside.sum() < MIN_FIXES:
            continue
        r = np.corrcoef(rg[inside], np.interp(ts[inside], t_mean, w_mean))[0, 1]
        if np.isfinite(r) and r > best[1]:
            best = (float(lag), float(r))
    if best[1] < MIN_CORRELATION:
        return OffsetEstimate(float("nan"), float(best[1]) if np.isfinite(best[1]) else float("nan"), int(tg.size))
    return OffsetEstimate(best[0], best[1], int(tg.size))

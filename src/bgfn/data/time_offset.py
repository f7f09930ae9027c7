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
stamped after the motion the IMU saw at that time), with its std from a block bootstrap over the fixes.

A correlation can peak at a wrong lag on a real log (vibration, a phone's own rotation), so an estimate is a
candidate, not a fact: :func:`decide_clock` applies an offset (``gnss_latency_s: auto``) only when it agrees with
the lag the reference shows (:func:`bgfn.data.reference_check.reference_lag`, a second, independent method), and
then the two's inverse-variance mean only when it is significant, a latency ``gnss_latency_s`` takes when typed,
and does not widen the fixes' along-track error against the reference; and it names an offset beyond
:data:`TOLERANCE_S` that the evidence supports (the loader's error).
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np
import pandas as pd

from bgfn.data.csv_meta import MAX_TIME_SHIFT_S
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
#: Block bootstrap of the estimate's std: blocks of this many seconds of fixes, the lags within this of the best,
#: this many draws, this seed; fewer blocks: no std.
BLOCK_S, BOOTSTRAP_HALF_S, BOOTSTRAP_DRAWS, BOOTSTRAP_SEED, MIN_BLOCKS = 10.0, 1.0, 200, 0, 4


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
    std_s : float
        Its std from a block bootstrap over the fixes (NaN: not estimable, or too few blocks), s.
    """

    offset_s: float
    correlation: float
    fixes: int
    std_s: float = float("nan")

    @property
    def estimable(self) -> bool:
        return bool(np.isfinite(self.offset_s))


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
    std = _bootstrap_std(tg, rg, t_mean, w_mean, best[0])
    return OffsetEstimate(best[0], best[1], int(tg.size), std)


def _bootstrap_std(tg: np.ndarray, rg: np.ndarray, t_mean: np.ndarray, w_mean: np.ndarray, lag0: float) -> float:
    """Std of the best lag over block-bootstrap draws of the fixes (blocks of ``BLOCK_S``), the lags within
    ``BOOTSTRAP_HALF_S`` of ``lag0`` (NaN with fewer than ``MIN_BLOCKS`` blocks); at least half a lag step."""
    lags = lag0 + np.arange(-BOOTSTRAP_HALF_S, BOOTSTRAP_HALF_S + LAG_STEP_S / 2, LAG_STEP_S)
    inside = np.ones(tg.size, bool)
    for lag in lags[[0, -1]]:
        inside &= (tg - lag >= t_mean[0]) & (tg - lag <= t_mean[-1])
    x, t = rg[inside], tg[inside]
    y = np.stack([np.interp(t - lag, t_mean, w_mean) for lag in lags])        # [L, n]
    block = np.floor((t - t[0]) / BLOCK_S).astype(int)
    blocks = np.unique(block)
    if blocks.size < MIN_BLOCKS:
        return float("nan")
    member = (block[None, :] == blocks[:, None]).astype(float)                # [B, n]
    sx, sxx, n_b = member @ x, member @ (x * x), member.sum(axis=1)
    sy, syy, sxy = y @ member.T, (y * y) @ member.T, (y * x) @ member.T       # [L, B]
    rng = np.random.default_rng(BOOTSTRAP_SEED)
    draws = np.stack([np.bincount(rng.integers(0, blocks.size, blocks.size), minlength=blocks.size)
                      for _ in range(BOOTSTRAP_DRAWS)]).astype(float).T       # [B, D]
    n = n_b @ draws
    mx, my = (sx @ draws) / n, (sy @ draws) / n
    cov = (sxy @ draws) / n - mx * my
    var_x, var_y = (sxx @ draws) / n - mx ** 2, (syy @ draws) / n - my ** 2
    r = cov / np.sqrt(np.maximum(var_x * var_y, 1e-30))                        # [L, D]
    return float(max(np.std(lags[np.argmax(r, axis=0)]), LAG_STEP_S / 2))


#: What became of an estimated offset (:func:`decide_clock`): ``applied``; ``not_asked`` (a stated latency: nothing
#: estimated is applied); ``not_estimable`` (the turn rates show none); ``not_significant`` (within :data:`CLOCK_SIGMAS`
#: of its std or the floor); ``unconfirmed`` (no lag from the reference to check it against); ``disagrees`` (with the
#: reference's lag); ``refused_by_key`` (a latency ``gnss_latency_s`` refuses when typed: negative, or beyond
#: :data:`bgfn.data.csv_meta.MAX_TIME_SHIFT_S`); ``worse`` (the fixes' along-track spread against the reference
#: grows with it).
CLOCK_STATUSES = ("applied", "not_asked", "not_estimable", "not_significant", "unconfirmed", "disagrees",
                  "refused_by_key", "worse")
#: A lag without a std (too few blocks) still names a gross offset when it shrinks the along-track spread by this.
GROSS_SPREAD_RATIO = 0.5
#: The rule's thresholds: an offset counts beyond this many of its std and beyond a floor (s); the two methods agree
#: within this (s) or within that many of their combined std.
CLOCK_SIGMAS, CLOCK_FLOOR_S, CLOCK_AGREEMENT_S = 3.0, 0.02, 0.1


@dataclass(frozen=True)
class ClockDecision:
    """The GNSS-IMU clock of a log (:func:`decide_clock`), numbers and codes.

    ``status`` (:data:`CLOCK_STATUSES`); ``applied_s`` (taken off the fixes' stamps, s); the turn-rate estimate
    ``turn_rate_s`` +- ``turn_rate_std_s`` (correlation ``correlation``, ``fixes``); the reference's lag
    ``reference_lag_s`` +- ``reference_std_s`` (``reference_reason``: why none); where they agree their
    inverse-variance mean ``combined_s`` +- ``combined_std_s`` (the candidate); the fixes' along-track RMS about
    its mean against the reference without and with the candidate (``rms_without_m``, ``rms_with_m``; NaN: not
    compared); ``gross_s``: an offset beyond :data:`TOLERANCE_S` left after ``applied_s`` that the evidence supports
    (NaN: none), ``gross_method`` (``reference`` or ``turn_rate``).
    """

    status: str
    applied_s: float
    turn_rate_s: float
    turn_rate_std_s: float
    correlation: float
    fixes: int
    reference_lag_s: float
    reference_std_s: float
    reference_reason: str | None
    combined_s: float = float("nan")
    combined_std_s: float = float("nan")
    rms_without_m: float = float("nan")
    rms_with_m: float = float("nan")
    gross_s: float = float("nan")
    gross_method: str | None = None

    def record(self) -> dict:
        """JSON-ready (``meta["gnss_offset"]``; NaN as None)."""
        return {k: (None if isinstance(v, float) and not np.isfinite(v) else v) for k, v in self.__dict__.items()}


def _significant(x: float, std: float) -> bool:
    return bool(np.isfinite(x) and np.isfinite(std) and abs(x) > max(CLOCK_FLOOR_S, CLOCK_SIGMAS * std))


def decide_clock(est: OffsetEstimate, lag, auto: bool, rms_at: Callable[[float], float] | None = None) -> ClockDecision:
    """Whether the GNSS-IMU offset is taken off the fixes (``auto``: ``gnss_latency_s: auto``): the turn-rate
    estimate ``est`` checked against the reference's lag ``lag`` (:class:`bgfn.data.reference_check.Lag`, or None
    without a usable reference).

    The two must agree (within :data:`CLOCK_AGREEMENT_S` or :data:`CLOCK_SIGMAS` of their combined std: the turn
    rates say that the reference shares the IMU's clock); their inverse-variance mean is then applied when it is significant
    (beyond :data:`CLOCK_SIGMAS` of its std and :data:`CLOCK_FLOOR_S`), a latency the key takes when typed (0 to
    :data:`~bgfn.data.csv_meta.MAX_TIME_SHIFT_S`) and does not widen the fixes' along-track spread against the
    reference (``rms_at(shift)``, m). Then the offset left (the lag's, else the turn rates' where no lag
    contradicts them) beyond :data:`TOLERANCE_S` is ``gross_s``: the loader's error.
    """
    c, sc = est.offset_s, est.std_s
    has_lag = lag is not None and lag.estimable and np.isfinite(lag.std_s)
    r, sr = (lag.lag_s, lag.std_s) if has_lag else (float("nan"), float("nan"))
    agree = has_lag and np.isfinite(c) and abs(c - r) <= max(CLOCK_AGREEMENT_S, CLOCK_SIGMAS * float(np.hypot(sc, sr)))
    both, both_std = float("nan"), float("nan")
    if agree and np.isfinite(sc):              # the two methods' inverse-variance mean
        w_c, w_r = 1.0 / sc ** 2, 1.0 / sr ** 2
        both, both_std = (w_c * c + w_r * r) / (w_c + w_r), float(np.sqrt(1.0 / (w_c + w_r)))
    rms0 = rms1 = float("nan")
    if not auto:
        status = "not_asked"
    elif not est.estimable or not np.isfinite(sc):
        status = "not_estimable"
    elif not has_lag:
        status = "unconfirmed"
    elif not agree:
        status = "disagrees"
    elif not _significant(both, both_std):
        status = "not_significant"
    elif both < 0 or both > MAX_TIME_SHIFT_S:
        status = "refused_by_key"
    else:
        rms0, rms1 = (float(rms_at(x)) for x in (0.0, both)) if rms_at is not None else (float("nan"),) * 2
        status = "worse" if rms1 > rms0 else "applied"
    applied = both if status == "applied" else 0.0
    gross, method = float("nan"), None
    # a lag beyond the tolerance counts when significant, or (too few blocks for a std) when it removes most of
    # the fixes' along-track spread: an 18 s offset on a minute of driving
    clear = lag is not None and lag.estimable and (_significant(lag.lag_s, lag.std_s) or
                                                   lag.rms_at_lag_m < GROSS_SPREAD_RATIO * lag.rms_m)
    if clear and abs(lag.lag_s - applied) > TOLERANCE_S:
        gross, method = lag.lag_s - applied, "reference"
    elif (np.isfinite(c) and abs(c - applied) > TOLERANCE_S and _significant(c, sc) and (agree or not has_lag)):
        gross, method = c - applied, "turn_rate"
    return ClockDecision(status, float(applied), c, sc, est.correlation, est.fixes,
                         r if lag is None else lag.lag_s, sr if lag is None else lag.std_s,
                         None if lag is None else lag.reason, both, both_std, rms0, rms1, gross, method)

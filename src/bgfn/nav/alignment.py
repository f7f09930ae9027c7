"""Coarse self-alignment of a land vehicle's INS from its own IMU and GNSS (no reference attitude needed).

The paper's filter (Sec. 2, Eqs. eq3-eq4) is linearized about a known attitude and cannot start from an unknown
heading; real logs rarely carry a reference attitude. So the filter starts at an *alignment epoch* chosen from the
data: the first fix that ends ``heading_time_s`` of GNSS intervals above ``speed_threshold_mps``. Level comes from
the mean specific force at rest (a still span of at least ``still_min_s`` at the start) carried by the gyros, else
from velocity matching over ``level_time_s``; heading from the course of those GNSS intervals, each turned by the
gyros to the epoch; position and velocity from the fix; P0 from the fixes' stds and the options' level and azimuth
stds. A land vehicle is taken to move along its body x axis. Durations in s, speeds m/s, angles rad unless a key's
name says deg; the options are the ``nav.alignment`` section (:data:`ALIGNMENT_DEFAULTS`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from .. import settings
from ..errors import DataError
from . import earth, error_model as em, transform
from .state import FilterNoise, FilterState, initial_covariance

#: How the filter's initial state is found (``nav.alignment.mode``): ``reference`` = the reference's first row
#: (the drive must carry an attitude), ``gnss`` = this module, ``auto`` = reference when the drive has an
#: attitude, else gnss.
MODES = ("reference", "gnss", "auto")

#: Defaults of the ``nav.alignment`` profile section (their home: :class:`bgfn.settings.Alignment`).
ALIGNMENT_DEFAULTS: dict = settings.defaults("nav.alignment")

#: Shortest GNSS interval the course and the speed are taken over, s: at 5 Hz a 0.2 s difference of metre-level
#: fixes would give speeds with several m/s of noise.
BASELINE_S = 1.0
#: A GNSS interval longer than this many nominal intervals is a gap: the moving run restarts after it.
MAX_GAP_INTERVALS = 2.5
#: Most level iterations of the velocity matching (each divides the error by about g / |dv/dt|), and the change
#: that ends them, rad.
LEVEL_ITERATIONS = 50
LEVEL_CONVERGED_RAD = 1e-12


@dataclass(frozen=True)
class Alignment:
    """Result of :func:`align`.

    Attributes
    ----------
    state : FilterState
        Initial filter state at ``state.time`` (the first IMU epoch at or after the alignment fix).
    gnss_time : float
        Time of the GNSS fix that gives the position and ends the heading run, s.
    roll, pitch, yaw : float
        Attitude at ``state.time``, rad.
    level_source : str
        ``rest`` (mean specific force at rest) or ``gnss_acceleration`` (velocity matching while moving).
    course_source : str
        ``gnss_velocity`` or ``gnss_positions`` (differenced fixes).
    rest_end : float or None
        End of the stationary span at the start, s (None: no rest of ``still_min_s``).
    moving_from : float
        Start of the run of GNSS intervals above the speed threshold, s.
    level_std, azimuth_std : float
        Their std in P0, rad.
    velocity_std : ndarray, shape (3,)
        NED velocity std in P0, m/s.
    """

    state: FilterState
    gnss_time: float
    roll: float
    pitch: float
    yaw: float
    level_source: str
    course_source: str
    rest_end: float | None
    moving_from: float
    level_std: float
    azimuth_std: float
    velocity_std: np.ndarray


def level_from_specific_force(f_b) -> tuple[float, float]:
    """Roll and pitch of a body whose specific force is ``f_b = C_bn^T (-g^n)`` (at rest, or gravity alone).

    Parameters
    ----------
    f_b : array_like, shape (3,)
        Specific force in the body frame, m/s^2.

    Returns
    -------
    roll, pitch : float
        rad.
    """
    f = np.asarray(f_b, dtype=float)
    # C_bn^T [0, 0, -g] = [g sin(pitch), -g sin(roll) cos(pitch), -g cos(roll) cos(pitch)]
    return float(np.arctan2(-f[1], -f[2])), float(np.arctan2(f[0], np.hypot(f[1], f[2])))


def level_by_velocity_matching(f_mean_b, accel_n, yaw: float) -> tuple[float, float]:
    """Roll and pitch such that ``C_bn(roll, pitch, yaw)^T (accel_n - g^n) = f_mean_b``.

    Parameters
    ----------
    f_mean_b : array_like, shape (3,)
        Specific force averaged over a span, in the body frame at its end, m/s^2.
    accel_n : array_like, shape (3,)
        Mean NED acceleration over the same span (velocity change over its length), m/s^2.
    yaw : float
        Heading at the span's end, rad.

    Returns
    -------
    roll, pitch : float
        rad. Iterated: the body-frame acceleration is removed with the current estimate, the rest is gravity.
    """
    f = np.asarray(f_mean_b, dtype=float)
    a = np.asarray(accel_n, dtype=float)
    roll = pitch = 0.0
    for _ in range(LEVEL_ITERATIONS):
        c = transform.dcm_from_euler(roll, pitch, yaw)
        new = level_from_specific_force(f - c.T @ a)
        done = max(abs(new[0] - roll), abs(new[1] - pitch)) < LEVEL_CONVERGED_RAD
        roll, pitch = new
        if done:
            break
    return roll, pitch


def rest_end(imu: pd.DataFrame, window_s: float, accel_std_max: float, gyro_std_max: float) -> float | None:
    """End of the stationary span at the start of a drive, detected from the IMU alone.

    Parameters
    ----------
    imu : DataFrame
        IMU table (CONTRIBUTING.md schema).
    window_s : float
        Block length, s.
    accel_std_max : float
        Largest spread of the specific force in a still block (root sum of the per-axis variances), and largest
        change of its block mean from the first block's, m/s^2.
    gyro_std_max : float
        The same for the angular rate, rad/s.

    Returns
    -------
    float or None
        Time of the last IMU row of the last still block but one (the last may hold the first motion), s;
        None when fewer than two leading blocks are still.
    """
    t = imu["time"].to_numpy(float)
    n = max(2, int(round(window_s / float(np.median(np.diff(t)))))) if t.size > 1 else 2
    blocks = t.size // n
    if blocks < 2:
        return None
    acc = imu[["accel_x", "accel_y", "accel_z"]].to_numpy(float)[: blocks * n].reshape(blocks, n, 3)
    gyr = imu[["gyro_x", "gyro_y", "gyro_z"]].to_numpy(float)[: blocks * n].reshape(blocks, n, 3)
    spread_a = np.sqrt(acc.var(axis=1).sum(axis=1))                   # [blocks]
    spread_g = np.sqrt(gyr.var(axis=1).sum(axis=1))
    # a smooth drive (a simulated IMU, no vibration) can be as quiet as rest: its means move away from the first
    # block's (acceleration, turning), a standing car's do not
    drift_a = np.linalg.norm(acc.mean(axis=1) - acc[0].mean(axis=0), axis=1)
    drift_g = np.linalg.norm(gyr.mean(axis=1) - gyr[0].mean(axis=0), axis=1)
    still = (spread_a < accel_std_max) & (spread_g < gyro_std_max) & (drift_a < accel_std_max) & (drift_g < gyro_std_max)
    k = int(np.argmin(still)) if not still.all() else blocks        # leading still blocks
    if k < 2:
        return None
    return float(t[(k - 1) * n - 1])


@dataclass(frozen=True)
class _Intervals:
    """GNSS intervals of at least :data:`BASELINE_S`: ends ``t0``/``t1`` (s), NED displacement ``d`` [M, 3] (m),
    its per-axis std ``d_std`` [M, 3] (m), whether ``d`` came from the GNSS velocities ``from_velocity`` [M]."""

    t0: np.ndarray
    t1: np.ndarray
    d: np.ndarray
    d_std: np.ndarray
    from_velocity: np.ndarray

    @property
    def speed(self) -> np.ndarray:
        return np.hypot(self.d[:, 0], self.d[:, 1]) / (self.t1 - self.t0)


def gnss_intervals(gnss: pd.DataFrame, velocity_std: float, source: str = "gnss") -> _Intervals:
    """Displacements between GNSS fixes at least :data:`BASELINE_S` apart (fixes without a position skipped).

    Where both fixes carry a velocity, the displacement is its trapezoid (``velocity_std`` per axis, m/s);
    otherwise the difference of the positions (std from the fixes' ``std_n/e/d``).
    """
    g = gnss[np.isfinite(gnss[["lat", "lon", "h"]].to_numpy(float)).all(axis=1)]
    t = g["time"].to_numpy(float)
    if t.size < 3:
        raise DataError(source, "lat/lon/h", "GNSS fixes to align the filter", f"{t.size} fixes")
    step = max(1, int(round(BASELINE_S / float(np.median(np.diff(t))))))
    g = g.iloc[::step]
    t = g["time"].to_numpy(float)
    lat, lon, h = (g[c].to_numpy(float) for c in ("lat", "lon", "h"))
    d = earth.lla_to_ned(lat[1:], lon[1:], h[1:], lat[:-1], lon[:-1], h[:-1])          # [M, 3]
    std = g[["std_n", "std_e", "std_d"]].to_numpy(float)
    d_std = np.sqrt(std[1:] ** 2 + std[:-1] ** 2)
    v = g[["v_n", "v_e", "v_d"]].to_numpy(float)
    has_v = np.isfinite(v[1:]).all(axis=1) & np.isfinite(v[:-1]).all(axis=1)
    dt = np.diff(t)
    d[has_v] = 0.5 * (v[1:] + v[:-1])[has_v] * dt[has_v, None]
    d_std[has_v] = velocity_std * dt[has_v, None]
    return _Intervals(t[:-1], t[1:], d, d_std, has_v)


def _moving_run(iv: _Intervals, speed_min: float, duration: float, t_after: float, source: str) -> tuple[int, int]:
    """Indices ``(first, last)`` of the first run of gap-free intervals above ``speed_min`` lasting ``duration``
    and starting at or after ``t_after``."""
    dt = iv.t1 - iv.t0
    ok = (iv.speed > speed_min) & (dt <= MAX_GAP_INTERVALS * float(np.median(dt))) & (iv.t0 >= t_after - 1e-9)
    first, best = None, 0.0
    for k in range(len(ok)):
        if not ok[k]:
            first = None
            continue
        first = k if first is None else first
        best = max(best, iv.t1[k] - iv.t0[first])
        if iv.t1[k] - iv.t0[first] >= duration - 1e-9:
            return first, k
    raise DataError(source, "gnss", f"{duration:g} s of driving above {speed_min:g} m/s to find the heading "
                    "(nav.alignment.heading_time_s, speed_threshold_mps)", f"at most {best:.1f} s")


def _body_track(t: np.ndarray, gyro: np.ndarray, i0: int, i1: int, bias: np.ndarray) -> np.ndarray:
    """Rotations ``R_k = C_b(t_i1)^T C_b(t_k)`` (body at row k -> body at row i1) for rows ``i0..i1`` from the
    gyros minus ``bias`` (IMU row k = mean rate over ``(t[k-1], t[k]]``), [i1 - i0 + 1, 3, 3]."""
    steps = transform.dcm_from_rotvec((gyro[i0 + 1:i1 + 1] - bias) * np.diff(t[i0:i1 + 1])[:, None])
    c = np.empty((i1 - i0 + 1, 3, 3))
    c[0] = np.eye(3)
    for k, s in enumerate(steps):
        c[k + 1] = c[k] @ s                                       # C_b0_bk
    return np.einsum("ji,kjl->kil", c[-1], c)                     # C_b0_bi1^T C_b0_bk


def align(imu: pd.DataFrame, gnss: pd.DataFrame, lever_arm, noise: FilterNoise, options: dict | None = None,
          source: str = "drive") -> Alignment:
    """Coarse self-alignment (module docstring): the filter state at the alignment epoch.

    Parameters
    ----------
    imu, gnss : DataFrame
        Drive tables (CONTRIBUTING.md schemas); GNSS velocities may be NaN.
    lever_arm : array_like, shape (3,)
        GNSS antenna in the body frame from the IMU, m.
    noise : FilterNoise
        The filter's noise (its bias priors enter P0 and the level std).
    options : dict, optional
        The ``nav.alignment`` section (:data:`ALIGNMENT_DEFAULTS` fill the missing keys).
    source : str
        Name used in error messages.

    Returns
    -------
    Alignment

    Raises
    ------
    DataError
        No GNSS run fast and long enough for the heading, or too few GNSS fixes.
    """
    o = {**ALIGNMENT_DEFAULTS, **(options or {})}
    lever = np.asarray(lever_arm, dtype=float).reshape(3)
    t = imu["time"].to_numpy(float)
    gyro = imu[["gyro_x", "gyro_y", "gyro_z"]].to_numpy(float)
    acc = imu[["accel_x", "accel_y", "accel_z"]].to_numpy(float)

    # 1. rest at the start
    t_rest = rest_end(imu, o["still_window_s"], o["still_accel_std_mps2"], np.radians(o["still_gyro_std_dps"]))
    if t_rest is not None and t_rest - t[0] < o["still_min_s"]:
        t_rest = None
    # 2. alignment epoch: the end of the first moving run, the state at the next IMU epoch
    iv = gnss_intervals(gnss, o["velocity_std_mps"], source)
    fast = iv.speed > o["speed_threshold_mps"]
    if t_rest is not None and fast.any() and iv.t0[fast][0] < t_rest:   # the GNSS saw motion the IMU did not
        t_rest = float(iv.t0[fast][0]) if iv.t0[fast][0] - t[0] >= o["still_min_s"] else None
    first, last = _moving_run(iv, o["speed_threshold_mps"], o["heading_time_s"],
                              t[0] if t_rest is None else t_rest, source)
    t_g = float(iv.t1[last])
    i_a = int(np.searchsorted(t, t_g - 1e-9))
    if i_a >= t.size:
        raise DataError(source, "imu", f"IMU rows after the alignment fix at {t_g} s", "none")
    t_a = float(t[i_a])
    # the gyro track reaches back to the rest, or over the heading run and the level span (one interval spare)
    t_from = t_rest if t_rest is not None else min(float(iv.t0[first]),
                                                   t_a - o["level_time_s"] - 2.0 * float(np.max(iv.t1 - iv.t0)))
    i0 = max(0, int(np.searchsorted(t, t_from + 1e-9)) - 1)
    bias = np.zeros(3)
    if t_rest is not None:
        rest = t <= t_rest
        bias = gyro[rest].mean(axis=0)                    # gyro bias plus Earth rate, removed while waiting
    R = _body_track(t, gyro, i0, i_a, bias)               # [K, 3, 3] body_k -> body_a
    tk = t[i0:i_a + 1]

    # 3a. level after rest: the mean specific force at rest, carried to t_a
    fix = gnss.loc[np.isclose(gnss["time"].to_numpy(float), t_g, rtol=0, atol=1e-9)].iloc[0]
    g = float(earth.normal_gravity(fix["lat"], fix["h"]))
    ba_h = float(np.hypot(*noise.accel_bias_std[:2]) / np.sqrt(2.0))
    if t_rest is not None:
        roll0, pitch0 = level_from_specific_force(acc[t <= t_rest].mean(axis=0))
        c_a = transform.dcm_from_euler(roll0, pitch0, 0.0) @ R[0].T         # C_bn(t_a) = C_bn(t_rest) R_rest^T
        roll, pitch, _ = transform.euler_from_dcm(c_a)
        level_std = np.hypot(np.radians(o["level_std_deg"]), ba_h / g)
        level_source = "rest"
    else:
        roll = pitch = 0.0
    # 4. heading from the course, then (moving start) the level, twice: each needs the other
    course = slice(first, last + 1)
    d_ne = iv.d[course, :2]                                          # [M, 2]
    mid = 0.5 * (iv.t0[course] + iv.t1[course])
    n_iter = 1 if t_rest is not None else 2
    for _ in range(n_iter):
        # heading of body_k in a frame with the aligned level at t_a and zero yaw: minus the change to t_a
        yaw_k = np.unwrap(transform.euler_from_dcm(transform.dcm_from_euler(roll, pitch, 0.0) @ R)[2])
        dpsi = -np.interp(mid, tk, yaw_k)                         # heading change from each mid-time to t_a
        turned = np.column_stack([d_ne[:, 0] * np.cos(dpsi) - d_ne[:, 1] * np.sin(dpsi),
                                  d_ne[:, 0] * np.sin(dpsi) + d_ne[:, 1] * np.cos(dpsi)])
        total = turned.sum(axis=0)
        yaw = float(np.arctan2(total[1], total[0]))
        if t_rest is None:
            roll, pitch, level_std = _moving_level(t, acc, R, tk, iv, last, o["level_time_s"], yaw, g, ba_h,
                                                   np.radians(o["level_std_deg"]))
            level_source = "gnss_acceleration"
    # course noise: the sum's error across its direction over its length. Differenced positions telescope (the
    # sum's error is that of its two end fixes, one interval's std); velocity displacements add their errors.
    path = float(np.hypot(*total))
    n_iv = last - first + 1
    cross = float(np.sqrt(np.mean(iv.d_std[course, :2] ** 2)) * (np.sqrt(n_iv) if iv.from_velocity[course].all()
                                                                   else 1.0))
    azimuth_std = float(np.hypot(np.radians(o["azimuth_std_deg"]), cross / max(path, 1e-6)))
    c_bn = transform.dcm_from_euler(roll, pitch, yaw)

    # 5. velocity and position at t_a
    v_fix = fix[["v_n", "v_e", "v_d"]].to_numpy(float)
    if np.isfinite(v_fix).all():
        v_ant, v_std = v_fix, np.full(3, o["velocity_std_mps"])
        course_source = "gnss_velocity" if iv.from_velocity[course].all() else "gnss_positions"
    else:
        dt_last = iv.t1[last] - iv.t0[last]
        t_mid = 0.5 * (iv.t0[last] + iv.t1[last])
        v_ant = iv.d[last] / dt_last + _velocity_change(t, acc, R, tk, c_bn, g, t_mid, t_a)
        v_std = np.maximum(iv.d_std[last] / dt_last, o["velocity_std_mps"])
        course_source = "gnss_positions"
    w = gyro[i_a] - bias
    v = v_ant - c_bn @ np.cross(w, lever)                            # the antenna's extra velocity when turning
    ant = np.array([fix["lat"], fix["lon"], fix["h"]], dtype=float)
    lat, lon, h = earth.ned_to_lla(-c_bn @ lever + v * (t_a - t_g), *ant)
    pos = np.array([lat, lon, h], dtype=float)

    # 6. P0 from the alignment's uncertainty
    std = fix[["std_n", "std_e", "std_d"]].to_numpy(float)
    if not (np.isfinite(std).all() and np.all(std > 0)):
        raise DataError(source, "gnss std_n/std_e/std_d", f"positive stds of the alignment fix at {t_g} s",
                        str(std.tolist()))
    P0 = initial_covariance(pos, noise, float(np.max(std[:2])), float(std[2]), 1.0, level_std, azimuth_std)
    P0[em.DV_NED, em.DV_NED] = v_std ** 2
    state = FilterState(t_a, pos, v, np.ascontiguousarray(c_bn), np.zeros(3), np.zeros(3), P0)
    return Alignment(state, t_g, float(roll), float(pitch), yaw, level_source, course_source, t_rest,
                     float(iv.t0[first]), float(level_std), azimuth_std, v_std)


def _mean_specific_force(t, acc, R, tk, t0: float, t1: float) -> np.ndarray:
    """Specific force averaged over ``(t0, t1]`` in the body frame at the track's end, m/s^2."""
    rows = np.flatnonzero((tk > t0 + 1e-9) & (tk <= t1 + 1e-9))
    i0 = int(np.searchsorted(t, tk[0] - 1e-9))
    k = rows + i0                                                    # IMU rows of the span
    prev = np.maximum(rows - 1, 0)                                   # body at the start of each step
    dt = t[k] - t[k - 1]
    return np.einsum("kij,kj,k->i", R[prev], acc[k], dt) / dt.sum()


def _velocity_change(t, acc, R, tk, c_bn, g, t0: float, t1: float) -> np.ndarray:
    """Velocity change over ``(t0, t1]`` from the IMU with the aligned attitude (``C_bn(t) = C_bn(t_a) R(t)``), m/s."""
    if t1 <= t0:
        return np.zeros(3)
    f = _mean_specific_force(t, acc, R, tk, t0, t1)
    return (c_bn @ f + np.array([0.0, 0.0, g])) * (t1 - t0)


def _moving_level(t, acc, R, tk, iv: _Intervals, last: int, level_time: float, yaw: float, g: float,
                  ba_h: float, floor: float) -> tuple[float, float, float]:
    """Velocity matching over the last ``level_time`` before the alignment fix (module docstring)."""
    mid = 0.5 * (iv.t0 + iv.t1)
    vel = iv.d / (iv.t1 - iv.t0)[:, None]
    j0 = int(np.argmin(np.abs(mid[: last + 1] - (mid[last] - level_time))))
    j0 = min(j0, last - 1) if last > 0 else last
    span = mid[last] - mid[j0]
    if span <= 0:
        raise DataError("gnss", "time", f"GNSS intervals over {level_time:g} s to level the IMU", "one interval")
    f = _mean_specific_force(t, acc, R, tk, mid[j0], mid[last])
    roll, pitch = level_by_velocity_matching(f, (vel[last] - vel[j0]) / span, yaw)
    v_std = iv.d_std[[j0, last], :2] / (iv.t1 - iv.t0)[[j0, last], None]          # [2, 2] m/s
    dv_std = float(np.sqrt(np.mean(v_std[0] ** 2 + v_std[1] ** 2)))                # per horizontal axis
    return roll, pitch, float(np.sqrt(floor ** 2 + (ba_h / g) ** 2 + (dv_std / (span * g)) ** 2))

"""Is a drive physically plausible? Checks that catch wrong units, unrotated axes and corrupted samples.

A drive can have the right columns and finite values and still be garbage to the filter: accelerations in g,
rates in deg/s, a z axis pointing up, latitude and longitude in degrees, times in milliseconds, a GNSS log on
another time base. The filter then runs without a word and diverges (mean NIS 74 to 1e16). Each check here
fails with one :class:`bgfn.errors.DataError` that names the file and column and says the likely cause.

The thresholds are generous bounds for a road vehicle, not tuning: a car's yaw rate stays below about
1 rad/s, its horizontal acceleration below about 1 g, so gravity dominates the specific force.
"""

from __future__ import annotations

import logging

import numpy as np
import pandas as pd

from bgfn.errors import DataError
from bgfn.nav.earth import curvature_radii
from bgfn.schema import ACCEL_COLUMNS, ATTITUDE_COLUMNS, GYRO_COLUMNS

log = logging.getLogger(__name__)

#: Standard gravity, m/s^2.
G = 9.80665
#: The median |specific force| of a drive lies within these fractions of g (gravity dominates, Sec. 2).
F_MEDIAN_RANGE_G = (0.5, 1.5)
#: The median specific force along body z (down) is below -this fraction of g: a level IMU reads -g.
F_Z_MEDIAN_MIN_G = 0.5
#: 99th percentile of |angular rate| above this is not a road vehicle, rad/s (172 deg/s).
RATE_P99_MAX = 3.0
#: A single sample beyond any MEMS sensor's range: |f| (m/s^2, about 20 g) or |w| (rad/s, 2300 deg/s).
F_SPIKE_MAX, RATE_SPIKE_MAX = 200.0, 40.0
#: The specific force averaged over this long (s) stays within this many g of the drive's median: a car brakes or
#: corners at under 1 g, a walker's steps average out within a second.
SUSTAINED_S, SUSTAINED_MAX_G = 1.0, 1.5
#: Plausible median sampling intervals, s: IMU 10 kHz..1 Hz, GNSS and reference 1 kHz..0.1 Hz.
IMU_STEP_RANGE, FIX_STEP_RANGE = (1e-4, 1.0), (1e-3, 10.0)
#: Ellipsoidal heights of a road drive, m.
HEIGHT_RANGE = (-500.0, 9000.0)
#: Horizontal speed implied by two successive positions above this is a jump, m/s (360 km/h).
SPEED_MAX = 100.0
#: Path length from positions / path length from velocities outside this range: units disagree.
PATH_RATIO_RANGE = (0.5, 2.0)
#: Below this fraction of the IMU span covered by GNSS fixes, the filter runs as pure INS over the rest.
GNSS_COVERAGE_WARN = 0.9


def check_drive(drive, files: dict | None = None) -> dict:
    """Raise a DataError when ``drive`` is physically implausible; return what was measured.

    Parameters
    ----------
    drive : bgfn.data.Drive
    files : dict, optional
        ``{table: label}`` naming where each table came from (e.g. ``{"imu": "<folder>/imu.csv"}``) for the
        messages; default ``<drive name>/<table>``.

    Returns
    -------
    dict
        ``f_median_g``, ``f_z_median_g``, ``rate_p99``, ``gnss_coverage`` (fraction of the IMU span between the
        first and last fix inside it), ``reference_attitude`` (False: a reference without attitude, its
        ``roll, pitch, yaw`` all NaN, which is accepted; a partial attitude raises).
    """
    name = {t: (files or {}).get(t, f"{drive.name}/{t}") for t in ("reference", "imu", "gnss")}
    out = _check_imu(drive.imu, name["imu"])
    for table in ("reference", "gnss"):
        _check_positions(getattr(drive, table), name[table])
    _check_path_against_velocity(drive.reference, name["reference"])
    for table in ("reference", "gnss"):
        _check_jumps(getattr(drive, table), name[table])
    out["gnss_coverage"] = _check_overlap(drive.imu, drive.gnss, name["imu"], name["gnss"])
    out["reference_attitude"] = reference_has_attitude(drive.reference, name["reference"])
    return out


def reference_has_attitude(reference: pd.DataFrame, src: str = "reference") -> bool:
    """Whether the reference carries an attitude: True when its ``roll, pitch, yaw`` are all finite, False when
    all three columns are NaN throughout (a reference without attitude, e.g. an RTK solution).

    Raises
    ------
    DataError
        Anything in between (some NaN, an inf): a partial attitude is a defect, not a missing one.
    """
    att = reference[list(ATTITUDE_COLUMNS)].to_numpy(float)   # [n, 3] rad
    if np.isnan(att).all():
        return False
    bad = ~np.isfinite(att)
    if bad.any():
        k, c = (int(i) for i in np.argwhere(bad)[0])
        raise DataError(src, ATTITUDE_COLUMNS[c], "finite roll, pitch and yaw, or all three NaN throughout (a "
                        "reference without attitude)", f"{int(bad.sum())} NaN/inf, first at row {k} "
                        f"(time {reference['time'].iloc[k]})")
    return True


def _median_step(time: np.ndarray) -> float:
    return float(np.median(np.diff(time))) if len(time) > 1 else float("nan")


def _check_imu(imu: pd.DataFrame, src: str) -> dict:
    t = imu["time"].to_numpy(float)
    step = _median_step(t)
    if not IMU_STEP_RANGE[0] <= step <= IMU_STEP_RANGE[1]:
        cause = " (time in milliseconds? expected seconds)" if 1.0 < step <= 1000.0 else ""
        raise DataError(src, "time", f"a median IMU interval within {IMU_STEP_RANGE} s{cause}", f"{step:g} s")
    f = imu[list(ACCEL_COLUMNS)].to_numpy(float)                # [K, 3] m/s^2
    w = imu[list(GYRO_COLUMNS)].to_numpy(float)                 # [K, 3] rad/s
    fn, wn = np.linalg.norm(f, axis=1), np.linalg.norm(w, axis=1)
    # units and axes first (medians and percentiles): a log in deg/s or g is a unit mistake, not a corrupted sample
    f_med = float(np.median(fn)) / G
    if not F_MEDIAN_RANGE_G[0] <= f_med <= F_MEDIAN_RANGE_G[1]:
        cause = (" -- accelerations in g? (expected m/s^2)" if 0.5 / G <= f_med <= 1.5 / G
                 else " -- accelerations in other units than m/s^2?")
        raise DataError(src, "accel_x/accel_y/accel_z", "a median |specific force| near g = 9.81 m/s^2 (gravity "
                        f"dominates a road drive){cause}", f"{f_med * G:.4g} m/s^2")
    fz_med = float(np.median(f[:, 2])) / G
    if fz_med > -F_Z_MEDIAN_MIN_G:
        mean = np.median(f, axis=0)
        cause = ("the z axis points up (expected body z down: a level IMU at rest reads accel_z = -g)"
                 if fz_med > F_Z_MEDIAN_MIN_G else
                 "gravity is not along body z: sensor axes not rotated to the body frame (x forward, y right, z down)")
        raise DataError(src, "accel_z", f"a median accel_z near -g -- {cause}",
                        f"median specific force [{mean[0]:.3g}, {mean[1]:.3g}, {mean[2]:.3g}] m/s^2")
    rate_p99 = float(np.percentile(wn, 99))
    if rate_p99 > RATE_P99_MAX:
        raise DataError(src, "gyro_x/gyro_y/gyro_z", f"angular rates a road vehicle reaches (99th percentile of |w| "
                        f"below {RATE_P99_MAX:g} rad/s) -- rates in deg/s? (expected rad/s)", f"{rate_p99:.4g} rad/s")
    for norm, cols, limit, unit in ((fn, ACCEL_COLUMNS, F_SPIKE_MAX, "m/s^2"), (wn, GYRO_COLUMNS, RATE_SPIKE_MAX, "rad/s")):
        k = int(np.argmax(norm))
        if norm[k] > limit:
            raise DataError(src, "/".join(cols), f"|value| below {limit:g} {unit} (beyond any MEMS sensor's range: a "
                            "corrupted sample)", f"{norm[k]:.4g} {unit} at row {k} (time {t[k]:.3f} s)")
    _check_sustained_force(t, f, step, src)
    return {"f_median_g": f_med, "f_z_median_g": fz_med, "rate_p99": rate_p99}


def _check_sustained_force(t: np.ndarray, f: np.ndarray, step: float, src: str) -> None:
    """The specific force averaged over :data:`SUSTAINED_S` departs from the drive's median (gravity, at rest or
    cruising) by more than :data:`SUSTAINED_MAX_G`: no road vehicle or walker accelerates so long so hard; a stuck
    or offset axis, or a saturated segment, does."""
    n = max(1, int(round(SUSTAINED_S / step)))
    if len(f) < n:
        return
    c = np.vstack([np.zeros((1, 3)), np.cumsum(f - np.median(f, axis=0), axis=0)])
    mean = (c[n:] - c[:-n]) / n                                   # [K - n + 1, 3] mean over each n-sample window
    dev = np.linalg.norm(mean, axis=1) / G
    k = int(np.argmax(dev))
    if dev[k] > SUSTAINED_MAX_G:
        axis = ACCEL_COLUMNS[int(np.argmax(np.abs(mean[k])))]
        raise DataError(src, axis, f"a specific force whose mean over {SUSTAINED_S:g} s stays within "
                        f"{SUSTAINED_MAX_G:g} g of the drive's median (a vehicle's or walker's accelerations)",
                        f"{dev[k]:.3g} g from {t[k]:.3f} s to {t[k + n - 1]:.3f} s (a stuck, offset or saturated axis?)")


def _check_positions(table: pd.DataFrame, src: str) -> None:
    t = table["time"].to_numpy(float)
    step = _median_step(t)
    if len(t) > 1 and not FIX_STEP_RANGE[0] <= step <= FIX_STEP_RANGE[1]:
        cause = " (time in milliseconds? expected seconds)" if 10.0 < step <= 1e4 else ""
        raise DataError(src, "time", f"a median interval within {FIX_STEP_RANGE} s{cause}", f"{step:g} s")
    lat, lon, h = (table[c].to_numpy(float) for c in ("lat", "lon", "h"))
    for col, v, lim in (("lat", lat, np.pi / 2), ("lon", lon, np.pi)):
        k = int(np.argmax(np.abs(v)))
        if abs(v[k]) > lim:
            raise DataError(src, col, f"{col} in radians within [-{lim:.4g}, {lim:.4g}] (degrees?)",
                            f"{v[k]:.6g} at row {k} (time {t[k]:.3f} s)")
    k = int(np.argmax((h < HEIGHT_RANGE[0]) | (h > HEIGHT_RANGE[1])))
    if not HEIGHT_RANGE[0] <= h[k] <= HEIGHT_RANGE[1]:
        raise DataError(src, "h", f"ellipsoidal height of a road drive within {HEIGHT_RANGE} m",
                        f"{h[k]:.6g} m at row {k} (time {t[k]:.3f} s)")


def _check_jumps(table: pd.DataFrame, src: str) -> None:
    t = table["time"].to_numpy(float)
    if len(t) > 1:
        dn, de = _steps_ne(table)
        speed = np.hypot(dn, de) / np.diff(t)
        k = int(np.argmax(speed))
        if speed[k] > SPEED_MAX:
            raise DataError(src, "lat/lon", f"successive positions a vehicle can cover (below {SPEED_MAX:g} m/s; a "
                            "corrupted fix?)",
                            f"{np.hypot(dn[k], de[k]):.4g} m in {t[k + 1] - t[k]:.3g} s at row {k + 1} "
                            f"(time {t[k + 1]:.3f} s)")


def _steps_ne(table: pd.DataFrame) -> tuple[np.ndarray, np.ndarray]:
    """North and east steps between successive positions, m (WGS84 radii of curvature)."""
    lat, lon, h = (table[c].to_numpy(float) for c in ("lat", "lon", "h"))
    r_m, r_n = curvature_radii(lat[1:])
    return np.diff(lat) * (r_m + h[1:]), np.diff(lon) * (r_n + h[1:]) * np.cos(lat[1:])


def _check_path_against_velocity(ref: pd.DataFrame, src: str) -> None:
    """Positions and velocities of the reference describe the same path (catches lat/lon in degrees whose
    values stay within the radian ranges, e.g. a drive near the prime meridian)."""
    if not {"v_n", "v_e"} <= set(ref.columns) or len(ref) < 2:
        return
    dt = np.diff(ref["time"].to_numpy(float))
    from_pos = float(np.sum(np.hypot(*_steps_ne(ref))))
    speed = np.hypot(ref["v_n"].to_numpy(float), ref["v_e"].to_numpy(float))
    from_vel = float(np.sum(0.5 * (speed[1:] + speed[:-1]) * dt))
    if from_vel < 50.0:               # hardly moving: the ratio says nothing
        return
    ratio = from_pos / from_vel
    if not PATH_RATIO_RANGE[0] <= ratio <= PATH_RATIO_RANGE[1]:
        cause = " -- lat/lon in degrees? (the ratio would be 57.3)" if 30 < ratio < 100 else ""
        raise DataError(src, "lat/lon", "a path length from the positions that matches the velocities (ratio "
                        f"within {PATH_RATIO_RANGE}){cause}", f"{from_pos:.4g} m against {from_vel:.4g} m, "
                        f"ratio {ratio:.3g}")


def _check_overlap(imu: pd.DataFrame, gnss: pd.DataFrame, imu_src: str, gnss_src: str) -> float:
    ti, tg = imu["time"].to_numpy(float), gnss["time"].to_numpy(float)
    inside = tg[(tg >= ti[0]) & (tg <= ti[-1])]
    if len(inside) == 0:
        raise DataError(gnss_src, "time", f"GNSS fixes inside the IMU span [{ti[0]:.3f}, {ti[-1]:.3f}] s of "
                        f"{imu_src} (the filter would run as pure INS): the same time base, e.g. GPS time of week",
                        f"fixes over [{tg[0]:.3f}, {tg[-1]:.3f}] s")
    coverage = float((inside[-1] - inside[0]) / (ti[-1] - ti[0])) if ti[-1] > ti[0] else 1.0
    if coverage < GNSS_COVERAGE_WARN:
        log.warning("%s: the GNSS fixes cover %.0f %% of the IMU span [%.3f, %.3f] s (fixes %.3f..%.3f s); the "
                    "filter runs as pure INS over the rest", gnss_src, 100 * coverage, ti[0], ti[-1], inside[0],
                    inside[-1])
    return coverage

"""A logged drive onto one regular time grid: the IMU resampled, the reference interpolated at the IMU epochs.

Real loggers timestamp their IMU with jitter and record the reference at its own rate, while everything downstream
works on the IMU's epochs (the filter's states, the row-by-row comparison with the reference, the networks'
windows). A jittery IMU log is resampled onto ``k / rate_hz`` by integrating its increments (angle and velocity
increments preserved); a gap longer than :data:`GAP_SAMPLES` median intervals is an error naming the file and the
time (interpolating across it would invent motion); the reference is interpolated at the IMU epochs, its position
by cubic Hermite segments with its own velocities as slopes, velocities and attitude linearly (yaw unwrapped).
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.interpolate import CubicHermiteSpline

from bgfn.data.navego import resample_imu
from bgfn.errors import DataError
from bgfn.nav.earth import curvature_radii
from bgfn.nav.transform import wrap_angle
from bgfn.schema import REFERENCE_COLUMNS

#: A time step longer than this many median intervals is a gap in the log (an error).
GAP_SAMPLES = 5.0
#: Steps within this fraction of the median interval count as regular (no resampling).
REGULAR_TOL = 1e-6
#: Significant digits of a median rate taken as the grid's rate (8-11 ms jitter around 10 ms -> 100 Hz).
RATE_DIGITS = 4
#: Times closer than this are the same epoch, s.
TIME_TOL = 1e-6


#: GNSS stamps within this fraction of their nominal interval of a regular grid are put on it (arrival jitter).
FIX_JITTER_TOL = 0.1


def regular_fix_times(t: np.ndarray, source="gnss") -> tuple[np.ndarray, float]:
    """GNSS fix stamps on their nominal grid: a receiver's fixes are valid at regular epochs, but a logger that
    stamps their arrival adds jitter, and a rate like 0.999475 Hz then divides nothing the evaluation needs.

    The nominal interval is the median step to two significant digits (0.9995 s -> 1 s); each stamp goes to the
    nearest epoch ``t0 + offset + k interval`` (``offset`` the median deviation), at most
    :data:`FIX_JITTER_TOL` of an interval away; gaps (missing fixes) stay gaps. A log already on a grid is returned
    as it is.

    Returns
    -------
    times : ndarray
    shift : float
        The largest move, s (0: unchanged).

    Raises
    ------
    DataError
        A stamp farther from the grid than the tolerance, or two on one epoch, naming ``source`` and the row.
    """
    t = np.asarray(t, dtype=float)
    if t.size < 3:
        return t, 0.0
    nominal = float(f"{median_interval(t):.2g}")
    k = np.round((t - t[0]) / nominal).astype(np.int64)
    grid = t[0] + k * nominal
    grid += float(np.median(t - grid))
    shift = np.abs(t - grid)
    worst = int(np.argmax(shift))
    if np.any(np.diff(k) <= 0) or shift[worst] > FIX_JITTER_TOL * nominal:
        raise DataError(source, "time", f"fix stamps within {FIX_JITTER_TOL:g} of their nominal interval "
                        f"({nominal:g} s) of a regular grid (a receiver's arrival jitter), one fix per epoch",
                        f"{shift[worst]:.3f} s off at data row {worst + 1} (time {t[worst]:.3f} s)")
    if shift[worst] < TIME_TOL:
        return t, 0.0
    return grid, float(shift[worst])


def median_interval(t: np.ndarray) -> float:
    """Median step of a time vector, s."""
    return float(np.median(np.diff(np.asarray(t, dtype=float))))


def median_rate_hz(t: np.ndarray) -> float:
    """The log's median rate, rounded to :data:`RATE_DIGITS` significant digits, Hz."""
    return float(f"{1.0 / median_interval(t):.{RATE_DIGITS}g}")


def is_regular(t: np.ndarray, rate_hz: float | None = None) -> bool:
    """True when every step equals the median (within :data:`REGULAR_TOL`) and, when given, ``1 / rate_hz``."""
    dt = np.diff(np.asarray(t, dtype=float))
    med = float(np.median(dt))
    if rate_hz is not None and abs(med * rate_hz - 1.0) > REGULAR_TOL:
        return False
    return bool(np.abs(dt - med).max() <= REGULAR_TOL * med)


def check_gaps(t: np.ndarray, source, max_samples: float = GAP_SAMPLES) -> None:
    """Raise a DataError naming ``source`` and the time of the first step longer than ``max_samples`` median
    intervals."""
    t = np.asarray(t, dtype=float)
    dt = np.diff(t)
    med = float(np.median(dt))
    k = int(np.argmax(dt))
    if dt[k] > max_samples * med:
        raise DataError(source, "time", f"no gap longer than {max_samples:g} median intervals ({med:.4g} s): "
                        "a log without interruptions (split the drive at the gap)",
                        f"a step of {dt[k]:.4g} s from {t[k]:.3f} s to {t[k + 1]:.3f} s (data rows {k + 1}-{k + 2})")


def imu_on_grid(imu: pd.DataFrame, rate_hz: float, t_lo: float, t_hi: float) -> tuple[pd.DataFrame, float, bool]:
    """The IMU rows whose intervals lie inside ``[t_lo, t_hi]`` on a regular grid (module docstring).

    Parameters
    ----------
    imu : DataFrame
        IMU table (row ``k`` = mean rates over ``(t[k-1], t[k]]``; row 0 over one median step before ``t[0]``).
    rate_hz : float
        Rate of the grid, Hz.
    t_lo, t_hi : float
        Span, s.

    Returns
    -------
    imu : DataFrame
        Rows on the regular grid.
    t_first : float
        Start of the first row's interval, s: the epoch the filter starts at.
    resampled : bool
        False when the log was regular at ``rate_hz`` and its rows are kept as they are.
    """
    t = imu["time"].to_numpy(float)
    start = np.concatenate([[2 * t[0] - t[1]], t[:-1]])            # start of each row's interval
    if is_regular(t, rate_hz):
        keep = (start >= t_lo - TIME_TOL) & (t <= t_hi + TIME_TOL)
        if keep.sum() >= 1:
            return imu.loc[keep].reset_index(drop=True), float(start[keep][0]), False
    rows = resample_imu(imu, rate_hz, t_start=t_lo, t_end=t_hi)
    return rows, float(rows["time"].iloc[0]) - 1.0 / rate_hz, True


def interpolate_reference(reference: pd.DataFrame, epochs: np.ndarray, source="reference") -> pd.DataFrame:
    """The reference at ``epochs`` (module docstring): its own rows where it has one at every epoch, else
    interpolated.

    Parameters
    ----------
    reference : DataFrame
        Reference table (``REFERENCE_COLUMNS``; attitude all NaN when unknown), strictly increasing time.
    epochs : ndarray, shape (n,)
        Times inside the reference's span, s.
    source : str
        Named in the error message.

    Returns
    -------
    DataFrame
        ``REFERENCE_COLUMNS`` at ``epochs``.
    """
    tr = reference["time"].to_numpy(float)
    epochs = np.asarray(epochs, dtype=float)
    if epochs[0] < tr[0] - TIME_TOL or epochs[-1] > tr[-1] + TIME_TOL:
        raise DataError(source, "time", f"a reference covering [{epochs[0]:.3f}, {epochs[-1]:.3f}] s",
                        f"[{tr[0]:.3f}, {tr[-1]:.3f}] s")
    i = np.clip(np.searchsorted(tr, epochs - TIME_TOL), 0, tr.size - 1)
    if np.all(np.abs(tr[i] - epochs) <= TIME_TOL):                   # a row at every epoch: as it is
        out = reference.iloc[i].reset_index(drop=True).copy()
        out["time"] = epochs
        return out[list(REFERENCE_COLUMNS)]
    x = np.clip(epochs, tr[0], tr[-1])
    lat, lon, h = (reference[c].to_numpy(float) for c in ("lat", "lon", "h"))
    v_n, v_e, v_d = (reference[c].to_numpy(float) for c in ("v_n", "v_e", "v_d"))
    r_m, r_n = curvature_radii(lat)
    slopes = {"lat": v_n / (r_m + h), "lon": v_e / ((r_n + h) * np.cos(lat)), "h": -v_d}   # rad/s, rad/s, m/s
    out = {"time": epochs}
    for c, y in (("lat", lat), ("lon", lon), ("h", h)):
        out[c] = CubicHermiteSpline(tr, y, slopes[c])(x)
    for c in ("v_n", "v_e", "v_d", "roll", "pitch"):
        out[c] = np.interp(x, tr, reference[c].to_numpy(float))
    yaw = reference["yaw"].to_numpy(float)
    out["yaw"] = wrap_angle(np.interp(x, tr, np.unwrap(yaw))) if np.isfinite(yaw).all() else np.full(x.size, np.nan)
    return pd.DataFrame(out, columns=list(REFERENCE_COLUMNS))

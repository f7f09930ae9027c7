"""GNSS outage windows and the pseudo-GPS hook (paper Eq. pred-gps).

An outage window ``(start, duration)`` removes every GNSS update with ``start <= t < start + duration``.
Inside a window the filter predicts only (the paper's "KF estimates held at their last values") unless a
pseudo-GPS source is given: a callable ``source(ctx: PseudoGpsContext) -> PseudoFix | None`` called at the
pseudo-GPS epochs ``start + k / rate`` (k = 1, 2, ...) inside the window. Its position is fused like a
GNSS fix (antenna position, NED standard deviations; a NaN std leaves that axis out). This is how
notebook 04 feeds MLP / AT-LSTM / BGFN predictions of ``delta_p_gps`` into the filter.

Which windows a drive gets is the profile's ``outage_windows``, read by :mod:`bgfn.nav.outages` (above the
filter: a rule counts its warm-up from the filter's start), which re-exports everything here.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Callable, NamedTuple, Optional

import numpy as np
import pandas as pd

from ..errors import DataError
from . import earth

#: Two window edges closer than this are the same time (float times of week), s.
TIME_TOL = 1e-6


@dataclass(frozen=True)
class OutageWindow:
    """A GNSS outage: no GNSS update for ``start <= t < start + duration`` (s)."""

    start: float
    duration: float

    @property
    def end(self) -> float:
        """End time (exclusive), s."""
        return self.start + self.duration

    def contains(self, t) -> np.ndarray:
        """Whether times ``t`` (s) fall inside the window."""
        t = np.asarray(t, dtype=float)
        return (t >= self.start - TIME_TOL) & (t < self.end - TIME_TOL)


def check_windows(windows, t_first: float, t_last: float, source: str = "outage_windows", sort: bool = True) -> list:
    """Validate outage windows against the data span.

    Parameters
    ----------
    windows : iterable of (start, duration) or OutageWindow
    t_first, t_last : float
        First and last time of the data, s.
    source : str
        Name used in error messages.
    sort : bool
        Return the windows sorted by start (default) or in the given order (``Outage k`` is the k-th).

    Returns
    -------
    list of OutageWindow
        Sorted by start, or in the given order.

    Raises
    ------
    DataError
        Non-finite values, zero or negative duration, a window outside ``[t_first, t_last]``, or two
        overlapping windows.
    """
    out = []
    for w in windows:
        start, duration = (w.start, w.duration) if isinstance(w, OutageWindow) else tuple(w)
        start, duration = float(start), float(duration)
        if not (np.isfinite(start) and np.isfinite(duration)):
            raise DataError(source, "window", "finite (start, duration)", f"({start}, {duration})")
        if duration <= 0:
            raise DataError(source, "duration", "a positive duration, s", f"{duration} at start {start}")
        if start < t_first - TIME_TOL or start + duration > t_last + TIME_TOL:
            raise DataError(source, "window", f"inside the data [{t_first}, {t_last}] s",
                            f"[{start}, {start + duration}] s")
        out.append(OutageWindow(start, duration))
    ordered = sorted(out, key=lambda w: w.start)
    for a, b in zip(ordered[:-1], ordered[1:]):
        if b.start < a.end - TIME_TOL:
            raise DataError(source, "window", "non-overlapping windows",
                            f"[{a.start}, {a.end}] overlaps [{b.start}, {b.end}]")
    return ordered if sort else out


def epochs_before(imu_time, starts, source: str = "outage_windows") -> np.ndarray:
    """The last IMU epoch strictly before each outage start, s.

    An outage run starts from the GPS-aided filter state at this epoch: windows are ``[start, end)``, so a
    fix at ``t = start`` belongs to the outage, and a state taken at the start row would already hold it.

    Parameters
    ----------
    imu_time : array_like, shape (n,)
        IMU epochs, s, increasing.
    starts : array_like
        Outage starts, s.
    source : str
        Name used in error messages.
    """
    imu_time = np.asarray(imu_time, dtype=float)
    starts = np.atleast_1d(np.asarray(starts, dtype=float))
    before = np.searchsorted(imu_time, starts - 1e-6, side="left") - 1
    if starts.size and before.min() < 0:
        raise DataError(source, "start", f"outage starts after the first IMU epoch {imu_time[0]}",
                        str(starts.min()))
    return imu_time[before]




@dataclass(frozen=True)
class SnappedWindow:
    """An outage window as asked (``asked``: ``(start, duration)``, s) and as run (``window``), its edges moved onto
    the IMU epochs (:func:`snap_windows`); ``moved`` when they differ."""

    asked: tuple
    window: tuple

    @property
    def moved(self) -> bool:
        """Whether snapping moved an edge."""
        return self.asked != self.window


def snap_windows(windows, imu_time) -> list[SnappedWindow]:
    """Outage windows with both edges on IMU epochs inside the data.

    The filter runs from IMU epoch to IMU epoch, so an outage ``[start, end)`` ends at the last IMU row before
    ``end``; a window whose edges lie off the IMU grid (a rule's whole-second starts on a log stamped at .xx1 s, a
    user's typed times) would end after the data or start between two rows. Each edge goes to the nearest IMU
    epoch (a tie to the earlier one), the end to one no later than the last; an edge within :data:`TIME_TOL` of an
    epoch keeps its value, so windows already on the grid come back unchanged, to the bit; an edge more than one IMU
    interval outside the data is left as it is (:func:`check_windows` names it: an outage does not shrink
    silently).

    Parameters
    ----------
    windows : iterable of (start, duration)
    imu_time : array_like
        IMU epochs, s, increasing.

    Returns
    -------
    list of SnappedWindow
        In the given order; a window that would shrink to nothing keeps its asked edges (:func:`check_windows`
        then names it).
    """
    t = np.asarray(imu_time, dtype=float)
    step = float(np.max(np.diff(t))) if t.size > 1 else 0.0

    def snap(x: float) -> float:
        i = int(np.clip(np.searchsorted(t, x), 1, len(t) - 1))
        j = i - 1 if x - t[i - 1] <= t[i] - x else i            # the nearest, a tie to the earlier
        if x > t[-1]:
            j = len(t) - 1
        gap = abs(t[j] - x)
        return x if gap <= TIME_TOL or gap > step else float(t[j])     # beyond one step: outside, not moved

    out = []
    for start, duration in windows:
        start, duration = float(start), float(duration)
        if t.size < 2 or not (np.isfinite(start) and np.isfinite(duration)):
            out.append(SnappedWindow((start, duration), (start, duration)))
            continue
        a, b = snap(start), snap(start + duration)
        window = (start, duration) if (a == start and b == start + duration) or not b > a else (a, b - a)
        out.append(SnappedWindow((start, duration), window))
    return out


class PseudoFix(NamedTuple):
    """A pseudo-GPS antenna position with its NED standard deviations (NaN std: axis not used)."""

    lat: float
    lon: float
    h: float
    std_n: float
    std_e: float
    std_d: float


@dataclass
class PseudoGpsContext:
    """What a pseudo-GPS source sees at a pseudo epoch.

    Attributes
    ----------
    t : float
        Epoch time, s.
    window : OutageWindow
    index : int
        Epoch number inside the window (1, 2, ...).
    nav : FilterState
        Current filter state (after propagation to ``t``, before the pseudo update).
    start_state : FilterState
        Filter state at the window start.
    lever_arm : ndarray, shape (3,)
        GNSS antenna lever arm (body, m).
    """

    t: float
    window: OutageWindow
    index: int
    nav: object
    start_state: object
    lever_arm: np.ndarray


PseudoGpsSource = Callable[[PseudoGpsContext], Optional[PseudoFix]]


class IncrementPseudoGps:
    """Eq. (pred-gps): ``P_GPS(k) = P_GPS0 + sum_{i<=k} delta_p_gps_i`` from a table of increments.

    Parameters
    ----------
    increments : DataFrame
        Columns ``time`` (s, end of each increment interval), ``delta_p_n``, ``delta_p_e`` (m): the
        predicted GPS position increments (north, east).
    std_n, std_e : float
        Standard deviation of the pseudo position at the first epoch, m.
    std_growth : float
        Added std per epoch (m per epoch), since the accumulated increments drift; 0 = constant.
    origin : {"filter", "last_fix"}
        ``P_GPS0``: the filter's antenna position at the outage start (default), or a given position
        via ``p0`` (``"last_fix"``, e.g. the last GNSS fix before the outage).
    p0 : array_like, shape (3,), optional
        ``[lat, lon, h]`` used with ``origin="last_fix"``.

    Notes
    -----
    Only north and east are fused (the height std is NaN): the networks predict 2-D increments (Eq. eq21).
    The increments whose ``time`` lies in ``(window.start, ctx.t]`` are summed.
    """

    def __init__(self, increments: pd.DataFrame, std_n: float, std_e: float, std_growth: float = 0.0,
                 origin: str = "filter", p0=None):
        for col in ("time", "delta_p_n", "delta_p_e"):
            if col not in increments.columns:
                raise DataError("pseudo_gps", col, "columns time, delta_p_n, delta_p_e", "missing")
        if origin not in ("filter", "last_fix") or (origin == "last_fix" and p0 is None):
            raise DataError("pseudo_gps", "origin", "'filter', or 'last_fix' with p0", repr(origin))
        self.t = increments["time"].to_numpy(dtype=float)
        self.cum = np.cumsum(increments[["delta_p_n", "delta_p_e"]].to_numpy(dtype=float), axis=0)
        self.std = np.array([std_n, std_e], dtype=float)
        self.std_growth = float(std_growth)
        self.origin = origin
        self.p0 = None if p0 is None else np.asarray(p0, dtype=float)

    def __call__(self, ctx: PseudoGpsContext) -> Optional[PseudoFix]:
        i0 = np.searchsorted(self.t, ctx.window.start + TIME_TOL, side="left")  # first with t > start
        i1 = np.searchsorted(self.t, ctx.t + TIME_TOL, side="right")  # last with t <= ctx.t
        if i1 <= i0:
            return None
        d = self.cum[i1 - 1] - (self.cum[i0 - 1] if i0 > 0 else 0.0)
        p0 = self.p0 if self.origin == "last_fix" else ctx.start_state.antenna_position(ctx.lever_arm)
        lat, lon, h = earth.ned_to_lla(np.array([d[0], d[1], 0.0]), *p0)
        std = self.std + self.std_growth * (ctx.index - 1)
        return PseudoFix(float(lat), float(lon), float(h), float(std[0]), float(std[1]), float("nan"))


class TablePseudoGps:
    """Pseudo-GPS fixes looked up by time in a table in the ``gnss`` schema (nearest within ``tol`` s)."""

    def __init__(self, fixes: pd.DataFrame, tol: float = 1e-3):
        self.fixes = fixes.reset_index(drop=True)
        self.t = fixes["time"].to_numpy(dtype=float)
        self.tol = tol

    def __call__(self, ctx: PseudoGpsContext) -> Optional[PseudoFix]:
        if self.t.size == 0:
            return None
        i = int(np.searchsorted(self.t, ctx.t))
        j = min((k for k in (i - 1, i) if 0 <= k < self.t.size), key=lambda k: abs(self.t[k] - ctx.t))
        if abs(self.t[j] - ctx.t) > self.tol:
            return None
        r = self.fixes.iloc[j]
        return PseudoFix(r["lat"], r["lon"], r["h"], r["std_n"], r["std_e"], r["std_d"])

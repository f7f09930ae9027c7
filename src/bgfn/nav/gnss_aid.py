"""Position fixes as aids of the filter engine: the GNSS fixes and the pseudo-GPS fixes of an outage (Eq. pred-gps).

A fix at ``t_m`` is applied at the first IMU epoch ``t_j >= t_m``. The measurement is the difference of the INS
antenna position (IMU position + ``C_bn`` lever arm, moved back by ``v (t_j - t_m)``) and the fix, in NED metres:
``z = D (p_ins_ant - p_fix)`` with ``D = diag(R_M + h, (R_N + h) cos L, -1)`` and
``H = [ [C_bn l]x  on phi | D on (dL, dlambda, dh) ]`` (Eq. eq4 then fuses it, :mod:`bgfn.nav.engine`).

GNSS fixes inside an outage window are removed; inside it a pseudo-GPS source may supply fixes at
``start + k / rate`` (:mod:`bgfn.nav.outages`: ``source(PseudoGpsContext) -> PseudoFix | None``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numba
import numpy as np
import pandas as pd
from bgfn.stats import chi2_quantile

from ..errors import DataError
from ..schema import GNSS_FIX_COLUMNS
from . import error_model as em
from .engine import EPOCH_TOL, Measurement, Stepper
from .outage_window import PseudoGpsContext
from .strapdown import radii_nb


@numba.njit(cache=True)
def position_measurement(pos, v, c, lever, fix, lag, dz, H):
    """Innovation of a position fix and its Jacobian (module docstring), filled into ``dz`` [3] and ``H`` [3, 15].

    ``dz``: INS antenna position at the measurement time minus the fix, NED metres; ``H``: its derivative with
    respect to the error states (attitude through the lever arm, position through ``D``).
    """
    lat, h = pos[0], pos[2]
    r_m, r_n = radii_nb(lat)
    cl = np.cos(lat)
    d = np.array([r_m + h, (r_n + h) * cl, -1.0])
    u = c @ lever  # antenna offset, NED m
    dz[0] = (lat - fix[0]) * d[0] + u[0] - v[0] * lag
    dz[1] = (pos[1] - fix[1]) * d[1] + u[1] - v[1] * lag
    dz[2] = (h - fix[2]) * d[2] + u[2] - v[2] * lag
    su = em.skew_nb(u)  # [u x]: d(antenna)/d(phi)
    phi_idx = np.array([em.PHI_N, em.PHI_E, em.PHI_D])
    pos_idx = np.array([em.DLAT, em.DLON, em.DH])
    H[:, :] = 0.0
    for a in range(3):
        for b in range(3):
            H[a, phi_idx[b]] = su[a, b]
        H[a, pos_idx[a]] = d[a]


def position_fix(nav: Stepper, lever: np.ndarray, fix, std, t_m: float, nis_gate: float = 0.0,
                 label: str | None = None) -> Measurement:
    """The measurement of a position fix ``fix`` (``[lat, lon, h]`` of the antenna, rad/rad/m) of time ``t_m`` with
    NED stds ``std`` (m; NaN: axis not used) against the current solution of ``nav`` (module docstring)."""
    dz, H = np.empty(3), np.empty((3, em.N_STATES))
    position_measurement(nav.pos, nav.v, nav.c, lever, np.asarray(fix, float), float(nav.times[nav.row] - t_m), dz, H)
    return Measurement(dz, H, np.asarray(std, float), None, nis_gate, label, t_m)


def gate_thresholds(probability: float | None, source: str = "nav") -> np.ndarray:
    """NIS thresholds of the innovation gate for 0..3 degrees of freedom: the ``probability`` quantiles of
    chi-square (0 = no gate). ``probability`` None or 0: no gate; otherwise it must lie in (0, 1)."""
    if not probability:
        return np.zeros(4)
    try:
        p = float(probability)
    except (TypeError, ValueError):
        p = float("nan")
    if not 0.0 < p < 1.0:
        raise DataError(source, "innovation_gate", "a probability in (0, 1), or null for no gate", repr(probability))
    return np.array([0.0] + [float(chi2_quantile(p, k)) for k in (1, 2, 3)])


def check_gnss(gnss: pd.DataFrame, source: str) -> None:
    """Raise unless ``gnss`` has the fix columns and strictly increasing times."""
    missing = [c for c in GNSS_FIX_COLUMNS if c not in gnss.columns]
    if missing:
        raise DataError(source, ",".join(missing), "gnss columns " + ", ".join(GNSS_FIX_COLUMNS), "missing")
    t = gnss["time"].to_numpy(dtype=float)
    if t.size > 1 and not np.all(np.diff(t) > 0):
        raise DataError(source, "time", "strictly increasing GNSS times")


@dataclass(frozen=True)
class GnssFixes:
    """The GNSS fixes of a drive as an aid (:class:`~bgfn.nav.engine.Aid`).

    Attributes
    ----------
    gnss : DataFrame
        ``time, lat, lon, h, std_n, std_e, std_d`` (checked by :func:`check_gnss`).
    lever : ndarray (3,)
        Antenna lever arm, body, m.
    windows : tuple of OutageWindow
        Outages: no fix inside them is used.
    gates : ndarray (4,)
        NIS thresholds by the fix's number of axes (:func:`gate_thresholds`; zeros: every fix fused, the paper).
    """

    gnss: pd.DataFrame
    lever: np.ndarray
    windows: tuple = ()
    gates: tuple = (0.0, 0.0, 0.0, 0.0)

    def schedule(self, times, source: str = "imu", hold_at: float | None = None) -> "FixSchedule":
        """The fixes inside ``(times[0], times[-1]]``, outside every window, with a finite position."""
        g = self.gnss[list(GNSS_FIX_COLUMNS)].to_numpy(dtype=float)
        inside = (g[:, 0] > times[0] + EPOCH_TOL) & (g[:, 0] <= times[-1] + EPOCH_TOL)
        for w in self.windows:
            inside &= ~w.contains(g[:, 0])
        g = g[inside & np.all(np.isfinite(g[:, 1:4]), axis=1)]
        rows = np.searchsorted(times, g[:, 0] - EPOCH_TOL, side="left")
        gates = [self.gates[int(np.sum(np.isfinite(std) & (std > 0)))] for std in g[:, 4:7]]
        return FixSchedule(rows, g, self.lever, gates)


@dataclass(frozen=True)
class FixSchedule:
    """GNSS fixes bound to one run: ``rows``, the fixes ``[time, lat, lon, h, std_n, std_e, std_d]`` and the NIS
    gate of each."""

    rows: np.ndarray
    fixes: np.ndarray
    lever: np.ndarray
    gates: list
    joint = False

    def measurement(self, i: int, nav: Stepper) -> Measurement:
        f = self.fixes[i]
        return position_fix(nav, self.lever, f[1:4], f[4:7], f[0], self.gates[i], "gnss")


class WindowStarts:
    """Not a measurement source: it keeps the filter state at each outage's start (at the epoch nearest to it) for
    :class:`PseudoGps`, the start of its sums (Eq. pred-gps). It is its own schedule; in the aid list it comes
    before the fixes, so that a fix of the start's epoch is not in the state it keeps."""

    joint = False

    def __init__(self, windows):
        self.windows = tuple(windows)
        self.rows = np.empty(0, dtype=np.int64)
        self.states: dict = {}

    def schedule(self, times, source: str = "imu", hold_at: float | None = None) -> "WindowStarts":
        self.rows = np.array([int(np.argmin(np.abs(times - w.start))) for w in self.windows], dtype=np.int64)
        self.states = {}
        return self

    def measurement(self, i: int, nav: Stepper) -> None:
        self.states[self.windows[i]] = nav.state()
        return None


@dataclass(frozen=True)
class PseudoGps:
    """Pseudo-GPS fixes inside the outage windows as an aid: ``source(PseudoGpsContext) -> PseudoFix | None`` at
    ``start + k / rate_hz`` (k = 1, 2, ...), fused like a GNSS fix, never gated (Eq. pred-gps).

    ``starts``: the states at the windows' starts (in the aid list before this one)."""

    source: object
    windows: tuple
    lever: np.ndarray
    rate_hz: float
    starts: WindowStarts

    def schedule(self, times, source: str = "imu", hold_at: float | None = None) -> "PseudoSchedule":
        rows, epochs = [], []
        for w in self.windows:
            k = np.arange(1, int(np.floor(w.duration * self.rate_hz + 1e-9)) + 1)
            tk = w.start + k / self.rate_hz
            tk = tk[(tk > times[0] + EPOCH_TOL) & (tk <= times[-1] + EPOCH_TOL)]
            for i, t in zip(k, tk):
                rows.append(int(np.searchsorted(times, t - EPOCH_TOL)))
                epochs.append((float(t), w, int(i)))
        return PseudoSchedule(np.array(rows, dtype=np.int64), epochs, self)


@dataclass(frozen=True)
class PseudoSchedule:
    """Pseudo-GPS epochs bound to one run: ``rows`` and ``(time, window, k)`` of each."""

    rows: np.ndarray
    epochs: list
    aid: PseudoGps
    joint = False

    def measurement(self, i: int, nav: Stepper) -> Measurement | None:
        t_m, w, k = self.epochs[i]
        pf = self.aid.source(PseudoGpsContext(t_m, w, k, nav.state(), self.aid.starts.states.get(w), self.aid.lever))
        if pf is None:
            return None
        return position_fix(nav, self.aid.lever, np.array(pf[:3], float), np.array(pf[3:6], float), t_m, 0.0,
                            "pseudo")


__all__ = ["FixSchedule", "GnssFixes", "PseudoGps", "PseudoSchedule", "WindowStarts", "check_gnss",
           "gate_thresholds", "position_fix", "position_measurement"]

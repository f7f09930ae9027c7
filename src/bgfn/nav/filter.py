"""The paper's loosely coupled GPS/INS filter (Sec. 2) over a drive: the engine (:mod:`bgfn.nav.engine`) with the
GNSS fixes, the pseudo-GPS fixes of the outages (Eq. pred-gps) and any further aids.

:func:`run_filter` steps the engine through the IMU rows after the initial state with its aids in this order at
one epoch: the caller's ``aids`` (the vehicle constraints, an odometer ...), the GNSS fix, the pseudo-GPS fix,
then the snapshots of the state. :func:`run_outage` is one outage from a saved state.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from ..errors import DataError
from . import error_model as em
from .engine import Stepper
from .gnss_aid import GnssFixes, PseudoGps, WindowStarts, check_gnss, gate_thresholds
from .outage_window import OutageWindow, check_windows
from .state import FilterNoise, FilterState
from .strapdown import imu_steps, trajectory_frame

#: Pseudo-GPS epochs per second inside an outage (the GNSS rate of the Turin drive).
PSEUDO_RATE_HZ = 1.0


# ---------------------------------------------------------------------------------------------------
# results
# ---------------------------------------------------------------------------------------------------
@dataclass
class FilterResult:
    """Output of :func:`run_filter`.

    Attributes
    ----------
    trajectory : DataFrame
        Reference schema, one row per epoch from the initial one (row 0) to the end.
    bias : DataFrame
        ``time``, ``accel_bias_x/y/z`` (m/s^2), ``gyro_bias_x/y/z`` (rad/s) at every epoch.
    sd : DataFrame
        ``time`` and the std of the 15 error states (names of ``error_model.STATE_NAMES``).
    updates : DataFrame
        One row per fix offered to the filter: ``time``, ``kind`` ('gnss' or 'pseudo'), ``innov_n/e/d`` (m),
        ``nis``, ``dof``, ``accepted`` (False: rejected by the innovation gate, not fused).
    P_updates : ndarray, shape (M, 15, 15)
        Covariance after each fix (unchanged by a rejected one).
    states : dict
        ``{name: FilterState}`` saved at the requested snapshot times.
    final : FilterState
        State at the last epoch.
    """

    trajectory: pd.DataFrame
    bias: pd.DataFrame
    sd: pd.DataFrame
    updates: pd.DataFrame
    P_updates: np.ndarray
    states: dict = field(default_factory=dict)
    final: FilterState | None = None


class Snapshots:
    """Not a measurement source: the filter state at the epoch nearest to each of ``times`` (``{name: time}``)."""

    joint = False

    def __init__(self, times: dict, source: str = "drive"):
        self.times, self.source = dict(times), source
        self.states: dict = {}

    def schedule(self, times, source: str = "imu", hold_at: float | None = None) -> "Snapshots":
        step = np.diff(times).max() if times.size > 1 else 0.0
        rows = []
        for name, t in self.times.items():
            r = int(np.argmin(np.abs(times - t)))
            if abs(times[r] - t) > max(step, 1e-9):
                raise DataError(self.source, f"snapshots[{name}]",
                                f"a time within the IMU span [{times[0]}, {times[-1]}]", str(t))
            rows.append(r)
        self.rows, self.names, self.states = np.array(rows, dtype=np.int64), list(self.times), {}
        return self

    def measurement(self, i: int, nav: Stepper) -> None:
        self.states[self.names[i]] = nav.state()
        return None


def run_filter(imu: pd.DataFrame, initial: FilterState, noise: FilterNoise, gnss: pd.DataFrame | None = None,
               lever_arm=(0.0, 0.0, 0.0), outage_windows=(), pseudo_gps=None, t_end: float | None = None,
               snapshots: dict | None = None, pseudo_rate_hz: float = PSEUDO_RATE_HZ,
               gate_probability: float | None = None, source: str = "drive", aids=(),
               hold_at: float | None = None) -> FilterResult:
    """Run the closed-loop GPS/INS filter from ``initial`` over the IMU rows after ``initial.time``.

    Parameters
    ----------
    imu : DataFrame
        IMU table (CONTRIBUTING.md schema); gaps over 5 samples raise.
    initial : FilterState
        State (navigation solution, bias estimates, P) at the start.
    noise : FilterNoise
        Process noise (:func:`bgfn.nav.state.noise_from_imu_errors`).
    gnss : DataFrame, optional
        GNSS table (``time, lat, lon, h, std_n, std_e, std_d``); None = standalone INS (prediction only).
    lever_arm : array_like, shape (3,)
        GNSS antenna position in the body frame from the IMU, m.
    outage_windows : iterable of (start, duration)
        GNSS outages (s); validated against the IMU span.
    pseudo_gps : callable, optional
        ``pseudo_gps(PseudoGpsContext) -> PseudoFix | None``, called at ``start + k / pseudo_rate_hz``
        inside each outage window (:mod:`bgfn.nav.outages`).
    t_end : float, optional
        Last time to process, s (default: the last IMU row).
    snapshots : dict, optional
        ``{name: time}``: save the filter state at the IMU epoch nearest to each time (within one sample).
    pseudo_rate_hz : float
        Rate of the pseudo-GPS epochs, Hz.
    gate_probability : float, optional
        Innovation gate on the GNSS fixes: a fix whose NIS exceeds the ``gate_probability`` quantile of the
        chi-square distribution (degrees of freedom: its axes with a std) is not fused. None: every fix is
        fused (the paper's filter). Pseudo fixes are never gated.
    source : str
        Name used in error messages.
    aids : sequence of Aid
        Further measurement sources fused at their own epochs (:class:`bgfn.nav.engine.Aid`), e.g. the vehicle
        constraints of :func:`bgfn.nav.constraints.build_constraints` (NHC, and ZUPT where the stillness detector
        fires) built for this ``imu``, and an odometer (:mod:`bgfn.nav.odometer`). Empty: the paper's filter.
        Their updates are not rows of ``updates``.
    hold_at : float, optional
        No GNSS fix comes after this time (:meth:`bgfn.nav.engine.Aid.schedule`; :func:`run_outage` sets it).

    Returns
    -------
    FilterResult
    """
    gates = gate_thresholds(gate_probability, source)
    t0 = float(initial.time)
    time, gyro, accel, dt = imu_steps(imu, t0, source + ":imu")
    if t_end is not None:
        keep = time <= t_end + 1e-9
        if not keep.any():
            raise DataError(source, "t_end", f"a time after the initial epoch {t0}", str(t_end))
        time, gyro, accel, dt = time[keep], gyro[keep], accel[keep], dt[keep]
    times = np.concatenate([[t0], time])  # output rows
    windows = tuple(check_windows(outage_windows, t0, times[-1], source + ":outage_windows"))
    lever = np.asarray(lever_arm, dtype=float).reshape(3)
    plan = list(aids)
    if gnss is not None and len(gnss):
        check_gnss(gnss, source + ":gnss")
        plan.append(GnssFixes(gnss, lever, windows, gates))
    if pseudo_gps is not None:
        starts = WindowStarts(windows)
        plan[len(aids):len(aids)] = [starts]          # the state at a window start, before that epoch's fix
        plan.append(PseudoGps(pseudo_gps, windows, lever, pseudo_rate_hz, starts))
    snaps = Snapshots(snapshots or {}, source)
    plan.append(snaps)
    nav = Stepper(times, dt, gyro, accel, initial, noise, plan, source + ":imu", hold_at)
    nav.step_to(times.size - 1)
    return _result(nav, snaps.states)


def _result(nav: Stepper, states: dict) -> FilterResult:
    times, n_rows = nav.times, nav.times.size
    # Bias estimates are piecewise constant between updates (random walk, or held) or decay (Gauss-Markov), as
    # propagate_steps applies them: with the estimates' decay (noise_arrays' last two), not the model's.
    bias_rows = np.array(nav.bias_rows)
    idx = np.searchsorted(bias_rows, np.arange(n_rows), side="right") - 1
    bias = np.array(nav.bias_vals)[idx]
    inv_a, inv_g = nav.q[6], nav.q[7]
    if np.any(inv_a > 0) or np.any(inv_g > 0):
        age = times - times[bias_rows[idx]]
        bias = bias * np.exp(-age[:, None] * np.concatenate([inv_a, inv_g])[None, :])
    bias_df = pd.DataFrame(bias, columns=["accel_bias_x", "accel_bias_y", "accel_bias_z",
                                          "gyro_bias_x", "gyro_bias_y", "gyro_bias_z"])
    bias_df.insert(0, "time", times)
    sd_df = pd.DataFrame(nav.out_sd, columns=list(em.STATE_NAMES))
    sd_df.insert(0, "time", times)
    upd = [(t, label, *innov, nis, int(np.sum(np.isfinite(innov))), accepted)
           for t, label, innov, nis, accepted in nav.log]
    updates = pd.DataFrame(upd, columns=["time", "kind", "innov_n", "innov_e", "innov_d", "nis", "dof", "accepted"])
    return FilterResult(trajectory=trajectory_frame(times, nav.out_pos, nav.out_v, nav.out_c), bias=bias_df,
                        sd=sd_df, updates=updates,
                        P_updates=np.array(nav.P_log).reshape(-1, em.N_STATES, em.N_STATES),
                        states=states, final=nav.state())


def run_outage(imu: pd.DataFrame, start_state: FilterState, window, noise: FilterNoise,
               lever_arm=(0.0, 0.0, 0.0), pseudo_gps=None, pseudo_rate_hz: float = PSEUDO_RATE_HZ,
               source: str = "drive", aids=()) -> FilterResult:
    """One outage from a saved filter state: only the window's own IMU rows are processed.

    Without ``pseudo_gps`` this is the standalone INS (prediction only, biases held at their last
    estimates); with it, the pseudo fixes of Eq. (pred-gps) are fused at ``pseudo_rate_hz``.

    Parameters
    ----------
    imu : DataFrame
        IMU table covering the window.
    start_state : FilterState
        State at the window start (e.g. from :func:`bgfn.nav.state.load_states`).
    window : OutageWindow or (start, duration)
    noise : FilterNoise
    lever_arm : array_like, shape (3,)
        Antenna lever arm, body, m.
    pseudo_gps : callable, optional
        See :func:`run_filter`.
    pseudo_rate_hz : float
    source : str
    aids : sequence of Aid
        See :func:`run_filter`; what they estimate from the GPS-aided solution (the vehicle frame of the
        constraints) is held at its value at the start (no fix inside: ``hold_at``).

    Returns
    -------
    FilterResult
        Rows from the window start to its end.
    """
    w = window if isinstance(window, OutageWindow) else OutageWindow(*map(float, window))
    if abs(start_state.time - w.start) > 0.5:
        raise DataError(source, "start_state.time", f"the outage start {w.start} s", str(start_state.time))
    return run_filter(imu, start_state, noise, None, lever_arm, [(start_state.time, w.end - start_state.time)],
                      pseudo_gps, t_end=w.end, pseudo_rate_hz=pseudo_rate_hz, source=source, aids=aids,
                      hold_at=start_state.time)


__all__ = ["FilterResult", "PSEUDO_RATE_HZ", "Snapshots", "gate_thresholds", "run_filter", "run_outage"]

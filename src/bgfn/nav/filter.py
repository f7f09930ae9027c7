"""The paper's 15-state loosely coupled GPS/INS Kalman filter (Sec. 2) with closed-loop feedback.

Per IMU row (100 Hz): bias-corrected readings drive the strapdown (:mod:`bgfn.nav.strapdown`) and the
covariance is propagated with ``Phi = I + F dt``, ``P = Phi P Phi^T + Q_d`` (Eq. eq3;
:mod:`bgfn.nav.error_model`). With feedback the error state is zero after every correction, so the
time update of ``x`` is trivial and only ``P`` is propagated.

At a GNSS epoch ``t_m`` (applied at the first IMU epoch ``t_j >= t_m``) the measurement is the
difference of the INS antenna position (IMU position + ``C_bn`` lever arm, moved back by
``v (t_j - t_m)``) and the GNSS position, in NED metres:
``z = D (p_ins_ant - p_gnss)`` with ``D = diag(R_M + h, (R_N + h) cos L, -1)`` and
``H = [ [C_bn l]x  on phi | D on (dL, dlambda, dh) ]``. The update (Eq. eq4) is processed one axis at a
time (exactly the batch update for the diagonal R), with the Joseph form for ``P``. Then the errors are
fed back: position, velocity, ``C_bn <- exp([phi]) C_bn``, bias estimates ``+= (nabla, eps)``, ``x = 0``.

Outage windows remove GNSS updates; inside them a pseudo-GPS source may supply fixes
(:mod:`bgfn.nav.outages`, Eq. pred-gps). Beyond the paper, an *aid* may add measurements at its own epochs
(``aid``; default none). The filter is the engine and knows no aid: it asks the aid's schedule "which
measurement after this IMU step?" (:class:`AidSchedule`) and fuses the answer (:class:`AidMeasurement`: an
innovation, its Jacobian and its std) with the same sequential update and feedback as a fix. The vehicle
constraints (NHC, ZUPT) are one such aid (:mod:`bgfn.nav.constraints`); a new aid is a new module.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Protocol

import numba
import numpy as np
import pandas as pd
from scipy.stats import chi2

from ..errors import DataError
from ..schema import GNSS_FIX_COLUMNS
from . import error_model as em
from .error_model import process_noise_nb, system_matrix_nb
from .outages import OutageWindow, PseudoGpsContext, check_windows
from .state import FilterNoise, FilterState
from .strapdown import imu_steps, radii_nb, rotvec_to_dcm_nb, step_inplace, trajectory_frame

#: Pseudo-GPS epochs per second inside an outage (the GNSS rate of the Turin drive).
PSEUDO_RATE_HZ = 1.0


# ---------------------------------------------------------------------------------------------------
# numba kernels: the low-level stepping API. run_filter/run_outage drive them from an event list; a caller
# that decides each fix on the fly (bgfn.evaluate's closed-loop pseudo-GPS) drives them directly.
# ---------------------------------------------------------------------------------------------------
@numba.njit(cache=True)
def propagate_steps(i0, i1, dt, gyro, accel, pos, v, c, ba, bg, P, q_g, q_a, q_bg, q_ba, inv_tau_a,
                  inv_tau_g, decay_a, decay_g, out_pos, out_v, out_c, out_sd):
    """Steps i0..i1-1 (IMU rows); output row k+1 holds the state after step k. ``inv_tau_*``: the bias model's
    inverse correlation times (in F); ``decay_*``: those the bias estimates relax with (0: held)."""
    n = P.shape[0]
    F = np.empty((n, n))
    Q = np.empty((n, n))
    phi = np.empty((n, n))
    wb = np.empty(3)
    fb = np.empty(3)
    for k in range(i0, i1):
        h = dt[k]
        for a in range(3):
            wb[a] = gyro[k, a] - bg[a]
            fb[a] = accel[k, a] - ba[a]
        # Eq. (eq3): covariance time update with F at the start of the step.
        system_matrix_nb(pos, v, c, fb, inv_tau_a, inv_tau_g, F)
        process_noise_nb(c, q_g, q_a, q_bg, q_ba, h, Q)
        for r in range(n):
            for s in range(n):
                phi[r, s] = F[r, s] * h
            phi[r, r] += 1.0
        P[:, :] = phi @ P @ phi.T + Q
        step_inplace(pos, v, c, wb, fb, h)
        # Gauss-Markov bias estimates decay with their model (decay = 0: random walk, or held as NaveGo does).
        for a in range(3):
            ba[a] *= np.exp(-h * decay_a[a])
            bg[a] *= np.exp(-h * decay_g[a])
        out_pos[k + 1] = pos
        out_v[k + 1] = v
        out_c[k + 1] = c
        for r in range(n):
            out_sd[k + 1, r] = np.sqrt(max(P[r, r], 0.0))


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


@numba.njit(cache=True)
def position_nis(P, H, dz, std):
    """Normalized innovation squared of a whole fix, ``dz^T (H P H^T + R)^-1 dz`` over the axes with a positive,
    finite ``std`` (``R = diag(std^2)``), and the number of those axes (its chi-square degrees of freedom).
    Equal to the sum of the scalar NIS of the sequential update."""
    sel = np.empty(3, np.int64)
    m = 0
    for a in range(3):
        if std[a] > 0.0 and np.isfinite(std[a]):
            sel[m] = a
            m += 1
    if m == 0:
        return 0.0, 0
    hs = np.empty((m, P.shape[0]))
    zs = np.empty(m)
    for i in range(m):
        hs[i] = H[sel[i]]
        zs[i] = dz[sel[i]]
    S = hs @ P @ hs.T
    for i in range(m):
        S[i, i] += std[sel[i]] ** 2
    return zs @ np.linalg.solve(S, zs), m


@numba.njit(cache=True)
def sequential_update(P, H, dz, std, x, innov):
    """Eq. (eq4) for the rows of ``H`` one scalar at a time (exactly the batch update for a diagonal R), Joseph
    form for ``P``; the error-state estimate accumulates in ``x`` (zero on entry: closed loop).

    A row whose ``std`` is not positive and finite is left out (its ``innov`` is NaN). Returns the sum of the
    scalar normalized innovations squared. Shared by every measurement of the filter: position fixes
    (:func:`update_position`) and the vehicle constraints (:mod:`bgfn.nav.constraints`).
    """
    n = P.shape[0]
    eye = np.eye(n)
    nis = 0.0
    for a in range(H.shape[0]):
        innov[a] = np.nan
        if not (std[a] > 0.0 and np.isfinite(std[a])):
            continue
        hrow = H[a].copy()
        ph = P @ hrow
        s = hrow @ ph + std[a] ** 2
        k = ph / s
        y = dz[a] - hrow @ x
        innov[a] = y
        nis += y * y / s
        x += k * y
        ikh = eye - np.outer(k, hrow)
        P[:, :] = ikh @ P @ ikh.T + np.outer(k, k) * std[a] ** 2
    return nis


@numba.njit(cache=True)
def feedback(pos, v, c, ba, bg, x):
    """Closed-loop feedback of the error-state estimate ``x`` (errors are computed - true) into the navigation
    solution and the bias estimates, in place; the caller then starts from ``x = 0``."""
    pos[0] -= x[em.DLAT]
    pos[1] -= x[em.DLON]
    pos[2] -= x[em.DH]
    v[0] -= x[em.DV_N]
    v[1] -= x[em.DV_E]
    v[2] -= x[em.DV_D]
    rv = np.array([x[em.PHI_N], x[em.PHI_E], x[em.PHI_D]])
    dc = np.empty((3, 3))
    rotvec_to_dcm_nb(rv, dc)  # C_true = (I - [phi])^-1 C_computed ~ exp([phi]) C_computed
    c[:, :] = dc @ c
    for a in range(3):
        ba[a] += x[em.BA_X + a]
        bg[a] += x[em.BG_X + a]


@numba.njit(cache=True)
def update_position(pos, v, c, ba, bg, P, lever, fix, std, lag, innov, gate):
    """Eq. (eq4) position update (:func:`sequential_update`) and feedback (:func:`feedback`).

    ``gate`` > 0: the fix is first tested as a whole; when its NIS (:func:`position_nis`) exceeds ``gate`` it is
    rejected and the state and ``P`` are left untouched (an innovation gate; 0: every fix is fused, as in the
    paper). Returns ``(nis, accepted)``; ``innov`` receives the NED innovations (m, NaN for unused axes).
    """
    n = P.shape[0]
    dz = np.empty(3)
    H = np.empty((3, n))
    position_measurement(pos, v, c, lever, fix, lag, dz, H)
    if gate > 0.0:
        nis_fix, _ = position_nis(P, H, dz, std)
        if nis_fix > gate:
            for a in range(3):
                innov[a] = dz[a] if (std[a] > 0.0 and np.isfinite(std[a])) else np.nan
            return nis_fix, False
    x = np.zeros(n)
    nis = sequential_update(P, H, dz, std, x, innov)
    feedback(pos, v, c, ba, bg, x)
    return nis, True


# ---------------------------------------------------------------------------------------------------
# the aid interface: an aid answers, after the IMU steps it names, with a measurement the engine fuses
# ---------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class AidMeasurement:
    """One aid measurement for :func:`sequential_update`: ``dz`` [m] (computed minus measured), ``H`` [m, 15] its
    Jacobian with respect to the error states (:mod:`bgfn.nav.error_model` order), ``std`` [m] the measurement
    noise per row (a row with a non-positive or non-finite std is left out).

    ``gate`` [m], optional: a chi-square threshold per row (0: none). The engine leaves out a row whose
    normalized innovation squared ``dz^2 / (H P H^T + std^2)`` against the covariance before the epoch's update
    exceeds it (:func:`gated_std`): the aid says how much it trusts a value, the engine owns the test.
    """

    dz: np.ndarray
    H: np.ndarray
    std: np.ndarray
    gate: np.ndarray | None = None


class AidSchedule(Protocol):
    """An aid bound to the IMU steps of one run (what :meth:`Aid.schedule` returns).

    ``rows``: the sorted step indices ``k`` (0-based, into the run's IMU steps) after which the engine asks;
    ``measurement(k, pos, v, c)`` answers with the measurement at that epoch from the current solution
    (``pos`` [lat, lon, h] rad/rad/m, ``v`` NED m/s, ``c`` C_bn), or None for no update.
    """

    rows: np.ndarray

    def measurement(self, k: int, pos: np.ndarray, v: np.ndarray, c: np.ndarray) -> AidMeasurement | None: ...


class Aid(Protocol):
    """A measurement source beyond the GNSS fixes (NHC/ZUPT, a learned odometer ...), built once per drive."""

    def schedule(self, time: np.ndarray, source: str = "imu", hold_at: float | None = None) -> AidSchedule:
        """Bind to the IMU steps ending at ``time`` (s). ``hold_at``: no GNSS fix comes after this time (an
        outage), so whatever the aid estimates from the GPS-aided solution is held at its value then."""
        ...


def gated_std(P: np.ndarray, H: np.ndarray, dz: np.ndarray, std: np.ndarray, gate: np.ndarray) -> np.ndarray:
    """``std`` with NaN for every row whose normalized innovation squared ``dz^2 / (h P h^T + std^2)`` (against
    ``P`` before the update) exceeds its ``gate`` > 0 (:class:`AidMeasurement`): such a row is not fused."""
    s = np.einsum("ij,jk,ik->i", H, P, H) + np.asarray(std, float) ** 2
    reject = (np.asarray(gate, float) > 0.0) & (np.asarray(dz, float) ** 2 > np.asarray(gate, float) * s)
    return np.where(reject, np.nan, std)


def propagate(r0: int, r1: int, dt, gyro, accel, nav: tuple, q: tuple, out: tuple,
              schedule: AidSchedule | None = None, out_bias: np.ndarray | None = None,
              aided_rows: list | None = None) -> None:
    """Prediction over output rows ``r0..r1`` (steps ``r0..r1-1``, Eq. eq3) with the aid's updates at its epochs.

    ``nav`` = ``(pos, v, c, ba, bg, P)`` and ``out`` = ``(out_pos, out_v, out_c, out_sd)`` are updated in place,
    as :func:`propagate_steps` does. After each step ``k`` of ``schedule.rows`` the aid's measurement is fused
    (:func:`sequential_update`, then :func:`feedback`); the output row ``k + 1`` then holds the corrected state,
    ``out_bias[k + 1]`` its bias estimates (accelerometer then gyro) and ``k + 1`` is appended to ``aided_rows``.
    """
    pos, v, c, ba, bg, P = nav
    out_pos, out_v, out_c, out_sd = out
    k = r0
    if schedule is not None:
        rows = schedule.rows
        for j in rows[np.searchsorted(rows, r0):np.searchsorted(rows, r1)]:
            j = int(j)
            propagate_steps(k, j + 1, dt, gyro, accel, pos, v, c, ba, bg, P, *q, out_pos, out_v, out_c, out_sd)
            k = j + 1
            m = schedule.measurement(j, pos, v, c)
            if m is None:
                continue
            x = np.zeros(P.shape[0])
            std = m.std if m.gate is None else gated_std(P, m.H, m.dz, m.std, m.gate)
            sequential_update(P, m.H, m.dz, std, x, np.empty(m.dz.size))
            feedback(pos, v, c, ba, bg, x)
            out_pos[k], out_v[k], out_c[k] = pos, v, c
            out_sd[k] = np.sqrt(np.maximum(np.diag(P), 0.0))
            if out_bias is not None:
                out_bias[k, :3], out_bias[k, 3:] = ba, bg
            if aided_rows is not None:
                aided_rows.append(k)
    if k < r1:
        propagate_steps(k, r1, dt, gyro, accel, pos, v, c, ba, bg, P, *q, out_pos, out_v, out_c, out_sd)


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


def noise_arrays(noise: FilterNoise):
    """Process-noise arrays in the order :func:`propagate_steps` takes them (PSDs, inverse correlation times of the
    model, then of the estimates' decay: zero when ``noise.hold_bias_estimates``)."""
    inv = [np.where(np.isfinite(t), 1.0 / np.asarray(t, float), 0.0) for t in
           (noise.accel_bias_tau, noise.gyro_bias_tau)]
    decay = [np.zeros(3) if noise.hold_bias_estimates else i for i in inv]
    return (np.asarray(noise.gyro_noise, float) ** 2, np.asarray(noise.accel_noise, float) ** 2,
            np.asarray(noise.gyro_bias_walk, float) ** 2, np.asarray(noise.accel_bias_walk, float) ** 2,
            inv[0], inv[1], decay[0], decay[1])


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
    return np.array([0.0] + [float(chi2.ppf(p, k)) for k in (1, 2, 3)])


def _check_gnss(gnss, source):
    missing = [c for c in GNSS_FIX_COLUMNS if c not in gnss.columns]
    if missing:
        raise DataError(source, ",".join(missing), "gnss columns " + ", ".join(GNSS_FIX_COLUMNS), "missing")
    t = gnss["time"].to_numpy(dtype=float)
    if t.size > 1 and not np.all(np.diff(t) > 0):
        raise DataError(source, "time", "strictly increasing GNSS times")


def run_filter(imu: pd.DataFrame, initial: FilterState, noise: FilterNoise, gnss: pd.DataFrame | None = None,
               lever_arm=(0.0, 0.0, 0.0), outage_windows=(), pseudo_gps=None, t_end: float | None = None,
               snapshots: dict | None = None, pseudo_rate_hz: float = PSEUDO_RATE_HZ,
               gate_probability: float | None = None, source: str = "drive", aid: Aid | None = None) -> FilterResult:
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
    aid : Aid, optional
        A measurement source fused at its own epochs (module docstring), e.g. the vehicle constraints of
        :func:`bgfn.nav.constraints.build_constraints` (NHC, and ZUPT where the stillness detector fires), built
        for this ``imu``. None: none (the paper's filter). Its updates are not rows of ``updates``.

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
    n_rows = times.size
    schedule = aid.schedule(time, source + ":imu") if aid is not None else None
    windows = check_windows(outage_windows, t0, times[-1], source + ":outage_windows")
    lever = np.asarray(lever_arm, dtype=float).reshape(3)

    # Events: (row, kind, payload). Rows index `times`; a fix at t_m goes to the first row >= t_m.
    events = []
    if gnss is not None and len(gnss):
        _check_gnss(gnss, source + ":gnss")
        g = gnss[list(GNSS_FIX_COLUMNS)].to_numpy(dtype=float)
        inside = (g[:, 0] > t0 + 1e-9) & (g[:, 0] <= times[-1] + 1e-9)
        for w in windows:
            inside &= ~w.contains(g[:, 0])
        g = g[inside & np.all(np.isfinite(g[:, 1:4]), axis=1)]
        rows = np.searchsorted(times, g[:, 0] - 1e-9, side="left")
        for r, fix in zip(rows, g):
            events.append((int(r), 1, fix))
    if pseudo_gps is not None:
        for w in windows:
            k = np.arange(1, int(np.floor(w.duration * pseudo_rate_hz + 1e-9)) + 1)
            tk = w.start + k / pseudo_rate_hz
            tk = tk[(tk > t0 + 1e-9) & (tk <= times[-1] + 1e-9)]
            for i, t in zip(k, tk):
                events.append((int(np.searchsorted(times, t - 1e-9)), 2, (float(t), w, int(i))))
    for w in windows:  # state at each window start for the pseudo-GPS context
        r = int(np.argmin(np.abs(times - w.start)))
        events.append((r, 0, ("__window__", w)))
    for name, t in (snapshots or {}).items():
        r = int(np.argmin(np.abs(times - t)))
        if abs(times[r] - t) > max(dt.max(), 1e-9):
            raise DataError(source, f"snapshots[{name}]", f"a time within the IMU span [{t0}, {times[-1]}]",
                            str(t))
        events.append((r, 3, name))
    events.sort(key=lambda e: (e[0], e[1]))

    pos, v, c = initial.pos.astype(float).copy(), initial.v.astype(float).copy(), np.ascontiguousarray(
        initial.c_bn, dtype=float).copy()
    ba, bg = initial.accel_bias.astype(float).copy(), initial.gyro_bias.astype(float).copy()
    P = np.ascontiguousarray(initial.P, dtype=float).copy()
    q = noise_arrays(noise)
    out_pos, out_v = np.empty((n_rows, 3)), np.empty((n_rows, 3))
    out_c, out_sd = np.empty((n_rows, 3, 3)), np.empty((n_rows, em.N_STATES))
    out_pos[0], out_v[0], out_c[0] = pos, v, c
    out_sd[0] = np.sqrt(np.clip(np.diag(P), 0, None))
    bias_rows, bias_vals = [0], [np.concatenate([ba, bg])]
    upd, P_upd = [], []
    states, window_start = {}, {}
    innov = np.empty(3)
    out_bias_aid = np.zeros((n_rows, 6)) if schedule is not None else None
    aided_rows: list[int] = []

    def advance(r0, r1):
        """Prediction over output rows r0..r1 (with the aid's updates at its epochs)."""
        propagate(r0, r1, dt, gyro, accel, (pos, v, c, ba, bg, P), q, (out_pos, out_v, out_c, out_sd), schedule,
                  out_bias_aid, aided_rows)

    def current(row):
        return FilterState(float(times[row]), pos.copy(), v.copy(), c.copy(), ba.copy(), bg.copy(), P.copy())

    row = 0
    for r, kind, payload in events:
        if r > row:
            advance(row, r)
            row = r
        if kind == 0:
            window_start[payload[1]] = current(row)
            continue
        if kind == 3:
            states[payload] = current(row)
            continue
        gate = 0.0
        if kind == 1:
            t_m, fix, std, label = payload[0], payload[1:4], payload[4:7], "gnss"
            gate = gates[int(np.sum(np.isfinite(std) & (std > 0)))]
        else:
            t_m, w, i = payload
            ctx = PseudoGpsContext(t_m, w, i, current(row), window_start.get(w), lever)
            pf = pseudo_gps(ctx)
            if pf is None:
                continue
            fix, std, label = np.array(pf[:3], float), np.array(pf[3:6], float), "pseudo"
        nis, accepted = update_position(pos, v, c, ba, bg, P, lever, np.asarray(fix, float),
                                        np.asarray(std, float), float(times[row] - t_m), innov, gate)
        out_pos[row], out_v[row], out_c[row] = pos, v, c
        out_sd[row] = np.sqrt(np.clip(np.diag(P), 0, None))
        bias_rows.append(row)
        bias_vals.append(np.concatenate([ba, bg]))
        upd.append((t_m, label, *innov, nis, int(np.sum(np.isfinite(innov))), bool(accepted)))
        P_upd.append(P.copy())
    if row < n_rows - 1:
        advance(row, n_rows - 1)

    if schedule is not None:
        # the aid's updates also move the bias estimates; at a row with both, the fix comes after
        aided = np.array(aided_rows, dtype=int)
        order = np.lexsort((np.r_[np.zeros(aided.size), np.ones(len(bias_rows))], np.r_[aided, bias_rows]))
        bias_rows = list(np.r_[aided, bias_rows][order])
        bias_vals = list(np.concatenate([out_bias_aid[aided], np.array(bias_vals)])[order])
    # Bias estimates are piecewise constant between updates (random walk, or held) or decay (Gauss-Markov), as
    # propagate_steps applies them: with the estimates' decay (noise_arrays' last two), not the model's.
    idx = np.searchsorted(np.array(bias_rows), np.arange(n_rows), side="right") - 1
    bias = np.array(bias_vals)[idx]
    inv_a, inv_g = q[6], q[7]
    if np.any(inv_a > 0) or np.any(inv_g > 0):
        age = times - times[np.array(bias_rows)[idx]]
        bias = bias * np.exp(-age[:, None] * np.concatenate([inv_a, inv_g])[None, :])
    bias_df = pd.DataFrame(bias, columns=["accel_bias_x", "accel_bias_y", "accel_bias_z",
                                          "gyro_bias_x", "gyro_bias_y", "gyro_bias_z"])
    bias_df.insert(0, "time", times)
    sd_df = pd.DataFrame(out_sd, columns=list(em.STATE_NAMES))
    sd_df.insert(0, "time", times)
    updates = pd.DataFrame(upd, columns=["time", "kind", "innov_n", "innov_e", "innov_d", "nis", "dof", "accepted"])
    return FilterResult(trajectory=trajectory_frame(times, out_pos, out_v, out_c), bias=bias_df, sd=sd_df,
                        updates=updates,
                        P_updates=np.array(P_upd).reshape(-1, em.N_STATES, em.N_STATES),
                        states=states, final=current(n_rows - 1))


def run_outage(imu: pd.DataFrame, start_state: FilterState, window, noise: FilterNoise,
               lever_arm=(0.0, 0.0, 0.0), pseudo_gps=None, pseudo_rate_hz: float = PSEUDO_RATE_HZ,
               source: str = "drive", aid: Aid | None = None) -> FilterResult:
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
    aid : Aid, optional
        See :func:`run_filter`; what it estimates from the GPS-aided solution (the vehicle frame of the
        constraints) is held at its value at the start (no fix inside: ``hold_at``).

    Returns
    -------
    FilterResult
        Rows from the window start to its end.
    """
    w = window if isinstance(window, OutageWindow) else OutageWindow(*map(float, window))
    if abs(start_state.time - w.start) > 0.5:
        raise DataError(source, "start_state.time", f"the outage start {w.start} s", str(start_state.time))
    if aid is not None:
        aid = _Held(aid, start_state.time)
    return run_filter(imu, start_state, noise, None, lever_arm, [(start_state.time, w.end - start_state.time)],
                      pseudo_gps, t_end=w.end, pseudo_rate_hz=pseudo_rate_hz, source=source, aid=aid)


@dataclass(frozen=True)
class _Held:
    """An aid whose schedule is always bound with ``hold_at`` (an outage run: no fix after ``t``)."""

    aid: Aid
    t: float

    def schedule(self, time, source: str = "imu", hold_at: float | None = None) -> AidSchedule:
        return self.aid.schedule(time, source, self.t if hold_at is None else min(hold_at, self.t))


__all__ = ["Aid", "AidMeasurement", "AidSchedule", "FilterResult", "gate_thresholds", "propagate", "run_filter",
           "run_outage"]

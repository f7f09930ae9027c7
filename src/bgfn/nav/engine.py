"""The filter engine: the paper's 15-state error-state Kalman filter (Sec. 2) stepped through a list of aids.

Per IMU row the bias-corrected readings drive the strapdown (:mod:`bgfn.nav.strapdown`) and the covariance is
propagated with ``Phi = I + F dt``, ``P = Phi P Phi^T + Q_d`` (Eq. eq3; :mod:`bgfn.nav.error_model`). An *aid*
(:class:`Aid`: GNSS and pseudo-GPS fixes, NHC/ZUPT, an odometer ...) names the epochs it measures at and, at
each, answers with a :class:`Measurement` ``(dz, H, std)``; the engine fuses it (Eq. eq4, one row at a time:
exactly the batch update for a diagonal R, Joseph form for ``P``) and feeds the errors back (closed loop: the
error state is zero after every update). The engine imports no aid.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Protocol, Sequence

import numba
import numpy as np

from . import error_model as em
from .error_model import process_noise_nb, system_matrix_nb
from .state import FilterNoise, FilterState
from .strapdown import rotvec_to_dcm_nb, step_inplace

#: Two times closer than this map to the same IMU epoch (:meth:`Stepper.row_at`), s.
EPOCH_TOL = 1e-9


# ---------------------------------------------------------------------------------------------------
# numba kernels: the time update (Eq. eq3) and the measurement update (Eq. eq4) with feedback
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
    phi_p = np.empty((n, n))        # phi P, and phi P phi^T: P's update written into these
    phi_p_phi = np.empty((n, n))
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
        # P = phi P phi^T + Q_d: the same two BLAS products as ``phi @ P @ phi.T`` (bit for bit), into buffers
        # allocated once per call rather than three arrays per IMU step
        np.dot(phi, P, phi_p)
        np.dot(phi_p, phi.T, phi_p_phi)
        for r in range(n):
            for s in range(n):
                P[r, s] = phi_p_phi[r, s] + Q[r, s]
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
def measurement_nis(P, H, dz, std):
    """Normalized innovation squared of a whole measurement, ``dz^T (H P H^T + R)^-1 dz`` over the rows with a
    positive, finite ``std`` (``R = diag(std^2)``), and the number of those rows (its chi-square degrees of
    freedom). Equal to the sum of the scalar NIS of the sequential update."""
    n_rows = dz.size
    sel = np.empty(n_rows, np.int64)
    m = 0
    for a in range(n_rows):
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
    scalar normalized innovations squared. Shared by every measurement of every aid (:func:`fuse`).
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
def fuse(pos, v, c, ba, bg, P, H, dz, std, gate, innov):
    """Eq. (eq4) update with one measurement (:func:`sequential_update`), then :func:`feedback`.

    ``gate`` > 0: the measurement is first tested as a whole; when its NIS (:func:`measurement_nis`) exceeds
    ``gate`` it is rejected and the state and ``P`` are left untouched (an innovation gate; 0: always fused, as
    in the paper). Returns ``(nis, accepted)``; ``innov`` receives the innovations (NaN for unused rows).
    """
    n = P.shape[0]
    if gate > 0.0:
        nis_all, _ = measurement_nis(P, H, dz, std)
        if nis_all > gate:
            for a in range(dz.size):
                innov[a] = dz[a] if (std[a] > 0.0 and np.isfinite(std[a])) else np.nan
            return nis_all, False
    x = np.zeros(n)
    nis = sequential_update(P, H, dz, std, x, innov)
    feedback(pos, v, c, ba, bg, x)
    return nis, True


# ---------------------------------------------------------------------------------------------------
# the aid interface
# ---------------------------------------------------------------------------------------------------
@dataclass(frozen=True)
class Measurement:
    """One measurement for Eq. (eq4): ``dz`` [m rows] (computed minus measured), ``H`` [m, 15] its Jacobian with
    respect to the error states (:mod:`bgfn.nav.error_model` order), ``std`` [m] the measurement noise per row (a
    row with a non-positive or non-finite std is left out).

    ``gate``, optional: a chi-square threshold per row (0: none). The engine leaves out a row whose normalized
    innovation squared ``dz^2 / (H P H^T + std^2)`` against the covariance before the epoch's update exceeds it
    (:func:`gated_std`): the aid says how much it trusts a value, the engine owns the test.
    ``nis_gate``: a threshold on the NIS of the whole measurement (0: none); beyond it nothing is fused.
    ``label``: the measurement enters the run's log of fixes under this name (None: not logged); ``time``: its
    epoch there, s.
    """

    dz: np.ndarray
    H: np.ndarray
    std: np.ndarray
    gate: np.ndarray | None = None
    nis_gate: float = 0.0
    label: str | None = None
    time: float = float("nan")


def stacked(measurements: Sequence[Measurement]) -> Measurement:
    """The rows of several measurements of one epoch as one (per-row gates kept, 0 for a row without one; the
    label, time and whole-measurement gate of the first)."""
    first = measurements[0]
    if len(measurements) == 1:
        return first
    gates = [m.gate for m in measurements]
    gate = None if all(g is None for g in gates) else np.concatenate(
        [np.zeros(m.dz.size) if g is None else g for m, g in zip(measurements, gates)])
    return Measurement(np.concatenate([m.dz for m in measurements]), np.vstack([m.H for m in measurements]),
                       np.concatenate([m.std for m in measurements]), gate, first.nis_gate, first.label, first.time)


class AidSchedule(Protocol):
    """An aid bound to the epochs of one run (what :meth:`Aid.schedule` returns).

    ``rows``: the sorted output rows (indices into the run's ``times``) at which the engine asks, once per entry;
    ``measurement(i, nav)`` answers for the ``i``-th entry from the current solution of ``nav`` (a
    :class:`Stepper` at ``rows[i]``), or None for no update. ``joint``: the measurement joins the one of the aid
    before it at the same epoch (both measured from the same state, fused as one update).
    """

    rows: np.ndarray
    joint: bool

    def measurement(self, i: int, nav: "Stepper") -> Measurement | None: ...


class Aid(Protocol):
    """A measurement source of the filter (GNSS fixes, pseudo-GPS, NHC/ZUPT, an odometer ...)."""

    def schedule(self, times: np.ndarray, source: str = "imu", hold_at: float | None = None) -> AidSchedule:
        """Bind to a run's epochs ``times`` (s; row 0: the initial state, row k: after IMU step k). ``hold_at``:
        no GNSS fix comes after this time (an outage), so whatever the aid estimates from the GPS-aided
        solution is held at its value then."""
        ...


def gated_std(P: np.ndarray, H: np.ndarray, dz: np.ndarray, std: np.ndarray, gate: np.ndarray) -> np.ndarray:
    """``std`` with NaN for every row whose normalized innovation squared ``dz^2 / (h P h^T + std^2)`` (against
    ``P`` before the update) exceeds its ``gate`` > 0 (:class:`Measurement`): such a row is not fused."""
    s = np.einsum("ij,jk,ik->i", H, P, H) + np.asarray(std, float) ** 2
    reject = (np.asarray(gate, float) > 0.0) & (np.asarray(dz, float) ** 2 > np.asarray(gate, float) * s)
    return np.where(reject, np.nan, std)


def noise_arrays(noise: FilterNoise):
    """Process-noise arrays in the order :func:`propagate_steps` takes them (PSDs, inverse correlation times of the
    model, then of the estimates' decay: zero when ``noise.hold_bias_estimates``)."""
    inv = [np.where(np.isfinite(t), 1.0 / np.asarray(t, float), 0.0) for t in
           (noise.accel_bias_tau, noise.gyro_bias_tau)]
    decay = [np.zeros(3) if noise.hold_bias_estimates else i for i in inv]
    return (np.asarray(noise.gyro_noise, float) ** 2, np.asarray(noise.accel_noise, float) ** 2,
            np.asarray(noise.gyro_bias_walk, float) ** 2, np.asarray(noise.accel_bias_walk, float) ** 2,
            inv[0], inv[1], decay[0], decay[1])


# ---------------------------------------------------------------------------------------------------
# the stepper
# ---------------------------------------------------------------------------------------------------
class Stepper:
    """The closed-loop filter over one run's IMU steps, advanced in time, updated by its aids.

    Parameters
    ----------
    times : ndarray [n]
        Epochs of the output rows, s: row 0 the initial state, row k the state after IMU step k.
    dt, gyro, accel : ndarray [n - 1], [n - 1, 3], [n - 1, 3]
        Step lengths (s) and the IMU readings of each step (rad/s, m/s^2).
    initial : FilterState
    noise : FilterNoise
    aids : sequence of Aid
        Asked at their epochs; at one epoch in list order, each fused (and fed back) before the next is asked,
        unless it is ``joint`` (:class:`AidSchedule`).
    source : str
        Name used in error messages.
    hold_at : float, optional
        Passed to every aid's schedule (:meth:`Aid.schedule`).

    Attributes
    ----------
    pos, v, c, ba, bg, P : ndarray
        The current solution (``[lat, lon, h]``, NED velocity, C_bn, bias estimates, covariance), updated in place.
    row : int
        Output row of the current solution.
    out_pos, out_v, out_c, out_sd : ndarray
        The solution and the error states' std at every row up to ``row``.
    bias_rows, bias_vals : list
        The rows of every update (row 0 first) and the bias estimates (accelerometer then gyro) after it.
    log : list
        ``(time, label, innov, nis, accepted)`` of every labelled measurement, in order; ``P_log`` the covariance
        after each.
    """

    def __init__(self, times, dt, gyro, accel, initial: FilterState, noise: FilterNoise, aids: Sequence[Aid] = (),
                 source: str = "imu", hold_at: float | None = None):
        self.times = np.asarray(times, dtype=float)
        self.dt, self.gyro, self.accel = dt, gyro, accel
        self.pos, self.v = initial.pos.astype(float).copy(), initial.v.astype(float).copy()
        self.c = np.ascontiguousarray(initial.c_bn, dtype=float).copy()
        self.ba, self.bg = initial.accel_bias.astype(float).copy(), initial.gyro_bias.astype(float).copy()
        self.P = np.ascontiguousarray(initial.P, dtype=float).copy()
        self.q = noise_arrays(noise)
        n = self.times.size
        self.out_pos, self.out_v = np.empty((n, 3)), np.empty((n, 3))
        self.out_c, self.out_sd = np.empty((n, 3, 3)), np.empty((n, em.N_STATES))
        self.out_pos[0], self.out_v[0], self.out_c[0] = self.pos, self.v, self.c
        self.out_sd[0] = np.sqrt(np.clip(np.diag(self.P), 0, None))
        self.row = 0
        self.bias_rows, self.bias_vals = [0], [np.concatenate([self.ba, self.bg])]
        self.log, self.P_log = [], []
        # every aid's epochs, merged: by row, then by the aid's place in the list, then in the aid's own order
        self.schedules = [a.schedule(self.times, source, hold_at) for a in aids]
        rows = [np.asarray(s.rows, dtype=np.int64) for s in self.schedules]
        ev_row = np.concatenate(rows + [np.empty(0, np.int64)])
        ev_aid = np.concatenate([np.full(r.size, i) for i, r in enumerate(rows)] + [np.empty(0, np.int64)])
        ev_idx = np.concatenate([np.arange(r.size) for r in rows] + [np.empty(0, np.int64)])
        order = np.lexsort((ev_idx, ev_aid, ev_row))
        self._events = list(zip(ev_row[order].tolist(), ev_aid[order].tolist(), ev_idx[order].tolist()))
        self._next = 0

    def row_at(self, t: float) -> int:
        """The output row a measurement of time ``t`` (s) is applied at: the first epoch at or after it (the last
        row at most); the measurement accounts for the lag."""
        return min(int(np.searchsorted(self.times, t - EPOCH_TOL, side="left")), self.times.size - 1)

    def propagate_to(self, t: float) -> None:
        """Predict (Eq. eq3) to the epoch of time ``t`` (:meth:`row_at`), fusing the aids due on the way and at it."""
        self.step_to(self.row_at(t))

    def step_to(self, r: int) -> None:
        """Predict to output row ``r``, fusing every aid due at a row up to ``r`` (in order) on the way."""
        r = min(int(r), self.times.size - 1)
        events, e, pending = self._events, self._next, []
        while e < len(events) and events[e][0] <= r:
            row, aid, i = events[e]
            schedule = self.schedules[aid]
            if pending and (row != self.row or not schedule.joint):
                self.update(stacked(pending))
                pending = []
            if row > self.row:
                self._predict(row)
            m = schedule.measurement(i, self)
            if m is not None:
                pending.append(m)
            e += 1
        self._next = e
        if pending:
            self.update(stacked(pending))
        if r > self.row:
            self._predict(r)

    def _predict(self, r: int) -> None:
        propagate_steps(self.row, r, self.dt, self.gyro, self.accel, self.pos, self.v, self.c, self.ba, self.bg,
                        self.P, *self.q, self.out_pos, self.out_v, self.out_c, self.out_sd)
        self.row = r

    def update(self, m: Measurement) -> tuple[float, bool, np.ndarray]:
        """Fuse ``m`` at the current row (Eq. eq4, :func:`fuse`) and write the corrected solution into it.

        Returns ``(nis, accepted, innov)``: the NIS (of the whole measurement when its ``nis_gate`` rejected it),
        whether it was fused, and the innovations per row (NaN for a row left out)."""
        std = m.std if m.gate is None else gated_std(self.P, m.H, m.dz, m.std, m.gate)
        innov = np.empty(m.dz.size)
        nis, accepted = fuse(self.pos, self.v, self.c, self.ba, self.bg, self.P, m.H, m.dz, std, m.nis_gate, innov)
        r = self.row
        self.out_pos[r], self.out_v[r], self.out_c[r] = self.pos, self.v, self.c
        self.out_sd[r] = np.sqrt(np.maximum(np.diag(self.P), 0.0))
        self.bias_rows.append(r)
        self.bias_vals.append(np.concatenate([self.ba, self.bg]))
        if m.label is not None:
            self.log.append((m.time, m.label, innov, nis, bool(accepted)))
            self.P_log.append(self.P.copy())
        return nis, bool(accepted), innov

    def state(self) -> FilterState:
        """A copy of the current solution as a :class:`FilterState` (at ``times[row]``)."""
        return FilterState(float(self.times[self.row]), self.pos.copy(), self.v.copy(), self.c.copy(),
                           self.ba.copy(), self.bg.copy(), self.P.copy())


__all__ = ["Aid", "AidSchedule", "EPOCH_TOL", "Measurement", "Stepper", "feedback", "fuse", "gated_std",
           "measurement_nis", "noise_arrays", "propagate_steps", "sequential_update", "stacked"]

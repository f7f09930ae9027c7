"""The hybrid GPS/INS structure in prediction mode (paper Sec. 3.1): the GPS-aided run, the outage runs fed
with pseudo-GPS fixes (Eq. pred-gps), and their error metrics."""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any, Sequence

import numpy as np
import pandas as pd

from bgfn.errors import DataError
from bgfn.evaluate.setup import EVALUATE_DEFAULTS, merge_checked
from bgfn.learning import (ANGULAR_RATE_CHANNELS, ATTITUDE_CHANNELS, CHANNELS, DERIVED_CHANNELS, EXTRA_START,
                           IMU_CHANNELS, SPECIFIC_FORCE_CHANNELS, YAW_CHANNEL, WindowSet, encode_yaw, heading_velocity,
                           with_derived_channels)
from bgfn.nav import baseline, earth, error_model as em, metrics, navego_setup, transform
from bgfn.nav.engine import Stepper
from bgfn.nav.filter import run_filter
from bgfn.nav.gnss_aid import position_fix
from bgfn.nav.outages import epochs_before
from bgfn.nav.strapdown import trajectory_frame


# ----------------------------------------------------------------------------------------------- Eq. pred-gps
def pseudo_gps_positions(p0, increments) -> np.ndarray:
    """Eq. (pred-gps): ``P_GPS(k) = P_GPS0 + sum_{i<=k} delta_p_gps_i``.

    Parameters
    ----------
    p0 : array_like, shape (3,)
        ``P_GPS0`` = ``[lat, lon, h]`` (rad, rad, m) when the GPS is lost.
    increments : array_like [K, 2]
        Predicted increments (north, east), m.

    Returns
    -------
    ndarray [K, 3]
        ``[lat, lon, h]`` of the pseudo-GPS positions after each increment; the sums are north/east offsets
        from ``P_GPS0`` in its local level frame (exact through ECEF), the height stays ``h0``.
    """
    inc = np.asarray(increments, dtype=float).reshape(-1, 2)
    cum = np.cumsum(inc, axis=0)                                     # [K, 2]
    ned = np.column_stack([cum, np.zeros(len(cum))])                 # [K, 3]
    p0 = np.asarray(p0, dtype=float).reshape(3)
    lat, lon, h = earth.ned_to_lla(ned, p0[0], p0[1], p0[2])
    return np.column_stack([lat, lon, h])


# ----------------------------------------------------------------------------------------------- GPS-aided run
@dataclass
class NavContext:
    """What the outage runs of one drive start from (all from the GPS-aided filter run).

    Attributes
    ----------
    drive : bgfn.data.Drive
    full : bgfn.nav.filter.FilterResult
        GPS/INS over the whole drive with every GNSS fix.
    noise : bgfn.nav.state.FilterNoise
    lever : ndarray (3,)
        Antenna lever arm, body, m.
    states : dict
        ``{start (s): FilterState}``: the state at the last IMU epoch before each outage start.
    imu_time : ndarray [M]
    imu : ndarray [M, 6]
        Raw ``accel_x..z, gyro_x..z`` (the order of Eq. eq21 after the attitude).
    nav_at_imu : dict
        ``roll, pitch, yaw, v_n, v_e, v_d, lat, lon, h`` of the GPS-aided solution at the IMU times [M].
    gnss_interval_s : float
        Median GNSS epoch interval (length of one ``delta_p_gps``), s.
    gnss_std_m : float
        Median horizontal std of the GNSS fixes, m.
    imu_static : ndarray [len(CHANNELS)] or None
        Static biases the strapdown of an outage run removes from ``imu`` (``nav.ins_tuning: navego``,
        :mod:`bgfn.nav.navego_setup`; zeros outside the IMU channels); None: the network inputs are read as is.
    constraints : bgfn.nav.constraints.Constraints or None
        The vehicle constraints of the ``+NHC`` rows: the stillness detector over the drive's IMU and the vehicle
        frame from this GPS-aided run (:func:`bgfn.nav.baseline.outage_constraints`; held at its estimate at
        each outage start).
    """

    drive: Any
    full: Any
    noise: Any
    lever: np.ndarray
    states: dict
    imu_time: np.ndarray
    imu: np.ndarray
    nav_at_imu: dict
    gnss_interval_s: float
    gnss_std_m: float
    imu_static: np.ndarray | None = None
    constraints: Any = None

    def attitude_table(self) -> pd.DataFrame:
        """The GPS-aided solution (reference schema; its attitude is the training input of notebook 03)."""
        return pd.DataFrame(self.full.trajectory).reset_index(drop=True)

    def state_at(self, start: float):
        """The saved filter state of the outage starting at ``start``."""
        key = min(self.states, key=lambda s: abs(s - start)) if self.states else None
        if key is None or abs(key - start) > 1e-6:
            raise DataError(self.drive.name, "start", "an outage start given to navigation_context",
                            f"{start} (known: {sorted(self.states)})")
        return self.states[key]


_NAV_COLUMNS = ("roll", "pitch", "yaw", "v_n", "v_e", "v_d", "lat", "lon", "h", "v_along", "v_cross")


def navigation_context(drive, nav_section: dict | None, starts: Sequence[float]) -> NavContext:
    """Run the GPS-aided filter over ``drive`` and save its state at every ``start``.

    Parameters
    ----------
    drive : bgfn.data.Drive
    nav_section : dict
        A profile's ``nav:`` section (:func:`bgfn.nav.baseline.nav_config`).
    starts : sequence of float
        Outage starts, s.
    """
    cfg = baseline.nav_config(nav_section)
    initial, noise = baseline.initial_and_noise(drive, cfg)
    filter_imu = baseline.filter_imu(drive, cfg)     # drive.imu, or without NaveGo's static biases
    lever = np.asarray(drive.meta.get("lever_arm_m", [0.0, 0.0, 0.0]), dtype=float)
    starts = sorted({float(s) for s in starts})
    if starts and starts[0] <= initial.time:                     # a self-aligned filter starts late
        raise DataError(drive.name, "outage start", f"starts after the filter's start at {initial.time:.2f} s "
                        "(nav.alignment)", f"{starts[0]:.2f} s")
    imu_time = drive.imu["time"].to_numpy(float)
    # The state is taken at the last IMU epoch *before* the start (bgfn.nav.outages.epochs_before).
    snaps = {f"start_{i}": float(t) for i, t in enumerate(epochs_before(imu_time, starts, drive.name))}
    full = run_filter(filter_imu, initial, noise, drive.gnss, lever, snapshots=snaps,
                      gate_probability=cfg["innovation_gate"], source=drive.name,
                      aids=baseline.gps_aids(drive, cfg, initial, noise))
    states = {s: full.states[f"start_{i}"] for i, s in enumerate(starts)}
    imu = drive.imu[list(CHANNELS[IMU_CHANNELS])].to_numpy(float)          # [M, 6] in the input layout
    tr = full.trajectory
    ttr = tr["time"].to_numpy(float)
    idx = np.clip(np.searchsorted(ttr, imu_time - 1e-6), 0, len(ttr) - 1)
    ok = np.abs(ttr[idx] - imu_time) < 1e-6
    tr = with_derived_channels(tr, DERIVED_CHANNELS)     # v_along, v_cross for train.extra_channels
    nav_at_imu = {}
    for c in _NAV_COLUMNS:
        v = tr[c].to_numpy(float)[idx]
        nav_at_imu[c] = np.where(ok, v, np.nan)
    g = drive.gnss
    tg = g["time"].to_numpy(float)
    interval = float(np.median(np.diff(tg))) if len(tg) > 1 else float("nan")
    std = float(np.nanmedian(np.hypot(g["std_n"].to_numpy(float), g["std_e"].to_numpy(float)) / np.sqrt(2.0)))
    static = None
    if filter_imu is not drive.imu:                   # the outage runs remove the same static biases
        static = np.zeros(len(CHANNELS))
        static[ANGULAR_RATE_CHANNELS], static[SPECIFIC_FORCE_CHANNELS] = navego_setup.static_biases(
            drive.meta["imu_errors"], f"{drive.name} meta['imu_errors']")
    return NavContext(drive, full, noise, lever, states, imu_time, imu, nav_at_imu, interval, std, static,
                      baseline.outage_constraints(drive, cfg, full))


# ----------------------------------------------------------------------------------------------- outage runs
@dataclass
class OutageRun:
    """One method in one outage.

    Attributes
    ----------
    method : str
        Table label (``INS``, ``BGFN``, ..., ``GPS``).
    seed : int or None
        Training seed of the network (None for INS and GPS).
    start, duration : float
        The outage window, s.
    trajectory : DataFrame
        Reference schema, IMU rate, from the start state to the window end.
    increments : DataFrame
        ``time`` (end of the GNSS interval, s), ``dn``, ``de`` (m): the predicted ``delta_p_gps``.
    pseudo : DataFrame
        The fused pseudo-GPS fixes: ``time``, ``lat``, ``lon``, ``h`` (antenna), ``cum_dn``, ``cum_de``
        (m, the sum of Eq. pred-gps), ``std_m``.
    errors : DataFrame or None
        :func:`bgfn.nav.metrics.navigation_errors` of ``trajectory`` plus ``t_rel`` (s since the start).
    sd : DataFrame or None
        The filter's own horizontal position std at the rows of ``trajectory``: ``time``, ``sd_north_m``,
        ``sd_east_m`` (m; None for the ``GPS`` row): what :func:`window_metrics` compares the errors with (NEES).
    """

    method: str
    seed: int | None
    start: float
    duration: float
    trajectory: pd.DataFrame
    increments: pd.DataFrame = field(default_factory=lambda: pd.DataFrame(columns=["time", "dn", "de"]))
    pseudo: pd.DataFrame = field(default_factory=lambda: pd.DataFrame(
        columns=["time", "lat", "lon", "h", "cum_dn", "cum_de", "std_m"]))
    errors: pd.DataFrame | None = None
    sd: pd.DataFrame | None = None


def _extra_columns(options: dict) -> tuple[str, ...]:
    extra = tuple((options or {}).get("extra_channels") or ())
    bad = [c for c in extra if c not in _NAV_COLUMNS]
    if bad:
        raise DataError("evaluate", "extra_channels", f"columns of the navigation solution {_NAV_COLUMNS}",
                        repr(bad))
    return extra


class _Run:
    """One outage run of the closed-loop filter, advanced pseudo epoch by pseudo epoch, and its network inputs.

    The filter is the engine's :class:`~bgfn.nav.engine.Stepper` (with ``aids``, e.g. the vehicle constraints, their
    vehicle frame held at its estimate at the start); this class keeps the network inputs, because those at a
    pseudo epoch need the attitude the run itself computed up to that epoch. ``tests/test_evaluate.py`` checks
    that the result equals ``run_filter`` / ``run_outage`` fed the same fixes.
    """

    def __init__(self, ctx: NavContext, start: float, duration: float, n_window: int, extra: tuple, aids=()):
        self.start, self.duration, self.end = float(start), float(duration), float(start) + float(duration)
        s = ctx.state_at(start)
        self.state0 = s
        t_all = ctx.imu_time
        sel = np.flatnonzero((t_all > s.time + 1e-9) & (t_all <= self.end + 1e-9))
        if len(sel) == 0:
            raise DataError(ctx.drive.name, "imu", f"IMU rows inside the outage [{start}, {self.end}]", "none")
        self.time = t_all[sel]
        self.times = np.concatenate([[s.time], self.time])          # output rows
        self.lever = ctx.lever
        self.p0 = s.antenna_position(ctx.lever)                     # P_GPS0 of Eq. (pred-gps)
        # Input features [roll, pitch, yaw, f, w, extra]: N samples up to the start from the GPS-aided run,
        # then this run's own solution (filled as it is computed).
        self.n_window = int(n_window)
        j0 = int(np.searchsorted(t_all, s.time + 1e-6, side="right")) - 1   # last IMU sample <= start
        if j0 - self.n_window + 1 < 0:
            raise DataError(ctx.drive.name, "start", f"{self.n_window} IMU samples before the outage start",
                            f"{j0 + 1} before {start}")
        pre = slice(j0 - self.n_window + 1, j0 + 1)
        self.extra = extra
        self.t_feat = np.concatenate([t_all[pre], self.time])
        self.feat = np.empty((self.n_window + len(self.time), EXTRA_START + len(extra)))      # [N + M, C]
        self.feat[: self.n_window, ATTITUDE_CHANNELS] = np.column_stack(
            [ctx.nav_at_imu[c][pre] for c in CHANNELS[ATTITUDE_CHANNELS]])
        self.feat[: self.n_window, IMU_CHANNELS] = ctx.imu[pre]
        for i, c in enumerate(extra):
            self.feat[: self.n_window, EXTRA_START + i] = ctx.nav_at_imu[c][pre]
        self.feat[self.n_window:, IMU_CHANNELS] = ctx.imu[sel]
        self.feat[self.n_window:, ATTITUDE_CHANNELS] = np.nan
        if not np.all(np.isfinite(self.feat[: self.n_window])):
            raise DataError(ctx.drive.name, "attitude", "the GPS-aided solution before the outage start", "NaN")
        # the strapdown of this run reads the same IMU samples as its network inputs
        gyro = np.ascontiguousarray(self.feat[self.n_window:, ANGULAR_RATE_CHANNELS])
        accel = np.ascontiguousarray(self.feat[self.n_window:, SPECIFIC_FORCE_CHANNELS])
        if ctx.imu_static is not None:      # nav.ins_tuning: navego reads the IMU without its static biases
            gyro = gyro - ctx.imu_static[ANGULAR_RATE_CHANNELS]
            accel = accel - ctx.imu_static[SPECIFIC_FORCE_CHANNELS]
        self.nav = Stepper(self.times, np.diff(self.times), gyro, accel, s, ctx.noise, aids, ctx.drive.name,
                           hold_at=s.time)

    @property
    def row(self) -> int:
        """Output row of the run's current solution."""
        return self.nav.row

    def _fill(self, r0: int, r1: int) -> None:
        """Features of output rows r0..r1 (inclusive, >= 1) from the current solution."""
        if r1 < r0:
            return
        roll, pitch, yaw = transform.euler_from_dcm(self.nav.out_c[r0:r1 + 1])
        k0, k1 = self.n_window + r0 - 1, self.n_window + r1
        self.feat[k0:k1, ATTITUDE_CHANNELS] = np.column_stack([roll, pitch, yaw])
        v = self.nav.out_v[r0:r1 + 1]
        for i, c in enumerate(self.extra):
            if c in ("v_n", "v_e", "v_d"):
                self.feat[k0:k1, EXTRA_START + i] = v[:, ("v_n", "v_e", "v_d").index(c)]
            elif c in DERIVED_CHANNELS:                  # (v_along, v_cross), in that order
                self.feat[k0:k1, EXTRA_START + i] = heading_velocity(v[:, 0], v[:, 1], yaw)[DERIVED_CHANNELS.index(c)]
            else:
                self.feat[k0:k1, EXTRA_START + i] = self.nav.out_pos[r0:r1 + 1, ("lat", "lon", "h").index(c)]

    def propagate_to(self, t: float) -> None:
        """Prediction (strapdown + covariance, Eq. eq3) up to the epoch of time ``t``, the aids fused on the way."""
        r0 = self.nav.row
        self.nav.propagate_to(t)
        self._fill(r0 + 1, self.nav.row)

    def update(self, t_m: float, fix: np.ndarray, std: np.ndarray) -> None:
        """Eq. (eq4) position update with a pseudo fix of time ``t_m`` at the current row, then feedback."""
        r = self.nav.row
        sd = self.nav.out_sd[r].copy()
        self.nav.update(position_fix(self.nav, self.lever, fix, std, t_m))      # never gated
        # the std of a pseudo epoch's row stays the prediction's: the NEES at a window's end (window_metrics)
        # has always compared the error with it
        self.nav.out_sd[r] = sd
        if r >= 1:        # later windows see the corrected solution, as the training attitude does
            self._fill(r, r)

    def window(self, t_end: float) -> tuple[np.ndarray, float, float]:
        """The ``N`` latest samples with time <= ``t_end``: features [N, C], last sample time, yaw there."""
        last = int(np.searchsorted(self.t_feat, t_end + 1e-6, side="right")) - 1
        first = last - self.n_window + 1
        if first < 0 or last >= self.n_window + self.row:
            raise DataError("evaluate", "window", f"features up to t = {t_end:.3f} s", "not yet computed")
        x = self.feat[first:last + 1]
        return x, float(self.t_feat[last]), float(x[-1, YAW_CHANNEL])

    def trajectory(self) -> pd.DataFrame:
        return trajectory_frame(self.times, self.nav.out_pos, self.nav.out_v, self.nav.out_c)

    def position_sd(self) -> pd.DataFrame:
        """The filter's horizontal position std (m) at every output row, from its latitude and longitude error
        states (rad) through the radii of curvature."""
        lat, h = self.nav.out_pos[:, 0], self.nav.out_pos[:, 2]
        r_m, r_n = earth.curvature_radii(lat)
        return pd.DataFrame({"time": self.times, "sd_north_m": self.nav.out_sd[:, em.DLAT] * (r_m + h),
                             "sd_east_m": self.nav.out_sd[:, em.DLON] * (r_n + h) * np.cos(lat)})


def run_outages(ctx: NavContext, windows, predictor=None, method: str = "INS", seed: int | None = None,
                pseudo: dict | None = None, errors: bool = True, aids=()) -> list[OutageRun]:
    """Prediction mode over outage ``windows`` from the GPS-aided states (module docstring, step 2).

    Parameters
    ----------
    ctx : NavContext
        From :func:`navigation_context` with every window's start.
    windows : sequence of (start, duration)
        Outages, s.
    predictor : object, optional
        ``predictor.options`` (learning options: ``window``, ``alignment``, ``yaw_encoding``,
        ``extra_channels``) and ``predictor.predict_windows(WindowSet) -> [M, 2]`` (north, east, m), e.g. a
        :class:`bgfn.train.TrainedModel`. None: standalone INS.
    method : str
        Label written into the results.
    seed : int, optional
    pseudo : dict, optional
        ``std_m``: a number (m, per horizontal axis), None (the drive's median GNSS std: the pseudo fix is
        trusted like a GNSS fix) or ``'validation'`` (the network's own held-out accuracy: the validation
        RMSE of one increment, ``predictor.val_rmse_m / sqrt(2)`` per axis, times ``sqrt(k)`` after ``k``
        accumulated increments, as for independent increment errors); ``std_growth_m_per_s``;
        ``fusion_rate_hz``.
    errors : bool
        Compute the errors against the reference.
    aids : sequence of bgfn.nav.engine.Aid
        Further aids fused at their epochs (``[ctx.constraints]``: the ``+NHC`` rows; an odometer after them,
        :func:`bgfn.nav.odometer.aid_list`); empty: the paper's filter.

    Returns
    -------
    list of OutageRun
        One per window, same order.
    """
    pcfg = merge_checked(EVALUATE_DEFAULTS["pseudo_gps"], pseudo or {}, "evaluate.pseudo_gps")
    windows = [(float(s), float(d)) for s, d in windows]
    opts = dict(getattr(predictor, "options", {}) or {}) if predictor is not None else {}
    n_window = int(opts.get("window", 1)) if predictor is not None else 1
    extra = _extra_columns(opts) if predictor is not None else ()
    runs = [_Run(ctx, s, d, n_window, extra, aids) for s, d in windows]
    inc_s = ctx.gnss_interval_s
    from_val = isinstance(pcfg["std_m"], str)
    if from_val and (pcfg["std_m"] != "validation" or predictor is not None
                     and not np.isfinite(getattr(predictor, "val_rmse_m", np.nan))):
        raise DataError("evaluate.pseudo_gps", "std_m", "a number, null, or 'validation' with a predictor "
                        "that has val_rmse_m", repr(pcfg["std_m"]))
    std0 = (float(pcfg["std_m"]) if pcfg["std_m"] is not None else ctx.gnss_std_m) if not from_val else 0.0
    growth = float(pcfg["std_growth_m_per_s"])
    incs = [[] for _ in runs]
    fixes = [[] for _ in runs]
    if predictor is not None:
        f = float(pcfg["fusion_rate_hz"])
        ratio = 1.0 / (f * inc_s)                                    # increments per fusion interval
        if not (np.isfinite(ratio) and ratio >= 1.0 - 1e-6 and abs(ratio - round(ratio)) < 1e-6):
            raise DataError("evaluate.pseudo_gps", "fusion_rate_hz",
                            f"a rate dividing the GNSS rate {1.0 / inc_s:g} Hz", repr(f))
        m = int(round(ratio))
        align_next = opts.get("alignment", "ending") == "next"
        yaw_encoding = opts.get("yaw_encoding", "unwrap")
        n_fuse = [int(math.floor(d * f + 1e-9)) for _, d in windows]
        cum = [np.zeros(2) for _ in runs]
        for k in range(1, max(n_fuse, default=0) + 1):
            active = [i for i, n in enumerate(n_fuse) if k <= n]
            xs, meta = [], []
            for i in active:
                r = runs[i]
                t_k = r.start + k / f
                r.propagate_to(t_k)
                for j in range(1, m + 1):                            # GNSS intervals ending in (t_{k-1}, t_k]
                    u = r.start + ((k - 1) * m + j) * inc_s
                    x, t_last, yaw_last = r.window(u - inc_s if align_next else u)
                    xs.append(x)
                    meta.append((i, u, t_last, yaw_last))
            x = encode_yaw(np.stack(xs).astype(np.float32), yaw_encoding)       # [M, N, C]
            nan = np.full((len(meta), 2), np.nan)
            t_to = np.array([mm[1] for mm in meta])
            t_last = np.array([mm[2] for mm in meta])
            ws = WindowSet(x=x, y=nan, t_from=t_to - inc_s, t_to=t_to, t_end=t_last,
                           t_start=t_last - n_window * (ctx.imu_time[1] - ctx.imu_time[0]), y_last=nan.copy(),
                           yaw_ref=np.array([mm[3] for mm in meta]), channels=CHANNELS + extra)
            d = np.asarray(predictor.predict_windows(ws), dtype=float).reshape(-1, 2)   # [M, 2] (dN, dE), m
            for (i, u, _, _), dd in zip(meta, d):
                cum[i] = cum[i] + dd                                 # Eq. (pred-gps): running sum
                incs[i].append((u, dd[0], dd[1]))
            for i in active:
                r = runs[i]
                t_k = r.start + k / f
                p = pseudo_gps_positions(r.p0, cum[i][None, :])[0]   # P_GPS(k), antenna, [lat, lon, h]
                sd = std0 + growth * (t_k - r.start)
                if from_val:                                         # sqrt(k m) accumulated increments
                    sd += float(predictor.val_rmse_m) / np.sqrt(2.0) * np.sqrt(k * m)
                r.update(t_k, p, np.array([sd, sd, np.nan]))
                fixes[i].append((t_k, p[0], p[1], p[2], cum[i][0], cum[i][1], sd))
    out = []
    for i, r in enumerate(runs):
        r.propagate_to(r.times[-1])
        traj = r.trajectory()
        run = OutageRun(method, seed, r.start, r.duration, traj,
                        pd.DataFrame(incs[i], columns=["time", "dn", "de"]),
                        pd.DataFrame(fixes[i], columns=["time", "lat", "lon", "h", "cum_dn", "cum_de", "std_m"]),
                        sd=r.position_sd())
        if errors:
            e = metrics.navigation_errors(traj, ctx.drive.reference, ctx.drive.meta)
            e.insert(1, "t_rel", e["time"] - r.start)
            run.errors = e
        out.append(run)
    return out


def gps_run(ctx: NavContext, start: float, duration: float, errors: bool = True) -> OutageRun:
    """The GPS-available solution over the outage window (the lower bound row ``GPS``)."""
    tr = ctx.full.trajectory
    t = tr["time"].to_numpy(float)
    s0 = ctx.state_at(start).time
    m = (t >= s0 - 1e-9) & (t <= start + duration + 1e-9)
    traj = tr.loc[m].reset_index(drop=True)
    run = OutageRun("GPS", None, float(start), float(duration), traj)
    if errors:
        e = metrics.navigation_errors(traj, ctx.drive.reference, ctx.drive.meta)
        e.insert(1, "t_rel", e["time"] - start)
        run.errors = e
    return run


# ----------------------------------------------------------------------------------------------- metrics
def window_metrics(errors: pd.DataFrame, start: float, duration: float, sd: pd.DataFrame | None = None) -> dict:
    """Error numbers of one run over ``[start, start + duration]``.

    Returns
    -------
    dict
        ``max_east_m``, ``max_north_m`` (max |error|, paper Tables 1-2), ``max_h_m`` (max horizontal),
        ``rmse_h_m`` (horizontal RMSE over the IMU epochs), ``final_h_m`` (horizontal error at the last epoch),
        ``nees_h``: the normalized estimation error squared of the horizontal position at the last epoch against the
        filter's own std there (``sd``, :attr:`OutageRun.sd`; NaN without it), ``(e_N / sd_N)^2 + (e_E / sd_E)^2``:
        chi-square with 2 degrees of freedom when the filter is consistent (the north-east correlation of its
        covariance left out: :mod:`bgfn.studies.ins_fidelity.nees`).
    """
    t = errors["time"].to_numpy(float)
    m = (t >= start - 1e-6) & (t <= start + duration + 1e-6)
    if not m.any():
        raise DataError("errors", "time", f"epochs inside [{start}, {start + duration}]", "none")
    e, n = errors["east"].to_numpy(float)[m], errors["north"].to_numpy(float)[m]
    h = np.hypot(e, n)
    nees = float("nan")
    if sd is not None and len(sd):
        k = int(np.flatnonzero(m)[-1])
        j = int(np.argmin(np.abs(sd["time"].to_numpy(float) - t[k])))
        if abs(float(sd["time"].iloc[j]) - t[k]) < 1e-6:
            nees = float((n[-1] / sd["sd_north_m"].iloc[j]) ** 2 + (e[-1] / sd["sd_east_m"].iloc[j]) ** 2)
    return {"max_east_m": float(np.abs(e).max()), "max_north_m": float(np.abs(n).max()), "max_h_m": float(h.max()),
            "rmse_h_m": float(np.sqrt(np.mean(h ** 2))), "final_h_m": float(h[-1]), "nees_h": nees}

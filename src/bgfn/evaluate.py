"""GPS-outage evaluation of the hybrid GPS/INS structure (paper Sec. 3.1 prediction mode, Sec. 4 Tables 1-2).

Protocol (notebook 04, the ``evaluate:`` section of a profile):

1. **GPS-aided run.** The 15-state loosely coupled filter (:mod:`bgfn.nav.filter`, the ``nav:`` section's
   settings) runs over the whole drive with every GNSS fix; its state is saved at every outage start
   (:func:`navigation_context`). Before an outage start everything the methods see comes from this causal run
   (a filter state at ``t`` has used the fixes up to ``t`` only). Its trajectory inside the outage is the
   **GPS** row: the lower bound, the solution had GNSS not been lost.
2. **Prediction mode** (:func:`run_outages`), from the saved state at the outage start, no GNSS inside:

   - **INS**: the filter only predicts (strapdown + covariance), its bias estimates held;
   - **MLP / AT-LSTM / BGFN / Transformer**: at each pseudo-GNSS epoch ``t_k = start + k / fusion_rate_hz``
     the filter is propagated to ``t_k``; the network predicts the GNSS position increments
     ``delta_p_gps`` (north, east) of every GNSS interval ending in ``(t_{k-1}, t_k]`` from windows of the
     ``N`` latest IMU samples (Eq. eq21: roll, pitch, yaw of *the navigation solution being computed* in
     this run -- the hybrid's own attitude, pre-outage samples from the GPS-aided run -- and the raw
     specific force and angular rate); the increments are accumulated into the pseudo-GPS position
     ``P_GPS(k) = P_GPS0 + sum_i delta_p_gps_i`` (Eq. pred-gps, :func:`pseudo_gps_positions`) with
     ``P_GPS0`` the filter's antenna position at the outage start, and fused as a north/east antenna
     position fix with the standard deviation of ``pseudo_gps.std_m`` (height not fused: the networks
     predict 2-D increments). Nothing inside the outage reads GNSS or the reference.

   The increments have the length the networks were trained on: the drive's GNSS epoch interval (0.2 s for
   the 5 Hz Ekinox fixes, 1 s for the 1 Hz u-blox-like receiver); ``fusion_rate_hz`` must divide the GNSS
   rate. Runs that share a network advance in lockstep so that one forward pass serves all of them.
3. **Metrics** (:func:`window_metrics`): errors = solution minus reference at the IMU position, local NED
   metres; per outage max |east|, max |north| (paper Tables 1-2), horizontal RMSE, horizontal error at the
   end, max horizontal error.

The networks of the two tables are those of notebook 03 (``results/<profile>/models/<dataset>/
<method>_seed<k>.pt``; trained here with the same code when missing). The main tables report, per
method and metric, the **median over the training seeds** (``seed_aggregate``); the per-seed values are
written beside them.

Outage sweep (:func:`run_sweep`, beyond the paper): ``n_starts`` outage starts spread evenly over the drive,
split into ``folds`` contiguous blocks; the networks of fold ``k`` are trained (cached under
``models/<dataset>/fold<k>/``) with the outages of fold ``k`` (longest duration, plus the ``train.margin_s``
margin) excluded by :func:`bgfn.learning.split_windows`, and evaluated on them only. Each start is run once
for the longest duration; since the runs are causal the first ``d`` seconds of it *are* the run of a
``d``-second outage (same start state, same pseudo fixes), so the metrics of every duration come from its
prefix. :func:`sweep_summary` gives per method and duration the median max horizontal error with a cluster
(by start) bootstrap interval, :func:`sweep_comparisons` how often BGFN beats each baseline with the
Wilcoxon signed-rank test on the (start, seed) pairs.
"""

from __future__ import annotations

import copy
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Sequence

import numpy as np
import pandas as pd

from bgfn.errors import DataError

# ----------------------------------------------------------------------------------------------- names
#: Method id (bgfn.models) -> label of the paper's tables.
METHOD_LABELS: dict[str, str] = {"mlp": "MLP", "at_lstm": "AT-LSTM", "bgfn": "BGFN", "transformer": "Transformer"}
#: Rows of the outage tables, in order.
TABLE_METHODS: tuple[str, ...] = ("INS", "MLP", "AT-LSTM", "BGFN", "Transformer", "GPS")
#: Methods of the paper's figures and their colours (red, yellow, black, blue).
FIGURE_METHODS: tuple[str, ...] = ("INS", "MLP", "AT-LSTM", "BGFN")
COLORS: dict[str, str] = {"INS": "red", "MLP": "goldenrod", "AT-LSTM": "black", "BGFN": "blue",
                          "Transformer": "tab:purple", "GPS": "tab:green"}
#: Columns of the outage tables (``tables/outage_dataset.csv``, ``outage_field.csv``).
METRIC_COLUMNS: tuple[str, ...] = ("max_east_m", "max_north_m", "rmse_h_m", "final_h_m")
TABLE_COLUMNS: tuple[str, ...] = ("outage", "method") + METRIC_COLUMNS
#: Columns of ``tables/outage_sweep.csv``.
SWEEP_COLUMNS: tuple[str, ...] = ("dataset", "start_s", "duration_s", "method", "seed", "fold", "max_east_m",
                                  "max_north_m", "max_h_m", "rmse_h_m", "final_h_m")
#: Dataset -> the paper's test it stands for (Table 1 = dataset test, Table 2 = field test).
PAPER_TESTS: dict[str, str] = {"turin-sim-ekinox": "dataset", "navego-ekinox": "dataset",
                               "turin-sim-mpu6000": "field", "navego-mpu6000": "field"}
TABLE_FILES: dict[str, str] = {"dataset": "outage_dataset.csv", "field": "outage_field.csv"}
#: Simulated dataset -> the dataset with NaveGo's recorded IMU, and the file it needs.
REAL_IMU_DATASETS: dict[str, tuple[str, str]] = {"turin-sim-ekinox": ("navego-ekinox", "ekinox_imu.mat"),
                                                 "turin-sim-mpu6000": ("navego-mpu6000", "mpu6000_imu.mat")}

#: Defaults of the ``evaluate:`` section (every key of a profile's section must be one of these).
EVALUATE_DEFAULTS: dict[str, Any] = {
    "datasets": ["turin-sim-ekinox", "turin-sim-mpu6000"],
    "real_imu": False,
    "methods": ["bgfn", "transformer", "at_lstm", "mlp"],
    "seeds": None,                       # None: train.seeds
    "seed_aggregate": "median",          # 'median' over seeds, or 'first' (the first seed)
    "outage_windows": [[138906.0, 30.0], [139170.0, 30.0]],   # (start, duration), s
    "pseudo_gps": {"std_m": None, "std_growth_m_per_s": 0.0, "fusion_rate_hz": 1.0},
    "series_rate_hz": 10.0,
    "train_missing": True,
    "sweep": {
        "datasets": ["turin-sim-mpu6000"],
        "n_starts": 20,
        "durations_s": [10.0, 30.0, 60.0, 120.0],
        "folds": 2,
        "seeds": [0, 1, 2],
        "warmup_s": 60.0,
        "train": {},
        "n_boot": 2000,
        "level": 0.95,
        "boot_seed": 0,
    },
}


def _merge(base: dict, upd: dict, where: str, strict: bool = True) -> dict:
    out = copy.deepcopy(base)
    for key, value in (upd or {}).items():
        if strict and key not in out:
            raise DataError(f"params {where}", key, f"one of {sorted(out)}", "unknown key")
        if isinstance(out.get(key), dict) and isinstance(value, dict) and key != "train":
            out[key] = _merge(out[key], value, f"{where}.{key}", strict)
        else:
            out[key] = copy.deepcopy(value)
    return out


def evaluate_config(section: dict | None, train_section: dict | None = None) -> dict:
    """``EVALUATE_DEFAULTS`` updated with a profile's ``evaluate:`` section (unknown keys raise).

    ``seeds: null`` takes ``train.seeds``. Checks the sweep sizes and the seed aggregate.
    """
    cfg = _merge(EVALUATE_DEFAULTS, section or {}, "evaluate")
    if cfg["seeds"] is None:
        cfg["seeds"] = list((train_section or {}).get("seeds") or [0])
    if cfg["seed_aggregate"] not in ("median", "first"):
        raise DataError("params evaluate", "seed_aggregate", "'median' or 'first'", repr(cfg["seed_aggregate"]))
    unknown = [m for m in cfg["methods"] if m not in METHOD_LABELS]
    if unknown:
        raise DataError("params evaluate", "methods", f"ids among {sorted(METHOD_LABELS)}", repr(unknown))
    sw = cfg["sweep"]
    if int(sw["n_starts"]) < 1 or int(sw["folds"]) < 1 or int(sw["folds"]) > int(sw["n_starts"]):
        raise DataError("params evaluate.sweep", "n_starts/folds", "1 <= folds <= n_starts",
                        f"{sw['n_starts']} starts, {sw['folds']} folds")
    if not sw["durations_s"] or min(sw["durations_s"]) <= 0:
        raise DataError("params evaluate.sweep", "durations_s", "positive durations, s", repr(sw["durations_s"]))
    return cfg


def choose_datasets(datasets: Sequence[str], real_imu: bool) -> tuple[list[str], list[str]]:
    """The datasets to evaluate: with ``real_imu`` the NaveGo recorded-IMU twin when its file is present.

    Returns
    -------
    names : list of str
    notes : list of str
        One line per dataset saying what is used and why.
    """
    names, notes = [], []
    for d in datasets:
        if not real_imu or d not in REAL_IMU_DATASETS:
            names.append(d)
            continue
        real, fname = REAL_IMU_DATASETS[d]
        from bgfn.data import acquire

        res = acquire.resolve(fname, download=False)
        if res.path is not None:
            names.append(real)
            notes.append(f"{fname} present ({res.origin}): evaluating {real} instead of {d}")
        else:
            names.append(d)
            notes.append(f"{fname} absent (the recorded NaveGo IMU is not available here): {d} "
                         f"(simulated IMU) stands in for {real}")
    return names, notes


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
    from bgfn.nav import earth

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
    from bgfn.learning import DERIVED_CHANNELS, with_derived_channels
    from bgfn.nav import baseline
    from bgfn.nav.filter import run_filter
    from bgfn.nav.outages import epochs_before

    cfg = baseline.nav_config(nav_section)
    initial, noise = baseline.filter_setup(drive, cfg)
    lever = np.asarray(drive.meta.get("lever_arm_m", [0.0, 0.0, 0.0]), dtype=float)
    starts = sorted({float(s) for s in starts})
    imu_time = drive.imu["time"].to_numpy(float)
    # The state is taken at the last IMU epoch *before* the start (bgfn.nav.outages.epochs_before).
    snaps = {f"start_{i}": float(t) for i, t in enumerate(epochs_before(imu_time, starts, drive.name))}
    full = run_filter(drive.imu, initial, noise, drive.gnss, lever, snapshots=snaps,
                      gate_probability=cfg["innovation_gate"], source=drive.name)
    states = {s: full.states[f"start_{i}"] for i, s in enumerate(starts)}
    imu = drive.imu[["accel_x", "accel_y", "accel_z", "gyro_x", "gyro_y", "gyro_z"]].to_numpy(float)
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
    return NavContext(drive, full, noise, lever, states, imu_time, imu, nav_at_imu, interval, std)


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


def _extra_columns(options: dict) -> tuple[str, ...]:
    extra = tuple((options or {}).get("extra_channels") or ())
    bad = [c for c in extra if c not in _NAV_COLUMNS]
    if bad:
        raise DataError("evaluate", "extra_channels", f"columns of the navigation solution {_NAV_COLUMNS}",
                        repr(bad))
    return extra


class _Run:
    """Closed-loop filter of one outage run, advanced epoch by epoch.

    It drives the stepping kernels of :mod:`bgfn.nav.filter` (``propagate_steps``, ``update_position``) directly, because
    the network inputs at a pseudo epoch need the attitude the run itself computed up to that epoch, and one
    ``run_filter`` call per epoch costs ~2 ms of pandas overhead (the sweep has ~10^5 epochs).
    ``tests/test_evaluate.py`` checks that the result equals ``run_filter`` / ``run_outage`` fed the same fixes.
    """

    def __init__(self, ctx: NavContext, start: float, duration: float, n_window: int, extra: tuple):
        from bgfn.nav import error_model as em
        from bgfn.nav.filter import noise_arrays

        self.start, self.duration, self.end = float(start), float(duration), float(start) + float(duration)
        s = ctx.state_at(start)
        self.state0 = s
        t_all = ctx.imu_time
        sel = np.flatnonzero((t_all > s.time + 1e-9) & (t_all <= self.end + 1e-9))
        if len(sel) == 0:
            raise DataError(ctx.drive.name, "imu", f"IMU rows inside the outage [{start}, {self.end}]", "none")
        self.time = t_all[sel]
        self.dt = np.diff(np.concatenate([[s.time], self.time]))
        self.gyro = np.ascontiguousarray(ctx.imu[sel, 3:6])
        self.accel = np.ascontiguousarray(ctx.imu[sel, 0:3])
        self.times = np.concatenate([[s.time], self.time])          # output rows
        n = len(self.times)
        self.pos, self.v = s.pos.astype(float).copy(), s.v.astype(float).copy()
        self.c = np.ascontiguousarray(s.c_bn, dtype=float).copy()
        self.ba, self.bg = s.accel_bias.astype(float).copy(), s.gyro_bias.astype(float).copy()
        self.P = np.ascontiguousarray(s.P, dtype=float).copy()
        self.q = noise_arrays(ctx.noise)
        self.out_pos, self.out_v = np.empty((n, 3)), np.empty((n, 3))
        self.out_c, self.out_sd = np.empty((n, 3, 3)), np.empty((n, em.N_STATES))
        self.out_pos[0], self.out_v[0], self.out_c[0] = self.pos, self.v, self.c
        self.row = 0
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
        cols = ("roll", "pitch", "yaw") + extra
        n_feat = 9 + len(extra)
        self.t_feat = np.concatenate([t_all[pre], self.time])
        self.feat = np.empty((self.n_window + len(self.time), n_feat))
        self.feat[: self.n_window, :3] = np.column_stack([ctx.nav_at_imu[c][pre] for c in cols[:3]])
        self.feat[: self.n_window, 3:9] = ctx.imu[pre]
        for i, c in enumerate(extra):
            self.feat[: self.n_window, 9 + i] = ctx.nav_at_imu[c][pre]
        self.feat[self.n_window:, 3:9] = ctx.imu[sel]
        self.feat[self.n_window:, :3] = np.nan
        if not np.all(np.isfinite(self.feat[: self.n_window])):
            raise DataError(ctx.drive.name, "attitude", "the GPS-aided solution before the outage start", "NaN")

    def _fill(self, r0: int, r1: int) -> None:
        """Features of output rows r0..r1 (inclusive, >= 1) from the current solution."""
        from bgfn.learning import DERIVED_CHANNELS, heading_velocity
        from bgfn.nav import transform

        if r1 < r0:
            return
        roll, pitch, yaw = transform.euler_from_dcm(self.out_c[r0:r1 + 1])
        k0, k1 = self.n_window + r0 - 1, self.n_window + r1
        self.feat[k0:k1, 0], self.feat[k0:k1, 1], self.feat[k0:k1, 2] = roll, pitch, yaw
        v = self.out_v[r0:r1 + 1]
        for i, c in enumerate(self.extra):
            if c in ("v_n", "v_e", "v_d"):
                self.feat[k0:k1, 9 + i] = v[:, ("v_n", "v_e", "v_d").index(c)]
            elif c in DERIVED_CHANNELS:                  # (v_along, v_cross), in that order
                self.feat[k0:k1, 9 + i] = heading_velocity(v[:, 0], v[:, 1], yaw)[DERIVED_CHANNELS.index(c)]
            else:
                self.feat[k0:k1, 9 + i] = self.out_pos[r0:r1 + 1, ("lat", "lon", "h").index(c)]

    def propagate_to(self, r: int) -> None:
        """Prediction (strapdown + covariance, Eq. eq3) up to output row ``r``."""
        from bgfn.nav.filter import propagate_steps

        r = min(int(r), len(self.times) - 1)
        if r > self.row:
            propagate_steps(self.row, r, self.dt, self.gyro, self.accel, self.pos, self.v, self.c, self.ba, self.bg,
                          self.P, *self.q, self.out_pos, self.out_v, self.out_c, self.out_sd)
            self._fill(self.row + 1, r)
            self.row = r

    def update(self, t_m: float, fix: np.ndarray, std: np.ndarray) -> None:
        """Eq. (eq4) position update with a pseudo fix of time ``t_m`` at the current row, then feedback."""
        from bgfn.nav.filter import update_position

        innov = np.empty(3)
        update_position(self.pos, self.v, self.c, self.ba, self.bg, self.P, self.lever, np.asarray(fix, float),
                        np.asarray(std, float), float(self.times[self.row] - t_m), innov, 0.0)   # never gated
        self.out_pos[self.row], self.out_v[self.row], self.out_c[self.row] = self.pos, self.v, self.c
        if self.row >= 1:        # later windows see the corrected solution, as the training attitude does
            self._fill(self.row, self.row)

    def window(self, t_end: float) -> tuple[np.ndarray, float, float]:
        """The ``N`` latest samples with time <= ``t_end``: features [N, C], last sample time, yaw there."""
        last = int(np.searchsorted(self.t_feat, t_end + 1e-6, side="right")) - 1
        first = last - self.n_window + 1
        if first < 0 or last >= self.n_window + self.row:
            raise DataError("evaluate", "window", f"features up to t = {t_end:.3f} s", "not yet computed")
        x = self.feat[first:last + 1]
        return x, float(self.t_feat[last]), float(x[-1, 2])

    def trajectory(self) -> pd.DataFrame:
        from bgfn.nav.strapdown import trajectory_frame

        return trajectory_frame(self.times, self.out_pos, self.out_v, self.out_c)


def _rows_at(times: np.ndarray, t) -> np.ndarray:
    """Output row where an event of time ``t`` is applied: the first row with time >= t (as run_filter)."""
    return np.searchsorted(times, np.asarray(t, dtype=float) - 1e-9, side="left")


def run_outages(ctx: NavContext, windows, predictor=None, method: str = "INS", seed: int | None = None,
                pseudo: dict | None = None, errors: bool = True) -> list[OutageRun]:
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

    Returns
    -------
    list of OutageRun
        One per window, same order.
    """
    from bgfn.learning import CHANNELS, WindowSet, encode_yaw
    from bgfn.nav import metrics

    pcfg = _merge(EVALUATE_DEFAULTS["pseudo_gps"], pseudo or {}, "evaluate.pseudo_gps")
    windows = [(float(s), float(d)) for s, d in windows]
    opts = dict(getattr(predictor, "options", {}) or {}) if predictor is not None else {}
    n_window = int(opts.get("window", 1)) if predictor is not None else 1
    extra = _extra_columns(opts) if predictor is not None else ()
    runs = [_Run(ctx, s, d, n_window, extra) for s, d in windows]
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
                r.propagate_to(int(_rows_at(r.times, t_k)))
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
        r.propagate_to(len(r.times) - 1)
        traj = r.trajectory()
        run = OutageRun(method, seed, r.start, r.duration, traj,
                        pd.DataFrame(incs[i], columns=["time", "dn", "de"]),
                        pd.DataFrame(fixes[i], columns=["time", "lat", "lon", "h", "cum_dn", "cum_de", "std_m"]))
        if errors:
            e = metrics.navigation_errors(traj, ctx.drive.reference)
            e.insert(1, "t_rel", e["time"] - r.start)
            run.errors = e
        out.append(run)
    return out


def gps_run(ctx: NavContext, start: float, duration: float, errors: bool = True) -> OutageRun:
    """The GPS-available solution over the outage window (the lower bound row ``GPS``)."""
    from bgfn.nav import metrics

    tr = ctx.full.trajectory
    t = tr["time"].to_numpy(float)
    s0 = ctx.state_at(start).time
    m = (t >= s0 - 1e-9) & (t <= start + duration + 1e-9)
    traj = tr.loc[m].reset_index(drop=True)
    run = OutageRun("GPS", None, float(start), float(duration), traj)
    if errors:
        e = metrics.navigation_errors(traj, ctx.drive.reference)
        e.insert(1, "t_rel", e["time"] - start)
        run.errors = e
    return run


# ----------------------------------------------------------------------------------------------- metrics
def window_metrics(errors: pd.DataFrame, start: float, duration: float) -> dict:
    """Error numbers of one run over ``[start, start + duration]``.

    Returns
    -------
    dict
        ``max_east_m``, ``max_north_m`` (max |error|, paper Tables 1-2), ``max_h_m`` (max horizontal),
        ``rmse_h_m`` (horizontal RMSE over the IMU epochs), ``final_h_m`` (horizontal error at the last epoch).
    """
    t = errors["time"].to_numpy(float)
    m = (t >= start - 1e-6) & (t <= start + duration + 1e-6)
    if not m.any():
        raise DataError("errors", "time", f"epochs inside [{start}, {start + duration}]", "none")
    e, n = errors["east"].to_numpy(float)[m], errors["north"].to_numpy(float)[m]
    h = np.hypot(e, n)
    return {"max_east_m": float(np.abs(e).max()), "max_north_m": float(np.abs(n).max()), "max_h_m": float(h.max()),
            "rmse_h_m": float(np.sqrt(np.mean(h ** 2))), "final_h_m": float(h[-1])}


# ----------------------------------------------------------------------------------------------- models
def model_path(profile: str, dataset: str, method: str, seed: int, fold: int | None = None) -> Path:
    """``results/<profile>/models/<dataset>/[fold<k>/]<method>_seed<seed>.pt``."""
    from bgfn.train import models_dir

    d = models_dir(profile, dataset)
    if fold is not None:
        d = d / f"fold{fold}"
    return d / f"{method}_seed{seed}.pt"


def load_model(path: str | Path):
    """A checkpoint of :mod:`bgfn.train` on the CPU, with ``val_rmse_m`` (validation RMSE of one increment,
    m, from its JSON card; NaN without a card) attached."""
    import json

    from bgfn import train

    model = train.load_trained(path, device="cpu")
    card = Path(path).with_suffix(".json")
    model.val_rmse_m = float(json.loads(card.read_text()).get("val_rmse_m", np.nan)) if card.exists() else np.nan
    return model


def ensure_models(cfg: dict, profile: str, dataset: str, ctx: NavContext, methods, seeds, windows,
                  train_missing: bool = True, progress: bool = False) -> dict:
    """Load notebook 03's networks of ``dataset``; train the missing ones with the same code and settings
    (training excludes the evaluation outages ``windows``).

    Returns
    -------
    dict
        ``{(method, seed): TrainedModel}``.
    """
    from bgfn import train

    models, data = {}, None
    tc = train.tuned_train_config(cfg, profile, dataset)      # notebook 03's selected learning rates
    for method in methods:
        for seed in seeds:
            path = model_path(profile, dataset, method, seed)
            if not path.exists():
                if not train_missing:
                    raise DataError(path, "checkpoint", "a network trained by notebook 03 "
                                    "(run notebooks/03_bgfn_training.ipynb first)", "missing")
                if data is None:
                    data = train.prepare_learning_data(cfg, dataset, attitude=ctx.attitude_table(), drive=ctx.drive,
                                                       outage_windows=windows)
                train.train_model(method, data, train.size_config(tc, method), tc, seed=seed, out_dir=path.parent,
                                  progress=progress, extra_card={"dataset": dataset, "profile": profile,
                                                                 "size": tc.get("size"),
                                                                 "trained_by": "notebook 04 (missing)"})
            models[(method, seed)] = load_model(path)
    return models


# ----------------------------------------------------------------------------------------------- paper tables
@dataclass
class TableResult:
    """Outage evaluation of one dataset (the paper's Table 1 or 2).

    Attributes
    ----------
    dataset, test : str
        Dataset name and the paper's test (``dataset`` / ``field``).
    per_seed : DataFrame
        ``outage``, ``start_s``, ``method``, ``seed`` and every metric, one row per run.
    table : DataFrame
        ``TABLE_COLUMNS``: per outage and method the seed aggregate.
    runs : list of OutageRun
    models : dict
        ``{(method id, seed): predictor}`` used.
    gnss_errors : DataFrame or None
        :func:`fix_error_table`: how far the GNSS fixes themselves are from the reference in each outage
        window, which the GPS row follows.
    """

    dataset: str
    test: str
    per_seed: pd.DataFrame
    table: pd.DataFrame
    runs: list
    models: dict = field(default_factory=dict)
    gnss_errors: pd.DataFrame | None = None


def fix_error_table(drive, windows, lever_arm_m) -> pd.DataFrame:
    """Per outage window: the largest |east| and |north| error of the GNSS fixes inside it against the true
    antenna position (:func:`bgfn.data.gnss.fix_errors`), m, and the number of fixes.

    The GPS row is the filter with these fixes: it cannot stay closer to the reference than they are for long,
    while an INS that starts from the same state may drift less than the fixes wander.
    """
    from bgfn.data.gnss import fix_errors

    err = fix_errors(drive.gnss, drive.reference, lever_arm_m)
    rows = []
    for k, (start, duration) in enumerate(windows):
        inside = err[(err["time"] >= start) & (err["time"] <= start + duration)]
        rows.append({"outage": k + 1, "start_s": float(start), "n_fixes": int(len(inside)),
                     "max_east_m": float(inside["east_m"].abs().max()) if len(inside) else float("nan"),
                     "max_north_m": float(inside["north_m"].abs().max()) if len(inside) else float("nan")})
    return pd.DataFrame(rows)


def aggregate_seeds(per_seed: pd.DataFrame, how: str = "median") -> pd.DataFrame:
    """Per outage and method, the median over seeds (``how='median'``) or the first seed's row."""
    rows = []
    for (outage, method), g in per_seed.groupby(["outage", "method"], sort=False):
        if how == "median":
            vals = {c: float(np.median(g[c])) for c in METRIC_COLUMNS}
        else:
            vals = {c: float(g.sort_values("seed", na_position="first")[c].iloc[0]) for c in METRIC_COLUMNS}
        rows.append({"outage": int(outage), "method": method, **vals})
    t = pd.DataFrame(rows, columns=list(TABLE_COLUMNS))
    order = {m: i for i, m in enumerate(TABLE_METHODS)}
    return t.sort_values(["outage", "method"], key=lambda s: s.map(order) if s.name == "method" else s,
                         kind="stable").reset_index(drop=True)


def evaluate_dataset(cfg: dict, profile: str, dataset: str, drive=None, ecfg: dict | None = None,
                     models: dict | None = None, progress: bool = False) -> TableResult:
    """All methods in the profile's evaluation outages of one dataset (paper Tables 1-2).

    Parameters
    ----------
    cfg : dict
        The profile (:func:`bgfn.config.load_profile`).
    profile : str
    dataset : str
    drive : Drive, optional
        Default ``load_drive(dataset, profile=profile)``.
    ecfg : dict, optional
        :func:`evaluate_config` (default: from ``cfg``).
    models : dict, optional
        ``{(method, seed): predictor}``; default :func:`ensure_models`.
    """
    from bgfn.nav import outages

    ecfg = ecfg or evaluate_config(cfg.get("evaluate"), cfg.get("train"))
    if drive is None:
        from bgfn.data import load_drive

        drive = load_drive(dataset, profile=profile)
    windows = outages.outage_windows(drive, ecfg)
    ctx = navigation_context(drive, cfg.get("nav"), [s for s, _ in windows])
    if models is None:
        models = ensure_models(cfg, profile, dataset, ctx, ecfg["methods"], ecfg["seeds"], windows,
                               ecfg["train_missing"], progress)
    runs = run_outages(ctx, windows, None, "INS", None, ecfg["pseudo_gps"])
    runs += [gps_run(ctx, s, d) for s, d in windows]
    for (method, seed), model in models.items():
        runs += run_outages(ctx, windows, model, METHOD_LABELS[method], seed, ecfg["pseudo_gps"])
    outage_no = {s: i + 1 for i, (s, _) in enumerate(windows)}
    rows = [{"outage": outage_no[r.start], "start_s": r.start, "method": r.method, "seed": r.seed,
             **window_metrics(r.errors, r.start, r.duration)} for r in runs]
    per_seed = pd.DataFrame(rows)
    return TableResult(dataset, PAPER_TESTS.get(dataset, dataset), per_seed,
                       aggregate_seeds(per_seed, ecfg["seed_aggregate"]), runs, models,
                       fix_error_table(drive, windows, ctx.lever))


def table_file(test: str) -> str:
    """File name of a test's table under ``tables/``: ``outage_dataset.csv``, ``outage_field.csv``, else
    ``outage_<test>.csv``."""
    return TABLE_FILES.get(test, f"outage_{test}.csv")


def save_table_result(out, result: TableResult, series_rate_hz: float = 10.0) -> dict:
    """Write one dataset's outage results under ``out`` (``results/<profile>``), atomically.

    Files (``<t>`` = ``dataset`` / ``field``): ``tables/outage_<t>.csv`` (``TABLE_COLUMNS``, the seed
    aggregate), ``tables/outage_<t>_seeds.csv`` (every run), ``tables/outage_errors_<t>.csv`` (error
    series, :func:`error_series`), ``tables/outage_<t>_gnss.csv`` (the fixes' own errors in each window,
    :func:`fix_error_table`; when known).

    Returns
    -------
    dict
        ``{kind: path}``.
    """
    from bgfn.io import atomic_write_csv

    out = Path(out)
    stem = table_file(result.test)[: -len(".csv")]
    paths = {"table": out / "tables" / f"{stem}.csv", "seeds": out / "tables" / f"{stem}_seeds.csv",
             "series": out / "tables" / f"{stem.replace('outage_', 'outage_errors_', 1)}.csv"}
    atomic_write_csv(paths["table"], result.table[list(TABLE_COLUMNS)], float_format="%.4f")
    seeds = result.per_seed.assign(dataset=result.dataset)
    seeds["seed"] = seeds["seed"].astype("Int64")
    atomic_write_csv(paths["seeds"], seeds, float_format="%.4f")
    series = error_series(result.runs, series_rate_hz)
    series.insert(0, "outage", series["start_s"].map(
        dict(zip(result.per_seed["start_s"], result.per_seed["outage"]))).astype(int))
    atomic_write_csv(paths["series"], series, float_format="%.4f")
    if result.gnss_errors is not None:
        paths["gnss"] = out / "tables" / f"{stem}_gnss.csv"
        atomic_write_csv(paths["gnss"], result.gnss_errors, float_format="%.4f")
    return paths


def error_series(runs, rate_hz: float = 10.0) -> pd.DataFrame:
    """East/north/horizontal error against time since the outage start, decimated to ``rate_hz``.

    Returns
    -------
    DataFrame
        ``start_s``, ``method``, ``seed``, ``t_rel`` (s), ``east_m``, ``north_m``, ``h_m``.
    """
    parts = []
    for r in runs:
        e = r.errors
        t = e["t_rel"].to_numpy(float)
        keep = (np.abs(t * rate_hz - np.round(t * rate_hz)) < 1e-3) | (np.arange(len(t)) == len(t) - 1)
        keep &= t >= -1e-6
        parts.append(pd.DataFrame({"start_s": r.start, "method": r.method,
                                   "seed": pd.array([r.seed] * int(keep.sum()), dtype="Int64"),
                                   "t_rel": np.round(t[keep], 6), "east_m": e["east"].to_numpy()[keep],
                                   "north_m": e["north"].to_numpy()[keep],
                                   "h_m": e["horizontal"].to_numpy()[keep]}))
    return pd.concat(parts, ignore_index=True)


def representative_seeds(per_seed: pd.DataFrame) -> dict:
    """``{(outage, method): seed}``: the seed whose max horizontal error is the (lower) median."""
    out = {}
    for (o, m), g in per_seed.groupby(["outage", "method"]):
        g = g.sort_values(["max_h_m", "seed"])
        out[(int(o), m)] = g["seed"].iloc[(len(g) - 1) // 2]
    return out


def paper_values(test: str) -> pd.DataFrame:
    """The paper's published max errors of ``test`` (``data/paper/outage_max_errors.csv``): columns
    ``outage``, ``method``, ``max_east_m``, ``max_north_m``. For display beside ours only."""
    from bgfn.config import DATA_DIR

    p = pd.read_csv(DATA_DIR / "paper" / "outage_max_errors.csv")
    return p[p["test"] == test].drop(columns="test").reset_index(drop=True)


def paper_claims() -> dict:
    """``data/paper/claims.yaml`` (percentages the paper states in its text)."""
    import yaml

    from bgfn.config import DATA_DIR

    return yaml.safe_load((DATA_DIR / "paper" / "claims.yaml").read_text(encoding="utf-8"))


def paper_layout(table: pd.DataFrame, paper: pd.DataFrame | None = None) -> pd.DataFrame:
    """Max east/north errors in the paper's layout: rows ``Outage k`` (ours, then the paper's), columns
    (method, East/North), m."""
    methods = [m for m in TABLE_METHODS if m in set(table["method"])]
    cols = pd.MultiIndex.from_product([methods, ["East", "North"]])
    rows, index = [], []
    for o in sorted(table["outage"].unique()):
        for src, df in (("ours", table), ("paper", paper)):
            if df is None:
                continue
            sub = df[df["outage"] == o].set_index("method")
            rows.append([sub.loc[m, c] if m in sub.index else np.nan
                         for m in methods for c in ("max_east_m", "max_north_m")])
            index.append((f"Outage {o}", src))
    return pd.DataFrame(rows, index=pd.MultiIndex.from_tuples(index), columns=cols)


def error_reduction(table: pd.DataFrame, reference: str = "INS") -> pd.DataFrame:
    """Reduction of the max east/north errors against ``reference``: ``100 (ref - method) / ref`` (%).

    Returns
    -------
    DataFrame
        ``outage``, ``method``, ``east_pct``, ``north_pct``.
    """
    rows = []
    for o, g in table.groupby("outage"):
        ref = g[g["method"] == reference]
        if ref.empty:
            continue
        re_, rn = float(ref["max_east_m"].iloc[0]), float(ref["max_north_m"].iloc[0])
        for _, r in g.iterrows():
            if r["method"] in (reference,):
                continue
            rows.append({"outage": int(o), "method": r["method"], "east_pct": 100.0 * (re_ - r["max_east_m"]) / re_,
                         "north_pct": 100.0 * (rn - r["max_north_m"]) / rn})
    return pd.DataFrame(rows, columns=["outage", "method", "east_pct", "north_pct"])


def describe_tables(results) -> list[str]:
    """Plain-language lines on the outage tables (what beats what), computed from the numbers."""
    lines = []
    for r in results:
        red = error_reduction(r.table).set_index(["outage", "method"])
        for o, g in r.table.groupby("outage"):
            g = g.set_index("method")
            score = (g["max_east_m"] + g["max_north_m"]) / 2.0
            learned = [m for m in ("MLP", "AT-LSTM", "BGFN", "Transformer") if m in g.index]
            best = min(learned, key=lambda m: score[m]) if learned else None
            txt = (f"{r.dataset} ({r.test} test), outage {o}: max east/north error INS "
                   f"{g.loc['INS', 'max_east_m']:.1f}/{g.loc['INS', 'max_north_m']:.1f} m, GPS "
                   f"{g.loc['GPS', 'max_east_m']:.1f}/{g.loc['GPS', 'max_north_m']:.1f} m")
            if "BGFN" in g.index:
                e, n = red.loc[(o, "BGFN"), "east_pct"], red.loc[(o, "BGFN"), "north_pct"]
                txt += (f"; BGFN {g.loc['BGFN', 'max_east_m']:.1f}/{g.loc['BGFN', 'max_north_m']:.1f} m "
                        f"({e:+.0f} % / {n:+.0f} % reduction against INS)")
                beats = [m for m in ["INS"] + learned if m != "BGFN" and score["BGFN"] < score[m]]
                loses = [m for m in ["INS"] + learned if m != "BGFN" and score["BGFN"] >= score[m]]
                txt += (f"; on the mean of the two max errors BGFN beats {', '.join(beats) or 'none'} and does "
                        f"not beat {', '.join(loses) or 'any'}")
            if best is not None:
                txt += f"; best network: {best}"
            below = [f"{m} {c.replace('_m', '').replace('_', ' ')} {g.loc[m, c]:.1f} < GPS {g.loc['GPS', c]:.1f} m"
                     for c in METRIC_COLUMNS for m in g.index if m != "GPS" and g.loc[m, c] < g.loc["GPS", c]]
            if below:   # the GPS row follows the GNSS fixes, whose own error against the reference can exceed a drift
                txt += ("; the GPS row is not the lower bound in every cell (" + "; ".join(below)
                        + "): the GPS-aided solution follows the GNSS fixes' own error against the reference")
                fixes = r.gnss_errors.set_index("outage") if r.gnss_errors is not None else pd.DataFrame()
                if o in fixes.index and fixes.loc[o, "n_fixes"] > 0:
                    txt += (f", and the fixes in this window are off by up to {fixes.loc[o, 'max_east_m']:.1f} m "
                            f"east and {fixes.loc[o, 'max_north_m']:.1f} m north")
            lines.append(txt + ".")
    return lines


def describe_sweep(summary: pd.DataFrame, pairs: pd.DataFrame, method: str = "BGFN") -> list[str]:
    """Plain-language lines on the sweep: medians with intervals and the paired comparisons."""
    lines = []
    for (ds, du), g in summary.groupby(["dataset", "duration_s"]):
        g = g.set_index("method")
        med = ", ".join(f"{m} {g.loc[m, 'median_m']:.1f} [{g.loc[m, 'ci_lo_m']:.1f}, {g.loc[m, 'ci_hi_m']:.1f}]"
                        for m in TABLE_METHODS if m in g.index)
        pp = pairs[(pairs["dataset"] == ds) & (pairs["duration_s"] == du)].set_index("baseline")
        cmp_ = "; ".join(f"vs {b}: wins {int(pp.loc[b, 'wins'])}/{int(pp.loc[b, 'n'])} "
                         f"(p = {pp.loc[b, 'p_value']:.2g}, by start {pp.loc[b, 'p_value_by_start']:.2g})"
                         for b in pp.index)
        lines.append(f"{ds}, {du:g} s outages: median max horizontal error (m) [95 % interval]: {med}. "
                     f"{method} {cmp_}.")
    return lines


# ----------------------------------------------------------------------------------------------- figures
def _ned_from_start(traj: pd.DataFrame, ref0) -> np.ndarray:
    from bgfn.nav import earth

    return earth.lla_to_ned(traj["lat"].to_numpy(), traj["lon"].to_numpy(), traj["h"].to_numpy(),
                            float(ref0["lat"]), float(ref0["lon"]), float(ref0["h"]))


def plot_outage(result: TableResult, outage: int, reference: pd.DataFrame, methods=FIGURE_METHODS,
                title: str = ""):
    """Paper Figs. 6-7, 9-10: east and north position error against time, plus a map of the outage segment.

    The learned methods show their representative seed (:func:`representative_seeds`).

    Returns
    -------
    matplotlib.figure.Figure
    """
    import matplotlib.pyplot as plt

    rep = representative_seeds(result.per_seed)
    start = float(result.per_seed.loc[result.per_seed["outage"] == outage, "start_s"].iloc[0])
    fig = plt.figure(figsize=(12, 4.2))
    gs = fig.add_gridspec(1, 3, width_ratios=[1, 1, 1])
    ax_e, ax_n, ax_m = fig.add_subplot(gs[0]), fig.add_subplot(gs[1]), fig.add_subplot(gs[2])
    runs = {(r.method, r.seed): r for r in result.runs if abs(r.start - start) < 1e-6}
    t_ref = reference["time"].to_numpy(float)
    i0 = int(np.argmin(np.abs(t_ref - start)))
    dur = next(iter(runs.values())).duration
    seg = reference[(t_ref >= start - 1e-6) & (t_ref <= start + dur + 1e-6)]
    ned_ref = _ned_from_start(seg, reference.iloc[i0])
    ax_m.plot(ned_ref[:, 1], ned_ref[:, 0], color="0.5", lw=3, alpha=0.5, label="reference")
    for m in methods:
        seed = rep.get((outage, m))
        r = runs.get((m, seed if m not in ("INS", "GPS") else None))
        if r is None:
            continue
        e = r.errors
        lab = m if r.seed is None else f"{m} (seed {r.seed})"
        ax_e.plot(e["t_rel"], e["east"], color=COLORS[m], lw=1.2, label=lab)
        ax_n.plot(e["t_rel"], e["north"], color=COLORS[m], lw=1.2, label=lab)
        ned = _ned_from_start(r.trajectory, reference.iloc[i0])
        ax_m.plot(ned[:, 1], ned[:, 0], color=COLORS[m], lw=1.0, label=m)
    for ax, lab in ((ax_e, "(a) east position error (m)"), (ax_n, "(b) north position error (m)")):
        ax.axhline(0.0, color="0.7", lw=0.6)
        ax.set_xlabel("time since outage start (s)")
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
    ax_e.legend(fontsize=8, loc="best")
    ax_m.plot(ned_ref[0, 1], ned_ref[0, 0], "o", color="0.3", ms=5)
    ax_m.set_xlabel("east (m)")
    ax_m.set_ylabel("north (m)")
    ax_m.set_title("(c) outage segment", fontsize=10)
    ax_m.set_aspect("equal", adjustable="datalim")
    ax_m.grid(alpha=0.3)
    ax_m.legend(fontsize=7, loc="best")
    if title:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return fig


def plot_sweep_boxes(sweep: pd.DataFrame, dataset: str, methods=TABLE_METHODS):
    """Box plots of the max horizontal error per duration and method (log scale)."""
    import matplotlib.pyplot as plt

    d = sweep[sweep["dataset"] == dataset]
    durations = sorted(d["duration_s"].unique())
    methods = [m for m in methods if m in set(d["method"])]
    fig, ax = plt.subplots(figsize=(max(6.0, 1.6 * len(durations) * len(methods) / 3), 4.5))
    width = 0.8 / len(methods)
    for j, m in enumerate(methods):
        data = [d[(d["duration_s"] == du) & (d["method"] == m)]["max_h_m"].to_numpy() for du in durations]
        pos = np.arange(len(durations)) + (j - (len(methods) - 1) / 2) * width
        bp = ax.boxplot(data, positions=pos, widths=width * 0.9, patch_artist=True, showfliers=True,
                        flierprops={"markersize": 2})
        for b in bp["boxes"]:
            b.set_facecolor(COLORS.get(m, "0.5"))
            b.set_alpha(0.6)
        for med in bp["medians"]:
            med.set_color("white" if m in ("AT-LSTM", "BGFN") else "black")
        ax.plot([], [], "s", color=COLORS.get(m, "0.5"), alpha=0.6, label=m)
    ax.set_xticks(np.arange(len(durations)))
    ax.set_xticklabels([f"{du:g} s" for du in durations])
    ax.set_yscale("log")
    ax.set_xlabel("outage duration")
    ax.set_ylabel("max horizontal error (m)")
    ax.set_title(f"{dataset}: outage sweep")
    ax.grid(alpha=0.3, axis="y")
    ax.legend(fontsize=8, ncol=3)
    fig.tight_layout()
    return fig


# ----------------------------------------------------------------------------------------------- sweep
def sweep_plan(drive, sweep: dict, window_samples: int = 200) -> pd.DataFrame:
    """Outage starts spread evenly over the drive and their folds (contiguous blocks of starts).

    The first start leaves ``warmup_s`` after the first epoch (filter convergence; at least the input window),
    the last one room for the longest duration.

    Returns
    -------
    DataFrame
        ``start_s`` (rounded to 0.1 s), ``fold`` (0 .. folds-1).
    """
    t = drive.imu["time"].to_numpy(float)
    rate = 1.0 / float(np.median(np.diff(t)))
    t0 = float(drive.reference["time"].iloc[0])
    lo = t0 + max(float(sweep["warmup_s"]), (window_samples + 1) / rate)
    hi = float(t[-1]) - max(sweep["durations_s"]) - 1.0 / rate
    n = int(sweep["n_starts"])
    if hi < lo:
        raise DataError(drive.name, "time", f"room for {n} outages of {max(sweep['durations_s'])} s after a "
                        f"{sweep['warmup_s']} s warm-up", f"{t[-1] - t0:.0f} s of data")
    starts = np.round(np.linspace(lo, hi, n) if n > 1 else np.array([0.5 * (lo + hi)]), 1)
    folds = np.concatenate([np.full(len(b), k) for k, b in enumerate(np.array_split(np.arange(n),
                                                                                     int(sweep["folds"])))])
    return pd.DataFrame({"start_s": starts, "fold": folds.astype(int)})


def sweep_train_config(train_section: dict, sweep: dict) -> dict:
    """The ``train:`` section with the sweep's overrides (``sweep.train``; ``optimizer`` merged key by key)."""
    tc = copy.deepcopy(train_section or {})
    for key, value in (sweep.get("train") or {}).items():
        if key == "optimizer" and isinstance(value, dict):
            tc["optimizer"] = {**(tc.get("optimizer") or {}), **value}
        else:
            tc[key] = copy.deepcopy(value)
    return tc


def run_sweep(cfg: dict, profile: str, dataset: str, drive=None, ecfg: dict | None = None,
              progress: bool = True) -> tuple[pd.DataFrame, dict]:
    """The outage sweep of one dataset (module docstring).

    Returns
    -------
    rows : DataFrame
        ``SWEEP_COLUMNS``; INS and GPS do not depend on a network and are repeated for every seed so that
        every (start, seed) pair has every method.
    info : dict
        Sizes, training and evaluation wall times, fold windows.
    """
    import time

    from tqdm import tqdm

    from bgfn import train
    from bgfn.learning import build_learning_data, learning_options

    ecfg = ecfg or evaluate_config(cfg.get("evaluate"), cfg.get("train"))
    sw = ecfg["sweep"]
    if drive is None:
        from bgfn.data import load_drive

        drive = load_drive(dataset, profile=profile)
    # the sweep's budget, with the learning rates notebook 03 selected for this dataset (same for every fold)
    tc = sweep_train_config(train.tuned_train_config(cfg, profile, dataset), sw)
    opts = learning_options(tc)
    plan = sweep_plan(drive, sw, int(opts["window"]))
    durations = sorted(float(d) for d in sw["durations_s"])
    dmax = durations[-1]
    seeds = [int(s) for s in sw["seeds"]]
    methods = list(ecfg["methods"])
    t0 = time.perf_counter()
    ctx = navigation_context(drive, cfg.get("nav"), plan["start_s"])
    rows = []

    def add(run, fold):
        for du in durations:
            mtr = window_metrics(run.errors, run.start, du)
            for seed in ([run.seed] if run.seed is not None else seeds):
                rows.append({"dataset": dataset, "start_s": run.start, "duration_s": du, "method": run.method,
                             "seed": int(seed), "fold": int(fold), **{k: mtr[k] for k in SWEEP_COLUMNS[6:]}})

    fold_of = dict(zip(plan["start_s"], plan["fold"]))
    windows_all = [(s, dmax) for s in plan["start_s"]]
    for r in run_outages(ctx, windows_all, None, "INS", None, ecfg["pseudo_gps"]):
        add(r, fold_of[r.start])
    for s in plan["start_s"]:
        add(gps_run(ctx, s, dmax), fold_of[s])
    t_nav = time.perf_counter() - t0
    attitude = ctx.attitude_table()
    t_train = t_eval = 0.0
    jobs = [(k, m, s) for k in sorted(plan["fold"].unique()) for m in methods for s in seeds]
    data_cache: dict = {}
    cards = []
    for k, method, seed in tqdm(jobs, desc=f"sweep {dataset}", disable=not progress):
        fw = [(s, dmax) for s in plan.loc[plan["fold"] == k, "start_s"]]
        if k not in data_cache:
            data_cache = {k: build_learning_data(drive.imu, attitude, drive.gnss, fw, **opts)}
        path = model_path(profile, dataset, method, seed, fold=int(k))
        ta = time.perf_counter()
        card = train.train_model(method, data_cache[k], train.size_config(tc, method), tc, seed=seed,
                                 out_dir=path.parent, progress=False,
                                 extra_card={"dataset": dataset, "profile": profile, "fold": int(k),
                                             "fold_outages": fw, "size": tc.get("size")})
        cards.append(card)
        model = load_model(path)
        tb = time.perf_counter()
        for r in run_outages(ctx, fw, model, METHOD_LABELS[method], seed, ecfg["pseudo_gps"]):
            add(r, k)
        tc_ = time.perf_counter()
        t_train += tb - ta
        t_eval += tc_ - tb
    df = pd.DataFrame(rows, columns=list(SWEEP_COLUMNS))
    info = {"dataset": dataset, "n_starts": len(plan), "folds": int(plan["fold"].nunique()), "seeds": seeds,
            "durations_s": durations, "methods": [METHOD_LABELS[m] for m in methods],
            "window": int(opts["window"]), "size": tc.get("size"), "optimizer": train.optimizer_options(tc),
            "lr": {METHOD_LABELS[m]: train.method_lr(tc, m) for m in methods},
            "fold_starts": {int(k): plan.loc[plan["fold"] == k, "start_s"].tolist() for k in plan["fold"].unique()},
            "train_wall_s": t_train, "eval_wall_s": t_eval + t_nav,
            "train_epochs_run": {f"{c['method']}_fold{c.get('fold')}_seed{c['seed']}": c["epochs_run"] for c in cards},
            "fold_val_rmse_m": {f"{c['method']}_fold{c.get('fold')}_seed{c['seed']}": c["val_rmse_m"] for c in cards}}
    return df, info


def sweep_summary(sweep: pd.DataFrame, n_boot: int = 2000, level: float = 0.95, seed: int = 0,
                  metric: str = "max_h_m") -> pd.DataFrame:
    """Median of ``metric`` per dataset, duration and method with a cluster-bootstrap interval (by start).

    Returns
    -------
    DataFrame
        ``dataset``, ``duration_s``, ``method``, ``n`` (runs), ``n_starts``, ``median_m``, ``ci_lo_m``, ``ci_hi_m``.
    """
    from bgfn.stats import bootstrap_ci

    rows = []
    order = {m: i for i, m in enumerate(TABLE_METHODS)}
    for (ds, du, m), g in sweep.groupby(["dataset", "duration_s", "method"]):
        if m in ("INS", "GPS"):          # one value per start (repeated per seed)
            g = g.drop_duplicates("start_s")
        lo, hi = bootstrap_ci(g[metric], n_boot=n_boot, level=level, seed=seed, groups=g["start_s"])
        rows.append({"dataset": ds, "duration_s": du, "method": m, "n": len(g), "n_starts": g["start_s"].nunique(),
                     "median_m": float(np.median(g[metric])), "ci_lo_m": lo, "ci_hi_m": hi})
    out = pd.DataFrame(rows)
    return out.sort_values(["dataset", "duration_s", "method"], key=lambda s: s.map(order) if s.name == "method"
                           else s).reset_index(drop=True)


def sweep_comparisons(sweep: pd.DataFrame, method: str = "BGFN", metric: str = "max_h_m") -> pd.DataFrame:
    """How often ``method`` beats each other method, paired by (start, seed), with the Wilcoxon test.

    ``p_value``: Wilcoxon signed-rank on the (start, seed) pairs; ``p_value_by_start``: on the per-start
    medians over seeds (pairs from the same start are not independent: the more conservative number).

    Returns
    -------
    DataFrame
        ``dataset``, ``duration_s``, ``baseline``, ``n``, ``wins``, ``ties``, ``win_rate``, ``median_diff_m``
        (method - baseline), ``median_ratio``, ``p_value``, ``n_starts``, ``p_value_by_start``.
    """
    from bgfn.stats import paired_comparison, wilcoxon_p

    rows = []
    for (ds, du), g in sweep.groupby(["dataset", "duration_s"]):
        piv = g.pivot_table(index=["start_s", "seed"], columns="method", values=metric, aggfunc="first")
        if method not in piv.columns:
            continue
        for base in [m for m in TABLE_METHODS if m in piv.columns and m != method]:
            pc = paired_comparison(piv[method].to_numpy(), piv[base].to_numpy())
            by_start = (piv[method] - piv[base]).groupby(level="start_s").median()
            rows.append({"dataset": ds, "duration_s": du, "baseline": base, "n": pc["n"], "wins": pc["wins"],
                         "ties": pc["ties"], "win_rate": pc["win_rate"], "median_diff_m": pc["median_diff"],
                         "median_ratio": pc["median_ratio"], "p_value": pc["p_value"],
                         "n_starts": int(by_start.notna().sum()), "p_value_by_start": wilcoxon_p(by_start)})
    return pd.DataFrame(rows)


__all__ = [
    "COLORS", "EVALUATE_DEFAULTS", "METHOD_LABELS", "METRIC_COLUMNS", "NavContext", "OutageRun", "PAPER_TESTS",
    "SWEEP_COLUMNS", "TABLE_COLUMNS", "TABLE_FILES", "TABLE_METHODS", "TableResult", "aggregate_seeds",
    "choose_datasets", "describe_sweep", "describe_tables", "ensure_models", "error_reduction", "error_series",
    "evaluate_config", "evaluate_dataset", "fix_error_table", "gps_run", "load_model", "model_path", "navigation_context",
    "paper_claims", "paper_layout", "paper_values", "plot_outage", "plot_sweep_boxes", "pseudo_gps_positions",
    "representative_seeds", "run_outages", "run_sweep", "save_table_result", "sweep_comparisons", "sweep_plan",
    "sweep_summary", "sweep_train_config", "table_file", "window_metrics",
]

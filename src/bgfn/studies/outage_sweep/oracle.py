"""Oracle rows (beyond the paper): how accurate must the increments be for the pseudo-GPS to help?

A stand-in network, :class:`OracleIncrements`, returns the *true* ``delta_p_gps`` of every GNSS interval plus white
noise of std ``sigma`` per increment and axis, and runs through :func:`bgfn.evaluate.run_outages` like a trained
network (Eq. pred-gps: after ``k`` summed increments the pseudo fix is off by ``sigma sqrt(k)`` per axis). It runs in
the paper's outages and the sweep's starts for the grid ``evaluate.oracle.sigmas_m``, beside the standalone INS:
``outage_oracle.csv`` (:data:`ORACLE_COLUMNS`: medians with bootstrap intervals clustered by start) and
``outage_oracle_breakeven.csv`` (:data:`BREAKEVEN_COLUMNS`: the sigma where the oracle curve crosses a learning-free
baseline, :func:`crossing_sigma`, beside each network's own increment error and its *equivalent sigma*, larger
than its RMSE when its errors are correlated). The noise is one draw per (dataset, seed) on the drive's grid of
GNSS intervals, scaled by every sigma (common random numbers, :func:`oracle_noise`).
"""

from __future__ import annotations

import time
import zlib
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from bgfn.config import SHARED_TABLES
from bgfn.data import dataset_id, load_drive
from bgfn.data.platforms import write_ran_table
from bgfn.errors import DataError
from bgfn.evaluate.setup import COLORS
from bgfn.evaluate.hybrid import navigation_context, run_outages, window_metrics
from bgfn.studies.outage_sweep.increments import AntennaTruth, increment_rmse
from bgfn.studies.outage_sweep.sweep import profile_sweep_plan
from bgfn.io import save_figure
from bgfn.nav.outages import outage_windows
from bgfn.paper import METHOD_LABELS, test_of
from bgfn.parallel import Runner
from bgfn.stats import bootstrap_ci

#: Method label of the oracle runs.
ORACLE_METHOD = "oracle"
#: ``outage`` value of the sweep's starts (the paper's outages are ``"1"``, ``"2"``, ...).
SWEEP_OUTAGE = "sweep"
#: Columns of the per-run rows (``outage_oracle_runs.csv``); ``sigma_m`` and ``seed`` empty for INS and sigma = 0.
RUN_COLUMNS: tuple[str, ...] = ("dataset", "test", "outage", "start_s", "duration_s", "method", "sigma_m", "seed",
                                "max_h_m", "rmse_h_m", "final_h_m", "increment_rmse_m")
#: Columns of ``outage_oracle.csv``; ``increment_s``: the length of one increment (the GNSS interval), s.
ORACLE_COLUMNS: tuple[str, ...] = ("dataset", "test", "outage", "duration_s", "method", "sigma_m", "increment_s",
                                   "n", "n_starts", "median_m", "ci_lo_m", "ci_hi_m")
#: Columns of the other methods' levels in the same windows (from the sweep and the tables).
LEVEL_COLUMNS: tuple[str, ...] = ("dataset", "outage", "duration_s", "method", "n", "median_m", "increment_rmse_m")
#: Columns of ``outage_oracle_breakeven.csv``.
BREAKEVEN_COLUMNS: tuple[str, ...] = (
    "dataset", "test", "outage", "duration_s", "increment_s", "baseline", "baseline_m", "breakeven_sigma_m",
    "crossing", "method", "method_m", "increment_rmse_m", "rmse_to_breakeven", "oracle_at_rmse_m",
    "equivalent_sigma_m", "equivalent_crossing")
#: :func:`crossing_sigma` outcomes: the curve crosses the level inside the grid; it is above the level already at
#: the smallest sigma; it stays below the level over the whole grid.
CROSSED, NEVER_BELOW, BEYOND_GRID = "crossed", "never_below", "beyond_grid"
#: Figure of one dataset (its short name, :func:`bgfn.data.names.dataset_id`), ``results/<profile>/figures/``.
FIGURE_FILE = "outage_oracle_{dataset}.png"


# ----------------------------------------------------------------------------------------------- the stand-in
def oracle_noise(dataset: str, seed: int, n_intervals: int) -> np.ndarray:
    """Standard normal draws [n_intervals, 2] (north, east) of one noise seed, one row per GNSS interval of the
    drive; the dataset's name enters the seed so that two drives never share a draw."""
    ss = np.random.SeedSequence([int(seed), zlib.crc32(dataset.encode("utf-8"))])
    return np.random.default_rng(ss).standard_normal((int(n_intervals), 2))


class OracleIncrements:
    """Predictor of :func:`bgfn.evaluate.run_outages`: the true ``delta_p_gps`` plus ``sigma`` times white noise.

    Parameters
    ----------
    truth : AntennaTruth
    interval_s : float
        Length of one increment (the drive's GNSS interval), s.
    sigma : float
        Noise std per increment and horizontal axis, m.
    noise : ndarray [G, 2]
        :func:`oracle_noise`: the draw of GNSS interval ``g`` is row ``g`` (counted from ``t0``).
    t0 : float
        Time of the drive's first epoch, s.

    Notes
    -----
    ``val_rmse_m`` is the RMSE of one 2-D increment, ``sigma sqrt(2)``, what a network's validation RMSE is, so
    that ``pseudo_gps.std_m: validation`` trusts the oracle as it trusts a network of that accuracy.
    """

    def __init__(self, truth: AntennaTruth, interval_s: float, sigma: float, noise: np.ndarray, t0: float):
        if not (np.isfinite(sigma) and sigma >= 0):
            raise DataError("evaluate.oracle", "sigmas_m", "noise std >= 0, m", repr(sigma))
        self.truth, self.interval_s, self.sigma, self.noise, self.t0 = truth, float(interval_s), float(sigma), noise, t0
        self.options = {"window": 1}            # the truth needs no input window; run_outages reads it
        self.val_rmse_m = self.sigma * np.sqrt(2.0)

    def predict_windows(self, ws) -> np.ndarray:
        """(dN, dE) [M, 2], m, of the intervals ``[ws.t_from, ws.t_to]``."""
        g = np.rint((np.asarray(ws.t_to, float) - self.t0) / self.interval_s).astype(int)
        if g.size and (g.min() < 0 or g.max() >= len(self.noise)):
            raise DataError("evaluate.oracle", "t_to", "interval ends inside the drive", f"interval {g.max()}")
        return self.truth.increments(ws.t_from, ws.t_to) + self.sigma * self.noise[g]


# ----------------------------------------------------------------------------------------------- runs
@dataclass(frozen=True)
class NoSweepStarts:
    """A drive that the sweep's plan gives no starts (:func:`oracle_windows`): its oracle rows are of the paper's
    outages only; ``expected`` and ``found``: the plan's refusal (the :class:`bgfn.errors.DataError`'s)."""

    dataset: str
    expected: str
    found: str


def oracle_windows(cfg: dict, drive, ecfg: dict, windows) -> tuple[list[tuple[str, float, float]],
                                                                   NoSweepStarts | None]:
    """The windows of one drive: the paper's outages, then the sweep's starts (its plan for this drive).

    Returns
    -------
    windows : list of (outage, start, duration)
        ``outage`` ``"1"``, ``"2"``, ... or :data:`SWEEP_OUTAGE`; the sweep's starts with the longest oracle
        duration (the shorter ones are prefixes, as in the sweep).
    no_starts : NoSweepStarts or None
        Why the drive has no sweep starts (None: it has them, or the oracle runs no duration).
    """
    out = [(str(k + 1), float(s), float(d)) for k, (s, d) in enumerate(windows)]
    sw, durations = ecfg["sweep"], ecfg["oracle"]["durations_s"]
    if not durations:
        return out, None
    if max(durations) > max(sw["durations_s"]):
        raise DataError("params evaluate.oracle", "durations_s", f"durations up to evaluate.sweep.durations_s's "
                        f"longest {max(sw['durations_s']):g} s (the sweep's starts leave room for no more)",
                        repr(durations))
    try:        # the sweep's own starts (a self-aligned filter starts late: none before it)
        plan = profile_sweep_plan(cfg, drive, sw)
    except DataError as exc:
        return out, NoSweepStarts(drive.name, str(exc.expected), str(exc.found))
    return out + [(SWEEP_OUTAGE, float(s), float(max(durations))) for s in plan["start_s"]], None


def oracle_runs(ctx, windows, oracle: dict, pseudo: dict | None = None,
                runner: Runner | None = None) -> pd.DataFrame:
    """INS and the oracle at every sigma and seed in ``windows`` of one drive.

    Parameters
    ----------
    ctx : bgfn.evaluate.NavContext
        From :func:`bgfn.evaluate.navigation_context` with every start of ``windows``.
    windows : list of (outage, start, duration)
        :func:`oracle_windows`.
    oracle : dict
        ``sigmas_m``, ``seeds``, ``durations_s`` (the ``evaluate.oracle`` section).
    pseudo : dict, optional
        ``evaluate.pseudo_gps``: the oracle's fixes are fused like a network's.
    runner : bgfn.parallel.Runner, optional
        Where the ``(sigma, seed)`` points run (default: one after the other).

    Returns
    -------
    DataFrame
        :data:`RUN_COLUMNS`, one row per run and duration (a sweep window gives one row per oracle duration).
    """
    name = ctx.drive.name
    test = test_of(name) or name
    truth = AntennaTruth.of(ctx)
    t = ctx.imu_time
    t0, interval = float(ctx.drive.reference["time"].iloc[0]), float(ctx.gnss_interval_s)
    n_intervals = int(np.ceil((t[-1] - t0) / interval)) + 2
    pairs = [(s, d) for _, s, d in windows]
    sigmas = sorted({float(x) for x in oracle["sigmas_m"]})
    rows = []

    def add(runs, sigma, seed):
        for (outage, _, d), r in zip(windows, runs):
            for du in (oracle["durations_s"] if outage == SWEEP_OUTAGE else [d]):
                m = window_metrics(r.errors, r.start, du)
                inc = increment_rmse(r, truth, interval, du) if len(r.increments) else float("nan")
                rows.append({"dataset": name, "test": test, "outage": outage, "start_s": r.start,
                             "duration_s": float(du), "method": r.method, "sigma_m": sigma, "seed": seed,
                             **{k: m[k] for k in ("max_h_m", "rmse_h_m", "final_h_m")}, "increment_rmse_m": inc})

    add(run_outages(ctx, pairs, None, "INS", None, pseudo), np.nan, np.nan)
    points = [(sigma, seed) for sigma in sigmas for seed in ([None] if sigma == 0.0 else
                                                               [int(s) for s in oracle["seeds"]])]
    tasks = [(ctx, pairs, OracleIncrements(truth, interval, sigma, oracle_noise(name, 0 if seed is None else seed,
                                                                                n_intervals), t0), seed, pseudo)
             for sigma, seed in points]
    done = (runner or Runner()).map(oracle_point, tasks, labels=[f"{name} sigma {sigma:g} m seed {seed}"
                                                                 for sigma, seed in points],
                                    desc=f"oracle {name}", bar=len(tasks) > 1)
    for (sigma, seed), runs in zip(points, done):
        add(runs, sigma, np.nan if seed is None else seed)
    return pd.DataFrame(rows, columns=list(RUN_COLUMNS))


def oracle_point(ctx, pairs, pred: OracleIncrements, seed: int | None, pseudo: dict | None) -> list:
    """The oracle's outage runs at one sigma and seed (an independent run of :func:`oracle_runs`)."""
    return run_outages(ctx, pairs, pred, ORACLE_METHOD, seed, pseudo)


# ----------------------------------------------------------------------------------------------- tables
def oracle_table(runs: pd.DataFrame, increment_s: dict, n_boot: int = 2000, level: float = 0.95,
                 seed: int = 0) -> pd.DataFrame:
    """Median max horizontal error per dataset, windows, duration, method and sigma, with its bootstrap interval.

    Over several starts (the sweep) whole starts are resampled, as :func:`bgfn.studies.outage_sweep.sweep.sweep_summary` does; in
    one outage the runs themselves (the noise seeds).

    Parameters
    ----------
    runs : DataFrame
        :data:`RUN_COLUMNS`.
    increment_s : dict
        ``{dataset: GNSS interval, s}``.

    Returns
    -------
    DataFrame
        :data:`ORACLE_COLUMNS`, INS first in each group, then sigma increasing.
    """
    rows = []
    keys = ["dataset", "test", "outage", "duration_s", "method", "sigma_m"]
    for k, g in runs.groupby(keys, dropna=False, sort=False):
        n_starts = int(g["start_s"].nunique())
        lo, hi = bootstrap_ci(g["max_h_m"], n_boot=n_boot, level=level, seed=seed,
                              groups=g["start_s"] if n_starts > 1 else None)
        rows.append({**dict(zip(keys, k)), "increment_s": float(increment_s.get(k[0], np.nan)), "n": len(g),
                     "n_starts": n_starts, "median_m": float(np.median(g["max_h_m"])), "ci_lo_m": lo, "ci_hi_m": hi})
    out = pd.DataFrame(rows, columns=list(ORACLE_COLUMNS))
    out["_ins"] = out["method"] != "INS"
    return (out.sort_values(["dataset", "outage", "duration_s", "_ins", "sigma_m"], kind="stable")
            .drop(columns="_ins").reset_index(drop=True))


def is_network(method: str) -> bool:
    """Whether a table label is a network's (``BGFN``, ``MLP``, ... and their ``+`` variants such as ``BGFN+NHC``)."""
    return str(method).split("+")[0] in set(METHOD_LABELS.values())


def method_levels(dataset: str, sweep: pd.DataFrame | None = None, result=None, truth: AntennaTruth | None = None,
                  interval_s: float | None = None, durations=()) -> pd.DataFrame:
    """Every other method's median max horizontal error and increment error in the oracle's windows.

    Parameters
    ----------
    dataset : str
    sweep : DataFrame, optional
        The sweep's rows (``SWEEP_COLUMNS``): medians over (start, seed) per duration in ``durations``.
    result : bgfn.evaluate.TableResult, optional
        The paper's outages: medians over the seeds per outage; the increment errors from its runs (with
        ``truth`` and ``interval_s``).

    Returns
    -------
    DataFrame
        :data:`LEVEL_COLUMNS`; ``increment_rmse_m`` NaN for the learning-free rows and the GPS row.
    """
    rows = []
    if sweep is not None and len(sweep):
        d = sweep[(sweep["dataset"] == dataset) & sweep["duration_s"].isin([float(x) for x in durations])]
        for (du, m), g in d.groupby(["duration_s", "method"], sort=False):
            inc = g["increment_rmse_m"].to_numpy(float) if "increment_rmse_m" in g else np.array([np.nan])
            rows.append({"dataset": dataset, "outage": SWEEP_OUTAGE, "duration_s": float(du), "method": m,
                         "n": len(g), "median_m": float(np.median(g["max_h_m"])),
                         "increment_rmse_m": float(np.median(inc)) if np.isfinite(inc).all() else float("nan")})
    if result is not None:
        duration, inc = {}, {}
        for r in result.runs:
            duration[round(r.start, 3)] = r.duration
            if truth is not None and len(r.increments):
                inc.setdefault((round(r.start, 3), r.method), []).append(
                    increment_rmse(r, truth, interval_s, r.duration))
        for (o, m), g in result.per_seed.groupby(["outage", "method"], sort=False):
            start = round(float(g["start_s"].iloc[0]), 3)
            v = inc.get((start, m))
            rows.append({"dataset": dataset, "outage": str(int(o)), "duration_s": float(duration.get(start, np.nan)),
                         "method": m, "n": len(g), "median_m": float(np.median(g["max_h_m"])),
                         "increment_rmse_m": float(np.median(v)) if v else float("nan")})
    return pd.DataFrame(rows, columns=list(LEVEL_COLUMNS))


def crossing_sigma(sigmas, errors, level: float) -> tuple[float, str]:
    """Where the oracle curve ``errors(sigmas)`` first reaches ``level``, interpolated linearly between grid points.

    Parameters
    ----------
    sigmas : array_like [K]
        Noise std, m (sorted here).
    errors : array_like [K]
        Aided error at each sigma, m.
    level : float
        A baseline's error (the break-even) or a network's own error (its equivalent sigma), m.

    Returns
    -------
    sigma : float
        m; NaN unless ``status`` is :data:`CROSSED`.
    status : str
        :data:`CROSSED`; :data:`NEVER_BELOW` (the curve is at or above ``level`` already at the smallest sigma:
        no accuracy on the grid beats it); :data:`BEYOND_GRID` (below ``level`` over the whole grid).
    """
    s, e = np.asarray(sigmas, float), np.asarray(errors, float)
    order = np.argsort(s)
    s, e = s[order], e[order]
    if not (np.isfinite(level) and len(s)):
        return float("nan"), BEYOND_GRID if len(s) else NEVER_BELOW
    above = np.flatnonzero(e >= level)
    if not len(above):
        return float("nan"), BEYOND_GRID
    i = int(above[0])
    if i == 0:
        return float("nan"), NEVER_BELOW
    # linear between the last grid point below the level and the first at or above it
    frac = (level - e[i - 1]) / (e[i] - e[i - 1])
    return float(s[i - 1] + frac * (s[i] - s[i - 1])), CROSSED


def curve_at(sigmas, errors, sigma: float) -> float:
    """The oracle curve at ``sigma`` (m), linear between grid points; NaN outside the grid."""
    s, e = np.asarray(sigmas, float), np.asarray(errors, float)
    order = np.argsort(s)
    s, e = s[order], e[order]
    if not (len(s) and np.isfinite(sigma) and s[0] <= sigma <= s[-1]):
        return float("nan")
    return float(np.interp(sigma, s, e))


def breakeven_table(table: pd.DataFrame, levels: pd.DataFrame) -> pd.DataFrame:
    """Break-even sigma per dataset, windows, duration and baseline, and each network's distance from it.

    Baselines: the oracle's own INS row, and every learning-free row of ``levels`` other than INS (``INS+NHC``
    when it exists). Networks: the rows of ``levels`` that :func:`is_network`, with ``oracle_at_rmse_m`` (the
    oracle's error at the network's increment RMSE: what the network would reach were its errors white,
    :func:`curve_at`) and ``equivalent_sigma_m`` (the oracle noise that gives the network's own error).

    Returns
    -------
    DataFrame
        :data:`BREAKEVEN_COLUMNS`; one row per (baseline, network), or one row with an empty ``method`` when the
        windows have no network.
    """
    rows = []
    for (ds, test, o, du), g in table.groupby(["dataset", "test", "outage", "duration_s"], sort=False):
        curve = g[g["method"] == ORACLE_METHOD]
        ins = g[g["method"] == "INS"]
        if curve.empty:
            continue
        lv = levels[(levels["dataset"] == ds) & (levels["outage"] == o) & np.isclose(levels["duration_s"], du)]
        bases = ([("INS", float(ins["median_m"].iloc[0]))] if len(ins) else [])
        bases += [(m, float(v)) for m, v in zip(lv["method"], lv["median_m"])
                  if not is_network(m) and m not in ("INS", "GPS")]
        nets = lv[lv["method"].map(is_network).astype(bool)]
        sig, err = curve["sigma_m"].to_numpy(float), curve["median_m"].to_numpy(float)
        for base, base_m in bases:
            be, status = crossing_sigma(sig, err, base_m)
            common = {"dataset": ds, "test": test, "outage": o, "duration_s": float(du),
                      "increment_s": float(g["increment_s"].iloc[0]), "baseline": base, "baseline_m": base_m,
                      "breakeven_sigma_m": be, "crossing": status}
            if nets.empty:
                rows.append({**common, "method": None})
            for n in nets.itertuples(index=False):
                eq, eq_status = crossing_sigma(sig, err, n.median_m)
                rows.append({**common, "method": n.method, "method_m": n.median_m,
                             "increment_rmse_m": n.increment_rmse_m,
                             "rmse_to_breakeven": n.increment_rmse_m / be if be > 0 else float("nan"),
                             "oracle_at_rmse_m": curve_at(sig, err, n.increment_rmse_m),
                             "equivalent_sigma_m": eq, "equivalent_crossing": eq_status})
    return pd.DataFrame(rows, columns=list(BREAKEVEN_COLUMNS))


def oracle_interval_table(table: pd.DataFrame) -> pd.DataFrame:
    """:func:`oracle_table` as one text cell ``median [lo, hi]`` (m, one decimal) per (dataset, windows, duration)
    row and column ``INS`` or ``sigma <s> m``."""
    t = table.assign(col=[m if m != ORACLE_METHOD else f"sigma {s:g} m" for m, s in zip(table["method"],
                                                                                        table["sigma_m"])],
                     text=[f"{r.median_m:.1f} [{r.ci_lo_m:.1f}, {r.ci_hi_m:.1f}]" for r in table.itertuples()])
    cols = list(dict.fromkeys(t["col"]))
    wide = t.pivot_table(index=["dataset", "outage", "duration_s"], columns="col", values="text", aggfunc="first",
                         sort=False)
    return wide[[c for c in cols if c in wide.columns]]


# ----------------------------------------------------------------------------------------------- notebook 06
@dataclass
class OracleResult:
    """The oracle rows of every test (:func:`run_oracle`).

    Attributes
    ----------
    runs : DataFrame
        :data:`RUN_COLUMNS`.
    table : DataFrame
        :data:`ORACLE_COLUMNS` (``outage_oracle.csv``).
    levels : DataFrame
        :data:`LEVEL_COLUMNS`: the other methods in the same windows.
    breakeven : DataFrame
        :data:`BREAKEVEN_COLUMNS` (``outage_oracle_breakeven.csv``).
    figures : dict
        ``{dataset: matplotlib Figure}``.
    timings : dict
        ``{"oracle_<dataset>_s": wall time, s}``.
    no_sweep_starts : list of NoSweepStarts
        The drives whose oracle rows are of the paper's outages only, and why.
    """

    runs: pd.DataFrame
    table: pd.DataFrame
    levels: pd.DataFrame
    breakeven: pd.DataFrame
    figures: dict = field(default_factory=dict)
    timings: dict = field(default_factory=dict)
    no_sweep_starts: list[NoSweepStarts] = field(default_factory=list)


def plot_oracle(table: pd.DataFrame, levels: pd.DataFrame, breakeven: pd.DataFrame, dataset: str):
    """The oracle rows of one dataset (:mod:`bgfn.studies.outage_sweep.oracle`): aided error against the increment noise.

    One panel per windows and duration (the sweep's durations, then the paper's outages): the oracle's median max
    horizontal error with its interval against sigma (log axis; sigma = 0 at the left edge), the learning-free
    baselines as horizontal lines (INS, and INS+NHC or any other ``INS...`` row when present), the break-even
    sigma on each, and every network at (its increment RMSE per axis, its own aided error).

    Returns
    -------
    matplotlib.figure.Figure
    """

    d = table[table["dataset"] == dataset]
    groups = [k for k, _ in d.groupby(["outage", "duration_s"], sort=False)]
    groups.sort(key=lambda k: (k[0] != SWEEP_OUTAGE, k[0], k[1]))
    ncol = min(2, max(1, len(groups)))
    nrow = max(1, -(-len(groups) // ncol))
    fig, axes = plt.subplots(nrow, ncol, figsize=(5.2 * ncol, 4.2 * nrow), squeeze=False)
    for ax in axes.ravel()[len(groups):]:
        ax.set_visible(False)
    for ax, (o, du) in zip(axes.ravel(), groups):
        g = d[(d["outage"] == o) & (d["duration_s"] == du)]
        curve = g[g["method"] == ORACLE_METHOD].sort_values("sigma_m")
        lv = levels[(levels["dataset"] == dataset) & (levels["outage"] == o) & np.isclose(levels["duration_s"], du)]
        nets = lv[lv["method"].map(is_network).astype(bool)]
        sig = curve["sigma_m"].to_numpy(float)
        pos = np.concatenate([sig[sig > 0], nets["increment_rmse_m"].dropna().to_numpy(float)])
        zero_x = (pos.min() if len(pos) else 1.0) / 3.0           # where sigma = 0 is drawn (log axis)
        x = np.where(sig > 0, sig, zero_x)
        ax.fill_between(x, curve["ci_lo_m"], curve["ci_hi_m"], color="0.6", alpha=0.3, lw=0)
        ax.plot(x, curve["median_m"], "o-", color="0.2", ms=4, label="oracle (true increments + noise)")
        ins = g[g["method"] == "INS"]
        bases = ([("INS", float(ins["median_m"].iloc[0]))] if len(ins) else [])
        bases += [(m, float(v)) for m, v in zip(lv["method"], lv["median_m"])
                  if not is_network(m) and m not in ("INS", "GPS")]
        for k, (m, v) in enumerate(bases):
            ax.axhline(v, color=COLORS.get(m, f"C{k + 4}"), ls="-" if m == "INS" else "--", lw=1.2, label=m)
            be = breakeven[(breakeven["dataset"] == dataset) & (breakeven["outage"] == o)
                           & np.isclose(breakeven["duration_s"], du) & (breakeven["baseline"] == m)]
            if len(be) and be["crossing"].iloc[0] == CROSSED:
                s = float(be["breakeven_sigma_m"].iloc[0])
                ax.axvline(s, color=COLORS.get(m, f"C{k + 4}"), ls=":", lw=1.0)
                ax.plot([s], [v], "D", color=COLORS.get(m, f"C{k + 4}"), ms=6,
                        label=f"break-even vs {m}: {s:.2g} m")
        for n in nets.itertuples(index=False):
            if not np.isfinite(n.increment_rmse_m):
                continue
            c = COLORS.get(n.method, COLORS.get(n.method.split("+")[0], "0.4"))
            ax.plot([n.increment_rmse_m], [n.median_m], "^" if "+" in n.method else "o", color=c, ms=7,
                    mec="white", label=f"{n.method} (own increments)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ticks = [zero_x] + [s for s in sig if s > 0]
        ax.set_xticks(ticks)
        ax.set_xticklabels(["0"] + [f"{s:g}" for s in sig if s > 0], fontsize=8)
        ax.minorticks_off()
        ax.set_xlim(zero_x / 1.6, max(ticks + list(pos)) * 1.6)
        ax.set_xlabel("increment error per axis, sigma or network RMSE (m)")
        ax.set_ylabel("max horizontal error (m)")
        n_starts = int(curve["n_starts"].max()) if len(curve) else 0
        ax.set_title(f"{dataset}: " + (f"sweep, {du:g} s outages ({n_starts} starts)" if o == SWEEP_OUTAGE
                                       else f"outage {o} ({du:g} s)"), fontsize=9)
        ax.grid(alpha=0.3, which="both")
        ax.legend(fontsize=7, loc="upper left")
    fig.tight_layout()
    return fig


def run_oracle(cfg: dict, profile: str, setup, out=None, results: dict | None = None,
               sweep: pd.DataFrame | None = None, figures: bool = True,
               report: Callable[[str], None] | None = None, runner: Runner | None = None) -> OracleResult:
    """The oracle rows of every dataset of notebooks 04 and 06 (module docstring), their tables and figures.

    Parameters
    ----------
    cfg : dict
        The profile.
    profile : str
    setup : bgfn.evaluate.EvaluationSetup
        Its ``config`` (``oracle``, ``sweep``, ``pseudo_gps``), ``datasets``, ``sweep_datasets`` and ``windows``.
    out : path, optional
        ``results/<profile>``: the tables (``SHARED_TABLES`` ``oracle``, ``oracle_breakeven``, ``oracle_runs``)
        and one figure per dataset (:data:`FIGURE_FILE`) are written there.
    results : dict, optional
        ``{dataset: TableResult}`` of the paper's outages (drives reused; networks' levels and increment errors).
    sweep : DataFrame, optional
        The sweep's rows (networks' levels and increment errors in the sweep's windows).
    figures : bool
        Draw :func:`bgfn.studies.outage_sweep.oracle.plot_oracle` per dataset.
    report : callable, optional
        Called with a line per dataset when it is done.
    runner : bgfn.parallel.Runner, optional
        Where the grid points of each dataset run (:func:`oracle_runs`).
    """
    ecfg = setup.config
    oc, sw = ecfg["oracle"], ecfg["sweep"]
    results = results or {}
    names = list(dict.fromkeys(list(setup.datasets) + list(setup.sweep_datasets))) if oc["sigmas_m"] else []
    parts, levels, interval, timings, no_starts = [], [], {}, {}, []
    for name in names:
        t0 = time.perf_counter()
        res = results.get(name)
        drive = res.drive if res is not None and res.drive is not None else load_drive(name, profile=profile)
        if res is not None and res.windows:          # each drive its own outages (notebook 04's tables)
            own = res.windows
        else:
            own = outage_windows(cfg, drive, name) if cfg.get("outage_windows") else setup.windows
        wins, why = oracle_windows(cfg, drive, ecfg, own)
        no_starts += [why] if why is not None else []
        ctx = navigation_context(drive, cfg.get("nav"), [s for _, s, _ in wins])
        interval[name] = float(ctx.gnss_interval_s)
        runs = oracle_runs(ctx, wins, oc, ecfg["pseudo_gps"], runner)
        parts.append(runs)
        levels.append(method_levels(name, sweep, res, AntennaTruth.of(ctx), ctx.gnss_interval_s, oc["durations_s"]))
        timings[f"oracle_{name}_s"] = time.perf_counter() - t0
        if report is not None:
            report(f"{name}: {len(runs)} oracle rows ({len(wins)} windows x {len(oc['sigmas_m'])} sigmas, seeds "
                   f"{oc['seeds']}) in {timings[f'oracle_{name}_s']:.1f} s")
    runs = pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=list(RUN_COLUMNS))
    lv = pd.concat(levels, ignore_index=True) if levels else pd.DataFrame(columns=list(LEVEL_COLUMNS))
    table = oracle_table(runs, interval, int(sw["n_boot"]), float(sw["level"]), int(sw["boot_seed"]))
    be = breakeven_table(table, lv)
    result = OracleResult(runs, table, lv, be, timings=timings, no_sweep_starts=no_starts)
    if figures:
        result.figures = {name: plot_oracle(table, lv, be, name) for name in names}
    if out is not None:
        tables = Path(out) / "tables"
        write_ran_table(tables / SHARED_TABLES["oracle"], table, out, float_format="%.4f")
        write_ran_table(tables / SHARED_TABLES["oracle_breakeven"], be, out, float_format="%.4f")
        write_ran_table(tables / SHARED_TABLES["oracle_runs"], runs, out, float_format="%.4f")
        for name, fig in result.figures.items():
            save_figure(fig, Path(out) / "figures" / FIGURE_FILE.format(dataset=dataset_id(name)))   # no path in a name
    return result

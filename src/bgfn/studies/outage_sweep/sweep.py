"""Outage sweep (beyond the paper): many starts and durations, networks trained without the outages they are
tested on (k-fold), bootstrap intervals and paired tests, and the lines and tables notebook 06 shows of it."""

from __future__ import annotations

import copy
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from bgfn import train
from bgfn.data import load_drive
from bgfn.errors import DataError
from bgfn.evaluate.setup import SEEDLESS_METHODS, SWEEP_COLUMNS, TABLE_METHODS, evaluate_config
from bgfn.evaluate.hybrid import NavContext, gps_run, navigation_context, run_outages, window_metrics
from bgfn.studies.outage_sweep.increments import AntennaTruth, increment_rmse
from bgfn.evaluate.networks import load_model
from bgfn.learning import build_learning_data, learning_options
from bgfn.nav.baseline import filter_start
from bgfn.nav.outages import snap_windows
from bgfn.paper import METHOD_LABELS, NHC_SUFFIX, nhc_label
from bgfn.parallel import Runner
from bgfn.stats import bootstrap_ci, paired_comparison, wilcoxon_p
from bgfn.train.checkpoints import checkpoint_name, checkpoint_path


def sweep_plan(drive, sweep: dict, window_samples: int = 200, t_first: float | None = None) -> pd.DataFrame:
    """Outage starts spread evenly over the drive and their folds (contiguous blocks of starts).

    The first start leaves ``warmup_s`` after the first epoch (filter convergence; at least the input window),
    the last one room for the longest duration before the end of the IMU and of the reference. ``t_first``: the filter's start when it is later than the
    reference's first row (a self-aligned filter, :func:`bgfn.nav.baseline.filter_start`), s.

    Returns
    -------
    DataFrame
        ``start_s`` (rounded to 0.1 s, then onto the nearest IMU epoch), ``fold`` (0 .. folds-1).
    """
    t = drive.imu["time"].to_numpy(float)
    rate = 1.0 / float(np.median(np.diff(t)))
    t0 = float(drive.reference["time"].iloc[0]) if t_first is None else max(float(t_first),
                                                                           float(drive.reference["time"].iloc[0]))
    lo = t0 + max(float(sweep["warmup_s"]), (window_samples + 1) / rate)
    # the last outage ends inside both the IMU and the reference (the errors are scored against the
    # reference; a recorded drive's IMU may run on past it); floored to the 0.1 s grid of the starts
    end = min(float(t[-1]), float(drive.reference["time"].iloc[-1]))
    hi = np.floor((end - max(sweep["durations_s"]) - 1.0 / rate) * 10.0) / 10.0
    n = int(sweep["n_starts"])
    if hi < lo:
        raise DataError(drive.name, "time", f"room for {n} outages of {max(sweep['durations_s'])} s after a "
                        f"{sweep['warmup_s']} s warm-up", f"{t[-1] - t0:.0f} s of data")
    starts = np.round(np.linspace(lo, hi, n) if n > 1 else np.array([0.5 * (lo + hi)]), 1)
    # on the IMU epochs, as every outage window (a log stamped at .xx1 s; on a whole-hundredth grid: unchanged)
    starts = np.array([w.window[0] for w in snap_windows([(s, 1.0) for s in starts], t)])
    folds = np.concatenate([np.full(len(b), k) for k, b in enumerate(np.array_split(np.arange(n),
                                                                                     int(sweep["folds"])))])
    return pd.DataFrame({"start_s": starts, "fold": folds.astype(int)})


def profile_sweep_plan(cfg: dict, drive, sweep: dict) -> pd.DataFrame:
    """:func:`sweep_plan` of ``drive`` under a profile: the input window of the sweep's networks (``train:`` with
    ``sweep.train``'s overrides) and the filter's start (``nav:``; a self-aligned filter starts late)."""
    n_window = int(learning_options(sweep_train_config(cfg.get("train") or {}, sweep))["window"])
    return sweep_plan(drive, sweep, n_window, t_first=filter_start(drive, cfg.get("nav")))


def sweep_train_config(train_section: dict, sweep: dict) -> dict:
    """The ``train:`` section with the sweep's overrides (``sweep.train``; ``optimizer`` merged key by key)."""
    tc = copy.deepcopy(train_section or {})
    for key, value in (sweep.get("train") or {}).items():
        if key == "optimizer" and isinstance(value, dict):
            tc["optimizer"] = {**(tc.get("optimizer") or {}), **value}
        else:
            tc[key] = copy.deepcopy(value)
    return tc


@dataclass(frozen=True)
class SweepRun:
    """One network of the sweep, an independent run: trained without fold ``k``'s outages (``training``), then
    run in them (``windows``, ``(start, longest duration)``), alone and (``nhc``) with the vehicle constraints."""

    label: str
    ctx: NavContext
    fold: int
    windows: list
    training: train.TrainingRun
    method: str
    seed: int
    pseudo_gps: dict
    nhc: bool


def sweep_run(run: SweepRun) -> tuple[dict, list, float, float]:
    """Train one sweep network and run it in its fold's outages: ``(card, outage runs, training s, evaluation
    s)``; the runs of ``<METHOD>`` first, then ``<METHOD>+NHC``."""
    ta = time.perf_counter()
    card = train.train_run(run.training)
    model = load_model(Path(run.training.out_dir) / checkpoint_name(run.method, run.seed))
    tb = time.perf_counter()
    runs = list(run_outages(run.ctx, run.windows, model, METHOD_LABELS[run.method], run.seed, run.pseudo_gps))
    if run.nhc:
        runs += run_outages(run.ctx, run.windows, model, nhc_label(run.method), run.seed, run.pseudo_gps,
                            aids=[run.ctx.constraints])
    return card, runs, tb - ta, time.perf_counter() - tb


def _sweep_summary(result: tuple) -> str:
    """The progress line's part of a finished sweep run."""
    card, runs = result[0], result[1]
    return f"{train.run_summary(card)}, {len(runs)} outage runs"


class _Sweep:
    """One dataset's sweep while it runs: its plan, the learning-free rows (computed at once) and the networks'
    runs (:class:`SweepRun`, handed to a runner), then its rows and info (:meth:`finish`)."""

    def __init__(self, cfg: dict, profile: str, dataset: str, drive, ecfg: dict):
        self.dataset, self.sw = dataset, ecfg["sweep"]
        if drive is None:
            drive = load_drive(dataset, profile=profile)
        # the sweep's budget, with the learning rates notebook 03 selected for this dataset (same for every fold)
        self.tc = tc = sweep_train_config(train.tuned_train_config(cfg, profile, dataset), self.sw)
        self.opts = opts = learning_options(tc)
        self.plan = plan = sweep_plan(drive, self.sw, int(opts["window"]), t_first=filter_start(drive, cfg.get("nav")))
        self.durations = sorted(float(d) for d in self.sw["durations_s"])
        dmax = self.durations[-1]
        self.seeds = [int(s) for s in self.sw["seeds"]]
        self.methods = list(ecfg["methods"])
        t0 = time.perf_counter()
        self.ctx = ctx = navigation_context(drive, cfg.get("nav"), plan["start_s"])
        self.rows: list[dict] = []
        self.truth = AntennaTruth.of(ctx)
        self.fold_of = dict(zip(plan["start_s"], plan["fold"]))
        windows_all = [(s, dmax) for s in plan["start_s"]]
        self.aids = aids = ctx.constraints if ecfg["nhc_rows"] else None
        for r in run_outages(ctx, windows_all, None, "INS", None, ecfg["pseudo_gps"]):
            self.add(r, self.fold_of[r.start])
        if aids is not None:
            for r in run_outages(ctx, windows_all, None, nhc_label("INS"), None, ecfg["pseudo_gps"], aids=[aids]):
                self.add(r, self.fold_of[r.start])
        for s in plan["start_s"]:
            self.add(gps_run(ctx, s, dmax), self.fold_of[s])
        self.t_nav = time.perf_counter() - t0
        attitude = ctx.attitude_table()
        self.runs = []
        for k in sorted(plan["fold"].unique()):
            fw = [(s, dmax) for s in plan.loc[plan["fold"] == k, "start_s"]]
            data = build_learning_data(drive.imu, attitude, drive.gnss, fw, **opts)
            for method in self.methods:
                for seed in self.seeds:
                    out = checkpoint_path(profile, dataset, method, seed, fold=int(k)).parent
                    extra = {"dataset": dataset, "profile": profile, "fold": int(k), "fold_outages": fw,
                             "size": tc.get("size")}
                    label = f"{dataset} fold {k} {METHOD_LABELS[method]} seed {seed}"
                    training = train.TrainingRun(label, method, data, train.size_config(tc, method), tc, seed, out,
                                                 None, extra)
                    self.runs.append(SweepRun(label, ctx, int(k), fw, training, method, seed, ecfg["pseudo_gps"],
                                              aids is not None))

    def add(self, run, fold) -> None:
        """The rows of one outage run, one per duration (and per seed for a run without one)."""
        for du in self.durations:
            mtr = window_metrics(run.errors, run.start, du, run.sd)
            # the network's own increment error in this outage (the oracle's sigma axis, bgfn.studies.outage_sweep.oracle)
            mtr["increment_rmse_m"] = (increment_rmse(run, self.truth, self.ctx.gnss_interval_s, du)
                                       if len(run.increments) else float("nan"))
            for seed in ([run.seed] if run.seed is not None else self.seeds):
                self.rows.append({"dataset": self.dataset, "start_s": run.start, "duration_s": du,
                                  "method": run.method, "seed": int(seed), "fold": int(fold),
                                  **{k: mtr[k] for k in SWEEP_COLUMNS[6:]}})

    def finish(self, results: list) -> tuple[pd.DataFrame, dict]:
        """The rows and info of :func:`run_sweep` from the results of :attr:`runs` (in their order)."""
        plan, tc, methods = self.plan, self.tc, self.methods
        cards = []
        t_train = t_eval = 0.0
        for run, (card, runs, train_s, eval_s) in zip(self.runs, results):
            cards.append(card)
            for r in runs:
                self.add(r, run.fold)
            t_train, t_eval = t_train + train_s, t_eval + eval_s
        df = pd.DataFrame(self.rows, columns=list(SWEEP_COLUMNS))
        info = {"dataset": self.dataset, "n_starts": len(plan), "folds": int(plan["fold"].nunique()),
                "seeds": self.seeds, "durations_s": self.durations, "methods": [METHOD_LABELS[m] for m in methods],
                "window": int(self.opts["window"]), "size": tc.get("size"), "optimizer": train.optimizer_options(tc),
                "lr": {METHOD_LABELS[m]: train.method_lr(tc, m) for m in methods},
                "fold_starts": {int(k): plan.loc[plan["fold"] == k, "start_s"].tolist() for k in plan["fold"].unique()},
                "train_wall_s": t_train, "eval_wall_s": t_eval + self.t_nav,
                "train_epochs_run": {f"{c['method']}_fold{c.get('fold')}_seed{c['seed']}": c["epochs_run"]
                                     for c in cards},
                "fold_val_rmse_m": {f"{c['method']}_fold{c.get('fold')}_seed{c['seed']}": c["val_rmse_m"]
                                    for c in cards},
                "constraints": self.aids.summary() if self.aids is not None else None}
        return df, info


def run_sweep(cfg: dict, profile: str, dataset: str, drive=None, ecfg: dict | None = None,
              runner: Runner | None = None) -> tuple[pd.DataFrame, dict]:
    """The outage sweep of one dataset (module docstring), its networks spread over ``runner``.

    Returns
    -------
    rows : DataFrame
        ``SWEEP_COLUMNS``; INS, INS+NHC and GPS do not depend on a network and are repeated for every seed so
        that every (start, seed) pair has every method. With ``nhc_rows`` every method also runs with the
        vehicle constraints (``INS+NHC``, ``<METHOD>+NHC``).
    info : dict
        Sizes, training and evaluation times (summed over the runs, s), fold windows.
    """
    ecfg = ecfg or evaluate_config(cfg.get("evaluate"), cfg.get("train"))
    sweep = _Sweep(cfg, profile, dataset, drive, ecfg)
    return sweep.finish((runner or Runner()).map(sweep_run, [(r,) for r in sweep.runs],
                                                 labels=[r.label for r in sweep.runs], summary=_sweep_summary,
                                                 desc=f"sweep {dataset}",
                                                 cost=[train.expected_cost(r.training) for r in sweep.runs]))


def sweep_summary(sweep: pd.DataFrame, n_boot: int = 2000, level: float = 0.95, seed: int = 0,
                  metric: str = "max_h_m") -> pd.DataFrame:
    """Median of ``metric`` per dataset, duration and method with a cluster-bootstrap interval (by start).

    Returns
    -------
    DataFrame
        ``dataset``, ``duration_s``, ``method``, ``n`` (runs), ``n_starts``, ``median_m``, ``ci_lo_m``, ``ci_hi_m``.
    """
    rows = []
    order = {m: i for i, m in enumerate(TABLE_METHODS)}
    for (ds, du, m), g in sweep.groupby(["dataset", "duration_s", "method"]):
        if m in SEEDLESS_METHODS:        # one value per start (repeated per seed)
            g = g.drop_duplicates("start_s")
        lo, hi = bootstrap_ci(g[metric], n_boot=n_boot, level=level, seed=seed, groups=g["start_s"])
        rows.append({"dataset": ds, "duration_s": du, "method": m, "n": len(g), "n_starts": g["start_s"].nunique(),
                     "median_m": float(np.median(g[metric])), "ci_lo_m": lo, "ci_hi_m": hi})
    out = pd.DataFrame(rows)
    return out.sort_values(["dataset", "duration_s", "method"], key=lambda s: s.map(order) if s.name == "method"
                           else s).reset_index(drop=True)


def sweep_comparisons(sweep: pd.DataFrame, method: str = "BGFN", metric: str = "max_h_m") -> pd.DataFrame:
    """How often ``method`` beats each other method, paired by (start, seed), with the Wilcoxon test; and, when the
    sweep has it, how often ``method`` with the vehicle constraints (``BGFN+NHC``) beats each other ``+NHC`` row
    (``INS+NHC`` first: does the learned aid add to the learning-free one?).

    ``p_value``: Wilcoxon signed-rank on the (start, seed) pairs; ``p_value_by_start``: on the per-start
    medians over seeds (pairs from the same start are not independent: the more conservative number).

    Returns
    -------
    DataFrame
        ``dataset``, ``duration_s``, ``method``, ``baseline``, ``n``, ``wins``, ``ties``, ``win_rate``,
        ``median_diff_m`` (method - baseline), ``median_ratio``, ``p_value``, ``n_starts``, ``p_value_by_start``.
    """
    rows = []
    aided = nhc_label(method)
    for (ds, du), g in sweep.groupby(["dataset", "duration_s"]):
        piv = g.pivot_table(index=["start_s", "seed"], columns="method", values=metric, aggfunc="first")
        pairs = [(method, b) for b in TABLE_METHODS if method in piv.columns and b in piv.columns and b != method]
        pairs += [(aided, b) for b in TABLE_METHODS if aided in piv.columns and b in piv.columns and b != aided
                  and b.endswith(NHC_SUFFIX)]
        for m, base in pairs:
            pc = paired_comparison(piv[m].to_numpy(), piv[base].to_numpy())
            by_start = (piv[m] - piv[base]).groupby(level="start_s").median()
            rows.append({"dataset": ds, "duration_s": du, "method": m, "baseline": base, "n": pc["n"],
                         "wins": pc["wins"], "ties": pc["ties"], "win_rate": pc["win_rate"],
                         "median_diff_m": pc["median_diff"], "median_ratio": pc["median_ratio"],
                         "p_value": pc["p_value"], "n_starts": int(by_start.notna().sum()),
                         "p_value_by_start": wilcoxon_p(by_start)})
    return pd.DataFrame(rows)


def run_sweeps(cfg: dict, profile: str, datasets, ecfg: dict, runner: Runner | None = None,
               report: Callable[[str], None] | None = None) -> tuple[pd.DataFrame, dict, dict]:
    """:func:`run_sweep` of every dataset, the networks of all of them spread over ``runner`` at once.

    Parameters
    ----------
    report : callable, optional
        Called with a line or two per dataset when its rows are in (its rows, times, fold starts).

    Returns
    -------
    rows : DataFrame
        ``SWEEP_COLUMNS``, the datasets in turn (empty, with those columns, when ``datasets`` is).
    info : dict
        ``{dataset: info of run_sweep}``.
    timings : dict
        ``{"sweep_<dataset>_s": its learning-free runs' wall time + its networks' run times, s}`` and
        ``sweep_wall_s`` (the whole sweep's wall time, s; absent without datasets).
    """
    t0 = time.perf_counter()
    sweeps = [_Sweep(cfg, profile, name, None, ecfg) for name in datasets]
    runs = [r for sw in sweeps for r in sw.runs]
    results = (runner or Runner()).map(sweep_run, [(r,) for r in runs], labels=[r.label for r in runs],
                                       summary=_sweep_summary, desc="sweep",
                                       cost=[train.expected_cost(r.training) for r in runs])
    parts, info, timings, i = [], {}, {}, 0
    for sw in sweeps:
        name = sw.dataset
        df, info[name] = sw.finish(results[i:i + len(sw.runs)])
        i += len(sw.runs)
        parts.append(df)
        timings[f"sweep_{name}_s"] = info[name]["train_wall_s"] + info[name]["eval_wall_s"]
        if report is not None:
            report(f"{name}: {len(df)} rows, training {info[name]['train_wall_s']:.0f} s, evaluation "
                   f"{info[name]['eval_wall_s']:.0f} s (summed over its runs)\n"
                   f"  fold starts (s): {info[name]['fold_starts']}")
    if sweeps:
        timings["sweep_wall_s"] = time.perf_counter() - t0
    rows = pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=list(SWEEP_COLUMNS))
    return rows, info, timings


def pairs_style(pairs: pd.DataFrame):
    """:func:`sweep_comparisons` styled for notebook 06 (win rate and ratios with two decimals, p with two digits)."""
    return pairs.style.format({"win_rate": "{:.2f}", "median_diff_m": "{:+.1f}", "median_ratio": "{:.2f}",
                               "p_value": "{:.2g}", "p_value_by_start": "{:.2g}"}).hide(axis="index")


def sweep_interval_table(summary: pd.DataFrame) -> pd.DataFrame:
    """:func:`sweep_summary` as one text cell per (dataset, method) row and duration column:
    ``median [lo, hi]`` of the max horizontal error, m, one decimal.

    Rows are ordered by method (``TABLE_METHODS``), then dataset; columns ``<d> s`` by duration.
    """
    cell = summary.assign(text=[f"{r.median_m:.1f} [{r.ci_lo_m:.1f}, {r.ci_hi_m:.1f}]"
                                for r in summary.itertuples(index=False)])
    wide = cell.pivot_table(index=["dataset", "method"], columns="duration_s", values="text", aggfunc="first")
    wide = wide.reindex([i for m in TABLE_METHODS for i in wide.index if i[1] == m])
    wide.columns = [f"{c:g} s" for c in wide.columns]
    return wide

"""The paper's Tables 1-2 (``tab-out1-exin``, ``tab-real``): every method in the evaluation outages, the seed
aggregate, the result files (in words: :mod:`bgfn.report.evaluation_words`). The paper's own values beside
ours are :mod:`bgfn.evaluate.claims`."""

from __future__ import annotations

import dataclasses
import functools
import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pandas as pd
import scipy
import torch

from bgfn.data import load_drive
from bgfn.data.gnss import fix_errors
from bgfn.data.names import dataset_id
from bgfn.evaluate.setup import METRIC_COLUMNS, TABLE_COLUMNS, TABLE_FILES, TABLE_METHODS, evaluate_config
from bgfn.evaluate.hybrid import gps_run, navigation_context, run_outages, window_metrics
from bgfn.evaluate.networks import ensure_models
from bgfn.io import atomic_write_csv, cached, locked, sources_hash
from bgfn.nav import outages
from bgfn.nav.baseline import run_key
from bgfn.nav.constraints import DEFAULT_PLATFORM, platform_aids
from bgfn.paper import METHOD_LABELS, nhc_label, test_of
from bgfn.row_labels import ran_labels
from bgfn.train.checkpoints import card_path, checkpoint_path, models_dir


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
    fix_errors : DataFrame or None
        :func:`bgfn.data.gnss.fix_errors` of the drive: each GNSS fix's own error, which the GPS row follows.
    gnss_errors : DataFrame or None
        :func:`fix_error_table` of ``fix_errors``: their largest values in each outage window.
    drive : bgfn.data.Drive or None
        The drive evaluated (its reference draws the figures; the sensitivity run reuses it).
    windows : list of (float, float) or None
        The outages evaluated, ``(start, duration)``, s; ``Outage k`` is ``windows[k - 1]``.
    constraints : dict or None
        :meth:`bgfn.nav.constraints.Constraints.summary` of the ``+NHC`` rows' constraints (None without them).
    """

    dataset: str
    test: str
    per_seed: pd.DataFrame
    table: pd.DataFrame
    runs: list
    models: dict = field(default_factory=dict)
    fix_errors: pd.DataFrame | None = None
    gnss_errors: pd.DataFrame | None = None
    drive: Any = None
    windows: list | None = None
    constraints: dict | None = None


def fix_error_table(err: pd.DataFrame, windows) -> pd.DataFrame:
    """Per outage window: the largest |east| and |north| error of the GNSS fixes inside it, m, and the number of
    fixes; ``err`` from :func:`bgfn.data.gnss.fix_errors` (fix minus true antenna position).

    The GPS row is the filter with these fixes: it cannot stay closer to the reference than they are for long,
    while an INS that starts from the same state may drift less than the fixes wander.
    """
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
                     models: dict | None = None, progress: bool = False, nhc_rows: bool | None = None) -> TableResult:
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
    nhc_rows : bool, optional
        Also run ``INS+NHC`` and every network with the vehicle constraints (``<METHOD>+NHC``); None:
        ``ecfg['nhc_rows']``.
    """
    ecfg = ecfg or evaluate_config(cfg.get("evaluate"), cfg.get("train"))
    if drive is None:
        drive = load_drive(dataset, profile=profile)
    windows = outages.outage_windows(cfg, drive, dataset)
    ctx = navigation_context(drive, cfg.get("nav"), [s for s, _ in windows])
    if models is None:
        models = ensure_models(cfg, profile, dataset, ctx, ecfg["methods"], ecfg["seeds"], windows,
                               ecfg["train_missing"], progress)
    return _evaluate(dataset, ctx, windows, models, ecfg, ecfg["nhc_rows"] if nhc_rows is None else nhc_rows)


def _evaluate(dataset: str, ctx, windows, models: dict, ecfg: dict, nhc_rows: bool) -> TableResult:
    """:func:`evaluate_dataset` once its drive's navigation context, outages and networks are at hand."""
    drive = ctx.drive
    aids = ctx.constraints if nhc_rows else None
    runs = run_outages(ctx, windows, None, "INS", None, ecfg["pseudo_gps"])
    if aids is not None:
        runs += run_outages(ctx, windows, None, nhc_label("INS"), None, ecfg["pseudo_gps"], aids=[aids])
    runs += [gps_run(ctx, s, d) for s, d in windows]
    for (method, seed), model in models.items():
        runs += run_outages(ctx, windows, model, METHOD_LABELS[method], seed, ecfg["pseudo_gps"])
        if aids is not None:
            runs += run_outages(ctx, windows, model, nhc_label(method), seed, ecfg["pseudo_gps"], aids=[aids])
    outage_no = {s: i + 1 for i, (s, _) in enumerate(windows)}
    rows = [{"outage": outage_no[r.start], "start_s": r.start, "method": r.method, "seed": r.seed,
             **window_metrics(r.errors, r.start, r.duration, r.sd)} for r in runs]
    per_seed = pd.DataFrame(rows)
    fixes = fix_errors(drive.gnss, drive.reference, ctx.lever, drive.meta)
    # a dataset that stands for none of the paper's tests names its table files by its id (never a folder path)
    return TableResult(dataset, test_of(dataset) or dataset_id(dataset), per_seed,
                       aggregate_seeds(per_seed, ecfg["seed_aggregate"]), runs, models, fixes,
                       fix_error_table(fixes, windows), drive, list(windows),
                       aids.summary() if aids is not None else None)


#: :func:`bgfn.io.cached`'s kind of the runs of the paper's outages (:func:`outage_result`).
OUTAGE_RUNS_CACHE = "outage_runs"
#: What of :func:`evaluate_config` the runs of :func:`outage_result` read (besides the drive, the ``nav:`` settings,
#: the outages and the networks, each in its key).
_RUN_SETTINGS = ("methods", "seeds", "pseudo_gps", "nhc_rows", "seed_aggregate")


def outage_result(cfg: dict, profile: str, dataset: str, ecfg: dict) -> TableResult:
    """:func:`evaluate_dataset` of the profile's networks, computed once per input and read back when asked again.

    Notebook 04 makes the paper's tables from these runs; notebook 06 builds on them (the oracle's and the NEES's
    level of each network). Under ``make`` (``BGFN_CACHE_DIR``) they are kept in the run cache (:func:`bgfn.io.cached`)
    with a key of every input: the drive's content, the ``nav:`` settings, the outages, the networks' checkpoint files,
    the evaluation settings they read, the package's code and the numerical libraries (numpy, pandas, numba, scipy,
    torch). Notebook 06 can so start beside notebook 04 instead of after it: whichever asks first computes them, the
    other waits for them and reads the same runs, bit for bit. Without a cache, computed here.
    """
    drive = load_drive(dataset, profile=profile)
    windows = outages.outage_windows(cfg, drive, dataset)
    # the GPS-aided run and its states (seconds per drive): built only when the runs are computed here
    context = functools.cache(lambda: navigation_context(drive, cfg.get("nav"), [s for s, _ in windows]))

    # 04 and 06 side by side: a network 03 did not train (the evaluation's methods or seeds beyond training's) is
    # trained by one of them while the other waits, never read half-trained
    with locked(models_dir(profile, dataset) / ".networks.lock"):
        missing = [(m, s) for m in ecfg["methods"] for s in ecfg["seeds"]
                   if not checkpoint_path(profile, dataset, m, s, create=False).exists()]
        models = ensure_models(cfg, profile, dataset, context() if missing and ecfg["train_missing"] else None,
                               ecfg["methods"], ecfg["seeds"], windows, ecfg["train_missing"])

    def key() -> dict:
        files = {f"{m}_seed{s}": sources_hash([path, card_path(path)])
                 for m, s in models for path in [checkpoint_path(profile, dataset, m, s, create=False)]}
        return run_key(drive, cfg.get("nav"), windows=[tuple(map(float, w)) for w in windows], networks=files,
                       evaluate={k: ecfg[k] for k in _RUN_SETTINGS}, package=_code_version(),
                       torch=torch.__version__, scipy=scipy.__version__)

    light = cached(OUTAGE_RUNS_CACHE, key, lambda: _without_drive_and_models(
        _evaluate(dataset, context(), windows, models, ecfg, ecfg["nhc_rows"])))
    return dataclasses.replace(light, drive=drive, models=models)


def outage_results(cfg: dict, profile: str, datasets, ecfg: dict) -> dict:
    """``{dataset: TableResult}``: :func:`outage_result` of each of ``datasets``, in turn."""
    return {name: outage_result(cfg, profile, name, ecfg) for name in datasets}


def _code_version() -> str:
    """The sources the runs of :func:`outage_result` are made by: the core facts and the packages of the data, the
    navigation, the networks, the learning problem, the training and this evaluation (not the studies or report)."""
    root = Path(__file__).resolve().parent.parent
    return sources_hash(sorted(root.glob("*.py")) + sorted(p for sub in ("data", "nav", "models", "learning", "train",
                                                                        "evaluate") for p in (root / sub).glob("*.py")))


def _without_drive_and_models(result: TableResult) -> TableResult:
    """``result`` as kept: the drive (in the data cache) and the networks (their checkpoints) are loaded again."""
    return dataclasses.replace(result, drive=None, models={})


def run_tables(cfg: dict, profile: str, datasets, ecfg: dict, out,
               report: Callable[[str], None] | None = None) -> tuple[dict, dict]:
    """:func:`evaluate_dataset` and :func:`save_table_result` of every dataset of the tables, in turn.

    Parameters
    ----------
    cfg : dict
        The profile.
    profile : str
    datasets : sequence of str
    ecfg : dict
        :func:`evaluate_config`.
    out : path
        ``results/<profile>``.
    report : callable, optional
        Called with one line per dataset as soon as it is done (runs, wall time, files written).

    Returns
    -------
    results : dict
        ``{dataset: TableResult}``.
    timings : dict
        ``{"tables_<dataset>_s": wall time of loading, evaluating and writing, s}``.
    """
    results, timings = {}, {}
    for name in datasets:
        t0 = time.perf_counter()
        res = results[name] = outage_result(cfg, profile, name, ecfg)
        paths = save_table_result(out, res, ecfg["series_rate_hz"])
        timings[f"tables_{name}_s"] = time.perf_counter() - t0
        if report is not None:
            report(f"{name} ({res.test} test): {len(res.runs)} runs in {timings[f'tables_{name}_s']:.1f} s -> "
                   + ", ".join(str(Path(q).relative_to(out)) for q in paths.values()))
    return results, timings


def table_file(test: str) -> str:
    """File name of a test's table under ``tables/``: ``outage_dataset.csv``, ``outage_field.csv``, else
    ``outage_<test>.csv``."""
    return TABLE_FILES.get(test, f"outage_{test}.csv")


def table_paths(out, test: str) -> dict[str, Path]:
    """The files of one test under ``out`` (``results/<profile>``): ``{kind: path}`` for the kinds ``table``,
    ``seeds``, ``series`` and ``gnss`` (:func:`save_table_result` writes them; the results page reads them)."""
    stem = table_file(test)[: -len(".csv")]
    tables = Path(out) / "tables"
    return {"table": tables / f"{stem}.csv", "seeds": tables / f"{stem}_seeds.csv",
            "series": tables / f"{stem.replace('outage_', 'outage_errors_', 1)}.csv",
            "gnss": tables / f"{stem}_gnss.csv"}


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
    paths = table_paths(out, result.test)
    gnss = paths.pop("gnss")
    # the +NHC rows named by the aids that ran (INS+ZUPT on a walker; the code keys them +NHC)
    aids = platform_aids((result.constraints or {}).get("platform", DEFAULT_PLATFORM))
    atomic_write_csv(paths["table"], ran_labels(result.table[list(TABLE_COLUMNS)], aids), float_format="%.4f")
    seeds = result.per_seed.assign(dataset=result.dataset)
    seeds["seed"] = seeds["seed"].astype("Int64")
    atomic_write_csv(paths["seeds"], ran_labels(seeds, aids), float_format="%.4f")
    series = error_series(result.runs, series_rate_hz)
    series.insert(0, "outage", series["start_s"].map(
        dict(zip(result.per_seed["start_s"], result.per_seed["outage"]))).astype(int))
    atomic_write_csv(paths["series"], ran_labels(series, aids), float_format="%.4f")
    if result.gnss_errors is not None:
        paths["gnss"] = gnss
        atomic_write_csv(gnss, result.gnss_errors, float_format="%.4f")
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

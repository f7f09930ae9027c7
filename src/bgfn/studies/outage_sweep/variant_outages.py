"""The learning-problem variants (:mod:`bgfn.train.variants`) in the paper's two outages: one table,
``tables/outage_variants.csv``, of every test, outage, variant and method.

Each network runs the prediction mode of the main tables (:func:`bgfn.evaluate.hybrid.run_outages`, the
profile's ``evaluate.pseudo_gps``) from the same GPS-aided states (:func:`bgfn.evaluate.hybrid.navigation_context`);
the ``main`` variant is the profile's own networks of notebook 03, taken for the same seeds as the variants so
that every cell compares like with like. A cell holds the median over its networks of the max |east|, max
|north| and max horizontal error (m) and ``n_runs``, how many networks it holds; the standalone INS is one row per
outage (variant ``-``, ``n_runs`` 0).
"""

from __future__ import annotations

import time
from pathlib import Path

import pandas as pd

from bgfn.config import MAIN_VARIANT
from bgfn.data import load_drive
from bgfn.data.names import dataset_id
from bgfn.errors import DataError
from bgfn.evaluate.setup import evaluate_config
from bgfn.evaluate.hybrid import navigation_context, run_outages, window_metrics
from bgfn.evaluate.networks import load_model
from bgfn.nav import outages
from bgfn.paper import METHOD_LABELS, test_of
from bgfn.train.checkpoints import checkpoint_name
from bgfn.train.variants import variant_options

#: Columns of ``tables/outage_variants.csv``.
VARIANT_COLUMNS: tuple[str, ...] = ("dataset", "test", "outage", "start_s", "variant", "inputs", "protocol",
                                    "method", "max_east_m", "max_north_m", "max_h_m", "n_runs")
#: The metrics of a cell (median over its networks).
VARIANT_METRICS: tuple[str, ...] = ("max_east_m", "max_north_m", "max_h_m")
#: Variant of the rows that need no network (the standalone INS).
NO_VARIANT = "-"


def load_variant_network(path):
    """The network at ``path`` (:func:`bgfn.evaluate.networks.load_model`); DataError when notebook 03 has not
    trained it."""
    if not Path(path).exists():
        raise DataError(path, "checkpoint", "a variant's network (notebook 06 trains it: train_variants)", "missing")
    return load_model(path)


def variant_runs(vplan, drives: dict | None = None, loader=load_variant_network, report=None) -> pd.DataFrame:
    """Every network of every variant (``main`` first) in the profile's outages, one row per run.

    Parameters
    ----------
    vplan : bgfn.train.variants.VariantPlan
        The variants, datasets, methods and seeds (their networks trained by
        :func:`bgfn.train.variants.train_variants`, the ``main`` ones by notebook 03).
    drives : dict, optional
        ``{dataset: Drive}`` already loaded (default: :func:`bgfn.data.load_drive`).
    loader : callable
        ``loader(checkpoint path) -> predictor`` (default :func:`load_variant_network`).
    report : callable, optional
        Called with one line per dataset.

    Returns
    -------
    DataFrame
        ``dataset, test, outage, start_s, variant, inputs, protocol, method, seed`` and
        :func:`bgfn.evaluate.hybrid.window_metrics`'s metrics.
    """
    cfg = vplan.cfg
    ecfg = evaluate_config(cfg.get("evaluate"), cfg.get("train"))
    rows = []
    for dataset in vplan.datasets:
        t0 = time.perf_counter()
        drive = (drives or {}).get(dataset)
        if drive is None:
            drive = load_drive(dataset, profile=vplan.profile)
        windows = outages.outage_windows(cfg, drive, dataset)         # each drive its own
        ctx = navigation_context(drive, cfg.get("nav"), [s for s, _ in windows])
        outage_no = {s: i + 1 for i, (s, _) in enumerate(windows)}
        head = {"dataset": dataset, "test": test_of(dataset) or dataset_id(dataset)}
        runs = [(NO_VARIANT, {"inputs": NO_VARIANT, "protocol": NO_VARIANT}, r)
                for r in run_outages(ctx, windows, None, "INS", None, ecfg["pseudo_gps"])]
        for name in [MAIN_VARIANT] + vplan.names:
            what = variant_options(vplan.train_section(name))
            folder = vplan.models_dir(name, dataset, create=False)
            for method in vplan.methods:
                for seed in vplan.seeds:
                    model = loader(folder / checkpoint_name(method, seed))
                    runs += [(name, what, r) for r in run_outages(ctx, windows, model, METHOD_LABELS[method], seed,
                                                                   ecfg["pseudo_gps"])]
        rows += [{**head, "outage": outage_no[r.start], "start_s": r.start, "variant": name, **what,
                  "method": r.method, "seed": r.seed, **window_metrics(r.errors, r.start, r.duration)}
                 for name, what, r in runs]
        if report is not None:
            report(f"{dataset}: {len(runs)} outage runs in {time.perf_counter() - t0:.1f} s")
    return pd.DataFrame(rows)


def variant_table(per_run: pd.DataFrame) -> pd.DataFrame:
    """Per dataset, outage, variant and method: the median of :data:`VARIANT_METRICS` over the networks and
    ``n_runs``, the number of networks (0 for the standalone INS); :data:`VARIANT_COLUMNS`, in the order of
    ``per_run``."""
    keys = ["dataset", "test", "outage", "start_s", "variant", "inputs", "protocol", "method"]
    g = per_run.groupby(keys, sort=False)
    table = g[list(VARIANT_METRICS)].median().reset_index()
    table["n_runs"] = g["seed"].count().to_numpy().astype(int)     # INS has no seed: 0 networks
    return table[list(VARIANT_COLUMNS)]


def variant_pivot(table: pd.DataFrame, metric: str = "max_h_m") -> pd.DataFrame:
    """``metric`` of :func:`variant_table` with one row per test, outage and method and one column per variant
    (the INS in its own column), for the notebook."""
    if metric not in VARIANT_METRICS:
        raise DataError("outage_variants", "metric", f"one of {VARIANT_METRICS}", repr(metric))
    ins = table[table["variant"] == NO_VARIANT].set_index(["test", "outage"])[metric].rename("INS")
    nets = table[table["variant"] != NO_VARIANT]
    wide = nets.pivot_table(index=["test", "outage", "method"], columns="variant", values=metric, sort=False)
    wide = wide[list(dict.fromkeys(nets["variant"]))]
    return wide.join(ins, on=["test", "outage"])


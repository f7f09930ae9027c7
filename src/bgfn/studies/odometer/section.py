"""The learned odometer's section of notebook 07: its tables and figures from the rows of
:mod:`bgfn.studies.odometer.bars` (the bars a learned odometer must clear in the outage sweep's windows); in words:
:mod:`bgfn.report.odometer_words`."""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from bgfn.config import SHARED_TABLES, odometer_datasets
from bgfn.data import dataset_id
from bgfn.data.platforms import write_ran_table
from bgfn.studies.odometer.errors import ERROR_COLUMNS, error_parts_table, offset_bar_mps, plot_error_parts
from bgfn.studies.odometer.uncertainty import UNCERTAINTY_COLUMNS, uncertainty_table
from bgfn.evaluate.plots import finish_duration_axes
from bgfn.studies.odometer.ridge_curve import CURVE_COLUMNS, plot_curve
from bgfn.io import save_figure
from bgfn.paper import ENSEMBLE_SUFFIX, nhc_label
from bgfn.parallel import Runner

from bgfn.studies.odometer.bars import (ODOMETER_METHODS, ORACLE, ORACLE_WALK, PAPER_FOLD, network_table,
                                        odometer_summary, paper_outage_table, run_odometer_bars)


@dataclass
class OdometerSection:
    """The odometer bars of notebook 07: the rows, their summary (:func:`odometer_summary`) and the facts per
    dataset (:func:`bgfn.report.odometer_words.odometer_markdown` words them)."""

    rows: pd.DataFrame
    summary: pd.DataFrame
    facts: dict
    figures: list = field(default_factory=list)
    paper: pd.DataFrame | None = None
    networks: pd.DataFrame | None = None
    curve: pd.DataFrame | None = None
    uncertainty: pd.DataFrame | None = None
    errors: pd.DataFrame | None = None


def odometer_table(summary: pd.DataFrame) -> pd.DataFrame:
    """:func:`odometer_summary`'s median max horizontal error (m) wide: a row per dataset and method in the order of
    :data:`ODOMETER_METHODS` (an oracle per sigma, ``ORACLE-SPEED 0.5 m/s``), a column per duration (``30 s``)."""
    order = {m: i for i, m in enumerate(ODOMETER_METHODS)}
    t = summary.assign(row=[m if s != s else f"{m} {s:g} m/s" for m, s in zip(summary["method"],
                                                                              summary["sigma_mps"])],
                       rank=summary["method"].map(order))
    wide = (t.sort_values(["dataset", "rank", "sigma_mps"], kind="stable")
            .pivot_table(index=["dataset", "row"], columns="duration_s", values="max_h_m", sort=False))
    wide.columns = [f"{c:g} s" for c in wide.columns]
    return wide


def run_odometer_section(cfg: dict, profile: str, setup, out, runner: Runner | None = None,
                         timings: dict | None = None, report: Callable[[str], None] | None = None) -> OdometerSection:
    """Notebook 04's odometer bars: :func:`run_odometer_bars` over ``evaluate.odometer.datasets`` (null: the
    sweep's), the tables written under ``out`` (``SHARED_TABLES`` ``odometer``, ``odometer_summary``), the wall time
    added to ``timings`` (``odometer_s``)."""
    t0 = time.perf_counter()
    ecfg = setup.config
    names = odometer_datasets(ecfg["odometer"], setup.sweep_datasets)
    rows, facts = run_odometer_bars(cfg, profile, names, ecfg, runner, report)
    paper = paper_outage_table(rows[rows["fold"] == PAPER_FOLD], {n: f["paper_windows"] for n, f in facts.items()})
    rows = rows[rows["fold"] != PAPER_FOLD].reset_index(drop=True)
    summary = odometer_summary(rows)
    networks = network_table(rows, facts)
    curves = [f["curve"] for f in facts.values() if f.get("curve") is not None and len(f["curve"])]
    curve = pd.concat(curves, ignore_index=True) if curves else pd.DataFrame(columns=list(CURVE_COLUMNS))
    ranked = [u for u in (uncertainty_table(name, f["speed_series"]) for name, f in facts.items()
                          if f.get("speed_series")) if len(u)]
    uncertainty = (pd.concat(ranked, ignore_index=True) if ranked else pd.DataFrame(columns=list(UNCERTAINTY_COLUMNS)))
    parts = [e for e in (error_parts_table(name, f["speed_series"], ecfg["sweep"]["durations_s"],
                                           float(ecfg["odometer"]["correlation_max_lag_s"]))
                         for name, f in facts.items() if f.get("speed_series")) if len(e)]
    errors = pd.concat(parts, ignore_index=True) if parts else pd.DataFrame(columns=list(ERROR_COLUMNS))
    tables = Path(out) / "tables"
    write_ran_table(tables / SHARED_TABLES["odometer_errors"], errors, out, float_format="%.4f")
    write_ran_table(tables / SHARED_TABLES["odometer_uncertainty"], uncertainty, out, float_format="%.4f")
    write_ran_table(tables / SHARED_TABLES["odometer_curve"], curve, out, float_format="%.4f")
    write_ran_table(tables / SHARED_TABLES["odometer_networks"], networks, out, float_format="%.4f")
    write_ran_table(tables / SHARED_TABLES["odometer"], rows, out, float_format="%.4f")
    write_ran_table(tables / SHARED_TABLES["odometer_summary"], summary, out, float_format="%.4f")
    write_ran_table(tables / SHARED_TABLES["odometer_paper"], paper, out, float_format="%.4f")
    figures = []
    for name, f in facts.items():
        if f.get("skipped"):
            continue
        for fig, stem in ((plot_speed_series(f["speed_series"], name), "odometer_speed"),
                          (plot_error_growth(summary[summary["dataset"] == name], name), "odometer_growth")):
            save_figure(fig, Path(out) / "figures" / f"{stem}_{dataset_id(name)}.png")
            plt.close(fig)
            figures.append(fig)
    for name in errors["dataset"].unique():
        nhc = summary[(summary["dataset"] == name) & (summary["method"] == nhc_label("INS"))]
        fig = plot_error_parts(errors[errors["dataset"] == name], name,
                               {float(d): offset_bar_mps(m, d) for d, m in zip(nhc["duration_s"], nhc["max_h_m"])})
        save_figure(fig, Path(out) / "figures" / f"odometer_errors_{dataset_id(name)}.png")
        plt.close(fig)
        figures.append(fig)
    if len(curve):
        fig = plot_curve(curve)
        save_figure(fig, Path(out) / "figures" / "odometer_curve.png")
        plt.close(fig)
        figures.append(fig)
    if timings is not None:
        timings["odometer_s"] = time.perf_counter() - t0
    return OdometerSection(rows, summary, facts, figures, paper, networks, curve, uncertainty, errors)


#: Colours of the speed bands (:func:`plot_speed_series`): the ridge, then the networks.
_BAND_COLOURS = ("tab:orange", "tab:blue", "tab:green", "tab:red", "tab:purple")
def plot_speed_series(series: dict, dataset: str, n_outages: int = 4):
    """The learned odometers' speed (RIDGE-ODO and each network's first seed; not the ensembles) with their 2-sigma
    bands against the reference's in a few outages spread over the drive, every outage predicted by the odometers
    of its own fold (trained without it)."""
    outages = sorted(series["outages"])
    pick = [outages[i] for i in np.unique(np.linspace(0, len(outages) - 1, min(n_outages, len(outages))).round()
                                          .astype(int))] if outages else []
    fig, axes = plt.subplots(1, max(len(pick), 1), figsize=(3.4 * max(len(pick), 1), 3.0), sharey=True,
                             squeeze=False)
    t, truth = np.asarray(series["time"], float), np.asarray(series["truth"], float)
    singles = {k: v for k, v in series["tracks"].items() if not k.endswith(ENSEMBLE_SUFFIX)}  # one band each
    for ax, (s, d) in zip(axes[0], pick):
        m = (t >= s) & (t <= s + d)
        for colour, (label, (speed, std)) in zip(_BAND_COLOURS, singles.items()):
            ax.fill_between(t[m] - s, speed[m] - 2 * std[m], speed[m] + 2 * std[m], color=colour, alpha=0.15)
            ax.plot(t[m] - s, speed[m], color=colour, lw=1.0, label=f"{label} (+- 2 sigma)")
        ax.plot(t[m] - s, truth[m], color="black", lw=1.4, label="reference")
        ax.set_title(f"start {s:.0f} s", fontsize=9)
        ax.set_xlabel("time in outage (s)")
    axes[0][0].set_ylabel("forward speed (m/s)")
    axes[0][0].legend(fontsize=6, loc="best")
    fig.suptitle(f"{dataset}: the learned odometers' speed in outages they were not trained on", fontsize=10)
    fig.tight_layout()
    return fig


def plot_error_growth(summary: pd.DataFrame, dataset: str):
    """Median max horizontal error against the outage duration, one line per odometer row (the oracle speed at its
    smallest and largest sigma, dashed)."""
    fig, ax = plt.subplots(figsize=(6.4, 3.8))
    for method in ODOMETER_METHODS:
        g = summary[summary["method"] == method]
        if not len(g):
            continue
        if method in (ORACLE, ORACLE_WALK):
            for sigma in sorted(g["sigma_mps"].unique())[::max(1, g["sigma_mps"].nunique() - 1)]:
                h = g[g["sigma_mps"] == sigma].sort_values("duration_s")
                ax.plot(h["duration_s"], h["max_h_m"], ls="--", lw=1.0, marker=".",
                        label=f"{method} {sigma:g} m/s")
        else:
            g = g.sort_values("duration_s")
            ax.plot(g["duration_s"], g["max_h_m"], marker="o", lw=2.0 if method == nhc_label("INS") else 1.3,
                    color="black" if method == nhc_label("INS") else None, label=method)
    return finish_duration_axes(fig, ax, "median max horizontal error (m)",
                                f"{dataset}: error growth over the outage, sweep starts")

"""Figures of notebook 04: position error during an outage (paper Figs. 6-7, 9-10, plus a map) and the
sweep's box plots."""

from __future__ import annotations

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd
from matplotlib.patches import Patch

from bgfn.evaluate.setup import COLORS, FIGURE_METHODS, TABLE_METHODS
from bgfn.evaluate.tables import TableResult, representative_seeds
from bgfn.nav import earth
from bgfn.paper import NHC_SUFFIX, base_label, nhc_label


def _style(method: str) -> str:
    """Line style of a method: dashed with the vehicle constraints (``+NHC``), solid otherwise."""
    return "--" if method.endswith(NHC_SUFFIX) else "-"


def finish_duration_axes(fig, ax, ylabel: str, title: str):
    """A figure of a quantity against the outage duration, finished as every such figure of notebook 04 is: log
    y axis, grid, a two-column legend, the title; returns ``fig``."""
    ax.set_xlabel("outage duration (s)")
    ax.set_ylabel(ylabel)
    ax.set_yscale("log")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, ncol=2)
    ax.set_title(title, fontsize=10)
    fig.tight_layout()
    return fig


def _ned_from_start(traj: pd.DataFrame, ref0) -> np.ndarray:
    return earth.lla_to_ned(traj["lat"].to_numpy(), traj["lon"].to_numpy(), traj["h"].to_numpy(),
                            float(ref0["lat"]), float(ref0["lon"]), float(ref0["h"]))


def plot_outage(result: TableResult, outage: int, reference: pd.DataFrame, methods=FIGURE_METHODS,
                title: str = ""):
    """Paper Figs. 6-7, 9-10: east and north position error against time, plus a map of the outage segment.

    The learned methods show their representative seed (:func:`representative_seeds`); a ``+NHC`` row (with the
    vehicle constraints) is dashed in its method's colour.

    Returns
    -------
    matplotlib.figure.Figure
    """
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
        r = runs.get((m, seed if m not in ("INS", nhc_label("INS"), "GPS") else None))
        if r is None:
            continue
        e = r.errors
        lab = m if r.seed is None else f"{m} (seed {r.seed})"
        ax_e.plot(e["t_rel"], e["east"], color=COLORS[m], ls=_style(m), lw=1.2, label=lab)
        ax_n.plot(e["t_rel"], e["north"], color=COLORS[m], ls=_style(m), lw=1.2, label=lab)
        ned = _ned_from_start(r.trajectory, reference.iloc[i0])
        ax_m.plot(ned[:, 1], ned[:, 0], color=COLORS[m], ls=_style(m), lw=1.0, label=m)
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


def outage_figures(result: TableResult, gps_row: bool = False):
    """Notebook 04's figures of one drive, outage by outage: ``(outage, figure)`` of :func:`plot_outage` (each
    drive its own windows in the title), or of :func:`plot_gps_row` with ``gps_row``."""
    name = result.dataset
    for o in sorted(int(k) for k in result.table["outage"].unique()):
        start, duration = result.windows[o - 1]
        if gps_row:
            yield o, plot_gps_row(result, o, title=f"{name} ({result.test} test), outage {o}: the GPS row and "
                                                  "the fixes it follows")
        else:
            yield o, plot_outage(result, o, result.drive.reference,
                                 title=f"{name} ({result.test} test), outage {o}: {duration:g} s from {start:g} s")


def plot_gps_row(result: TableResult, outage: int, title: str = ""):
    """Why the GPS row is where it is: its east and north error during an outage beside the errors of the GNSS
    fixes it follows (dots; ``result.fix_errors``, fix minus true antenna position) and the standalone INS
    started from the same state.

    Returns
    -------
    matplotlib.figure.Figure
    """
    start = float(result.per_seed.loc[result.per_seed["outage"] == outage, "start_s"].iloc[0])
    runs = {r.method: r for r in result.runs if r.seed is None and abs(r.start - start) < 1e-6}
    dur = runs["GPS"].duration
    fixes = result.fix_errors
    inside = fixes[(fixes["time"] >= start - 1e-6) & (fixes["time"] <= start + dur + 1e-6)]
    fig, axes = plt.subplots(1, 2, figsize=(10, 3.8), sharex=True)
    for ax, axis, lab in ((axes[0], "east", "(a) east error (m)"), (axes[1], "north", "(b) north error (m)")):
        ax.plot(inside["time"] - start, inside[f"{axis}_m"], ".", color="0.55", ms=3, label="GNSS fixes")
        for m in ("GPS", "INS"):
            if m in runs:
                e = runs[m].errors
                ax.plot(e["t_rel"], e[axis], color=COLORS[m], lw=1.4, label=m)
        ax.axhline(0.0, color="0.7", lw=0.6)
        ax.set_xlabel("time since outage start (s)")
        ax.set_ylabel(lab)
        ax.grid(alpha=0.3)
    axes[0].legend(fontsize=8, loc="best")
    if title:
        fig.suptitle(title, fontsize=11)
    fig.tight_layout()
    return fig


def plot_sweep_boxes(sweep: pd.DataFrame, dataset: str, methods=TABLE_METHODS):
    """Box plots of the max horizontal error per duration and method (log scale; ``+NHC`` rows hatched)."""
    d = sweep[sweep["dataset"] == dataset]
    durations = sorted(d["duration_s"].unique())
    methods = [m for m in methods if m in set(d["method"])]
    fig, ax = plt.subplots(figsize=(max(6.0, min(16.0, 1.6 * len(durations) * len(methods) / 3)), 4.5))
    width = 0.8 / len(methods)
    handles = []
    for j, m in enumerate(methods):
        data = [d[(d["duration_s"] == du) & (d["method"] == m)]["max_h_m"].to_numpy() for du in durations]
        pos = np.arange(len(durations)) + (j - (len(methods) - 1) / 2) * width
        bp = ax.boxplot(data, positions=pos, widths=width * 0.9, patch_artist=True, showfliers=True,
                        flierprops={"markersize": 2})
        for b in bp["boxes"]:
            b.set_facecolor(COLORS.get(m, "0.5"))
            b.set_alpha(0.6)
            if m.endswith(NHC_SUFFIX):
                b.set_hatch("///")
        for med in bp["medians"]:
            med.set_color("white" if base_label(m) in ("AT-LSTM", "BGFN") else "black")
        handles.append(Patch(facecolor=COLORS.get(m, "0.5"), alpha=0.6, label=m,
                             hatch="///" if m.endswith(NHC_SUFFIX) else None))
    ax.set_xticks(np.arange(len(durations)))
    ax.set_xticklabels([f"{du:g} s" for du in durations])
    ax.set_yscale("log")
    ax.set_xlabel("outage duration")
    ax.set_ylabel("max horizontal error (m)")
    ax.set_title(f"{dataset}: outage sweep")
    ax.grid(alpha=0.3, axis="y")
    ax.legend(handles=handles, fontsize=8, ncol=3)
    fig.tight_layout()
    return fig

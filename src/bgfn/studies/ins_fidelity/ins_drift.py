"""Standalone-INS drift over the outage sweep's starts, drive against drive (notebook 08).

How far does the INS alone drift in an outage of 10, 30, 60 s? Two outages per drive say little; the sweep's starts
(:func:`bgfn.studies.outage_sweep.sweep.sweep_plan`) say it for the whole drive. The simulated field-test stand-in
``turin-sim-mpu6000`` stands beside the recorded drive its error model was set from (``rtklib-drive0708``), and
``INS+NHC`` beside the INS alone. Each run starts from the GPS-aided filter's state and runs the longest duration
once; the shorter ones are its prefixes.
"""

from __future__ import annotations

from typing import Callable

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from bgfn.evaluate.setup import evaluate_config
from bgfn.evaluate.hybrid import navigation_context, run_outages, window_metrics
from bgfn.studies.outage_sweep.sweep import profile_sweep_plan
from bgfn.paper import nhc_label, test_of
from bgfn.parallel import Runner

#: The stand-in drifts "as a real MEMS IMU does" when its median INS drift lies within this factor of the recorded
#: drive's at every duration (notebook 08; the stand-in's error model: :mod:`bgfn.studies.ins_fidelity.imu_twin`).
DRIFT_TOLERANCE = 1.5
#: Columns of the per-run rows (``tables/kf_ins_drift_runs.csv``).
DRIFT_RUN_COLUMNS: tuple[str, ...] = ("dataset", "test", "start_s", "duration_s", "method", "max_h_m", "final_h_m")
#: Columns of :func:`drift_summary` (``tables/kf_ins_drift.csv``).
DRIFT_COLUMNS: tuple[str, ...] = ("dataset", "test", "duration_s", "method", "n_starts", "median_max_h_m",
                                  "q25_max_h_m", "q75_max_h_m")


def drift_starts(cfg: dict, drive) -> list[float]:
    """The sweep's starts on ``drive`` (``evaluate.sweep`` of the profile; after the filter's start), s."""
    plan = profile_sweep_plan(cfg, drive, evaluate_config(cfg.get("evaluate"), cfg.get("train"))["sweep"])
    return [float(s) for s in plan["start_s"]]


def ins_drift_runs(cfg: dict, drives: list, durations=None, nhc: bool = True,
                   report: Callable[[str], None] | None = None, runner: Runner | None = None) -> pd.DataFrame:
    """INS (and ``INS+NHC``) from every sweep start of every drive.

    Parameters
    ----------
    cfg : dict
        The profile (its ``nav:`` section runs the filter, ``evaluate.sweep`` places the starts).
    drives : list of bgfn.data.Drive
    durations : list of float, optional
        Outage durations, s; default ``evaluate.sweep.durations_s``.
    nhc : bool
        Also the INS with the vehicle constraints (``INS+NHC``).
    report : callable, optional
        Called with one progress line per drive (under ``make reproduce`` the lines go to its log instead,
        :class:`bgfn.parallel.RunProgress`).
    runner : bgfn.parallel.Runner, optional
        Where the drives run (default: one after the other); the rows come back in the drives' order.

    Returns
    -------
    DataFrame
        :data:`DRIFT_RUN_COLUMNS`, one row per drive, start, duration and method.
    """
    ecfg = evaluate_config(cfg.get("evaluate"), cfg.get("train"))
    durations = sorted(float(d) for d in (durations or ecfg["sweep"]["durations_s"]))
    tasks = [(cfg, drive, durations, ecfg["pseudo_gps"], nhc) for drive in drives]
    done = (runner or Runner()).map(drive_drift_rows, tasks,
                                    labels=[drive.name for drive in drives], summary=lambda rows: rows[1],
                                    desc="INS drift", echo=report or (lambda line: None), bar=False)
    return pd.DataFrame([row for rows, _ in done for row in rows], columns=list(DRIFT_RUN_COLUMNS))


def drive_drift_rows(cfg: dict, drive, durations: list[float], pseudo: dict,
                     nhc: bool = True) -> tuple[list[dict], str]:
    """One drive of :func:`ins_drift_runs` (an independent run, ``pseudo`` the evaluation's ``pseudo_gps``): its rows
    and what its progress line says."""
    starts = drift_starts(cfg, drive)
    ctx = navigation_context(drive, cfg.get("nav"), starts)
    windows = [(s, durations[-1]) for s in starts]
    runs = run_outages(ctx, windows, None, "INS", None, pseudo)
    if nhc and ctx.constraints is not None:
        runs += run_outages(ctx, windows, None, nhc_label("INS"), None, pseudo,
                            aids=[ctx.constraints])
    rows = []
    for r in runs:
        for du in durations:
            m = window_metrics(r.errors, r.start, du)
            rows.append({"dataset": drive.name, "test": test_of(drive.name) or "", "start_s": r.start,
                         "duration_s": du, "method": r.method, "max_h_m": m["max_h_m"], "final_h_m": m["final_h_m"]})
    return rows, f"{len(starts)} starts x {len(durations)} durations, {len(runs)} standalone runs"


def drift_summary(runs: pd.DataFrame) -> pd.DataFrame:
    """Median and quartiles of the max horizontal error over the starts, per drive, duration and method."""
    g = runs.groupby(["dataset", "test", "duration_s", "method"], sort=False)["max_h_m"]
    out = g.agg(n_starts="count", median_max_h_m="median", q25_max_h_m=lambda x: float(np.quantile(x, 0.25)),
                q75_max_h_m=lambda x: float(np.quantile(x, 0.75))).reset_index()
    return out[list(DRIFT_COLUMNS)]


def plot_ins_drift(runs: pd.DataFrame, title: str = ""):
    """Max horizontal error of every start against the outage duration, one panel per method, a box per drive."""
    methods = list(dict.fromkeys(runs["method"]))
    names = list(dict.fromkeys(runs["dataset"]))
    durations = sorted(runs["duration_s"].unique())
    fig, axes = plt.subplots(1, len(methods), figsize=(5.0 * len(methods), 3.6), squeeze=False, sharey=True)
    width = 0.8 / max(len(names), 1)
    for ax, method in zip(axes[0], methods):
        for k, name in enumerate(names):
            sel = runs[(runs["method"] == method) & (runs["dataset"] == name)]
            data = [sel.loc[sel["duration_s"] == d, "max_h_m"].to_numpy() for d in durations]
            pos = np.arange(len(durations)) + (k - (len(names) - 1) / 2) * width
            bp = ax.boxplot(data, positions=pos, widths=width * 0.9, patch_artist=True, manage_ticks=False)
            for patch in bp["boxes"]:
                patch.set_facecolor(f"C{k}")
                patch.set_alpha(0.6)
            ax.plot([], [], "s", color=f"C{k}", label=name)
        ax.set_xticks(np.arange(len(durations)), [f"{d:g}" for d in durations])
        ax.set_yscale("log")
        ax.set_xlabel("outage duration (s)")
        ax.set_title(method)
        ax.grid(alpha=0.3)
    axes[0, 0].set_ylabel("max horizontal error (m)")
    axes[0, -1].legend(fontsize=8)
    fig.suptitle(title)
    fig.tight_layout()
    return fig

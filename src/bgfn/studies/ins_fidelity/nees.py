"""Is the filter's covariance honest during an outage? The NEES of the horizontal position at each window's end.

Every aid is fused with the filter's covariance: an *overconfident* filter (covariance too small) under-weights
every aid, an *underconfident* one over-weights them. The normalized estimation error squared of the horizontal
position at the end of each outage window, ``NEES = (e_N / sd_N)^2 + (e_E / sd_E)^2``, is chi-square with 2 degrees
of freedom when the filter is consistent: median 2 ln 2 = 1.39, 95 % below 5.99. Per dataset, method and duration
(the sweep) or outage (the paper's two): the median, the share inside the 95 % bound and a word (within a factor
:data:`FACTOR` of 1.39: consistent). :func:`consistency_scan` (notebook 08) finds which gyro bias instability of
the filter's error model makes the standalone INS of a recorded drive consistent.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Callable

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from bgfn import settings
from bgfn.config import SHARED_TABLES
from bgfn.data.names import dataset_id
from bgfn.data.platforms import write_ran_table
from bgfn.data.registry import SIMULATED_IMU
from bgfn.evaluate.hybrid import navigation_context, run_outages, window_metrics
from bgfn.evaluate.plots import finish_duration_axes
from bgfn.studies.outage_sweep.sweep import profile_sweep_plan
from bgfn.io import save_figure
from bgfn.parallel import Runner

#: chi-square with 2 degrees of freedom: its median (2 ln 2) and its 95 % quantile (-2 ln 0.05).
CHI2_MEDIAN, CHI2_95 = 2.0 * np.log(2.0), -2.0 * np.log(0.05)
#: A median NEES within this factor of :data:`CHI2_MEDIAN` is called consistent.
FACTOR = 3.0
#: Columns of ``tables/outage_nees.csv``.
NEES_COLUMNS: tuple[str, ...] = ("dataset", "window", "duration_s", "method", "runs", "median_nees", "inside_95",
                                 "verdict")


def verdict(median: float) -> str:
    """``consistent`` / ``overconfident`` / ``underconfident`` of a median NEES (module docstring)."""
    if not np.isfinite(median):
        return "not measured"
    return ("overconfident" if median > FACTOR * CHI2_MEDIAN else "underconfident" if median < CHI2_MEDIAN / FACTOR
            else "consistent")


def nees_stats(nees) -> dict:
    """``runs``, ``median_nees``, ``inside_95`` (share at most :data:`CHI2_95`) and ``verdict`` of the horizontal
    NEES of some runs; non-finite values are left out (NaN statistics when none is left)."""
    v = np.asarray(nees, dtype=float)
    v = v[np.isfinite(v)]
    median = float(np.median(v)) if v.size else float("nan")
    return {"runs": int(v.size), "median_nees": median,
            "inside_95": float(np.mean(v <= CHI2_95)) if v.size else float("nan"), "verdict": verdict(median)}


def _summarize(rows: pd.DataFrame, keys: list[str]) -> pd.DataFrame:
    """:func:`nees_stats` of ``rows['nees_h']`` per group of ``keys`` (groups with a finite NEES only)."""
    ok = rows[np.isfinite(rows["nees_h"].astype(float))]
    out = [{**dict(zip(keys, k if isinstance(k, tuple) else (k,))), **nees_stats(g["nees_h"])}
           for k, g in ok.groupby(keys, sort=False)]
    return pd.DataFrame(out, columns=[*keys, "runs", "median_nees", "inside_95", "verdict"])


def nees_summary(sweep: pd.DataFrame | None, results: dict | None = None) -> pd.DataFrame:
    """The NEES per dataset, method and sweep duration (``window`` ``sweep``) and per paper outage (``window``
    ``outage <k>``, ``duration_s`` its length) from the sweep rows and the outage tables' per-seed rows
    (:class:`bgfn.evaluate.tables.TableResult`)."""
    parts = []
    if sweep is not None and len(sweep) and "nees_h" in sweep.columns:
        s = _summarize(sweep, ["dataset", "duration_s", "method"])
        parts.append(s.assign(window="sweep"))
    for name, res in (results or {}).items():
        ps = res.per_seed
        if "nees_h" not in ps.columns:
            continue
        durations = {i + 1: float(d) for i, (_, d) in enumerate(res.windows)}
        s = _summarize(ps.assign(dataset=name), ["dataset", "outage", "method"])
        parts.append(s.assign(window=[f"outage {int(o)}" for o in s["outage"]],
                              duration_s=[durations.get(int(o), np.nan) for o in s["outage"]]).drop(columns="outage"))
    if not parts:
        return pd.DataFrame(columns=list(NEES_COLUMNS))
    return pd.concat(parts, ignore_index=True)[list(NEES_COLUMNS)]


def plot_nees(summary: pd.DataFrame, dataset: str):
    """Median NEES against the outage duration (the sweep), one line per method, with chi-square(2)'s median and
    95 % bound."""
    fig, ax = plt.subplots(figsize=(6.4, 3.6))
    g = summary[(summary["dataset"] == dataset) & (summary["window"] == "sweep")]
    for m, h in g.groupby("method", sort=False):
        h = h.sort_values("duration_s")
        ax.plot(h["duration_s"], h["median_nees"], marker="o", label=m)
    ax.axhline(CHI2_MEDIAN, color="grey", ls="--", lw=1, label="consistent: median")
    ax.axhline(CHI2_95, color="grey", ls=":", lw=1, label="consistent: 95 % bound")
    return finish_duration_axes(fig, ax, "median horizontal NEES",
                                f"{dataset}: the filter's covariance against its errors at the outage end")


def nees_section(out: str | Path, results: dict, sweep: pd.DataFrame | None) -> pd.DataFrame:
    """Notebook 06: :func:`nees_summary` written to ``tables/outage_nees.csv``, one figure per sweep dataset
    (``figures/outage_nees_<id>.png``); returns the summary (in words:
    :func:`bgfn.report.ins_fidelity_words.nees_lines`)."""
    summary = nees_summary(sweep, results)
    write_ran_table(Path(out) / "tables" / SHARED_TABLES["nees"], summary, out, float_format="%.4f")
    for name in summary.loc[summary["window"] == "sweep", "dataset"].unique():
        fig = plot_nees(summary, name)
        save_figure(fig, Path(out) / "figures" / f"outage_nees_{dataset_id(name)}.png")
        plt.close(fig)
    return summary


#: Outage durations of the scan, s, where the sweep's starts leave room for them (:func:`scan_durations`).
SCAN_DURATIONS_S: tuple[float, ...] = (30.0, 60.0)
#: Columns of ``tables/kf_nees_scan.csv``.
SCAN_COLUMNS: tuple[str, ...] = ("dataset", "gyro_bias_instability_dps", "profile", "duration_s", "runs",
                                 "median_nees", "inside_95", "median_max_h_m", "verdict")


def scan_options(cfg: dict) -> dict:
    """``evaluate.nees_scan`` with its defaults (:class:`bgfn.settings.NeesScan`: the gyro bias instabilities scanned on
    a recorded drive, half the MPU-6000 profile's 0.01 deg/s up to 0.3 deg/s and dense where the recorded drive and
    its trajectory twin turn consistent; those of the twins, null: the same; the twins' seeds)."""
    return {**settings.defaults("evaluate.nees_scan"), **((cfg.get("evaluate") or {}).get("nees_scan") or {})}


def scan_point(cfg: dict, drive, value_dps: float, own: bool, starts: list[float], durations) -> list[dict]:
    """One point of :func:`consistency_scan`: the standalone INS of ``drive`` from ``starts`` with the gyro bias
    instability ``value_dps`` (deg/s, every axis), one row per duration (:data:`SCAN_COLUMNS`)."""
    errors = {**drive.meta["imu_errors"], "gyro_bias_instability": [float(np.radians(value_dps))] * 3}
    d = dataclasses.replace(drive, meta={**drive.meta, "imu_errors": errors})
    ctx = navigation_context(d, cfg.get("nav"), starts)
    runs = run_outages(ctx, [(s, max(durations)) for s in starts], None, "INS", None, cfg["evaluate"]["pseudo_gps"])
    rows = []
    for du in durations:
        m = [window_metrics(r.errors, r.start, du, r.sd) for r in runs]
        rows.append({"dataset": drive.name, "gyro_bias_instability_dps": float(f"{value_dps:.4g}"), "profile": own,
                     "duration_s": du, **nees_stats([x["nees_h"] for x in m]),
                     "median_max_h_m": float(np.median([x["max_h_m"] for x in m]))})
    return rows


def scan_durations(sweep: dict) -> list[float]:
    """The durations of the NEES scan: those of :data:`SCAN_DURATIONS_S` that the sweep's starts leave room for (at
    most its longest duration), else the sweep's longest alone (a short log's scan speaks of what ran)."""
    longest = max(float(d) for d in sweep["durations_s"])
    return [d for d in SCAN_DURATIONS_S if d <= longest] or [longest]


def brackets_crossing(scan: pd.DataFrame) -> bool:
    """Whether the scan of one drive has, at every duration, its median NEES above :data:`CHI2_MEDIAN` at its smallest
    gyro bias instability and at or below it at some larger one: :func:`effective_instability` then interpolates
    inside the scan's grid, and a wider grid that adds no crossing below it gives the same value."""
    for _, g in scan.groupby("duration_s", sort=False):
        y = g.sort_values("gyro_bias_instability_dps", kind="stable")["median_nees"].to_numpy(float)
        if not (y[0] > CHI2_MEDIAN and np.any(y <= CHI2_MEDIAN)):
            return False
    return len(scan) > 0


def consistency_scan(cfg: dict, drives, durations=None, values_dps=None,
                     report: Callable[[str], None] | None = None, runner: Runner | None = None) -> pd.DataFrame:
    """The INS NEES of every recorded drive among ``drives`` from the sweep's starts (``evaluate.sweep``) with the
    filter's gyro bias instability set to each of ``values_dps`` (deg/s, every axis) and to the profile's own
    (``profile`` True): median NEES, share inside the 95 % bound, median max horizontal error, per duration
    (default :func:`scan_durations`). ``values_dps`` defaults to ``evaluate.nees_scan.gyro_bias_dps``; a drive whose
    scan on that grid does not bracket its crossing (:func:`brackets_crossing`: a profile's grid may be a narrow one)
    is scanned again on it widened by the default grid.

    The points are independent runs (:func:`scan_point`), spread over ``runner`` (default: one after the other);
    the rows come back in the grid's order whatever the number of jobs."""
    widen = values_dps is None
    tasks, labels = [], []
    values_dps = scan_options(cfg)["gyro_bias_dps"] if values_dps is None else values_dps
    durations = scan_durations(cfg["evaluate"]["sweep"]) if durations is None else durations
    for drive in drives:
        if drive.name in SIMULATED_IMU:
            continue
        starts = [float(x) for x in profile_sweep_plan(cfg, drive, cfg["evaluate"]["sweep"])["start_s"]]
        own = float(np.degrees(np.mean(drive.meta["imu_errors"]["gyro_bias_instability"])))
        grid = [float(v) for v in values_dps if not np.isclose(v, own, rtol=1e-3)]   # the profile's own once
        for value in sorted(grid + [own]):
            tasks.append((cfg, drive, value, bool(value == own), starts, tuple(durations)))
            labels.append(f"{drive.name} gyro bias instability {value:g} deg/s")

    def line(rows: list[dict]) -> str:
        return "INS median NEES " + ", ".join(f"{r['median_nees']:.3g} at {r['duration_s']:g} s" for r in rows)

    done = (runner or Runner()).map(scan_point, tasks, labels=labels, summary=line, desc="NEES scan",
                                    echo=report if report is not None else (lambda _line: None), bar=False)
    scan = pd.DataFrame([row for rows in done for row in rows], columns=list(SCAN_COLUMNS))
    if not widen:
        return scan
    wide = sorted({*map(float, values_dps), *map(float, settings.defaults("evaluate.nees_scan")["gyro_bias_dps"])})
    narrow = [d for d in drives if d.name not in SIMULATED_IMU
              and not brackets_crossing(scan[scan["dataset"] == d.name])]
    if narrow and wide != sorted(map(float, values_dps)):
        again = consistency_scan(cfg, narrow, durations, wide, report, runner)
        names = {d.name for d in narrow}
        scan = pd.concat([(again if d.name in names else scan).query("dataset == @d.name")
                          for d in drives if d.name not in SIMULATED_IMU], ignore_index=True)
    return scan

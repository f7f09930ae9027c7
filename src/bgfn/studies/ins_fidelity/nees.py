"""Is the filter's covariance honest during an outage? The NEES of the horizontal position at each window's end.

Every aid is fused with the filter's covariance, so a filter that believes its position better than it is (its
covariance too small: *overconfident*) under-weights every aid, and one that believes it worse (*underconfident*)
over-weights them. The normalized estimation error squared of the horizontal position against the filter's own
std at the end of each outage window (:func:`bgfn.evaluate.hybrid.window_metrics`)::

    NEES = (e_N / sd_N)^2 + (e_E / sd_E)^2

is chi-square with 2 degrees of freedom when the filter is consistent: median 2 ln 2 = 1.39, 95 % of the runs
below 5.99. The north-east correlation of the covariance is left out (the filter keeps only the stds of its
states per epoch); with it the NEES could only be larger or smaller by the correlation's effect on the ellipse, not
by the orders of magnitude that separate a consistent from an inconsistent filter.

Per dataset, method and duration (the sweep) or outage (the paper's two): the median NEES, the share of runs
inside the 95 % bound, and a word: *consistent* when the median lies within a factor :data:`FACTOR` of 1.39,
*overconfident* above, *underconfident* below.

Which setting explains an inconsistent filter? :func:`consistency_scan` (notebook 08) runs the standalone INS from
the sweep's starts of each recorded drive (a simulated IMU's error model is known exactly) with the gyro bias
instability of the filter's error model set to each value of a grid: the INS drift of a MEMS IMU over tens of
seconds is the heading error its gyro biases build, and a filter that under-states them is overconfident.
"""

from __future__ import annotations

import dataclasses
from pathlib import Path
from typing import Callable

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from bgfn.config import SHARED_TABLES
from bgfn.data.names import dataset_id
from bgfn.data.registry import SIMULATED_IMU
from bgfn.evaluate.hybrid import navigation_context, run_outages, window_metrics
from bgfn.evaluate.plots import finish_duration_axes
from bgfn.studies.outage_sweep.sweep import profile_sweep_plan
from bgfn.io import atomic_write_csv, save_figure
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


def nees_lines(summary: pd.DataFrame, methods=("INS", "INS+NHC")) -> list[str]:
    """Per dataset, whether the filter is consistent during outages: the INS rows (and INS+NHC) in the sweep at
    each duration, else in the paper's outages."""
    lines = []
    for ds, g in summary.groupby("dataset", sort=False):
        part = []
        for m in methods:
            h = g[(g["method"] == m) & (g["window"] == "sweep")]
            h = h if len(h) else g[g["method"] == m]
            if len(h):
                part.append(f"{m} " + ", ".join(f"{r.window if r.window != 'sweep' else f'{r.duration_s:g} s'}: "
                                                 f"median {r.median_nees:.3g}, {100 * r.inside_95:.0f} % inside, "
                                                 f"{r.verdict}" for r in h.itertuples()))
        if part:
            lines.append(f"{ds}, NEES of the horizontal position at the outage end against the filter's covariance "
                         f"(consistent: median {CHI2_MEDIAN:.2f}, 95 % below {CHI2_95:.2f}): " + "; ".join(part) + ".")
    return lines


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


def nees_section(out: str | Path, results: dict, sweep: pd.DataFrame | None) -> list[str]:
    """Notebook 04: :func:`nees_summary` written to ``tables/outage_nees.csv``, one figure per sweep dataset
    (``figures/outage_nees_<id>.png``), and :func:`nees_lines`."""
    summary = nees_summary(sweep, results)
    atomic_write_csv(Path(out) / "tables" / SHARED_TABLES["nees"], summary, float_format="%.4f")
    for name in summary.loc[summary["window"] == "sweep", "dataset"].unique():
        fig = plot_nees(summary, name)
        save_figure(fig, Path(out) / "figures" / f"outage_nees_{dataset_id(name)}.png")
        plt.close(fig)
    return nees_lines(summary)


#: Gyro bias instabilities the scan tries, deg/s (half the MPU-6000 profile's 0.01 deg/s up to 0.3 deg/s; dense where the
#: recorded drive and its trajectory twin turn consistent, :mod:`bgfn.studies.ins_fidelity.imu_twin`).
SCAN_GYRO_BIAS_DPS: tuple[float, ...] = (0.005, 0.01, 0.02, 0.03, 0.05, 0.1, 0.2, 0.3)
#: Outage durations of the scan, s, where the sweep's starts leave room for them (:func:`scan_durations`).
SCAN_DURATIONS_S: tuple[float, ...] = (30.0, 60.0)
#: Columns of ``tables/kf_nees_scan.csv``.
SCAN_COLUMNS: tuple[str, ...] = ("dataset", "gyro_bias_instability_dps", "profile", "duration_s", "runs",
                                 "median_nees", "inside_95", "median_max_h_m", "verdict")


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


def consistency_scan(cfg: dict, drives, durations=None, values_dps=SCAN_GYRO_BIAS_DPS,
                     report: Callable[[str], None] | None = None, runner: Runner | None = None) -> pd.DataFrame:
    """The INS NEES of every recorded drive among ``drives`` from the sweep's starts (``evaluate.sweep``) with the
    filter's gyro bias instability set to each of ``values_dps`` (deg/s, every axis) and to the profile's own
    (``profile`` True): median NEES, share inside the 95 % bound, median max horizontal error, per duration
    (default :func:`scan_durations`).

    The points are independent runs (:func:`scan_point`), spread over ``runner`` (default: one after the other);
    the rows come back in the grid's order whatever the number of jobs."""
    tasks, labels = [], []
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
    return pd.DataFrame([row for rows in done for row in rows], columns=list(SCAN_COLUMNS))


def scan_lines(scan: pd.DataFrame) -> list[str]:
    """Per recorded drive: the profile's setting and its word, and the values of the grid that are consistent."""
    lines = []
    for ds, g in scan.groupby("dataset", sort=False):
        longest = g[g["duration_s"] == g["duration_s"].max()]
        own = longest[longest["profile"]]
        ok = longest.loc[longest["verdict"] == "consistent", "gyro_bias_instability_dps"]
        lines.append(f"{ds}: with the profile's gyro bias instability ({own['gyro_bias_instability_dps'].iloc[0]:g} "
                     f"deg/s) the INS is {own['verdict'].iloc[0]} at {longest['duration_s'].iloc[0]:g} s (median NEES "
                     f"{own['median_nees'].iloc[0]:.3g}); consistent with "
                     + (", ".join(f"{v:g}" for v in ok) + " deg/s" if len(ok) else "no value of the grid") + ".")
    return lines

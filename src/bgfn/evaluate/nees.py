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
"""

from __future__ import annotations

from pathlib import Path

import matplotlib.pyplot as plt
import numpy as np
import pandas as pd

from bgfn.config import SHARED_TABLES
from bgfn.data.names import dataset_id
from bgfn.io import atomic_write_csv, save_figure

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


def _summarize(rows: pd.DataFrame, keys: list[str]) -> pd.DataFrame:
    ok = rows[np.isfinite(rows["nees_h"].astype(float))]
    out = ok.groupby(keys, sort=False).agg(runs=("nees_h", "size"), median_nees=("nees_h", "median"),
                                            inside_95=("nees_h", lambda x: float(np.mean(x <= CHI2_95))))
    out = out.reset_index()
    out["verdict"] = out["median_nees"].map(verdict)
    return out


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
    ax.set_yscale("log")
    ax.set_xlabel("outage duration (s)")
    ax.set_ylabel("median horizontal NEES")
    ax.grid(alpha=0.3, which="both")
    ax.legend(fontsize=7, ncol=2)
    ax.set_title(f"{dataset}: the filter's covariance against its errors at the outage end", fontsize=10)
    fig.tight_layout()
    return fig


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

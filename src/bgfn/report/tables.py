"""The tables of the results page: the paper-layout table's styling, BGFN's reduction against INS, and the
energy, Kalman filter, training and sweep tables built from notebooks 02-05's files.

The paper's layout itself (rows ``Outage k``, columns method x East/North) is :func:`bgfn.paper.layout`;
this module only styles it. Reduction against INS, as in the paper's text: ``100 (INS - method) / INS`` of
the max error per axis (positive: the method's error is smaller), computed by
:func:`bgfn.evaluate.error_reduction`, the same function notebook 04 shows.
"""

from __future__ import annotations

import math
from typing import Iterable, Sequence

import numpy as np
import pandas as pd

from bgfn.evaluate import error_reduction
from bgfn.paper import DECIMALS, PAPER_METHODS, claim_for, label, published_test
from bgfn.report.sentences import network_improved


# ----------------------------------------------------------------------------------------------- styling
def best_mask(layout: pd.DataFrame) -> pd.DataFrame:
    """True where a value is the smallest of its row among the methods of one source and axis (ties: all)."""
    mask = pd.DataFrame(False, index=layout.index, columns=layout.columns)
    for src in layout.columns.get_level_values("source").unique():
        for axis in layout.columns.get_level_values("axis").unique():
            cols = [c for c in layout.columns if c[0] == src and c[2] == axis]
            vals = layout[cols].round(DECIMALS)
            mins = vals.min(axis=1)
            for c in cols:
                mask[c] = vals[c].eq(mins) & vals[c].notna()
    return mask


#: CSS of the tables on the results page: small type and tight cells, so that the paper's 16-column layout fits
#: the book's text width.
TABLE_STYLES: list[dict] = [
    {"selector": "", "props": "font-size: 0.78em; border-collapse: collapse; margin-bottom: 0.4em;"},
    {"selector": "th, td", "props": "padding: 2px 5px; text-align: right;"},
    {"selector": "td", "props": "white-space: nowrap;"},
    {"selector": "th.col_heading", "props": "text-align: center;"},
    {"selector": "th.col_heading.level0", "props": "border-bottom: 1px solid #888;"},
    {"selector": "caption", "props": "caption-side: top; font-size: 1.15em; text-align: left; padding-bottom: 4px;"},
]


def compact(styler, caption: str | None = None):
    """Apply :data:`TABLE_STYLES` (and a caption) to a pandas Styler."""
    styler = styler.set_table_styles(TABLE_STYLES, overwrite=False)
    return styler.set_caption(caption) if caption else styler


def style_layout(layout: pd.DataFrame, caption: str):
    """The paper-layout table as a pandas Styler: one decimal, the best method per source/axis in bold, a rule
    before every method group and a heavier one before the paper's group."""
    mask = best_mask(layout)
    css = mask.replace({True: "font-weight: bold;", False: ""}).astype(str)
    prev = None
    for c in layout.columns:
        if prev is not None and c[0] != prev[0]:
            css[c] += " border-left: 2px solid #555;"
        elif prev is not None and c[1] != prev[1]:
            css[c] += " border-left: 1px solid #ccc;"
        prev = c
    shown = layout.copy()
    shown.columns = shown.columns.set_names([None] * shown.columns.nlevels)
    shown.index.name = None
    css.columns = shown.columns
    css.index = shown.index
    sty = shown.style.format(f"{{:.{DECIMALS}f}}", na_rep="-").apply(lambda _: css, axis=None)
    return compact(sty, caption).set_table_styles(
        [{"selector": "", "props": "font-size: 0.74em;"}, {"selector": "th, td", "props": "padding: 2px 3px;"},
         {"selector": "th.row_heading", "props": "white-space: nowrap;"}], overwrite=False)


# ----------------------------------------------------------------------------------------------- reductions
def reductions(table: pd.DataFrame, reference: str = "INS", methods: Iterable[str] | None = None) -> pd.DataFrame:
    """Reduction of the max east/north error against ``reference``: ``100 (ref - method) / ref`` (%).

    :func:`bgfn.evaluate.error_reduction` (the one place of the arithmetic), kept to ``methods`` when given.

    Returns
    -------
    DataFrame
        ``outage, method, east_pct, north_pct``; rows only for outages where ``reference`` is present.
    """
    red = error_reduction(table, reference)
    if methods is not None:
        red = red[red["method"].isin(set(methods))].reset_index(drop=True)
    return red


def reduction_comparison(ours: pd.DataFrame | None, paper: pd.DataFrame, claims: dict, test: str,
                         method: str = "BGFN", reference: str = "INS") -> pd.DataFrame:
    """BGFN's reduction against INS per outage: ours, the paper's table (recomputed), the paper's text claim.

    Columns: a MultiIndex ``(source, axis)`` with sources ``ours``, ``paper (table)``, ``paper (text)``;
    rows ``Outage k``. ``paper`` is the table beside ours (:func:`bgfn.paper.published_values`), and the text's
    claims are those of the same test (beside the real drive: the field test's).
    """
    parts = {"ours": ours, "paper (table)": paper}
    red = {k: (reductions(v, reference, [method]).set_index("outage") if v is not None else None)
           for k, v in parts.items()}
    outages = sorted({int(o) for v in parts.values() if v is not None for o in v["outage"]})
    data = {}
    for src in ("ours", "paper (table)", "paper (text)"):
        for axis in ("east", "north"):
            vals = []
            for o in outages:
                if src == "paper (text)":
                    c = claim_for(claims, published_test(test), o)
                    vals.append(float(c[axis]) if c and axis in c else np.nan)
                else:
                    r = red[src]
                    vals.append(float(r.loc[o, f"{axis}_pct"]) if r is not None and o in r.index else np.nan)
            data[(src, axis.capitalize())] = vals
    return pd.DataFrame(data, index=pd.Index([f"Outage {o}" for o in outages], name=f"{method} vs {reference} (%)"),
                        columns=pd.MultiIndex.from_tuples(list(data), names=["source", "axis"]))


# ----------------------------------------------------------------------------------------------- other tables
def energy_table(energy: dict | None, claims: dict) -> pd.DataFrame:
    """Energy per prediction and the reduction, ours (``energy.json``) beside the paper's claim; our reduction
    empty when BGFN did not train (:func:`bgfn.report.sentences.network_improved`: no saving is claimed)."""
    paper_red = claims.get("energy_reduction_vs_transformer_pct")
    rows = {"BGFN energy per prediction (µJ)": (np.nan, np.nan),
            "Transformer energy per prediction (µJ)": (np.nan, np.nan),
            "BGFN MACs per prediction": (np.nan, np.nan), "BGFN synaptic operations per prediction": (np.nan, np.nan),
            "Transformer MACs per prediction": (np.nan, np.nan),
            "energy reduction (%)": (np.nan, paper_red)}
    if energy:
        e, macs, sops = energy.get("energy_uj_per_prediction", {}), energy.get("macs", {}), energy.get("sops", {})
        rows.update({
            "BGFN energy per prediction (µJ)": (e.get("bgfn", np.nan), np.nan),
            "Transformer energy per prediction (µJ)": (e.get("transformer", np.nan), np.nan),
            "BGFN MACs per prediction": (macs.get("bgfn", np.nan), np.nan),
            "BGFN synaptic operations per prediction": (sops.get("bgfn", np.nan), np.nan),
            "Transformer MACs per prediction": (macs.get("transformer", np.nan), np.nan),
            "energy reduction (%)": (energy.get("reduction_pct", np.nan) if network_improved(energy) else np.nan,
                                     paper_red)})
    return pd.DataFrame([[float(a), float(b) if b is not None else np.nan] for a, b in rows.values()],
                        index=list(rows), columns=["ours", "paper"])


#: What a GPS-aided error is measured against (``kf_table``'s ``reference`` column): a reference independent of the
#: fixes, or the fixes themselves (its RMS then measures how closely the filter follows them, no accuracy).
REFERENCE_KINDS = {False: "independent", True: "the GNSS itself"}


def kf_table(kf: dict | None) -> pd.DataFrame | None:
    """Full-drive GPS/INS filter errors per dataset (``kf_baseline.json``): updates, NIS, RMS position/attitude, and
    what the reference is (:data:`REFERENCE_KINDS`); against a reference that is the GNSS the position RMS is left
    empty."""
    if not kf:
        return None
    rows = []
    for name, d in kf.get("datasets", {}).items():
        same = bool(d.get("reference_equals_gnss", False))
        rms = {k: v for k, v in d.get("rms", {}).items() if not same or k not in ("north", "east", "down",
                                                                                   "horizontal")}
        rows.append({"dataset": name, "GNSS updates": d.get("gnss_updates"),
                     "mean NIS": d.get("mean_nis"), "NIS dof": d.get("mean_nis_dof"),
                     "RMS north (m)": rms.get("north", np.nan), "RMS east (m)": rms.get("east", np.nan),
                     "RMS down (m)": rms.get("down", np.nan), "RMS horizontal (m)": rms.get("horizontal", np.nan),
                     "RMS yaw (deg)": math.degrees(rms["yaw"]) if rms.get("yaw") is not None else np.nan,
                     "reference": REFERENCE_KINDS[same]})
    return pd.DataFrame(rows).set_index("dataset")


#: Reference columns of the training tables -> their short labels (:func:`bgfn.learning.reference_rmse`).
REFERENCE_LABELS: dict[str, str] = {"val_rmse_zero_m": "zero", "val_rmse_last_m": "last increment",
                                    "val_rmse_ins_m": "INS increment"}
#: Columns of ``tables/training_summary.csv`` shown on the page, with their labels.
TRAINING_COLUMNS: dict[str, str] = {
    "params": "parameters", "lr": "learning rate", "seeds": "seeds", "epochs_mean": "epochs",
    "train_time_s_mean": "time (s)",
    "val_rmse_m_mean": "val. RMSE (m)", "val_rmse_m_std": "std over seeds (m)",
    **{col: f"{label} (m)" for col, label in REFERENCE_LABELS.items()}}


def fmt_num(v) -> str:
    """Readable number for the summary tables: integers as integers, no exponents for ordinary values."""
    try:
        x = float(v)
    except (TypeError, ValueError):
        return str(v)
    if not math.isfinite(x):
        return "-"
    if x.is_integer() and abs(x) < 1e12:
        return f"{int(x):,}"
    a = abs(x)
    if a >= 100:
        return f"{x:,.1f}"
    if a >= 1:
        return f"{x:.2f}"
    if a >= 1e-3:
        return f"{x:.3g}"
    return f"{x:.2e}"


def training_table(summary: pd.DataFrame | None, times: pd.DataFrame | None = None) -> pd.DataFrame | None:
    """``tables/training_summary.csv`` (with the wall-clock times of ``tables/training_times.csv`` when given)
    with readable labels, indexed by (dataset, method)."""
    if summary is None:
        return None
    if times is not None:
        summary = summary.merge(times, on=["dataset", "method"], how="left")
    cols = [c for c in TRAINING_COLUMNS if c in summary.columns]
    shown = summary.assign(method=summary["method"].map(lambda m: label(m)))
    return shown.set_index(["dataset", "method"])[cols].rename(columns=TRAINING_COLUMNS)


def sweep_table(summary: pd.DataFrame | None, methods: Sequence[str] = PAPER_METHODS + ("Transformer", "GPS"),
                decimals: int = 1) -> pd.DataFrame | None:
    """``tables/outage_sweep_summary.csv`` as ``median [lo, hi]`` per (dataset, method) and outage duration."""
    if summary is None or summary.empty:
        return None
    cell = summary.assign(text=[f"{r.median_m:.{decimals}f} [{r.ci_lo_m:.{decimals}f}, {r.ci_hi_m:.{decimals}f}]"
                                for r in summary.itertuples(index=False)])
    wide = cell.pivot_table(index=["dataset", "method"], columns="duration_s", values="text", aggfunc="first")
    order = [i for m in methods for i in wide.index if i[1] == m] + [i for i in wide.index if i[1] not in methods]
    wide = wide.reindex(order)
    wide.columns = [f"{c:g} s" for c in wide.columns]
    n = summary.groupby(["dataset", "method"])["n"].max()
    wide.insert(0, "runs", n.reindex(wide.index).astype(int))
    return wide

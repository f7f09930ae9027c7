"""The results page (notebook 06): our tables beside the paper's, where each number came from, and plain
sentences computed from the numbers.

Inputs (all written by notebooks 01-05 under ``results/<profile>/``; a missing file is reported, never
fatal):

- ``tables/outage_dataset.csv``, ``tables/outage_field.csv`` (notebook 04): ``outage, method, max_east_m,
  max_north_m, rmse_h_m, final_h_m`` -- paper Tables ``tab-out1-exin`` and ``tab-real``;
- ``data/paper/outage_max_errors.csv`` and ``data/paper/claims.yaml``: the paper's published values (shown
  in a column group labelled *paper*; never used to choose anything);
- ``kf_baseline.json`` (02), ``training.json`` and ``tables/training_summary.csv`` (03),
  ``outage_evaluation.json`` and ``tables/outage_sweep_summary.csv`` (04), ``energy.json`` (05), the model
  cards ``models/<dataset>/<method>_seed<k>.json`` (03/04): metadata lines under every table.

Reduction against INS, as in the paper's text: ``100 (INS - method) / INS`` of the max error per axis
(positive: the method's error is smaller).
"""

from __future__ import annotations

import json
import math
from pathlib import Path
from typing import Any, Iterable, Sequence

import numpy as np
import pandas as pd

from bgfn import checkpoints
from bgfn.config import PROJECT_ROOT
from bgfn.paper import AXES, DECIMALS, PAPER_METHODS, TESTS, claim_for, label, test_of

#: Everything BGFN is compared with on this page (Transformer: ANN twin; GPS: the lower bound).
BASELINES: tuple[str, ...] = ("INS", "MLP", "AT-LSTM", "Transformer", "GPS")
#: Extra rows of our tables that the paper does not have, and what they are.
EXTRA_METHODS: dict[str, str] = {"Transformer": "the ANN twin of BGFN, not in the paper",
                                 "GPS": "the GPS-aided solution over the same window: the lower bound"}
EXTRA_TAGS: dict[str, str] = {"Transformer": "ANN twin", "GPS": "lower bound"}


# ----------------------------------------------------------------------------------------------- reading
def rel(path: str | Path) -> str:
    """``path`` relative to the project root (for messages), else as given."""
    p = Path(path)
    try:
        return p.resolve().relative_to(PROJECT_ROOT).as_posix()
    except ValueError:
        return str(p)


def read_csv(path: str | Path) -> pd.DataFrame | None:
    """A CSV table (``#`` comment lines skipped), or ``None`` when the file does not exist."""
    path = Path(path)
    if not path.is_file():
        return None
    return pd.read_csv(path, comment="#")


def read_json(path: str | Path) -> dict | None:
    """A JSON file as a dict, or ``None`` when it does not exist."""
    path = Path(path)
    if not path.is_file():
        return None
    return json.loads(path.read_text(encoding="utf-8"))


def missing_note(path: str | Path, what: str, producer: str) -> str:
    """Markdown line for a table or figure that is not there (instead of failing)."""
    return f"*`{rel(path)}` is missing: {what} was not produced for this profile ({producer}).*"


# ----------------------------------------------------------------------------------------------- tables
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


def reductions(table: pd.DataFrame, reference: str = "INS", methods: Iterable[str] | None = None) -> pd.DataFrame:
    """Reduction of the max east/north error against ``reference``: ``100 (ref - method) / ref`` (%).

    Returns
    -------
    DataFrame
        ``outage, method, east_pct, north_pct``; rows only for outages where ``reference`` is present.
    """
    rows = []
    keep = None if methods is None else set(methods)
    for o, g in table.groupby("outage", sort=True):
        g = g.set_index("method")
        if reference not in g.index:
            continue
        for m in g.index:
            if m == reference or (keep is not None and m not in keep):
                continue
            ref = g.loc[reference]
            pct = {f"{axis.lower()}_pct": 100.0 * (ref[col] - g.loc[m, col]) / ref[col] for col, axis in AXES}
            rows.append({"outage": int(o), "method": m, **pct})
    return pd.DataFrame(rows, columns=["outage", "method", "east_pct", "north_pct"])


def reduction_comparison(ours: pd.DataFrame | None, paper: pd.DataFrame, claims: dict, test: str,
                         method: str = "BGFN", reference: str = "INS") -> pd.DataFrame:
    """BGFN's reduction against INS per outage: ours, the paper's table (recomputed), the paper's text claim.

    Columns: a MultiIndex ``(source, axis)`` with sources ``ours``, ``paper (table)``, ``paper (text)``;
    rows ``Outage k``.
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
                    c = claim_for(claims, test, o)
                    vals.append(float(c[axis]) if c and axis in c else np.nan)
                else:
                    r = red[src]
                    vals.append(float(r.loc[o, f"{axis}_pct"]) if r is not None and o in r.index else np.nan)
            data[(src, axis.capitalize())] = vals
    return pd.DataFrame(data, index=pd.Index([f"Outage {o}" for o in outages], name=f"{method} vs {reference} (%)"),
                        columns=pd.MultiIndex.from_tuples(list(data), names=["source", "axis"]))


def energy_table(energy: dict | None, claims: dict) -> pd.DataFrame:
    """Energy per prediction and the reduction, ours (``energy.json``) beside the paper's claim."""
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
            "energy reduction (%)": (energy.get("reduction_pct", np.nan), paper_red)})
    return pd.DataFrame([[float(a), float(b) if b is not None else np.nan] for a, b in rows.values()],
                        index=list(rows), columns=["ours", "paper"])


def kf_table(kf: dict | None) -> pd.DataFrame | None:
    """Full-drive GPS/INS filter errors per dataset (``kf_baseline.json``): updates, NIS, RMS position/attitude."""
    if not kf:
        return None
    rows = []
    for name, d in kf.get("datasets", {}).items():
        rms = d.get("rms", {})
        rows.append({"dataset": name, "GNSS updates": d.get("gnss_updates"),
                     "mean NIS": d.get("mean_nis"), "NIS dof": d.get("mean_nis_dof"),
                     "RMS north (m)": rms.get("north"), "RMS east (m)": rms.get("east"),
                     "RMS down (m)": rms.get("down"), "RMS horizontal (m)": rms.get("horizontal"),
                     "RMS yaw (deg)": math.degrees(rms["yaw"]) if rms.get("yaw") is not None else np.nan})
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
#: Method ids of the model cards and training tables -> labels of the paper's tables.


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


# ----------------------------------------------------------------------------------------------- provenance
def model_cards(profile: str, dataset: str, results_root: str | Path | None = None) -> list[dict]:
    """The model cards ``results/<profile>/models/<dataset>/<method>_seed<k>.json`` (fold models excluded)."""
    from bgfn.config import RESULTS_ROOT

    d = Path(results_root or RESULTS_ROOT) / profile / "models" / dataset
    cards = []
    for p in checkpoints.cards(d):
        try:
            cards.append({**json.loads(p.read_text(encoding="utf-8")), "_file": rel(p)})
        except json.JSONDecodeError:
            continue
    return cards


def _fmt_size(method: str, size_cfg: dict) -> str:
    keys = {"bgfn": ("dim", "ffn_dim", "depth", "heads", "time_steps"),
            "transformer": ("dim", "ffn_dim", "depth", "heads", "time_steps")}.get(method)
    items = [(k, size_cfg[k]) for k in (keys or sorted(size_cfg)) if k in size_cfg]
    names = {"time_steps": "T_s", "ffn_dim": "FFN"}
    return ", ".join(f"{names.get(k, k)} {v}" for k, v in items)


def cards_line(cards: list[dict]) -> str:
    """One line on the trained networks behind a table: methods, seeds, size block, window, epochs."""
    if not cards:
        return "no model cards found"
    methods = list(dict.fromkeys(c.get("method") for c in cards))
    seeds = sorted({int(c["seed"]) for c in cards if c.get("seed") is not None})
    sizes = sorted({str(c.get("size")) for c in cards if c.get("size")})
    windows = sorted({int(c["options"]["window"]) for c in cards if c.get("options", {}).get("window")})
    epochs = [int(c["epochs_run"]) for c in cards if c.get("epochs_run") is not None]
    by = sorted({str(c.get("trained_by")) for c in cards if c.get("trained_by")})
    bgfn = next((c for c in cards if c.get("method") == "bgfn" and c.get("size_cfg")), None)
    parts = [f"networks {', '.join(methods)}", f"seeds {', '.join(map(str, seeds)) or '?'}",
             f"size block {', '.join(sizes) or '?'}"]
    if bgfn:
        parts.append(f"BGFN {_fmt_size('bgfn', bgfn['size_cfg'])}")
    if windows:
        parts.append(f"window N = {', '.join(map(str, windows))}")
    if epochs:
        parts.append(f"epochs run {min(epochs)}" + (f"-{max(epochs)}" if max(epochs) != min(epochs) else ""))
    if by:
        parts.append(f"trained by {', '.join(by)}")
    return "; ".join(parts)


def meta_line(meta: dict | None, current: dict | None = None) -> str:
    """Profile, parameter file (hash, and whether it changed since), commit and key versions of a run."""
    if not meta:
        return "no run metadata recorded"
    sha = str(meta.get("params_sha256") or "")
    txt = f"profile `{meta.get('profile')}` (`{meta.get('params_file')}`, sha256 `{sha[:12]}`"
    if current and current.get("params_sha256"):
        txt += (", unchanged since" if current["params_sha256"] == sha else
                f", **changed since**: now `{str(current['params_sha256'])[:12]}`")
    txt += f"), seed {meta.get('seed')}"
    commit = meta.get("git_commit")
    if commit:
        txt += f", commit `{str(commit)[:7]}`" + (" with uncommitted changes" if meta.get("git_dirty") else "")
    pk = meta.get("packages") or {}
    vers = ", ".join(f"{k} {pk[k]}" for k in ("torch", "spikingjelly") if pk.get(k))
    return txt + (f"; {vers}" if vers else "")


def provenance(source: str | Path, meta: dict | None, current: dict | None = None, **facts: Any) -> str:
    """Markdown line stating what produced a table: its file, the run's metadata and any ``facts``
    (e.g. ``dataset=...``, ``seeds=...``), in the order given."""
    def fmt(v):
        return ", ".join(map(str, v)) if isinstance(v, (list, tuple)) else str(v)

    extra = "; ".join(f"{k.replace('_', ' ')} {fmt(v)}" for k, v in facts.items() if v not in (None, "", []))
    return f"*Source: `{rel(source)}`; {meta_line(meta, current)}" + (f"; {extra}" if extra else "") + ".*"


def short_source(paths: Sequence[str | Path], profile: str, **facts: Any) -> str:
    """A one-line source note for a table derived from ``paths`` (the full metadata line is above it)."""
    files = ", ".join(f"`{rel(p)}`" for p in paths)
    extra = "; ".join(f"{k.replace('_', ' ')} {', '.join(map(str, v)) if isinstance(v, (list, tuple)) else v}"
                      for k, v in facts.items() if v not in (None, "", []))
    return f"*From {files}; profile `{profile}`" + (f"; {extra}" if extra else "") + ".*"


def outage_datasets(evaluation: dict | None) -> dict[str, str]:
    """``{test: dataset}`` of the outage tables, from ``outage_evaluation.json`` (its ``datasets`` in order)."""
    if not evaluation:
        return {}
    out = {}
    for name in evaluation.get("datasets", []):
        test = test_of(name)
        if test and test not in out:
            out[test] = name
    return out


# ----------------------------------------------------------------------------------------------- sentences
def _m(x: float) -> str:
    return f"{x:.{DECIMALS}f} m"


def _cmp(a: float, b: float) -> str:
    """'better' / 'worse' / 'equal' for a BGFN error ``a`` against a baseline error ``b`` (at table precision)."""
    ra, rb = round(float(a), DECIMALS), round(float(b), DECIMALS)
    return "equal" if ra == rb else ("better" if ra < rb else "worse")


def _verdict(east: str, north: str) -> str:
    if east == north:
        return {"better": "better on both axes", "worse": "worse on both axes",
                "equal": "equal on both axes"}[east]
    return f"{east} in east, {north} in north"


def _lookup(table: pd.DataFrame | None) -> dict:
    if table is None:
        return {}
    return {(int(r.outage), r.method): (float(r.max_east_m), float(r.max_north_m)) for r in table.itertuples()}


def win_counts(table: pd.DataFrame | None, method: str = "BGFN", baselines: Sequence[str] = BASELINES) -> dict:
    """``{baseline: (wins, comparisons)}``: in how many (outage, axis) cases ``method``'s max error is smaller."""
    look = _lookup(table)
    outages = sorted({o for o, _ in look})
    out = {}
    for b in baselines:
        wins = n = 0
        for o in outages:
            if (o, method) in look and (o, b) in look:
                for i in range(2):
                    n += 1
                    wins += _cmp(look[(o, method)][i], look[(o, b)][i]) == "better"
        if n:
            out[b] = (wins, n)
    return out


def summary_sentence(test: str, ours: pd.DataFrame | None, paper: pd.DataFrame | None, method: str = "BGFN") -> str:
    """How often BGFN has the smaller max error against each baseline, ours and in the paper."""
    t = TESTS[test]["title"]
    if ours is None:
        return f"{t.capitalize()}: our table is missing, so no comparison can be made."
    mine, theirs = win_counts(ours, method), win_counts(paper, method)
    parts = []
    for b, (w, n) in mine.items():
        p = theirs.get(b)
        tag = f" ({EXTRA_TAGS[b]})" if b in EXTRA_TAGS else ""
        parts.append(f"against {b}{tag} in {w} of {n}" + (f" (paper: {p[0]} of {p[1]})" if p else ""))
    return (f"{t.capitalize()}: {method} has the smaller max error (cases: outage x axis) " + "; ".join(parts)
            + ".")


def comparison_sentences(test: str, ours: pd.DataFrame | None, paper: pd.DataFrame | None, method: str = "BGFN",
                         baselines: Sequence[str] = BASELINES) -> list[str]:
    """One sentence per outage and baseline: BGFN's max east/north errors against the baseline's, ours and the
    paper's, and which is smaller."""
    look, plook = _lookup(ours), _lookup(paper)
    lines = []
    for o in sorted({k[0] for k in look} | {k[0] for k in plook}):
        if (o, method) not in look:
            lines.append(f"Outage {o}: no {method} row in our table.")
            continue
        be, bn = look[(o, method)]
        for b in baselines:
            if (o, b) not in look:
                continue
            e, n = look[(o, b)]
            txt = (f"Outage {o}, {method} vs {b}: {method}'s max east error is {_m(be)} vs {b}'s {_m(e)}, its max "
                   f"north error {_m(bn)} vs {_m(n)}; {method} is {_verdict(_cmp(be, e), _cmp(bn, n))}")
            if (o, method) in plook and (o, b) in plook:
                pbe, pbn = plook[(o, method)]
                pe, pn = plook[(o, b)]
                txt += (f" (paper: {_m(pbe)} vs {_m(pe)} east, {_m(pbn)} vs {_m(pn)} north, "
                        f"{_verdict(_cmp(pbe, pe), _cmp(pbn, pn))})")
            elif b in EXTRA_METHODS:
                txt += f" ({b}: {EXTRA_METHODS[b]})"
            lines.append(txt + ".")
    return lines


def _pct_phrase(pct: float) -> str:
    if not math.isfinite(pct):
        return "undefined"
    return f"reduced by {pct:.1f} %" if pct >= 0 else f"increased by {-pct:.1f} %"


def reduction_sentences(comp: pd.DataFrame, method: str = "BGFN") -> list[str]:
    """Sentences from :func:`reduction_comparison`: our reduction against INS beside the paper's."""
    lines = []
    for row in comp.index:
        for axis in ("East", "North"):
            ours = comp.loc[row, ("ours", axis)]
            if not np.isfinite(ours):
                continue
            txt = f"{row}, {axis.lower()}: with {method} the max error of INS is {_pct_phrase(ours)}"
            ptab, ptxt = comp.loc[row, ("paper (table)", axis)], comp.loc[row, ("paper (text)", axis)]
            ref = []
            if np.isfinite(ptab):
                ref.append(f"paper's table: {_pct_phrase(ptab)}")
            if np.isfinite(ptxt):
                ref.append(f"paper's text: {ptxt:.1f} %")
            lines.append(txt + (f" ({'; '.join(ref)})" if ref else "") + ".")
    return lines


def energy_sentences(energy: dict | None, claims: dict) -> list[str]:
    """BGFN's theoretical energy against its Transformer twin, and the paper's claim."""
    paper = claims.get("energy_reduction_vs_transformer_pct")
    if not energy:
        return ["`energy.json` is missing: notebook 05 has not run for this profile, so there is no energy "
                "estimate to compare with the paper's claim."]
    e = energy.get("energy_uj_per_prediction", {})
    red = float(energy.get("reduction_pct", float("nan")))
    verb = "less" if red >= 0 else "more"
    txt = (f"BGFN needs {e.get('bgfn', float('nan')):.3g} µJ per prediction against "
           f"{e.get('transformer', float('nan')):.3g} µJ for its ANN Transformer twin, {abs(red):.1f} % {verb} "
           f"energy (45 nm, {energy.get('e_mac_pj')} pJ per MAC, {energy.get('e_ac_pj')} pJ per accumulate, "
           f"T_s = {energy.get('time_steps')})")
    if paper is not None:
        txt += f"; the paper states {float(paper):.1f} % less than a conventional Transformer"
        diff = red - float(paper)
        txt += (f", so our estimate is {abs(diff):.1f} percentage points "
                + ("higher" if diff > 0 else "lower" if diff < 0 else "equal") + "")
    lines = [txt + "."]
    if energy.get("reduction_pct_without_attention") is not None:
        lines.append(f"Leaving the attention products out of both counts, the reduction is "
                     f"{float(energy['reduction_pct_without_attention']):.1f} %.")
    return lines


# ----------------------------------------------------------------------------------------------- figures
#: The paper's figures that carry data or structure, and what regenerates each (``{dataset}``: per dataset).
PAPER_FIGURES: tuple[dict[str, str], ...] = (
    {"label": "ins-gps-loose", "file": "diagram_loosely_coupled.png", "by": "notebook 06 (bgfn.figures)",
     "caption": "A block diagram of a loosely coupled GPS/INS integration."},
    {"label": "fig:LIF", "file": "lif_neuron.png", "by": "notebook 06 (bgfn.figures)",
     "caption": "The LIF neuron: a SpikingJelly LIF node with the model's time constant and threshold, driven by "
                "an input current; membrane potential, threshold and output spikes."},
    {"label": "BGFN", "file": "diagram_hybrid_system.png", "by": "notebook 06 (bgfn.figures)",
     "caption": "The GPS/INS integrated navigation system based on BGFN (training mode solid, prediction mode "
                "dashed)."},
    {"label": "BGFN-arc", "file": "diagram_bgfn_architecture.png", "by": "notebook 06 (bgfn.figures)",
     "caption": "The architecture of the BGFN, read from the model this profile builds."},
    {"label": "3d", "file": "trajectory_3d.png", "by": "notebook 01",
     "caption": "The NaveGo dataset trajectory, the two outages in red."},
    {"label": "out1-exin", "file": "outage_dataset_1.png", "by": "notebook 04",
     "caption": "The position errors among different algorithms during the first outage in the dataset test."},
    {"label": "out2-exin", "file": "outage_dataset_2.png", "by": "notebook 04",
     "caption": "The position errors among different algorithms during the second outage in the dataset test."},
    {"label": "rob_tra (b)", "file": "trajectory_map.png", "by": "notebook 01",
     "caption": "The vehicle trajectory of the field test; here the Turin drive on which the MPU-6000 stand-in is "
                "simulated (panel (a), a photograph of the vehicle, carries no data)."},
    {"label": "out1-mpu", "file": "outage_field_1.png", "by": "notebook 04",
     "caption": "The position errors among different algorithms during the first outage in the field test."},
    {"label": "out2-mpu", "file": "outage_field_2.png", "by": "notebook 04",
     "caption": "The position errors among different algorithms during the second outage in the field test."},
)

#: Figures beyond the paper shown on the results page (``{dataset}`` expands to every dataset).
EXTRA_FIGURES: tuple[dict[str, str], ...] = (
    {"label": "energy per layer", "file": "energy_per_layer.png", "by": "notebook 05",
     "caption": "Theoretical energy per layer, BGFN and its Transformer twin (the paper gives no figure for "
                "its energy claim)."},
    {"label": "firing rates", "file": "energy_firing_rates.png", "by": "notebook 05",
     "caption": "Firing rate of every LIF layer of the trained BGFN."},
    {"label": "energy sweeps", "file": "energy_sweeps.png", "by": "notebook 05",
     "caption": "Energy reduction as a function of T_s and of the firing rate."},
    *({"label": f"the GPS row in outage {k} of the dataset test", "file": f"outage_dataset_{k}_gps.png",
       "by": "notebook 04",
       "caption": "East and north error of the GPS row beside the errors of the real GNSS fixes it follows (dots) "
                  "and the standalone INS from the same state."} for k in (1, 2)),
    {"label": "outage sweep", "file": "outage_sweep_{dataset}.png", "by": "notebook 04", "datasets": "sweep",
     "caption": "Max horizontal error over many outage starts and durations ({dataset})."},
    {"label": "training curves", "file": "training_curves_{dataset}.png", "by": "notebook 03",
     "caption": "Training and validation loss per epoch ({dataset})."},
    {"label": "headings and speeds seen", "file": "motion_coverage_{dataset}.png", "by": "notebook 03",
     "caption": "Heading and speed of the training and validation windows and of the evaluation outages "
                "({dataset}): what the networks must extrapolate to."},
)


def figure_list(figures_dir: str | Path, entries: Sequence[dict],
                datasets: Sequence[str] | dict[str, Sequence[str]] = ()) -> list[dict]:
    """``entries`` with ``path`` and ``exists`` filled in; ``{dataset}`` entries expanded per dataset.

    ``datasets`` is a list, or a dict naming lists (an entry's ``datasets`` key picks one, default ``all``).
    """
    out = []
    for e in entries:
        if "{dataset}" in e["file"]:
            dsets = (list(datasets.get(e.get("datasets", "all"), ())) if isinstance(datasets, dict)
                     else list(datasets))
        else:
            dsets = [None]
        for d in dsets:
            name = e["file"].format(dataset=d)
            p = Path(figures_dir) / name
            out.append({**e, "file": name, "caption": e["caption"].format(dataset=d), "path": p,
                        "exists": p.is_file()})
    return out


# ----------------------------------------------------------------------------------------------- page pieces
#: The JSON files of notebooks 02-05 (what each holds).
RUN_FILES: dict[str, str] = {"kf_baseline.json": "notebook 02, Kalman filter baseline",
                             "training.json": "notebook 03, training",
                             "outage_evaluation.json": "notebook 04, outage evaluation",
                             "energy.json": "notebook 05, energy estimate"}


def _meta_of(d: dict | None) -> dict | None:
    if not d:
        return None
    return d.get("meta") or d.get("metadata")


def run_header(profile: str, cfg: dict, results: str | Path, current: dict | None = None) -> list[str]:
    """Markdown lines: the profile of this page and, per JSON file of notebooks 02-05, whether it is there and
    what produced it."""
    results = Path(results)
    lines = [f"Profile **`{profile}`** (`params/{profile}.yaml`): {cfg.get('description', '')}",
             f"Results read from `{rel(results)}/`; the page itself: {meta_line(current) if current else '-'}.", ""]
    for name, what in RUN_FILES.items():
        d = read_json(results / name)
        state = meta_line(_meta_of(d), current) if d else "**missing**"
        lines.append(f"- `{name}` ({what}): {state}")
    return lines


def outage_provenance(profile: str, test: str, results: str | Path, evaluation: dict | None,
                      current: dict | None = None) -> str:
    """Metadata line under an outage table: file, run metadata, dataset, seeds, aggregation, networks."""
    results = Path(results)
    dataset = outage_datasets(evaluation).get(test)
    ev = (evaluation or {}).get("evaluate", {})
    seeds = ev.get("seeds")
    agg = ev.get("seed_aggregate")
    windows = ", ".join(f"{d:g} s from {s:g} s (GPS time of week)"
                        for s, d in (evaluation or {}).get("outage_windows", []))
    return provenance(results / "tables" / TESTS[test]["file"], _meta_of(evaluation), current,
                      dataset=f"`{dataset}`" if dataset else None,
                      seeds=(f"{', '.join(map(str, seeds))} ({agg} over seeds)" if seeds else None),
                      outages=windows or None,
                      model_cards=(cards_line(model_cards(profile, dataset, results.parent)) if dataset else None))


__all__ = [
    "BASELINES", "EXTRA_METHODS", "EXTRA_TAGS", "PAPER_FIGURES",
    "EXTRA_FIGURES", "RUN_FILES", "TABLE_STYLES",
    "read_csv", "read_json", "missing_note",
    "best_mask", "style_layout", "compact", "reductions", "reduction_comparison", "energy_table", "kf_table",
    "training_table", "sweep_table", "fmt_num", "model_cards", "cards_line", "meta_line", "provenance",
    "short_source", "outage_datasets", "outage_provenance", "run_header", "win_counts", "summary_sentence",
    "comparison_sentences", "reduction_sentences", "energy_sentences", "figure_list", "rel", "glance_lines",
    "reference_sentences", "findings_markdown",
]


def glance_lines(profile: str, ours: dict, paper: dict, energy: dict | None, claims: dict,
                 training_summary: pd.DataFrame | None) -> list[str]:
    """The results page's *At a glance*: per test how often BGFN beats each method (ours and the paper's), the
    energy estimate beside the claim, BGFN's validation error against the untrained references."""
    return ([summary_sentence(t, ours[t], paper[t]) for t in TESTS] + energy_sentences(energy, claims)
            + reference_sentences(profile, training_summary))


def reference_sentences(profile: str, training_summary: pd.DataFrame | None) -> list[str]:
    """:func:`variant_sentences` of one profile's ``tables/training_summary.csv``: per dataset BGFN against the
    untrained references, and which networks beat the *last increment*."""
    return variant_sentences(variant_training_table({profile: training_summary}))


def findings_markdown(profile: str, lines: Sequence[str]) -> str:
    """The *At a glance* lines as a Markdown list for the book's first page (``results/<profile>/findings.md``,
    included there by the book build)."""
    head = (f"From profile `{profile}` (`params/{profile}.yaml`); how each number is made, and the paper's beside "
            "it, is on the {doc}`results page <notebooks/06_results>`.")
    return head + "\n\n" + "\n".join(f"- {s}" for s in lines) + "\n"


# ----------------------------------------------------------------------------------------------- variants
def compared_profiles(profile: str, variants: Sequence[str],
                      results_root: str | Path | None = None) -> tuple[list[str], list[str]]:
    """The profiles the *Variants* section puts side by side: ``profile``, then ``variants`` and the profile
    it builds on (``base:``), without repeats.

    Returns
    -------
    shown : list of str
        Those whose notebook 03 has run (``tables/training_summary.csv`` exists), in that order.
    missing : list of str
        The others, ``profile`` itself left out.
    """
    from bgfn.config import RESULTS_ROOT, profile_chain

    base = [p.stem for p in profile_chain(profile)[1:2]]
    names = list(dict.fromkeys([profile, *variants, *base]))
    root = Path(results_root or RESULTS_ROOT)
    shown = [p for p in names if (root / p / "tables" / "training_summary.csv").exists()]
    return shown, [p for p in names[1:] if p not in shown]


def profile_tables(profiles: Sequence[str], file: str, results_root: str | Path | None = None) -> dict:
    """``{profile: results/<profile>/tables/<file>}`` (None where it is missing)."""
    from bgfn.config import RESULTS_ROOT

    root = Path(results_root or RESULTS_ROOT)
    return {p: read_csv(root / p / "tables" / file) for p in profiles}


def variant_training_table(summaries: dict[str, pd.DataFrame | None]) -> pd.DataFrame | None:
    """Validation RMSE (m, mean over seeds) per (dataset, method), one column per profile, beside the
    references (*zero*, *last increment*, *INS increment*; those in the first profile's table), which are the
    same windows in every profile of one drive.

    ``summaries``: ``{profile: tables/training_summary.csv}``; profiles without a table are left out.
    """
    cols, ref = [], None
    for profile, s in summaries.items():
        if s is None:
            continue
        s = s.assign(method=s["method"].map(lambda m: label(m))).set_index(["dataset", "method"])
        cols.append(s["val_rmse_m_mean"].rename(f"val. RMSE {profile}"))
        if ref is None:
            ref = s[[c for c in REFERENCE_LABELS if c in s.columns]].rename(columns=REFERENCE_LABELS)
    if not cols:
        return None
    return pd.concat(cols + [ref], axis=1)


def variant_outage_table(tables: dict[str, pd.DataFrame | None], metric: str = "max_h") -> pd.DataFrame | None:
    """One outage table per profile side by side: per (outage, method) the mean of the max east and max north
    error (m, ``metric='max_h'``) or one column of :data:`bgfn.evaluate.METRIC_COLUMNS`."""
    cols = []
    for profile, t in tables.items():
        if t is None:
            continue
        t = t.set_index(["outage", "method"])
        v = (t["max_east_m"] + t["max_north_m"]) / 2.0 if metric == "max_h" else t[metric]
        cols.append(v.rename(profile))
    return pd.concat(cols, axis=1) if cols else None


def variant_sentences(training: pd.DataFrame | None, method: str = "BGFN") -> list[str]:
    """Per profile and dataset: which networks beat the *last increment* reference on validation RMSE, and
    the *INS increment* (the speed known) beside it."""
    if training is None:
        return []
    lines = []
    for col in [c for c in training.columns if c.startswith("val. RMSE ")]:
        profile = col[len("val. RMSE "):]
        for dataset, g in training.groupby(level="dataset"):
            g = g.droplevel("dataset")
            if g[col].isna().all():
                continue
            last, zero = float(g["last increment"].iloc[0]), float(g["zero"].iloc[0])
            beat = [m for m in g.index if g.loc[m, col] < last]
            txt = f"`{profile}`, `{dataset}`"
            if method in g.index:
                txt += (f": {method} {fmt_num(g.loc[method, col])} m against last increment {fmt_num(last)} m "
                        f"and zero {fmt_num(zero)} m")
            txt += f"; below the last increment: {', '.join(beat) if beat else 'no network'}"
            if "INS increment" in g.columns and np.isfinite(g["INS increment"].iloc[0]):
                txt += (f"; the INS increment (the GPS-aided INS's speed over the same interval): "
                        f"{fmt_num(g['INS increment'].iloc[0])} m")
            lines.append(txt + ".")
    return lines


def variant_sweep_table(summaries: dict[str, pd.DataFrame | None]) -> pd.DataFrame | None:
    """Median max horizontal error of the outage sweep (m) per (dataset, duration, method), one column per
    profile (``tables/outage_sweep_summary.csv`` of each; profiles without one are left out)."""
    cols = [s.set_index(["dataset", "duration_s", "method"])["median_m"].rename(p)
            for p, s in summaries.items() if s is not None]
    return pd.concat(cols, axis=1) if cols else None

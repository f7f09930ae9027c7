"""The verdict on top of the results page: per test one table of every aid in the paper's two outages and in the
outage sweep, and sentences answering what a navigation engineer asks of a learned outage aid: how accurate the
increments must be (the oracle), whether it beats the learning-free aids (INS+NHC), whether the networks can know
the speed (the velocity-input variant), whether the paper's protocol was leaky, whether the INS row is comparable
(NaveGo's setup) and whether a learned odometer helps (:mod:`bgfn.report.odometer_verdict`).

The recorded drives come first: a simulated IMU is kinder than a real one. Every number comes from
``results/<profile>/tables/``; a table a notebook has not written leaves its cells empty and its sentence says so.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from bgfn import paper
from bgfn.config import MAIN_VARIANT, SHARED_TABLES
from bgfn.data.names import dataset_id
from bgfn.data.registry import recorded_first
from bgfn.evaluate.tables import table_paths
from bgfn.studies.ins_fidelity.ins_setups import NAVEGO_CONSISTENT, NAVEGO_RUN, gap_explained
from bgfn.report.aid_words import aid_label, aid_suffix, aided_ins_words, recorded_platform
from bgfn.report.odometer_verdict import (OdometerInputs, answer_odometer, odometer_headline, odometer_rows,
                                          read_odometer_inputs, same_dataset)
from bgfn.report.reading import read_csv
from bgfn.report.sample_words import sample_note

#: Rows of the verdict table, in order: (label, method label in the tables). The oracle row is built apart.
METHOD_ROWS: tuple[tuple[str, str], ...] = (
    ("INS", "INS"), ("INS+NHC", "INS+NHC"), ("MLP", "MLP"), ("AT-LSTM", "AT-LSTM"),
    ("Transformer", "Transformer"), ("BGFN", "BGFN"), ("BGFN+NHC", "BGFN+NHC"))
#: The network whose verdict the page gives (the paper's method).
SUBJECT = "BGFN"
#: Sweep durations of the verdict's columns, s.
SWEEP_DURATIONS: tuple[float, ...] = (30.0, 60.0)
#: Label of the oracle row: the true increments plus white noise of the subject's own increment error.
ORACLE_ROW = "oracle at BGFN's increment error"
#: Columns of :func:`verdict_table`; ``Holm p``: a learned odometer's p against INS+NHC Holm-adjusted over the
#: learned odometers (the page names their best; :meth:`bgfn.report.odometer_verdict.OdometerInputs.holm_p`).
VERDICT_COLUMNS: tuple[str, ...] = ("row", "inputs", "protocol", "outage 1", "outage 2", "sweep 30 s", "sweep 60 s",
                                    "p 30 s", "p 60 s", "Holm p 30 s", "Holm p 60 s", "runs", "covariance")
#: Rows whose filter consistency in the outages the table states (``covariance``: :mod:`bgfn.studies.ins_fidelity.nees`).
NEES_ROWS: tuple[str, ...] = ("INS", "INS+NHC")


@dataclass
class VerdictInputs:
    """The tables one test's verdict reads (None where a notebook has not written one)."""

    dataset: str
    test: str
    seeds: pd.DataFrame | None          # outage_<test>_seeds.csv: every run in the paper's outages
    sweep_summary: pd.DataFrame | None  # outage_sweep_summary.csv
    sweep_pairs: pd.DataFrame | None    # outage_sweep_pairs.csv
    breakeven: pd.DataFrame | None      # outage_oracle_breakeven.csv
    variants: pd.DataFrame | None       # outage_variants.csv
    ins_tuning: pd.DataFrame | None     # kf_ins_tuning.csv
    training: pd.DataFrame | None = None            # training_runs.csv: the main networks' cards
    training_variants: pd.DataFrame | None = None   # training_variants.csv: the variants' cards
    training_all_windows: pd.DataFrame | None = None    # training_all_windows.csv: untrained runs, all windows
    odometer: OdometerInputs | None = None          # outage_odometer*.csv, energy_odometer.csv
    nees: pd.DataFrame | None = None                # outage_nees.csv: the filter's consistency in outages
    platform: str = "car"                           # kf_baseline.json: what carried the IMU (its aids)
    ins_drift: pd.DataFrame | None = None           # kf_ins_drift.csv: INS and INS+NHC from the drive's starts

    @classmethod
    def read(cls, out: str | Path, dataset: str) -> "VerdictInputs":
        """The tables of ``dataset`` under ``out`` (``results/<profile>``), each restricted to that dataset."""
        out = Path(out)
        test = paper.test_of(dataset) or dataset_id(dataset)
        tables = out / "tables"

        def of(df):      # a table names a CSV drive by its path or by its own name: compare the ids
            return None if df is None or "dataset" not in df.columns else df[same_dataset(df["dataset"], dataset)]

        return cls(dataset, test, of(read_csv(table_paths(out, test)["seeds"])),
                   of(read_csv(tables / SHARED_TABLES["sweep_summary"])),
                   of(read_csv(tables / SHARED_TABLES["sweep_pairs"])),
                   of(read_csv(tables / SHARED_TABLES["oracle_breakeven"])),
                   of(read_csv(tables / SHARED_TABLES["variants"])) if "variants" in SHARED_TABLES else None,
                   of(read_csv(tables / SHARED_TABLES["kf_ins_tuning"])),
                   of(read_csv(tables / SHARED_TABLES["training_runs"])),
                   of(read_csv(tables / SHARED_TABLES["training_variants"])),
                   of(read_csv(tables / SHARED_TABLES["training_all_windows"])),
                   read_odometer_inputs(read_csv(tables / SHARED_TABLES["odometer"]),
                                        read_csv(tables / SHARED_TABLES["odometer_summary"]),
                                        read_csv(tables / SHARED_TABLES["energy_odometer"]), dataset,
                                        read_csv(tables / SHARED_TABLES["odometer_paper"]),
                                        read_csv(tables / SHARED_TABLES["odometer_curve"]),
                                        read_csv(tables / SHARED_TABLES["odometer_uncertainty"]),
                                        errors=read_csv(tables / SHARED_TABLES["odometer_errors"]),
                                        networks=read_csv(tables / SHARED_TABLES["odometer_networks"])),
                   of(read_csv(tables / SHARED_TABLES["nees"])), _platform(out, dataset),
                   of(read_csv(tables / SHARED_TABLES["kf_ins_drift"])))


def _outage_value(seeds: pd.DataFrame | None, method: str, outage: int) -> float:
    """Median over seeds of the max horizontal error of ``method`` in the paper's outage ``outage`` (m)."""
    if seeds is None:
        return float("nan")
    sel = seeds[(seeds["method"] == method) & (seeds["outage"].astype(int) == outage)]
    return float(sel["max_h_m"].median()) if len(sel) else float("nan")


def _runs(seeds: pd.DataFrame | None, method: str) -> int:
    """How many runs one outage cell of ``method`` holds (its seeds; 1 for the learning-free rows)."""
    if seeds is None:
        return 0
    sel = seeds[seeds["method"] == method]
    return int(sel.groupby("outage").size().max()) if len(sel) else 0


def _sweep_value(summary: pd.DataFrame | None, method: str, duration: float) -> float:
    if summary is None:
        return float("nan")
    sel = summary[(summary["method"] == method) & np.isclose(summary["duration_s"].astype(float), duration)]
    return float(sel["median_m"].iloc[0]) if len(sel) else float("nan")


def _p_value(pairs: pd.DataFrame | None, row: str, duration: float) -> float:
    """Wilcoxon p in the sweep (paired by start and seed) of BGFN against the row; for the row ``BGFN+NHC``, of
    BGFN+NHC against INS+NHC (does the learned aid add to the free one?); NaN for BGFN itself."""
    if pairs is None or row == SUBJECT:
        return float("nan")
    method, baseline = (row, "INS+NHC") if row == f"{SUBJECT}+NHC" else (SUBJECT, row)
    m = pairs["method"] if "method" in pairs.columns else pd.Series(SUBJECT, pairs.index)
    sel = pairs[(m == method) & (pairs["baseline"] == baseline)
                & np.isclose(pairs["duration_s"].astype(float), duration)]
    return float(sel["p_value"].iloc[0]) if len(sel) else float("nan")


def _oracle_value(breakeven: pd.DataFrame | None, outage: str, duration: float | None) -> float:
    """The oracle's aided error at the subject's own increment RMSE (m), against INS, in one kind of window."""
    if breakeven is None or not len(breakeven):
        return float("nan")
    sel = breakeven[(breakeven["method"] == SUBJECT) & (breakeven["baseline"] == "INS")
                    & (breakeven["outage"].astype(str) == outage)]
    if duration is not None:
        sel = sel[np.isclose(sel["duration_s"].astype(float), duration)]
    return float(sel["oracle_at_rmse_m"].iloc[0]) if len(sel) else float("nan")


def nees_of(nees: pd.DataFrame | None, method: str) -> pd.Series | None:
    """The NEES row (:mod:`bgfn.studies.ins_fidelity.nees`) that speaks for ``method``: the sweep at its longest verdict duration
    (:data:`SWEEP_DURATIONS`), else the paper's first outage; None without one."""
    if nees is None or not len(nees):
        return None
    g = nees[nees["method"] == method]
    sweep = g[(g["window"] == "sweep") & np.isclose(g["duration_s"].astype(float), max(SWEEP_DURATIONS))]
    pick = sweep if len(sweep) else g[g["window"] != "sweep"]
    return pick.iloc[0] if len(pick) else None


def _main_inputs(variants: pd.DataFrame | None) -> str:
    """The main networks' inputs as the variants table describes them (its ``main`` rows), ``Eq. (eq21)`` for
    the paper's; the paper's when there is no variants table."""
    if variants is not None and len(variants) and "inputs" in variants.columns:
        rows = variants[variants["variant"] == MAIN_VARIANT]
        if len(rows) and str(rows["inputs"].iloc[0]) != EQ21_INPUTS:
            return str(rows["inputs"].iloc[0])
    return "Eq. (eq21)"


def verdict_table(inp: VerdictInputs) -> pd.DataFrame:
    """One test's verdict: every aid in the paper's two outages (max horizontal error, median over the seeds) and
    in the sweep (median over starts and seeds at 30 and 60 s), the Wilcoxon p of BGFN against the row in the sweep,
    (of BGFN+NHC against INS+NHC in its own row), then BGFN under each input reading and protocol of the variants
    (paper outages only; ``runs``: networks per cell).

    Returns
    -------
    DataFrame
        :data:`VERDICT_COLUMNS`; lengths in m.
    """
    rows = []
    main = _main_inputs(inp.variants)
    for label, method in METHOD_ROWS:
        rows.append({"row": label, "inputs": main if method not in ("INS", "INS+NHC") else "-",
                     "protocol": "honest" if method not in ("INS", "INS+NHC") else "-",
                     "outage 1": _outage_value(inp.seeds, method, 1), "outage 2": _outage_value(inp.seeds, method, 2),
                     **{f"sweep {d:g} s": _sweep_value(inp.sweep_summary, method, d) for d in SWEEP_DURATIONS},
                     **{f"p {d:g} s": _p_value(inp.sweep_pairs, method, d) for d in SWEEP_DURATIONS},
                     "runs": _runs(inp.seeds, method),
                     "covariance": (str(nees_of(inp.nees, method)["verdict"]) if method in NEES_ROWS
                                    and nees_of(inp.nees, method) is not None else "-")})
        if method == "INS+NHC":
            rows.append({"row": ORACLE_ROW, "inputs": "-", "protocol": "-",
                         "outage 1": _oracle_value(inp.breakeven, "1", None),
                         "outage 2": _oracle_value(inp.breakeven, "2", None),
                         **{f"sweep {d:g} s": _oracle_value(inp.breakeven, "sweep", d) for d in SWEEP_DURATIONS},
                         **{f"p {d:g} s": float("nan") for d in SWEEP_DURATIONS}, "runs": 0})
        if method == f"{SUBJECT}+NHC" and inp.odometer is not None:
            rows += odometer_rows(inp.odometer, SWEEP_DURATIONS)
    if inp.variants is not None and len(inp.variants):
        v = inp.variants[(inp.variants["method"] == SUBJECT)]
        for variant, g in v.groupby("variant", sort=False):
            first = g.iloc[0]
            cell = {int(o): float(x) for o, x in zip(g["outage"], g["max_h_m"])}
            rows.append({"row": f"{SUBJECT} ({variant})", "inputs": first["inputs"], "protocol": first["protocol"],
                         "outage 1": cell.get(1, np.nan), "outage 2": cell.get(2, np.nan),
                         **{f"sweep {d:g} s": np.nan for d in SWEEP_DURATIONS},
                         **{f"p {d:g} s": np.nan for d in SWEEP_DURATIONS}, "runs": int(g["n_runs"].max())})
    return pd.DataFrame(rows, columns=list(VERDICT_COLUMNS))


def _m(x: float) -> str:
    return "n/a" if not np.isfinite(x) else f"{x:.1f} m" if x >= 1 else f"{x:.2f} m"


def _row(table: pd.DataFrame, label: str) -> pd.Series | None:
    sel = table[table["row"] == label]
    return sel.iloc[0] if len(sel) else None


def _outage_sample(row: pd.Series | None) -> tuple[int, int]:
    """(seeds, windows) a row's mean over the paper's outages rests on: its ``runs`` per cell and its outages with
    a value; (0, 0) without the row."""
    if row is None:
        return 0, 0
    cells = np.array([row["outage 1"], row["outage 2"]], dtype=float)
    return int(row["runs"]) if np.isfinite(float(row["runs"])) else 0, int(np.isfinite(cells).sum())


def _sweep_sample(summary: pd.DataFrame | None, method: str, duration: float) -> tuple[int, int]:
    """(seeds, windows) ``method``'s sweep median at ``duration`` rests on: its runs per start and its starts
    (``outage_sweep_summary.csv``'s ``n`` and ``n_starts``); (0, 0) without them."""
    if summary is None or not {"n", "n_starts"} <= set(summary.columns):
        return 0, 0
    sel = summary[(summary["method"] == method) & np.isclose(summary["duration_s"].astype(float), duration)]
    if not len(sel) or int(sel["n_starts"].iloc[0]) < 1:
        return 0, 0
    starts = int(sel["n_starts"].iloc[0])
    return int(round(int(sel["n"].iloc[0]) / starts)), starts


def _mean_outages(row: pd.Series | None) -> float:
    """Mean of a row's max errors over the outages it has (a user's drive may have one), NaN without any."""
    if row is None:
        return float("nan")
    vals = np.array([row["outage 1"], row["outage 2"]], dtype=float)
    return float(vals[np.isfinite(vals)].mean()) if np.isfinite(vals).any() else float("nan")


def answer_accuracy(inp: VerdictInputs) -> str:
    """Question 1: the break-even increment error against BGFN's own, in the sweep at 30 s (else the outages)."""
    be = inp.breakeven
    if be is None or not len(be):
        return "How accurate must the increments be? Not measured: notebook 06's oracle has not run for this drive."
    sel = be[(be["method"] == SUBJECT) & (be["baseline"] == "INS")]
    sweep = sel[(sel["outage"].astype(str) == "sweep") & np.isclose(sel["duration_s"].astype(float), 30.0)]
    r = (sweep if len(sweep) else sel).iloc[0] if len(sel) else None
    if r is None:
        return "How accurate must the increments be? The oracle ran, but BGFN has no increment error in its windows."
    where = "in the 30 s sweep" if len(sweep) else f"in outage {r['outage']}"
    bar = float(r["breakeven_sigma_m"])
    own = float(r["increment_rmse_m"])
    eq = float(r["equivalent_sigma_m"])
    bar_text = (f"below {_m(bar)} per increment of {float(r['increment_s']):g} s" if r["crossing"] == "crossed"
                else "no noise level of the grid (the oracle is worse than INS everywhere)" if r["crossing"] ==
                "never_below" else f"any noise up to the grid's largest ({_m(bar)})")
    verdict = ("clears the bar" if np.isfinite(own) and np.isfinite(bar) and own < bar else "misses the bar")
    acts = (f"white noise of {_m(eq)}" if np.isfinite(eq) else "more noise than the oracle's grid holds")
    return (f"How accurate must the increments be? Fed the true increments plus white noise, the filter beats INS "
            f"{where} for {bar_text}. BGFN's own increment error there is {_m(own)} ({verdict}); in the filter its "
            f"errors act like {acts} (more than their size when they are correlated: they add up along the "
            f"outage).")


def answer_free_aids(table: pd.DataFrame, drift: pd.DataFrame | None = None, platform: str = "car") -> str:
    """Question 2: INS+NHC against INS and BGFN, and whether BGFN adds to NHC; ``drift`` (notebook 08's
    ``kf_ins_drift.csv``) puts the paper's two outages beside the drive's starts where they rank INS+NHC otherwise
    (:func:`drift_clause`); ``platform`` names the free aid that ran (:func:`bgfn.report.aid_words.aid_suffix`)."""
    aid = aid_suffix(platform)[1:]
    ins, nhc, bgfn, both = (_row(table, k) for k in ("INS", "INS+NHC", "BGFN", "BGFN+NHC"))
    if nhc is None or not np.isfinite(_mean_outages(nhc)):
        return "Does it beat the learning-free aids? Not measured: the INS+NHC row has not run."
    col = "sweep 30 s" if np.isfinite(nhc["sweep 30 s"]) else None
    if col:
        text = (f"In the 30 s sweep the median error is {_m(ins['sweep 30 s'])} for INS, {_m(nhc['sweep 30 s'])} for "
                f"INS+NHC (no learning), {_m(bgfn['sweep 30 s'])} for BGFN and {_m(both['sweep 30 s'])} for BGFN+NHC")
        p = both["p 30 s"] if both is not None else float("nan")
        text += f" (BGFN+NHC against INS+NHC: Wilcoxon p {p:.2g})." if np.isfinite(p) else "."
    else:
        text = (f"In the paper's two outages (mean of their max errors) INS reaches {_m(_mean_outages(ins))}, INS+NHC "
                f"{_m(_mean_outages(nhc))}" + drift_clause(drift, _mean_outages(ins), _mean_outages(nhc))
                + f"; BGFN {_m(_mean_outages(bgfn))} and BGFN+NHC {_m(_mean_outages(both))}"
                + sample_note(*_outage_sample(bgfn)) + ".")
    a, b = (both[col], nhc[col]) if col else (_mean_outages(both), _mean_outages(nhc))
    add = ("BGFN adds to the free aid" if np.isfinite(a) and np.isfinite(b) and a < b
           else f"BGFN does not add to the free aid: fused with {aid} it is worse than {aid} alone")
    return f"Does it beat the learning-free aids? {text} {add}."


#: The variants' ``inputs`` of Eq. (eq21) alone (:func:`bgfn.train.variants.variant_options`); more channels are
#: written ``eq21+<channel>...``.
EQ21_INPUTS = "eq21"


def _variant_rows(table: pd.DataFrame, velocity: bool | None = None, protocol: str | None = None) -> pd.DataFrame:
    """The subject's variant rows; ``velocity``: with extra input channels (True) or Eq. (eq21)'s alone (False)."""
    rows = table[table["row"].str.startswith(f"{SUBJECT} (")]
    if velocity is not None:
        rows = rows[(rows["inputs"].astype(str) != EQ21_INPUTS) == velocity]
    if protocol is not None:
        rows = rows[rows["protocol"] == protocol]
    return rows


def _learned(cards: pd.DataFrame | None) -> tuple[int, int, float] | None:
    """(runs that improved on their initial network, runs, median validation RMSE in m) of a cards table."""
    if cards is None or not len(cards) or "best_epoch" not in cards.columns:
        return None
    return int((cards["best_epoch"] >= 1).sum()), len(cards), float(cards["val_rmse_m"].median())


def learning_evidence(inp: VerdictInputs) -> str:
    """Did the networks learn the increments at all? On the validation block: how many runs improved on their
    initial weights (``best_epoch >= 1``) and their median RMSE per increment, with Eq. (eq21)'s inputs (the main
    networks) and given the INS velocity (the honest velocity variant), beside predicting zero. Empty when
    the training tables are missing."""
    variants = inp.training_variants
    if variants is not None and len(variants) and {"inputs", "protocol"} <= set(variants.columns):
        variants = variants[(variants["inputs"].astype(str) != EQ21_INPUTS) & (variants["protocol"] == "honest")]
    base, fast = _learned(inp.training), _learned(variants)
    if base is None:
        return ""
    zero = float(inp.training["val_rmse_zero_m"].median()) if "val_rmse_zero_m" in inp.training else float("nan")
    label = _main_inputs(inp.variants)
    words = "Eq. (eq21)'s inputs" if label == "Eq. (eq21)" else f"the inputs {label}"
    text = (f" On the validation block {base[0]} of {base[1]} networks with {words} improved on their "
            f"initial weights (median RMSE per increment {base[2]:.2f} m; predicting zero: {zero:.2f} m)")
    if fast is not None:
        text += f"; given the INS velocity {fast[0]} of {fast[1]} did (median {fast[2]:.2f} m)"
    return text + "." + _fitted_but_not_improved(inp.training) + _all_windows(inp.training_all_windows)


def _all_windows(recheck: pd.DataFrame | None) -> str:
    """How many of the networks that never improved did once trained on all their training windows
    (:mod:`bgfn.train.recheck`); empty without such runs."""
    if recheck is None or not len(recheck) or "best_epoch_all" not in recheck.columns:
        return ""
    improved = int((recheck["best_epoch_all"] >= 1).sum())
    return (f" The {len(recheck)} of them whose training windows had been capped were trained again on all of them "
            f"({int(recheck['n_train'].max())} -> {int(recheck['n_train_all'].max())}): {improved} then improved.")


def _fitted_but_not_improved(cards: pd.DataFrame) -> str:
    """Why the networks that never improved did not: their lowest training loss against predicting the mean
    (about 1 in normalized units). Empty when every run improved or the column is missing."""
    if "train_loss_min" not in cards.columns:
        return ""
    stuck = cards[(cards["best_epoch"] < 1) & cards["train_loss_min"].notna()]
    if not len(stuck):
        return ""
    fit = float(stuck["train_loss_min"].median())
    if fit >= 0.9:
        return (f" The {len(stuck)} that never improved did not fit their training windows either (median lowest "
                f"training loss {fit:.2f}; predicting the training mean: about 1).")
    return (f" The {len(stuck)} that never improved did fit their training windows (median lowest training loss "
            f"{fit:.2f}; predicting the training mean: about 1): what they learned there does not carry over to the "
            f"validation block.")


def answer_speed(table: pd.DataFrame, inp: VerdictInputs | None = None) -> str:
    """Question 3: BGFN with velocity inputs against Eq. (eq21)'s inputs, honest protocol, paper outages; with
    ``inp`` also :func:`learning_evidence` (did the networks learn at all?)."""
    base = _variant_rows(table, False, "honest")
    fast = _variant_rows(table, True, "honest")
    evidence = learning_evidence(inp) if inp is not None else ""
    if not len(fast):
        return "Can the networks know the speed? Not measured: the velocity-input variant has not run." + evidence
    b = _mean_outages(base.iloc[0]) if len(base) else _mean_outages(_row(table, SUBJECT))
    f = _mean_outages(fast.iloc[0])
    ins = _mean_outages(_row(table, "INS"))
    return (f"Can the networks know the speed? Eq. (eq21) gives no velocity. With Eq. (eq21)'s inputs BGFN's max error "
            f"in the paper's two outages averages {_m(b)}; given the INS velocity {_m(f)} (INS: {_m(ins)}; "
            f"{int(fast.iloc[0]['runs'])} network(s) per cell)." + evidence)


def answer_protocol(table: pd.DataFrame, claims: dict | None = None) -> str:
    """Question 4: trained on the whole drive (test outages included), BGFN's reduction against INS."""
    leaky = _variant_rows(table, None, "leaky")
    if not len(leaky):
        return "Was the paper's protocol leaky? Not measured: the variant trained on the whole drive has not run."
    ins = _mean_outages(_row(table, "INS"))
    lines, samples = [], []
    for _, r in pd.concat([_variant_rows(table, None, "honest"), leaky]).iterrows():
        samples.append(_outage_sample(r))
        err = _mean_outages(r)
        red = 100.0 * (ins - err) / ins if np.isfinite(ins) and ins > 0 else float("nan")
        lines.append(f"{r['row']}, {r['protocol']}: {_m(err)}, "
                     + (f"{red:.0f} % below INS" if red >= 0 else f"{err / ins:.1f} times INS"))
    stated = ""
    if claims:
        pct = [v for v in _numbers(claims.get("bgfn_reduction_vs_ins_pct")) if 0 < v <= 100]
        if pct:
            stated = f" The paper states reductions of {min(pct):g}-{max(pct):g} %."
    return ("Was the paper's protocol leaky? Mean max error in the paper's two outages, trained with the test outages "
            "and a margin left out (honest) and on the whole drive, the test outages included (leaky): "
            + "; ".join(lines) + f" (INS {_m(ins)}"
            + sample_note(min(n for n, _ in samples), max(w for _, w in samples), "; each from ")[:-1] + ")."
            + stated)


def _numbers(node) -> list[float]:
    if isinstance(node, dict):
        return [x for v in node.values() for x in _numbers(v)]
    if isinstance(node, (list, tuple)):
        return [x for v in node for x in _numbers(v)]
    return [float(node)] if isinstance(node, (int, float)) and not isinstance(node, bool) else []


def answer_ins_tuning(inp: VerdictInputs) -> str:
    """Question 5: the INS row under NaveGo v1.4's bias modelling beside ours and the paper's."""
    if inp.ins_tuning is None or not len(inp.ins_tuning):
        return "Is the INS row comparable? Not measured: notebook 08's INS-setup table has not run." + \
            consistency_sentence(inp)
    gap = gap_explained(inp.ins_tuning)
    g = gap[gap["setup"] == "navego"]
    if not len(g):
        return "Is the INS row comparable? The paper has no INS row for this drive's test."
    r = g.iloc[0]
    whose = "" if paper.has_own_values(inp.test) else " (its field test: it has no table of this drive)"
    own = dict(zip(gap["setup"], gap["setup_m"]))
    navego = ("" if NAVEGO_RUN not in own else f", {_m(own[NAVEGO_RUN])} with NaveGo v1.4 itself under Octave"
              + ("" if NAVEGO_CONSISTENT not in own else
                 f" ({_m(own[NAVEGO_CONSISTENT])} with its bias feedback made consistent)"))
    return (f"Is the INS row comparable? Mean of the INS row's max east and north errors: {_m(r['shipped_m'])} with "
            f"our filter, {_m(r['setup_m'])} with NaveGo v1.4's bias modelling{navego}, {_m(r['paper_m'])} in the "
            f"paper{whose}." + consistency_sentence(inp))


def consistency_sentence(inp: VerdictInputs) -> str:
    """Whether the filter's covariance at the end of the outages matches its errors (the INS row's NEES), or ''."""
    r = nees_of(inp.nees, "INS")
    if r is None:
        return ""
    where = f"the {float(r['duration_s']):g} s sweep" if r["window"] == "sweep" else f"the paper's {r['window']}"
    return (f" During the outages the filter is {r['verdict']}: the INS row's median NEES of the horizontal position "
            f"in {where} is {float(r['median_nees']):.3g} ({100 * float(r['inside_95']):.0f} % of the runs inside the "
            f"95 % bound; a consistent filter: 1.39 and 95 %), so every aid fused with it is weighted "
            + {"overconfident": "too little (the filter believes its drift smaller than it is).",
               "underconfident": "too much (the filter believes its drift larger than it is).",
               "consistent": "as its accuracy deserves."}.get(str(r["verdict"]), "as measured."))


def verdict_sentences(inp: VerdictInputs, table: pd.DataFrame, claims: dict | None = None) -> list[str]:
    """The six answers for one test, in the issues' order, the rows named by the aids that ran
    (:func:`bgfn.report.aid_words.aid_label`: ``INS+ZUPT`` on a walker)."""
    answers = [answer_accuracy(inp), answer_free_aids(table, inp.ins_drift, inp.platform), answer_speed(table, inp),
               answer_protocol(table, claims), answer_ins_tuning(inp),
               answer_odometer(inp.odometer or OdometerInputs(None, None, None), SWEEP_DURATIONS)]
    return [aid_label(a, inp.platform) for a in answers]


#: The drive's platform as notebook 02 recorded it (:func:`bgfn.report.aid_words.recorded_platform`).
_platform = recorded_platform


def headline(inp: VerdictInputs, table: pd.DataFrame) -> str:
    """One line per test for the book's first page: BGFN against INS and INS+NHC where both were measured (the
    rows named by the aids that ran, :func:`bgfn.report.aid_words.aid_label`)."""
    return aid_label(_headline(inp, table), inp.platform)


def _headline(inp: VerdictInputs, table: pd.DataFrame) -> str:
    title = paper.TESTS[inp.test]["title"] if inp.test in paper.TESTS else inp.test
    b, i, n = (_row(table, k) for k in (SUBJECT, "INS", "INS+NHC"))
    col = "sweep 30 s" if b is not None and np.isfinite(b["sweep 30 s"]) else None
    if b is None or i is None or not (np.isfinite(_mean_outages(b)) and np.isfinite(_mean_outages(i))):
        return f"{title} ({inp.dataset}): not evaluated."
    if col:
        vals = (b[col], i[col], n[col] if n is not None else np.nan)
        where = ("median max error over the 30 s sweep"
                 + sample_note(*_sweep_sample(inp.sweep_summary, SUBJECT, 30.0), " (BGFN: "))
    else:
        vals = (_mean_outages(b), _mean_outages(i), _mean_outages(n))
        where = ("mean max error in the paper's two outages" if paper.has_own_values(inp.test)
                 else "mean max error in the profile's outages") + sample_note(*_outage_sample(b), " (BGFN: ")
    word = "below" if vals[0] < vals[1] else "above"
    odo = odometer_headline(inp.odometer, SWEEP_DURATIONS) if inp.odometer is not None else ""
    return (f"{title} ({inp.dataset}): " + (f"{odo[0].upper()}{odo[1:]}. " if odo else "")
            + f"The paper's design, {where}: BGFN {_m(vals[0])}, {word} standalone INS ({_m(vals[1])}); "
            f"{aided_ins_words(inp.platform)} {_m(vals[2])}"
            + ("" if col else drift_clause(inp.ins_drift, vals[1], vals[2])) + ".")


def drift_clause(drift: pd.DataFrame | None, ins_m: float, aided_m: float, duration_s: float = 30.0) -> str:
    """Where the aided INS is worse than standalone INS in the paper's two outages but better from the drive's
    starts (notebook 08's ``kf_ins_drift.csv``, median at ``duration_s``), the clause that says so: two outages
    are a small sample of a drive, and a reader should not take their order for the aid's (empty otherwise)."""
    if drift is None or drift.empty or not (np.isfinite(ins_m) and np.isfinite(aided_m)) or aided_m <= ins_m:
        return ""
    at = drift[np.isclose(drift["duration_s"].astype(float), duration_s)]
    med = {m: at.loc[at["method"] == m, "median_max_h_m"] for m in ("INS", "INS+NHC")}
    if any(v.empty for v in med.values()):
        return ""
    ins, aided = float(med["INS"].iloc[0]), float(med["INS+NHC"].iloc[0])
    if not aided < ins:
        return ""
    n = int(at["n_starts"].iloc[0])
    return (f", worse than standalone INS in these two outages though not over the drive: from notebook 08's {n} "
            f"starts it is {_m(aided)} against INS's {_m(ins)} (median max error, {duration_s:g} s)")


def format_table(table: pd.DataFrame, platform: str = "car"):
    """The verdict table styled for the page (lengths with one decimal, p with two digits, n/a for empty), its rows
    named by the aids that ran on ``platform`` (:func:`bgfn.report.aid_words.aid_label`: ``INS+ZUPT`` on a
    walker)."""
    table = table.assign(row=[aid_label(r, platform) for r in table["row"]])
    fmt = {c: "{:.1f}" for c in ("outage 1", "outage 2", "sweep 30 s", "sweep 60 s")}
    fmt.update({c: "{:.2g}" for c in ("p 30 s", "p 60 s", "Holm p 30 s", "Holm p 60 s")})
    return table.style.format(fmt, na_rep="-").hide(axis="index")


@dataclass
class Verdict:
    """The verdict of a profile: per evaluated dataset its inputs, table and answers."""

    inputs: dict[str, VerdictInputs]
    tables: dict[str, pd.DataFrame]
    answers: dict[str, list[str]]

    def headlines(self) -> list[str]:
        """One line per test (:func:`headline`): the book's first page."""
        return [headline(self.inputs[d], self.tables[d]) for d in self.inputs]

    def pieces(self) -> list:
        """What the results page shows: per test a title, its headline, the table and the six answers."""
        out = []
        for d, inp in self.inputs.items():
            title = paper.TESTS[inp.test]["title"] if inp.test in paper.TESTS else inp.test
            out += [f"### {title}: `{d}`", f"**{headline(inp, self.tables[d])}**",
                    format_table(self.tables[d], inp.platform),
                    "\n".join(f"{k}. {a}" for k, a in enumerate(self.answers[d], 1))]
        return out


def verdict_of(res) -> Verdict:
    """The verdict of every dataset notebook 04 evaluated for ``res`` (:class:`bgfn.report.reading.ProfileResults`).
    """
    datasets = recorded_first(dict.fromkeys(res.cfg["evaluate"]["datasets"]))   # the decisive test first
    inputs = {d: VerdictInputs.read(res.out, d) for d in datasets}
    tables = {d: verdict_table(inp) for d, inp in inputs.items()}
    answers = {d: verdict_sentences(inputs[d], tables[d], res.claims) for d in datasets}
    return Verdict(inputs, tables, answers)

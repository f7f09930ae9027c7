"""The top of the results page, one screen: per drive its headline, the duration figure, a short table and the six
answers as bullets of at most three lines, each linking to the notebook that holds the detail; the provenance one
collapsed line. The full verdict table and the long answers stay below (:mod:`bgfn.report.verdict`)."""

from __future__ import annotations

import html
import re
from pathlib import Path

import numpy as np
import pandas as pd

from bgfn import paper
from bgfn.config import SHARED_TABLES
from bgfn.data.names import dataset_id
from bgfn.io import save_figure
from bgfn.report.aid_words import aid_label
from bgfn.report.duration_curves import duration_curves, plot_duration_curves
from bgfn.report.glance import run_header
from bgfn.report.odometer_verdict import OdometerInputs, odometer_headline
from bgfn.report.reading import read_csv
from bgfn.report.verdict import (SUBJECT, SWEEP_DURATIONS, Verdict, VerdictInputs, _mean_outages, _outage_sample,
                                 _row, _variant_rows, format_table, headline)
from bgfn.report.sample_words import sample_note
from bgfn.studies.ins_fidelity.ins_setups import gap_explained

#: The rows and columns of the short table (the full one, with the variants and the NEES, is further down).
SHORT_ROWS: tuple[str, ...] = ("INS", "INS+NHC", "MLP", "AT-LSTM", "Transformer", SUBJECT, f"{SUBJECT}+NHC")
SHORT_COLUMNS: tuple[str, ...] = ("row", "outage 1", "outage 2", "sweep 30 s", "sweep 60 s", "p 30 s", "p 60 s")
#: The notebook of each answer's detail (the book's HTML pages sit side by side in notebooks/).
DETAIL = {"accuracy": ("06_outage_sweep", "the oracle"), "free_aids": ("06_outage_sweep", "the sweep"),
          "speed": ("06_outage_sweep", "the variants"), "protocol": ("06_outage_sweep", "the variants"),
          "ins": ("08_ins_fidelity", "the INS's fidelity"), "odometer": ("07_learned_odometer", "the odometer")}
#: A bullet longer than this would wrap to a fourth line in the book's text column (about 110 characters a line).
MAX_BULLET_CHARS = 330
#: File of a drive's figure under ``results/<profile>/figures/``.
FIGURE_FILE = "verdict_{dataset}.png"


class HtmlPiece(str):
    """A piece of the page that is HTML, not Markdown (the notebook displays it as such)."""


def _m(x) -> str:
    return f"{float(x):.1f} m" if x is not None and np.isfinite(float(x)) else "n/a"


def short_accuracy(inp: VerdictInputs) -> str:
    """Question 1 in one line: BGFN's own increment error against the oracle's break-even noise."""
    be = inp.breakeven
    sel = be[(be["method"] == SUBJECT) & (be["baseline"] == "INS")] if be is not None and len(be) else None
    if sel is None or not len(sel):
        return "not measured for this drive."
    sweep = sel[(sel["outage"].astype(str) == "sweep") & np.isclose(sel["duration_s"].astype(float), 30.0)]
    r = (sweep if len(sweep) else sel).iloc[0]
    bar, own = float(r["breakeven_sigma_m"]), float(r["increment_rmse_m"])
    where = "30 s sweep" if len(sweep) else f"outage {r['outage']}"
    bar_text = {"crossed": f"below {_m(bar)}", "never_below": "at no noise level of the grid"}.get(
        str(r["crossing"]), f"at every noise level up to {_m(bar)}")
    ok = np.isfinite(own) and (r["crossing"] != "never_below") and (r["crossing"] != "crossed" or own < bar)
    return (f"{'yes' if ok else 'no'}: BGFN's error per increment is {_m(own)}; the true increments plus white "
            f"noise beat INS {bar_text} ({where}).")


def short_free_aids(table: pd.DataFrame) -> str:
    """Question 2 in one line: BGFN and BGFN+NHC against INS+NHC in the 30 s sweep (else the paper's outages)."""
    rows = {k: _row(table, k) for k in ("INS", "INS+NHC", SUBJECT, f"{SUBJECT}+NHC")}
    if rows["INS+NHC"] is None:
        return "not measured: the INS+NHC row has not run."
    sweep = np.isfinite(rows["INS+NHC"]["sweep 30 s"])

    def value(k):
        r = rows[k]
        return float("nan") if r is None else float(r["sweep 30 s"]) if sweep else _mean_outages(r)
    ins, nhc, bgfn, both = (value(k) for k in rows)
    p = rows[f"{SUBJECT}+NHC"]["p 30 s"] if sweep and rows[f"{SUBJECT}+NHC"] is not None else float("nan")
    where = "30 s sweep" if sweep else "paper's two outages" + sample_note(*_outage_sample(rows[SUBJECT]))
    return (f"{'yes' if np.isfinite(both) and both < nhc else 'no'}: in the {where} INS+NHC (no learning) reaches "
            f"{_m(nhc)}, BGFN {_m(bgfn)}, BGFN+NHC {_m(both)}" + (f" (p {p:.2g})" if np.isfinite(p) else "")
            + f"; INS {_m(ins)}.")


def short_speed(table: pd.DataFrame) -> str:
    """Question 3 in one line: BGFN in the paper's outages with and without the INS velocity as an input."""
    base, fast = _variant_rows(table, False, "honest"), _variant_rows(table, True, "honest")
    if not len(fast):
        return "not measured: the velocity-input variant has not run."
    b = _mean_outages(base.iloc[0]) if len(base) else _mean_outages(_row(table, SUBJECT))
    f = _mean_outages(fast.iloc[0])
    return (f"given the INS velocity, BGFN's mean max error in the paper's two outages goes from {_m(b)} to {_m(f)} "
            f"(INS {_m(_mean_outages(_row(table, 'INS')))}).")


def short_protocol(table: pd.DataFrame) -> str:
    """Question 4 in one line: BGFN trained on the whole drive (test outages included) against the honest one."""
    leaky, honest = _variant_rows(table, False, "leaky"), _variant_rows(table, False, "honest")
    if not len(leaky):
        return "not measured: the variant trained on the whole drive has not run."
    h = _mean_outages(honest.iloc[0]) if len(honest) else _mean_outages(_row(table, SUBJECT))
    return (f"trained with the test outages included, BGFN reaches {_m(_mean_outages(leaky.iloc[0]))} in them, "
            f"honest {_m(h)} (INS {_m(_mean_outages(_row(table, 'INS')))}).")


def short_ins(inp: VerdictInputs) -> str:
    """Question 5 in one line: the INS row with our filter, NaveGo's bias modelling and the paper's."""
    if inp.ins_tuning is None or not len(inp.ins_tuning):
        return "not measured: notebook 08's INS-setup table has not run."
    g = gap_explained(inp.ins_tuning)
    g = g[g["setup"] == "navego"]
    if not len(g):
        return "the paper has no INS row for this drive's test."
    r = g.iloc[0]
    whose = "" if paper.has_own_values(inp.test) else " (its field test)"
    return (f"our filter {_m(r['shipped_m'])}, NaveGo v1.4's bias modelling {_m(r['setup_m'])}, the paper "
            f"{_m(r['paper_m'])}{whose}: mean of the max east and north errors in the two outages.")


def short_odometer(odo: OdometerInputs) -> str:
    """Question 6 in one line: the odometer clause of the headline."""
    clause = odometer_headline(odo, SWEEP_DURATIONS)
    return clause + "." if clause else "not measured for this drive."


#: The six questions, in the order of the long answers (:func:`bgfn.report.verdict.verdict_sentences`).
QUESTIONS: tuple[tuple[str, str], ...] = (
    ("accuracy", "Are the increments accurate enough?"), ("free_aids", "Does it beat the learning-free aid?"),
    ("speed", "Can the networks know the speed?"), ("protocol", "Was the paper's protocol leaky?"),
    ("ins", "Is the INS row comparable?"), ("odometer", "Does a learned odometer help?"))


def short_answers(inp: VerdictInputs, table: pd.DataFrame) -> dict[str, str]:
    """``{question key: one-line answer}`` for one drive, the rows named by the aids that ran
    (:func:`bgfn.report.aid_words.aid_label`)."""
    answers = {"accuracy": short_accuracy(inp), "free_aids": short_free_aids(table), "speed": short_speed(table),
               "protocol": short_protocol(table), "ins": short_ins(inp),
               "odometer": short_odometer(inp.odometer or OdometerInputs(None, None, None))}
    return {k: aid_label(a, inp.platform) for k, a in answers.items()}


def _inline(text: str) -> str:
    """Markdown's ``code`` and **bold** as HTML, the rest escaped."""
    out = html.escape(text, quote=False)
    out = re.sub(r"`([^`]+)`", r"<code>\1</code>", out)
    return re.sub(r"\*\*([^*]+)\*\*", r"<b>\1</b>", out)


def answer_bullets(answers: dict[str, str]) -> str:
    """The answers as an HTML list, each bullet the question, its answer and a link to its notebook."""
    items = []
    for key, question in QUESTIONS:
        page, what = DETAIL[key]
        items.append(f'<li><b>{html.escape(question)}</b> {_inline(answers[key])} '
                     f'<a href="{page}.html">{html.escape(what)}</a></li>')
    return "<ul>\n" + "\n".join(items) + "\n</ul>"


def short_table(table: pd.DataFrame, platform: str = "car"):
    """The verdict table's main rows and length columns, styled (:func:`bgfn.report.verdict.format_table`, the rows
    named by the aids that ran on ``platform``)."""
    t = table[table["row"].isin(SHORT_ROWS)][list(SHORT_COLUMNS)]
    return format_table(t, platform)


def provenance_details(header_lines: list[str]) -> HtmlPiece:
    """The run header (:func:`bgfn.report.glance.run_header`) as one collapsed HTML line."""
    body = "<br>\n".join(_inline(line) for line in header_lines if line.strip())
    first = next((line for line in header_lines if line.strip()), "")
    summary = _inline(first.split(":")[0]) if first else "Provenance"
    return HtmlPiece(f"<details><summary>Provenance: {summary}</summary>\n<p>{body}</p>\n</details>")


def header_details(res) -> HtmlPiece:
    """The page's provenance (which profile, which files, which code) as one collapsed line."""
    return provenance_details(run_header(res.profile, res.cfg, res.out, res.current))


def verdict_figure(res, dataset: str, figures_dir: str | Path, platform: str = "car") -> Path | None:
    """Draw and save one drive's duration figure (:mod:`bgfn.report.duration_curves`); None without a sweep."""
    sw = res.cfg["evaluate"]["sweep"]
    curves = duration_curves(dataset, res.sweep, read_csv(res.table(SHARED_TABLES["odometer"])),
                             n_boot=int(sw["n_boot"]), level=float(sw["level"]), seed=int(sw["boot_seed"]))
    if not len(curves):
        return None
    title = f"{dataset}: median max horizontal error over the sweep's starts, 95 % interval"
    return save_figure(plot_duration_curves(curves, title, platform),
                       Path(figures_dir) / FIGURE_FILE.format(dataset=dataset_id(dataset)))


def verdict_top(res, verdict: Verdict) -> list:
    """The pieces of the page's first screen, per drive (recorded first): title, headline, figure, short table and
    the six bullets."""
    out = []
    for d, inp in verdict.inputs.items():
        title = paper.TESTS[inp.test]["title"] if inp.test in paper.TESTS else inp.test
        table = verdict.tables[d]
        out += [f"### {title}: `{d}`", f"**{headline(inp, table)}**"]
        figure = verdict_figure(res, d, res.out / "figures", inp.platform)
        if figure is not None:
            out.append(figure)
        out += [short_table(table, inp.platform), HtmlPiece(answer_bullets(short_answers(inp, table)))]
    return out

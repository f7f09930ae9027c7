"""The sections of the results page (notebook 10), each as the pieces to display, in order.

A *piece* is a Markdown string, a pandas Styler (a table) or a :class:`~pathlib.Path` (a figure file); the
notebook only displays them, between its prose. An input that is missing gives a note saying which notebook
produces it, never an error.
"""

from __future__ import annotations

from dataclasses import dataclass

import pandas as pd

from bgfn import paper
from bgfn.config import RUN_RECORDS, SHARED_TABLES
from bgfn.data.names import dataset_id
from bgfn.data.registry import recorded_first
from bgfn.report.sweep_words import describe_sweep
from bgfn.report.odometer_words import odometer_lines
from bgfn.studies.odometer.section import odometer_table
from bgfn.report.aid_words import aid_label, recorded_platform
from bgfn.report.glance import run_header
from bgfn.report.provenance import cards_line, model_cards, outage_datasets, outage_provenance, provenance, short_source
from bgfn.report.reading import ProfileResults, missing_note, read_csv
from bgfn.report.sentences import bullets, comparison_sentences, energy_sentences, reduction_sentences
from bgfn.report.tables import (compact, energy_table, fmt_num, kf_table, reduction_comparison, style_layout,
                                sweep_table, training_table)

#: Format of the outage tables' values: the paper's precision.
_VALUE = f"{{:.{paper.DECIMALS}f}}"


def header_section(res: ProfileResults) -> list:
    """The run header (:func:`bgfn.report.glance.run_header`) as one Markdown piece."""
    return ["\n".join(run_header(res.profile, res.cfg, res.out, res.current))]


@dataclass
class OutageSection:
    """One outage test on the results page (paper Table ``tab-out1-exin`` or ``tab-real``): four parts, each
    a list of pieces, shown under their own prose.

    Attributes
    ----------
    layout : list
        A missing note when our table is missing; the paper-layout table, ours beside the paper's; its
        provenance line.
    all_rows : list
        Every row and metric of our table and its source line (empty when our table is missing).
    reduction : list
        BGFN's reduction against INS, ours beside the paper's table and text; its source line; the sentences.
    comparison : list
        One Markdown list: BGFN against each other method, outage by outage.
    """

    layout: list
    all_rows: list
    reduction: list
    comparison: list


def shown_tests(res: ProfileResults) -> list[str]:
    """The outage tests the results page shows: the paper's own (always: a missing table gets a note) and a test
    it has no table of (the real drive) when notebook 04 wrote its table or the profile evaluates a dataset of
    it."""
    evaluated = {paper.test_of(d) for d in (res.cfg.get("evaluate") or {}).get("datasets") or []}
    return [t for t in paper.TESTS
            if paper.has_own_values(t) or res.ours.get(t) is not None or t in evaluated]


def outage_section(res: ProfileResults, test: str) -> OutageSection:
    """The section of one outage test (a key of :data:`bgfn.paper.TESTS`): the paper's dataset or field test, or
    our real drive beside the paper's field test."""
    spec = paper.TESTS[test]
    title, profile = spec["title"], res.profile
    ours, published = res.ours[test], res.published[test]
    file = res.table(spec["file"])
    dataset = outage_datasets(res.evaluation).get(test)

    layout = [missing_note(file, f"the {title} table", "notebook 04")] if ours is None else []
    if spec["label"]:
        caption = f"Table {spec['label']}: {spec['caption']}; ours ({profile}) beside the paper's"
    else:                                   # not a table of the paper: its test whose values stand beside ours
        shown = paper.TESTS[paper.published_test(test)]
        caption = f"{spec['caption']}; ours ({profile}) beside the paper's {shown['title']} (Table {shown['label']})"
    layout += [style_layout(paper.layout(ours, published, ours_label=f"ours ({profile})",
                                         paper_label=paper.paper_label(test)), caption),
               outage_provenance(profile, test, res.out, res.evaluation, res.current)]

    all_rows = []
    if ours is not None:
        ev = (res.evaluation or {}).get("evaluate", {})
        all_rows = [compact(ours.set_index(["outage", "method"]).style.format(_VALUE),
                            f"All methods and metrics (m), {title}, profile {profile}"),
                    short_source([file], profile, dataset=dataset, seeds=ev.get("seeds"),
                                 seed_aggregate=ev.get("seed_aggregate"))]

    comp = reduction_comparison(ours, published, res.claims, test)
    reduction = [compact(comp.style.format(_VALUE, na_rep="-"), f"BGFN vs INS, {title} (%)"),
                 short_source([file, paper.OUTAGE_TABLE_FILE, paper.CLAIMS_FILE], profile, dataset=dataset),
                 bullets(reduction_sentences(comp, test=test))]
    return OutageSection(layout, all_rows, reduction, [bullets(comparison_sentences(test, ours, published))])


def energy_section(res: ProfileResults) -> list:
    """Energy per prediction (notebook 05) beside the paper's claim, its source, the sentences."""
    energy = res.energy
    pieces: list = [compact(energy_table(energy, res.claims).style.format(fmt_num),
                            "Energy per prediction and reduction, ours beside the paper's claim")]
    if energy:
        pieces.append(provenance(res.out / RUN_RECORDS["energy"], energy.get("metadata"), res.current,
                                 dataset=f"`{dataset_id(energy['dataset']) if energy.get('dataset') else None}`", seed=energy.get("seed"),
                                 time_steps=energy.get("time_steps"),
                                 checkpoints=", ".join(f"`{p}`" for p in energy.get("checkpoints", {}).values()),
                                 validation_windows=energy.get("windows", {}).get("n_windows")))
    else:
        pieces.append(missing_note(res.out / RUN_RECORDS["energy"], "the energy estimate", "notebook 05"))
    return pieces + [bullets(energy_sentences(energy, res.claims))]


def kf_section(res: ProfileResults) -> list:
    """The full-drive Kalman filter errors (notebook 02) and their source."""
    kt = kf_table(res.kf)
    if kt is None:
        return [missing_note(res.out / RUN_RECORDS["kf_baseline"], "the Kalman filter baseline", "notebook 02")]
    return [compact(kt.style.format(fmt_num), f"GPS/INS filter errors against the reference, profile {res.profile}"),
            provenance(res.out / RUN_RECORDS["kf_baseline"], res.kf.get("meta"), res.current,
                       datasets=[f"`{d}`" for d in kt.index], bias_model=res.kf.get("nav", {}).get("bias_model"))]


def training_section(res: ProfileResults) -> list:
    """The training summary (notebook 03), its source, and per dataset the trained networks (model cards)."""
    file = res.table(SHARED_TABLES["training_summary"])
    tt = training_table(res.training_summary, res.training_times)
    if tt is None:
        return [missing_note(file, "the training summary", "notebook 03")]
    return [compact(tt.style.format(fmt_num), f"Training summary, profile {res.profile}"),
            provenance(file, (res.training or {}).get("meta"), res.current, seeds=res.cfg["train"].get("seeds")),
            "\n".join(f"- `{d}`: {cards_line(model_cards(res.profile, d, res.out.parent))}"
                      for d in tt.index.get_level_values("dataset").unique())]


def odometer_section(res: ProfileResults) -> list:
    """The bars a learned odometer must clear (notebook 07, :mod:`bgfn.studies.odometer.bars`): median max horizontal
    error per dataset, method (the oracle speed per sigma) and duration, its lines, then per dataset (recorded drives
    first) the odometers' speed in a few outages, the error growth over the outage and the speed error's offset per
    outage beside its fluctuation."""
    file = res.table(SHARED_TABLES["odometer_summary"])
    summary = read_csv(file)
    if summary is None or summary.empty:
        return [missing_note(file, "the odometer bars", "notebook 07, `evaluate.odometer`")]
    wide = odometer_table(summary)
    figures = [res.out / "figures" / f"{stem}_{dataset_id(d)}.png" for d in recorded_first(summary["dataset"].unique())
               for stem in ("odometer_speed", "odometer_growth", "odometer_errors")]
    return [compact(wide.style.format("{:.1f}"), f"Median max horizontal error (m) over the sweep's starts, "
                                                 f"profile {res.profile}"),
            bullets(odometer_lines(summary)), *[f for f in figures if f.is_file()]]


def sweep_section(res: ProfileResults) -> list:
    """The outage sweep (notebook 06) as ``median [interval]`` per duration, its source, the paired
    comparisons (:func:`bgfn.report.sweep_words.describe_sweep`) when their table is there."""
    file = res.table(SHARED_TABLES["sweep_summary"])
    st = sweep_table(res.sweep)
    if st is None:
        return [missing_note(file, "the outage sweep", "notebook 06, `evaluate.sweep`")]
    # each drive's rows named by the aids that ran on it (INS+ZUPT on a walker)
    st.index = pd.MultiIndex.from_tuples([(d, aid_label(m, recorded_platform(res.out, d))) for d, m in st.index],
                                         names=st.index.names)
    sw = (res.evaluation or {}).get("evaluate", {}).get("sweep", {})
    pieces = [compact(st.style, f"Median max horizontal error (m) [95 % interval], profile {res.profile}"),
              provenance(file, (res.sweep_record or {}).get("meta"), res.current,
                         datasets=[f"`{d}`" for d in sw.get("datasets", [])], seeds=sw.get("seeds"),
                         starts=sw.get("n_starts"), folds=sw.get("folds"))]
    if res.sweep_pairs is not None:
        datasets = [str(d) for d in res.sweep["dataset"].unique()] if "dataset" in res.sweep.columns else []

        def platform_of(line: str) -> str:       # each line leads with its drive (describe_sweep)
            drive = next((d for d in datasets if line.startswith(f"{d}, ")), None)
            return recorded_platform(res.out, drive) if drive is not None else "car"
        pieces.append(bullets([aid_label(line, platform_of(line))
                               for line in describe_sweep(res.sweep, res.sweep_pairs)]))
    return pieces

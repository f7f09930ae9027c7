"""The results page (notebook 10): our tables beside the paper's, where each number came from, and plain
sentences computed from the numbers.

Inputs (all written by notebooks 01-05 under ``results/<profile>/``; a missing file is reported, never
fatal):

- ``tables/outage_dataset.csv``, ``tables/outage_field.csv`` (notebook 04): ``outage, method, max_east_m,
  max_north_m, rmse_h_m, final_h_m`` -- paper Tables ``tab-out1-exin`` and ``tab-real``;
- ``data/paper/outage_max_errors.csv`` and ``data/paper/claims.yaml`` (read by :mod:`bgfn.paper`): the
  paper's published values (shown in a column group labelled *paper*; never used to choose anything);
- ``kf_baseline.json`` (02), ``training.json`` and ``tables/training_summary.csv`` (03),
  ``outage_evaluation.json`` and ``tables/outage_sweep_summary.csv`` (04), ``energy.json`` (05), the model
  cards ``models/<dataset>/<method>_seed<k>.json`` (03/04): metadata lines under every table.

Modules, in the order the page needs them:

- :mod:`bgfn.report.reading` -- read ``results/<profile>/`` (:func:`read_results`), a missing file is ``None``;
- :mod:`bgfn.report.tables` -- table styling, BGFN's reduction against INS, the energy, filter, training and
  sweep tables;
- :mod:`bgfn.report.provenance` -- the source and run-metadata line under every table;
- :mod:`bgfn.report.sentences` -- plain sentences computed from the numbers;
- :mod:`bgfn.report.profile_comparison` -- profiles side by side, and one profile against the untrained references;
- :mod:`bgfn.report.glance` -- the run header, the *At a glance* lines and ``findings.md``;
- :mod:`bgfn.report.figures` -- the page's figure lists and the four drawings made from the profile;
- :mod:`bgfn.report.sections` -- each section of the page as the pieces to display;
- :mod:`bgfn.report.verdict` -- the verdict on top: every aid per test and the answers to five questions.

Everything public is re-exported here: ``from bgfn import report; report.outage_section(res, "dataset")``.
"""

from bgfn.report.figures import (EXTRA_FIGURES, PAPER_FIGURES, draw_diagrams, extra_figure_section, figure_list,
                                 paper_figure_section)
from bgfn.report.glance import RUN_FILES, findings_markdown, glance_lines, run_header
from bgfn.report.provenance import (cards_line, meta_line, model_cards, outage_datasets, outage_provenance, provenance,
                                    run_meta, short_source)
from bgfn.report.reading import ProfileResults, missing_note, read_csv, read_json, read_results, rel
from bgfn.report.sections import (OutageSection, energy_section, header_section, kf_section, outage_section,
                                  odometer_section, shown_tests, sweep_section, training_section)
from bgfn.report.run_plan import part_off_line, plan_lines
from bgfn.report.sentences import (BASELINES, EXTRA_METHODS, EXTRA_TAGS, bullets, comparison_sentences,
                                   energy_sentences, paper_name, reduction_sentences, summary_sentence, win_counts)
from bgfn.report.tables import (REFERENCE_LABELS, TABLE_STYLES, TRAINING_COLUMNS, best_mask, compact, energy_table,
                                fmt_num, kf_table, reduction_comparison, reductions, style_layout, sweep_table,
                                training_table)
from bgfn.report.profile_comparison import (compared_profiles, profile_tables, reference_sentences, variant_outage_table,
                                  variant_sentences, variant_sweep_table, variant_training_table, variants_section)
from bgfn.report.verdict import Verdict, VerdictInputs, verdict_of, verdict_table
from bgfn.report.verdict_page import HtmlPiece, header_details, short_answers, verdict_top

__all__ = [
    "BASELINES", "EXTRA_METHODS", "EXTRA_TAGS", "PAPER_FIGURES",
    "EXTRA_FIGURES", "RUN_FILES", "TABLE_STYLES",
    "read_csv", "read_json", "missing_note",
    "best_mask", "style_layout", "compact", "reductions", "reduction_comparison", "energy_table", "kf_table",
    "training_table", "sweep_table", "fmt_num", "model_cards", "cards_line", "meta_line", "provenance",
    "short_source", "outage_datasets", "outage_provenance", "run_header", "win_counts", "summary_sentence",
    "comparison_sentences", "reduction_sentences", "energy_sentences", "figure_list", "rel", "glance_lines",
    "reference_sentences", "findings_markdown",
    # public before, not listed: the variants section's functions and the training tables' labels
    "compared_profiles", "profile_tables", "variant_training_table", "variant_outage_table", "variant_sentences",
    "variant_sweep_table", "REFERENCE_LABELS", "TRAINING_COLUMNS",
    # the page as sections of pieces to display (notebook 10)
    "Verdict", "VerdictInputs", "verdict_of", "verdict_table", "HtmlPiece", "header_details", "short_answers",
    "verdict_top",
    "ProfileResults", "read_results", "OutageSection", "header_section", "outage_section", "energy_section",
    "kf_section", "training_section", "sweep_section", "odometer_section", "variants_section", "paper_figure_section",
    "extra_figure_section", "draw_diagrams", "bullets", "run_meta",
    # a test the paper has no table of (the real drive): which tests the page shows, how it names the paper's
    "shown_tests", "paper_name",
    # the run plan in words (bgfn.run_plan: notebook 01, the profile check)
    "plan_lines", "part_off_line",
]

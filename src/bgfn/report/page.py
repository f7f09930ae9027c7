"""The results page's pieces in one namespace, for notebook 10: ``from bgfn.report import page as report;
report.outage_section(res, "dataset")``. The package itself imports nothing, so that a notebook which words its
results with one ``*_words`` module depends on that module only (``tools/notebook_deps.py``)."""

from bgfn.report.figures import (EXTRA_FIGURES, PAPER_FIGURES, draw_diagrams, extra_figure_section, figure_list,
                                 paper_figure_section)
from bgfn.report.glance import RUN_FILES, findings_markdown, glance_lines, run_header
from bgfn.report.provenance import (cards_line, meta_line, model_cards, outage_datasets, outage_provenance, provenance,
                                    run_meta, short_source)
from bgfn.report.reading import ProfileResults, missing_note, read_csv, read_json, read_results, rel
from bgfn.report.sections import (OutageSection, energy_section, header_section, kf_section, outage_section,
                                  odometer_section, shown_tests, sweep_section, training_section)
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
    ]

"""bgfn.report (the results page's tables and sentences), the book's sources and tools/check_book.py.

The book must never show a result typed by hand: :func:`test_book_pages_type_no_results` scans the Markdown
pages (and notebook 10's Markdown cells) for numbers with a unit of length, energy or a percentage, and
accepts only the paper's and the profiles' *settings* listed in :data:`ALLOWED`.
"""

from __future__ import annotations

import importlib.util
import json
import math
import re
from pathlib import Path

import nbformat
import numpy as np
import pandas as pd
import pytest

from bgfn import paper
from bgfn.report import page as report
from bgfn.config import PROJECT_ROOT
from bgfn.report import evaluation_words
from bgfn.report.book_notebooks import main as book_main
from bgfn.report.book_notebooks import one_parameters_cell, rewrite, warnings_in

BOOK = PROJECT_ROOT / "book"


def table(rows):
    return pd.DataFrame(rows, columns=["outage", "method", "max_east_m", "max_north_m"])


OURS = table([(2, "BGFN", 3.0, 4.0), (1, "INS", 20.0, 10.0), (1, "BGFN", 5.0, 12.0), (2, "INS", 6.0, 8.0),
              (1, "MLP", 7.0, 9.0), (1, "GPS", 1.0, 1.0)])
PAPER = table([(1, "INS", 23.1, 23.2), (1, "BGFN", 4.7, 4.8), (2, "BGFN", 1.8, 4.2), (2, "INS", 10.6, 19.6),
               (1, "AT-LSTM", 7.9, 7.7)])


# ----------------------------------------------------------------------------------------------- tables
def test_paper_layout_joins_on_outage_and_method():
    lay = paper.layout(OURS, PAPER, ours_label="ours (t)")
    assert list(lay.index) == ["Outage 1", "Outage 2"]
    assert list(lay.columns.get_level_values(0).unique()) == ["ours (t)", "paper"]
    assert lay.loc["Outage 1", ("ours (t)", "BGFN", "North")] == 12.0
    assert lay.loc["Outage 2", ("ours (t)", "INS", "East")] == 6.0
    assert lay.loc["Outage 2", ("paper", "BGFN", "North")] == 4.2
    assert lay.loc["Outage 1", ("paper", "AT-LSTM", "East")] == 7.9
    # a value one side lacks is NaN, never another row's value
    assert math.isnan(lay.loc["Outage 2", ("ours (t)", "MLP", "East")])
    assert math.isnan(lay.loc["Outage 1", ("paper", "MLP", "North")])
    assert math.isnan(lay.loc["Outage 2", ("paper", "AT-LSTM", "North")])
    # the paper's four methods in its order; the extra GPS row stays out of this layout
    assert list(lay.columns.get_level_values(1).unique()) == list(paper.PAPER_METHODS)


def test_paper_layout_without_our_table_keeps_the_papers_values():
    lay = paper.layout(None, PAPER)
    assert lay[("ours", "BGFN", "East")].isna().all()
    assert lay.loc["Outage 1", ("paper", "INS", "North")] == 23.2


def test_paper_table_read_from_the_transcription():
    raw = pd.read_csv(PROJECT_ROOT / "data" / "paper" / "outage_max_errors.csv")
    for test in [t for t in paper.TESTS if paper.has_own_values(t)]:
        p = paper.outage_table(test)
        lay = paper.layout(None, p)
        for r in raw[raw["test"] == test].itertuples():
            assert lay.loc[f"Outage {r.outage}", ("paper", r.method, "East")] == r.max_east_m
            assert lay.loc[f"Outage {r.outage}", ("paper", r.method, "North")] == r.max_north_m
    with pytest.raises(ValueError):
        paper.outage_table("no-such-test")


def test_best_mask_marks_the_smallest_per_source_and_axis():
    mask = report.best_mask(paper.layout(OURS, PAPER))
    assert mask.loc["Outage 1", ("ours", "BGFN", "East")]            # 5 < 7 < 20
    assert mask.loc["Outage 1", ("ours", "MLP", "North")]            # 9 < 10 < 12
    assert not mask.loc["Outage 1", ("ours", "BGFN", "North")]
    assert mask.loc["Outage 1", ("paper", "BGFN", "East")] and mask.loc["Outage 1", ("paper", "BGFN", "North")]
    html = report.style_layout(paper.layout(OURS, PAPER), "cap").to_html()
    assert "cap" in html and "font-weight: bold" in html and "<table" in html


def test_reductions_by_hand():
    red = report.reductions(OURS).set_index(["outage", "method"])
    # outage 1: INS 20 / 10 -> BGFN 5 / 12: east 100 (20 - 5) / 20 = 75 %, north 100 (10 - 12) / 10 = -20 %
    assert red.loc[(1, "BGFN"), "east_pct"] == pytest.approx(75.0)
    assert red.loc[(1, "BGFN"), "north_pct"] == pytest.approx(-20.0)
    # MLP 7 / 9: 65 % and 10 %; outage 2: INS 6 / 8 -> BGFN 3 / 4: 50 % and 50 %
    assert red.loc[(1, "MLP"), "east_pct"] == pytest.approx(65.0)
    assert red.loc[(1, "MLP"), "north_pct"] == pytest.approx(10.0)
    assert red.loc[(2, "BGFN"), ["east_pct", "north_pct"]].tolist() == pytest.approx([50.0, 50.0])
    assert (1, "INS") not in red.index


def test_reduction_comparison_ours_paper_table_and_text():
    claims = {"bgfn_reduction_vs_ins_pct": {"dataset_outage1": {"east": 79.7, "north": 79.3}}}
    comp = report.reduction_comparison(OURS, PAPER, claims, "dataset")
    assert comp.loc["Outage 1", ("ours", "East")] == pytest.approx(75.0)
    assert comp.loc["Outage 1", ("paper (table)", "East")] == pytest.approx(100 * (23.1 - 4.7) / 23.1)
    assert comp.loc["Outage 1", ("paper (text)", "North")] == 79.3
    assert math.isnan(comp.loc["Outage 2", ("paper (text)", "East")])
    lines = report.reduction_sentences(comp)
    assert "Outage 1, east: with BGFN the max error of INS is reduced by 75.0 %" in lines[0]
    assert "increased by 20.0 %" in lines[1]


def test_the_papers_text_agrees_with_its_tables():
    # a consistency check of the transcription: each percentage of Sec. 4 follows from the tables
    claims = paper.claims()
    for key, stated in claims["bgfn_reduction_vs_ins_pct"].items():
        test, outage = key.split("_outage")
        comp = report.reduction_comparison(None, paper.outage_table(test), claims, test)
        for axis in ("East", "North"):
            assert comp.loc[f"Outage {outage}", ("paper (table)", axis)] == pytest.approx(
                stated[axis.lower()], abs=0.05)


def test_energy_table_and_sentences():
    energy = {"energy_uj_per_prediction": {"bgfn": 0.25, "transformer": 1.0}, "reduction_pct": 75.0,
              "macs": {"bgfn": 10.0, "transformer": 100.0}, "sops": {"bgfn": 5.0}, "e_mac_pj": 4.6,
              "e_ac_pj": 0.9, "time_steps": 4}
    claims = {"energy_reduction_vs_transformer_pct": 66.3}
    t = report.energy_table(energy, claims)
    assert t.loc["energy reduction (%)", "ours"] == 75.0 and t.loc["energy reduction (%)", "paper"] == 66.3
    assert t.loc["BGFN energy per prediction (µJ)", "ours"] == 0.25
    assert math.isnan(t.loc["BGFN energy per prediction (µJ)", "paper"])
    s = report.energy_sentences(energy, claims)[0]
    assert "75.0 % less" in s and "66.3 %" in s and "8.7 percentage points higher" in s
    missing = report.energy_table(None, claims)
    assert missing["ours"].isna().all() and missing.loc["energy reduction (%)", "paper"] == 66.3
    assert "missing" in report.energy_sentences(None, claims)[0]


def test_an_untrained_bgfn_claims_no_energy_saving():
    # energy.json of a BGFN whose best epoch is 0 (energy.allow_untrained): its 99.7 % is an untrained network's
    energy = {"energy_uj_per_prediction": {"bgfn": 0.003, "transformer": 1.0}, "reduction_pct": 99.7,
              "macs": {"bgfn": 10.0, "transformer": 100.0}, "sops": {"bgfn": 5.0}, "e_mac_pj": 4.6,
              "e_ac_pj": 0.9, "time_steps": 4, "checkpoint_epochs": {"bgfn": 0, "transformer": 7},
              "improved": {"bgfn": False, "transformer": True}}
    claims = {"energy_reduction_vs_transformer_pct": 66.3}
    lines = report.energy_sentences(energy, claims)
    assert len(lines) == 1 and lines[0].startswith("BGFN did not train: the checkpoint measured (best epoch 0)")
    assert "no energy saving against the Transformer twin is claimed" in lines[0]
    assert "99.7" not in lines[0] and "less energy" not in lines[0]
    t = report.energy_table(energy, claims)
    assert math.isnan(t.loc["energy reduction (%)", "ours"]) and t.loc["energy reduction (%)", "paper"] == 66.3
    assert t.loc["BGFN energy per prediction (µJ)", "ours"] == 0.003                 # measured, not compared
    # a file written before the flag: its checkpoint_epochs say the same
    older = {k: v for k, v in energy.items() if k != "improved"}
    assert report.energy_sentences(older, claims)[0].startswith("BGFN did not train")
    trained = {**energy, "checkpoint_epochs": {"bgfn": 4}, "improved": {"bgfn": True}}
    assert "99.7 % less energy" in report.energy_sentences(trained, claims)[0]


def test_comparison_sentences_say_who_wins():
    lines = report.comparison_sentences("dataset", OURS, PAPER)
    by = {(ln.split(",")[0], ln.split(" vs ")[1].split(":")[0]): ln for ln in lines}
    ins1 = by[("Outage 1", "INS")]
    assert "BGFN's max east error is 5.0 m vs INS's 20.0 m, its max north error 12.0 m vs 10.0 m" in ins1
    assert "better in east, worse in north" in ins1
    assert "paper: 4.7 m vs 23.1 m east, 4.8 m vs 23.2 m north, better on both axes" in ins1
    assert "worse on both axes" in by[("Outage 1", "GPS")] and "lower bound" in by[("Outage 1", "GPS")]
    assert "better on both axes" in by[("Outage 2", "INS")]
    # equal at the tables' precision is called equal
    tie = table([(1, "INS", 5.04, 3.0), (1, "BGFN", 5.0, 2.0)])
    assert "equal in east, better in north" in report.comparison_sentences("field", tie, None)[0]


def test_win_counts_and_summary():
    assert report.win_counts(OURS)["INS"] == (3, 4)            # 5<20, 12>10, 3<6, 4<8
    assert report.win_counts(OURS)["MLP"] == (1, 2)            # outage 1 only: 5<7, 12>9
    assert report.win_counts(PAPER)["INS"] == (4, 4)
    s = report.summary_sentence("dataset", OURS, PAPER)
    assert "against INS in 3 of 4 (paper: 4 of 4)" in s and "against MLP in 1 of 2" in s
    assert "missing" in report.summary_sentence("field", None, PAPER)


def test_missing_inputs_are_reported_not_fatal(tmp_path):
    assert report.read_csv(tmp_path / "nope.csv") is None
    assert report.read_json(tmp_path / "nope.json") is None
    assert report.kf_table(None) is None and report.training_table(None) is None
    assert report.sweep_table(None) is None
    assert "is missing" in report.missing_note(tmp_path / "nope.csv", "the sweep", "notebook 04")
    (tmp_path / "a.png").write_bytes(b"x")
    figs = report.figure_list(tmp_path, [{"label": "a", "file": "a.png", "by": "x", "caption": "c"},
                                         {"label": "b", "file": "b_{dataset}.png", "by": "x", "caption": "{dataset}",
                                          "datasets": "sweep"}],
                              {"all": ["d1", "d2"], "sweep": ["d2"]})
    assert [(f["file"], f["exists"]) for f in figs] == [("a.png", True), ("b_d2.png", False)]
    assert figs[1]["caption"] == "d2"


def test_read_csv_skips_metadata_comments(tmp_path):
    p = tmp_path / "t.csv"
    p.write_text("# profile: smoke\n# seed: 1\noutage,method,max_east_m,max_north_m\n1,INS,2.5,3.5\n")
    t = report.read_csv(p)
    assert list(t.columns) == ["outage", "method", "max_east_m", "max_north_m"] and t.iloc[0]["max_east_m"] == 2.5


def test_meta_and_provenance_lines():
    meta = {"profile": "smoke", "params_file": "params/smoke.yaml", "params_sha256": "a" * 64, "seed": 7,
            "git_commit": "0123456789abcdef", "git_dirty": True, "packages": {"torch": "2.0", "spikingjelly": "2.0.0"}}
    same = report.meta_line(meta, {"params_sha256": "a" * 64})
    assert "profile `smoke`" in same and "unchanged since" in same and "commit `0123456`" in same
    assert "uncommitted" in same and "torch 2.0" in same
    assert "**changed since**" in report.meta_line(meta, {"params_sha256": "b" * 64})
    line = report.provenance("results/smoke/tables/x.csv", meta, None, dataset="`d`", seeds=[0, 1, 2])
    assert line.startswith("*Source: `results/smoke/tables/x.csv`") and "dataset `d`" in line
    assert "seeds 0, 1, 2" in line
    assert report.meta_line(None) == "no run metadata recorded"


def test_cards_line_and_outage_provenance(tmp_path):
    d = tmp_path / "p" / "models" / "ds"
    d.mkdir(parents=True)
    for m, seed in (("bgfn", 0), ("bgfn", 1), ("mlp", 0)):
        card = {"method": m, "seed": seed, "size": "smoke", "epochs_run": 2 + seed, "options": {"window": 50},
                "size_cfg": {"dim": 16, "depth": 1, "heads": 2, "time_steps": 2, "ffn_dim": 16}}
        (d / f"{m}_seed{seed}.json").write_text(json.dumps(card))
    (d / "fold0").mkdir()
    (d / "fold0" / "bgfn_seed9.json").write_text(json.dumps({"method": "bgfn", "seed": 9}))
    cards = report.model_cards("p", "ds", tmp_path)
    assert len(cards) == 3                                      # fold models are not the tables' networks
    line = report.cards_line(cards)
    assert "seeds 0, 1" in line and "T_s 2" in line and "window N = 50" in line and "epochs run 2-3" in line
    ev = {"datasets": ["turin-sim-ekinox", "turin-sim-mpu6000"], "meta": {"profile": "p"},
          "evaluate": {"seeds": [0, 1], "seed_aggregate": "median"}, "outage_windows": [[100.0, 30.0]]}
    assert report.outage_datasets(ev) == {"dataset": "turin-sim-ekinox", "field": "turin-sim-mpu6000"}
    prov = report.outage_provenance("p", "dataset", tmp_path / "p", ev)
    assert "dataset `turin-sim-ekinox`" in prov and "seeds 0, 1 (median over seeds)" in prov
    assert "30 s from 100 s (GPS time of week)" in prov


def test_training_and_sweep_tables():
    summary = pd.DataFrame({"dataset": ["d"], "method": ["at_lstm"], "params": [722], "seeds": [3],
                            "val_rmse_m_mean": [2.2]})
    t = report.training_table(summary)
    assert t.index[0] == ("d", "AT-LSTM") and t.loc[("d", "AT-LSTM"), "val. RMSE (m)"] == 2.2
    sw = pd.DataFrame({"dataset": ["d", "d"], "duration_s": [10.0, 30.0], "method": ["BGFN", "BGFN"], "n": [4, 4],
                       "n_starts": [2, 2], "median_m": [1.23, 4.56], "ci_lo_m": [1.0, 4.0], "ci_hi_m": [2.0, 5.0]})
    w = report.sweep_table(sw)
    assert w.loc[("d", "BGFN"), "10 s"] == "1.2 [1.0, 2.0]" and w.loc[("d", "BGFN"), "30 s"] == "4.6 [4.0, 5.0]"
    assert report.fmt_num(2800.0) == "2,800" and report.fmt_num(0.0133) == "0.0133" and report.fmt_num(np.nan) == "-"


# ----------------------------------------------------------------------------------------------- the book
#: Numbers with a unit the book may type: the paper's and the profiles' settings, never a result.
ALLOWED: dict[str, str] = {
    "0.05 m": "truth smoothing sigma (setting, (deviations page)",
    "100 m/s": "the velocity std that makes NaveGo's velocity rows carry nothing (setting of make navego-check)",
    "30 %": "how far our setup of NaveGo may lie from NaveGo itself (bgfn.studies.ins_fidelity.ins_setups.NAVEGO_TOLERANCE)",
    "10 %": "Ekinox run-to-run bias part (setting)",
    "3 %": "MPU-6000 scale-factor tolerance (setting)",
    "2 %": "MPU-6000 cross-axis tolerance (setting)",
    "[0.3, 0.3, 0.6] m": "simulated GNSS white noise (setting)",
    "[1, 1, 2] m": "simulated GNSS correlated noise (setting)",
    "[-0.369, 0, -0.219] m": "lever arm (setting)",
    "[1, 1, 3] m": "Ekinox GNSS stdm (data setting)",
    "4.6 pJ": "45 nm float32 MAC energy (Horowitz 2014, setting)",
    "0.9 pJ": "45 nm float32 add energy (Horowitz 2014, setting)",
    "95 %": "bootstrap interval level (setting)",
}
UNIT = r"(?:%|m/s\b|m\b|km\b|cm\b|mm\b|µJ|uJ|mJ|nJ|pJ|J\b)"
RESULT_LIKE = re.compile(r"(?<![\w.\-])(?:\[[^\]\n]*\d[^\]\n]*\]|-?\d+(?:\.\d+)?)\s*" + UNIT)
#: Directive options (figure widths) are layout, not numbers of the paper.
OPTION_LINE = re.compile(r"^\s*:(?:width|height|scale|align|name):.*$", re.M)


def result_like_numbers(text: str) -> list[str]:
    text = OPTION_LINE.sub("", text).replace("$", "").replace("−", "-").replace("\u2009", " ")
    return [" ".join(m.group(0).split()) for m in RESULT_LIKE.finditer(text)]


def book_texts() -> dict[str, str]:
    pages = {p.name: p.read_text(encoding="utf-8") for p in sorted(BOOK.glob("*.md")) if p.name != "README.md"}
    for path in sorted((PROJECT_ROOT / "notebooks").glob("*.ipynb")):  # every notebook is a book page
        nb = nbformat.read(path, as_version=4)
        pages[f"{path.name} (markdown)"] = "\n".join(c.source for c in nb.cells if c.cell_type == "markdown")
    return pages


def test_scanner_finds_typed_results():
    found = result_like_numbers("BGFN reaches 4.7 m, i.e. 79.7 % less; energy 0.013 µJ; [0.5, 0.6, -2.1] m "
                                "off; $E = 4.6$ pJ\n:width: 90%\n")
    assert found == ["4.7 m", "79.7 %", "0.013 µJ", "[0.5, 0.6, -2.1] m", "4.6 pJ"]
    assert result_like_numbers("Eq. (eq13), 15 states, 100 Hz, 30 s, window N=200, item 3 mentions") == []


def test_book_pages_type_no_results():
    bad = [f"{page}: {num!r}" for page, text in book_texts().items() for num in result_like_numbers(text)
           if num not in ALLOWED]
    assert not bad, ("numbers that look like results are typed in the book (let the code produce them, or add "
                     "a paper/profile *setting* to ALLOWED with its reason):\n  " + "\n  ".join(bad))


def test_book_figures_exist():
    # (links to the code page: tests/test_docs.py)
    for page in BOOK.glob("*.md"):
        if page.name == "README.md":                            # not part of the book
            continue
        for fig in re.findall(r"```\{figure\}\s+(\S+)", page.read_text(encoding="utf-8")):
            name = Path(fig).name
            produced = name in {e["file"] for e in report.PAPER_FIGURES}
            assert not fig.startswith("_generated/") or produced, (
                f"{page.name}: {fig} is not one of the figures every profile produces (report.PAPER_FIGURES)")


def test_results_notebook_is_thin_and_wired_in():
    nb = nbformat.read(PROJECT_ROOT / "notebooks" / "10_results.ipynb", as_version=4)
    code = [c for c in nb.cells if c.cell_type == "code"]
    assert "parameters" in code[0].metadata.get("tags", [])
    assert code[0].source.strip().splitlines()[0] == 'profile = "quick"' and "variants = [" in code[0].source
    assert all(not c.get("outputs") and c.get("execution_count") is None for c in code), "store it without outputs"
    assert nb.cells[0].cell_type == "markdown" and nb.cells[0].source.startswith("# Results")
    make = (PROJECT_ROOT / "Makefile").read_text()
    assert re.search(r"\b09_own_logs 10_results$", make, re.M)            # the last of NOTEBOOKS
    assert re.search(r"^\$\(RES\)/notebooks/10_results\.ipynb: \$\(filter-out \$\(RES\)/notebooks/10_results\.ipynb ", make, re.M)
    toc = (BOOK / "_toc.yml").read_text()
    assert "file: notebooks/10_results" in toc and "file: code" in toc


# ----------------------------------------------------------------------------------------------- check_book
def _check_book():
    spec = importlib.util.spec_from_file_location("check_book", PROJECT_ROOT / "tools" / "check_book.py")
    mod = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(mod)
    return mod


def _site(root: Path, results_body: str, img: bytes = b"png") -> None:
    (root / "notebooks").mkdir(parents=True)
    (root / "_images").mkdir()
    (root / "_images" / "a.png").write_bytes(img)
    (root / "index.html").write_text('<meta http-equiv="Refresh" content="0; url=intro.html" />')
    (root / "intro.html").write_text('<h1 id="top">x</h1><table><tr><td>1</td></tr></table>'
                                     '<img src="_images/a.png"><a href="notebooks/10_results.html#res">r</a>')
    (root / "notebooks" / "10_results.html").write_text(f'<h1 id="res">Results</h1>{results_body}')


def test_check_book_accepts_a_good_site(tmp_path):
    cb = _check_book()
    _site(tmp_path, '<table><tr><td>1</td></tr></table><img src="../_images/a.png"><a href="../intro.html#top">i</a>')
    assert cb.check(tmp_path) == [] and cb.check_content(tmp_path) == []
    assert cb.index_page(tmp_path) == (tmp_path / "intro.html").resolve()
    assert cb.main([str(tmp_path)]) == 0


def test_check_book_finds_broken_images_anchors_and_bare_results(tmp_path):
    cb = _check_book()
    _site(tmp_path, '<img src="../_images/missing.png"><a href="../intro.html#nowhere">i</a>', img=b"")
    problems = "\n".join(cb.check(tmp_path) + cb.check_content(tmp_path))
    assert "missing _images/missing.png" in problems
    assert "no anchor #nowhere" in problems
    assert "empty file _images/a.png" in problems
    assert "notebooks/10_results.html (results page): no <table>" in problems
    assert cb.main([str(tmp_path)]) == 1


def test_variant_tables_put_profiles_side_by_side():
    def summary(bgfn, mlp):
        return pd.DataFrame({"dataset": ["d", "d"], "method": ["bgfn", "mlp"], "val_rmse_m_mean": [bgfn, mlp],
                             "val_rmse_zero_m": [10.0, 10.0], "val_rmse_last_m": [1.4, 1.4]})
    t = report.variant_training_table({"quick": summary(5.0, 7.0), "quick-heading": summary(1.7, 0.8),
                                       "absent": None})
    assert list(t.columns) == ["val. RMSE quick", "val. RMSE quick-heading", "zero", "last increment"]
    assert t.loc[("d", "BGFN"), "val. RMSE quick-heading"] == 1.7
    lines = report.variant_sentences(t)
    assert lines[0].endswith("below the last increment: no network.")
    assert "BGFN 1.70 m against last increment 1.40 m" in lines[1] and lines[1].endswith(": MLP.")
    out = pd.DataFrame({"outage": [1, 1], "method": ["INS", "BGFN"], "max_east_m": [8.0, 100.0],
                        "max_north_m": [2.0, 300.0], "rmse_h_m": 1.0, "final_h_m": 1.0})
    o = report.variant_outage_table({"quick": out, "quick-heading": out.assign(max_east_m=[8.0, 4.0])})
    assert o.loc[(1, "INS")].tolist() == [5.0, 5.0]          # (8 + 2) / 2 in both
    assert o.loc[(1, "BGFN")].tolist() == [200.0, 152.0]     # (100 + 300) / 2, (4 + 300) / 2
    assert report.variant_training_table({"a": None}) is None
    # a table with the INS increment reference (newer notebooks) shows it and names it in the sentences
    with_ins = {"quick": summary(5.0, 7.0).assign(val_rmse_ins_m=0.7)}
    t = report.variant_training_table(with_ins)
    assert list(t.columns) == ["val. RMSE quick", "zero", "last increment", "INS increment"]
    assert report.variant_sentences(t)[0].endswith("no network; the INS increment (the GPS-aided INS's speed "
                                                   "over the same interval): 0.7 m.")


def test_variant_sweep_table_aligns_durations_and_methods():
    def summary(bgfn):
        return pd.DataFrame({"dataset": "d", "duration_s": [10.0, 10.0, 120.0, 120.0],
                             "method": ["INS", "BGFN"] * 2, "median_m": [3.0, bgfn[0], 500.0, bgfn[1]]})
    t = report.variant_sweep_table({"quick": summary((13.0, 390.0)), "quick-heading": summary((5.0, 110.0)),
                                    "none": None})
    assert list(t.columns) == ["quick", "quick-heading"]
    assert t.loc[("d", 120.0, "BGFN")].tolist() == [390.0, 110.0]
    assert t.loc[("d", 10.0, "INS")].tolist() == [3.0, 3.0]
    assert report.variant_sweep_table({"x": None}) is None


def test_compared_profiles_adds_the_base_and_splits_on_results(tmp_path):
    for p in ("quick", "quick-heading"):
        (tmp_path / p / "tables").mkdir(parents=True)
        (tmp_path / p / "tables" / "training_summary.csv").write_text("dataset,method\n")
    # quick-heading builds on quick: compared with it even when not listed; no profile twice
    assert report.compared_profiles("quick-heading", ["quick-heading"], tmp_path) == (["quick-heading", "quick"], [])
    assert report.compared_profiles("quick", ["quick-heading", "smoke"], tmp_path) == (
        ["quick", "quick-heading"], ["smoke"])
    assert report.profile_tables(["quick", "smoke"], "training_summary.csv", tmp_path)["smoke"] is None


def test_findings_for_the_first_page_are_the_glance_lines_as_a_list():
    text = report.findings_markdown("quick", ["BGFN beats INS in 0 of 4.", "energy: 98.6 % less."])
    head, body = text.split("\n\n")
    assert head.startswith("From profile `quick` (`params/quick.yaml`)") and "{doc}`results page" in head
    assert body.splitlines() == ["- BGFN beats INS in 0 of 4.", "- energy: 98.6 % less."]
    intro = (BOOK / "intro.md").read_text(encoding="utf-8")
    assert "_generated/findings.md" in intro                    # the first page includes them


# ----------------------------------------------------------------------------------------------- page sections
def results(tmp_path, ours=None, **inputs) -> report.ProfileResults:
    """A ProfileResults of profile ``p`` under ``tmp_path/p`` with the paper's tables and claims, and ``ours``
    as the dataset test's table (the field test's missing)."""
    out = tmp_path / "p"
    fields = {"profile": "p", "cfg": {"train": {"seeds": [0], "datasets": ["d1"]}}, "out": out, "current": None,
              "claims": paper.claims(), "kf": None, "training": None, "evaluation": None, "energy": None,
              "ours": {"dataset": ours, "field": None}, "published": {t: paper.published_values(t) for t in paper.TESTS},
              "training_summary": None, "training_times": None, "sweep": None, "sweep_pairs": None}
    return report.ProfileResults(**{**fields, **inputs})


def test_read_results_reads_what_is_there_and_none_for_the_rest(tmp_path):
    (tmp_path / "tables").mkdir()
    OURS.to_csv(tmp_path / "tables" / "outage_dataset.csv", index=False)
    (tmp_path / "energy.json").write_text(json.dumps({"reduction_pct": 75.0}))
    res = report.read_results("smoke", tmp_path)
    assert res.out == tmp_path and res.cfg["profile"] == "smoke" and res.current["profile"] == "smoke"
    pd.testing.assert_frame_equal(res.ours["dataset"], OURS)
    assert res.ours["field"] is None and res.kf is None and res.sweep is None
    assert res.energy == {"reduction_pct": 75.0}
    pd.testing.assert_frame_equal(res.published["field"], paper.outage_table("field"))
    assert res.claims == paper.claims() and res.table("x.csv") == tmp_path / "tables" / "x.csv"


def test_outage_section_serves_both_tests(tmp_path):
    res = results(tmp_path, OURS)
    ds = report.outage_section(res, "dataset")
    # our table there: the paper-layout table with the paper's label and caption, then its provenance line
    assert len(ds.layout) == 2
    caption = paper.TESTS["dataset"]["caption"]
    assert ds.layout[0].caption == f"Table tab-out1-exin: {caption}; ours (p) beside the paper's"
    assert ds.layout[1].startswith("*Source: `") and "outage_dataset.csv" in ds.layout[1]
    assert ds.all_rows[0].caption == "All methods and metrics (m), dataset test, profile p"
    assert ds.reduction[0].caption == "BGFN vs INS, dataset test (%)"
    assert "outage_max_errors.csv" in ds.reduction[1] and "claims.yaml" in ds.reduction[1]
    assert ds.reduction[2].startswith("- Outage 1, east: with BGFN the max error of INS is reduced by 75.0 %")
    assert ds.comparison == ["\n".join(f"- {s}" for s in report.comparison_sentences("dataset", OURS,
                                                                                      res.published["dataset"]))]
    # our table missing: a note naming the producer, the paper's values still shown, no table of ours
    fd = report.outage_section(res, "field")
    assert "the field test table was not produced" in fd.layout[0] and "notebook 04" in fd.layout[0]
    assert fd.layout[1].caption.startswith("Table tab-real: ")
    assert fd.all_rows == [] and fd.comparison == ["- Outage 1: no BGFN row in our table.\n"
                                                   "- Outage 2: no BGFN row in our table."]
    assert fd.layout[1].data[("paper", "BGFN", "East")].notna().all()


def test_the_real_drive_stands_beside_the_papers_field_test(tmp_path):
    from bgfn import evaluate as ev
    from bgfn.nav import baseline

    assert paper.test_of("rtklib-drive0708") == "real" and not paper.has_own_values("real")
    pd.testing.assert_frame_equal(paper.published_values("real"), paper.outage_table("field"))
    assert (paper.paper_label("real"), paper.paper_label("field")) == ("paper (field test)", "paper")
    assert evaluation_words.paper_table_title("field") == "Table 2 (field test)"
    assert evaluation_words.paper_table_title("real") == "real drive (not in the paper; beside it Table 2 (field test))"
    res = results(tmp_path, OURS)
    assert report.shown_tests(res) == ["dataset", "field"]          # no real-drive table, none evaluated: hidden
    glance = report.glance_lines("p", res.ours, res.published, None, res.claims, None)
    assert not any(line.startswith("Real drive") for line in glance)
    res.ours["real"] = OURS
    assert report.shown_tests(res) == ["dataset", "field", "real"]
    sec = report.outage_section(res, "real")
    caption = sec.layout[0].caption
    assert caption.startswith(paper.TESTS["real"]["caption"]) and "field test (Table tab-real)" in caption
    lay = sec.layout[0].data
    assert lay.loc["Outage 1", ("paper (field test)", "INS", "East")] == 289.4      # the paper's Table tab-real
    assert not any(c[0] == "paper" for c in lay.columns)
    # BGFN's reduction beside the field test's table and text (its outage 2, the manoeuvre: 90.0 % east)
    assert "paper's field test table" in sec.reduction[2] and "paper's field test text: 90.0 %" in sec.reduction[2]
    glance = report.glance_lines("p", res.ours, res.published, None, res.claims, None)
    real = [line for line in glance if line.startswith("Real drive")]
    assert len(real) == 1 and "(paper's field test: " in real[0]
    assert "(paper's field test: " in report.comparison_sentences("real", OURS, res.published["real"])[0]
    # notebook 04's claim lines quote the paper's own tests only; notebook 02's INS row says whose it is
    reductions = {"rtklib-drive0708": report.reduction_comparison(OURS, res.published["real"], res.claims, "real")}
    claimed = evaluation_words.claim_lines({})
    assert len(claimed) == 2 and all("real drive" not in line for line in claimed)   # dataset 1, field 2
    beside = baseline.ins_layout(pd.DataFrame({"max_abs_east": [1.0, 2.0], "max_abs_north": [3.0, 4.0]}),
                                 "rtklib-drive0708")
    assert beside.loc["Outage 2", ("paper (field test)", "INS", "East")] == 477.5
    assert reductions["rtklib-drive0708"].loc["Outage 2", ("paper (text)", "East")] == 90.0


def test_sections_name_the_notebook_of_a_missing_input(tmp_path):
    res = results(tmp_path)
    assert "notebook 02" in report.kf_section(res)[0] and "kf_baseline.json" in report.kf_section(res)[0]
    assert "notebook 03" in report.training_section(res)[0]
    assert "notebook 06" in report.sweep_section(res)[0]
    assert "notebook 07" in report.odometer_section(res)[0] and "outage_odometer_summary.csv" in \
        report.odometer_section(res)[0]
    energy = report.energy_section(res)
    assert "energy.json` is missing" in energy[1] and "notebook 05" in energy[1]
    assert energy[0].data.loc["energy reduction (%)", "paper"] == paper.claims()["energy_reduction_vs_transformer_pct"]
    kf = {"meta": None, "nav": {"bias_model": "markov"},
          "datasets": {"d1": {"gnss_updates": 10, "rms": {"north": 1.0, "yaw": math.pi / 180}}}}
    table, line = report.kf_section(results(tmp_path, kf=kf))
    assert table.data.loc["d1", "RMS yaw (deg)"] == pytest.approx(1.0)
    assert "datasets `d1`" in line and "bias model markov" in line


def test_variants_section_puts_a_run_variant_beside_and_names_a_missing_one(tmp_path):
    for p, bgfn in (("quick", 5.0), ("quick-heading", 1.7)):
        (tmp_path / p / "tables").mkdir(parents=True)
        pd.DataFrame({"dataset": ["d"], "method": ["bgfn"], "val_rmse_m_mean": [bgfn], "val_rmse_zero_m": [10.0],
                      "val_rmse_last_m": [1.4]}).to_csv(tmp_path / p / "tables" / "training_summary.csv", index=False)
    pieces = report.variants_section("quick", ["quick-heading", "smoke"], tmp_path)
    assert "`make reproduce PROFILE=smoke`" in pieces[0] and "the variant `smoke`" in pieces[0]
    assert list(pieces[1].data.columns) == ["val. RMSE quick", "val. RMSE quick-heading", "zero", "last increment"]
    assert "`quick-heading`, `d`: BGFN 1.70 m" in pieces[2]
    assert pieces[-1].startswith("*From ") and "profile `quick and quick-heading`" in pieces[-1]
    # nothing run beside the profile: only the notes
    assert report.variants_section("quick", ["smoke"], tmp_path / "none") == [
        report.missing_note(tmp_path / "none" / p / "tables" / "training_summary.csv", f"the variant `{p}`",
                            f"`make reproduce PROFILE={p}`") for p in ("smoke",)]


def test_figure_sections_show_a_file_or_say_it_is_missing(tmp_path):
    res = results(tmp_path)
    (res.out / "figures").mkdir(parents=True)
    (res.out / "figures" / "trajectory_3d.png").write_bytes(b"png")
    pieces = report.paper_figure_section(res)
    assert len(pieces) == 2 * len(report.PAPER_FIGURES)           # a heading, then the file or a note
    i = [e["file"] for e in report.PAPER_FIGURES].index("trajectory_3d.png")
    assert pieces[2 * i].startswith("**Fig. 3d** (paper).") and "Regenerated by notebook 01" in pieces[2 * i]
    assert pieces[2 * i + 1] == res.out / "figures" / "trajectory_3d.png"
    assert "is missing" in pieces[1] and "notebook 10" in pieces[1]          # the first diagram, not drawn here
    extra = report.extra_figure_section(res)                      # {dataset} figures: per trained dataset
    assert "**Training curves.** Training and validation loss per epoch (d1)." in "\n".join(
        p for p in extra if isinstance(p, str))


def test_draw_diagrams_writes_the_papers_figures_made_by_notebook_06(tmp_path):
    from bgfn.profile_schema import load_profile

    written = report.draw_diagrams(load_profile("smoke"), None, tmp_path)
    assert [p.name for p in written] == [e["file"] for e in report.PAPER_FIGURES if e["by"].startswith("notebook 10")]
    assert all(p.parent == tmp_path and p.stat().st_size > 0 for p in written)


def test_odometer_section_lists_the_bars_and_the_oracle_per_sigma(tmp_path):
    res = results(tmp_path)
    rows = [("INS+NHC", float("nan"), 50.0, 1.0), ("RIDGE-ODO", float("nan"), 45.0, 0.9),
            ("INS+NHC+HOLD", float("nan"), 44.0, 0.99), ("ORACLE-SPEED", 0.1, 34.0, 0.9),
            ("ORACLE-SPEED", 2.0, 60.0, 1.1)]
    summary = pd.DataFrame([{"dataset": "d", "duration_s": 60.0, "method": m, "sigma_mps": s, "max_h_m": v,
                             "ratio_to_nhc": r, "speed_rmse_mps": 1.0, "coverage_2sigma": 0.95, "runs": 20}
                            for m, s, v, r in rows])
    (res.out / "tables").mkdir(parents=True, exist_ok=True)
    summary.to_csv(res.table("outage_odometer_summary.csv"), index=False)
    table, lines = report.odometer_section(res)
    assert list(table.data.index.get_level_values(1)) == ["INS+NHC", "INS+NHC+HOLD", "RIDGE-ODO",
                                                         "ORACLE-SPEED 0.1 m/s", "ORACLE-SPEED 2 m/s"]
    assert table.data.loc[("d", "RIDGE-ODO"), "60 s"] == 45.0
    assert "INS+NHC 50.0 m" in lines and "an oracle speed beats INS+NHC up to a noise of 0.1 m/s" in lines


def test_the_book_shows_one_parameters_cell_with_the_values_of_the_run(tmp_path):
    def cell(src, tags=()):
        return {"cell_type": "code", "metadata": {"tags": list(tags)}, "source": src, "outputs": []}

    nb = {"cells": [cell("# title"), cell('profile = "quick"\n# compared profiles\nvariants = ["a"]  # shown', ["parameters"]),
                    cell('# Parameters\nprofile = "paper"\nextra = 3\n', ["injected-parameters"]), cell("x = 1")]}
    path = tmp_path / "nb.ipynb"
    path.write_text(json.dumps(nb))
    rewrite(path)
    out = json.loads(path.read_text())
    assert len(out["cells"]) == 3 and not any("injected-parameters" in c["metadata"]["tags"] for c in out["cells"])
    # the run's value in the notebook's own cell, its comments kept; a value the cell did not assign is appended
    assert out["cells"][1]["source"] == 'profile = "paper"\n# compared profiles\nvariants = ["a"]  # shown\nextra = 3'
    assert one_parameters_cell({"cells": [cell("x = 1", ["parameters"])]})["cells"][0]["source"] == "x = 1"


def test_a_warning_in_an_executed_notebook_stops_the_book(tmp_path):
    nb = {"cells": [{"cell_type": "code", "metadata": {}, "source": "x", "outputs": [
        {"output_type": "stream", "name": "stderr",
         "text": ["/src/bgfn/learning/coverage.py:57: RuntimeWarning: invalid value encountered in cast\n",
                  "  hit = [c in seen]\n"]},
        {"output_type": "stream", "name": "stdout", "text": "a UserWarning: in printed text is not a warning\n"}]}]}
    assert warnings_in(nb) == ["cell 0: RuntimeWarning: invalid value encountered in cast"]
    path = tmp_path / "nb.ipynb"
    path.write_text(json.dumps(nb))
    assert book_main([str(path)]) == 1
    nb["cells"][0]["outputs"] = nb["cells"][0]["outputs"][1:]
    path.write_text(json.dumps(nb))
    assert book_main([str(path)]) == 0


def test_the_book_shows_no_machine_path(tmp_path):
    from bgfn.config import PROJECT_ROOT
    from bgfn.report.book_notebooks import machine_paths, without_machine_paths
    root = str(PROJECT_ROOT.resolve())
    log = tmp_path / "my drive log"
    paths = {**{str(log): "my-drive-log"}, **machine_paths(None)}
    nb = {"cells": [{"cell_type": "code", "source": "x", "outputs": [
        {"output_type": "stream", "name": "stdout", "text": [f"{log}: outages [[1.0, 2.0]]\n"]},
        {"output_type": "execute_result", "data": {"text/plain": f"PosixPath('{root}/results/p/figures/a.png')"}}]}]}
    out = without_machine_paths(nb, paths)["cells"][0]["outputs"]
    assert out[0]["text"] == ["my-drive-log: outages [[1.0, 2.0]]\n"]
    assert out[1]["data"]["text/plain"] == "PosixPath('results/p/figures/a.png')"

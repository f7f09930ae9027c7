"""The paper's outage evaluation in words (notebook 04): what a run evaluates, what beats what in Tables 1-2, and
the reductions the paper's text quotes beside ours."""

from __future__ import annotations

from typing import Mapping

import pandas as pd

from bgfn import paper
from bgfn.data import dataset_id
from bgfn.evaluate.setup import METRIC_COLUMNS, REAL_IMU_DATASETS, EvaluationSetup, OwnOutages, RealImuChoice
from bgfn.evaluate.tables import error_reduction
from bgfn.paper import nhc_label
from bgfn.report.run_words import runner_words
from bgfn.report.sample_words import sample_note


def real_imu_words(choice: RealImuChoice) -> str:
    """What ``real_imu`` chose for one dataset (:class:`~bgfn.evaluate.setup.RealImuChoice`) and why."""
    if choice.origin is not None:
        return f"{choice.file} present ({choice.origin}): evaluating {choice.twin} instead of {choice.asked}"
    return (f"{choice.file} absent (the recorded NaveGo IMU is not available here): {choice.asked} (simulated IMU) "
            f"stands in for {choice.twin}")


def own_outages_words(own: OwnOutages) -> str:
    """A dataset's outages that are not the default list (:class:`~bgfn.evaluate.setup.OwnOutages`)."""
    if own.rule is not None:
        return f"{dataset_id(own.dataset)}: rule {own.rule} (picked from the drive)"
    return f"{dataset_id(own.dataset)}: {own.windows}"


def setup_lines(setup: EvaluationSetup) -> list[str]:
    """Lines saying what notebook 04's :class:`~bgfn.evaluate.setup.EvaluationSetup` evaluates: profile, IMUs,
    datasets, methods, seeds, outages, pseudo-GPS."""
    ecfg = setup.config
    lines = [f"profile {setup.profile!r}: {setup.description}"]
    names = list(dict.fromkeys(list(setup.datasets) + list(setup.sweep_datasets)))
    simulated = [d for d in names if d in REAL_IMU_DATASETS]          # the only drives with simulated IMUs
    recorded = [dataset_id(d) for d in names if d not in REAL_IMU_DATASETS]
    if ecfg["real_imu"]:
        lines += [f"real_imu: {real_imu_words(c)}" for c in dict.fromkeys(setup.choices + setup.sweep_choices)]
    else:                                   # one line: which IMUs are simulated, which recorded
        kinds = ([f"real_imu: false -> simulated IMUs for {', '.join(simulated)} (set real_imu=True to use "
                  "NaveGo's recorded IMU files when present)"] if simulated else [])
        kinds += [f"recorded IMUs: {', '.join(recorded)}"] if recorded else []
        lines.append("; ".join(kinds))
    lines.append(f"tables: {[dataset_id(d) for d in setup.datasets]} | methods: {ecfg['methods']} | "
                 f"seeds: {ecfg['seeds']} | seed aggregate: {ecfg['seed_aggregate']}")
    lines.append(f"outages (start, duration) s: {[list(w) for w in setup.windows]}"
                 + "".join(f"; {own_outages_words(own)}" for own in setup.own_outages))
    lines.append(f"pseudo-GPS: {ecfg['pseudo_gps']}")
    lines.append(f"independent runs: {runner_words(setup.runner)}")
    return lines


def _network_seeds(result, outage, methods) -> int:
    """The training seeds of the networks ``methods`` in one outage of a table (``per_seed``; 0: runs not kept)."""
    per = result.per_seed
    if not {"outage", "method", "seed"} <= set(per.columns):
        return 0
    sel = per[(per["outage"] == outage) & per["method"].isin(list(methods))]
    return int(sel.groupby("method")["seed"].nunique().max()) if len(sel) else 0


def describe_tables(results) -> list[str]:
    """Plain-language lines on the outage tables (what beats what), computed from the numbers; a line on networks
    says how many training seeds and windows (the table's outages) it rests on when too few for statistics
    (:func:`bgfn.report.sample_words.sample_clause`)."""
    lines = []
    for r in results:
        red = error_reduction(r.table).set_index(["outage", "method"])
        n_windows = int(r.table["outage"].nunique())
        for o, g in r.table.groupby("outage"):
            g = g.set_index("method")
            score = (g["max_east_m"] + g["max_north_m"]) / 2.0
            learned = [m for m in ("MLP", "AT-LSTM", "BGFN", "Transformer") if m in g.index]
            best = min(learned, key=lambda m: score[m]) if learned else None
            sample = sample_note(_network_seeds(r, o, learned), n_windows) if learned else ""
            txt = (f"{r.dataset} ({r.test} test), outage {o}{sample}: max east/north error INS "
                   f"{g.loc['INS', 'max_east_m']:.1f}/{g.loc['INS', 'max_north_m']:.1f} m, GPS "
                   f"{g.loc['GPS', 'max_east_m']:.1f}/{g.loc['GPS', 'max_north_m']:.1f} m")
            if "BGFN" in g.index:
                e, n = red.loc[(o, "BGFN"), "east_pct"], red.loc[(o, "BGFN"), "north_pct"]
                txt += (f"; BGFN {g.loc['BGFN', 'max_east_m']:.1f}/{g.loc['BGFN', 'max_north_m']:.1f} m "
                        f"({e:+.0f} % / {n:+.0f} % reduction against INS)")
                beats = [m for m in ["INS"] + learned if m != "BGFN" and score["BGFN"] < score[m]]
                loses = [m for m in ["INS"] + learned if m != "BGFN" and score["BGFN"] >= score[m]]
                txt += (f"; on the mean of the two max errors BGFN beats {', '.join(beats) or 'none'} and does "
                        f"not beat {', '.join(loses) or 'any'}")
            if best is not None:
                txt += f"; best network: {best}"
            ins_nhc, bgfn_nhc = nhc_label("INS"), nhc_label("BGFN")
            if ins_nhc in g.index:      # the learning-free aid a learned one must beat or add to
                txt += (f"; with the vehicle constraints INS+NHC {g.loc[ins_nhc, 'max_east_m']:.1f}/"
                        f"{g.loc[ins_nhc, 'max_north_m']:.1f} m ({'better' if score[ins_nhc] < score['INS'] else 'not better'}"
                        " than INS)")
                if bgfn_nhc in g.index:
                    txt += (f", BGFN+NHC {g.loc[bgfn_nhc, 'max_east_m']:.1f}/{g.loc[bgfn_nhc, 'max_north_m']:.1f} m "
                            f"({'beats' if score[bgfn_nhc] < score[ins_nhc] else 'does not beat'} INS+NHC)")
            below = [f"{m} {c.replace('_m', '').replace('_', ' ')} {g.loc[m, c]:.1f} < GPS {g.loc['GPS', c]:.1f} m"
                     for c in METRIC_COLUMNS for m in g.index if m != "GPS" and g.loc[m, c] < g.loc["GPS", c]]
            if below:   # the GPS row follows the GNSS fixes, whose own error against the reference can exceed a drift
                txt += ("; the GPS row is not the lower bound in every cell (" + "; ".join(below)
                        + "): the GPS-aided solution follows the GNSS fixes' own error against the reference")
                fixes = r.gnss_errors.set_index("outage") if r.gnss_errors is not None else pd.DataFrame()
                if o in fixes.index and fixes.loc[o, "n_fixes"] > 0:
                    txt += (f", and the fixes in this window are off by up to {fixes.loc[o, 'max_east_m']:.1f} m "
                            f"east and {fixes.loc[o, 'max_north_m']:.1f} m north")
            lines.append(txt + ".")
    return lines


def claim_lines(reductions: Mapping[str, pd.DataFrame]) -> list[str]:
    """One line per reduction the paper quotes in its text (``claims.yaml``: BGFN against INS in the dataset
    test's outage 1, the field test's outage 2) with ours beside it.

    Parameters
    ----------
    reductions : mapping
        ``{dataset: reduction_table(...)}``; a test's first dataset answers for it.

    Returns
    -------
    list of str
        ``BGFN vs INS, <test title>, outage <k>: paper quotes E % east / N % north; ours ...`` (``not
        evaluated`` when no dataset of that test, or no BGFN row, was run), ended by
        :func:`bgfn.report.sample_words.sample_clause` in parentheses when ours rests on one seed or fewer than
        :data:`bgfn.stats.MIN_WINDOWS` windows (the table's ``n_seeds``, ``n_windows``); the quotes are of the
        paper's own tests, so a test it has no table of (the real drive) gets no line.
    """
    claims = paper.claims()
    by_test: dict[str, pd.DataFrame] = {}
    for name, red in reductions.items():
        by_test.setdefault(paper.test_of(name) or name, red)
    lines = []
    for test, spec in paper.TESTS.items():
        if not paper.has_own_values(test):
            continue
        for outage in sorted({int(o) for o in paper.outage_table(test)["outage"]}):
            stated = paper.claim_for(claims, test, outage)
            if stated is None:
                continue
            red = by_test.get(test)
            row = red[(red["outage"] == outage) & (red["method"] == "BGFN")] if red is not None else None
            got = (f"ours {row['east_%'].item():.1f} % east / {row['north_%'].item():.1f} % north"
                   if row is not None and len(row) else "not evaluated")
            if row is not None and len(row) and {"n_seeds", "n_windows"} <= set(row.columns):
                got += sample_note(int(row["n_seeds"].item()), int(row["n_windows"].item()))
            lines.append(f"BGFN vs INS, {spec['title']}, outage {outage}: paper quotes {stated['east']} % east / "
                         f"{stated['north']} % north; {got}")
    return lines


def paper_table_title(test: str) -> str:
    """How notebook 04 names the paper's table beside a test: ``Table 1 (dataset test)``, ``Table 2 (field
    test)`` (the order of the paper's tests in :data:`bgfn.paper.TESTS`); for a test the paper has no table of,
    ``real drive (not in the paper; beside it Table 2 (field test))``; ``no table of the paper (<test>)`` for any
    other drive (a user's)."""
    if test not in paper.TESTS:
        return f"no table of the paper ({test})"
    own = [t for t in paper.TESTS if paper.has_own_values(t)]
    shown = paper.published_test(test)
    title = f"Table {own.index(shown) + 1} ({paper.TESTS[shown]['title']})"
    return title if shown == test else f"{paper.TESTS[test]['title']} (not in the paper; beside it {title})"

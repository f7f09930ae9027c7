"""Our outage tables beside the paper's: its Tables 1-2 (``tab-out1-exin``, ``tab-real``) in its layout, the
error reductions against INS beside the ones its tables give (the two reductions its text quotes, beside ours:
:func:`bgfn.report.evaluation_words.claim_lines`). Our real drive (test ``real``) has no table in the paper: its
field test stands beside it (:func:`bgfn.paper.published_values`), labelled as such.

The paper's values are read through :mod:`bgfn.paper` (``data/paper/outage_max_errors.csv`` and
``claims.yaml``); they are shown beside ours, never used to choose anything.
"""

from __future__ import annotations

import pandas as pd

from bgfn import paper
from bgfn.evaluate.setup import TABLE_METHODS
from bgfn.evaluate.tables import TableResult, error_reduction

#: Columns of :func:`reduction_table`: ours, then the paper's (reduction against INS, %), then what ours rests on
#: (``n_seeds``: the method's runs in the outage, ``n_windows``: the outages of the table).
REDUCTION_COLUMNS: tuple[str, ...] = ("outage", "method", "east_%", "north_%", "paper east_%", "paper north_%",
                                      "n_seeds", "n_windows")


def _paper_values(test: str) -> pd.DataFrame | None:
    """The paper's values shown beside ``test`` (:func:`bgfn.paper.published_values`); None for a dataset that
    stands for none of its tests (a user's drive)."""
    return paper.published_values(test) if test in paper.TESTS else None


def ours_above_paper(result: TableResult) -> pd.DataFrame:
    """Max east/north errors (m) of one dataset in the paper's layout, ours above its Table 1 or 2.

    :func:`bgfn.paper.layout` over :data:`TABLE_METHODS` with the source moved to the rows, so that each
    outage reads as two rows of the paper's table (``ours``, then ``paper``) under its columns.

    Returns
    -------
    DataFrame
        Rows ``(Outage k, source)``; columns ``(method, axis)`` with axis ``East``/``North``; NaN where the
        paper has no such method (Transformer, GPS), or no such test (a user's drive: its rows all NaN). The
        paper's rows are labelled ``paper``, or ``paper (field test)`` beside the real drive
        (:func:`bgfn.paper.paper_label`).
    """
    label = paper.paper_label(result.test) if result.test in paper.TESTS else "paper"
    lay = paper.layout(result.table, _paper_values(result.test), methods=TABLE_METHODS, paper_label=label)
    return lay.stack("source", future_stack=True)


def reduction_table(result: TableResult, reference: str = "INS") -> pd.DataFrame:
    """Reduction of the max east/north errors against ``reference`` (``100 (ref - method) / ref``, %), ours
    beside the same arithmetic on the paper's table of the same test (of its field test for the real drive).

    Returns
    -------
    DataFrame
        :data:`REDUCTION_COLUMNS`: one row per outage and method of ours; the paper's columns NaN where it
        has no such row (Transformer, GPS) or no such test (a user's drive); ``n_seeds`` the method's seeds in
        that outage (``result.per_seed``; 0 when it holds no runs), ``n_windows`` the outages of the table.
    """
    ours = error_reduction(result.table, reference).rename(columns={"east_pct": "east_%", "north_pct": "north_%"})
    values = _paper_values(result.test)
    theirs = (error_reduction(values, reference) if values is not None
              else pd.DataFrame({"outage": pd.Series(dtype=ours["outage"].dtype), "method": pd.Series(dtype=object),
                                 "east_pct": pd.Series(dtype=float), "north_pct": pd.Series(dtype=float)})).rename(
        columns={"east_pct": "paper east_%", "north_pct": "paper north_%"})
    per = result.per_seed
    seeds = (per.groupby(["outage", "method"])["seed"].nunique().rename("n_seeds").reset_index()
             if {"outage", "method", "seed"} <= set(per.columns)
             else pd.DataFrame({"outage": pd.Series(dtype=int), "method": pd.Series(dtype=object),
                                "n_seeds": pd.Series(dtype=int)}))
    seeds["outage"] = seeds["outage"].astype(int)
    out = ours.merge(theirs, on=["outage", "method"], how="left").merge(seeds, on=["outage", "method"], how="left")
    out["n_seeds"] = out["n_seeds"].fillna(0).astype(int)          # 0: the runs were not kept (unknown)
    out["n_windows"] = int(result.table["outage"].nunique())
    return out[list(REDUCTION_COLUMNS)]


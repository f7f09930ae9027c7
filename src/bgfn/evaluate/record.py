"""``results/<profile>/outage_evaluation.json``: the record of one run of notebook 04 (its configuration, the
outages, the tables, the reductions against INS beside the paper's, wall times and run metadata). The results
page reads it (:func:`bgfn.report.outage_datasets`: which dataset stands for which test).
"""

from __future__ import annotations

from dataclasses import asdict
from pathlib import Path
from typing import Mapping

import pandas as pd

from bgfn import paper
from bgfn.config import RUN_RECORDS, run_metadata
from bgfn.evaluate.setup import EvaluationSetup
from bgfn.evaluate.tables import TableResult
from bgfn.io import atomic_write_json

#: File name under ``results/<profile>/``.
RECORD_FILE = RUN_RECORDS["evaluation"]


def evaluation_record(setup: EvaluationSetup, results: Mapping[str, TableResult],
                      reductions: Mapping[str, pd.DataFrame], timings: dict) -> dict:
    """The content of ``outage_evaluation.json`` (without the run metadata).

    Parameters
    ----------
    setup : EvaluationSetup
    results : mapping
        ``{dataset: TableResult}`` of the two tables.
    reductions : mapping
        ``{dataset: reduction_table(...)}`` (:func:`bgfn.evaluate.claims.reduction_table`).
    timings : dict
        Wall times, s.

    Returns
    -------
    dict
        ``profile``, ``evaluate`` (the configuration), ``outage_windows`` (``[[start, duration], ...]``, s: the
        profile's default list), ``outage_windows_by_dataset`` (``{dataset: [[start, duration], ...]}``: the
        windows each table was evaluated in),
        ``datasets``, ``real_imu_choices`` (:class:`~bgfn.evaluate.setup.RealImuChoice`'s fields), ``tables``
        and ``reduction_vs_ins_pct`` (keyed by the paper's test),
        ``paper_claims`` (the BGFN reductions the paper quotes, %),
        ``timings_s``, ``constraints`` (per test the vehicle constraints' facts of the ``+NHC`` rows, or None).
    """
    return {
        "profile": setup.profile, "evaluate": setup.config, "outage_windows": [list(w) for w in setup.windows],
        "outage_windows_by_dataset": {name: [list(w) for w in (res.windows if res.windows is not None
                                                               else setup.windows)]
                                      for name, res in results.items()},
        "datasets": setup.datasets, "real_imu_choices": [asdict(c) for c in setup.choices],
        "tables": {res.test: res.table.to_dict(orient="records") for res in results.values()},
        "reduction_vs_ins_pct": {results[n].test: r.to_dict(orient="records") for n, r in reductions.items()},
        "paper_claims": paper.claims()["bgfn_reduction_vs_ins_pct"],
        "timings_s": timings,
        "constraints": {res.test: res.constraints for res in results.values()},
    }


def write_evaluation_record(out, setup: EvaluationSetup, results: Mapping[str, TableResult],
                            reductions: Mapping[str, pd.DataFrame], timings: dict) -> Path:
    """Write :func:`evaluation_record` plus ``meta`` (:func:`bgfn.config.run_metadata`) to
    ``<out>/outage_evaluation.json`` atomically; returns the path."""
    record = {**evaluation_record(setup, results, reductions, timings),
              "meta": run_metadata(setup.profile)}
    return atomic_write_json(Path(out) / RECORD_FILE, record)

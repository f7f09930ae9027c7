"""The paper's published values and its vocabulary, in one place.

Its outage tables (``data/paper/outage_max_errors.csv``), the numbers its text states (``data/paper/claims.yaml``),
its method labels, which of our datasets stands for which of its tests, and the layout of its tables. The values
are shown beside ours in a column labelled *paper*; no code reads them to choose a parameter, a seed or a stopping
point. A *test* is ``dataset`` (Table ``tab-out1-exin``), ``field`` (Table ``tab-real``) or ``real`` (ours, a
recorded car drive, beside the paper's field test: :func:`published_test`); a *method label* names a table's row
(``INS``, ``BGFN``, ... and ``+NHC`` with the vehicle constraints, :func:`nhc_label`), a *method id* the key of
:mod:`bgfn.models`.
"""

from __future__ import annotations

from functools import lru_cache
from typing import Sequence

import numpy as np
import pandas as pd
import yaml

from bgfn.config import DATA_DIR

#: Folder of the transcribed values (see its README.md).
PAPER_DIR = DATA_DIR / "paper"
#: The paper's Tables tab-out1-exin and tab-real: ``test, outage, method, max_east_m, max_north_m``.
OUTAGE_TABLE_FILE = PAPER_DIR / "outage_max_errors.csv"
#: Percentages and settings the paper states in its text.
CLAIMS_FILE = PAPER_DIR / "claims.yaml"

#: Method id (bgfn.models) -> label in the tables (the paper's labels; Transformer is ours: BGFN's ANN twin).
METHOD_LABELS: dict[str, str] = {"mlp": "MLP", "at_lstm": "AT-LSTM", "bgfn": "BGFN", "transformer": "Transformer"}
#: The paper's methods, in the order of its tables.
PAPER_METHODS: tuple[str, ...] = ("INS", "MLP", "AT-LSTM", "BGFN")
#: Suffix of a row whose filter also applies the non-holonomic constraints (and a zero-velocity update whenever
#: the stillness detector fires; :mod:`bgfn.nav.constraints`): ours, beyond the paper.
NHC_SUFFIX = "+NHC"
#: Max-error columns of an outage table and their axis labels in the paper's layout.
AXES: tuple[tuple[str, str], ...] = (("max_east_m", "East"), ("max_north_m", "North"))
#: Decimals of the paper's tables: values equal at this precision are called equal.
DECIMALS = 1

#: The outage tests: the paper's two and our real drive. Per test: the paper's table label (None: not a table of
#: the paper), our title, our table file (``results/<profile>/tables/``), the caption, and ``paper``: the
#: paper's test whose published values stand beside ours (:func:`published_test`).
TESTS: dict[str, dict] = {
    "dataset": {"label": "tab-out1-exin", "title": "dataset test", "file": "outage_dataset.csv",
                "caption": "The max position error (m) among different algorithms in the dataset test",
                "paper": "dataset"},
    "field": {"label": "tab-real", "title": "field test", "file": "outage_field.csv",
              "caption": "The max position error among different algorithms in the real field test",
              "paper": "field"},
    # a recorded car drive: no values of its own in the paper; its field test (also a car with a
    # MEMS IMU, one outage cruising, one manoeuvring) is the closest published comparison
    "real": {"label": None, "title": "real drive", "file": "outage_real.csv",
             "caption": "The max position error (m) among different algorithms on a recorded car drive with a "
                        "MEMS IMU (not in the paper; the paper's field test beside it)",
             "paper": "field"},
}
#: Our dataset -> the test it stands for.
DATASET_TESTS: dict[str, str] = {"turin-sim-ekinox": "dataset", "navego-ekinox": "dataset",
                                 "turin-sim-mpu6000": "field", "navego-mpu6000": "field",
                                 "rtklib-drive0708": "real"}


def test_of(dataset: str) -> str | None:
    """The test (``dataset`` | ``field`` | ``real``) that ``dataset`` stands for, or None."""
    return DATASET_TESTS.get(dataset)


def published_test(test: str) -> str:
    """The paper's test whose published values stand beside our ``test``: itself for ``dataset`` and
    ``field``, the field test for ``real``; an unknown name is returned as given."""
    return (TESTS.get(test) or {}).get("paper", test)


def has_own_values(test: str) -> bool:
    """Whether the paper publishes a table for ``test`` itself (``dataset``, ``field``; not ``real``)."""
    return test in TESTS and published_test(test) == test


def paper_label(test: str) -> str:
    """The column label of the paper's values beside our ``test``: ``paper``, or ``paper (field test)`` when
    they are another test's."""
    shown = published_test(test)
    return "paper" if shown == test else f"paper ({TESTS[shown]['title']})"


def label(method: str) -> str:
    """Table label of a method id (``bgfn`` -> ``BGFN``); a label or unknown name is returned as given."""
    return METHOD_LABELS.get(method, method)


def nhc_label(method: str) -> str:
    """Label of a method run with the vehicle constraints: ``INS`` -> ``INS+NHC``, ``bgfn`` -> ``BGFN+NHC``."""
    return label(method) + NHC_SUFFIX


#: Suffix of a network trained as a learned odometer (forward speed and its std fused with the NHC rows; beyond
#: the paper): ``BGFN-ODO``.
ODO_SUFFIX = "-ODO"
#: Suffix of the equal-weight ensemble of an odometer network's seeds (beyond the paper; :func:`ensemble_label`).
ENSEMBLE_SUFFIX = "-ENS"


def odometer_label(method: str) -> str:
    """Label of a network trained as a learned odometer: ``bgfn`` -> ``BGFN-ODO``."""
    return label(method) + ODO_SUFFIX


def ensemble_label(odometer: str) -> str:
    """Label of the equal-weight ensemble of an odometer network's seeds: ``BGFN-ODO`` -> ``BGFN-ODO-ENS``."""
    return odometer + ENSEMBLE_SUFFIX


def base_label(method: str) -> str:
    """The label without the constraints' suffix: ``BGFN+NHC`` -> ``BGFN`` (others as given)."""
    return method[: -len(NHC_SUFFIX)] if method.endswith(NHC_SUFFIX) else method


@lru_cache(maxsize=None)
def _outage_values() -> pd.DataFrame:
    return pd.read_csv(OUTAGE_TABLE_FILE)


def outage_table(test: str) -> pd.DataFrame:
    """The paper's max errors of one of its tests: ``outage, method, max_east_m, max_north_m`` (m).

    Raises
    ------
    ValueError
        ``test`` is not one of the paper's tests (``real`` has no table of its own: use
        :func:`published_values`).
    """
    p = _outage_values()
    if test not in set(p["test"]):
        raise ValueError(f"no test {test!r} in {OUTAGE_TABLE_FILE.name} (have {sorted(set(p['test']))})")
    return p[p["test"] == test].drop(columns="test").reset_index(drop=True)


def published_values(test: str) -> pd.DataFrame:
    """The paper's max errors shown beside our ``test``: :func:`outage_table` of :func:`published_test`."""
    return outage_table(published_test(test))


def claims() -> dict:
    """``data/paper/claims.yaml``: the percentages and settings the paper states in its text."""
    return yaml.safe_load(CLAIMS_FILE.read_text(encoding="utf-8"))


def claim_for(claims: dict, test: str, outage: int) -> dict | None:
    """The paper's stated BGFN reduction against INS (``{'east': %, 'north': %}``) for one outage, if any."""
    return (claims.get("bgfn_reduction_vs_ins_pct") or {}).get(f"{test}_outage{int(outage)}")


def layout(ours: pd.DataFrame | None, paper: pd.DataFrame | None, methods: Sequence[str] = PAPER_METHODS,
           ours_label: str = "ours", paper_label: str = "paper") -> pd.DataFrame:
    """Max east/north errors in the paper's layout, ours beside the paper's.

    Parameters
    ----------
    ours, paper : DataFrame or None
        Long tables with ``outage`` (int), ``method`` (label), ``max_east_m``, ``max_north_m`` (m).
    methods : sequence of str
        Method labels, in column order.

    Returns
    -------
    DataFrame
        Rows ``Outage k``; columns a MultiIndex ``(source, method, axis)`` with source ``ours_label`` then
        ``paper_label``, axis ``East``/``North``; the paper's side has only the paper's methods
        (:data:`PAPER_METHODS`). A value one side lacks (or a side given as None) is NaN.
    """
    frames = [(ours_label, ours), (paper_label, paper)]
    outages = sorted({int(o) for _, df in frames if df is not None for o in df["outage"]})
    data = {}
    for src, df in frames:
        lookup = {} if df is None else {(int(r.outage), r.method): r for r in df.itertuples(index=False)}
        for m in methods if src == ours_label else [m for m in methods if m in PAPER_METHODS]:
            for col, axis in AXES:
                data[(src, m, axis)] = [float(getattr(lookup[(o, m)], col)) if (o, m) in lookup else np.nan
                                        for o in outages]
    return pd.DataFrame(data, index=pd.Index([f"Outage {o}" for o in outages], name="Max Position Error (m)"),
                        columns=pd.MultiIndex.from_tuples(list(data), names=["source", "method", "axis"]))

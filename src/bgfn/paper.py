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

import re
from functools import lru_cache
from typing import Callable, Sequence

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


#: A row label's constraint suffix after a method's name (``INS+NHC``, ``BGFN+NHC``, ``INS+NHC+HOLD``; not a bare
#: ``+NHC`` in a sentence about the rows in general).
_NHC_IN_TEXT = re.compile(r"(?<=[A-Za-z0-9])" + re.escape(NHC_SUFFIX) + r"(?![A-Za-z0-9])")
#: A written label whose suffix names other aids than NHC (:func:`ran_label`), read back: the method's label, then
#: ``+ZUPT`` (a walker) or ``+no aid``.
_OTHER_AIDS_IN_TEXT = re.compile(r"(?<![A-Za-z0-9-])(" + "|".join(map(re.escape, ("INS", *METHOD_LABELS.values())))
                                 + r")\+(?:ZUPT|no aid)(?![A-Za-z0-9])")


def _is_text(column: pd.Series) -> bool:
    return pd.api.types.is_object_dtype(column) or pd.api.types.is_string_dtype(column)


def aids_suffix(aids: Sequence[str]) -> str:
    """The suffix of the rows run with the learning-free aids ``aids`` (the names a platform takes, ``NHC`` /
    ``ZUPT``): ``+NHC`` whenever NHC ran (the project's label; ZUPT at stops beside it, as ever), ``+ZUPT`` when
    ZUPT ran alone (a walker), ``+no aid`` when neither did."""
    aids = tuple(aids)
    if "NHC" in aids:
        return NHC_SUFFIX
    return "+" + "+".join(aids) if aids else "+no aid"


def ran_label(text, aids: Sequence[str]) -> str:
    """A row label (or every row label in ``text``) named by the aids that ran: ``INS+NHC`` -> ``INS+ZUPT``,
    ``BGFN+NHC+HOLD`` -> ``BGFN+ZUPT+HOLD`` with ``aids=("ZUPT",)``; unchanged whenever NHC ran."""
    suffix = aids_suffix(aids)
    return str(text) if suffix == NHC_SUFFIX else _NHC_IN_TEXT.sub(suffix, str(text))


def key_label(text) -> str:
    """The label a written row label stands for in the code (:func:`ran_label` undone): ``INS+ZUPT`` ->
    ``INS+NHC``; a label of a run with NHC, and any other text, as given."""
    return _OTHER_AIDS_IN_TEXT.sub(lambda m: m.group(1) + NHC_SUFFIX, str(text))


def ran_labels(frame: pd.DataFrame, aids: Sequence[str] | Callable[[str], Sequence[str]]) -> pd.DataFrame:
    """``frame`` as a table file writes it: every ``+NHC`` row label (cells and column names) named by the aids that
    ran (:func:`ran_label`). ``aids``: the aids of every row, or a function of a row's ``dataset`` (a table of
    several drives; column names then stay as they are). ``frame`` itself when every row ran NHC, so a car's
    table keeps its bytes."""
    if callable(aids):
        if "dataset" not in frame.columns or not len(frame):
            return frame
        row_aids = [tuple(aids(d)) for d in frame["dataset"]]
        columns = {}
    else:
        row_aids = [tuple(aids)] * len(frame)
        columns = {c: ran_label(c, aids) for c in frame.columns if isinstance(c, str)}
    if all(aids_suffix(a) == NHC_SUFFIX for a in row_aids) and all(k == v for k, v in columns.items()):
        return frame
    out = frame.rename(columns=columns)
    for c in out.columns:
        if _is_text(out[c]):
            out[c] = [ran_label(v, a) if isinstance(v, str) else v for v, a in zip(out[c], row_aids)]
    return out


def key_labels(frame: pd.DataFrame) -> pd.DataFrame:
    """A table read back with the code's labels (:func:`key_label` of its cells and column names; :func:`ran_labels`
    undone)."""
    out = frame.rename(columns={c: key_label(c) for c in frame.columns if isinstance(c, str)})
    for c in out.columns:
        if _is_text(out[c]):
            keys = {v: key_label(v) for v in out[c].unique() if isinstance(v, str)}
            if any(k != v for k, v in keys.items()):
                out[c] = out[c].map(lambda v: keys.get(v, v) if isinstance(v, str) else v)
    return out


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

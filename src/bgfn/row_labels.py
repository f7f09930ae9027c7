"""Row labels named by the aids that ran: a walker's tables say ``INS+ZUPT`` where a car's say ``INS+NHC``.

The code keys every row by the paper's vocabulary (:mod:`bgfn.paper`: ``INS+NHC``, ``BGFN+NHC+HOLD``); a table is
written with the label of the learning-free aids that ran on its drive (:func:`ran_labels`) and read back with the
code's keys (:func:`key_labels`), so that a car's tables keep their bytes and a walker's say what ran.
"""

from __future__ import annotations

import re
from typing import Callable, Sequence

import pandas as pd

from bgfn.paper import METHOD_LABELS, NHC_SUFFIX


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

"""The navigation aids in words, for the results page: what the learning-free aided row is on each platform, and
the rows' labels with the aids that ran (``INS+ZUPT`` for a walker, whose filter takes no NHC), in sentences and in
the frames the notebooks display (:func:`ran_frame`, :func:`ran_lines`)."""

from __future__ import annotations

from collections.abc import Iterable, Mapping
from pathlib import Path

import pandas as pd

from bgfn.data.platforms import drive_platform
from bgfn.data.platforms import recorded_platform as _recorded_platform
from bgfn.nav.constraints import DEFAULT_PLATFORM, PLATFORM_AIDS, PLATFORM_NOTES, ConstraintConfig, platform_aids
from bgfn.paper import NHC_SUFFIX
from bgfn.row_labels import aids_suffix, ran_label

#: The aids in words (:func:`aided_ins_words`).
AID_WORDS: dict[str, str] = {"NHC": "non-holonomic constraints", "ZUPT": "zero-velocity updates"}


def _platform(platform: str) -> str:
    return platform if platform in PLATFORM_AIDS else DEFAULT_PLATFORM


def aided_ins_words(platform: str) -> str:
    """What the learning-free aided row (``INS+NHC``) is on ``platform``, in words: "INS with non-holonomic
    constraints and zero-velocity updates" for a car; a platform this module does not know reads as a car's."""
    platform = _platform(platform)
    aids = platform_aids(platform)
    return (("INS with " + " and ".join(AID_WORDS[a] for a in aids)) if aids else "INS with no constraint") \
        + PLATFORM_NOTES[platform]


def constraint_words(config: ConstraintConfig) -> str:
    """Which aids run, and why (the platform of a :class:`bgfn.nav.constraints.ConstraintConfig`)."""
    aids = platform_aids(config.platform)
    return (f"platform {config.platform}: " + (" and ".join(aids) if aids else "no vehicle constraint")
            + PLATFORM_NOTES[config.platform])


def aid_suffix(platform: str) -> str:
    """The suffix of the rows the code keys ``+NHC`` (run with the platform's learning-free aids): ``+NHC`` on a
    car (the paper's label; its ZUPT at stops beside it, as ever), ``+ZUPT`` on a walker (no NHC ran), ``+no aid``
    on a platform that takes neither (:func:`bgfn.row_labels.aids_suffix`; the tables write the same)."""
    return aids_suffix(platform_aids(_platform(platform)))


def aid_label(text: str, platform: str) -> str:
    """A row's label, or every row label in a sentence, with the aids that ran on ``platform``: ``INS+NHC`` ->
    ``INS+ZUPT``, ``BGFN+NHC`` -> ``BGFN+ZUPT`` for a walker; a car's labels (and text without them) as they are."""
    return ran_label(text, platform_aids(_platform(platform)))


def recorded_platform(out: str | Path, dataset: str) -> str:
    """The drive's platform as notebook 02 recorded it (``kf_baseline.json`` under ``out``; ``car`` when it says
    nothing): :func:`bgfn.data.platforms.recorded_platform`."""
    return _recorded_platform(out, dataset)


def platform_of(drive) -> str:
    """A loaded drive's platform (its ``meta``, as the filter reads it; ``car`` when it says nothing)."""
    return str(drive.meta.get("platform", DEFAULT_PLATFORM))


def drive_platforms(out: str | Path, datasets: Iterable[str]) -> dict[str, str]:
    """``{dataset: platform}`` of the drives (:func:`bgfn.data.platforms.drive_platform`: notebook 02's record under
    ``out``, else the folder's ``meta.yaml``)."""
    return {str(d): drive_platform(out, str(d)) for d in dict.fromkeys(datasets)}


def _relabel_axis(index: pd.Index, label) -> pd.Index:
    if isinstance(index, pd.MultiIndex):
        return pd.MultiIndex.from_tuples([tuple(label(v, k) for v in t) for k, t in enumerate(index)],
                                         names=index.names)
    return pd.Index([label(v, k) for k, v in enumerate(index)], name=index.name)


def ran_frame(frame: pd.DataFrame, platform: str | Mapping[str, str]) -> pd.DataFrame:
    """``frame`` as a notebook displays it: every ``+NHC`` row label (cells, column names and index labels, each
    level) named by the aids that ran (:func:`aid_label`). ``platform``: the one drive's, or ``{dataset: platform}``
    for a frame of several drives (each row by its ``dataset`` column or index level; the column names then by
    the drives' one platform, else as they are). ``frame`` itself when every drive took NHC, so a car's display is
    as before."""
    if isinstance(platform, Mapping):
        if "dataset" in frame.columns:
            rows = [str(d) for d in frame["dataset"]]
        elif "dataset" in (frame.index.names or []):
            rows = [str(d) for d in frame.index.get_level_values("dataset")]
        else:
            rows = []
        shared = set(platform.get(d, DEFAULT_PLATFORM) for d in rows) if rows else set(platform.values())
        whole = next(iter(shared)) if len(shared) == 1 else DEFAULT_PLATFORM
        platforms = [platform.get(d, DEFAULT_PLATFORM) for d in rows] if rows else [whole] * len(frame)
    else:
        platforms, whole = [platform] * len(frame), platform
    if all(aid_suffix(p) == NHC_SUFFIX for p in platforms + [whole]):
        return frame
    out = frame.copy()
    out.columns = _relabel_axis(out.columns, lambda v, _k: aid_label(v, whole) if isinstance(v, str) else v)
    out.index = _relabel_axis(out.index, lambda v, k: aid_label(v, platforms[k]) if isinstance(v, str) else v)
    for j in range(out.shape[1]):
        col = out.iloc[:, j]
        if pd.api.types.is_object_dtype(col) or pd.api.types.is_string_dtype(col):
            out.isetitem(j, pd.Series([aid_label(v, p) if isinstance(v, str) else v for v, p in zip(col, platforms)],
                                      index=out.index, dtype=col.dtype))
    return out


def ran_lines(lines: Iterable[str], platforms: Mapping[str, str]) -> list[str]:
    """Sentences with their row labels named by the aids that ran (:func:`aid_label`): a line that leads with a
    drive of ``platforms`` (its name, then a comma, a space and an opening parenthesis, or a colon) by that
    drive's platform; any other line by the drives' one platform when they share one, else as it is."""
    shared = set(platforms.values())
    whole = next(iter(shared)) if len(shared) == 1 else DEFAULT_PLATFORM
    names = sorted(platforms, key=len, reverse=True)          # the longest name first: "walk-2" before "walk"

    def line_platform(line: str) -> str:
        d = next((d for d in names if line.startswith(d) and line[len(d):len(d) + 1] in (",", " ", ":")), None)
        return platforms[d] if d is not None else whole
    return [aid_label(line, line_platform(line)) for line in lines]

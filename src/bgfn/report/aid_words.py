"""The navigation aids in words, for the results page: what the learning-free aided row is on each platform, and
the rows' labels with the aids that ran (``INS+ZUPT`` for a walker, whose filter takes no NHC)."""

from __future__ import annotations

import re
from pathlib import Path

from bgfn.config import RUN_RECORDS
from bgfn.data.names import dataset_id
from bgfn.report.reading import read_json
from bgfn.nav.constraints import DEFAULT_PLATFORM, PLATFORM_AIDS, PLATFORM_NOTES, ConstraintConfig, platform_aids
from bgfn.paper import NHC_SUFFIX

#: The aids in words (:func:`aided_ins_words`).
AID_WORDS: dict[str, str] = {"NHC": "non-holonomic constraints", "ZUPT": "zero-velocity updates"}
#: A label's constraint suffix where the tables write it (``INS+NHC``, ``BGFN+NHC``, ``INS+NHC+HOLD``), after a
#: method's name (not a bare ``+NHC`` in a sentence about the rows in general).
_SUFFIX_IN_TEXT = re.compile(r"(?<=[A-Za-z0-9])" + re.escape(NHC_SUFFIX) + r"(?![A-Za-z0-9])")


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
    """The suffix of the rows the tables write ``+NHC`` (run with the platform's learning-free aids): ``+NHC`` on a
    car (the paper's label; its ZUPT at stops beside it, as ever), ``+ZUPT`` on a walker (no NHC ran), ``+no aid``
    on a platform that takes neither (:data:`bgfn.nav.constraints.PLATFORM_AIDS`)."""
    platform = _platform(platform)
    if platform == DEFAULT_PLATFORM:
        return NHC_SUFFIX
    aids = platform_aids(platform)
    return "+" + "+".join(aids) if aids else "+no aid"


def aid_label(text: str, platform: str) -> str:
    """A row's label, or every row label in a sentence, with the aids that ran on ``platform``: ``INS+NHC`` ->
    ``INS+ZUPT``, ``BGFN+NHC`` -> ``BGFN+ZUPT`` for a walker; a car's labels (and text without them) as they are."""
    suffix = aid_suffix(platform)
    return str(text) if suffix == NHC_SUFFIX else _SUFFIX_IN_TEXT.sub(suffix, str(text))


def recorded_platform(out: str | Path, dataset: str) -> str:
    """The drive's platform as notebook 02 recorded it (``kf_baseline.json`` under ``out``; ``car`` when it says
    nothing)."""
    record = read_json(Path(out) / RUN_RECORDS["kf_baseline"]) or {}
    for name, facts in (record.get("datasets") or {}).items():
        if dataset_id(name) == dataset_id(dataset):
            return str(((facts or {}).get("constraints") or {}).get("platform", DEFAULT_PLATFORM))
    return DEFAULT_PLATFORM

"""The navigation aids in words, for the results page: what the learning-free aided row is on each platform, and
the rows' labels with the aids that ran (``INS+ZUPT`` for a walker, whose filter takes no NHC)."""

from __future__ import annotations

from pathlib import Path

from bgfn.data.platforms import recorded_platform as _recorded_platform
from bgfn.nav.constraints import DEFAULT_PLATFORM, PLATFORM_AIDS, PLATFORM_NOTES, ConstraintConfig, platform_aids
from bgfn.paper import aids_suffix, ran_label

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
    on a platform that takes neither (:func:`bgfn.paper.aids_suffix`; the tables write the same)."""
    return aids_suffix(platform_aids(_platform(platform)))


def aid_label(text: str, platform: str) -> str:
    """A row's label, or every row label in a sentence, with the aids that ran on ``platform``: ``INS+NHC`` ->
    ``INS+ZUPT``, ``BGFN+NHC`` -> ``BGFN+ZUPT`` for a walker; a car's labels (and text without them) as they are."""
    return ran_label(text, platform_aids(_platform(platform)))


def recorded_platform(out: str | Path, dataset: str) -> str:
    """The drive's platform as notebook 02 recorded it (``kf_baseline.json`` under ``out``; ``car`` when it says
    nothing): :func:`bgfn.data.platforms.recorded_platform`."""
    return _recorded_platform(out, dataset)

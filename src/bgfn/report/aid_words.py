"""The navigation aids in words, for the results page: what the learning-free aided row is on each platform."""

from __future__ import annotations

from bgfn.nav.constraints import DEFAULT_PLATFORM, PLATFORM_AIDS, PLATFORM_NOTES, ConstraintConfig, platform_aids

#: The aids in words (:func:`aided_ins_words`).
AID_WORDS: dict[str, str] = {"NHC": "non-holonomic constraints", "ZUPT": "zero-velocity updates"}


def aided_ins_words(platform: str) -> str:
    """What the learning-free aided row (``INS+NHC``) is on ``platform``, in words: "INS with non-holonomic
    constraints and zero-velocity updates" for a car; a platform this module does not know reads as a car's."""
    platform = platform if platform in PLATFORM_AIDS else DEFAULT_PLATFORM
    aids = platform_aids(platform)
    return (("INS with " + " and ".join(AID_WORDS[a] for a in aids)) if aids else "INS with no constraint") \
        + PLATFORM_NOTES[platform]


def constraint_words(config: ConstraintConfig) -> str:
    """Which aids run, and why (the platform of a :class:`bgfn.nav.constraints.ConstraintConfig`)."""
    aids = platform_aids(config.platform)
    return (f"platform {config.platform}: " + (" and ".join(aids) if aids else "no vehicle constraint")
            + PLATFORM_NOTES[config.platform])

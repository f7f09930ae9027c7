"""How many training seeds and outage windows a sentence rests on, in words: a comparison of one seed or fewer
than :data:`bgfn.stats.MIN_WINDOWS` windows says so beside its numbers."""

from __future__ import annotations

from bgfn.stats import MIN_WINDOWS, too_few_for_statistics


def _count(n: int, noun: str) -> str:
    return f"one {noun}" if n == 1 else f"{n} {noun}s"


def sample_clause(n_seeds: int, n_windows: int) -> str:
    """``one seed, 2 windows: no statistics`` for fewer than :data:`~bgfn.stats.MIN_WINDOWS` windows, ``one seed,
    20 windows: no spread between training seeds`` for one seed in enough windows, empty when neither (two or more
    seeds and enough windows: the statistics beside the sentence speak for it)."""
    if not too_few_for_statistics(n_seeds, n_windows):
        return ""
    if n_windows < MIN_WINDOWS:
        return f"{_count(n_seeds, 'seed')}, {_count(n_windows, 'window')}: no statistics"
    return f"{_count(n_seeds, 'seed')}, {_count(n_windows, 'window')}: no spread between training seeds"


def sample_note(n_seeds: int, n_windows: int, lead: str = " (") -> str:
    """:func:`sample_clause` in parentheses (``lead`` opens it: ``" ("``, or ``" (BGFN: "``); empty when the sample
    is large enough or either count is unknown (0: the runs were not kept)."""
    clause = sample_clause(n_seeds, n_windows) if n_seeds > 0 and n_windows > 0 else ""
    return f"{lead}{clause})" if clause else ""


#: What an odometer network reads (``evaluate.odometer.inputs``, ``fleet.inputs``), in words.
INPUT_WORDS = {"imu": "the raw IMU samples", "band_frames": "band frames"}

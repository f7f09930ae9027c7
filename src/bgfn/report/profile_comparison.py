"""Profiles side by side (the results page's *Variants* section): a variant such as ``quick-heading`` changes
the learning problem, and its validation errors, outage tables and sweep are shown beside the profile's.

One profile's BGFN against the references that need no training (:func:`reference_sentences`) is the same
comparison with one column; notebook 03 and the *At a glance* lines use it.
"""

from __future__ import annotations

from pathlib import Path
from typing import Sequence

import numpy as np
import pandas as pd

from bgfn.config import RESULTS_ROOT, SHARED_TABLES, profile_chain, read_profile
from bgfn.data.names import dataset_folder
from bgfn.errors import DataError
from bgfn.report.sweep_words import describe_sweep
from bgfn.paper import TESTS, label
from bgfn.report.provenance import short_source
from bgfn.report.reading import missing_note, read_csv
from bgfn.report.sentences import bullets
from bgfn.report.tables import REFERENCE_LABELS, compact, fmt_num


def compared_profiles(profile: str, variants: Sequence[str],
                      results_root: str | Path | None = None) -> tuple[list[str], list[str]]:
    """The profiles the *Variants* section puts side by side: ``profile``, then ``variants`` and the profile
    it builds on (``base:``), without repeats.

    Returns
    -------
    shown : list of str
        Those whose notebook 03 has run (``tables/training_summary.csv`` exists), in that order.
    missing : list of str
        The others, ``profile`` itself left out.
    """
    base = [p.stem for p in profile_chain(profile)[1:2]]
    names = list(dict.fromkeys([profile, *variants, *base]))
    root = Path(results_root or RESULTS_ROOT)
    shown = [p for p in names if (root / p / "tables" / SHARED_TABLES["training_summary"]).exists()]
    return shown, [p for p in names[1:] if p not in shown]


def own_log_profile(profile: str) -> bool:
    """Whether ``profile`` runs logs of its own (a CSV folder among ``data.datasets``): its page asks for no variant
    of the shipped drives to be run beside it."""
    try:
        names = read_profile(profile)["data"]["datasets"]
    except DataError:
        return False
    return any(dataset_folder(name) is not None for name in names)


def profile_tables(profiles: Sequence[str], file: str, results_root: str | Path | None = None) -> dict:
    """``{profile: results/<profile>/tables/<file>}`` (None where it is missing)."""
    root = Path(results_root or RESULTS_ROOT)
    return {p: read_csv(root / p / "tables" / file) for p in profiles}


def variant_training_table(summaries: dict[str, pd.DataFrame | None]) -> pd.DataFrame | None:
    """Validation RMSE (m, mean over seeds) per (dataset, method), one column per profile, beside the
    references (*zero*, *last increment*, *INS increment*; those in the first profile's table), which are the
    same windows in every profile of one drive.

    ``summaries``: ``{profile: tables/training_summary.csv}``; profiles without a table are left out.
    """
    cols, ref = [], None
    for profile, s in summaries.items():
        if s is None:
            continue
        s = s.assign(method=s["method"].map(lambda m: label(m))).set_index(["dataset", "method"])
        cols.append(s["val_rmse_m_mean"].rename(f"val. RMSE {profile}"))
        if ref is None:
            ref = s[[c for c in REFERENCE_LABELS if c in s.columns]].rename(columns=REFERENCE_LABELS)
    if not cols:
        return None
    return pd.concat(cols + [ref], axis=1)


def variant_outage_table(tables: dict[str, pd.DataFrame | None], metric: str = "max_h") -> pd.DataFrame | None:
    """One outage table per profile side by side: per (outage, method) the mean of the max east and max north
    error (m, ``metric='max_h'``) or one column of :data:`bgfn.evaluate.METRIC_COLUMNS`."""
    cols = []
    for profile, t in tables.items():
        if t is None:
            continue
        t = t.set_index(["outage", "method"])
        v = (t["max_east_m"] + t["max_north_m"]) / 2.0 if metric == "max_h" else t[metric]
        cols.append(v.rename(profile))
    return pd.concat(cols, axis=1) if cols else None


def variant_sentences(training: pd.DataFrame | None, method: str = "BGFN") -> list[str]:
    """Per profile and dataset: which networks beat the *last increment* reference on validation RMSE, and
    the *INS increment* (the speed known) beside it."""
    if training is None:
        return []
    lines = []
    for col in [c for c in training.columns if c.startswith("val. RMSE ")]:
        profile = col[len("val. RMSE "):]
        for dataset, g in training.groupby(level="dataset"):
            g = g.droplevel("dataset")
            if g[col].isna().all():
                continue
            last, zero = float(g["last increment"].iloc[0]), float(g["zero"].iloc[0])
            beat = [m for m in g.index if g.loc[m, col] < last]
            txt = f"`{profile}`, `{dataset}`"
            if method in g.index:
                txt += (f": {method} {fmt_num(g.loc[method, col])} m against last increment {fmt_num(last)} m "
                        f"and zero {fmt_num(zero)} m")
            txt += f"; below the last increment: {', '.join(beat) if beat else 'no network'}"
            if "INS increment" in g.columns and np.isfinite(g["INS increment"].iloc[0]):
                txt += (f"; the INS increment (the GPS-aided INS's speed over the same interval): "
                        f"{fmt_num(g['INS increment'].iloc[0])} m")
            lines.append(txt + ".")
    return lines


def variant_sweep_table(summaries: dict[str, pd.DataFrame | None]) -> pd.DataFrame | None:
    """Median max horizontal error of the outage sweep (m) per (dataset, duration, method), one column per
    profile (``tables/outage_sweep_summary.csv`` of each; profiles without one are left out)."""
    cols = [s.set_index(["dataset", "duration_s", "method"])["median_m"].rename(p)
            for p, s in summaries.items() if s is not None]
    return pd.concat(cols, axis=1) if cols else None


def reference_sentences(profile: str, training_summary: pd.DataFrame | None) -> list[str]:
    """:func:`variant_sentences` of one profile's ``tables/training_summary.csv``: per dataset BGFN against the
    untrained references, and which networks beat the *last increment*."""
    return variant_sentences(variant_training_table({profile: training_summary}))


def variants_section(profile: str, variants: Sequence[str], results_root: str | Path | None = None) -> list:
    """The *Variants* section of the results page: what to display, in order.

    Parameters
    ----------
    profile : str
        The page's profile.
    variants : sequence of str
        Profiles to compare with it (its ``base:`` is added, :func:`compared_profiles`).
    results_root : path, optional
        Folder of ``<profile>/`` results (default ``results/``).

    Returns
    -------
    list
        Markdown strings and pandas Stylers: a note per compared profile that has not run; when another profile
        has, the validation RMSE per profile with its sentences, each outage test's table per profile, the
        sweep per profile with each variant's paired comparisons, and a source line.
    """
    root = Path(results_root or RESULTS_ROOT)
    shown, missing = compared_profiles(profile, variants, root)
    if own_log_profile(profile):   # the shipped variants run other drives, and own/own-walker are bases: no request
        missing = []
    pieces: list = [missing_note(root / v / "tables" / SHARED_TABLES["training_summary"], f"the variant `{v}`",
                                 f"`make reproduce PROFILE={v}`") for v in missing]
    if len(shown) < 2:                     # nothing to put beside this profile
        return pieces
    vt = variant_training_table(profile_tables(shown, SHARED_TABLES["training_summary"], root))
    pieces += [compact(vt.style.format(fmt_num), "Validation RMSE of one increment (m), per profile"),
               bullets(variant_sentences(vt))]
    for info in TESTS.values():
        ot = variant_outage_table(profile_tables(shown, info["file"], root))
        if ot is not None:
            caption = f"{info['title'].capitalize()}: mean of max east and max north error (m), per profile"
            pieces.append(compact(ot.style.format("{:.1f}"), caption))
    sweeps = profile_tables(shown, SHARED_TABLES["sweep_summary"], root)
    sw = variant_sweep_table(sweeps)
    if sw is not None:
        pieces.append(compact(sw.style.format("{:.1f}").format_index("{:g}", axis=0, level=1),
                              "Outage sweep: median max horizontal error (m), per profile"))
        pairs = profile_tables(shown[1:], SHARED_TABLES["sweep_pairs"], root)
        pieces += ["\n".join(f"- `{p}`: {line}" for line in describe_sweep(sweeps[p], pairs[p]))
                   for p in shown[1:] if sweeps[p] is not None and pairs[p] is not None]
    pieces.append(short_source([root / p / "tables" for p in shown], " and ".join(shown)))
    return pieces

"""The outage sweep and the oracle in words (notebook 06 and the results page): what the sweep runs, its medians
and paired comparisons, and the increment accuracy at which a pseudo-GPS fix beats the learning-free rows."""

from __future__ import annotations

import numpy as np
import pandas as pd

from bgfn.evaluate.setup import TABLE_METHODS
from bgfn.nav.constraints import DEFAULT_PLATFORM
from bgfn.paper import label, nhc_label
from bgfn.report.aid_words import aid_label, aided_ins_words
from bgfn.studies.outage_sweep.oracle import (BEYOND_GRID, CROSSED, NEVER_BELOW, SWEEP_OUTAGE, NoSweepStarts,
                                             OracleResult)
from bgfn.studies.outage_sweep.sweep import sweep_train_config


def describe_sweep_setup(train_section: dict, ecfg: dict, datasets, platforms: dict | None = None) -> list[str]:
    """Lines saying what the sweep runs: its sizes, and the fold networks' window, size block, optimizer budget
    and per-method sizes (the ``train:`` section with the ``sweep.train`` overrides, :func:`sweep_train_config`);
    the aided rows by the aids that ran on the drives (``platforms``, ``{dataset: platform}``; none: a car's).
    """
    sw = ecfg["sweep"]
    tc = sweep_train_config(train_section, sw)
    budget = {k: tc["optimizer"][k] for k in ("epochs", "batch_size", "max_train_windows", "patience")
              if k in tc["optimizer"]}
    lines = [f"datasets {list(datasets)}: {sw['n_starts']} starts x durations {sw['durations_s']} s x "
             f"{sw['folds']} folds x seeds {sw['seeds']} x methods {[label(m) for m in ecfg['methods']]} + INS + GPS",
             f"fold networks: window {tc.get('window')} samples, size block {tc.get('size')!r}, optimizer {budget}"]
    lines += [f"  {label(m):>12}: {tc['sizes'][m][tc['size']]}" for m in ecfg["methods"]]
    if ecfg["nhc_rows"]:
        rows = [nhc_label(m) for m in ["INS"] + list(ecfg["methods"])]
        ran = {(platforms or {}).get(d, DEFAULT_PLATFORM) for d in datasets} or {DEFAULT_PLATFORM}
        kinds = sorted(ran - {DEFAULT_PLATFORM}, key=str)
        if DEFAULT_PLATFORM in ran:                                  # a car among the drives
            lines.append("INS and every network also with the vehicle constraints (NHC, ZUPT when still): rows "
                         + ", ".join(rows))
        lines += [f"INS and every network also with the aids of the {p}'s drives -- {aided_ins_words(p)}: rows "
                  + ", ".join(aid_label(r, p) for r in rows) for p in kinds]
    return lines


def describe_sweep_size(sweep: pd.DataFrame) -> str:
    """``<n> rows, <a> starts x <b> durations x <c> methods x <d> seeds`` of a sweep table."""
    return (f"{len(sweep)} rows, {sweep['start_s'].nunique()} starts x {sweep['duration_s'].nunique()} durations x "
            f"{sweep['method'].nunique()} methods x {sweep['seed'].nunique()} seeds")


def describe_sweep(summary: pd.DataFrame, pairs: pd.DataFrame, method: str = "BGFN") -> list[str]:
    """Plain-language lines on the sweep: medians with intervals and the paired comparisons."""
    lines = []
    for (ds, du), g in summary.groupby(["dataset", "duration_s"]):
        g = g.set_index("method")
        med = ", ".join(f"{m} {g.loc[m, 'median_m']:.1f} [{g.loc[m, 'ci_lo_m']:.1f}, {g.loc[m, 'ci_hi_m']:.1f}]"
                        for m in TABLE_METHODS if m in g.index)
        here = pairs[(pairs["dataset"] == ds) & (pairs["duration_s"] == du)]
        text = []
        for m in (method, nhc_label(method)):
            # a pairs table written before the +NHC rows has no method column: all its rows are `method`'s
            pp = (here[here["method"] == m] if "method" in here.columns else here if m == method
                  else here.iloc[:0]).set_index("baseline")
            if len(pp):
                text.append(f"{m} " + "; ".join(
                    f"vs {b}: wins {int(pp.loc[b, 'wins'])}/{int(pp.loc[b, 'n'])} "
                    f"(p = {pp.loc[b, 'p_value']:.2g}, by start {pp.loc[b, 'p_value_by_start']:.2g})" for b in pp.index))
        lines.append(f"{ds}, {du:g} s outages: median max horizontal error (m) [95 % interval]: {med}. "
                     + ". ".join(text) + ("." if text else ""))
    return lines


def _m(x: float) -> str:
    """A length in the sentences: two significant digits below 1 m, one decimal above."""
    return f"{x:.2g}" if abs(x) < 1 else f"{x:.1f}"


def _windows_text(outage: str, duration: float) -> str:
    return f"sweep, {duration:g} s outages" if outage == SWEEP_OUTAGE else f"outage {outage} ({duration:g} s)"


def describe_oracle(breakeven: pd.DataFrame) -> list[str]:
    """One plain sentence per dataset, windows, duration and baseline: the break-even sigma and how far each
    network is from it, computed from :func:`breakeven_table`."""
    lines = []
    keys = ["dataset", "test", "outage", "duration_s", "baseline"]
    for (ds, test, o, du, base), g in breakeven.groupby(keys, sort=False):
        r0 = g.iloc[0]
        head = f"{ds} ({test} test), {_windows_text(o, du)}: "
        if r0["crossing"] == NEVER_BELOW:
            lines.append(head + f"even the exact increments do not beat {base} ({r0['baseline_m']:.1f} m): no "
                         "increment accuracy makes the pseudo-GPS worth fusing.")
            continue
        if r0["crossing"] == BEYOND_GRID:
            s = head + (f"the oracle beats {base} ({r0['baseline_m']:.1f} m) at every sigma of the grid: the "
                        "break-even lies beyond it")
        else:
            s = head + (f"the pseudo-GPS beats {base} ({r0['baseline_m']:.1f} m) while the increment error stays "
                        f"below {_m(r0['breakeven_sigma_m'])} m per axis and {r0['increment_s']:.2g} s increment "
                        "(break-even)")
        nets = []
        for r in g.dropna(subset=["method"]).itertuples(index=False):
            if not np.isfinite(r.increment_rmse_m):
                continue
            far = [f"{r.rmse_to_breakeven:.1f} times the break-even"] if np.isfinite(r.rmse_to_breakeven) else []
            if r.equivalent_crossing == CROSSED:
                far.append(f"its aided error ({r.method_m:.1f} m) is the oracle's at sigma "
                           f"{_m(r.equivalent_sigma_m)} m")
            elif r.equivalent_crossing == BEYOND_GRID:
                far.append(f"its aided error ({r.method_m:.1f} m) exceeds the oracle's at every sigma of the grid")
            else:
                far.append(f"its aided error ({r.method_m:.1f} m) is below the exact oracle's")
            nets.append(f"{r.method} {_m(r.increment_rmse_m)} m ({'; '.join(far)})")
        lines.append(s + ("; the networks' increment errors (RMS per axis): " + ", ".join(nets) if nets else "")
                     + ".")
    return lines


def no_sweep_starts_words(no: NoSweepStarts) -> str:
    """Why a drive's oracle rows are of the paper's outages only
    (:class:`~bgfn.studies.outage_sweep.oracle.NoSweepStarts`)."""
    return f"{no.dataset}: no sweep starts ({no.expected}; found {no.found}): the paper's outages only"


def oracle_lines(result: OracleResult) -> list[str]:
    """The oracle rows of notebook 06 (:class:`~bgfn.studies.outage_sweep.oracle.OracleResult`) in words: the
    drives without sweep starts, then :func:`describe_oracle`."""
    return [no_sweep_starts_words(n) for n in result.no_sweep_starts] + describe_oracle(result.breakeven)

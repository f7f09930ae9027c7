"""The fleet's tables per test drive and pooled over them, for all outages and for those in and out of the training
drives' speed range: the odometer table's summary (:func:`bgfn.studies.odometer.bars.odometer_summary`, Wilcoxon
paired by start against INS+NHC) with the learned odometers' p Holm-adjusted per drive, duration and range
(:func:`bgfn.stats.holm_adjust`), and the offset per outage (:func:`bgfn.studies.odometer.errors.error_parts_table`)
with each odometer's sigma judged on the epochs and on the outages' means (:func:`sigma_table`). Pooled, a start is
one drive's start: the pairs stay within a drive."""

from __future__ import annotations

import numpy as np
import pandas as pd

from bgfn.stats import holm_adjust
from bgfn.studies.fleet.protocol import DRIVE_TIME_SHIFT_S, LEARNED
from bgfn.studies.odometer.bars import SUMMARY_COLUMNS, odometer_summary
from bgfn.studies.odometer.errors import ERROR_COLUMNS, error_parts_table

#: The pooled rows' ``dataset``: every test drive together.
POOLED = "pooled"
#: ``speed_range`` codes: every outage, those inside the training drives' speeds, those outside.
SPEED_RANGES: tuple[str, ...] = ("all", "in", "out")
#: Columns of ``tables/fleet_summary.csv`` (:func:`fleet_summary`).
FLEET_SUMMARY_COLUMNS: tuple[str, ...] = ("speed_range", *(c for c in SUMMARY_COLUMNS if c != "p_vs_nhc_holm"), "p_vs_nhc_holm")
#: Columns of ``tables/fleet_offsets.csv`` (:func:`offset_table`).
OFFSET_COLUMNS: tuple[str, ...] = ("speed_range", *ERROR_COLUMNS, "epoch_within_2sigma", "mean_within_2sigma")
#: The columns of :func:`sigma_table`.
SIGMA_COLUMNS: tuple[str, ...] = ("dataset", "method", "duration_s", "epoch_within_2sigma", "mean_within_2sigma")


def pooled_rows(rows: pd.DataFrame) -> pd.DataFrame:
    """``rows`` of every test drive as one dataset :data:`POOLED`, each drive's starts kept apart (shifted by the
    drive's order times :data:`DRIVE_TIME_SHIFT_S`)."""
    order = {n: i for i, n in enumerate(dict.fromkeys(rows["dataset"]))}
    return rows.assign(start_s=rows["start_s"] + rows["dataset"].map(order) * DRIVE_TIME_SHIFT_S, dataset=POOLED)


def in_range(rows: pd.DataFrame, flags: pd.DataFrame, which: str) -> pd.DataFrame:
    """The rows of the outages in (``which='in'``) or out of (``'out'``) range, or all (``'all'``)."""
    if which == "all":
        return rows
    f = flags.set_index(["dataset", "start_s", "duration_s"])["out_of_range"]
    key = pd.MultiIndex.from_frame(rows[["dataset", "start_s", "duration_s"]])
    out = f.reindex(key).fillna(False).to_numpy(bool)
    return rows[out if which == "out" else ~out]


def with_holm(summary: pd.DataFrame) -> pd.DataFrame:
    """``p_vs_nhc_holm``: the learned odometers' ``p_vs_nhc`` Holm-adjusted per speed range, dataset and duration
    (the family a table names its best of); NaN for the other rows."""
    out = summary.assign(p_vs_nhc_holm=np.nan)
    learned = out["method"].isin(LEARNED)
    for _, g in out[learned].groupby(["speed_range", "dataset", "duration_s"], sort=False):
        out.loc[g.index, "p_vs_nhc_holm"] = holm_adjust(g["p_vs_nhc"].to_numpy(float))
    return out


def fleet_summary(rows: pd.DataFrame, flags: pd.DataFrame) -> pd.DataFrame:
    """Per test drive and pooled, for all outages and those in and out of range: the odometer table's summary with
    the Holm-adjusted p (:data:`FLEET_SUMMARY_COLUMNS`)."""
    parts = []
    for which in SPEED_RANGES:
        r = in_range(rows, flags, which)
        if r.empty:
            continue
        for s in (odometer_summary(r), odometer_summary(pooled_rows(r))):
            parts.append(s.assign(speed_range=which))
    if not parts:
        return pd.DataFrame(columns=list(FLEET_SUMMARY_COLUMNS))
    return with_holm(pd.concat(parts, ignore_index=True)).reindex(columns=list(FLEET_SUMMARY_COLUMNS))


def pooled_series(series: dict) -> dict:
    """The honest speed series of every test drive (``{drive: series}``) as one, each drive's times shifted."""
    items = list(series.values())
    if not items:
        return {}
    shift = [i * DRIVE_TIME_SHIFT_S for i in range(len(items))]
    labels = sorted({k for s in items for k in s["tracks"]})

    def track(s, k):
        n = len(s["time"])
        return s["tracks"].get(k, (np.full(n, np.nan), np.full(n, np.nan)))

    def fused(s, k):
        return s.get("fused_std", {}).get(k, track(s, k)[1])

    return {"time": np.concatenate([s["time"] + d for s, d in zip(items, shift)]),
            "truth": np.concatenate([s["truth"] for s in items]),
            "outages": [(a + d, b) for s, d in zip(items, shift) for a, b in s["outages"]],
            "tracks": {k: tuple(np.concatenate([track(s, k)[j] for s in items]) for j in (0, 1)) for k in labels},
            "fused_std": {k: np.concatenate([fused(s, k) for s in items]) for k in labels}}


def sigma_table(dataset: str, series: dict, durations) -> pd.DataFrame:
    """Each odometer's sigma judged twice over the first ``d`` s of the outages of ``series``
    (:func:`bgfn.studies.fleet.protocol.speed_series`): ``epoch_within_2sigma``, the share of epochs whose speed
    error lies within 2 std (white errors: 95 %); ``mean_within_2sigma``, the share of outages whose mean speed error
    lies within 2 std of the mean as the filter weighs it: the speeds fused with ``fused_std`` each as independent,
    the mean's std is ``sqrt(mean(fused_std^2) / N)`` over the outage's ``N`` epochs. An offset the std does not
    allow for shows in the second share, not in the first (:data:`SIGMA_COLUMNS`)."""
    t, truth = np.asarray(series["time"], dtype=float), np.asarray(series["truth"], dtype=float)
    rows = []
    for label, (speed, std) in series["tracks"].items():
        err, std = np.asarray(speed, dtype=float) - truth, np.asarray(std, dtype=float)
        fused = np.asarray(series.get("fused_std", {}).get(label, std), dtype=float)
        for d in durations:
            epochs, means = [], []
            for start, length in series["outages"]:
                m = ((t > start) & (t <= start + min(float(d), float(length)) + 1e-6) & np.isfinite(err)
                     & np.isfinite(std) & (std > 0))
                if m.sum() < 2:
                    continue
                epochs.append(np.abs(err[m]) <= 2.0 * std[m])
                means.append(abs(err[m].mean()) <= 2.0 * np.sqrt(np.mean(fused[m] ** 2) / m.sum()))
            if means:
                rows.append({"dataset": dataset, "method": label, "duration_s": float(d),
                             "epoch_within_2sigma": float(np.concatenate(epochs).mean()),
                             "mean_within_2sigma": float(np.mean(means))})
    return pd.DataFrame(rows, columns=list(SIGMA_COLUMNS))


def offset_table(series: dict, durations, flags: pd.DataFrame, max_lag_s: float) -> pd.DataFrame:
    """Per test drive and pooled, speed range and duration: each odometer's offset per outage and fluctuation in the
    outages (:data:`OFFSET_COLUMNS`). ``series``: ``{drive: honest speed series}``."""
    flag = {(r.dataset, float(r.start_s), float(r.duration_s)): bool(r.out_of_range) for r in flags.itertuples()}
    parts = []
    for which in SPEED_RANGES:
        for d in durations:
            chosen = {}
            for name, s in series.items():
                keep = [(a, b) for a, b in s["outages"]
                        if which == "all" or flag.get((name, float(a), float(d)), False) == (which == "out")]
                if keep:
                    chosen[name] = {**s, "outages": keep}
            for name, s in [*chosen.items(), (POOLED, pooled_series(chosen))]:
                if s:
                    parts.append(error_parts_table(name, s, [d], max_lag_s)
                                 .merge(sigma_table(name, s, [d]), on=["dataset", "method", "duration_s"], how="left")
                                 .assign(speed_range=which))
    if not parts:
        return pd.DataFrame(columns=list(OFFSET_COLUMNS))
    return pd.concat(parts, ignore_index=True).reindex(columns=list(OFFSET_COLUMNS))

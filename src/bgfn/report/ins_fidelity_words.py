"""How good and how honest our INS is, in words (notebooks 06 and 08): its drift on the stand-in against the recorded
drive, the filter's NEES during outages, the gyro bias scan, the IMU twin's check and the INS under each filter setup
beside the paper's and NaveGo's own."""

from __future__ import annotations

import numpy as np
import pandas as pd

from bgfn import paper
from bgfn.studies.ins_fidelity.imu_twin import effective_levels, implied_setting
from bgfn.studies.ins_fidelity.ins_drift import DRIFT_TOLERANCE
from bgfn.studies.ins_fidelity.ins_setups import (NAVEGO_CONSISTENT, NAVEGO_RUN, NAVEGO_TOLERANCE, RESET, TRUE_COLUMNS,
                                                  gap_explained)
from bgfn.studies.ins_fidelity.nees import CHI2_95, CHI2_MEDIAN

_NAN = float("nan")


def drift_sentences(summary: pd.DataFrame, stand_in: str = "turin-sim-mpu6000",
                    recorded: str = "rtklib-drive0708", tolerance: float = DRIFT_TOLERANCE) -> list[str]:
    """One sentence per duration: the stand-in's median drift against the recorded drive's, INS and INS+NHC; then
    whether the standalone INS of the stand-in lies within a factor ``tolerance`` of the recorded one everywhere.

    Empty when either drive is missing from ``summary``.
    """
    have = set(summary["dataset"])
    if stand_in not in have or recorded not in have:
        return []
    lines, outside = [], []
    for du, g in summary.groupby("duration_s", sort=True):
        parts = []
        for method, gm in g.groupby("method", sort=False):
            level = gm.set_index("dataset")["median_max_h_m"]
            if stand_in in level and recorded in level:
                a, b = float(level[stand_in]), float(level[recorded])
                parts.append(f"{method} {a:.1f} m on the stand-in {stand_in}, {b:.1f} m on the recorded drive "
                             f"{recorded} ({b / a:.1f} times)" if a > 0 else f"{method}: stand-in 0 m")
                if method == "INS" and not (a > 0 and 1.0 / tolerance <= b / a <= tolerance):
                    outside.append(f"{du:g} s ({b / a:.2f})" if a > 0 else f"{du:g} s")
        n = int(g["n_starts"].max())
        lines.append(f"{du:g} s outages, median max horizontal error over up to {n} starts: " + "; ".join(parts))
    lines.append(f"The stand-in's standalone INS drifts within a factor {tolerance:g} of the recorded drive's at every "
                 "duration." if not outside else f"The stand-in's standalone INS drifts outside a factor {tolerance:g} "
                 f"of the recorded drive's at " + ", ".join(outside) + " (recorded over stand-in).")
    return lines


def nees_lines(summary: pd.DataFrame, methods=("INS", "INS+NHC")) -> list[str]:
    """Per dataset, whether the filter is consistent during outages: the INS rows (and INS+NHC) in the sweep at
    each duration, else in the paper's outages."""
    lines = []
    for ds, g in summary.groupby("dataset", sort=False):
        part = []
        for m in methods:
            h = g[(g["method"] == m) & (g["window"] == "sweep")]
            h = h if len(h) else g[g["method"] == m]
            if len(h):
                part.append(f"{m} " + ", ".join(f"{r.window if r.window != 'sweep' else f'{r.duration_s:g} s'}: "
                                                 f"median {r.median_nees:.3g}, {100 * r.inside_95:.0f} % inside, "
                                                 f"{r.verdict}" for r in h.itertuples()))
        if part:
            lines.append(f"{ds}, NEES of the horizontal position at the outage end against the filter's covariance "
                         f"(consistent: median {CHI2_MEDIAN:.2f}, 95 % below {CHI2_95:.2f}): " + "; ".join(part) + ".")
    return lines


def scan_lines(scan: pd.DataFrame) -> list[str]:
    """Per recorded drive: the profile's setting and its word, and the values of the grid that are consistent."""
    lines = []
    for ds, g in scan.groupby("dataset", sort=False):
        longest = g[g["duration_s"] == g["duration_s"].max()]
        own = longest[longest["profile"]]
        ok = longest.loc[longest["verdict"] == "consistent", "gyro_bias_instability_dps"]
        lines.append(f"{ds}: with the profile's gyro bias instability ({own['gyro_bias_instability_dps'].iloc[0]:g} "
                     f"deg/s) the INS is {own['verdict'].iloc[0]} at {longest['duration_s'].iloc[0]:g} s (median NEES "
                     f"{own['median_nees'].iloc[0]:.3g}); consistent with "
                     + (", ".join(f"{v:g}" for v in ok) + " deg/s" if len(ok) else "no value of the grid") + ".")
    return lines


def twin_lines(table: pd.DataFrame | None, tolerance: float = 1.25) -> list[str]:
    """What the check says: the two effective instabilities, the drift on one road, and whether the stand-in's
    setting holds (the twin within a factor ``tolerance`` of the recorded drive); empty without a table (no pair of
    drives to compare, :func:`~bgfn.studies.ins_fidelity.imu_twin.twin_section`)."""
    if table is None:
        return []
    rec_e, twin_e, model = effective_levels(table)
    rec = table[table["imu"] == "recorded"]
    twin = table[table["imu"] != "recorded"]
    drift = ", ".join(f"{du:g} s: {float(rec.loc[rec['duration_s'] == du, 'median_max_h_m'].iloc[0]):.1f} m recorded "
                      f"against {float(twin.loc[twin['duration_s'] == du, 'median_max_h_m'].median()):.1f} m simulated"
                      for du in sorted(rec["duration_s"].unique()))
    if not (np.isfinite(rec_e) and np.isfinite(twin_e)):
        return [f"The effective gyro bias instability lies outside the scan's grid for one IMU: no comparison ({drift})."]
    ratio = rec_e / twin_e
    holds = 1.0 / tolerance <= ratio <= tolerance
    return [f"Effective gyro bias instability on the recorded drive's road: {rec_e:.3g} deg/s for its real IMU, "
            f"{twin_e:.3g} deg/s for the stand-in's error model simulated with {model:.3g} deg/s (ratio {ratio:.2f}; "
            f"median INS drift, each with its filter's own model: {drift}).",
            ("The stand-in's setting holds: its simulated IMU is as rough as the recorded one within a factor "
             f"{tolerance:g}." if holds else "The stand-in's setting does not hold: its simulated IMU is "
             + ("smoother" if ratio > 1 else "rougher") + f" than the recorded one; the measurement implies "
             f"{implied_setting(table):.3g} deg/s (evaluate.imu_twin.settle_setting).")]


def gate_lines(table: pd.DataFrame) -> list[str]:
    """One sentence per drive of :func:`bgfn.nav.baseline.gate_comparison`'s table (its first row without the gate,
    its second with it): the fixes the gate rejects, and the GPS-aided horizontal RMS and max error without and
    with it."""
    lines = []
    for name, g in table.groupby("dataset", sort=False):
        off, on = g.iloc[0], g.iloc[1]
        lines.append(f"{name}: the gate ({on['innovation_gate']}) rejects {on['gnss_rejected']} of {on['gnss_fixes']} "
                     f"fixes; horizontal RMS {off['rms_h_m']:.2f} -> {on['rms_h_m']:.2f} m, max "
                     f"{off['max_h_m']:.2f} -> {on['max_h_m']:.2f} m")
    return lines


def _share(pct: float) -> str:
    if not np.isfinite(pct):
        return "there is no gap to explain"
    if pct < 0:
        return f"it moves away from the paper's row ({pct:.0f} % of the gap)"
    if pct > 100:
        return f"it overshoots the paper's row ({pct:.0f} % of the gap)"
    return f"it explains {pct:.0f} % of the gap"


def ins_setup_sentences(table: pd.DataFrame) -> list[str]:
    """Plain sentences from :func:`~bgfn.studies.ins_fidelity.ins_setups.gap_explained`: per dataset, the mean INS max error under each setup, the
    paper's, and the share of the gap each setup explains."""
    gap = gap_explained(table)
    names = {"navego": "NaveGo v1.4's setup", RESET: "that setup with the bias estimates cleared at the outage start",
             NAVEGO_RUN: "NaveGo v1.4 itself, run under Octave on the same drive and outages",
             NAVEGO_CONSISTENT: "the same with its bias feedback made consistent"}
    out = []
    for dataset, g in gap.groupby("dataset", sort=False):
        first = g.iloc[0]
        parts = [f"{names.get(r.setup, r.setup)}: {r.setup_m:.1f} m, so {_share(r.explained_pct)}"
                 for r in g.itertuples(index=False)]
        out.append(f"{dataset} ({paper.TESTS[first.test]['title']}): the INS max error (mean of east and north over "
                   f"the outages) is {first.shipped_m:.1f} m with the shipped filter against the paper's "
                   f"{first.paper_m:.1f} m; " + "; ".join(parts) + "." + _against_navego(g))
    return out


def _within(ratio: float, why: str = "") -> str:
    """``(within 30 %)`` or ``(more than 30 % apart<why>)`` for a ratio of INS errors."""
    return ("(within 30 %)" if abs(ratio - 1.0) <= NAVEGO_TOLERANCE else f"(more than 30 % apart{why})")


def _bias_states(row, ours, true: dict) -> str:
    """The largest gyro- and accelerometer-bias estimates of NaveGo's run ``row`` and of our setup ``ours``,
    against the drive's largest true biases (``true``), in words; empty where they are not measured."""
    parts = []
    for col, true_col, unit, fmt in (("max_gyro_bias_est_dps", "true_gyro_bias_dps", "deg/s", ".3g"),
                                     ("max_accel_bias_est_mps2", "true_accel_bias_mps2", "m/s^2", ".2g")):
        theirs, mine = getattr(row, col, _NAN), getattr(ours, col, _NAN)
        if not (np.isfinite(theirs) and np.isfinite(mine)):
            continue
        sensor = "gyro" if "gyro" in col else "accelerometer"
        text = f"the largest {sensor}-bias estimate over the drive is {theirs:{fmt}} {unit} in NaveGo, {mine:{fmt}} {unit} in our setup of it"
        t = true.get(true_col, _NAN)
        parts.append(text + (f", against the drive's largest true {sensor} bias of {t:{fmt}} {unit}" if np.isfinite(t) else ""))
    return "; ".join(parts)


def _against_navego(gap: pd.DataFrame) -> str:
    """Our ``navego`` setup against NaveGo's own runs (within 30 % of it?), when both are there: the INS
    ratio, both GPS-aided solutions' horizontal RMS (outages that start from far different states cannot agree) and
    the bias states step by step; then the same against NaveGo with its bias feedback made consistent."""
    rows = {r.setup: r for r in gap.itertuples(index=False)}
    ours = rows.get("navego")
    if ours is None:
        return ""
    true = {c: float(gap[c].iloc[0]) if c in gap.columns else _NAN for c in TRUE_COLUMNS}
    text = ""
    released = rows.get(NAVEGO_RUN)
    if released is not None and released.setup_m > 0:
        ratio = ours.setup_m / released.setup_m
        text += (f" Our setup of NaveGo gives {ratio:.2f} times NaveGo's own INS error "
                 f"{_within(ratio, ': methods page, NaveGo run beside us, lists the differences')}.")
        a_ours, a_theirs = getattr(ours, "aided_rms_h_m", _NAN), getattr(released, "aided_rms_h_m", _NAN)
        if np.isfinite(a_ours) and np.isfinite(a_theirs):
            text += (f" Their GPS-aided solutions, from which every outage starts: {a_theirs:.1f} m horizontal RMS for "
                     f"NaveGo, {a_ours:.1f} m for our setup of it"
                     + (" (NaveGo's own filter loses the drive with the GNSS still there)." if a_theirs > 3 * max(a_ours, 1.0)
                        else "."))
        states = _bias_states(released, ours, true)
        text += f" Their bias states, step by step: {states}." if states else ""
    fixed = rows.get(NAVEGO_CONSISTENT)
    if fixed is not None and fixed.setup_m > 0:
        ratio = ours.setup_m / fixed.setup_m
        text += (" With NaveGo's bias feedback made consistent (every error state zeroed before an update and the "
                 "bias estimates corrected by the states with the signs of its own F, where v1.4 carries the bias "
                 f"states and takes their negative as the estimate), our setup gives {ratio:.2f} times its INS error "
                 f"{_within(ratio)}")
        a_fixed = getattr(fixed, "aided_rms_h_m", _NAN)
        text += f"; its GPS-aided RMS is {a_fixed:.1f} m" if np.isfinite(a_fixed) else ""
        states = _bias_states(fixed, ours, true)
        text += (f"; {states}." if states else ".")
    return text

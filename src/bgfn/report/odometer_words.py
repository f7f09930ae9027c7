"""The learned odometer in words (notebook 07): what its bars, its networks, its uncertainty, its speed error and
the ridge's learning curve say, and its energy."""

from __future__ import annotations

import numpy as np
import pandas as pd

from bgfn.paper import nhc_label
from bgfn.studies.odometer.bars import (ENSEMBLE_ODOMETERS, HOLD, NETWORK_ODOMETERS, ODOMETER_METHODS, ORACLE,
                                        ORACLE_WALK, RIDGE)
from bgfn.studies.odometer.energy import FOLD, OdometerEnergy
from bgfn.energy.tables import total_energy_uj
from bgfn.studies.odometer.ridge_curve import CURVE_COLUMNS
from bgfn.studies.odometer.section import OdometerSection, odometer_table
from bgfn.studies.odometer.uncertainty import ranks_errors


def skipped_lines(facts: dict) -> list[str]:
    """One line per drive without odometer bars (``facts[name]["skipped"]``: its platform)."""
    return [f"{name}: no odometer bars (platform {f['skipped']}: the learned odometer is a car's forward speed, "
            "fused with the non-holonomic constraints)" for name, f in facts.items() if f.get("skipped")]


def odometer_markdown(section: OdometerSection) -> str:
    """Notebook 07's odometer bars (:class:`~bgfn.studies.odometer.section.OdometerSection`): the summary at the
    sweep's durations as a Markdown table (:func:`~bgfn.studies.odometer.section.odometer_table`), then the lines."""
    skipped = skipped_lines(section.facts)
    if section.summary.empty:
        return "\n".join(skipped or ["No odometer bars (``evaluate.odometer.datasets`` is empty or the sweep has no "
                                      "dataset)."])
    wide = odometer_table(section.summary)
    head = "| dataset | method | " + " | ".join(wide.columns) + " |"
    body = [f"| {ds} | {m} | " + " | ".join(f"{v:.1f}" for v in r) + " |" for (ds, m), r in wide.iterrows()]
    text = "\n".join(["Median max horizontal error (m) over the sweep's starts:", "", head,
                       "|---" * (len(wide.columns) + 2) + "|", *body, ""]
                      + [f"- {s}" for s in odometer_lines(section.summary)]
                      + [f"- {s}" for s in network_lines(section.networks)]
                      + [f"- {s}" for s in (uncertainty_lines(section.uncertainty) if section.uncertainty is not None
                                            else [])]
                      + [f"- {s}" for s in error_parts_lines(section.errors)]
                      + [f"- {s}" for s in curve_lines(section.curve if section.curve is not None
                                                       else pd.DataFrame(columns=list(CURVE_COLUMNS)))]
                      + [f"- {s}" for s in skipped])
    if section.paper is None or section.paper.empty:
        return text
    p = section.paper[section.paper["sigma_mps"].isna()]       # the oracle's grid: tables/outage_odometer_paper.csv
    wide = p.pivot_table(index=["dataset", "method"], columns="outage", values="max_h_m", sort=False)
    head = "| dataset | method | " + " | ".join(f"outage {c}" for c in wide.columns) + " |"
    body = [f"| {ds} | {m} | " + " | ".join(f"{v:.1f}" for v in r) + " |" for (ds, m), r in wide.iterrows()]
    return "\n".join([text, "", "Max horizontal error (m) in each drive's two evaluation outages (the paper's tables; "
                      "the networks and the ridge trained with those outages +- margin held out, median over "
                      "seeds):", "", head, "|---" * (len(wide.columns) + 2) + "|", *body])


def odometer_lines(summary: pd.DataFrame) -> list[str]:
    """Per dataset and duration: INS+NHC, the held speed, the ridge odometer and the oracle's break-even."""
    lines = []
    for (ds, du), g in summary.groupby(["dataset", "duration_s"], sort=False):
        by = {m: g[g["method"] == m] for m in ODOMETER_METHODS}
        nhc = float(by[nhc_label("INS")]["max_h_m"].iloc[0]) if len(by[nhc_label("INS")]) else np.nan
        part = [f"{ds}, {du:g} s outages (median max horizontal error): INS+NHC {nhc:.1f} m"]
        for m in (HOLD, RIDGE, *NETWORK_ODOMETERS, *ENSEMBLE_ODOMETERS):
            if len(by[m]):
                row = by[m].iloc[0]
                part.append(f"{m} {row['max_h_m']:.1f} m ({row['ratio_to_nhc']:.2f} of INS+NHC per start"
                            + (f", Wilcoxon p = {row['p_vs_nhc']:.2g}" if "p_vs_nhc" in row else "")
                            + (f", Holm-corrected over the learned odometers {row['p_vs_nhc_holm']:.2g}"
                               if np.isfinite(row.get("p_vs_nhc_holm", np.nan)) else "")
                            + (f"; speed RMSE {row['speed_rmse_mps']:.2f} m/s, 2-sigma coverage "
                               f"{100 * row['coverage_2sigma']:.0f} %" if m != HOLD else "") + ")")
        for m, what in ((ORACLE, "an oracle speed"), (ORACLE_WALK, "with a random walk")):
            orc = by[m].sort_values("sigma_mps")
            if len(orc):
                best = orc.loc[orc["max_h_m"].idxmin()]
                better = orc[orc["max_h_m"] < nhc]
                part.append(f"{what} beats INS+NHC " + (f"up to a noise of {better['sigma_mps'].max():g} m/s"
                                                         if len(better) else "at no noise level of the grid")
                            + f" (its best: {best['max_h_m']:.1f} m at {best['sigma_mps']:g} m/s)")
        lines.append("; ".join(part) + ".")
    return lines


def network_lines(networks: pd.DataFrame | None) -> list[str]:
    """Per dataset and fold: each network odometer's speed RMSE on its validation block against its own fold's
    outages, with its share of outage epochs within +-2 sigma (medians over seeds, :func:`network_table`). A fold
    whose validation block is easier than its outages gets too small a std there (the calibration shrinks it)."""
    if networks is None or networks.empty:
        return []
    lines = []
    cols = ["val_rmse_mps", "outage_speed_rmse_mps", "outage_coverage_2sigma"]
    for (ds, fold), g in networks.groupby(["dataset", "fold"], sort=False):
        med = g.groupby("method", sort=False)[cols].median()
        lines.append(f"{ds}, fold {fold}: the network odometers' speed RMSE on the validation block their std was "
                     "calibrated on, then in the fold's outages (median over seeds): "
                     + "; ".join(f"{m} {r['val_rmse_mps']:.2f}, then {r['outage_speed_rmse_mps']:.2f} m/s "
                                 f"({100 * r['outage_coverage_2sigma']:.0f} % of outage epochs within +-2 sigma)"
                                 for m, r in med.iterrows()) + ".")
    return lines


def uncertainty_sentence(group_rows: pd.DataFrame) -> str:
    """What one odometer's rows of :func:`uncertainty_table` say: whether its std ranks its errors
    (:func:`ranks_errors`), the correlation, and the smallest- and largest-std groups' speed RMSE and coverage."""
    g = group_rows.sort_values("group")
    lo, hi = g.iloc[0], g.iloc[-1]
    verdict = "ranks its errors" if ranks_errors(g) else "does not rank its errors"
    part = {2: "half", 3: "third", 4: "quarter"}.get(len(g), f"1/{len(g)}")
    return (f"its predicted std {verdict} in the outages (correlation of |error| and std "
            f"{lo['corr_abs_error_std']:.2f}): the {part} of its epochs with the smallest std "
            f"({lo['std_lo_mps']:.2f}-{lo['std_hi_mps']:.2f} m/s) has a speed RMSE of {lo['speed_rmse_mps']:.2f} m/s "
            f"({100 * lo['coverage_2sigma']:.0f} % within 2 sigma), the one with the largest "
            f"({hi['std_lo_mps']:.2f}-{hi['std_hi_mps']:.2f} m/s) {hi['speed_rmse_mps']:.2f} m/s "
            f"({100 * hi['coverage_2sigma']:.0f} %)")


def uncertainty_lines(table: pd.DataFrame) -> list[str]:
    """One line per dataset and odometer (:func:`uncertainty_sentence`)."""
    return [f"{method}, {ds}: {uncertainty_sentence(g)}"
            for (ds, method), g in table.groupby(["dataset", "method"], sort=False)]


def error_parts_lines(table: pd.DataFrame) -> list[str]:
    """Per dataset and duration: each odometer's offset and fluctuation in the outages (notebook 07)."""
    if table is None or table.empty:
        return []
    lines = []
    for (ds, d), g in table.groupby(["dataset", "duration_s"], sort=False):
        lines.append(f"{ds}, the first {d:g} s of each outage: the learned speed's error as an offset per outage (RMS "
                     "over the outages) and a fluctuation around it, with its integrated autocorrelation there: "
                     + "; ".join(f"{r['method']} {r['offset_rms_mps']:.2f} and {r['fluctuation_mps']:.2f} m/s "
                                 f"(kappa {r['outage_correlation']:.1f})" for _, r in g.iterrows()) + ".")
    return lines


def curve_lines(curve: pd.DataFrame) -> list[str]:
    """One sentence per dataset: the ridge's speed error in its outages as its training windows per fold grow."""
    lines = []
    for ds, g in curve.groupby("dataset", sort=False):
        g = g.sort_values("folds")
        lines.append(f"{ds}: RIDGE-ODO's speed RMSE in its own fold's {g['duration_s'].iloc[0]:g} s outages as the "
                     "sweep's starts are split into more folds (each holding out less of the drive): "
                     + "; ".join(f"{r.folds} folds, {r.n_train:.0f} training windows per fold: "
                                 f"{r.outage_speed_rmse_mps:.2f} m/s ({100 * r.outage_coverage_2sigma:.0f} % "
                                 "within +-2 sigma)" for r in g.itertuples()) + ".")
    return lines


def odometer_energy_lines(odo: OdometerEnergy) -> list[str]:
    """The learned odometers' energy (:class:`~bgfn.studies.odometer.energy.OdometerEnergy`): which networks, on
    which windows, and the reduction."""
    e = {m: total_energy_uj(t) for m, t in odo.tables.items()}
    out = [f"{odo.dataset}, sweep fold {FOLD}, seed {odo.seed}: {odo.n_windows} IMU windows evenly spaced over "
           f"the drive; BGFN-ODO mean input firing rate {odo.mean_rate:.3f}"]
    if not odo.improved.get("bgfn", True):
        out.append(f"BGFN-ODO {e['bgfn']:.4g} µJ per prediction; BGFN-ODO did not train (best epoch 0), so no "
                   f"energy saving against its twin is claimed")
    elif np.isfinite(odo.reduction_pct):
        out.append(f"BGFN-ODO {e['bgfn']:.4g} µJ, Transformer-ODO {e['transformer']:.4g} µJ per prediction: "
                   f"{odo.reduction_pct:.1f} % less energy for the spiking odometer")
    else:
        out.append(f"BGFN-ODO {e['bgfn']:.4g} µJ per prediction; no Transformer-ODO was trained "
                   f"(evaluate.odometer.methods) to compare with")
    return out

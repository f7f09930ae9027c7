"""Is the stand-in's IMU as rough as a real one? The recorded drive against its trajectory twin (notebook 08).

At rest (:mod:`bgfn.studies.ins_fidelity.imu_roughness`) the recorded car's IMU is no rougher than the stand-in's
error model, yet in outages it drifts several times further: what acts only while driving is seen by the filter.
The measurement is a drive's *effective gyro bias instability*, the filter's setting at which its standalone INS is
consistent in outages (median NEES 1.39, :mod:`bgfn.studies.ins_fidelity.nees`; :func:`effective_instability`), on
the recorded drive and on its trajectory twin (the same road, GNSS, starts and filter, with the stand-in's error
model simulated). Taking the terms the filter does not model in quadrature, :func:`implied_setting` gives the
simulated instability that matches the recorded drive and :func:`settle_setting` iterates it; the profile carries
the result and notebook 08 checks it on every run (:func:`twin_check`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Callable

import numpy as np
import pandas as pd

from bgfn.config import SHARED_TABLES
from bgfn.studies.ins_fidelity.imu_roughness import trajectory_twin
from bgfn.studies.ins_fidelity.nees import CHI2_MEDIAN, brackets_crossing, consistency_scan, scan_options
from bgfn.io import atomic_write_csv
from bgfn.paper import test_of
from bgfn.parallel import Runner

#: Columns of ``tables/kf_imu_twin.csv``.
TWIN_COLUMNS: tuple[str, ...] = ("dataset", "imu", "seed", "duration_s", "effective_dps", "model_dps",
                                 "median_max_h_m")


def effective_instability(scan: pd.DataFrame) -> pd.DataFrame:
    """Per dataset and duration of a :func:`bgfn.studies.ins_fidelity.nees.consistency_scan`: the gyro bias instability at which the
    median NEES first falls to :data:`CHI2_MEDIAN` (deg/s, log-log interpolated; NaN when it never does, the grid's
    first value when it already does there).

    Returns
    -------
    DataFrame
        ``dataset, duration_s, effective_dps``.
    """
    rows = []
    for (ds, du), g in scan.groupby(["dataset", "duration_s"], sort=False):
        g = g.sort_values("gyro_bias_instability_dps")
        x, y = g["gyro_bias_instability_dps"].to_numpy(float), g["median_nees"].to_numpy(float)
        below = np.flatnonzero(y <= CHI2_MEDIAN)
        if below.size == 0:
            value = np.nan
        elif below[0] == 0:
            value = float(x[0])
        else:
            k = below[0]
            w = np.log(y[k - 1] / CHI2_MEDIAN) / np.log(y[k - 1] / y[k])
            value = float(np.exp(np.log(x[k - 1]) + w * (np.log(x[k]) - np.log(x[k - 1]))))
        rows.append((ds, float(du), value))
    return pd.DataFrame(rows, columns=["dataset", "duration_s", "effective_dps"])


def _rows(scan: pd.DataFrame, imu: str, seed) -> list[dict]:
    eff = effective_instability(scan)
    own = scan[scan["profile"]]
    out = []
    for _, r in eff.iterrows():
        o = own[own["duration_s"] == r["duration_s"]].iloc[0]
        out.append({"dataset": r["dataset"], "imu": imu, "seed": seed, "duration_s": r["duration_s"],
                    "effective_dps": r["effective_dps"], "model_dps": float(o["gyro_bias_instability_dps"]),
                    "median_max_h_m": float(o["median_max_h_m"])})
    return out


def twin_check(cfg: dict, recorded, stand_in, seeds=None, scan: pd.DataFrame | None = None,
               gyro_dps: float | None = None, report: Callable[[str], None] | None = None,
               runner: Runner | None = None) -> pd.DataFrame:
    """The effective gyro bias instability of the recorded drive and of its trajectory twins (module docstring).

    Parameters
    ----------
    cfg : dict
        The profile (``nav:`` runs the filter, ``evaluate.sweep`` places the starts).
    recorded, stand_in : bgfn.data.Drive
        The recorded drive, and the simulated stand-in whose ``meta["imu_errors"]`` the twin simulates.
    seeds : sequence of int, optional
        Seeds of the twin's IMU errors (default ``evaluate.nees_scan.twin_seeds``).
    scan : DataFrame, optional
        The recorded drive's :func:`bgfn.studies.ins_fidelity.nees.consistency_scan` (notebook 08 has run it; default: run here).
    gyro_dps : float, optional
        Simulate the twin with this gyro bias instability (deg/s, every axis) instead of the stand-in's.
    report : callable, optional
        Called with one line per drive.
    runner : bgfn.parallel.Runner, optional
        Where the scans' points run (default: one after the other).

    Returns
    -------
    DataFrame
        :data:`TWIN_COLUMNS`: ``imu`` ``recorded`` or ``<stand-in> model``; ``model_dps`` the filter's own setting
        and ``median_max_h_m`` the INS drift with it (the twin's: the stand-in's model, exact).
    """
    options = scan_options(cfg)
    seeds = options["twin_seeds"] if seeds is None else seeds
    scan = (consistency_scan(cfg, [recorded], runner=runner) if scan is None
            else scan[scan["dataset"] == recorded.name])
    rows = _rows(scan, "recorded", None)
    errors = dict(stand_in.meta["imu_errors"])
    if gyro_dps is not None:
        errors["gyro_bias_instability"] = [float(np.radians(gyro_dps))] * 3
    twins = [trajectory_twin(recorded, errors, seed) for seed in seeds]
    # every twin's scan in one map: its points spread over the runner's jobs together
    # (the twins carry the recorded drive's name, so its settings apply: their rows come back twin by twin, each
    # twin the same number of them)
    # a twin's scan only has to bracket where its NEES falls to 1.39 (effective_instability): a profile may give it
    # fewer points than the recorded drive's (evaluate.nees_scan.twin_gyro_bias_dps); where they do not bracket it
    # (already consistent at the first point, or never), the twins are scanned again on the recorded drive's grid
    short = options["twin_gyro_bias_dps"]
    twin_scan = consistency_scan(cfg, twins, values_dps=short, runner=runner)
    per_twin = len(twin_scan) // max(len(twins), 1)
    if short is not None and not all(brackets_crossing(twin_scan.iloc[k * per_twin:(k + 1) * per_twin])
                                     for k in range(len(twins))):
        twin_scan = consistency_scan(cfg, twins, runner=runner)
        per_twin = len(twin_scan) // max(len(twins), 1)
    for k, seed in enumerate(seeds):
        rows += _rows(twin_scan.iloc[k * per_twin:(k + 1) * per_twin], f"{stand_in.name} model", int(seed))
    out = pd.DataFrame(rows, columns=list(TWIN_COLUMNS))
    if report is not None:
        for imu, g in out.groupby("imu", sort=False):
            report(f"{recorded.name}, {imu} IMU: effective gyro bias instability "
                   + ", ".join(f"{v:.3g} deg/s at {d:g} s" for d, v in g.groupby("duration_s")["effective_dps"]
                               .apply(lambda x: float(np.exp(np.log(x).mean()))).items()))
    return out


def _gmean(x: pd.Series) -> float:
    x = x.to_numpy(float)
    return float(np.exp(np.mean(np.log(x)))) if x.size and np.all(np.isfinite(x)) and np.all(x > 0) else np.nan


def effective_levels(table: pd.DataFrame) -> tuple[float, float, float]:
    """``(recorded, twin, twin's simulated)`` gyro bias instability, deg/s: the effective ones as geometric means
    over durations and seeds."""
    twin = table[table["imu"] != "recorded"]
    return (_gmean(table.loc[table["imu"] == "recorded", "effective_dps"]), _gmean(twin["effective_dps"]),
            float(twin["model_dps"].iloc[0]))


def implied_setting(table: pd.DataFrame) -> float:
    """The simulated gyro bias instability that gives the twin the recorded drive's effective one (module
    docstring: ``sqrt(e_rec^2 - (e_twin^2 - m^2))``, deg/s; 0 when the twin's unmodelled terms alone exceed it)."""
    rec, twin, model = effective_levels(table)
    extra2 = max(twin ** 2 - model ** 2, 0.0)
    return float(np.sqrt(max(rec ** 2 - extra2, 0.0)))


def settle_setting(cfg: dict, recorded, stand_in, start_dps: float, seeds=None, rtol: float = 0.1,
                   max_steps: int = 5, report: Callable[[str], None] | None = None) -> tuple[float, pd.DataFrame]:
    """Repeat :func:`implied_setting` from ``start_dps`` until a step changes it by less than ``rtol``.

    Returns
    -------
    (float, DataFrame)
        The settled setting (deg/s) and one row per step (``step, model_dps, recorded_dps, twin_dps,
        implied_dps``).
    """
    scan = consistency_scan(cfg, [recorded])
    value, steps = float(start_dps), []
    for step in range(max_steps):
        table = twin_check(cfg, recorded, stand_in, seeds, scan=scan, gyro_dps=value)
        rec, twin, _ = effective_levels(table)
        implied = implied_setting(table)
        steps.append((step, value, rec, twin, implied))
        if report is not None:
            report(f"step {step}: simulated {value:.4g} deg/s -> twin {twin:.4g}, recorded {rec:.4g}, "
                   f"implied {implied:.4g} deg/s")
        done = abs(implied - value) <= rtol * value
        value = implied
        if done:
            break
    return value, pd.DataFrame(steps, columns=["step", "model_dps", "recorded_dps", "twin_dps", "implied_dps"])


def twin_section(cfg: dict, drives, scan: pd.DataFrame, out: Path,
                 report: Callable[[str], None] | None = None, runner: Runner | None = None) -> pd.DataFrame | None:
    """Notebook 08's check: :func:`twin_check` of the first recorded drive (test ``real``) against the stand-in
    (test ``field``) among ``drives``, written to ``tables/kf_imu_twin.csv`` and returned (None without such a pair;
    in words: :func:`bgfn.report.ins_fidelity_words.twin_lines`)."""
    recorded = next((d for d in drives if test_of(d.name) == "real"), None)
    stand_in = next((d for d in drives if test_of(d.name) == "field"), None)
    if recorded is None or stand_in is None:
        return None
    table = twin_check(cfg, recorded, stand_in, scan=scan, report=report, runner=runner)
    atomic_write_csv(Path(out) / "tables" / SHARED_TABLES["kf_imu_twin"], table, float_format="%.6g")
    return table

"""Notebook 02 workflow: the KF baseline on a drive (full GPS/INS run, standalone INS in the outages).

The ``nav:`` section of ``params/<profile>.yaml`` configures it (keys and defaults in ``NAV_DEFAULTS``); the
outages are the profile's ``outage_windows`` (:func:`bgfn.nav.outages.outage_windows`).

- ``datasets``: drive names for :func:`bgfn.data.load_drive` (the profile's ``data:`` section crops them);
- ``init``: initial std ``position_std_m``, ``height_std_m``, ``velocity_std_mps``, ``level_std_deg``,
  ``azimuth_std_deg`` (P0; the filter starts from the reference's first row);
- ``bias_model`` (``random_walk`` | ``gauss_markov``), ``noise_scale``: see
  :func:`bgfn.nav.state.noise_from_imu_errors`;
- ``innovation_gate``: null (every GNSS fix fused, the paper's filter) or a probability ``p``: a fix whose NIS
  exceeds the ``p`` quantile of chi-square is not fused (:func:`bgfn.nav.filter.run_filter`);
- ``nhc``, ``zupt``: the vehicle constraints of the ``INS+NHC`` rows (:mod:`bgfn.nav.constraints`; ZUPT whenever
  the stillness detector fires, the label says NHC anyway); ``constraints_in_gps_run``: false (the paper's
  GPS-aided filter) or true (the GPS-aided run applies them too, :func:`gps_constraints`).
"""

from __future__ import annotations

import copy
from dataclasses import dataclass

import numpy as np
import pandas as pd

from .. import paper
from ..errors import DataError
from . import metrics
from . import constraints as cn
from .filter import FilterResult, gate_thresholds, run_filter, run_outage
from .outages import check_windows, epochs_before
from .state import FilterNoise, FilterState, initial_covariance, initial_state, noise_from_imu_errors

#: Defaults of the ``nav:`` profile section.
NAV_DEFAULTS: dict = {
    "datasets": ["turin-sim-ekinox", "turin-sim-mpu6000"],
    "init": {"position_std_m": 1.0, "height_std_m": 3.0, "velocity_std_mps": 0.1, "level_std_deg": 0.5,
             "azimuth_std_deg": 2.0},
    "bias_model": "random_walk",
    "noise_scale": 1.0,
    "innovation_gate": None,
    "nhc": dict(cn.NHC_DEFAULTS),
    "zupt": dict(cn.ZUPT_DEFAULTS),
    "constraints_in_gps_run": False,
}
#: Sections of ``nav:`` merged key by key (their own keys checked).
_SUBSECTIONS = ("init", "nhc", "zupt")
#: Label of the standalone INS with the vehicle constraints (:func:`bgfn.paper.nhc_label`).
INS_NHC = paper.nhc_label("INS")


def nav_config(section: dict | None) -> dict:
    """``NAV_DEFAULTS`` updated with a profile's ``nav:`` section (unknown keys raise)."""
    cfg = copy.deepcopy(NAV_DEFAULTS)
    for key, value in (section or {}).items():
        if key not in cfg:
            raise DataError("params nav", key, f"one of {sorted(cfg)}", "unknown key")
        if key in _SUBSECTIONS:
            unknown = set(value) - set(cfg[key])
            if unknown:
                raise DataError(f"params nav.{key}", sorted(unknown)[0], f"one of {sorted(cfg[key])}",
                                "unknown key")
            cfg[key].update(value)
        else:
            cfg[key] = value
    gate_thresholds(cfg["innovation_gate"], "params nav")      # a bad probability fails here, by name
    cn.constraint_config(cfg)                                   # and bad constraint settings
    return cfg


def gps_constraints(drive, cfg: dict, initial: FilterState, noise: FilterNoise):
    """The vehicle constraints of the GPS-aided run: None unless ``constraints_in_gps_run``.

    When asked, a first GPS-aided pass without them gives the vehicle frame (its causal running estimate,
    :func:`bgfn.nav.constraints.mounting_track`), then the constraints hold the whole drive's detector and aid
    epochs. Used by every GPS-aided run (:func:`run_drive`, :func:`run_baseline`,
    :func:`bgfn.evaluate.navigation_context`) so that they agree.
    """
    if not cfg["constraints_in_gps_run"]:
        return None
    first = run_filter(drive.imu, initial, noise, drive.gnss, drive.meta.get("lever_arm_m", [0.0, 0.0, 0.0]),
                       gate_probability=cfg["innovation_gate"], source=drive.name)
    return outage_constraints(drive, cfg, first.trajectory)


def outage_constraints(drive, cfg: dict, trajectory: pd.DataFrame):
    """The vehicle constraints of the ``INS+NHC`` runs of ``drive``: the stillness detector over its IMU and the
    vehicle frame from the GPS-aided ``trajectory`` (:func:`bgfn.nav.constraints.build_constraints`)."""
    return cn.build_constraints(drive.imu, drive.meta["imu_errors"], cn.constraint_config(cfg), trajectory,
                                source=drive.name)


def run_drive(drive, section: dict | None = None, snapshots: dict | None = None) -> FilterResult:
    """GPS/INS filter over a whole drive with every GNSS fix (the paper's online-training mode).

    Parameters
    ----------
    drive : bgfn.data.Drive
    section : dict, optional
        A profile's ``nav:`` section (defaults: ``NAV_DEFAULTS``).
    snapshots : dict, optional
        ``{name: time}`` of filter states to save (see :func:`bgfn.nav.filter.run_filter`).

    Returns
    -------
    FilterResult
    """
    cfg = nav_config(section)
    initial, noise = filter_setup(drive, cfg)
    return run_filter(drive.imu, initial, noise, drive.gnss, drive.meta.get("lever_arm_m", [0.0, 0.0, 0.0]),
                      snapshots=snapshots, gate_probability=cfg["innovation_gate"], source=drive.name,
                      constraints=gps_constraints(drive, cfg, initial, noise))


def filter_setup(drive, cfg: dict) -> tuple[FilterState, FilterNoise]:
    """Initial filter state (at the reference's first row) and noise for a drive.

    Parameters
    ----------
    drive : bgfn.data.Drive
    cfg : dict
        Output of :func:`nav_config`.

    Returns
    -------
    initial : FilterState
    noise : FilterNoise
    """
    noise = noise_from_imu_errors(drive.meta["imu_errors"], cfg["bias_model"], cfg["noise_scale"],
                                  source=f"{drive.name} meta['imu_errors']")
    row = drive.reference.iloc[0]
    init = cfg["init"]
    P0 = initial_covariance(row[["lat", "lon", "h"]].to_numpy(float), noise, init["position_std_m"],
                            init["height_std_m"], init["velocity_std_mps"], np.radians(init["level_std_deg"]),
                            np.radians(init["azimuth_std_deg"]))
    return initial_state(row, P0), noise


@dataclass
class Baseline:
    """KF baseline of one drive.

    Attributes
    ----------
    drive_name : str
    full : FilterResult
        GPS/INS over the whole drive (GNSS everywhere).
    errors : DataFrame
        ``metrics.navigation_errors`` of ``full``.
    rms : DataFrame
        ``metrics.rms_table`` of ``errors``.
    states : dict
        ``{"outage_1": FilterState, ...}`` at the outage starts.
    outage_errors : dict
        ``{"outage_1": DataFrame}``: errors of the standalone INS in each outage, then those of ``INS+NHC``
        (column ``method``).
    outage_table : DataFrame
        One row per outage and method (``INS``, then ``INS+NHC``): ``dataset``, ``outage``, ``method`` and
        ``metrics.outage_metrics``.
    noise : FilterNoise
    constraints : dict
        :meth:`bgfn.nav.constraints.Constraints.summary` of the ``INS+NHC`` runs' constraints.
    """

    drive_name: str
    full: FilterResult
    errors: pd.DataFrame
    rms: pd.DataFrame
    states: dict
    outage_errors: dict
    outage_table: pd.DataFrame
    noise: FilterNoise
    constraints: dict | None = None


def run_baseline(drive, cfg: dict, windows) -> Baseline:
    """Full-drive GPS/INS run, then the standalone INS in each outage from the saved state at its start, without
    and with the vehicle constraints (``INS``, ``INS+NHC``: :func:`outage_constraints`).

    Parameters
    ----------
    drive : bgfn.data.Drive
    cfg : dict
        Output of :func:`nav_config`.
    windows : sequence of (start, duration)
        The outages, s (:func:`bgfn.nav.outages.outage_windows`).

    Returns
    -------
    Baseline
    """
    windows = check_windows(windows, float(drive.reference["time"].iloc[0]),
                            float(drive.imu["time"].iloc[-1]), f"{drive.name}: profile outage_windows")
    initial, noise = filter_setup(drive, cfg)
    lever = drive.meta.get("lever_arm_m", [0.0, 0.0, 0.0])
    names = [f"outage_{i + 1}" for i in range(len(windows))]
    starts = epochs_before(drive.imu["time"], [w.start for w in windows], drive.name)
    full = run_filter(drive.imu, initial, noise, drive.gnss, lever, snapshots=dict(zip(names, starts)),
                      gate_probability=cfg["innovation_gate"], source=drive.name,
                      constraints=gps_constraints(drive, cfg, initial, noise))
    errors = metrics.navigation_errors(full.trajectory, drive.reference)
    aids = outage_constraints(drive, cfg, full.trajectory)
    rows, outage_errors = [], {}
    for n, w in zip(names, windows):
        parts = []
        for method, con in (("INS", None), (INS_NHC, aids)):
            res = run_outage(drive.imu, full.states[n], w, noise, lever, source=drive.name, constraints=con)
            e = metrics.navigation_errors(res.trajectory, drive.reference)
            e.insert(1, "t_rel", e["time"] - w.start)
            e.insert(0, "method", method)
            parts.append(e)
            rows.append({"dataset": drive.name, "outage": n, "method": method, **metrics.outage_metrics(e, w)})
        outage_errors[n] = pd.concat(parts, ignore_index=True)
    table = pd.DataFrame(rows).sort_values("method", key=lambda m: m != "INS", kind="stable").reset_index(drop=True)
    return Baseline(drive.name, full, errors, metrics.rms_table(errors), full.states, outage_errors, table, noise,
                    aids.summary())


def ins_layout(outage_table: pd.DataFrame, dataset: str | None = None) -> pd.DataFrame:
    """Standalone-INS max errors in the paper's layout (:func:`bgfn.paper.layout`, methods ``INS`` and, when the
    table has them, ``INS+NHC``).

    Parameters
    ----------
    outage_table : DataFrame
        ``Baseline.outage_table`` of one dataset (per method one row per outage, in order; no ``method``
        column: all ``INS``).
    dataset : str, optional
        When it stands for one of the paper's tests (:func:`bgfn.paper.test_of`), the paper's INS row is
        beside ours.

    Returns
    -------
    DataFrame
        Rows ``Outage k``; columns ``(source, method, East/North)``, m (the paper's side: ``INS`` only).
    """
    method = outage_table["method"] if "method" in outage_table.columns else pd.Series("INS", outage_table.index)
    parts = []
    for m in dict.fromkeys(method):
        rows = outage_table[method == m]
        parts.append(pd.DataFrame({"outage": np.arange(1, len(rows) + 1), "method": m,
                                   "max_east_m": rows["max_abs_east"].to_numpy(float),
                                   "max_north_m": rows["max_abs_north"].to_numpy(float)}))
    ours = pd.concat(parts, ignore_index=True)
    test = paper.test_of(dataset) if dataset else None
    return paper.layout(ours, paper.outage_table(test) if test else None, methods=tuple(dict.fromkeys(method)))


def ins_max_error_file(outage_table: pd.DataFrame) -> pd.DataFrame:
    """:func:`ins_layout` (ours) flattened for ``tables/kf_outage_max_errors_<d>.csv``: ``outage``
    (``Outage k``), ``INS_east_m``, ``INS_north_m`` and, with the constraints' rows, ``INS+NHC_east_m``,
    ``INS+NHC_north_m`` (m, 2 decimals)."""
    ours = ins_layout(outage_table)["ours"]
    methods = list(dict.fromkeys(ours.columns.get_level_values("method")))
    return pd.DataFrame({"outage": list(ours.index),
                         **{f"{m}_{axis.lower()}_m": ours[(m, axis)].round(2).to_numpy()
                            for m in methods for _, axis in paper.AXES}})


def save_baseline(b: Baseline, out, lat=None) -> dict:
    """Write one drive's baseline under ``out`` (``results/<profile>``) atomically.

    Files (``<d>`` = dataset name):

    - ``nav_states_<d>.npz``: the filter states at the outage starts (:func:`bgfn.nav.state.save_states`,
      names ``outage_1``, ``outage_2``, ...), the start of every outage run of notebook 04;
    - ``tables/kf_rms_<d>.csv``: RMS / max-abs errors of the full GPS/INS run;
    - ``tables/kf_outage_max_errors_<d>.csv``: :func:`ins_max_error_file`;
    - ``tables/kf_outage_metrics_<d>.csv``: all outage metrics;
    - ``tables/kf_outage_errors_<d>.csv``: standalone-INS error series (``outage``, ``method``, ``t_rel``,
      ``east``, ``north``, ``down``, ``horizontal``, m).

    Returns
    -------
    dict
        JSON-ready summary (RMS, outage metrics, mean NIS, the constraints' facts) for ``kf_baseline.json``.
    """
    from pathlib import Path

    from ..io import atomic_write_csv
    from .state import save_states

    out = Path(out)
    d = b.drive_name
    save_states(out / f"nav_states_{d}.npz", b.states)
    atomic_write_csv(out / "tables" / f"kf_rms_{d}.csv", b.rms.reset_index(), float_format="%.6g")
    atomic_write_csv(out / "tables" / f"kf_outage_max_errors_{d}.csv", ins_max_error_file(b.outage_table))
    atomic_write_csv(out / "tables" / f"kf_outage_metrics_{d}.csv", b.outage_table, float_format="%.6g")
    series = pd.concat([e.assign(outage=name)[["outage", "method", "t_rel", "east", "north", "down", "horizontal"]]
                        for name, e in b.outage_errors.items()], ignore_index=True)
    atomic_write_csv(out / "tables" / f"kf_outage_errors_{d}.csv", series, float_format="%.6g")
    upd = b.full.updates
    return {"rms": {k: float(v) for k, v in b.rms["rms"].items()},
            "outages": b.outage_table.drop(columns=["dataset"]).to_dict(orient="records"),
            "gnss_updates": int(len(upd)), "gnss_rejected": int((~upd["accepted"]).sum()) if len(upd) else 0,
            "mean_nis": float(upd["nis"].mean()) if len(upd) else None,
            "mean_nis_dof": float(upd["dof"].mean()) if len(upd) else None,
            "states_file": f"nav_states_{d}.npz", "constraints": b.constraints}


def gate_comparison(drive, cfg: dict, windows, probability: float, baseline: Baseline | None = None) -> pd.DataFrame:
    """The baseline of ``drive`` without and with an innovation gate on the GNSS fixes (notebook 02).

    Parameters
    ----------
    drive : bgfn.data.Drive
    cfg : dict
        Output of :func:`nav_config`; its ``innovation_gate`` is replaced by None and by ``probability``.
    windows : sequence of (start, duration)
        The outages, s (as for :func:`run_baseline`).
    probability : float
        Chi-square probability of the gate (:func:`bgfn.nav.filter.gate_thresholds`).
    baseline : Baseline, optional
        The run with ``cfg`` as it is (notebook 02 has it already): reused for the setting it matches.

    Returns
    -------
    DataFrame
        One row per setting (``innovation_gate``: ``none`` or the probability): ``gnss_rejected`` (fixes not
        fused), ``mean_nis``, the full-drive horizontal ``rms_h_m`` and ``max_h_m`` against the reference, and
        the standalone INS's ``max_east_m`` / ``max_north_m`` in each outage ``k`` (``outage_k_...``), which
        start from the filter's state.
    """
    rows = []
    for gate in (None, probability):
        same = baseline is not None and gate == cfg["innovation_gate"]
        b = baseline if same else run_baseline(drive, {**cfg, "innovation_gate": gate}, windows)
        upd = b.full.updates
        row = {"dataset": drive.name, "innovation_gate": "none" if gate is None else f"{gate:g}",
               "gnss_fixes": int(len(upd)), "gnss_rejected": int((~upd["accepted"]).sum()),
               "mean_nis": float(upd["nis"].mean()) if len(upd) else float("nan"),
               "rms_h_m": float(b.rms.loc["horizontal", "rms"]), "max_h_m": float(b.rms.loc["horizontal", "max_abs"])}
        for k, r in enumerate(b.outage_table[b.outage_table["method"] == "INS"].itertuples(index=False)):
            row[f"outage_{k + 1}_max_east_m"] = float(r.max_abs_east)
            row[f"outage_{k + 1}_max_north_m"] = float(r.max_abs_north)
        rows.append(row)
    return pd.DataFrame(rows)

"""The fleet study end to end (notebook 11): drives made comparable, the protocol's splits, per test drive the
odometer table's rows and honest speed series, the coverage flags and the learning curve, then the tables."""

from __future__ import annotations

import time
from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from bgfn.errors import DataError
from bgfn.io import atomic_write_csv
from bgfn.parallel import Runner
from bgfn.studies.fleet import coverage as cv
from bgfn.studies.fleet import protocol as fp
from bgfn.studies.fleet.drives import fleet_drives, prepare_fleet, preparation_table
from bgfn.studies.fleet.summary import fleet_summary, offset_table
from bgfn.studies.odometer import bars

#: Columns of ``tables/fleet_splits.csv``: each test drive, its training drives, the ridge's numbers.
SPLIT_COLUMNS: tuple[str, ...] = ("test_drive", "train_drives", "train_min", "n_train_windows", "ridge_std_mps",
                                  "ridge_correlation", "outages", "out_of_range_outages")


@dataclass
class FleetResult:
    """The fleet study's tables (each module's columns) and facts."""

    preparation: pd.DataFrame
    splits: pd.DataFrame
    rows: pd.DataFrame
    summary: pd.DataFrame
    offsets: pd.DataFrame
    motion: pd.DataFrame
    flags: pd.DataFrame
    curve: pd.DataFrame
    facts: dict = field(default_factory=dict)


def fleet_enabled(cfg: dict) -> bool:
    """Whether the profile names a fleet (``fleet.drives`` not empty)."""
    return bool((cfg.get("fleet") or {}).get("drives"))


def check_fleet(cfg: dict) -> None:
    """The fleet's settings that must agree with the rest of the profile, checked before any heavy work."""
    fleet, sw = cfg["fleet"], cfg["evaluate"]["sweep"]
    if fleet["curve"] and float(fleet["curve_duration_s"]) > max(map(float, sw["durations_s"])):
        raise DataError("fleet", "curve_duration_s", f"at most the sweep's longest duration "
                        f"({max(map(float, sw['durations_s'])):g} s)", f"{fleet['curve_duration_s']:g}")
    if fleet["protocol"] == "named" and not (fleet["train"] and fleet["test"]):
        raise DataError("fleet", "train/test", "both lists with protocol: named", "an empty list")


def run_fleet(cfg: dict, profile: str, runner: Runner | None = None, drives=None,
              report=None) -> FleetResult:
    """The fleet study of a profile (module docstring); ``drives``: the fleet's Drive objects instead of
    ``fleet.drives`` (tests)."""
    t0 = time.perf_counter()
    fleet, ecfg = cfg["fleet"], cfg["evaluate"]
    oc = ecfg["odometer"]
    check_fleet(cfg)
    prepared = prepare_fleet(drives if drives is not None else fleet_drives(fleet, profile), fleet)
    by_name = {p.name: p for p in prepared}
    splits = fp.fleet_splits(list(by_name), fleet)
    params = fp.learning_params(cfg)
    rows, flags, curves, series, split_rows = [], [], [], {}, []
    for i, (test_name, train) in enumerate(splits):
        data = fp.pooled_speed_data([by_name[n] for n in train], params)
        model = fp.fit_ridge(data, by_name[test_name].rate_hz, params)
        test = fp.TestDrive(cfg, by_name[test_name], params)
        learned = {(bars.RIDGE, 0): fp.ridge_track(model, test.windows, params)}
        if fleet["networks"]:
            learned.update(fp.network_tracks(cfg, profile, f"fleet-test{i + 1}", data, test, runner))
        runs, tracks = fp.test_runs(test, learned, oc)
        rows.append(fp.run_rows(test, runs, tracks, ecfg["pseudo_gps"], runner))
        held = fp.held_track(test.windows.t_end, test.starts, test.dmax, test.start_speed, float(oc["hold_std_mps"]))
        first = {label: track for (label, seed), track in learned.items()
                 if seed == min(s for (m, s) in learned if m == label)}
        series[test_name] = fp.speed_series(test.windows.t_end, test.truth, test.outages,
                                            {**first, bars.HOLD: held})
        lo_v, hi_v = cv.speed_range([by_name[n] for n in train])
        lo_w, hi_w = cv.turn_range([by_name[n] for n in train], params["window_s"])
        f = cv.outage_flags(test_name, test.windows.t_end, test.truth, test.starts, test.durations, lo_v, hi_v,
                            float(fleet["out_of_range_share"]),
                            cv.turn_rate_at(by_name[test_name], test.windows.t_end, params["window_s"]), lo_w, hi_w)
        flags.append(f)
        if fleet["curve"]:
            curves.append(fp.curve_rows(cfg, profile, f"fleet-test{i + 1}", test, by_name, train, params, runner,
                                        full=learned))
        longest = f[f["duration_s"] == test.dmax]
        split_rows.append({"test_drive": test_name, "train_drives": "; ".join(train),
                           "train_min": fp.training_minutes(data, params["aid_rate_hz"]),
                           "n_train_windows": len(data.train), "ridge_std_mps": model.std_mps,
                           "ridge_correlation": model.correlation, "outages": len(test.starts),
                           "out_of_range_outages": int(longest["out_of_range"].sum())})
        if report is not None:
            report(f"{test_name}: {len(rows[-1])} rows, trained on {len(train)} drives")
    rows_all = pd.concat(rows, ignore_index=True)
    flags_all = pd.concat(flags, ignore_index=True)
    durations = sorted({float(d) for d in ecfg["sweep"]["durations_s"]})
    return FleetResult(
        preparation=preparation_table(prepared),
        splits=pd.DataFrame(split_rows, columns=list(SPLIT_COLUMNS)),
        rows=rows_all, summary=fleet_summary(rows_all, flags_all),
        offsets=offset_table(series, durations, flags_all, params["max_lag_s"]),
        motion=cv.motion_table(splits, by_name, params["window_s"]), flags=flags_all,
        curve=pd.concat(curves, ignore_index=True) if curves else pd.DataFrame(columns=list(fp.CURVE_COLUMNS)),
        facts={"wall_s": time.perf_counter() - t0, "pieces": fleet.get("pieces"), "protocol": fleet["protocol"],
               "rate_hz": float(np.unique([p.rate_hz for p in prepared])[0]), "networks": bool(fleet["networks"]),
               "inputs": fp.network_inputs(cfg) if fleet["networks"] else {}})


#: ``results/<profile>/tables/`` file of each table of a :class:`FleetResult`.
FLEET_TABLES = {"preparation": "fleet_preparation.csv", "splits": "fleet_splits.csv", "rows": "fleet_odometer.csv",
                "summary": "fleet_summary.csv", "offsets": "fleet_offsets.csv", "motion": "fleet_motion.csv",
                "flags": "fleet_coverage.csv", "curve": "fleet_curve.csv"}


def write_fleet_tables(result: FleetResult, out) -> list:
    """Every table of ``result`` under ``out / "tables"`` (:data:`FLEET_TABLES`); the paths written."""
    paths = []
    for key, name in FLEET_TABLES.items():
        paths.append(out / "tables" / name)
        atomic_write_csv(paths[-1], getattr(result, key))
    return paths

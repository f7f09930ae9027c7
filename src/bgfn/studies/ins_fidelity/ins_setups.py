"""Is the INS row comparable? The standalone INS in the outages under each filter setup, beside the paper's.

The paper's INS row (its data come from NaveGo) is larger than ours. The INS of an outage starts from the
GPS-aided filter's state, so its drift depends on how that filter modelled the IMU biases. :func:`ins_tuning_table`
runs :func:`bgfn.nav.baseline.run_baseline` once per setup of ``nav.ins_tuning`` (``shipped``, ``navego``:
:mod:`bgfn.nav.navego_setup`), adds ``navego-reset`` (each outage's bias estimates cleared: a bound), NaveGo v1.4
itself run under Octave as released and with its bias feedback made consistent (``make navego-check``,
``data/measured/navego_check.csv``), and the paper's row where a dataset stands for one of its tests. The table
(:data:`COLUMNS`, ``tables/kf_ins_tuning.csv``) gives per outage and setup the max east/north error, the GPS-aided
run's horizontal RMS and the largest bias estimates beside the true ones (a simulated IMU's).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from bgfn import paper
from bgfn.config import PROJECT_ROOT, SHARED_TABLES
from bgfn.io import atomic_write_csv
from bgfn.nav import metrics, navego_setup
from bgfn.nav.baseline import Baseline, filter_imu, nav_config, run_baseline
from bgfn.nav.filter import run_outage
from bgfn.nav.outages import check_windows

#: Setup of the INS row with the bias estimates cleared at the outage start (a bound: no accumulated bias estimate).
RESET = "navego-reset"
#: Label of the paper's row.
PAPER = "paper"
#: Label of NaveGo v1.4 itself, run under GNU Octave on the same drive and outages (``make navego-check``).
NAVEGO_RUN = "NaveGo (Octave)"
#: Label of NaveGo v1.4 with its bias feedback made consistent (``make navego-check``'s diagnostic run).
NAVEGO_CONSISTENT = "NaveGo, bias feedback consistent (Octave)"
#: ``variant`` of ``data/measured/navego_check.csv`` -> the table's setup label (``tools/navego_check.py``'s VARIANTS).
RELEASED, CONSISTENT = "as released", "bias feedback consistent"
NAVEGO_VARIANTS: dict[str, str] = {RELEASED: NAVEGO_RUN, CONSISTENT: NAVEGO_CONSISTENT}
#: Row order of the table: our setups, NaveGo's own runs, then the paper's.
SETUPS: tuple[str, ...] = navego_setup.INS_TUNINGS + (RESET, NAVEGO_RUN, NAVEGO_CONSISTENT, PAPER)
#: What ``tools/navego_check.py`` measured (NaveGo's INS-only errors in the outages), with date and commit.
NAVEGO_CHECK_FILE = PROJECT_ROOT / "data" / "measured" / "navego_check.csv"
#: Its columns.
NAVEGO_CHECK_COLUMNS: tuple[str, ...] = ("dataset", "outage", "start_s", "duration_s", "max_east_m", "max_north_m",
                                         "aided_rms_h_m", "max_gyro_bias_est_dps", "max_accel_bias_est_mps2",
                                         "setting", "navego", "variant", "octave", "date", "commit")


def navego_measured(dataset: str, windows, path: Path = NAVEGO_CHECK_FILE,
                    variant: str = RELEASED) -> pd.DataFrame:
    """NaveGo's own rows of ``dataset`` and ``variant`` (a key of :data:`NAVEGO_VARIANTS`; a file without the
    column holds the released one only) from ``path`` whose outage matches one of ``windows`` (same start and
    duration; the profile's ``Outage k`` numbering); empty when the check has not run for them."""
    if not Path(path).is_file():
        return pd.DataFrame(columns=list(NAVEGO_CHECK_COLUMNS))
    t = pd.read_csv(path)
    variants = t["variant"] if "variant" in t.columns else pd.Series(RELEASED, index=t.index)
    t = t[(t["dataset"] == dataset) & (variants == variant)]
    rows = []
    for k, (s, d) in enumerate(windows, 1):
        hit = t[np.isclose(t["start_s"], s) & np.isclose(t["duration_s"], d)]
        if len(hit):
            rows.append(hit.iloc[0].to_dict() | {"outage": k})
    return pd.DataFrame(rows, columns=list(NAVEGO_CHECK_COLUMNS))
#: Columns of :func:`ins_tuning_table`.
COLUMNS: tuple[str, ...] = ("dataset", "test", "outage", "setup", "max_east_m", "max_north_m", "aided_rms_h_m",
                            "max_gyro_bias_est_dps", "true_gyro_bias_dps", "max_accel_bias_est_mps2",
                            "true_accel_bias_mps2")
_NAN = float("nan")


def _row(dataset, test, outage, setup, east, north, aided=_NAN, gyro=_NAN, true=_NAN, accel=_NAN,
         true_accel=_NAN) -> dict:
    return dict(zip(COLUMNS, (dataset, test or "", int(outage), setup, float(east), float(north), float(aided),
                              float(gyro), float(true), float(accel), float(true_accel))))


def _max_bias(bias: pd.DataFrame | None, sensor: str) -> float:
    """The largest absolute ``sensor`` ('gyro', deg/s; 'accel', m/s^2) bias of a bias table (estimates or truth)
    over the drive."""
    cols = [f"{sensor}_bias_{a}" for a in "xyz"]
    if bias is None or not set(cols) <= set(bias.columns):
        return float("nan")
    top = float(np.nanmax(np.abs(bias[cols].to_numpy(float))))
    return float(np.degrees(top)) if sensor == "gyro" else top


def ins_tuning_table(drive, cfg: dict, windows, baseline: Baseline | None = None) -> pd.DataFrame:
    """The standalone-INS max errors of ``drive`` in each outage under every setup (module docstring).

    Parameters
    ----------
    drive : bgfn.data.Drive
    cfg : dict
        Output of :func:`bgfn.nav.baseline.nav_config`; its ``ins_tuning`` is replaced by each setup.
    windows : sequence of (start, duration)
        The outages, s (:func:`bgfn.nav.outages.outage_windows`).
    baseline : Baseline, optional
        The run with ``cfg`` as it is (notebook 08 has it already): reused for the setup it matches.

    Returns
    -------
    DataFrame
        :data:`COLUMNS`, rows in :data:`SETUPS` order, then by outage.
    """
    test = paper.test_of(drive.name)
    checked = check_windows(windows, float(drive.reference["time"].iloc[0]), float(drive.imu["time"].iloc[-1]),
                            f"{drive.name}: profile outage_windows", sort=False)      # Outage k as in notebook 08
    lever = drive.meta.get("lever_arm_m", [0.0, 0.0, 0.0])
    true = _max_bias(drive.imu_bias, "gyro")            # NaN for a recorded IMU (its biases are unknown)
    true_accel = _max_bias(drive.imu_bias, "accel")
    rows = []
    for tuning in navego_setup.INS_TUNINGS:
        c = {**cfg, "ins_tuning": tuning}
        same = baseline is not None and tuning == cfg["ins_tuning"]
        b = baseline if same else run_baseline(drive, c, windows, keep=False)   # another setup: read once
        ins = b.outage_table
        if "method" in ins.columns:                   # the standalone INS only (not the INS+NHC rows)
            ins = ins[ins["method"] == "INS"]
        aided, gyro, accel = (float(b.rms.loc["horizontal", "rms"]), _max_bias(b.full.bias, "gyro"),
                              _max_bias(b.full.bias, "accel"))
        for k, r in enumerate(ins.itertuples(index=False)):
            rows.append(_row(drive.name, test, k + 1, tuning, r.max_abs_east, r.max_abs_north, aided, gyro, true,
                             accel, true_accel))
        if tuning != "navego":
            continue
        imu = filter_imu(drive, c)
        for k, w in enumerate(checked):
            s = b.states[f"outage_{k + 1}"].copy()
            s.gyro_bias[:] = 0.0      # a bound: no accumulated bias estimate (a later ins_gnss.m, Version 012)
            s.accel_bias[:] = 0.0
            e = metrics.navigation_errors(run_outage(imu, s, w, b.noise, lever, source=drive.name).trajectory,
                                          drive.reference, drive.meta)
            m = metrics.outage_metrics(e, w)
            rows.append(_row(drive.name, test, k + 1, RESET, m["max_abs_east"], m["max_abs_north"]))
    for variant, setup in NAVEGO_VARIANTS.items():
        for r in navego_measured(drive.name, [(w.start, w.duration) for w in checked],
                                 variant=variant).itertuples(index=False):
            rows.append(_row(drive.name, test, r.outage, setup, r.max_east_m, r.max_north_m, r.aided_rms_h_m,
                             getattr(r, "max_gyro_bias_est_dps", _NAN), true,
                             getattr(r, "max_accel_bias_est_mps2", _NAN), true_accel))
    if test:
        for r in paper.published_values(test).query("method == 'INS'").itertuples(index=False):
            rows.append(_row(drive.name, test, r.outage, PAPER, r.max_east_m, r.max_north_m))
    return pd.DataFrame(rows, columns=list(COLUMNS))


def ins_tuning_tables(drives, nav_section: dict | None, windows, baselines: dict | None = None) -> pd.DataFrame:
    """:func:`ins_tuning_table` of several drives, one table (notebooks 02 and 04).

    Parameters
    ----------
    drives : iterable of bgfn.data.Drive
    nav_section : dict or None
        A profile's ``nav:`` section (:func:`bgfn.nav.baseline.nav_config` fills and checks it).
    windows : sequence of (start, duration), or dict
        The outages, s; or ``{drive name: outages}`` (each drive its own, :func:`bgfn.nav.outages.outage_windows`).
    baselines : dict, optional
        ``{drive name: Baseline}`` run with ``nav_section`` as it is, reused.
    """
    cfg = nav_config(nav_section)
    return pd.concat([ins_tuning_table(d, cfg, windows[d.name] if isinstance(windows, dict) else windows,
                                       (baselines or {}).get(d.name)) for d in drives], ignore_index=True)


def layouts(table: pd.DataFrame) -> pd.DataFrame:
    """:func:`layout` of every dataset of ``table``, stacked (outer row level: the dataset)."""
    return pd.concat({d: layout(table, d) for d in dict.fromkeys(table["dataset"])}, names=["dataset"])


def layout(table: pd.DataFrame, dataset: str) -> pd.DataFrame:
    """One dataset of :func:`ins_tuning_table` in the paper's layout.

    Returns
    -------
    DataFrame
        Rows ``Outage k``; columns ``(setup, East/North)`` in :data:`SETUPS` order, m (NaN where a setup has
        no value for an outage).
    """
    t = table[table["dataset"] == dataset]
    outages = sorted({int(o) for o in t["outage"]})
    setups = [s for s in SETUPS if s in set(t["setup"])]
    data = {}
    for s in setups:
        ts = t[t["setup"] == s].set_index("outage")
        for col, axis in paper.AXES:
            data[(s, axis)] = [float(ts.loc[o, col]) if o in ts.index else np.nan for o in outages]
    return pd.DataFrame(data, index=pd.Index([f"Outage {o}" for o in outages], name="Max Position Error (m)"),
                        columns=pd.MultiIndex.from_tuples(list(data), names=["setup", "axis"]))


#: Columns of a setup's GPS-aided run (one value per drive) and of the drive's truth, carried by :func:`gap_explained`.
_RUN_COLUMNS = ("aided_rms_h_m", "max_gyro_bias_est_dps", "max_accel_bias_est_mps2")
TRUE_COLUMNS = ("true_gyro_bias_dps", "true_accel_bias_mps2")


def gap_explained(table: pd.DataFrame) -> pd.DataFrame:
    """How much of the gap between our INS row and the paper's each setup closes, per dataset.

    The size of a row is the mean of its max east and north errors over the outages the paper also has (m).
    ``explained_pct`` of a setup is ``100 (setup - shipped) / (paper - shipped)``: 0 when it changes nothing,
    100 when it reaches the paper's row, negative when it moves away from it.

    Returns
    -------
    DataFrame
        One row per dataset with a paper test and per setup other than ``shipped``: ``dataset``, ``test``,
        ``setup``, ``shipped_m``, ``setup_m``, ``paper_m``, ``explained_pct`` (NaN when there is no gap),
        ``aided_rms_h_m`` (the setup's GPS-aided horizontal RMS, m; NaN where the table has none),
        ``max_gyro_bias_est_dps`` (its largest gyro-bias estimate over the drive, deg/s), ``max_accel_bias_est_mps2``
        (the same for the accelerometers, m/s^2), ``true_gyro_bias_dps``, ``true_accel_bias_mps2`` (the drive's
        largest true biases; NaN for a recorded IMU).
    """
    rows = []
    for dataset, t in table.groupby("dataset", sort=False):
        on = set(t.loc[t["setup"] == PAPER, "outage"])
        if not on:
            continue
        t = t[t["outage"].isin(on)]
        size = {s: float(g[["max_east_m", "max_north_m"]].to_numpy().mean()) for s, g in t.groupby("setup")}
        # per setup: its run's values (one per drive, repeated on every outage row); the truth: the drive's
        per_setup = {c: {s: float(g[c].iloc[0]) for s, g in t.groupby("setup")} for c in _RUN_COLUMNS if c in t.columns}
        truth = {c: float(t[c].iloc[0]) if c in t.columns else _NAN for c in TRUE_COLUMNS}
        gap = size[PAPER] - size["shipped"]
        for s in SETUPS:
            if s in ("shipped", PAPER) or s not in size:
                continue
            pct = 100.0 * (size[s] - size["shipped"]) / gap if abs(gap) > 1e-9 else float("nan")
            rows.append({"dataset": dataset, "test": t["test"].iloc[0], "setup": s, "shipped_m": size["shipped"],
                         "setup_m": size[s], "paper_m": size[PAPER], "explained_pct": pct,
                         **{c: per_setup.get(c, {}).get(s, _NAN) for c in _RUN_COLUMNS}, **truth})
    return pd.DataFrame(rows, columns=["dataset", "test", "setup", "shipped_m", "setup_m", "paper_m",
                                       "explained_pct", *_RUN_COLUMNS, *TRUE_COLUMNS])


#: How far our ``navego`` setup's INS error may lie from NaveGo's own, as a ratio.
NAVEGO_TOLERANCE = 0.3


def save_table(out, table: pd.DataFrame) -> Path:
    """Write :func:`ins_tuning_table` (all datasets) to ``<out>/tables/kf_ins_tuning.csv`` atomically."""
    return atomic_write_csv(Path(out) / "tables" / SHARED_TABLES["kf_ins_tuning"], table, float_format="%.6g")


def read_table(out) -> pd.DataFrame | None:
    """The table :func:`save_table` wrote under ``out`` (``results/<profile>``), or None when it is missing."""
    path = Path(out) / "tables" / SHARED_TABLES["kf_ins_tuning"]
    return pd.read_csv(path) if path.exists() else None


__all__ = ["COLUMNS", "NAVEGO_CHECK_COLUMNS", "NAVEGO_CHECK_FILE", "NAVEGO_CONSISTENT", "NAVEGO_RUN", "NAVEGO_VARIANTS", "PAPER", "RESET", "SETUPS",
           "navego_measured", "gap_explained", "ins_tuning_table", "ins_tuning_tables", "layout",
           "layouts", "read_table", "save_table", "TRUE_COLUMNS"]

"""A user's own drive: a folder with ``imu.csv``, ``gnss.csv``, ``reference.csv`` and optional ``meta.yaml``.

Schema (``data/README.md``; CONTRIBUTING.md tables; SI units, rad, GPS time of week or any common time
base in s, body frame x forward / y right / z down, NED):

- ``imu.csv``: ``time, gyro_x, gyro_y, gyro_z`` (rad/s), ``accel_x, accel_y, accel_z`` (m/s^2); row k =
  mean rates over ``(time[k-1], time[k]]``. The times may jitter; a gap of more than a few samples is an error.
- ``gnss.csv``: ``time, lat, lon`` (rad), ``h`` (m), ``std_n, std_e, std_d`` (m); optional
  ``v_n, v_e, v_d`` (m/s; empty/NaN when not given).
- ``reference.csv``: ``time, lat, lon, h, v_n, v_e, v_d`` at its own rate; optional ``roll, pitch, yaw``
  (all three or none; absent: NaN columns, a drive without reference attitude, ``Drive.has_attitude``).
- ``meta.yaml`` (optional; :mod:`bgfn.data.csv_meta`): ``name``, ``lever_arm_m``, ``source``, ``imu_errors``
  (default: the consumer-MEMS profile :data:`bgfn.data.imu_errors.MPU6000`).

Loading (:func:`load_csv_drive`): the raw tables first pass the plausibility checks of
:mod:`bgfn.data.physics` (accelerations in g, rates in deg/s, unrotated axes, lat/lon in degrees, times in ms:
each a DataError naming the CSV file and column), then go onto one regular grid (:mod:`bgfn.data.regrid`): the
IMU resampled by integrating its increments when its steps jitter, the reference interpolated at the IMU epochs
(position by cubic Hermite segments with the reference's velocities as slopes, velocities and attitude linearly,
yaw unwrapped), the GNSS stamps onto their nominal grid when they jitter (:func:`bgfn.data.regrid.regular_fix_times`),
after the clocks that ``meta.yaml`` states and the GNSS-IMU offset estimated from the data (:mod:`bgfn.data.time_offset`)
are checked. Extra columns are ignored; any defect raises :class:`bgfn.errors.DataError` naming the file and
column.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from bgfn.data.csv_meta import META_FILE, read_meta
from bgfn.data.drive import Drive
from bgfn.data.gnss import imu_position
from bgfn.data.imu_errors import OPTIONAL_VECTOR_KEYS, SCALAR_KEYS, VECTOR_KEYS
from bgfn.data.names import safe_id
from bgfn.data.navego import check_time
from bgfn.data.physics import check_drive
from bgfn.data.regrid import check_gaps, imu_on_grid, interpolate_reference, median_rate_hz, regular_fix_times
from bgfn.data.reference_check import along_rms, check_reference, reference_equals_gnss, reference_lag
from bgfn.data.time_offset import TOLERANCE_S, decide_clock, estimate_gnss_offset
from bgfn.errors import DataError
from bgfn.io import atomic_write_csv, atomic_write_text
from bgfn.nav.transform import dcm_from_euler
from bgfn.schema import ACCEL_COLUMNS, GNSS_COLUMNS, GNSS_FIX_COLUMNS, GYRO_COLUMNS, IMU_COLUMNS, REFERENCE_COLUMNS

#: Reference attitude columns: all three or none.
ATTITUDE_COLUMNS: tuple[str, ...] = ("roll", "pitch", "yaw")
#: Files of a CSV drive and their required columns.
CSV_FILES = {
    "imu.csv": IMU_COLUMNS,
    "gnss.csv": tuple(c for c in GNSS_FIX_COLUMNS if not c.startswith("std_")),   # the std: file or meta.yaml
    "reference.csv": tuple(c for c in REFERENCE_COLUMNS if c not in ATTITUDE_COLUMNS),
}
_OPTIONAL = {"gnss.csv": ("std_n", "std_e", "std_d", "v_n", "v_e", "v_d"), "reference.csv": ATTITUDE_COLUMNS}
#: Table of the drive each file holds.
TABLE_OF = {"imu.csv": "imu", "gnss.csv": "gnss", "reference.csv": "reference"}


def read_table(path: Path, required: tuple[str, ...], optional: tuple[str, ...] = ()) -> pd.DataFrame:
    """Read one CSV table, check its columns, finite values and strictly increasing ``time``.

    Parameters
    ----------
    path : Path
        CSV file.
    required : tuple of str
        Columns that must be present and finite.
    optional : tuple of str
        Columns added as NaN when absent (may hold NaN).

    Returns
    -------
    DataFrame
        Columns ``required`` then ``optional`` in schema order, float64.
    """
    if not path.is_file():
        raise DataError(path, "file", f"a CSV file with columns {', '.join(required)}", "no such file")
    try:
        df = pd.read_csv(path, comment="#", skipinitialspace=True)
    except (pd.errors.ParserError, pd.errors.EmptyDataError, UnicodeDecodeError) as exc:
        raise DataError(path, "file", "a readable CSV table with a header row", str(exc)) from None
    df.columns = [str(c).strip() for c in df.columns]
    missing = [c for c in required if c not in df.columns]
    if missing:
        raise DataError(path, missing[0], f"columns {', '.join(required)}", f"missing {', '.join(missing)}"
                        f" (header: {', '.join(df.columns)})")
    out = {}
    for c in required + optional:
        if c not in df.columns:
            out[c] = np.full(len(df), np.nan)
            continue
        vals = pd.to_numeric(df[c], errors="coerce").to_numpy(float)
        if c in required:
            bad = ~np.isfinite(vals)
            if bad.any():
                k = int(np.argmax(bad))
                raise DataError(path, c, "finite numbers", f"{int(bad.sum())} empty/non-numeric/NaN values, "
                                f"first in data row {k + 1} ({df[c].iloc[k]!r})")
        out[c] = vals
    if len(df) < 2:
        raise DataError(path, "time", "at least 2 rows", f"{len(df)}")
    check_time(path, "time", out["time"])
    schema = [c for c in REFERENCE_COLUMNS + IMU_COLUMNS + GNSS_COLUMNS if c in out]
    order = list(dict.fromkeys(schema))
    return pd.DataFrame({c: out[c] for c in order})


def _check_attitude(path: Path, header: list[str], ref: pd.DataFrame) -> None:
    """All three attitude columns or none; present ones finite."""
    given = [c for c in ATTITUDE_COLUMNS if c in header]
    if given and len(given) < len(ATTITUDE_COLUMNS):
        absent = [c for c in ATTITUDE_COLUMNS if c not in given]
        raise DataError(path, absent[0], "all of roll, pitch, yaw (rad) or none of them (a drive without "
                        "reference attitude)", f"{', '.join(given)} without {', '.join(absent)}")
    for c in given:
        bad = ~np.isfinite(ref[c].to_numpy(float))
        if bad.any():
            k = int(np.argmax(bad))
            raise DataError(path, c, "finite numbers", f"{int(bad.sum())} empty/non-numeric/NaN values, first in "
                            f"data row {k + 1}")


def _gnss_std(gnss: pd.DataFrame, path: Path, header: list[str], default, meta_path: Path) -> pd.DataFrame:
    """The fixes with their std: the file's ``std_n, std_e, std_d`` (all three, positive), else ``meta.yaml``'s
    ``gnss_std_m`` for every fix; one error naming both when neither is given."""
    cols = ["std_n", "std_e", "std_d"]
    given = [c for c in cols if c in header]
    if not given:
        if default is None:
            raise DataError(path, "std_n/std_e/std_d", f"the fixes' std columns, or gnss_std_m [north, east, down] "
                            f"in {meta_path} for a receiver that reports no accuracy", "neither")
        return gnss.assign(**{c: float(v) for c, v in zip(cols, default)})
    if len(given) < 3:
        raise DataError(path, [c for c in cols if c not in given][0], "all of std_n, std_e, std_d or none",
                        f"{', '.join(given)} only")
    std = gnss[cols].to_numpy(float)
    if not np.isfinite(std).all() or (std <= 0).any():
        raise DataError(path, "std_n/std_e/std_d", "positive position std, m", f"min {np.nanmin(std)}, "
                        f"{int((~np.isfinite(std)).sum())} empty")
    return gnss


def _on_imu_clock(imu: pd.DataFrame, gnss: pd.DataFrame, reference: pd.DataFrame, lever_arm_m, auto: bool,
                  files: dict, meta_path: Path) -> tuple:
    """The fixes (already shifted by a stated latency) on the IMU's clock: the offset the turn rates show
    (:func:`bgfn.data.time_offset.estimate_gnss_offset`) checked against the reference's lag
    (:func:`bgfn.data.reference_check.reference_lag`) and taken off only when ``auto`` and the rule of
    :func:`bgfn.data.time_offset.decide_clock` holds; one error naming both files when an offset beyond
    :data:`~bgfn.data.time_offset.TOLERANCE_S` is left. A reference that is the GNSS itself says nothing of the clock.
    Returns the fixes and the facts (``meta["gnss_offset"]``: :meth:`~bgfn.data.time_offset.ClockDecision.record`
    and ``applied_latency_s``; worded by :func:`bgfn.report.data_checks.clock_offset_line`)."""
    est = estimate_gnss_offset(imu, gnss)
    lag = None if reference_equals_gnss(reference, gnss, lever_arm_m) else \
        reference_lag(reference, gnss, lever_arm_m)
    decision = decide_clock(est, lag, auto, lambda shift: along_rms(reference, gnss, lever_arm_m, shift))
    if np.isfinite(decision.gross_s):
        leap = " -- GNSS in UTC against an IMU in GPS time (18 s apart)?" if abs(abs(decision.gross_s) - 18.0) < 1.5 \
            else ""
        how = ("the fixes' along-track offsets against reference.csv follow the speed" if decision.gross_method ==
               "reference" else f"the turn rates of both correlate {est.correlation:.2f} at that lag")
        raise DataError(files["gnss"], "time", f"fixes on the clock of {files['imu']} within {TOLERANCE_S:g} s "
                        f"(a known delay: gnss_latency_s or imu_time_offset_s in {meta_path})",
                        f"stamps {decision.gross_s:+.2f} s late ({how}){leap}")
    gnss = gnss.assign(time=gnss["time"] - decision.applied_s)
    return gnss, {**decision.record(), "applied_latency_s": decision.applied_s}


def rotate_imu(imu: pd.DataFrame, mounting_deg) -> pd.DataFrame:
    """The IMU rows in the body frame: ``x_b = C x_s`` for the rates and specific forces, ``C`` the rotation of the
    IMU's axes in the body frame by ``mounting_deg`` = [roll, pitch, yaw] (deg, ZYX as the attitude); unchanged
    for zeros."""
    if not np.any(mounting_deg):
        return imu
    c = dcm_from_euler(*np.radians(np.asarray(mounting_deg, float))).reshape(3, 3)     # sensor -> body
    out = imu.copy()
    for cols in (list(GYRO_COLUMNS), list(ACCEL_COLUMNS)):
        out[cols] = imu[cols].to_numpy(float) @ c.T
    return out


def _header(path: Path) -> list[str]:
    return [str(c).strip() for c in pd.read_csv(path, comment="#", skipinitialspace=True, nrows=0).columns]


def load_csv_drive(folder: str | Path, *, imu_rate_hz: float | None = None, t_start: float | None = None,
                   t_end: float | None = None, reference_tolerance_m: float | None = None) -> Drive:
    """Load a drive from a folder in the CSV schema of the module docstring.

    Parameters
    ----------
    folder : str or Path
        Folder holding ``imu.csv``, ``gnss.csv``, ``reference.csv`` (and optionally ``meta.yaml``).
    imu_rate_hz : float, optional
        Rate of the IMU grid, Hz (resampled by integrating the increments,
        :func:`bgfn.data.navego.resample_imu`); default: the log's median rate (a regular log is kept as is).
    t_start, t_end : float, optional
        Keep only this span, s (on the files' time base).
    reference_tolerance_m : float, optional
        The profile's ``data.reference_tolerance_m`` (:func:`bgfn.data.reference_check.check_reference`).

    Returns
    -------
    Drive
        Named by ``meta.yaml``'s ``name``, else by the folder (:func:`bgfn.data.names.dataset_id`); the
        reference at the IMU epochs; ``meta``: ``imu_rate_hz``, ``native_imu_rate_hz``, ``imu_resampled``,
        ``reference_rate_hz``, ``reference_interpolated``, ``gnss_rate_hz`` (from the median intervals),
        ``lever_arm_m``, ``imu_errors``, ``imu_errors_source``, ``source``, ``params``.

    Raises
    ------
    DataError
        Naming the file and the column (or ``meta.yaml`` and the key).
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise DataError(folder, "folder", "a folder with imu.csv, gnss.csv, reference.csv", "no such folder")
    files = {TABLE_OF[name]: folder / name for name in CSV_FILES}
    meta_path = folder / META_FILE
    user = read_meta(meta_path)            # first: its keys say how to read the tables
    raw = {TABLE_OF[name]: read_table(folder / name, cols, _OPTIONAL.get(name, ())) for name, cols in CSV_FILES.items()}
    _check_attitude(files["reference"], _header(files["reference"]), raw["reference"])
    gnss = _gnss_std(raw["gnss"], files["gnss"], _header(files["gnss"]), user["gnss_std_m"], meta_path)
    # the clocks and the mounting that meta.yaml states, before the checks that would blame them on the data
    raw["imu"] = rotate_imu(raw["imu"], user["imu_mounting_deg"]).assign(
        time=lambda t: t["time"] + user["imu_time_offset_s"])
    latency = user["gnss_latency_s"]
    gnss = gnss.assign(time=gnss["time"] - (0.0 if latency == "auto" else latency))
    # units and axes on the files' own rows, so that each message names the CSV file, column and data row
    check_drive(Drive(str(folder), raw["reference"], raw["imu"], gnss), {t: str(p) for t, p in files.items()})
    for table in ("imu", "reference"):
        check_gaps(raw[table]["time"].to_numpy(float), files[table])
    t_imu, t_ref = raw["imu"]["time"].to_numpy(float), raw["reference"]["time"].to_numpy(float)
    native = median_rate_hz(t_imu)
    rate = float(imu_rate_hz) if imu_rate_hz is not None else native
    # the common span; IMU row 0 covers one step before its own time (schema, CONTRIBUTING.md)
    lo = max(t_ref[0], 2 * t_imu[0] - t_imu[1], -np.inf if t_start is None else float(t_start))
    hi = min(t_ref[-1], t_imu[-1], np.inf if t_end is None else float(t_end))
    if hi - lo < 2.0 / rate:
        raise DataError(files["reference"], "time", f"a reference overlapping the IMU span [{t_imu[0]:.3f}, "
                        f"{t_imu[-1]:.3f}] s of {files['imu']} (within t_start {t_start}, t_end {t_end}) by "
                        "at least two IMU intervals: the same time base", f"[{t_ref[0]:.3f}, {t_ref[-1]:.3f}] s")
    imu, t_first, resampled = imu_on_grid(raw["imu"], rate, lo, hi)
    epochs = np.concatenate([[t_first], imu["time"].to_numpy(float)])
    reference = interpolate_reference(raw["reference"], epochs, files["reference"])
    if np.any(user["reference_lever_arm_m"]):       # a reference given at another point (an RTK antenna): to the IMU
        lat, lon, h = imu_position(reference, user["reference_lever_arm_m"])
        reference = reference.assign(lat=lat, lon=lon, h=h)
    # then the clocks, on plausible data (a unit mistake is not blamed on a clock offset), against the reference
    gnss, offset = _on_imu_clock(raw["imu"], gnss, reference, user["lever_arm_m"], latency == "auto", files,
                                 meta_path)
    fix_times, fix_shift = regular_fix_times(gnss["time"].to_numpy(float), files["gnss"])   # arrival jitter
    gnss = gnss.assign(time=fix_times)
    tg = gnss["time"].to_numpy(float)
    gnss = gnss.loc[(tg >= epochs[0]) & (tg <= epochs[-1])].reset_index(drop=True)
    checked = check_reference(reference, gnss, user["lever_arm_m"], reference_tolerance_m)
    meta = {
        "imu_rate_hz": rate,
        "native_imu_rate_hz": native,
        "imu_resampled": resampled,
        "reference_rate_hz": median_rate_hz(t_ref),
        "reference_interpolated": not np.isin(epochs, t_ref).all(),
        "gnss_rate_hz": median_rate_hz(tg) if len(tg) > 1 else None,
        "lever_arm_m": user["lever_arm_m"],
        "imu_errors": user["imu_errors"],
        "imu_errors_source": user["imu_errors_source"],
        "source": user["source"] or f"CSV drive {folder}",
        "platform": user["platform"],
        "time_shifts_s": {"imu_time_offset_s": user["imu_time_offset_s"], "gnss_latency_s": user["gnss_latency_s"]},
        "gnss_offset": offset,
        "reference_check": checked.record(),
        "reference_equals_gnss": checked.equals_gnss,
        "gnss_regridded_max_s": fix_shift,
        "imu_mounting_deg": user["imu_mounting_deg"],
        "reference_lever_arm_m": user["reference_lever_arm_m"],
        "params": {"folder": str(folder), "imu_rate_hz": imu_rate_hz, "t_start": t_start, "t_end": t_end},
    }
    return Drive(user["name"] or safe_id(folder.name), reference, imu, gnss, meta)


def write_csv_drive(drive: Drive, folder: str | Path) -> Path:
    """Write a drive in the CSV schema (atomically per file); the inverse of :func:`load_csv_drive`.

    Returns
    -------
    Path
        The folder.
    """
    folder = Path(folder)
    ref_cols = [c for c in REFERENCE_COLUMNS if drive.has_attitude or c not in ATTITUDE_COLUMNS]
    atomic_write_csv(folder / "imu.csv", drive.imu[list(IMU_COLUMNS)], float_format="%.17g")
    atomic_write_csv(folder / "gnss.csv", drive.gnss[list(GNSS_COLUMNS)], float_format="%.17g")
    atomic_write_csv(folder / "reference.csv", drive.reference[ref_cols], float_format="%.17g")
    meta = {"name": safe_id(drive.name), "lever_arm_m": [float(x) for x in drive.meta.get("lever_arm_m", [0, 0, 0])],
            "source": str(drive.meta.get("source", ""))}
    errs = drive.meta.get("imu_errors")
    if errs:
        meta["imu_errors"] = {k: errs[k] for k in VECTOR_KEYS + OPTIONAL_VECTOR_KEYS + SCALAR_KEYS + ("model",) if k in errs}
    atomic_write_text(folder / META_FILE, yaml.safe_dump(meta, sort_keys=True))
    return folder

"""A user's own drive: a folder with ``imu.csv``, ``gnss.csv``, ``reference.csv`` and optional ``meta.yaml``.

Schema (``data/README.md``; CONTRIBUTING.md tables; SI units, rad, GPS time of week or any common time
base in s, body frame x forward / y right / z down, NED):

- ``imu.csv``: ``time, gyro_x, gyro_y, gyro_z`` (rad/s), ``accel_x, accel_y, accel_z`` (m/s^2); row k =
  mean rates over ``(time[k-1], time[k]]``.
- ``gnss.csv``: ``time, lat, lon`` (rad), ``h`` (m), ``std_n, std_e, std_d`` (m); optional
  ``v_n, v_e, v_d`` (m/s; empty/NaN when not given).
- ``reference.csv``: ``time, lat, lon, h, v_n, v_e, v_d, roll, pitch, yaw``.
- ``meta.yaml`` (optional): ``name``, ``lever_arm_m`` ([x, y, z] antenna in the body frame, m,
  default [0, 0, 0]), ``imu_errors`` (keys of :mod:`bgfn.data.imu_errors`, e.g. noise densities, for the
  KF), ``source`` (free text).

Extra columns are ignored; any defect raises :class:`bgfn.errors.DataError` naming the file and column.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd

from bgfn.data.drive import Drive
from bgfn.data.imu_errors import error_params
from bgfn.data.navego import check_time, resample_imu
from bgfn.errors import DataError
from bgfn.schema import GNSS_COLUMNS, GNSS_FIX_COLUMNS, IMU_COLUMNS, REFERENCE_COLUMNS

#: Files of a CSV drive and their required columns.
CSV_FILES = {
    "imu.csv": IMU_COLUMNS,
    "gnss.csv": GNSS_FIX_COLUMNS,
    "reference.csv": REFERENCE_COLUMNS,
}
_OPTIONAL = {"gnss.csv": ("v_n", "v_e", "v_d")}


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


def _read_meta(path: Path) -> dict:
    if not path.is_file():
        return {}
    import yaml

    try:
        meta = yaml.safe_load(path.read_text(encoding="utf-8")) or {}
    except yaml.YAMLError as exc:
        raise DataError(path, "<yaml>", "valid YAML", str(exc).replace("\n", " ")) from None
    if not isinstance(meta, dict):
        raise DataError(path, "<top level>", "a mapping", type(meta).__name__)
    return meta


def load_csv_drive(folder: str | Path, *, imu_rate_hz: float | None = None) -> Drive:
    """Load a drive from a folder in the CSV schema of the module docstring.

    Parameters
    ----------
    folder : str or Path
        Folder holding ``imu.csv``, ``gnss.csv``, ``reference.csv`` (and optionally ``meta.yaml``).
    imu_rate_hz : float, optional
        Resample the IMU to this rate by integrating its increments
        (:func:`bgfn.data.navego.resample_imu`); default: keep the file's rate.

    Returns
    -------
    Drive
        ``meta``: ``imu_rate_hz``, ``gnss_rate_hz`` (from the median intervals), ``lever_arm_m``,
        ``imu_errors`` (validated, or None), ``source``, ``params``.
    """
    folder = Path(folder)
    if not folder.is_dir():
        raise DataError(folder, "folder", "a folder with imu.csv, gnss.csv, reference.csv", "no such folder")
    tables = {name: read_table(folder / name, cols, _OPTIONAL.get(name, ())) for name, cols in CSV_FILES.items()}
    gnss = tables["gnss.csv"]
    std = gnss[["std_n", "std_e", "std_d"]].to_numpy(float)
    if (std <= 0).any():
        raise DataError(folder / "gnss.csv", "std_n/std_e/std_d", "positive position std, m",
                        f"min {std.min()}")
    meta_path = folder / "meta.yaml"
    user = _read_meta(meta_path)
    larm = np.asarray(user.get("lever_arm_m", [0.0, 0.0, 0.0]), dtype=float).ravel()
    if larm.size != 3 or not np.isfinite(larm).all():
        raise DataError(meta_path, "lever_arm_m", "3 finite numbers [x, y, z], m", str(user.get("lever_arm_m")))
    imu_errors = None
    if "imu_errors" in user:
        if not isinstance(user["imu_errors"], dict):
            raise DataError(meta_path, "imu_errors", "a mapping of error parameters", type(user["imu_errors"]).__name__)
        try:
            imu_errors = error_params(dict(user["imu_errors"], model=user["imu_errors"].get("model", "user")))
        except DataError as exc:
            raise DataError(meta_path, f"imu_errors.{exc.field}", exc.expected, exc.found) from None
    imu = tables["imu.csv"]
    if imu_rate_hz is not None:
        imu = resample_imu(imu, imu_rate_hz)
    rate = float(imu_rate_hz) if imu_rate_hz is not None else float(1.0 / np.median(np.diff(imu["time"])))
    meta = {
        "imu_rate_hz": rate,
        "gnss_rate_hz": float(1.0 / np.median(np.diff(gnss["time"]))),
        "lever_arm_m": larm.tolist(),
        "imu_errors": imu_errors,
        "source": str(user.get("source", f"CSV drive {folder}")),
        "params": {"folder": str(folder), "imu_rate_hz": imu_rate_hz},
    }
    return Drive(str(user.get("name", folder.name)), tables["reference.csv"], imu, gnss, meta)


def write_csv_drive(drive: Drive, folder: str | Path) -> Path:
    """Write a drive in the CSV schema (atomically per file); the inverse of :func:`load_csv_drive`.

    Returns
    -------
    Path
        The folder.
    """
    import yaml

    from bgfn.io import atomic_write_csv, atomic_write_text

    folder = Path(folder)
    atomic_write_csv(folder / "imu.csv", drive.imu[list(IMU_COLUMNS)], float_format="%.17g")
    atomic_write_csv(folder / "gnss.csv", drive.gnss[list(GNSS_COLUMNS)], float_format="%.17g")
    atomic_write_csv(folder / "reference.csv", drive.reference[list(REFERENCE_COLUMNS)], float_format="%.17g")
    meta = {"name": drive.name, "lever_arm_m": [float(x) for x in drive.meta.get("lever_arm_m", [0, 0, 0])],
            "source": str(drive.meta.get("source", ""))}
    errs = drive.meta.get("imu_errors")
    if errs:
        from bgfn.data.imu_errors import OPTIONAL_VECTOR_KEYS, SCALAR_KEYS, VECTOR_KEYS

        meta["imu_errors"] = {k: errs[k] for k in VECTOR_KEYS + OPTIONAL_VECTOR_KEYS + SCALAR_KEYS + ("model",) if k in errs}
    atomic_write_text(folder / "meta.yaml", yaml.safe_dump(meta, sort_keys=True))
    return folder

"""Read and validate the NaveGo MATLAB structs (``ref``, ``ekinox_gnss``, ``ekinox_imu``, ``mpu6000_imu``).

Every reader returns tables in the schemas of CONTRIBUTING.md (NaveGo's fields: ``t`` in s of GPS time of week,
``lat``/``lon`` rad, ``vel`` NED m/s, ``wb`` rad/s, ``fb`` m/s^2, ``stdm`` and ``larm`` m; an IMU's optional error
profile ``arw``, ``gb_sta``, ``gb_dyn``, ``gb_corr``, ...) and raises :class:`bgfn.errors.DataError` naming the file
and the field on any defect: an unreadable or truncated file, a missing struct or field, a wrong length, a
non-finite value, a time not strictly increasing.
"""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pandas as pd
import scipy.io

from bgfn.errors import DataError
from bgfn.schema import GNSS_COLUMNS, IMU_COLUMNS, REFERENCE_COLUMNS

#: Error-profile fields of a NaveGo IMU struct that are copied into ``meta['imu_errors']`` when present.
IMU_PROFILE_FIELDS = ("arw", "vrw", "gb_sta", "ab_sta", "gb_dyn", "ab_dyn", "gb_corr", "ab_corr",
                      "gb_psd", "ab_psd", "freq", "ini_align", "ini_align_err")


def load_struct(path: str | Path, name: str | None = None) -> dict[str, np.ndarray]:
    """Load one MATLAB struct from a .mat file as a dict of numpy arrays.

    Parameters
    ----------
    path : str or Path
        The .mat file.
    name : str, optional
        Variable name of the struct (e.g. ``"ref"``); when absent from the file, the file's only
        struct variable is used.

    Returns
    -------
    dict of str to ndarray
        One entry per struct field (squeezed).

    Raises
    ------
    DataError
        Unreadable/truncated file (field ``file``) or no struct (field ``struct``).
    """
    path = Path(path)
    try:
        mat = scipy.io.loadmat(path, squeeze_me=True, struct_as_record=False)
    except FileNotFoundError:
        raise DataError(path, "file", "an existing MATLAB .mat file", "no such file") from None
    except Exception as exc:  # scipy raises ValueError, TypeError, OSError, MatReadError, ... on bad bytes
        raise DataError(path, "file", "a readable MATLAB v5 .mat file",
                        f"{type(exc).__name__}: {exc} (corrupted or truncated?)") from None
    structs = {k: v for k, v in mat.items()
               if not k.startswith("__") and isinstance(v, scipy.io.matlab.mat_struct)}
    if name is not None and name in structs:
        struct = structs[name]
    elif len(structs) == 1:
        struct = next(iter(structs.values()))
    else:
        raise DataError(path, "struct", f"a MATLAB struct variable {name or ''!s}".rstrip(),
                        f"variables {sorted(k for k in mat if not k.startswith('__'))}")
    return {f: np.asarray(getattr(struct, f)) for f in struct._fieldnames}


def _field(path: Path, s: dict, field: str) -> np.ndarray:
    if field not in s:
        raise DataError(path, field, "a field of that name in the struct", f"fields {sorted(s)}")
    try:
        return np.asarray(s[field], dtype=float)
    except (TypeError, ValueError):
        raise DataError(path, field, "numeric values", f"dtype {np.asarray(s[field]).dtype}") from None


def _vector(path: Path, s: dict, field: str, n: int | None = None) -> np.ndarray:
    """A 1-D finite float field (of length n when given)."""
    a = _field(path, s, field)
    if a.ndim != 1 or (n is not None and a.shape[0] != n):
        raise DataError(path, field, f"a vector of {n if n is not None else 'n'} samples", f"shape {a.shape}")
    _finite(path, field, a)
    return a


def _columns3(path: Path, s: dict, field: str, n: int) -> np.ndarray:
    """An n x 3 finite float field (a 3 x n one is transposed)."""
    a = _field(path, s, field)
    if a.shape == (3, n) and n != 3:
        a = a.T
    if a.shape != (n, 3):
        raise DataError(path, field, f"an array of shape ({n}, 3)", f"shape {a.shape}")
    _finite(path, field, a)
    return a


def _triple(path: Path, s: dict, field: str) -> np.ndarray:
    """A 3-vector (a scalar is broadcast)."""
    a = _field(path, s, field).ravel()
    if a.size == 1:
        a = np.repeat(a, 3)
    if a.size != 3:
        raise DataError(path, field, "3 values (x, y, z or north, east, down)", f"{a.size} values")
    _finite(path, field, a)
    return a


def _finite(path: Path, field: str, a: np.ndarray) -> None:
    bad = ~np.isfinite(a)
    if bad.any():
        idx = np.argwhere(bad)[0]
        raise DataError(path, field, "finite values", f"{int(bad.sum())} NaN/inf values, first at index "
                        f"{tuple(int(i) for i in idx)}")


def check_time(source, field: str, t: np.ndarray) -> None:
    """Raise DataError unless ``t`` is finite and strictly increasing (names the first bad index)."""
    t = np.asarray(t, dtype=float)
    _finite(source, field, t)
    dt = np.diff(t)
    if (dt <= 0).any():
        k = int(np.argmax(dt <= 0))
        raise DataError(source, field, "strictly increasing time",
                        f"t[{k}] = {t[k]!r} followed by t[{k + 1}] = {t[k + 1]!r}")


def _time(path: Path, s: dict) -> np.ndarray:
    t = _vector(path, s, "t")
    if t.size < 2:
        raise DataError(path, "t", "at least 2 samples", f"{t.size}")
    check_time(path, "t", t)
    return t


def read_reference(path: str | Path) -> pd.DataFrame:
    """Read NaveGo ``ref.mat`` into a reference table (CONTRIBUTING.md schema).

    Parameters
    ----------
    path : str or Path
        ``ref.mat``.

    Returns
    -------
    DataFrame
        Columns ``REFERENCE_COLUMNS``; time in s (GPS time of week), angles in rad, yaw wrapped to
        (-pi, pi].
    """
    path = Path(path)
    s = load_struct(path, "ref")
    t = _time(path, s)
    n = t.size
    cols = {"time": t}
    for f in ("lat", "lon", "h"):
        cols[f] = _vector(path, s, f, n)
    vel = _columns3(path, s, "vel", n)
    cols.update(v_n=vel[:, 0], v_e=vel[:, 1], v_d=vel[:, 2])
    for f in ("roll", "pitch", "yaw"):
        cols[f] = _vector(path, s, f, n)
    _check_latlon(path, cols["lat"], cols["lon"])
    cols["yaw"] = np.mod(cols["yaw"] + np.pi, 2 * np.pi) - np.pi
    return pd.DataFrame(cols, columns=list(REFERENCE_COLUMNS))


def _check_latlon(path: Path, lat: np.ndarray, lon: np.ndarray) -> None:
    if np.abs(lat).max() > np.pi / 2:
        raise DataError(path, "lat", "latitude in rad within [-pi/2, pi/2]", f"max |lat| = {np.abs(lat).max()}")
    if np.abs(lon).max() > 2 * np.pi:
        raise DataError(path, "lon", "longitude in rad", f"max |lon| = {np.abs(lon).max()}")


def read_gnss(path: str | Path) -> tuple[pd.DataFrame, dict]:
    """Read a NaveGo GNSS struct (``ekinox_gnss.mat``) into a GNSS table.

    Parameters
    ----------
    path : str or Path
        ``ekinox_gnss.mat``.

    Returns
    -------
    gnss : DataFrame
        Columns ``GNSS_COLUMNS``; ``std_n``, ``std_e``, ``std_d`` from the struct's ``stdm`` (m).
    info : dict
        ``lever_arm_m`` (``larm``, body frame, m), ``rate_hz`` (``freq``), ``stdm`` (m),
        ``stdv`` (m/s, when present).
    """
    path = Path(path)
    s = load_struct(path, "ekinox_gnss")
    t = _time(path, s)
    n = t.size
    cols = {"time": t}
    for f in ("lat", "lon", "h"):
        cols[f] = _vector(path, s, f, n)
    _check_latlon(path, cols["lat"], cols["lon"])
    vel = _columns3(path, s, "vel", n)
    cols.update(v_n=vel[:, 0], v_e=vel[:, 1], v_d=vel[:, 2])
    stdm = _triple(path, s, "stdm")
    if (stdm <= 0).any():
        raise DataError(path, "stdm", "positive position std (m)", str(stdm.tolist()))
    cols.update(std_n=np.full(n, stdm[0]), std_e=np.full(n, stdm[1]), std_d=np.full(n, stdm[2]))
    larm = _triple(path, s, "larm")
    # The file's `freq` holds 5 + 4.6e-14; rates are rounded to 1e-6 Hz.
    rate = _field(path, s, "freq").ravel()[0] if "freq" in s else 1.0 / np.median(np.diff(t))
    info = {"lever_arm_m": larm.tolist(), "stdm": stdm.tolist(), "rate_hz": round(float(rate), 6)}
    if "stdv" in s:
        info["stdv"] = _triple(path, s, "stdv").tolist()
    return pd.DataFrame(cols, columns=list(GNSS_COLUMNS)), info


def read_imu(path: str | Path, name: str | None = None) -> tuple[pd.DataFrame, dict]:
    """Read a NaveGo IMU struct (``ekinox_imu.mat``, ``mpu6000_imu.mat``) at its native rate.

    Parameters
    ----------
    path : str or Path
        The .mat file.
    name : str, optional
        Struct variable name (default: the file's stem, else its only struct).

    Returns
    -------
    imu : DataFrame
        Columns ``IMU_COLUMNS`` at the native rate: ``gyro_*`` = ``wb`` (rad/s), ``accel_*`` = ``fb``
        (m/s^2); body frame x forward, y right, z down.
    profile : dict
        The error-profile fields of ``IMU_PROFILE_FIELDS`` present in the struct (lists, SI units).
    """
    path = Path(path)
    s = load_struct(path, name or path.stem)
    t = _time(path, s)
    n = t.size
    wb = _columns3(path, s, "wb", n)
    fb = _columns3(path, s, "fb", n)
    imu = pd.DataFrame({"time": t, "gyro_x": wb[:, 0], "gyro_y": wb[:, 1], "gyro_z": wb[:, 2],
                        "accel_x": fb[:, 0], "accel_y": fb[:, 1], "accel_z": fb[:, 2]},
                       columns=list(IMU_COLUMNS))
    profile = {}
    for f in IMU_PROFILE_FIELDS:
        if f in s:
            try:
                profile[f] = np.asarray(s[f], dtype=float).ravel().tolist()
            except (TypeError, ValueError):
                continue
    return imu, profile


def resample_imu(imu: pd.DataFrame, rate_hz: float, *, t_start: float | None = None,
                 t_end: float | None = None) -> pd.DataFrame:
    """Resample an IMU table to ``rate_hz`` by integrating its increments.

    Row ``k`` of the input is the mean rate over ``(t[k-1], t[k]]`` (CONTRIBUTING.md; row 0 over
    ``(t[0] - (t[1] - t[0]), t[0]]``); its cumulative
    integral (angle / velocity increments) is interpolated linearly at the new epochs and differenced,
    so increments are preserved exactly (no aliasing of the sum). The output grid is
    ``round(t * rate_hz) / rate_hz`` within ``[t_start, t_end]`` and the input span; as in the schema,
    rows are given for the grid epochs after the first.

    Parameters
    ----------
    imu : DataFrame
        IMU table, strictly increasing ``time``.
    rate_hz : float
        Output rate, Hz.
    t_start, t_end : float, optional
        Limits of the output grid, s.

    Returns
    -------
    DataFrame
        IMU table at ``rate_hz``.
    """
    t_rows = imu["time"].to_numpy(float)
    check_time("imu", "time", t_rows)
    if t_rows.size < 2:
        raise DataError("imu", "time", "at least 2 samples", str(t_rows.size))
    # Row 0 covers (t[0] - (t[1] - t[0]), t[0]]: prepend that start so that no row is lost.
    t = np.concatenate([[2 * t_rows[0] - t_rows[1]], t_rows])
    lo = t[0] if t_start is None else max(t[0], t_start)
    hi = t[-1] if t_end is None else min(t[-1], t_end)
    k0, k1 = int(np.ceil(lo * rate_hz - 1e-9)), int(np.floor(hi * rate_hz + 1e-9))
    if k1 - k0 < 1:
        raise DataError("imu", "time", f"a span of at least 2 epochs at {rate_hz} Hz", f"[{lo}, {hi}]")
    grid = np.arange(k0, k1 + 1) / rate_hz
    dt = np.diff(t)
    out = {"time": grid[1:]}
    for c in IMU_COLUMNS[1:]:
        x = imu[c].to_numpy(float)
        cum = np.concatenate([[0.0], np.cumsum(x * dt)])  # integral from t[0] to t[k]
        out[c] = np.diff(np.interp(grid, t, cum)) / np.diff(grid)
    return pd.DataFrame(out, columns=list(IMU_COLUMNS))

"""The ``Drive`` container (reference, IMU and GNSS tables + meta) and its cache format (.npz + JSON).

A cache entry is two files written atomically: ``<stem>.npz`` (one float64 array per table, no pickles)
then ``<stem>.json`` (meta, column names, cache key, code hash). The JSON is written last, so an entry without
it is incomplete and ignored. Entries written by other code can never be read again (the key holds the code);
:func:`prune_stale` removes them.
"""

from __future__ import annotations

import json
import logging
import zipfile
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from bgfn.data.navego import check_time
from bgfn.data.physics import check_drive, reference_has_attitude
from bgfn.errors import DataError
from bgfn.io import atomic_path, atomic_write_json
from bgfn.schema import ATTITUDE_COLUMNS, GNSS_COLUMNS, IMU_COLUMNS, REFERENCE_COLUMNS

_TABLES = ("reference", "imu", "gnss", "imu_bias")
log = logging.getLogger(__name__)


@dataclass
class Drive:
    """One drive: truth, IMU and GNSS on a common time base (GPS time of week, s).

    Attributes
    ----------
    name : str
        Dataset name (``turin-sim-ekinox``, ...) or the CSV folder's name.
    reference : DataFrame
        Truth, reference schema (CONTRIBUTING.md), at the IMU rate. ``roll, pitch, yaw`` are all NaN when the
        reference has no attitude (:attr:`has_attitude`).
    imu : DataFrame
        IMU schema; row k = mean rates over ``(time[k-1], time[k]]``.
    gnss : DataFrame
        GNSS schema (antenna position; ``v_*`` NaN when not given).
    meta : dict
        ``imu_rate_hz``, ``gnss_rate_hz``, ``lever_arm_m`` (antenna in the body frame, m),
        ``imu_errors`` (see :mod:`bgfn.data.imu_errors`), ``source``, ``params``, and per dataset
        diagnostics (``truth_fit``, ``gnss_residual_*``, ``cache_key``); ``reference_excluded_s``
        (``[[t0, t1], ...]``, s): spans where the reference is not trusted, left out of every error metric
        (:func:`bgfn.nav.metrics.reference_rows`).
    imu_bias : DataFrame or None
        True additive IMU bias per epoch (simulated datasets): ``time``, ``gyro_bias_x/y/z`` (rad/s),
        ``accel_bias_x/y/z`` (m/s^2).
    """

    name: str
    reference: pd.DataFrame
    imu: pd.DataFrame
    gnss: pd.DataFrame
    meta: dict = field(default_factory=dict)
    imu_bias: pd.DataFrame | None = None

    @property
    def has_attitude(self) -> bool:
        """Whether the reference carries an attitude (``roll``, ``pitch``, ``yaw`` all finite): the filter can start
        from its first row; otherwise it aligns itself (:mod:`bgfn.nav.alignment`)."""
        cols = list(ATTITUDE_COLUMNS)
        return set(cols) <= set(self.reference.columns) and bool(
            np.isfinite(self.reference[cols].to_numpy(float)).all())

    def crop(self, t_start: float | None = None, t_end: float | None = None) -> "Drive":
        """A copy restricted to ``t_start <= time <= t_end`` (s, GPS time of week).

        The IMU keeps the rows whose interval lies inside the span (``time > t_start``), so that
        integrating from the first reference row uses exactly the IMU rows of the span.
        """
        lo = -np.inf if t_start is None else float(t_start)
        hi = np.inf if t_end is None else float(t_end)

        def sel(df):
            t = df["time"].to_numpy(float)
            return df.loc[(t >= lo) & (t <= hi)].reset_index(drop=True)

        ref = sel(self.reference)
        if len(ref) < 2:
            raise DataError(self.name, "t_start/t_end", "a span holding at least 2 reference epochs",
                            f"[{t_start}, {t_end}]")
        t0 = float(ref["time"].iloc[0])
        t1 = float(ref["time"].iloc[-1])

        def sel_imu(df):  # rows whose interval (t[k-1], t[k]] lies within the reference span
            if df is None:
                return None
            return df.loc[(df["time"] > t0) & (df["time"] <= t1)].reset_index(drop=True)

        meta = dict(self.meta, crop=[t_start, t_end])
        return Drive(self.name, ref, sel_imu(self.imu), sel(self.gnss), meta, sel_imu(self.imu_bias))

    def validate(self, source: str | None = None, files: dict | None = None) -> "Drive":
        """Check columns, strictly increasing times, finite values and physics; return self.

        Parameters
        ----------
        source : str, optional
            Name used in messages (default: the drive's name).
        files : dict, optional
            ``{table: file}`` where each table was read from, for the messages of the physics checks.

        Raises
        ------
        DataError
            Naming the table (or file) and the column; for implausible physics (units, axes, spikes, time
            base) also the likely cause (:func:`bgfn.data.physics.check_drive`). A reference whose roll, pitch
            and yaw are all NaN (no attitude) passes; one with some of them NaN does not.
        """
        src = source or self.name
        ref_nan_ok = ()
        if all(c in self.reference.columns for c in ATTITUDE_COLUMNS) and \
                not reference_has_attitude(self.reference, f"{src}/reference"):
            ref_nan_ok = ATTITUDE_COLUMNS
        for table, cols, nan_ok in (("reference", REFERENCE_COLUMNS, ref_nan_ok), ("imu", IMU_COLUMNS, ()),
                                    ("gnss", GNSS_COLUMNS, ("v_n", "v_e", "v_d"))):
            df = getattr(self, table)
            missing = [c for c in cols if c not in df.columns]
            if missing:
                raise DataError(f"{src}/{table}", missing[0], f"columns {', '.join(cols)}",
                                f"missing {', '.join(missing)}")
            check_time(f"{src}/{table}", "time", df["time"].to_numpy(float))
            for c in cols:
                if c in nan_ok:
                    continue
                bad = ~np.isfinite(df[c].to_numpy(float))
                if bad.any():
                    k = int(np.argmax(bad))
                    raise DataError(f"{src}/{table}", c, "finite values",
                                    f"{int(bad.sum())} NaN/inf, first at row {k} (time {df['time'].iloc[k]})")
        check_drive(self, files or {t: f"{src}/{t}" for t in ("reference", "imu", "gnss")})
        return self


def save_drive(drive: Drive, stem: str | Path, key: str, code: str | None = None) -> None:
    """Write ``<stem>.npz`` then ``<stem>.json`` atomically (see module docstring); ``code``: hash of the code
    that built it (for :func:`prune_stale`)."""
    stem = Path(stem)
    arrays, columns = {}, {}
    for table in _TABLES:
        df = getattr(drive, table)
        if df is not None:
            arrays[table] = df.to_numpy(dtype=np.float64)
            columns[table] = list(df.columns)
    with atomic_path(stem.with_suffix(".npz")) as tmp:
        with open(tmp, "wb") as fh:
            np.savez(fh, **arrays)
    atomic_write_json(stem.with_suffix(".json"), {"key": key, "code": code, "name": drive.name,
                                                  "columns": columns, "meta": drive.meta})


def load_cached(stem: str | Path, key: str) -> Drive | None:
    """Read a cache entry written by :func:`save_drive`; None when absent, incomplete, stale or unreadable.

    An entry that exists but cannot be read (a truncated ``.npz``, a corrupt JSON) is reported with one
    warning line and treated as absent, so the caller rebuilds it and overwrites it atomically.
    """
    stem = Path(stem)
    jpath, npath = stem.with_suffix(".json"), stem.with_suffix(".npz")
    if not (jpath.is_file() and npath.is_file()):
        return None
    try:
        info = json.loads(jpath.read_text())
        if info.get("key") != key:
            return None
        with np.load(npath, allow_pickle=False) as npz:
            tables = {t: pd.DataFrame(npz[t], columns=info["columns"][t]) for t in info["columns"]}
    except (OSError, ValueError, KeyError, EOFError, zipfile.BadZipFile) as exc:
        log.warning("cache entry %s is unreadable (%s: %s): rebuilding it", npath, type(exc).__name__, exc)
        return None
    return Drive(info["name"], tables["reference"], tables["imu"], tables["gnss"], info["meta"],
                 tables.get("imu_bias"))


def prune_stale(folder: str | Path, code: str) -> list[Path]:
    """Delete the cache entries in ``folder`` that other code wrote (their ``code`` differs from ``code``, or
    their JSON cannot be read): their keys can never match again. The JSON goes first, so a half-deleted
    entry is an incomplete one. Entries without a JSON (being written, or interrupted) are left alone.

    Returns
    -------
    list of Path
        The stems removed.
    """
    removed = []
    for jpath in sorted(Path(folder).glob("*.json")):
        try:
            stale = json.loads(jpath.read_text()).get("code") != code
        except (OSError, ValueError, AttributeError):
            stale = True
        if stale:
            jpath.unlink(missing_ok=True)
            jpath.with_suffix(".npz").unlink(missing_ok=True)
            removed.append(jpath.with_suffix(""))
    return removed


def horizontal_distance_m(reference: pd.DataFrame) -> float:
    """Length of the horizontal path, m (sum of ``|v_h| dt``, trapezoid rule)."""
    t = reference["time"].to_numpy(float)
    speed = np.hypot(reference["v_n"].to_numpy(float), reference["v_e"].to_numpy(float))
    return float(np.sum(0.5 * (speed[1:] + speed[:-1]) * np.diff(t)))

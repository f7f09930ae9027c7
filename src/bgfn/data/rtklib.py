"""Read the files of a drive logged with RTKLIB (demo5): the IMU's CSV, its time-tag file and a ``.pos`` solution.

The drive ``rtklib-drive0708`` (:mod:`bgfn.data.drives`) comes from ``rtklibexplorer/GNSS_IMU`` (``data/drive_0708``,
BSD 3-Clause; ``data/NOTICE``): a TDK ICM-45686 MEMS IMU and a u-blox X20 receiver on a car roof. The file formats
and the drive's configuration (the IMU time offset of -0.125 s, the mounting ``[180, 0, 180] + [0, -6.79, 5.35]``
deg, the 5 cm lever arm :data:`LEVER_ARM_M`) are read from that repository's source at commit ``c35774d``; its
stretch of the IMU counter to the tags is not applied (``stretch_to_tags=False``, deviations page): this drive's
yaw rate against its course over ground contradicts it (``tests/test_data_rtklib.py``). Every reader returns tables
in the schemas of CONTRIBUTING.md (SI units, GPS time of week) and raises :class:`bgfn.errors.DataError` naming the
file and the field on any defect.
"""

from __future__ import annotations

import struct
from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from bgfn.data.imu_errors import G0
from bgfn.data.navego import check_time
from bgfn.errors import DataError
from bgfn.nav.transform import dcm_from_euler
from bgfn.schema import IMU_COLUMNS

#: Length of the text header of an RTKLIB time-tag file, bytes.
TAG_HEADER_BYTES = 60
#: What the tag header starts with.
TAG_MAGIC = b"TIMETAG RTKLIB"
#: The GPS epoch 1980-01-06 00:00:00 in seconds since 1970-01-01 (RTKLIB's ``gtime_t`` in the GPS time scale).
GPS_EPOCH_UNIX_S = 315964800
#: Seconds in a GPS week.
SECONDS_PER_WEEK = 604800
#: IMU-to-body Euler angles (roll, pitch, yaw) of drive_0708, deg: the mounting, then the measured misalignment
#: (``drive_config.py``; added as angles, as the source does).
MOUNTING_DEG = (180.0, 0.0, 180.0)
MISALIGNMENT_DEG = (0.0, -6.79, 5.35)
#: Added to the tagged IMU time, s (``imu_t_off`` of ``drive_config.py``: logging delay).
IMU_TIME_OFFSET_S = -0.125
#: GNSS antenna position relative to the IMU in the body frame (x forward, y right, z down), m.
LEVER_ARM_M = (0.0, -0.05, 0.0)
#: RTKLIB solution quality flags.
Q_FIX, Q_FLOAT, Q_SINGLE = 1, 2, 5
#: Columns of :func:`read_pos`.
POS_COLUMNS = ("time", "lat", "lon", "h", "q", "ns", "std_n", "std_e", "std_d", "v_n", "v_e", "v_d",
               "std_v_n", "std_v_e", "std_v_d")
_POS_MIN_FIELDS = 21  # date time lat lon h Q ns sdn sde sdu sdne sdeu sdun age ratio vn ve vu sdvn sdve sdvu
_CSV_FIELDS = 7       # ax ay az gx gy gz counter


@dataclass(frozen=True)
class TimeTags:
    """An RTKLIB time-tag file.

    Attributes
    ----------
    start_gps_whole_s : int
        GPS time of the file's start: whole seconds since the GPS epoch (1980-01-06).
    start_frac_s : float
        Its fraction, s.
    start_tick_ms : int
        The logging computer's tick at the start (unused).
    tick_ms : ndarray of int
        Milliseconds since the start at which each chunk had been received.
    file_pos : ndarray of int
        Byte position in the data file after each chunk.
    """

    start_gps_whole_s: int
    start_frac_s: float
    start_tick_ms: int
    tick_ms: np.ndarray
    file_pos: np.ndarray

    @property
    def span_s(self) -> float:
        """Time from the start to the last chunk, s."""
        return float(self.tick_ms[-1]) / 1000.0 if self.tick_ms.size else 0.0


def read_tag(path: str | Path) -> TimeTags:
    """Read an RTKLIB time-tag file (module docstring).

    Parameters
    ----------
    path : str or Path
        The ``.tag`` file.

    Returns
    -------
    TimeTags

    Raises
    ------
    DataError
        Missing file, wrong header, a truncated record, ticks that decrease.
    """
    path = Path(path)
    try:
        raw = path.read_bytes()
    except OSError as exc:
        raise DataError(path, "file", "a readable RTKLIB time-tag file", str(exc)) from None
    fixed = TAG_HEADER_BYTES + 4 + 4 + 8
    if len(raw) < fixed or not raw.startswith(TAG_MAGIC):
        raise DataError(path, "header", f"a {TAG_HEADER_BYTES}-byte header starting with {TAG_MAGIC.decode()!r} "
                        "then the start tick and time", f"{len(raw)} bytes starting with {raw[:16]!r}")
    start_tick, start_s = struct.unpack_from("<II", raw, TAG_HEADER_BYTES)
    (start_frac,) = struct.unpack_from("<d", raw, TAG_HEADER_BYTES + 8)
    body = raw[fixed:]
    if len(body) % 8:
        raise DataError(path, "records", "pairs of uint32 (tick in ms, file position)",
                        f"{len(body)} bytes after the header (not a multiple of 8)")
    pairs = np.frombuffer(body, dtype="<u4").reshape(-1, 2).astype(np.int64)  # [n, 2]
    if not 0.0 <= start_frac < 1.0 or start_s < GPS_EPOCH_UNIX_S:
        raise DataError(path, "start time", "a GPS time after 1980-01-06 and a fraction in [0, 1)",
                        f"{start_s} s + {start_frac}")
    if pairs.size and (np.diff(pairs[:, 0]) < 0).any():
        k = int(np.argmax(np.diff(pairs[:, 0]) < 0))
        raise DataError(path, "tick", "non-decreasing ticks", f"{pairs[k, 0]} then {pairs[k + 1, 0]} at record {k}")
    return TimeTags(int(start_s) - GPS_EPOCH_UNIX_S, float(start_frac), int(start_tick), pairs[:, 0], pairs[:, 1])


def week_and_tow(gps_whole_s, frac_s=0.0) -> tuple[int, np.ndarray]:
    """GPS week of the first time and the times as seconds of that week.

    The whole seconds are reduced in integers before the fraction is added, so that the seconds of the week keep
    their sub-microsecond digits (seconds since 1980 in float64 would not).

    Parameters
    ----------
    gps_whole_s : array_like of int
        Whole seconds since the GPS epoch.
    frac_s : array_like of float
        Seconds to add (fraction, elapsed time), s.

    Returns
    -------
    week : int
    tow : ndarray
        s since the start of ``week`` (continues past 604800 s when a drive crosses a week boundary).
    """
    whole = np.atleast_1d(np.asarray(gps_whole_s, dtype=np.int64))
    week = int(whole[0] // SECONDS_PER_WEEK)
    return week, (whole - week * SECONDS_PER_WEEK).astype(float) + np.asarray(frac_s, dtype=float)


def imu_to_body_dcm(mounting_deg=MOUNTING_DEG, misalignment_deg=MISALIGNMENT_DEG) -> np.ndarray:
    """Sensor-to-body rotation ``C`` with ``x_b = C @ x_sensor`` (module docstring: as the source builds it).

    Parameters
    ----------
    mounting_deg, misalignment_deg : array_like, shape (3,)
        Roll, pitch, yaw, deg; added as angles.

    Returns
    -------
    ndarray, shape (3, 3)
    """
    r, p, y = np.radians(np.asarray(mounting_deg, dtype=float) + np.asarray(misalignment_deg, dtype=float))
    # Groves' Euler_to_CTM(r, p, y) is C_nb = C_bn^T of paper Eq. (cnb).
    return dcm_from_euler(r, p, y).T


def read_imu_csv(path: str | Path, tags: TimeTags, *, week: int | None = None,
                 time_offset_s: float = IMU_TIME_OFFSET_S, stretch_to_tags: bool = False,
                 mounting_deg=MOUNTING_DEG, misalignment_deg=MISALIGNMENT_DEG) -> tuple[pd.DataFrame, dict]:
    """Read the IMU CSV into the IMU schema at the sensor's own (jittery) times.

    Parameters
    ----------
    path : str or Path
        The CSV (``ax, ay, az`` g, ``gx, gy, gz`` deg/s, ms counter; first and last line skipped).
    tags : TimeTags
        Its time tags (:func:`read_tag`).
    week : int, optional
        GPS week whose seconds the times are given in; default the week of the first sample.
    time_offset_s : float
        Added to the tagged time, s (:data:`IMU_TIME_OFFSET_S`).
    stretch_to_tags : bool
        Stretch the counter so that the last sample falls at the tags' last tick, as the source does (module
        docstring: this drive's data contradict it).
    mounting_deg, misalignment_deg : array_like, shape (3,)
        Sensor-to-body Euler angles, deg (:func:`imu_to_body_dcm`).

    Returns
    -------
    imu : DataFrame
        IMU schema, body frame, SI units, time = GPS time of week (s) at the sensor's epochs.
    info : dict
        ``week``, ``time_offset_s``, ``tag_span_ratio`` (tag span / counter span: the source's stretch),
        ``stretched`` (whether it was applied), ``n_samples``, ``step_s`` (min, median, max interval, s).

    Raises
    ------
    DataError
        Unreadable file, a line without 7 numbers, a counter that does not increase.
    """
    path = Path(path)
    try:
        lines = path.read_text(encoding="ascii").splitlines()
    except (OSError, UnicodeDecodeError) as exc:
        raise DataError(path, "file", "a readable ASCII CSV", str(exc)) from None
    body = [ln for ln in lines[1:-1] if ln.strip()]  # the first and the last line are not samples
    if len(body) < 2:
        raise DataError(path, "lines", "at least 2 sample lines between the first and the last", str(len(body)))
    try:
        data = np.array([[float(v) for v in ln.split(",")] for ln in body])  # [n, 7]
    except ValueError as exc:
        raise DataError(path, "values", f"{_CSV_FIELDS} numbers per line (ax, ay, az, gx, gy, gz, counter)",
                        str(exc)) from None
    if data.ndim != 2 or data.shape[1] != _CSV_FIELDS:
        widths = sorted({len(ln.split(",")) for ln in body})
        raise DataError(path, "columns", f"{_CSV_FIELDS} comma-separated fields per line", f"{widths}")
    counter_s = (data[:, 6] - data[0, 6]) / 1000.0
    check_time(path, "counter", counter_s)
    ratio = tags.span_s / counter_s[-1] if tags.span_s > 0 else 1.0
    elapsed = counter_s * ratio if stretch_to_tags else counter_s
    week_, tow = week_and_tow(np.full(counter_s.size, tags.start_gps_whole_s),
                             tags.start_frac_s + elapsed + time_offset_s)
    if week is not None:
        tow = tow + (week_ - week) * SECONDS_PER_WEEK
    c = imu_to_body_dcm(mounting_deg, misalignment_deg)
    accel = data[:, 0:3] * G0 @ c.T               # [n, 3] m/s^2, body
    gyro = np.radians(data[:, 3:6]) @ c.T         # [n, 3] rad/s, body
    imu = pd.DataFrame(np.column_stack([tow, gyro, accel]), columns=list(IMU_COLUMNS))
    step = np.diff(tow)
    info = {"week": week_ if week is None else int(week), "time_offset_s": float(time_offset_s),
            "tag_span_ratio": float(ratio), "stretched": bool(stretch_to_tags), "n_samples": int(len(tow)),
            "step_s": [float(step.min()), float(np.median(step)), float(step.max())]}
    return imu, info


def read_pos(path: str | Path, *, week: int | None = None) -> tuple[pd.DataFrame, int]:
    """Read an RTKLIB ``.pos`` solution (lat/lon/height format, GPS time).

    Parameters
    ----------
    path : str or Path
        The solution file.
    week : int, optional
        GPS week whose seconds the times are given in; default the week of the first epoch.

    Returns
    -------
    pos : DataFrame
        :data:`POS_COLUMNS`: ``time`` (s of ``week``), ``lat``, ``lon`` (rad), ``h`` (m, ellipsoidal), ``q``
        (quality flag), ``ns`` (satellites), ``std_n``, ``std_e``, ``std_d`` (m), ``v_n``, ``v_e``, ``v_d``
        (m/s, NED: ``v_d = -vu``), ``std_v_n``, ``std_v_e``, ``std_v_d`` (m/s).
    week : int

    Raises
    ------
    DataError
        Unreadable file, fewer than 21 fields, a bad date, latitude/longitude outside degrees, times not
        increasing.
    """
    path = Path(path)
    try:
        lines = [ln.split() for ln in path.read_text(encoding="ascii").splitlines()
                 if ln.strip() and not ln.lstrip().startswith("%")]
    except (OSError, UnicodeDecodeError) as exc:
        raise DataError(path, "file", "a readable RTKLIB .pos file", str(exc)) from None
    if not lines:
        raise DataError(path, "epochs", "solution lines after the '%' header", "none")
    short = [i for i, f in enumerate(lines) if len(f) < _POS_MIN_FIELDS]
    if short:
        raise DataError(path, "columns", f"at least {_POS_MIN_FIELDS} fields (date time lat lon h Q ns sdn sde sdu "
                        "sdne sdeu sdun age ratio vn ve vu sdvn sdve sdvu): lat/lon/h output with velocities",
                        f"{len(lines[short[0]])} fields on solution line {short[0] + 1}")
    try:
        stamps = np.array([f"{f[0].replace('/', '-')}T{f[1]}" for f in lines], dtype="datetime64[ns]")
        num = np.array([[float(v) for v in f[2:_POS_MIN_FIELDS]] for f in lines])  # [n, 19]
    except ValueError as exc:
        raise DataError(path, "date/values", "'YYYY/MM/DD hh:mm:ss.sss' (GPST) then numbers", str(exc)) from None
    ns = (stamps - np.datetime64("1980-01-06T00:00:00", "ns")).astype(np.int64)  # since the GPS epoch
    week_, tow = week_and_tow(ns // 10**9, (ns % 10**9) / 1e9)
    if week is not None:
        tow = tow + (week_ - week) * SECONDS_PER_WEEK
    check_time(path, "time", tow)
    lat_deg, lon_deg = num[:, 0], num[:, 1]
    if np.abs(lat_deg).max() > 90 or np.abs(lon_deg).max() > 180 or not np.isfinite(num[:, :3]).all():
        raise DataError(path, "latitude/longitude", "degrees (RTKLIB's lat/lon/height output)",
                        f"lat {lat_deg.min():g}..{lat_deg.max():g}, lon {lon_deg.min():g}..{lon_deg.max():g}")
    pos = pd.DataFrame({
        "time": tow, "lat": np.radians(lat_deg), "lon": np.radians(lon_deg), "h": num[:, 2],
        "q": num[:, 3], "ns": num[:, 4], "std_n": num[:, 5], "std_e": num[:, 6], "std_d": num[:, 7],
        # RTKLIB gives north/east/up velocity: down = -up
        "v_n": num[:, 13], "v_e": num[:, 14], "v_d": -num[:, 15],
        "std_v_n": num[:, 16], "std_v_e": num[:, 17], "std_v_d": num[:, 18]}, columns=list(POS_COLUMNS))
    return pos, week_ if week is None else int(week)


def quality_spans(pos: pd.DataFrame, good: int = Q_FIX) -> list[list[float]]:
    """Spans of the epochs whose quality is not ``good``, each bracketed by the good epochs around it.

    Parameters
    ----------
    pos : DataFrame
        Output of :func:`read_pos`.
    good : int
        The quality kept (default RTK fixed).

    Returns
    -------
    list of [t0, t1]
        s; ``t0`` the last good epoch before a run of other epochs (or the run's first epoch at the start of
        the file), ``t1`` the first good one after it (or the run's last epoch at the end).
    """
    t = pos["time"].to_numpy(float)
    bad = pos["q"].to_numpy(float) != good
    spans = []
    k = 0
    while k < len(t):
        if not bad[k]:
            k += 1
            continue
        j = k
        while j + 1 < len(t) and bad[j + 1]:
            j += 1
        spans.append([float(t[max(k - 1, 0)]), float(t[min(j + 1, len(t) - 1)])])
        k = j + 1
    return spans

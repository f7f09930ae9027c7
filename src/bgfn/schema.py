"""The columns of a drive's three tables, defined once (frames and units: ``CONTRIBUTING.md``).

Every table is a pandas DataFrame, one row per epoch, sorted by strictly increasing ``time`` (s). Readers
(:mod:`bgfn.data`), the strapdown INS and the filter (:mod:`bgfn.nav`) and the CSV format of a user's drive
(:mod:`bgfn.data.csv_drive`) all import these tuples; none spells a column list of its own.
"""

from __future__ import annotations

#: Reference (truth) trajectory: geodetic position (rad, rad, m), NED velocity (m/s), ZYX Euler angles (rad).
REFERENCE_COLUMNS: tuple[str, ...] = ("time", "lat", "lon", "h", "v_n", "v_e", "v_d", "roll", "pitch", "yaw")
#: The reference's attitude: all finite, or all NaN for a drive whose reference has no attitude (an RTK-only
#: reference, e.g. ``rtklib-drive0708``); ``bgfn.data.physics.reference_has_attitude`` tells which.
ATTITUDE_COLUMNS: tuple[str, ...] = ("roll", "pitch", "yaw")
#: IMU mean angular rate (rad/s) and specific force (m/s^2) over ``(time[k-1], time[k]]``, body frame.
GYRO_COLUMNS: tuple[str, ...] = ("gyro_x", "gyro_y", "gyro_z")
ACCEL_COLUMNS: tuple[str, ...] = ("accel_x", "accel_y", "accel_z")
IMU_COLUMNS: tuple[str, ...] = ("time",) + GYRO_COLUMNS + ACCEL_COLUMNS
#: GNSS fix: antenna position (rad, rad, m), NED velocity (m/s; NaN when the receiver gives none), NED std (m).
GNSS_VELOCITY_COLUMNS: tuple[str, ...] = ("v_n", "v_e", "v_d")
GNSS_COLUMNS: tuple[str, ...] = ("time", "lat", "lon", "h") + GNSS_VELOCITY_COLUMNS + ("std_n", "std_e", "std_d")
#: What the loosely coupled filter fuses of a fix (position and its std; the velocity is not used).
GNSS_FIX_COLUMNS: tuple[str, ...] = tuple(c for c in GNSS_COLUMNS if c not in GNSS_VELOCITY_COLUMNS)

"""Physically implausible drives fail on loading, naming the file, the column and the likely cause."""

from __future__ import annotations

import numpy as np
import pytest

from bgfn.data import Drive, load_drive, write_csv_drive
from bgfn.data.imu_errors import error_params
from bgfn.data.physics import G, check_drive
from bgfn.errors import DataError
from bgfn.nav.sim import demo_trajectory
from synthetic_drive import exact_drive

pytestmark = pytest.mark.usefixtures("repo_untouched")


@pytest.fixture(scope="module")
def drive():
    return exact_drive(60.0, imu_errors=error_params("mpu6000"), source="demo")


def _imu(d, **cols):
    imu = d.imu.copy()
    for c, f in cols.items():
        imu[c] = f(imu)
    return imu


def _spike(col, value, row=500):
    def f(t):
        v = t[col].to_numpy(copy=True)
        v[row] = value
        return v
    return f


def _in_degrees(ref):
    return ref.assign(lat=np.degrees(ref["lat"]), lon=np.degrees(ref["lon"]))


# (table, change, column named, words of the likely cause)
BAD = {
    "accelerations in g": ("imu", lambda d: _imu(d, **{c: (lambda t, c=c: t[c] / G) for c in ("accel_x", "accel_y",
                                                                                              "accel_z")}),
                           "accel_x/accel_y/accel_z", "in g"),
    "z axis up": ("imu", lambda d: _imu(d, accel_z=lambda t: -t["accel_z"]), "accel_z", "points up"),
    "axes not rotated": ("imu", lambda d: d.imu.assign(accel_x=d.imu["accel_z"], accel_z=d.imu["accel_x"]),
                         "accel_z", "not rotated to the body frame"),
    "rates in deg/s": ("imu", lambda d: _imu(d, **{c: (lambda t, c=c: np.degrees(t[c]) + 3.0)
                                                   for c in ("gyro_x", "gyro_y", "gyro_z")}),
                       "gyro_x/gyro_y/gyro_z", "deg/s"),
    "rates in deg/s with a sharp turn": (   # a value beyond a MEMS gyro's range in rad/s: still a unit mistake
        "imu", lambda d: _imu(d, **{c: (lambda t, c=c: _spike(c, 60.0)(t.assign(**{c: np.degrees(t[c]) + 3.0})))
                                    for c in ("gyro_x", "gyro_y", "gyro_z")}), "gyro_x/gyro_y/gyro_z", "deg/s"),
    "two seconds of +50 m/s^2 on one axis": (
        "imu", lambda d: _imu(d, accel_y=lambda t: t["accel_y"] + np.where(
            (t["time"] > t["time"].iloc[0] + 20) & (t["time"] <= t["time"].iloc[0] + 22), 50.0, 0.0)),
        "accel_y", "stuck, offset or saturated axis"),
    "a spike in the IMU": ("imu", lambda d: _imu(d, accel_y=_spike("accel_y", 2e9)), "accel_x/accel_y/accel_z",
                           "corrupted sample"),
    "a spike in the GNSS height": ("gnss", lambda d: d.gnss.assign(h=_spike("h", 2e9, row=7)), "h", "height"),
    "longitude in degrees": ("gnss", lambda d: d.gnss.assign(lon=np.degrees(d.gnss["lon"])), "lon", "degrees"),
    "reference in degrees near the equator": (   # 1.2 deg N, 0.5 deg E: degrees that pass the radian ranges
        "reference", lambda d: _in_degrees(demo_trajectory(60.0, 100.0, lat0=np.radians(1.2), lon0=np.radians(0.5))),
        "lat/lon", "in degrees"),
    "IMU time in ms": ("imu", lambda d: d.imu.assign(time=d.imu["time"] * 1000.0), "time", "milliseconds"),
    "GNSS on another time base": ("gnss", lambda d: d.gnss.assign(time=d.gnss["time"] + 1e6), "time",
                                  "same time base"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_an_implausible_csv_drive_fails_naming_file_column_and_cause(drive, tmp_path, case):
    table, change, column, cause = BAD[case]
    bad = Drive(drive.name, drive.reference, drive.imu, drive.gnss, drive.meta)
    setattr(bad, table, change(drive))
    folder = write_csv_drive(bad, tmp_path / "mine")
    before = {p.name: p.read_bytes() for p in folder.iterdir()}
    with pytest.raises(DataError) as err:
        load_drive(folder)
    assert err.value.source == str(folder / f"{table}.csv") and err.value.field == column, str(err.value)
    assert cause in str(err.value)
    assert {p.name: p.read_bytes() for p in folder.iterdir()} == before       # nothing written or changed


def test_a_plausible_drive_passes_and_reports_what_it_measured(drive, caplog):
    out = check_drive(drive)
    assert out["f_median_g"] == pytest.approx(1.0, abs=0.05) and out["f_z_median_g"] < -0.9
    assert out["gnss_coverage"] == pytest.approx(1.0, abs=0.02)
    short = drive.gnss[drive.gnss["time"] < drive.gnss["time"].iloc[0] + 20.0]     # a third of the span
    with caplog.at_level("WARNING"):
        out = check_drive(Drive("demo", drive.reference, drive.imu, short, drive.meta))
    assert out["gnss_coverage"] < 0.5 and "pure INS" in caplog.text

"""Notebook 01 helpers: dataset summary (hand-computed values) and outage masks/segments of the plots."""

from __future__ import annotations

import matplotlib

matplotlib.use("Agg")

import numpy as np  # noqa: E402
import pandas as pd  # noqa: E402
import pytest  # noqa: E402

from bgfn.data import Drive  # noqa: E402
from bgfn.data.plots import _segments, in_windows, local_enu, plot_map, plot_trajectory_3d  # noqa: E402
from bgfn.data.summary import summary_table  # noqa: E402
from bgfn.nav.earth import curvature_radii  # noqa: E402


@pytest.fixture()
def drive():
    t = 1000.0 + np.arange(0, 10001) / 100.0  # 100 s at 100 Hz
    lat0, h0 = np.radians(45.0), 200.0
    r_m, _ = curvature_radii(lat0)
    ref = pd.DataFrame({"time": t, "lat": lat0 + 12.0 * (t - t[0]) / (r_m + h0), "lon": np.radians(7.0), "h": h0,
                        "v_n": 12.0, "v_e": 0.0, "v_d": 0.0, "roll": 0.0, "pitch": 0.0, "yaw": 0.0})
    imu = pd.DataFrame({"time": t[1:], **{c: 0.0 for c in ("gyro_x", "gyro_y", "gyro_z", "accel_x", "accel_y")},
                        "accel_z": -9.8})
    gnss = ref.iloc[::100][["time", "lat", "lon", "h"]].assign(v_n=np.nan, v_e=np.nan, v_d=np.nan, std_n=1.0,
                                                               std_e=1.0, std_d=3.0)
    return Drive("line", ref, imu, gnss, {"imu_rate_hz": 100.0, "gnss_rate_hz": 1.0, "lever_arm_m": [0, 0, 0]})


def test_summary_values(drive):
    tab = summary_table(drive).set_index("quantity")["value"]
    assert float(tab["duration"]) == 100.0
    assert float(tab["distance_horizontal"]) == pytest.approx(1.2)  # 12 m/s * 100 s, km
    assert float(tab["speed_max"]) == 12.0 and float(tab["time_stopped_fraction"]) == 0.0
    assert int(tab["imu_samples"]) == 10000 and int(tab["gnss_fixes"]) == 101
    assert tab["gnss_std_neu"] == "[1, 1, 3]"


def test_outage_mask_and_segments(drive):
    t = drive.reference["time"].to_numpy()
    mask = in_windows(t, [(1010.0, 5.0), (1050.0, 30.0)])
    assert mask.sum() == 500 + 3000  # [start, start + duration) at 100 Hz
    segs = _segments(mask)
    assert [(t[a], t[b]) for a, b in segs] == [(1010.0, pytest.approx(1014.99)), (1050.0, pytest.approx(1079.99))]
    enu = local_enu(drive.reference)
    assert enu[-1, 1] == pytest.approx(1200.0, rel=1e-5) and abs(enu[-1, 0]) < 1e-6  # north 1.2 km
    for fig in (plot_trajectory_3d(drive.reference, [(1010.0, 5.0)]),
                plot_map(drive.reference, drive.gnss, [(1010.0, 5.0)])):
        assert any(line.get_color() == "red" for line in fig.axes[0].get_lines())
        matplotlib.pyplot.close(fig)

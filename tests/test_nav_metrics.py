"""Outage metrics, the paper-layout table, the nav: profile section and saved-state files."""

import numpy as np
import pandas as pd
import pytest

from bgfn.errors import DataError
from bgfn.nav import baseline, earth, metrics, outages, sim
from bgfn.nav import state as st


def test_outage_metrics_hand_computed():
    t = np.arange(0.0, 31.0)
    e = pd.DataFrame({"time": 100.0 + t, "east": -0.1 * t, "north": 0.2 * t})
    e["horizontal"] = np.hypot(e["east"], e["north"])
    m = metrics.outage_metrics(e, outages.OutageWindow(100.0, 30.0))
    assert m["max_abs_east"] == pytest.approx(3.0) and m["max_abs_north"] == pytest.approx(6.0)
    assert m["end_east"] == pytest.approx(-3.0) and m["end_horizontal"] == pytest.approx(np.hypot(3, 6))
    assert m["rmse_horizontal"] == pytest.approx(np.hypot(0.1, 0.2) * np.sqrt(np.mean(t ** 2)))
    table = baseline.ins_max_error_file(pd.DataFrame([m, m]))
    assert table["outage"].tolist() == ["Outage 1", "Outage 2"] and table["INS_north_m"].iloc[0] == 6.0
    beside = baseline.ins_layout(pd.DataFrame([m, m]), "turin-sim-mpu6000")     # the field test's INS row
    assert beside.loc["Outage 2", ("paper", "INS", "East")] == 477.5
    assert beside.loc["Outage 1", ("ours", "INS", "North")] == pytest.approx(6.0)


def test_navigation_errors_of_a_shifted_trajectory():
    ref = sim.demo_trajectory(5.0)
    lat, lon, h = earth.ned_to_lla(np.array([3.0, -4.0, 0.5]), ref["lat"].to_numpy(), ref["lon"].to_numpy(),
                                   ref["h"].to_numpy())
    shifted = ref.assign(lat=lat, lon=lon, h=h, yaw=ref["yaw"] + 0.01, v_e=ref["v_e"] + 0.2)
    e = metrics.navigation_errors(shifted, ref)
    np.testing.assert_allclose(e[["north", "east", "down"]].to_numpy(), np.tile([3.0, -4.0, 0.5], (len(e), 1)),
                               atol=1e-6)
    np.testing.assert_allclose(e["horizontal"], 5.0, atol=1e-6)
    np.testing.assert_allclose(e["yaw"], 0.01, atol=1e-12)
    np.testing.assert_allclose(e["v_e"], 0.2, atol=1e-12)
    with pytest.raises(DataError, match="reference rows"):
        metrics.navigation_errors(shifted.assign(time=shifted["time"] + 0.005), ref)


def test_nav_config_and_outage_windows():
    cfg = baseline.nav_config({"init": {"azimuth_std_deg": 5.0}})
    assert cfg["init"]["azimuth_std_deg"] == 5.0 and cfg["init"]["position_std_m"] == 1.0
    assert outages.outage_windows({"outage_windows": [[10, 5], [30, 2.5]]}) == [(10.0, 5.0), (30.0, 2.5)]
    with pytest.raises(DataError, match="outage_windows"):
        outages.outage_windows({"profile": "p"})
    ref = sim.demo_trajectory(20.0)                    # 0..20 s: a window past the end fails, naming the key
    drive = type("D", (), {"name": "demo", "reference": ref, "imu": ref[["time"]]})()
    assert outages.outage_windows({"outage_windows": [[5, 10]]}, drive) == [(5.0, 10.0)]
    with pytest.raises(DataError, match="outage_windows"):
        outages.outage_windows({"outage_windows": [[15, 10]]}, drive)
    with pytest.raises(DataError, match="unknown key"):
        baseline.nav_config({"outage_starts": [1.0]})
    with pytest.raises(DataError, match="unknown key"):
        baseline.nav_config({"init": {"pos_std": 1.0}})


def test_saved_state_file_is_checked(tmp_path):
    s = st.FilterState(1.0, np.array([0.7, 0.1, 5.0]), np.zeros(3), np.eye(3))
    path = st.save_states(tmp_path / "s.npz", {"outage_1": s})
    back = st.load_states(path)["outage_1"]
    assert back.time == 1.0 and back.P.shape == (15, 15)
    np.savez(tmp_path / "bad.npz", names=np.array(["x"]))
    with pytest.raises(DataError, match="format"):
        st.load_states(tmp_path / "bad.npz")
    with pytest.raises(DataError, match="name"):
        st.save_states(tmp_path / "t.npz", {"a/b": s})

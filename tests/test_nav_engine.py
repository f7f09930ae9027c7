"""The filter engine (bgfn.nav.engine): a list of aids, each changing the solution only from its own epochs on; one
position update with a known P and R is the textbook Kalman update (Eq. eq4); ZUPT holds a static IMU still."""

from __future__ import annotations

from dataclasses import dataclass
from types import SimpleNamespace

import numpy as np
import pandas as pd
import pytest

from bgfn.nav import constraints as cn
from bgfn.nav import error_model as em
from bgfn.nav import sim
from bgfn.nav.earth import curvature_radii
from bgfn.nav.engine import Measurement, Stepper
from bgfn.nav.filter import run_filter
from bgfn.nav.gnss_aid import position_fix
from test_nav_constraints import _body_frame, _imu, _road, _start, EKINOX

V_ROWS = np.array(em.DV_NED)


def _velocity_rows(nav, axes, value, std):
    """A velocity measurement of ``axes`` (NED) against ``value``, m/s."""
    H = np.zeros((len(axes), em.N_STATES))
    H[np.arange(len(axes)), V_ROWS[list(axes)]] = 1.0
    return Measurement(nav.v[list(axes)] - value, H, np.full(len(axes), std))


@dataclass
class VelocityAid:
    """A test aid: the NED velocity components ``axes`` equal ``value`` (std ``std``) at the epochs of ``times``;
    ``silent``: it is asked but never answers; ``joint``: it joins the update of the aid before it."""

    times: tuple
    axes: tuple = (0, 1, 2)
    value: float = 0.0
    std: float = 0.1
    silent: bool = False
    joint: bool = False

    def schedule(self, times, source="imu", hold_at=None):
        rows = np.searchsorted(times, np.asarray(self.times) - 1e-9)
        return SimpleNamespace(rows=rows, joint=self.joint, measurement=self.measurement)

    def measurement(self, i, nav):
        return None if self.silent else _velocity_rows(nav, self.axes, self.value, self.std)


@pytest.fixture(scope="module")
def road():
    """A 40 s drive at 10 m/s with a small accelerometer bias, 1 Hz GNSS fixes."""
    ref = _road(np.full(4001, 10.0))
    imu = _imu(ref, accel_x=0.01)
    gnss = sim.gnss_from_trajectory(ref, 1.0, 1.0, 2.0, seed=3)
    init, noise = _start(ref)
    return ref, imu, gnss, init, noise


def _frames(res):
    return (res.trajectory, res.bias, res.sd, res.updates)


def test_an_aid_changes_the_solution_only_from_its_epoch_on(road):
    ref, imu, gnss, init, noise = road
    plain = run_filter(imu, init, noise, gnss)
    t_aid = 12.345
    aided = run_filter(imu, init, noise, gnss, aids=[VelocityAid((t_aid,), value=9.0)])
    row = int(np.searchsorted(plain.trajectory["time"].to_numpy(), t_aid - 1e-9))
    for a, b in zip(_frames(plain)[:3], _frames(aided)[:3]):
        pd.testing.assert_frame_equal(a.iloc[:row], b.iloc[:row], check_exact=True)     # untouched before it
        assert not np.array_equal(a.iloc[row:, 1:].to_numpy(), b.iloc[row:, 1:].to_numpy())
    before = plain.updates["time"] < t_aid
    pd.testing.assert_frame_equal(plain.updates[before], aided.updates[before], check_exact=True)
    assert len(aided.updates) == len(plain.updates)            # an aid's updates are not fixes
    # an aid asked at every second that never answers changes nothing at all, bit for bit
    silent = run_filter(imu, init, noise, gnss, aids=[VelocityAid(tuple(np.arange(1.0, 40.0)), silent=True)])
    for a, b in zip(_frames(plain), _frames(silent)):
        pd.testing.assert_frame_equal(a, b, check_exact=True)
    np.testing.assert_array_equal(plain.P_updates, silent.P_updates)


def test_aids_at_one_epoch_in_list_order_and_joint_rows_in_one_update(road):
    ref, imu, gnss, init, noise = road
    epochs = tuple(np.arange(0.5, 40.0, 1.0))
    north, east = VelocityAid(epochs, (0,), 9.0), VelocityAid(epochs, (1,), 4.0)
    joint = run_filter(imu, init, noise, aids=[north, VelocityAid(epochs, (1,), 4.0, joint=True)])
    both = run_filter(imu, init, noise, aids=[_Stacked(epochs)])
    for a, b in zip(_frames(joint), _frames(both)):
        pd.testing.assert_frame_equal(a, b, check_exact=True)
    # apart (fed back in between), the second is measured from the corrected state: not the same numbers
    apart = run_filter(imu, init, noise, aids=[north, east])
    assert not np.array_equal(apart.trajectory["lat"].to_numpy(), joint.trajectory["lat"].to_numpy())
    assert np.allclose(apart.trajectory["lat"].to_numpy(), joint.trajectory["lat"].to_numpy(), rtol=0, atol=1e-8)


@dataclass
class _Stacked:
    """One aid measuring north (against 9 m/s) and east (against 4 m/s) velocity in one measurement."""

    times: tuple

    def schedule(self, times, source="imu", hold_at=None):
        rows = np.searchsorted(times, np.asarray(self.times) - 1e-9)
        return SimpleNamespace(rows=rows, joint=False, measurement=self.measurement)

    def measurement(self, i, nav):
        a, b = _velocity_rows(nav, (0,), 9.0, 0.1), _velocity_rows(nav, (1,), 4.0, 0.1)
        return Measurement(np.concatenate([a.dz, b.dz]), np.vstack([a.H, b.H]), np.concatenate([a.std, b.std]))


def test_one_position_fix_is_the_textbook_update():
    """Diagonal P (position variance p in m^2 per axis), R = diag(r), no lever arm: each axis moves by the gain
    p / (p + r) of its innovation, its variance becomes p r / (p + r), the NIS is sum dz^2 / (p + r)."""
    ref = _road(np.full(3, 10.0))
    init, noise = _start(ref)
    lat, h = init.pos[0], init.pos[2]
    r_m, r_n = curvature_radii(lat)
    d = np.array([r_m + h, (r_n + h) * np.cos(lat), -1.0])       # rad/rad/m -> NED m
    p_m, r = np.array([4.0, 9.0, 16.0]), np.array([1.0, 2.0, 4.0])
    P = np.diag(np.full(em.N_STATES, 1e-4))
    P[[em.DLAT, em.DLON, em.DH], [em.DLAT, em.DLON, em.DH]] = p_m / d ** 2
    init.P = P
    times = ref["time"].to_numpy(float)
    nav = Stepper(times, np.diff(times), np.zeros((2, 3)), np.zeros((2, 3)), init, noise)
    offset = np.array([3.0, -2.0, 1.5])                          # the fix minus the solution, NED m
    fix = init.pos + offset / d
    nis, accepted, innov = nav.update(position_fix(nav, np.zeros(3), fix, np.sqrt(r), times[0]))
    gain = p_m / (p_m + r)
    assert accepted
    np.testing.assert_allclose((nav.pos - init.pos) * d, gain * offset, rtol=1e-9, atol=1e-9)
    np.testing.assert_allclose(innov, -offset, rtol=1e-9)
    np.testing.assert_allclose(np.diag(nav.P)[[em.DLAT, em.DLON, em.DH]] * d ** 2, p_m * r / (p_m + r), rtol=1e-9)
    assert nis == pytest.approx(np.sum(offset ** 2 / (p_m + r)), rel=1e-9)
    np.testing.assert_array_equal(nav.v, init.v)                 # uncorrelated states stay
    np.testing.assert_array_equal(np.diag(nav.P)[em.DV_NED], np.diag(P)[em.DV_NED])
    # the row's output holds the corrected solution
    np.testing.assert_array_equal(nav.out_pos[0], nav.pos)


def test_zupt_holds_a_static_imu_still_where_the_ins_runs_away():
    """A static IMU with an accelerometer bias the filter does not know: with ZUPT (the stillness detector fires
    at every aid epoch once its window is full) the velocity stays near zero and the position stays put."""
    ref = _road(np.zeros(6001))
    imu = _imu(ref, accel_x=0.02, accel_y=-0.015)
    init, noise = _start(ref)
    con = cn.build_constraints(imu, EKINOX, _body_frame())
    assert np.count_nonzero(con.aid == cn.AID_ZUPT) >= 55 and np.count_nonzero(con.aid == cn.AID_NHC) <= 3
    drift, speed = {}, {}
    for name, aids in (("INS", []), ("ZUPT", [con])):
        tr = run_filter(imu, init, noise, aids=aids).trajectory
        ned = np.column_stack([(tr["lat"] - ref["lat"].iloc[0]) * 6.37e6,
                               (tr["lon"] - ref["lon"].iloc[0]) * 6.37e6 * np.cos(ref["lat"].iloc[0])])
        drift[name] = np.hypot(*ned.T).max()
        speed[name] = np.hypot(tr["v_n"], tr["v_e"]).to_numpy()[tr["time"].to_numpy() > 5.0].max()
    assert drift["INS"] > 20.0 and speed["INS"] > 1.0                  # 0.5 * 0.025 m/s^2 * 60^2 s^2 = 45 m
    # between two ZUPT epochs (1 s) the unknown bias adds at most ~0.025 m/s to a velocity held at 0 +- 0.05 m/s
    assert drift["ZUPT"] < 0.5 and speed["ZUPT"] < 0.1

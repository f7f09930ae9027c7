"""The odometer aid (bgfn.nav.odometer): the forward-speed row is the linearized measurement, a good speed removes
the along-track drift of a biased accelerometer that NHC alone cannot see, a poor speed with a large std changes
almost nothing, and the chi-square gate keeps a wild value out."""

import numpy as np
import pytest

from bgfn.errors import DataError
from bgfn.nav import constraints as cn
from bgfn.nav import error_model as em
from bgfn.nav import odometer as od
from bgfn.nav import transform
from bgfn.nav.engine import Measurement, gated_std
from bgfn.nav.filter import run_filter
from test_nav_constraints import EKINOX, RATE, _body_frame, _cross_along, _imu, _road, _start

SPEED = 12.0


def _along_error(imu, ref, aid):
    init, noise = _start(ref)
    return _cross_along(run_filter(imu, init, noise, aids=od.aid_list(aid)), ref)[1]


def _track(ref, speed, std, rate=1.0):
    t = np.arange(ref["time"].iloc[0], ref["time"].iloc[-1] + 1e-9, 1.0 / rate)
    return od.SpeedTrack(t, np.broadcast_to(np.asarray(speed, float), t.shape).copy(), np.full(t.size, std))


@pytest.fixture(scope="module")
def biased():
    """Straight level road at 12 m/s for 60 s; an unknown forward accelerometer bias of 0.03 m/s^2 (inside the
    filter's prior): unaided, the along-track error grows as b t^2 / 2 = 54 m, which NHC does not observe."""
    ref = _road(np.full(int(60 * RATE) + 1, SPEED))
    imu = _imu(ref, seed=2, accel_x=0.03)
    return ref, imu, cn.build_constraints(imu, EKINOX, _body_frame())


def test_forward_row_is_the_linearized_measurement():
    """computed(x_err) - computed(true) = H x for small velocity and attitude errors (filter's conventions)."""
    rng = np.random.default_rng(4)
    v = np.array([8.0, -5.0, 0.3])
    c = transform.dcm_from_euler(0.02, -0.03, 0.7)
    r_vb = np.empty((3, 3))
    cn.vehicle_rotation_nb(0.01, -0.02, r_vb)
    true, row = od.forward_speed_row(v, c, r_vb)
    dv, phi = rng.normal(0, 0.05, 3), rng.normal(0, 1e-3, 3)
    c_err = (np.eye(3) - em.skew_nb(phi)) @ c                  # C_computed = (I - [phi]) C_true
    computed, _ = od.forward_speed_row(v + dv, c_err, r_vb)
    x = np.zeros(em.N_STATES)
    x[em.DV_NED], x[em.PHI_NED] = dv, phi
    assert computed - true == pytest.approx(row @ x, abs=2e-4)


def test_a_good_speed_removes_the_along_track_drift(biased):
    ref, imu, con = biased
    nhc = _along_error(imu, ref, con)
    odo = _along_error(imu, ref, od.Odometer(con, _track(ref, SPEED, 0.05)))
    assert abs(nhc[-1]) > 40.0                                 # NHC holds the lateral axes only
    assert np.abs(odo).max() < 2.0


def test_a_poor_speed_with_a_large_std_changes_almost_nothing(biased):
    ref, imu, con = biased
    nhc = _along_error(imu, ref, con)
    poor = _along_error(imu, ref, od.Odometer(con, _track(ref, SPEED + 3.0, 50.0)))
    assert np.abs(poor - nhc).max() < 0.05 * np.abs(nhc).max()


def test_the_gate_keeps_a_wild_speed_out(biased):
    ref, imu, con = biased
    track = _track(ref, SPEED, 0.05)
    wild = track.speed.copy()
    wild[20:40] = 60.0                                         # 20 s of nonsense at a claimed 5 cm/s accuracy
    missing = track.speed.copy()
    missing[20:40] = np.nan                                    # the same 20 s without a speed
    gated = _along_error(imu, ref, od.Odometer(con, od.SpeedTrack(track.time, wild, track.std)))
    ungated = _along_error(imu, ref, od.Odometer(con, od.SpeedTrack(track.time, wild, track.std), None))
    without = _along_error(imu, ref, od.Odometer(con, od.SpeedTrack(track.time, missing, track.std)))
    assert np.abs(gated - without).max() < 0.01                # the gate turns the wild values into no values
    assert np.abs(gated).max() < 5.0
    assert np.abs(ungated).max() > 100.0


def test_a_correlated_track_is_fused_as_a_white_one_of_kappa_times_its_variance(biased):
    """R = kappa std^2: a speed whose errors last kappa epochs weighs in the filter as a white one of std
    sqrt(kappa) std, while its own std (what its coverage is scored against) stays as it was."""
    ref, imu, con = biased
    white = _track(ref, SPEED + 0.5, 0.2)                       # 0.5 m/s too fast all along: one correlated error
    lasting = white.correlated(9.0)
    assert np.array_equal(lasting.std, white.std) and lasting.scaled(2.0).correlation == 9.0
    assert lasting.fused_std(0.2) == pytest.approx(0.6)
    same = _along_error(imu, ref, od.Odometer(con, _track(ref, SPEED + 0.5, 0.6)))
    assert np.abs(_along_error(imu, ref, od.Odometer(con, lasting)) - same).max() < 1e-9
    with pytest.raises(DataError, match="correlation"):
        white.correlated(0.5)


def test_gated_std_drops_only_the_rows_beyond_their_threshold():
    P = np.eye(em.N_STATES) * 0.01
    H = np.zeros((3, em.N_STATES))
    H[np.arange(3), em.DV_NED] = 1.0
    std = np.array([0.1, 0.1, 0.1])
    out = gated_std(P, H, np.array([5.0, 5.0, 0.05]), std, np.array([0.0, 10.0, 10.0]))
    # s = 0.01 + 0.01 = 0.02: row 1 (25 / 0.02 = 1250 > 10) out; row 0 has no gate; row 2 (0.125) in
    assert np.isfinite(out[0]) and np.isnan(out[1]) and out[2] == 0.1
    assert Measurement(np.zeros(1), H[:1], std[:1]).gate is None


def test_speed_track_lookup_and_bad_input():
    tr = od.SpeedTrack([10.0, 11.0, 12.0], [1.0, 2.0, 3.0], [0.1, 0.2, 0.3])
    speed, std = tr.at([9.0, 10.0, 11.5, 12.0, 20.0], max_age_s=1.5)
    assert np.isnan(speed[0]) and list(speed[1:4]) == [1.0, 2.0, 3.0] and np.isnan(speed[4])
    assert list(std[1:4]) == [0.1, 0.2, 0.3] and list(tr.scaled(2.0).std) == [0.2, 0.4, 0.6]
    with pytest.raises(DataError, match="increasing"):
        od.SpeedTrack([1.0, 1.0], [0.0, 0.0], [1.0, 1.0])
    with pytest.raises(DataError, match="one length"):
        od.SpeedTrack([1.0], [0.0, 1.0], [1.0])
    with pytest.raises(DataError, match="calibration"):
        tr.scaled(0.0)

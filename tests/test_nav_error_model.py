"""The 15-state error model (Eq. eq9, IVE, IPE) against finite differences of the nonlinear strapdown."""

import numpy as np
import pytest
from scipy.linalg import expm

from bgfn.nav import error_model as em
from bgfn.nav import strapdown, transform


def _errors(pos_c, v_c, c_c, pos_t, v_t, c_t):
    """Error state (computed - true) in the paper's order, without biases."""
    x = np.zeros(em.N_STATES)
    x[em.PHI_NED] = -transform.rotvec_from_dcm(c_c @ c_t.T)  # C_c = (I - [phi]) C_t
    x[em.DV_NED] = v_c - v_t
    x[em.POS] = pos_c - pos_t
    return x


def test_state_order_is_the_papers_eq13():
    assert em.STATE_NAMES[em.PHI_E] == "phi_E" and em.STATE_NAMES[em.DV_D] == "dV_D"
    assert [em.DLAT, em.DLON, em.DH] == [6, 7, 8] and em.BA_X == 9 and em.BG_Z == 14
    assert em.N_STATES == len(set(em.STATE_NAMES)) == 15


@pytest.mark.parametrize("lat_deg", [45.06, -30.0])
def test_system_matrix_matches_finite_differences_of_strapdown(lat_deg):
    pos = np.array([np.radians(lat_deg), 0.13, 420.0])
    v = np.array([12.0, -7.0, 0.8])
    c = transform.dcm_from_euler(0.1, -0.05, 2.0)
    gyro = np.array([0.01, -0.02, 0.15])
    accel = np.array([0.8, 1.1, -9.7])
    dt = 1e-2
    deltas = np.array([1e-5] * 3 + [1e-3] * 3 + [1e-5, 1e-5, 10.0] + [1e-3] * 3 + [1e-5] * 3)

    def step(p, vv, cc, g, a):
        p, vv, cc = p.copy(), vv.copy(), cc.copy()
        strapdown.step_inplace(p, vv, cc, g, a, dt)
        return p, vv, cc

    pt, vt, ct = step(pos, v, c, gyro, accel)
    phi_num = np.zeros((15, 15))
    for j in range(15):
        x0 = np.zeros(15)
        x0[j] = deltas[j]
        pc = pos + x0[em.POS]
        vc = v + x0[em.DV_NED]
        cc = transform.dcm_from_rotvec(-x0[em.PHI_NED]) @ c
        p1, v1, c1 = step(pc, vc, cc, gyro + x0[em.BG], accel + x0[em.BA])
        x1 = _errors(p1, v1, c1, pt, vt, ct)
        x1[em.BA] = x0[em.BA]
        x1[em.BG] = x0[em.BG]
        phi_num[:, j] = x1 / deltas[j]
    f = em.system_matrix(pos, v, c, accel)
    phi = expm(f * dt)
    # Compare each row against its own magnitude (rows mix rad, m/s and rad of latitude).
    scale = np.abs(phi - np.eye(15)).max(axis=1, keepdims=True) + 1e-30
    rel_num, rel = (phi_num - np.eye(15)) / scale, (phi - np.eye(15)) / scale
    other = np.setdiff1d(np.arange(15), em.POS[:2])
    np.testing.assert_allclose(rel_num[other], rel[other], atol=2e-3)
    # Latitude/longitude rows: Eq. (IPE) neglects the derivative of R_M, R_N with latitude (~10 %).
    np.testing.assert_allclose(rel_num[em.POS[:2]], rel[em.POS[:2]], atol=0.15)
    # A few entries by hand: dlat_dot / dV_N = 1/(R_M + h), dh_dot / dV_D = -1, C_bn couples the biases.
    from bgfn.nav.earth import curvature_radii
    r_m, _ = curvature_radii(pos[0])
    assert f[em.DLAT, em.DV_N] == pytest.approx(1 / (r_m + pos[2]))
    assert f[em.DH, em.DV_D] == -1.0
    np.testing.assert_allclose(f[np.ix_(em.DV_NED, em.BA)], c)
    np.testing.assert_allclose(f[np.ix_(em.PHI_NED, em.BG)], -c)


def test_bias_gauss_markov_diagonal():
    f = em.system_matrix([0.7, 0.1, 0.0], [0, 0, 0], np.eye(3), [0, 0, -9.8], tau_a=[2.0, 4.0, 8.0],
                         tau_g=100.0)
    np.testing.assert_allclose(np.diag(f)[em.BA], [-0.5, -0.25, -0.125])
    np.testing.assert_allclose(np.diag(f)[em.BG], [-0.01] * 3)

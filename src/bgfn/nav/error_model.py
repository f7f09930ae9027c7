"""The paper's 15-state INS error model (Sec. 2): state indices, system matrix F, discrete Phi and Q.

State vector, Eq. (eq13), in the paper's order::

    x = [phi_E, phi_N, phi_D, dV_E, dV_N, dV_D, dL, dlambda, dh, nabla_x, nabla_y, nabla_z, eps_x, eps_y, eps_z]

``phi`` the attitude errors (``C_bn_computed = (I - [phi x]) C_bn_true``), ``dV``, ``dL, dlambda, dh`` the velocity
and position errors (computed - true), ``nabla``/``eps`` the accelerometer/gyro bias errors (body frame). F follows
Eqs. (eq9, IVE, IPE) with the normal-gravity variation added to Eq. IVE; the biases are first-order Gauss-Markov
(``tau = inf``: random walk). Discretization per IMU step: ``Phi = I + F dt``, ``Q_d = G Q_c G^T dt`` (Eq. eq3).
"""

from __future__ import annotations

import numba
import numpy as np

from .earth import E2, GAMMA_E, K_SOMIGLIANA, OMEGA_IE
from .strapdown import gravity_nb, radii_nb

# Eq. (eq13), the paper's order.
PHI_E, PHI_N, PHI_D = 0, 1, 2
DV_E, DV_N, DV_D = 3, 4, 5
DLAT, DLON, DH = 6, 7, 8
BA_X, BA_Y, BA_Z = 9, 10, 11
BG_X, BG_Y, BG_Z = 12, 13, 14
N_STATES = 15
#: Names of the states, index order.
STATE_NAMES = ("phi_E", "phi_N", "phi_D", "dV_E", "dV_N", "dV_D", "dL", "dlambda", "dh",
               "nabla_x", "nabla_y", "nabla_z", "eps_x", "eps_y", "eps_z")
#: Index arrays that map NED 3-vectors (north, east, down) onto the paper's (E, N, D) slots.
PHI_NED = np.array([PHI_N, PHI_E, PHI_D])
DV_NED = np.array([DV_N, DV_E, DV_D])
POS = np.array([DLAT, DLON, DH])
BA = np.array([BA_X, BA_Y, BA_Z])
BG = np.array([BG_X, BG_Y, BG_Z])


@numba.njit(cache=True)
def _put(m, rows, cols, block):
    for i in range(3):
        for j in range(3):
            m[rows[i], cols[j]] += block[i, j]


@numba.njit(cache=True)
def skew_nb(a):
    """[a x], the cross-product matrix of a 3-vector (numba; bgfn.nav.transform.skew for numpy)."""
    s = np.zeros((3, 3))
    s[0, 1] = -a[2]
    s[0, 2] = a[1]
    s[1, 0] = a[2]
    s[1, 2] = -a[0]
    s[2, 0] = -a[1]
    s[2, 1] = a[0]
    return s


@numba.njit(cache=True)
def system_matrix_nb(pos, v, c_bn, f_b, inv_tau_a, inv_tau_g, out):
    """Continuous-time system matrix F (15 x 15) of the module docstring, written into ``out``.

    Parameters
    ----------
    pos : ndarray, shape (3,)
        ``[lat, lon, h]`` (rad, rad, m).
    v : ndarray, shape (3,)
        NED velocity, m/s.
    c_bn : ndarray, shape (3, 3)
        Body-to-NED DCM.
    f_b : ndarray, shape (3,)
        Bias-corrected specific force in the body frame, m/s^2.
    inv_tau_a, inv_tau_g : ndarray, shape (3,)
        Inverse bias correlation times, 1/s (0 = random walk).
    out : ndarray, shape (15, 15)
        Overwritten with F.
    """
    out[:, :] = 0.0
    lat, h = pos[0], pos[2]
    r_m, r_n = radii_nb(lat)
    rm_h, rn_h = r_m + h, r_n + h
    sl, cl = np.sin(lat), np.cos(lat)
    tl = sl / cl
    vn, ve = v[0], v[1]
    w_ie = np.array([OMEGA_IE * cl, 0.0, -OMEGA_IE * sl])
    w_en = np.array([ve / rn_h, -vn / rm_h, -ve * tl / rn_h])
    # Partial derivatives of w_ie and w_en (columns: dV_N, dV_E, dV_D | dL | dh).
    dwen_dv = np.zeros((3, 3))
    dwen_dv[0, 1] = 1.0 / rn_h
    dwen_dv[1, 0] = -1.0 / rm_h
    dwen_dv[2, 1] = -tl / rn_h
    dwie_dl = np.array([-OMEGA_IE * sl, 0.0, -OMEGA_IE * cl])
    dwen_dl = np.array([0.0, 0.0, -ve / (rn_h * cl * cl)])
    dwen_dh = np.array([-ve / rn_h ** 2, vn / rm_h ** 2, ve * tl / rn_h ** 2])
    phi, dv, ba, bg = PHI_NED, DV_NED, BA, BG      # module constants: numba bakes them in, no array per step
    # Eq. (eq9): attitude error.
    _put(out, phi, phi, -skew_nb(w_ie + w_en))
    _put(out, phi, dv, dwen_dv)
    for i in range(3):
        out[phi[i], DLAT] += dwie_dl[i] + dwen_dl[i]
        out[phi[i], DH] += dwen_dh[i]
    _put(out, phi, bg, -c_bn)
    # Eq. (IVE): velocity error.
    f_n = c_bn @ f_b
    sv = skew_nb(v)
    _put(out, dv, phi, skew_nb(f_n))
    _put(out, dv, dv, -skew_nb(2.0 * w_ie + w_en) + sv @ dwen_dv)
    t_l = sv @ (2.0 * dwie_dl + dwen_dl)
    t_h = sv @ dwen_dh
    for i in range(3):
        out[dv[i], DLAT] += t_l[i]
        out[dv[i], DH] += t_h[i]
    # dg^n: normal gravity varies with height (free air) and latitude (Somigliana).
    out[DV_D, DH] += -2.0 * gravity_nb(lat, h) / np.sqrt(rm_h * rn_h)
    s2 = sl * sl
    x = 1.0 - E2 * s2
    dg_ds2 = GAMMA_E * (K_SOMIGLIANA / np.sqrt(x) + 0.5 * E2 * (1.0 + K_SOMIGLIANA * s2) / x ** 1.5)
    out[DV_D, DLAT] += dg_ds2 * 2.0 * sl * cl
    _put(out, dv, ba, c_bn)
    # Eq. (IPE): position error (NED, dh_dot = -dV_D).
    out[DLAT, DV_N] = 1.0 / rm_h
    out[DLAT, DH] = -vn / rm_h ** 2
    out[DLON, DV_E] = 1.0 / (rn_h * cl)
    out[DLON, DLAT] = ve * tl / (rn_h * cl)
    out[DLON, DH] = -ve / (rn_h ** 2 * cl)
    out[DH, DV_D] = -1.0
    # Bias models (Gauss-Markov; inv_tau = 0 is a random walk).
    for i in range(3):
        out[ba[i], ba[i]] = -inv_tau_a[i]
        out[bg[i], bg[i]] = -inv_tau_g[i]


@numba.njit(cache=True)
def process_noise_nb(c_bn, q_g, q_a, q_bg, q_ba, dt, out):
    """Discrete process noise ``Q_d = G Q_c G^T dt`` (15 x 15), written into ``out``.

    Parameters
    ----------
    c_bn : ndarray, shape (3, 3)
        Body-to-NED DCM (white sensor noise enters as ``-C eta_g`` and ``C eta_a``).
    q_g, q_a : ndarray, shape (3,)
        Gyro (rad^2/s) and accelerometer ((m/s^2)^2 s) white-noise PSD per body axis
        (noise density squared).
    q_bg, q_ba : ndarray, shape (3,)
        Bias driving-noise PSD per axis, (rad/s)^2/s and (m/s^2)^2/s.
    dt : float
        Step, s.
    out : ndarray, shape (15, 15)
    """
    out[:, :] = 0.0
    phi, dv = PHI_NED, DV_NED
    qg = (c_bn * q_g) @ c_bn.T * dt
    qa = (c_bn * q_a) @ c_bn.T * dt
    _put(out, phi, phi, qg)
    _put(out, dv, dv, qa)
    for i in range(3):
        out[BA_X + i, BA_X + i] = q_ba[i] * dt
        out[BG_X + i, BG_X + i] = q_bg[i] * dt


def system_matrix(pos, v, c_bn, f_b, tau_a=np.inf, tau_g=np.inf):
    """F of the module docstring (Python wrapper of :func:`system_matrix_nb`).

    Parameters
    ----------
    pos : array_like, shape (3,)
        ``[lat, lon, h]`` (rad, rad, m).
    v : array_like, shape (3,)
        NED velocity, m/s.
    c_bn : array_like, shape (3, 3)
    f_b : array_like, shape (3,)
        Specific force, body, m/s^2.
    tau_a, tau_g : float or array_like
        Bias correlation times, s (inf: random walk).

    Returns
    -------
    ndarray, shape (15, 15)
    """
    out = np.empty((N_STATES, N_STATES))
    inv_a = np.broadcast_to(1.0 / np.asarray(tau_a, dtype=float), (3,)).copy()
    inv_g = np.broadcast_to(1.0 / np.asarray(tau_g, dtype=float), (3,)).copy()
    system_matrix_nb(np.asarray(pos, float), np.asarray(v, float), np.ascontiguousarray(c_bn, dtype=float),
                     np.asarray(f_b, float), inv_a, inv_g, out)
    return out

"""WGS84 Earth model: constants, curvature radii, normal gravity, Earth and transport rates.

All functions are vectorized over numpy arrays (broadcasting). Angles in radians, lengths in m.
The navigation frame is NED (north, east, down), see CONTRIBUTING.md.

The radii ``R_M`` (meridian) and ``R_N`` (prime vertical) are the ones of the paper's position error
equation, Eq. (IPE); the rates ``omega_ie^n`` and ``omega_en^n`` are the ones of Eq. (eq9) and Eq. (IVE).
"""

from __future__ import annotations

import numpy as np

#: Semi-major axis of the WGS84 ellipsoid, m.
A = 6378137.0
#: Flattening of the WGS84 ellipsoid.
F = 1.0 / 298.257223563
#: First eccentricity squared of the WGS84 ellipsoid.
E2 = F * (2.0 - F)
#: Semi-minor axis, m.
B = A * (1.0 - F)
#: Earth rotation rate, rad/s.
OMEGA_IE = 7.292115e-5
#: Earth gravitational constant GM (WGS84), m^3/s^2.
GM = 3.986004418e14
#: Normal gravity at the equator, m/s^2.
GAMMA_E = 9.7803253359
#: Normal gravity at the poles, m/s^2.
GAMMA_P = 9.8321849378
#: Somigliana constant k = b*gamma_p / (a*gamma_e) - 1.
K_SOMIGLIANA = B * GAMMA_P / (A * GAMMA_E) - 1.0
#: m = omega^2 a^2 b / GM (WGS84 free-air correction).
M_RATIO = OMEGA_IE ** 2 * A ** 2 * B / GM


def curvature_radii(lat):
    """Meridian and prime-vertical radii of curvature (without height).

    Parameters
    ----------
    lat : array_like
        Geodetic latitude, rad.

    Returns
    -------
    r_m : ndarray
        Meridian radius R_M, m.
    r_n : ndarray
        Prime-vertical radius R_N, m.
    """
    s2 = np.sin(lat) ** 2
    x = 1.0 - E2 * s2
    r_n = A / np.sqrt(x)
    r_m = r_n * (1.0 - E2) / x
    return r_m, r_n


def normal_gravity(lat, h):
    """Magnitude of WGS84 normal gravity: Somigliana formula plus the second-order free-air correction.

    Parameters
    ----------
    lat : array_like
        Geodetic latitude, rad.
    h : array_like
        Ellipsoidal height, m.

    Returns
    -------
    ndarray
        Normal gravity, m/s^2 (positive; in NED the gravity vector is ``[0, 0, g]``).
    """
    s2 = np.sin(lat) ** 2
    g0 = GAMMA_E * (1.0 + K_SOMIGLIANA * s2) / np.sqrt(1.0 - E2 * s2)
    return g0 * (1.0 - 2.0 / A * (1.0 + F + M_RATIO - 2.0 * F * s2) * h + 3.0 / A ** 2 * h ** 2)


def earth_rate_n(lat):
    """Earth rotation rate omega_ie^n in NED.

    Parameters
    ----------
    lat : array_like
        Geodetic latitude, rad.

    Returns
    -------
    ndarray, shape (..., 3)
        rad/s.
    """
    lat = np.asarray(lat, dtype=float)
    return np.stack([OMEGA_IE * np.cos(lat), np.zeros_like(lat), -OMEGA_IE * np.sin(lat)], axis=-1)


def transport_rate_n(lat, h, v_n):
    """Transport rate omega_en^n (rotation of NED relative to the Earth) in NED.

    Parameters
    ----------
    lat : array_like
        Geodetic latitude, rad.
    h : array_like
        Ellipsoidal height, m.
    v_n : array_like, shape (..., 3)
        Velocity in NED, m/s.

    Returns
    -------
    ndarray, shape (..., 3)
        rad/s: ``[v_e/(R_N+h), -v_n/(R_M+h), -v_e tan(lat)/(R_N+h)]``.
    """
    v_n = np.asarray(v_n, dtype=float)
    r_m, r_n = curvature_radii(lat)
    rn_h = r_n + h
    return np.stack([v_n[..., 1] / rn_h, -v_n[..., 0] / (r_m + h), -v_n[..., 1] * np.tan(lat) / rn_h],
                    axis=-1)


def lla_to_ecef(lat, lon, h):
    """Geodetic coordinates to ECEF.

    Parameters
    ----------
    lat, lon : array_like
        rad.
    h : array_like
        m.

    Returns
    -------
    ndarray, shape (..., 3)
        ECEF position, m.
    """
    _, r_n = curvature_radii(lat)
    cl = np.cos(lat)
    return np.stack([(r_n + h) * cl * np.cos(lon), (r_n + h) * cl * np.sin(lon),
                     (r_n * (1.0 - E2) + h) * np.sin(lat)], axis=-1)


def ecef_to_lla(r_e):
    """ECEF to geodetic coordinates (iterative, converged to well below 1 um near the Earth).

    Parameters
    ----------
    r_e : array_like, shape (..., 3)
        ECEF position, m.

    Returns
    -------
    lat, lon, h : ndarray
        rad, rad, m.
    """
    r_e = np.asarray(r_e, dtype=float)
    x, y, z = r_e[..., 0], r_e[..., 1], r_e[..., 2]
    p = np.hypot(x, y)
    lon = np.arctan2(y, x)
    # Bowring's initial guess, then fixed-point iterations on lat (quadratic-like convergence near h=0).
    lat = np.arctan2(z, p * (1.0 - E2))
    for _ in range(5):
        _, r_n = curvature_radii(lat)
        h = p * np.cos(lat) + z * np.sin(lat) - A * A / r_n
        lat = np.arctan2(z, p * (1.0 - E2 * r_n / (r_n + h)))
    _, r_n = curvature_radii(lat)
    h = p * np.cos(lat) + z * np.sin(lat) - A * A / r_n
    return lat, lon, h


def dcm_ecef_to_ned(lat, lon):
    """DCM C_e^n rotating ECEF vectors into the local NED frame.

    Parameters
    ----------
    lat, lon : array_like
        rad.

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    sl, cl = np.sin(lat), np.cos(lat)
    so, co = np.sin(lon), np.cos(lon)
    row_n = np.stack([-sl * co, -sl * so, cl], axis=-1)
    row_e = np.stack([-so, co, np.zeros_like(so)], axis=-1)
    row_d = np.stack([-cl * co, -cl * so, -sl], axis=-1)
    return np.stack([row_n, row_e, row_d], axis=-2)


def lla_to_ned(lat, lon, h, lat0, lon0, h0):
    """Exact NED coordinates of points relative to an origin (via ECEF).

    Parameters
    ----------
    lat, lon, h : array_like
        Points, rad, rad, m.
    lat0, lon0, h0 : float or array_like
        Origin, rad, rad, m.

    Returns
    -------
    ndarray, shape (..., 3)
        North, east, down, m.
    """
    d_e = lla_to_ecef(lat, lon, h) - lla_to_ecef(lat0, lon0, h0)
    return np.einsum("...ij,...j->...i", dcm_ecef_to_ned(lat0, lon0), d_e)


def ned_to_lla(ned, lat0, lon0, h0):
    """Inverse of :func:`lla_to_ned`.

    Parameters
    ----------
    ned : array_like, shape (..., 3)
        North, east, down relative to the origin, m.
    lat0, lon0, h0 : float or array_like
        Origin, rad, rad, m.

    Returns
    -------
    lat, lon, h : ndarray
        rad, rad, m.
    """
    ned = np.asarray(ned, dtype=float)
    c_ne = np.swapaxes(dcm_ecef_to_ned(lat0, lon0), -1, -2)
    r_e = lla_to_ecef(lat0, lon0, h0) + np.einsum("...ij,...j->...i", c_ne, ned)
    return ecef_to_lla(r_e)

"""Attitude representations: Euler angles <-> DCM (paper Eq. cnb), rotation vectors, skew matrices.

Conventions (CONTRIBUTING.md): ZYX Euler angles ``roll`` (gamma), ``pitch`` (theta), ``yaw`` (psi),
yaw clockwise from north; ``C_bn`` rotates body-frame vectors into NED: ``x_n = C_bn @ x_b``.
All functions are vectorized: leading dimensions broadcast, matrices have shape ``(..., 3, 3)``.
"""

from __future__ import annotations

import numpy as np
from scipy.spatial.transform import Rotation


def skew(v):
    """Skew-symmetric (cross-product) matrix: ``skew(a) @ b == cross(a, b)``.

    Parameters
    ----------
    v : array_like, shape (..., 3)

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    v = np.asarray(v, dtype=float)
    z = np.zeros_like(v[..., 0])
    return np.stack([np.stack([z, -v[..., 2], v[..., 1]], axis=-1),
                     np.stack([v[..., 2], z, -v[..., 0]], axis=-1),
                     np.stack([-v[..., 1], v[..., 0], z], axis=-1)], axis=-2)


def dcm_from_euler(roll, pitch, yaw):
    """Body-to-navigation DCM C_b^n from ZYX Euler angles, paper Eq. (cnb).

    Parameters
    ----------
    roll, pitch, yaw : array_like
        rad (broadcast together).

    Returns
    -------
    ndarray, shape (..., 3, 3)
    """
    roll, pitch, yaw = np.broadcast_arrays(*(np.asarray(a, dtype=float) for a in (roll, pitch, yaw)))
    cg, sg = np.cos(roll), np.sin(roll)
    ct, st = np.cos(pitch), np.sin(pitch)
    cp, sp = np.cos(yaw), np.sin(yaw)
    # Eq. (cnb), gamma = roll, theta = pitch, psi = yaw.
    r0 = np.stack([ct * cp, -cg * sp + sg * st * cp, sg * sp + cg * st * cp], axis=-1)
    r1 = np.stack([ct * sp, cg * cp + sg * st * sp, -sg * cp + cg * st * sp], axis=-1)
    r2 = np.stack([-st, sg * ct, cg * ct], axis=-1)
    return np.stack([r0, r1, r2], axis=-2)


def euler_from_dcm(c_bn):
    """ZYX Euler angles from C_b^n (inverse of :func:`dcm_from_euler`).

    Parameters
    ----------
    c_bn : array_like, shape (..., 3, 3)

    Returns
    -------
    roll, pitch, yaw : ndarray
        rad; roll and yaw in (-pi, pi], pitch in [-pi/2, pi/2].
    """
    c = np.asarray(c_bn, dtype=float)
    roll = np.arctan2(c[..., 2, 1], c[..., 2, 2])
    pitch = -np.arcsin(np.clip(c[..., 2, 0], -1.0, 1.0))
    yaw = np.arctan2(c[..., 1, 0], c[..., 0, 0])
    return wrap_angle(roll), pitch, wrap_angle(yaw)


def dcm_from_rotvec(rv):
    """DCM of a rotation vector (Rodrigues formula; accurate for small angles).

    Parameters
    ----------
    rv : array_like, shape (..., 3)
        Rotation vector (axis times angle), rad.

    Returns
    -------
    ndarray, shape (..., 3, 3)
        ``exp(skew(rv))``.
    """
    rv = np.asarray(rv, dtype=float)
    shape = rv.shape[:-1]
    return Rotation.from_rotvec(rv.reshape(-1, 3)).as_matrix().reshape(shape + (3, 3))


def rotvec_from_dcm(c):
    """Rotation vector of a DCM (inverse of :func:`dcm_from_rotvec`, angle in [0, pi]).

    Parameters
    ----------
    c : array_like, shape (..., 3, 3)

    Returns
    -------
    ndarray, shape (..., 3)
        rad.
    """
    c = np.asarray(c, dtype=float)
    shape = c.shape[:-2]
    return Rotation.from_matrix(c.reshape(-1, 3, 3)).as_rotvec().reshape(shape + (3,))


def wrap_angle(angle):
    """Wrap angles to (-pi, pi].

    Parameters
    ----------
    angle : array_like
        rad.

    Returns
    -------
    ndarray
        rad.
    """
    w = np.mod(np.asarray(angle, dtype=float) + np.pi, 2.0 * np.pi) - np.pi
    return np.where(w == -np.pi, np.pi, w)

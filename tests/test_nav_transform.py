"""Attitude representations: paper Eq. (cnb), inverses, rotation vectors."""

import numpy as np
import pytest

from bgfn.nav import transform


def test_dcm_yaw_only_rotates_north_to_heading():
    c = transform.dcm_from_euler(0.0, 0.0, np.pi / 2)
    # Body x (forward) points east when yaw = 90 deg (clockwise from north).
    np.testing.assert_allclose(c @ [1.0, 0.0, 0.0], [0.0, 1.0, 0.0], atol=1e-15)


def test_dcm_is_zyx_product():
    r, p, y = 0.3, -0.2, 2.5
    rz = np.array([[np.cos(y), -np.sin(y), 0], [np.sin(y), np.cos(y), 0], [0, 0, 1]])
    ry = np.array([[np.cos(p), 0, np.sin(p)], [0, 1, 0], [-np.sin(p), 0, np.cos(p)]])
    rx = np.array([[1, 0, 0], [0, np.cos(r), -np.sin(r)], [0, np.sin(r), np.cos(r)]])
    np.testing.assert_allclose(transform.dcm_from_euler(r, p, y), rz @ ry @ rx, atol=1e-15)


def test_euler_roundtrip_vectorized():
    rng = np.random.default_rng(1)
    e = np.stack([rng.uniform(-3, 3, 500), rng.uniform(-1.5, 1.5, 500), rng.uniform(-3, 3, 500)])
    c = transform.dcm_from_euler(*e)
    assert c.shape == (500, 3, 3)
    np.testing.assert_allclose(np.einsum("nij,nkj->nik", c, c), np.broadcast_to(np.eye(3), c.shape),
                               atol=1e-14)
    np.testing.assert_allclose(np.stack(transform.euler_from_dcm(c)), e, atol=1e-12)


def test_rotvec_roundtrip_and_skew():
    rng = np.random.default_rng(2)
    rv = rng.normal(size=(100, 3)) * np.array([[1.0], [1e-6]] * 50)
    np.testing.assert_allclose(transform.rotvec_from_dcm(transform.dcm_from_rotvec(rv)), rv,
                               rtol=1e-12, atol=1e-18)
    a, b = rng.normal(size=3), rng.normal(size=3)
    np.testing.assert_allclose(transform.skew(a) @ b, np.cross(a, b), atol=1e-15)


@pytest.mark.parametrize("angle,expected", [(np.pi, np.pi), (-np.pi, np.pi), (3 * np.pi / 2, -np.pi / 2),
                                            (0.1, 0.1), (-7.0, -7.0 + 2 * np.pi)])
def test_wrap_angle(angle, expected):
    assert transform.wrap_angle(angle) == pytest.approx(expected, abs=1e-15)

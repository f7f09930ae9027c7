"""WGS84 Earth model against published values and exact identities."""

import numpy as np
import pytest

from bgfn.nav import earth, strapdown


def test_radii_published_wgs84():
    # NIMA TR8350.2: R_M(equator) = a(1-e^2), R_N(equator) = a, polar radius a^2/b at the poles.
    r_m, r_n = earth.curvature_radii(np.array([0.0, np.pi / 2]))
    assert r_m[0] == pytest.approx(6335439.327, abs=1e-3)
    assert r_n[0] == pytest.approx(6378137.0, abs=1e-6)
    assert r_m[1] == pytest.approx(6399593.626, abs=1e-3)
    assert r_n[1] == pytest.approx(6399593.626, abs=1e-3)


def test_normal_gravity_published_wgs84():
    g = earth.normal_gravity(np.array([0.0, np.pi / 2, np.pi / 4]), 0.0)
    assert g[0] == pytest.approx(9.7803253359, abs=1e-10)
    assert g[1] == pytest.approx(9.8321849378, abs=1e-9)
    # Somigliana at 45 deg with the published k = 0.00193185265241, e^2 = 0.00669437999013.
    assert g[2] == pytest.approx(9.7803253359 * (1 + 0.00193185265241 * 0.5)
                                 / np.sqrt(1 - 0.00669437999013 * 0.5), abs=1e-9)
    # Free-air gradient near the equator ~ -3.086e-6 s^-2.
    grad = (earth.normal_gravity(0.0, 100.0) - earth.normal_gravity(0.0, 0.0)) / 100.0
    assert grad == pytest.approx(-3.086e-6, rel=2e-3)


def test_numba_kernels_match_vectorized():
    lat = np.radians(np.array([-80.0, -10.0, 0.0, 45.06, 89.0]))
    h = np.array([0.0, 100.0, -30.0, 250.0, 8000.0])
    g = [strapdown.gravity_nb(a, b) for a, b in zip(lat, h)]
    np.testing.assert_allclose(g, earth.normal_gravity(lat, h), rtol=1e-15)
    r = np.array([strapdown.radii_nb(a) for a in lat])
    np.testing.assert_allclose(r, np.stack(earth.curvature_radii(lat), -1), rtol=1e-15)


def test_rates():
    lat = np.radians(45.0)
    w = earth.earth_rate_n(lat)
    assert np.linalg.norm(w) == pytest.approx(earth.OMEGA_IE, rel=1e-15)
    assert w[1] == 0.0 and w[2] < 0  # NED: vertical component points up, i.e. negative down
    # Going east at 10 m/s: rho = [v_e/(R_N+h), 0, -v_e tan(lat)/(R_N+h)].
    r_m, r_n = earth.curvature_radii(lat)
    rho = earth.transport_rate_n(lat, 100.0, np.array([0.0, 10.0, 0.0]))
    np.testing.assert_allclose(rho, [10 / (r_n + 100), 0.0, -10 / (r_n + 100)], rtol=1e-12)
    rho = earth.transport_rate_n(lat, 0.0, np.array([5.0, 0.0, 0.0]))
    np.testing.assert_allclose(rho, [0.0, -5 / r_m, 0.0], rtol=1e-12, atol=0)


def test_lla_ned_roundtrip_and_local_scale():
    rng = np.random.default_rng(0)
    lat0, lon0, h0 = np.radians(45.06), np.radians(7.66), 250.0
    ned = rng.normal(scale=[2000.0, 2000.0, 50.0], size=(200, 3))
    lat, lon, h = earth.ned_to_lla(ned, lat0, lon0, h0)
    np.testing.assert_allclose(earth.lla_to_ned(lat, lon, h, lat0, lon0, h0), ned, atol=1e-7)
    # 1 m north / east near the origin matches the curvature radii.
    r_m, r_n = earth.curvature_radii(lat0)
    lat1, lon1, _ = earth.ned_to_lla(np.array([1.0, 1.0, 0.0]), lat0, lon0, h0)
    assert (lat1 - lat0) * (r_m + h0) == pytest.approx(1.0, abs=1e-6)
    assert (lon1 - lon0) * (r_n + h0) * np.cos(lat0) == pytest.approx(1.0, abs=1e-6)


def test_ecef_roundtrip_extreme():
    lat = np.radians(np.array([-89.9, -45.0, 0.0, 30.0, 89.9]))
    lon = np.radians(np.array([-179.0, -20.0, 0.0, 100.0, 179.9]))
    h = np.array([-100.0, 0.0, 5000.0, 20000.0, 300.0])
    lat2, lon2, h2 = earth.ecef_to_lla(earth.lla_to_ecef(lat, lon, h))
    np.testing.assert_allclose(lat2, lat, atol=1e-13)
    np.testing.assert_allclose(lon2, lon, atol=1e-13)
    np.testing.assert_allclose(h2, h, atol=1e-6)

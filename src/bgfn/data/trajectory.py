"""The 1 Hz NaveGo reference -> a smooth, continuous, self-consistent 100 Hz truth trajectory.

Position: smoothing splines (default degree 5) of north, east and up in a scaled geodetic local frame, a linear map
of ``lat``, ``lon``, ``h``, so the velocity is their exact time derivative in the form the strapdown integrates
(paper Eq. IPE): position and velocity are consistent to rounding, which the strapdown-consistency test relies on.
Attitude: smoothing splines of roll, pitch and unwrapped yaw. Each spline's smoothing factor is ``s = n sigma^2``
(``position_sigma_m``, ``attitude_sigma_rad``): its RMS residual against the 1 Hz samples is about ``sigma``.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
from scipy.interpolate import UnivariateSpline

from bgfn.data.navego import check_time
from bgfn.errors import DataError
from bgfn.nav.earth import curvature_radii
from bgfn.schema import REFERENCE_COLUMNS


def time_grid(t_start: float, t_end: float, rate_hz: float) -> np.ndarray:
    """Epochs ``k / rate_hz`` (integer ``k``) within ``[t_start, t_end]``, s.

    All datasets share this grid, so that their epochs are bit-identical.
    """
    k0, k1 = int(np.ceil(t_start * rate_hz - 1e-9)), int(np.floor(t_end * rate_hz + 1e-9))
    return np.arange(k0, k1 + 1) / rate_hz


def _spline(t: np.ndarray, y: np.ndarray, degree: int, sigma: float, name: str) -> UnivariateSpline:
    if sigma < 0:
        raise DataError("trajectory", name, "a non-negative smoothing sigma", str(sigma))
    return UnivariateSpline(t, y, k=degree, s=t.size * sigma ** 2)


def smooth_reference(ref: pd.DataFrame, *, rate_hz: float = 100.0, degree: int = 5,
                     position_sigma_m: float = 0.05, attitude_sigma_rad: float = 0.002,
                     t_start: float | None = None, t_end: float | None = None) -> tuple[pd.DataFrame, dict]:
    """Smooth a (1 Hz) reference table into a continuous truth at ``rate_hz``.

    Parameters
    ----------
    ref : DataFrame
        Reference table (CONTRIBUTING.md schema), strictly increasing ``time``.
    rate_hz : float
        Output rate, Hz.
    degree : int
        Spline degree (odd, 3 or 5; 5 keeps the specific force and its rate continuous).
    position_sigma_m : float
        Smoothing of north/east/up, m (``s = n sigma^2``).
    attitude_sigma_rad : float
        Smoothing of roll/pitch/yaw, rad.
    t_start, t_end : float, optional
        Span of the output (default: the reference's span), s.

    Returns
    -------
    truth : DataFrame
        Reference table at ``rate_hz`` on :func:`time_grid`.
    fit : dict
        Diagnostics against the input samples: RMS position residual ``pos_rms_m`` (north, east, up),
        RMS velocity difference ``vel_rms_mps`` (n, e, d) to the input's velocity, RMS attitude residual
        ``att_rms_rad`` (roll, pitch, yaw).
    """
    if degree not in (3, 5):
        raise DataError("trajectory", "degree", "3 or 5", str(degree))
    t = ref["time"].to_numpy(float)
    check_time("reference", "time", t)
    lat, lon, h = (ref[c].to_numpy(float) for c in ("lat", "lon", "h"))
    lat0, lon0, h0 = lat[0], lon[0], h[0]
    r_m0, r_n0 = curvature_radii(lat0)
    k_n = r_m0 + h0                  # m per rad of latitude at the origin
    k_e = (r_n0 + h0) * np.cos(lat0)  # m per rad of longitude at the origin
    pos = {"north": (lat - lat0) * k_n, "east": (lon - lon0) * k_e, "up": h - h0}
    spl = {k: _spline(t, v, degree, position_sigma_m, "position_sigma_m") for k, v in pos.items()}
    yaw_u = np.unwrap(ref["yaw"].to_numpy(float))
    att = {"roll": ref["roll"].to_numpy(float), "pitch": ref["pitch"].to_numpy(float), "yaw": yaw_u}
    spl.update({k: _spline(t, v, degree, attitude_sigma_rad, "attitude_sigma_rad") for k, v in att.items()})

    grid = time_grid(t[0] if t_start is None else max(t_start, t[0]),
                     t[-1] if t_end is None else min(t_end, t[-1]), rate_hz)
    if grid.size < 2:
        raise DataError("trajectory", "t_start/t_end", "a span of at least 2 epochs", f"{grid.size}")
    lat_g = lat0 + spl["north"](grid) / k_n
    lon_g = lon0 + spl["east"](grid) / k_e
    h_g = h0 + spl["up"](grid)
    r_m, r_n = curvature_radii(lat_g)
    # Eq. (IPE) inverted: velocity is the exact derivative of the smooth position.
    v_n = spl["north"].derivative()(grid) / k_n * (r_m + h_g)
    v_e = spl["east"].derivative()(grid) / k_e * (r_n + h_g) * np.cos(lat_g)
    v_d = -spl["up"].derivative()(grid)
    yaw = np.mod(spl["yaw"](grid) + np.pi, 2 * np.pi) - np.pi
    truth = pd.DataFrame({"time": grid, "lat": lat_g, "lon": lon_g, "h": h_g, "v_n": v_n, "v_e": v_e,
                          "v_d": v_d, "roll": spl["roll"](grid), "pitch": spl["pitch"](grid), "yaw": yaw},
                         columns=list(REFERENCE_COLUMNS))

    vel_ref = ref[["v_n", "v_e", "v_d"]].to_numpy(float)
    r_m1, r_n1 = curvature_radii(lat)
    vel_fit = np.column_stack([spl["north"].derivative()(t) / k_n * (r_m1 + h),
                               spl["east"].derivative()(t) / k_e * (r_n1 + h) * np.cos(lat),
                               -spl["up"].derivative()(t)])
    fit = {
        "pos_rms_m": [float(np.sqrt(np.mean((spl[k](t) - v) ** 2))) for k, v in pos.items()],
        "vel_rms_mps": np.sqrt(np.mean((vel_fit - vel_ref) ** 2, axis=0)).tolist(),
        "att_rms_rad": [float(np.sqrt(np.mean((spl[k](t) - v) ** 2))) for k, v in att.items()],
    }
    return truth, fit

"""The GNSS fixes against the reference, and the reference's attitude against the IMU and the course (numbers only;
``bgfn.report.data_checks`` words them).

- **Offsets** (:func:`fix_offsets`): each moving fix minus the reference's antenna position (the reference moved by
  the lever arm) at the fix's time, split along the reference's course (positive: the fix ahead) and across it
  (positive: to the right). A fix stamped ``L`` s late sits ``L`` times the speed *behind* the reference.
- **Lag** (:func:`reference_lag`): the shift ``tau`` of the fixes' stamps (the reference read at ``t - tau``) that
  minimises the spread of the along-track offsets about their mean: a lag moves each fix by its speed times the lag,
  a lever arm or a datum by a constant, so the two separate where the speed varies. Its std from a block bootstrap
  over the fixes (errors of a receiver last many seconds). A coarse search over +-``MAX_LAG_S`` on the median
  horizontal distance finds a gross offset (the 18 s between UTC and GPS time) first.
- **Verdict** (:func:`check_reference`): medians and spreads (scaled MAD, 5-95 %), whether every moving fix equals
  the reference to millimetres (the reference *is* the GNSS: a GPS-aided error against it is no accuracy), and a
  cause code when a median offset exceeds the tolerance: ``latency`` (the lag explains it) or
  ``lever_arm_or_datum`` (a constant).
- **Attitude**: :func:`bgfn.nav.reference_attitude.check_attitude` (the filter's start decides with it).
"""

from __future__ import annotations

from dataclasses import asdict, dataclass

import numpy as np
import pandas as pd

from bgfn import settings
from bgfn.data.gnss import antenna_position
from bgfn.nav.earth import lla_to_ned
from bgfn.nav.reference_attitude import check_attitude

#: Every fix within this of the reference (3D): the reference is the GNSS itself, m.
EQUAL_TOLERANCE_M = 0.005
#: A median along- or cross-track offset beyond this draws a warning (the profile's ``data.reference_tolerance_m``;
#: its home: :class:`bgfn.settings.Data`), m.
DEFAULT_TOLERANCE_M: float = settings.defaults("data")["reference_tolerance_m"]
#: A lag explains an offset when it is beyond this many of its std.
LAG_SIGMAS = 3.0
#: Fixes count only above this speed (their along-track direction is the course; a walker's 1.4 m/s passes), m/s.
MIN_SPEED_MPS = 1.0
#: Fewer moving fixes: nothing is estimated.
MIN_FIXES = 20
#: Coarse search of a gross offset: +- this, s, in steps of ``COARSE_STEP_S``; then +- ``FINE_HALF_S`` around it in
#: steps of ``FINE_STEP_S``.
MAX_LAG_S, COARSE_STEP_S, FINE_HALF_S, FINE_STEP_S = 30.0, 0.25, 1.0, 0.01
#: Block bootstrap of the lag: blocks of at least this many seconds of fixes (longer: the residuals' correlation
#: time), this many draws, this seed; fewer blocks: no std.
BLOCK_S, BOOTSTRAP_DRAWS, BOOTSTRAP_SEED, MIN_BLOCKS = 60.0, 200, 0, 4
#: Fixes beyond this many scaled MADs from the median along-track offset are left out of the lag (outliers).
OUTLIER_MADS = 5.0


def _mad(x: np.ndarray) -> float:
    return float(1.4826 * np.median(np.abs(x - np.median(x)))) if x.size else float("nan")


def _antenna_track(reference: pd.DataFrame, lever_arm_m) -> tuple:
    """``(time, lat, lon, h, v_n, v_e)`` of the reference's antenna (:func:`bgfn.data.gnss.antenna_position`)."""
    lat, lon, h = antenna_position(reference, lever_arm_m)
    return (reference["time"].to_numpy(float), lat, lon, h, reference["v_n"].to_numpy(float),
            reference["v_e"].to_numpy(float))


def _interp_reference(track: tuple, t: np.ndarray) -> dict:
    """The antenna track at times ``t`` (linear between its rows; NaN outside its span)."""
    tr = track[0]
    return {key: np.interp(t, tr, col, left=np.nan, right=np.nan)
            for key, col in zip(("lat", "lon", "h", "v_n", "v_e"), track[1:])}


def fix_offsets(reference: pd.DataFrame, gnss: pd.DataFrame, lever_arm_m, shift_s: float = 0.0) -> pd.DataFrame:
    """Each fix against the reference's antenna at ``time - shift_s`` (module docstring).

    Returns
    -------
    DataFrame
        ``time`` (the fix's, s), ``speed_mps`` (the reference's horizontal speed), ``along_m``, ``cross_m``,
        ``up_m`` (fix minus reference); the fixes inside the reference's span with a finite position.
    """
    t = gnss["time"].to_numpy(float)
    r = _interp_reference(_antenna_track(reference, lever_arm_m), t - shift_s)
    ok = np.isfinite(r["lat"]) & np.isfinite(gnss[["lat", "lon", "h"]].to_numpy(float)).all(axis=1)
    d = lla_to_ned(gnss["lat"].to_numpy(float)[ok], gnss["lon"].to_numpy(float)[ok], gnss["h"].to_numpy(float)[ok],
                   r["lat"][ok], r["lon"][ok], r["h"][ok]).reshape(-1, 3)
    speed = np.hypot(r["v_n"][ok], r["v_e"][ok])
    u_n, u_e = r["v_n"][ok] / np.maximum(speed, 1e-9), r["v_e"][ok] / np.maximum(speed, 1e-9)
    return pd.DataFrame({"time": t[ok], "speed_mps": speed, "along_m": d[:, 0] * u_n + d[:, 1] * u_e,
                         "cross_m": -d[:, 0] * u_e + d[:, 1] * u_n, "up_m": -d[:, 2]})


@dataclass(frozen=True)
class Lag:
    """The lag of the fixes against the reference (:func:`reference_lag`): ``lag_s`` (s; positive: the fixes are
    stamped late; NaN: not estimable), its bootstrap ``std_s`` (NaN: too few blocks), the ``fixes`` used, the
    along-track RMS about the mean without and with the lag (``rms_m``, ``rms_at_lag_m``), and ``reason``
    (``None`` or a code: ``too_few_moving_fixes``, ``at_search_edge``)."""

    lag_s: float
    std_s: float
    fixes: int
    rms_m: float
    rms_at_lag_m: float
    reason: str | None = None

    @property
    def estimable(self) -> bool:
        return bool(np.isfinite(self.lag_s))


def _moving(reference, gnss, lever_arm_m) -> np.ndarray:
    off = fix_offsets(reference, gnss, lever_arm_m)
    keep = off["speed_mps"].to_numpy() > MIN_SPEED_MPS
    return off["time"].to_numpy()[keep]


def along_rms(reference: pd.DataFrame, gnss: pd.DataFrame, lever_arm_m, shift_s: float) -> float:
    """RMS of the moving fixes' along-track offsets about their mean with the stamps shifted by ``shift_s``, m."""
    off = fix_offsets(reference, gnss, lever_arm_m, shift_s)
    a = off["along_m"].to_numpy()[off["speed_mps"].to_numpy() > MIN_SPEED_MPS]
    return float(np.sqrt(np.mean((a - a.mean()) ** 2))) if a.size else float("nan")


def _along_matrix(track, gnss_t, fix_lla, taus) -> np.ndarray:
    """Along-track offsets [len(taus), n] of the fixes at ``gnss_t`` for each shift (NaN outside the reference)."""
    out = np.full((len(taus), gnss_t.size), np.nan)
    for k, tau in enumerate(taus):
        r = _interp_reference(track, gnss_t - tau)
        ok = np.isfinite(r["lat"])
        if not ok.any():
            continue
        d = lla_to_ned(*(c[ok] for c in fix_lla), r["lat"][ok], r["lon"][ok], r["h"][ok]).reshape(-1, 3)
        speed = np.maximum(np.hypot(r["v_n"][ok], r["v_e"][ok]), 1e-9)
        out[k, ok] = (d[:, 0] * r["v_n"][ok] + d[:, 1] * r["v_e"][ok]) / speed
    return out


def correlation_time_s(t: np.ndarray, x: np.ndarray) -> float:
    """Integral correlation time of the series ``x`` at times ``t`` (s): ``dt (1 + 2 sum rho_k)`` over the lags up
    to the first negative autocorrelation (``dt`` the median step)."""
    x = np.asarray(x, float) - np.mean(x)
    if x.size < 3 or not np.any(x):
        return 0.0
    acf = np.correlate(x, x, "full")[x.size - 1:] / np.dot(x, x)
    neg = np.flatnonzero(acf[1:] < 0)
    k = int(neg[0]) + 1 if neg.size else x.size
    return float(np.median(np.diff(t)) * (1.0 + 2.0 * acf[1:k].sum()))


def reference_lag(reference: pd.DataFrame, gnss: pd.DataFrame, lever_arm_m) -> Lag:
    """The lag of the fixes' stamps against the reference (module docstring): coarse search on the median
    horizontal distance, then the along-track spread about its mean, its std from a block bootstrap."""
    t_all = gnss["time"].to_numpy(float)
    moving = np.isin(t_all, _moving(reference, gnss, lever_arm_m))
    g = gnss.loc[moving]
    if len(g) < MIN_FIXES:
        return Lag(float("nan"), float("nan"), int(len(g)), float("nan"), float("nan"), "too_few_moving_fixes")
    t = g["time"].to_numpy(float)
    lla = tuple(g[c].to_numpy(float) for c in ("lat", "lon", "h"))
    track = _antenna_track(reference, lever_arm_m)
    coarse = np.arange(-MAX_LAG_S, MAX_LAG_S + COARSE_STEP_S / 2, COARSE_STEP_S)
    med = []
    for tau in coarse:
        r = _interp_reference(track, t - tau)
        ok = np.isfinite(r["lat"])
        if ok.sum() < MIN_FIXES:
            med.append(np.inf)
            continue
        d = lla_to_ned(*(c[ok] for c in lla), r["lat"][ok], r["lon"][ok], r["h"][ok]).reshape(-1, 3)
        med.append(float(np.median(np.hypot(d[:, 0], d[:, 1]))))
    tau0 = float(coarse[int(np.argmin(med))])
    fine = tau0 + np.arange(-FINE_HALF_S, FINE_HALF_S + FINE_STEP_S / 2, FINE_STEP_S)
    a = _along_matrix(track, t, lla, fine)
    a0 = _along_matrix(track, t, lla, [0.0])[0]
    keep = np.isfinite(a).all(axis=0)
    k0 = int(np.argmin(np.abs(fine - tau0)))
    ref_row = a[k0, keep]
    inlier = np.abs(ref_row - np.median(ref_row)) <= OUTLIER_MADS * max(_mad(ref_row), 1e-3)
    cols = np.flatnonzero(keep)[inlier]
    if cols.size < MIN_FIXES:
        return Lag(float("nan"), float("nan"), int(cols.size), float("nan"), float("nan"), "too_few_moving_fixes")
    a = a[:, cols]
    spread = a.var(axis=1)
    k = int(np.argmin(spread))
    rms0 = float(np.nanstd(a0[cols])) if np.isfinite(a0[cols]).all() else float("nan")
    if k in (0, len(fine) - 1):
        return Lag(float("nan"), float("nan"), int(cols.size), rms0, float(np.sqrt(spread[k])), "at_search_edge")
    # block bootstrap: whole blocks drawn with replacement, the lag of each draw; a block spans the residuals'
    # correlation time at least (a receiver's errors last tens of seconds: shorter blocks would understate the std)
    block_s = max(BLOCK_S, 2.0 * correlation_time_s(t[cols], a[k] - a[k].mean()))
    block = np.floor((t[cols] - t[cols][0]) / block_s).astype(int)
    blocks = np.unique(block)
    std = float("nan")
    if blocks.size >= MIN_BLOCKS:
        member = (block[None, :] == blocks[:, None]).astype(float)       # [B, n]
        s1, s2, count = a @ member.T, (a * a) @ member.T, member.sum(axis=1)      # per shift and block
        rng = np.random.default_rng(BOOTSTRAP_SEED)
        draws = np.stack([np.bincount(rng.integers(0, blocks.size, blocks.size), minlength=blocks.size)
                          for _ in range(BOOTSTRAP_DRAWS)]).astype(float)          # [D, B] block counts
        n = draws @ count
        mean = (s1 @ draws.T) / n
        var = (s2 @ draws.T) / n - mean ** 2                              # [shifts, D]
        std = float(max(np.std(fine[np.argmin(var, axis=0)]), FINE_STEP_S / 2))       # at least half a step
    return Lag(float(fine[k]), std, int(cols.size), rms0, float(np.sqrt(spread[k])))


def reference_equals_gnss(reference: pd.DataFrame, gnss: pd.DataFrame, lever_arm_m) -> bool:
    """Whether every fix inside the reference's span sits within :data:`EQUAL_TOLERANCE_M` of the reference's antenna
    (3D): the reference is the GNSS itself (at least :data:`MIN_FIXES` fixes)."""
    tol = EQUAL_TOLERANCE_M
    off = fix_offsets(reference, gnss, lever_arm_m)
    dist = np.sqrt(off["along_m"] ** 2 + off["cross_m"] ** 2 + off["up_m"] ** 2).to_numpy()
    return bool(dist.size >= MIN_FIXES and np.all(dist <= tol))


@dataclass(frozen=True)
class ReferenceCheck:
    """The fixes against the reference (:func:`check_reference`; offsets in m, NaN without moving fixes).

    ``fixes``: moving fixes compared; ``along_median_m``, ``along_mad_m``, ``along_p05_m``, ``along_p95_m`` and the
    same for ``cross``; ``horizontal_median_m``; ``lag_s``, ``lag_std_s``, ``lag_reason`` (:class:`Lag`);
    ``equals_gnss`` (every moving fix within ``EQUAL_TOLERANCE_M``); ``exceeds`` (a median offset beyond
    the tolerance); ``cause`` (``None``, ``latency``, ``lever_arm_or_datum`` or ``equals_gnss``);
    ``tolerance_m``.
    """

    fixes: int
    along_median_m: float
    along_mad_m: float
    along_p05_m: float
    along_p95_m: float
    cross_median_m: float
    cross_mad_m: float
    cross_p05_m: float
    cross_p95_m: float
    horizontal_median_m: float
    lag_s: float
    lag_std_s: float
    lag_reason: str | None
    equals_gnss: bool
    exceeds: bool
    cause: str | None
    tolerance_m: float

    def record(self) -> dict:
        """JSON-ready (``meta["reference_check"]``)."""
        return {k: (None if isinstance(v, float) and not np.isfinite(v) else v) for k, v in asdict(self).items()}


def check_reference(reference: pd.DataFrame, gnss: pd.DataFrame, lever_arm_m, tolerance_m: float | None = None,
                    lag: Lag | None = None) -> ReferenceCheck:
    """The verdict of the module docstring. ``tolerance_m``: the profile's ``data.reference_tolerance_m`` (default
    :data:`DEFAULT_TOLERANCE_M`); ``lag``: :func:`reference_lag` when already computed."""
    tol = float(DEFAULT_TOLERANCE_M if tolerance_m is None else tolerance_m)
    equals = reference_equals_gnss(reference, gnss, lever_arm_m)
    off = fix_offsets(reference, gnss, lever_arm_m)
    off = off[off["speed_mps"] > MIN_SPEED_MPS]
    a, c = off["along_m"].to_numpy(), off["cross_m"].to_numpy()
    nan = float("nan")
    if a.size < MIN_FIXES:
        return ReferenceCheck(int(a.size), *[nan] * 9, nan, nan, "too_few_moving_fixes", equals, False,
                              "equals_gnss" if equals else None, tol)
    lag = lag if lag is not None else reference_lag(reference, gnss, lever_arm_m)
    horizontal = np.hypot(a, c)
    exceeds = bool(abs(np.median(a)) > tol or abs(np.median(c)) > tol)
    cause = None
    if equals:
        cause = "equals_gnss"
    elif exceeds:
        # a lag that moves the fixes by more than the tolerance at the median speed explains the along-track offset
        explained = lag.estimable and abs(lag.lag_s) * float(np.median(off["speed_mps"])) > tol / 2 and \
            (not np.isfinite(lag.std_s) or abs(lag.lag_s) > LAG_SIGMAS * lag.std_s)
        cause = "latency" if explained else "lever_arm_or_datum"
    q = lambda x, p: float(np.percentile(x, p))      # noqa: E731
    return ReferenceCheck(int(a.size), float(np.median(a)), _mad(a), q(a, 5), q(a, 95), float(np.median(c)), _mad(c),
                          q(c, 5), q(c, 95), float(np.median(horizontal)), lag.lag_s, lag.std_s, lag.reason, equals,
                          exceeds, cause, tol)


def drive_checks(drive, tolerance_m: float | None = None, alignment_options: dict | None = None) -> dict:
    """Notebook 01's checks of one drive: ``reference`` (:func:`check_reference` with the profile's
    ``data.reference_tolerance_m``), ``attitude`` (:func:`bgfn.nav.reference_attitude.check_attitude` under
    ``nav.alignment``; None without a reference attitude) and ``clock`` (a CSV drive's ``meta["gnss_offset"]``,
    :func:`bgfn.data.time_offset.decide_clock`; None for a built-in drive)."""
    lever = drive.meta.get("lever_arm_m", [0.0, 0.0, 0.0])
    reference = check_reference(drive.reference, drive.gnss, lever, tolerance_m).record()
    return {"reference": reference, "attitude": check_attitude(drive.reference, drive.imu, alignment_options),
            "clock": drive.meta.get("gnss_offset")}


def checks_table(checks: dict) -> pd.DataFrame:
    """One row per drive of :func:`drive_checks` outputs (``{name: checks}``; ``tables/reference_check.csv``): the
    offsets, the lag, the flags and cause codes, the attitude check and the clock decision (empty where none)."""
    rows = []
    for name, c in checks.items():
        ref, att, clock = c["reference"], c["attitude"] or {}, c["clock"] or {}
        yaw = att.get("yaw_minus_course_deg") or [None] * 3
        level = att.get("level_minus_imu_deg") or [None] * 2
        rows.append({"dataset": name, **{k: ref[k] for k in ("fixes", "along_median_m", "along_mad_m", "along_p05_m",
                                                             "along_p95_m", "cross_median_m", "cross_mad_m",
                                                             "cross_p05_m", "cross_p95_m", "horizontal_median_m",
                                                             "lag_s", "lag_std_s", "equals_gnss", "exceeds", "cause")},
                     "attitude_usable": att.get("usable"), "attitude_reason": att.get("reason"),
                     "yaw_minus_course_median_deg": yaw[0], "yaw_minus_course_p05_deg": yaw[1],
                     "yaw_minus_course_p95_deg": yaw[2], "roll_minus_imu_deg": level[0],
                     "pitch_minus_imu_deg": level[1], "clock_status": clock.get("status"),
                     "clock_applied_s": clock.get("applied_s"), "turn_rate_offset_s": clock.get("turn_rate_s"),
                     "turn_rate_std_s": clock.get("turn_rate_std_s")})
    return pd.DataFrame(rows)

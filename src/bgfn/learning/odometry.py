"""The odometer learning problem (beyond the paper): body-frame IMU windows -> forward speed.

Unlike ``delta_p_gps``, the forward speed does not accumulate, and an IMU window can observe it (centripetal
acceleration over yaw rate in turns, the vibration while rolling, stillness at stops). The inputs are the six raw
IMU channels only, so nothing of the GPS-aided solution leaks into an outage; the target is the GPS-aided
solution's speed along the vehicle's x axis (:func:`forward_speed`). ``RIDGE-ODO`` (:class:`RidgeOdometer`), the bar
a network must clear, is a ridge on per-axis log band energies; the networks read, by default, the same features
over time (:func:`network_inputs`). Networks that predict a speed and its log-variance fit the beta-NLL loss
(:func:`beta_nll`) and one calibration factor on their std (:func:`calibration_factor`, NIS = 1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np
import pandas as pd

from bgfn.errors import DataError
from bgfn.learning.normalize import Normalizer
from bgfn.learning.split import forbidden_intervals, overlaps
from bgfn.learning.windows import gather_windows, windows_ending_at
from bgfn.nav.odometer import SpeedTrack
from bgfn.nav.transform import dcm_from_euler
from bgfn.schema import ACCEL_COLUMNS, GYRO_COLUMNS

#: The odometer's input channels: the raw body-frame IMU.
ODOMETER_CHANNELS: tuple[str, ...] = ACCEL_COLUMNS + GYRO_COLUMNS
#: Frequency bands of :func:`band_energies`, Hz: five log-spaced bands from 0.5 Hz to 50 Hz (the Nyquist
#: frequency of a 100 Hz IMU).
BANDS_HZ: tuple[tuple[float, float], ...] = tuple(zip(np.geomspace(0.5, 50.0, 6)[:-1], np.geomspace(0.5, 50.0, 6)[1:]))

#: What the odometer networks read (:func:`network_inputs`; ``evaluate.odometer.inputs``).
ODOMETER_INPUTS: tuple[str, ...] = ("imu", "band_frames")
#: Frames of :func:`band_frames`, s: 0.4 s (a 2.5 Hz resolution) every 0.2 s, 9 frames of a 2 s window.
FRAME_S, HOP_S = 0.4, 0.2
#: Bands per frame of :func:`band_frames` (:func:`frame_bands`).
FRAME_N_BANDS = 4


def forward_speed(solution: pd.DataFrame, mount: np.ndarray | None = None) -> np.ndarray:
    """Forward speed in the vehicle frame of every row of a solution (reference schema: ``roll, pitch, yaw`` rad,
    ``v_n, v_e, v_d`` m/s), m/s.

    ``mount`` [n, 2] or [2]: the mounting tangents (yaw, pitch) of the vehicle's x axis in the body frame
    (:func:`bgfn.nav.constraints.mounting_track`); None: the body x axis.
    """
    need = ("roll", "pitch", "yaw", "v_n", "v_e", "v_d")
    missing = [c for c in need if c not in solution.columns]
    if missing:
        raise DataError("solution", missing[0], "a column of the reference schema", "missing")
    c_bn = dcm_from_euler(*(solution[k].to_numpy(float) for k in ("roll", "pitch", "yaw")))     # [n, 3, 3]
    v_n = solution[["v_n", "v_e", "v_d"]].to_numpy(float)
    v_b = np.einsum("nji,nj->ni", c_bn.reshape(-1, 3, 3), v_n)                                # C_bn^T v^n
    tan = np.zeros((len(v_b), 2)) if mount is None else np.broadcast_to(np.asarray(mount, float), (len(v_b), 2))
    u = np.column_stack([np.ones(len(v_b)), tan])
    u /= np.linalg.norm(u, axis=1, keepdims=True)
    return np.einsum("ni,ni->n", u, v_b)


@dataclass
class SpeedWindows:
    """IMU windows ending at epochs and the forward speed there.

    Attributes
    ----------
    x : ndarray [M, N, 6] float32
        Raw body-frame IMU windows (:data:`ODOMETER_CHANNELS`).
    speed : ndarray [M]
        Target forward speed, m/s (NaN when unknown: an outage).
    t_end : ndarray [M]
        The epoch each window ends at, s.
    t_start : ndarray [M]
        Start of the window's first sample interval, s.
    """

    x: np.ndarray
    speed: np.ndarray
    t_end: np.ndarray
    t_start: np.ndarray

    def __len__(self) -> int:
        return len(self.x)

    def subset(self, idx) -> "SpeedWindows":
        """The windows at integer/boolean index ``idx``."""
        return SpeedWindows(self.x[idx], self.speed[idx], self.t_end[idx], self.t_start[idx])

    @property
    def span(self) -> tuple[np.ndarray, np.ndarray]:
        """Time span ``[lo, hi]`` each window touches, s (its inputs; the target is at its end)."""
        return self.t_start, self.t_end

    @property
    def y(self) -> np.ndarray:
        """The targets as a column [M, 1] (what a training run's data fingerprint reads)."""
        return self.speed[:, None]


@dataclass
class SpeedData:
    """Training and validation windows of a learned odometer and their standardization (training windows only).

    Attributes
    ----------
    train, val : SpeedWindows
    norm : Normalizer
        Per-channel input and speed standardization (``y_mean``/``y_std`` of length 1).
    options : dict
        ``window`` (IMU samples), ``margin_s``, ``val_fraction`` and ``objective: speed``.
    info : dict
        Window counts of the split.
    calibration : SpeedWindows or None
        Held-out windows that only calibrate the odometer's std (its factor and its correlation), which early
        stopping never sees (:func:`build_speed_data` with ``calibration_blocks``); None: ``val`` does both.
    """

    train: SpeedWindows
    val: SpeedWindows
    norm: Normalizer
    options: dict
    info: dict
    calibration: SpeedWindows | None = None

    @property
    def calibration_windows(self) -> SpeedWindows:
        """The windows the std is calibrated on: :attr:`calibration`, else :attr:`val`."""
        return self.val if self.calibration is None else self.calibration


def build_speed_data(ws: SpeedWindows, outage_windows=(), margin_s: float = 30.0,
                     val_fraction: float = 0.2, val_blocks: int = 1, calibration_blocks: bool = False) -> SpeedData:
    """The honest split of speed windows ``ws`` (sorted by time): windows touching an outage +- ``margin_s`` are
    dropped, ``val_fraction`` of the rest is validation, and training windows touching it are dropped too; the
    normalizer is fitted on the training windows.

    The validation windows form ``val_blocks`` equal blocks, centred at the ``(k + 1/2) / val_blocks`` quantiles of
    the remaining windows (1: the middle block, as the increments' split). The odometer's std is calibrated on
    them (:func:`calibration_factor`), so several blocks spread over the drive are meant to hold its situations
    (cruise, turns, stops) rather than one stretch of it, which may be all cruise.

    With ``calibration_blocks`` (and two blocks or more) every other block (the 2nd, the 4th ...) becomes
    :attr:`SpeedData.calibration` instead: the std is then calibrated on windows that did not choose the network's
    epoch, whose residuals early stopping has not made small (the others stay ``val``)."""
    lo_, hi_ = ws.span
    idx = np.flatnonzero(~overlaps(lo_, hi_, forbidden_intervals(outage_windows, margin_s)) & np.isfinite(ws.speed))
    n_val = max(1, int(round(val_fraction * idx.size)))
    # val_blocks blocks of n_val / val_blocks windows each, centred at the (k + 1/2) / val_blocks quantiles
    sizes = np.diff(np.round(np.linspace(0, n_val, val_blocks + 1)).astype(int))
    centres = ((np.arange(val_blocks) + 0.5) / val_blocks * idx.size).astype(int)
    parts = [idx[max(0, min(c - n // 2, idx.size - n)):][:n] for c, n in zip(centres, sizes) if n > 0]
    val = np.unique(np.concatenate(parts))
    if val.size == 0 or idx.size - val.size < 2:
        raise DataError("train", "windows", "at least 2 training and 1 validation speed window outside the outages",
                        f"{idx.size} in all")
    block = np.array([[ws.t_start[p].min(), ws.t_end[p].max()] for p in parts])
    train = idx[~overlaps(lo_[idx], hi_[idx], block)]
    cal = None
    if calibration_blocks and len(parts) > 1:
        val, cal = np.unique(np.concatenate(parts[0::2])), np.unique(np.concatenate(parts[1::2]))
    tr, va = ws.subset(train), ws.subset(val)
    norm = speed_normalizer(tr)
    options = {"window": int(ws.x.shape[1]), "margin_s": float(margin_s), "val_fraction": float(val_fraction),
               "objective": "speed"}
    return SpeedData(tr, va, norm, options, {"n_train": int(train.size), "n_val": int(val.size),
                                             "n_calibration": 0 if cal is None else int(cal.size),
                                             "n_outage_excluded": int(ws.x.shape[0] - idx.size)},
                     None if cal is None else ws.subset(cal))


def frame_bands(rate_hz: float, frame_s: float = FRAME_S, n_bands: int = FRAME_N_BANDS) -> tuple:
    """The bands of :func:`band_frames`, Hz: ``n_bands`` log-spaced from a frame's frequency resolution
    ``1 / frame_s`` to the Nyquist frequency ``rate_hz / 2``."""
    edges = np.geomspace(1.0 / frame_s, rate_hz / 2.0, n_bands + 1)
    return tuple(zip(edges[:-1], edges[1:]))


def band_frames(x: np.ndarray, rate_hz: float, frame_s: float = FRAME_S, hop_s: float = HOP_S,
                bands=None) -> np.ndarray:
    """The odometer networks' front end (``evaluate.odometer.inputs: band_frames``): each window ``x`` [M, N, C]
    cut into frames of ``frame_s`` every ``hop_s`` seconds, and per frame each channel's mean and its log mean
    power in each band (:func:`frame_bands`; :func:`band_energies` on the frame).

    Returns
    -------
    ndarray [M, T, C * (1 + B)] float32
        T frames in time order; per frame the C means, then the C log powers of each band in turn.
    """
    x = np.asarray(x, dtype=float)
    frame, hop = int(round(frame_s * rate_hz)), max(1, int(round(hop_s * rate_hz)))
    if frame < 2 or frame > x.shape[1]:
        raise DataError("odometer", "inputs", f"frames of 2 to {x.shape[1]} IMU samples (band_frames, "
                        f"{frame_s:g} s at {rate_hz:g} Hz)", f"{frame} samples")
    starts = np.arange(0, x.shape[1] - frame + 1, hop)
    frames = np.stack([x[:, s:s + frame, :] for s in starts], axis=1)                      # [M, T, F, C]
    m, t, f, c = frames.shape
    power = band_energies(frames.reshape(m * t, f, c), rate_hz,
                          bands or frame_bands(rate_hz, frame_s)).reshape(m, t, c, -1)       # [M, T, C, B]
    means = frames.mean(axis=2)                                                             # [M, T, C]
    return np.concatenate([means, power.transpose(0, 1, 3, 2).reshape(m, t, -1)], axis=-1).astype(np.float32)


def network_inputs(ws: SpeedWindows, inputs: str, rate_hz: float) -> SpeedWindows:
    """The windows as the odometer networks read them (``evaluate.odometer.inputs``): ``imu``, the raw body-frame
    samples [M, N, 6]; ``band_frames``, :func:`band_frames` of them [M, T, 30]. The same for every network, for
    training, the outages and the energy audit."""
    if inputs == "imu":
        return ws
    if inputs == "band_frames":
        return SpeedWindows(band_frames(ws.x, rate_hz), ws.speed, ws.t_end, ws.t_start)
    raise DataError("evaluate.odometer", "inputs", f"one of {ODOMETER_INPUTS}", repr(inputs))


def speed_normalizer(train: SpeedWindows) -> Normalizer:
    """Per-channel input and speed standardization fitted on the training windows ``train``."""
    x = train.x.reshape(-1, train.x.shape[-1]).astype(np.float64)
    return Normalizer(x.mean(0), np.maximum(x.std(0), 1e-8), np.array([train.speed.mean()]),
                      np.array([max(float(train.speed.std()), 1e-8)]))


def with_inputs(data: SpeedData, inputs: str, rate_hz: float) -> SpeedData:
    """``data``'s split as the odometer networks read it (:func:`network_inputs`): the same training, validation and
    calibration windows through the front end, the input standardization refit on them, ``options['inputs']`` set."""
    tr, va = network_inputs(data.train, inputs, rate_hz), network_inputs(data.val, inputs, rate_hz)
    cal = None if data.calibration is None else network_inputs(data.calibration, inputs, rate_hz)
    return SpeedData(tr, va, speed_normalizer(tr), {**data.options, "inputs": inputs}, data.info, cal)


def inner_speed_split(data: SpeedData, fraction: float = 0.2) -> SpeedData:
    """A tuning split inside ``data.train`` (the speed twin of :func:`bgfn.learning.inner_split`): its middle
    ``fraction`` becomes the validation block, training windows touching it are dropped, the normalizer is refit.
    A learning rate chosen on it never sees ``data.val``, the block the odometer's std is calibrated on."""
    inner = build_speed_data(data.train, (), 0.0, fraction)
    return SpeedData(inner.train, inner.val, inner.norm, {**data.options, **{"val_fraction": float(fraction)}},
                     {**inner.info, "inner_of": "train"})


def window_samples(imu: pd.DataFrame, window_s: float) -> tuple[int, float]:
    """(IMU samples in a window of ``window_s`` seconds, the IMU rate in Hz) of a drive's IMU table: the odometer's
    window (``evaluate.odometer.window_s``), the same for the ridge, the networks and the energy audit."""
    rate = 1.0 / float(np.median(np.diff(imu["time"].to_numpy(float))))
    return int(round(float(window_s) * rate)), rate


def speed_windows(imu: pd.DataFrame, epochs, window: int, speed=None) -> SpeedWindows:
    """The IMU windows of ``window`` samples ending at each of ``epochs`` (s) that are complete (no gap, no NaN),
    with ``speed`` at those epochs (NaN when not given)."""
    if window < 2:
        raise DataError("train", "window", "at least 2 IMU samples", str(window))
    t = imu["time"].to_numpy(float)
    feats = imu[list(ODOMETER_CHANNELS)].to_numpy(float)
    epochs = np.asarray(epochs, dtype=float)
    last, ok = windows_ending_at(t, feats, epochs, window)
    sp = np.full(epochs.size, np.nan) if speed is None else np.asarray(speed, dtype=float)
    last, ep, sp = last[ok], epochs[ok], sp[ok]
    return SpeedWindows(gather_windows(feats, last, window), sp, ep, t[last - window])


def band_energies(x: np.ndarray, rate_hz: float, bands=BANDS_HZ) -> np.ndarray:
    """Log mean power of every channel of the windows ``x`` [M, N, C] in each band (Hz), after removing each
    window's mean: features [M, C * len(bands)], channel-major. A band with no frequency bin of the window
    (too short a window for its lowest band) is an error naming the band."""
    x = np.asarray(x, dtype=float)
    n = x.shape[1]
    spec = np.abs(np.fft.rfft(x - x.mean(axis=1, keepdims=True), axis=1)) ** 2 / n          # [M, F, C]
    freq = np.fft.rfftfreq(n, 1.0 / rate_hz)
    out = []
    for lo, hi in bands:
        sel = (freq >= lo) & (freq < hi) if hi < freq[-1] else (freq >= lo)
        if not sel.any():
            raise DataError("odometer", "bands", f"frequency bins of a {n}-sample window at {rate_hz:g} Hz",
                            f"none in {lo:.2f}-{hi:.2f} Hz")
        out.append(np.log(spec[:, sel, :].mean(axis=1) + 1e-12))                             # [M, C]
    return np.stack(out, axis=-1).reshape(len(x), -1)                                        # [M, C * B]


#: Longest lag of :func:`error_correlation`, s: the validation blocks last about 15 s, so longer lags have few pairs.
DEFAULT_MAX_LAG_S = 10.0
#: Fewest pairs of windows a lag of :func:`error_correlation` needs to count.
MIN_LAG_PAIRS = 10


def error_correlation(t_end, residuals, std, step_s: float = 1.0, max_lag_s: float = DEFAULT_MAX_LAG_S,
                      min_pairs: int = MIN_LAG_PAIRS) -> float:
    """The integrated autocorrelation ``kappa = 1 + 2 sum_k rho_k`` of an odometer's normalized errors
    ``z = residuals / std`` on held-out windows ending at ``t_end`` (s), the epochs ``step_s`` apart (the aid rate):
    how many consecutive epochs carry the information of one independent measurement.

    ``rho_k = mean(z_i z_j) / mean(z^2)`` over the pairs of windows ``k step_s`` apart (both held out: a block's
    inside), about zero, not the mean, because a shared offset is an error the filter cannot average away either.
    The sum stops before the first lag whose ``rho_k <= 0`` (Geyer's initial positive sequence, as for an MCMC
    chain's effective sample size), at ``max_lag_s``, or where fewer than ``min_pairs`` pairs are left. White
    errors give 1; an AR(1) error of coefficient ``phi`` gives about ``(1 + phi) / (1 - phi)``. The filter fuses
    each speed with ``R = kappa std^2`` (:class:`bgfn.nav.odometer.SpeedTrack`), so that ``kappa`` correlated
    epochs weigh as much as one independent one; non-finite pairs are left out, and 1 is returned when no lag has
    enough pairs."""
    t, r, s = (np.asarray(a, dtype=float).ravel() for a in (t_end, residuals, std))
    ok = np.isfinite(t) & np.isfinite(r) & np.isfinite(s) & (s > 0)
    t, z = t[ok], r[ok] / s[ok]
    if z.size < 2 or not np.any(z):
        return 1.0
    step = np.round(t / step_s).astype(np.int64)              # epoch numbers on the aid grid
    where = {int(e): i for i, e in enumerate(step)}
    power = float(np.mean(z ** 2))
    total = 0.0
    for k in range(1, int(np.floor(max_lag_s / step_s + 1e-9)) + 1):
        pairs = np.array([(i, where[int(e) + k]) for i, e in enumerate(step) if int(e) + k in where], dtype=np.int64)
        if len(pairs) < min_pairs:
            break
        rho = float(np.mean(z[pairs[:, 0]] * z[pairs[:, 1]])) / power
        if rho <= 0:
            break
        total += rho
    return 1.0 + 2.0 * total


@dataclass
class RidgeOdometer:
    """``RIDGE-ODO``: ridge regression of the forward speed on :func:`band_energies` (module docstring).

    Attributes
    ----------
    mean, scale : ndarray [F]
        Standardization of the features (training windows).
    coef : ndarray [F]
    intercept : float
    std_mps : float
        RMS of the validation residuals, m/s: the std every prediction carries.
    rate_hz : float
        IMU rate the features were computed at.
    alpha : float
        Ridge penalty on the standardized features.
    correlation : float
        The integrated autocorrelation of its validation residuals (:func:`error_correlation`, >= 1).
    """

    mean: np.ndarray
    scale: np.ndarray
    coef: np.ndarray
    intercept: float
    std_mps: float
    rate_hz: float
    alpha: float
    correlation: float = 1.0

    @classmethod
    def fit(cls, train: SpeedWindows, val: SpeedWindows, rate_hz: float, alpha: float = 1.0,
            max_lag_s: float = DEFAULT_MAX_LAG_S) -> "RidgeOdometer":
        """Fit on ``train`` (closed form), the std and the correlation (up to ``max_lag_s``) from the residuals on
        ``val``."""
        if len(train) < 2 or len(val) < 1:
            raise DataError("odometer", "windows", "at least 2 training and 1 validation window",
                            f"{len(train)} and {len(val)}")
        f = band_energies(train.x, rate_hz)
        mean, scale = f.mean(axis=0), f.std(axis=0)
        scale = np.where(scale > 0, scale, 1.0)
        z = (f - mean) / scale
        y = train.speed - train.speed.mean()
        coef = np.linalg.solve(z.T @ z + alpha * np.eye(z.shape[1]), z.T @ y)
        model = cls(mean, scale, coef, float(train.speed.mean()), float("nan"), float(rate_hz), float(alpha))
        residuals = model.predict(val) - val.speed
        model.std_mps = float(np.sqrt(np.mean(residuals ** 2)))
        model.correlation = error_correlation(val.t_end, residuals, np.full(residuals.size, model.std_mps),
                                              max_lag_s=max_lag_s)
        return model

    def predict(self, ws: SpeedWindows) -> np.ndarray:
        """Forward speed of each window, m/s (never negative: a car's odometer)."""
        z = (band_energies(ws.x, self.rate_hz) - self.mean) / self.scale
        return np.maximum(z @ self.coef + self.intercept, 0.0)

    def track(self, ws: SpeedWindows) -> SpeedTrack:
        """The prediction of each window at the epoch it ends at, each with the validation std (a filter's aid),
        and the validation residuals' :attr:`correlation`."""
        pred = self.predict(ws)
        return SpeedTrack(ws.t_end, pred, np.full(pred.size, self.std_mps), self.correlation)


def beta_nll(mean, log_var, target, beta: float = 0.5):
    """Gaussian negative log-likelihood of ``target`` under ``N(mean, exp(log_var))``, each sample's term weighted
    by its own variance to the power ``beta`` (Seitzer et al. 2022, beta-NLL), averaged; torch tensors [M].

    With ``beta = 0`` it is the plain NLL, where a network can "explain away" a hard sample by a large variance
    and stop fitting its mean; ``beta = 1`` weights every sample like the MSE does for the mean. The weight is
    detached (a factor, not a path for the gradient), as in the paper that proposes it.
    """
    var = log_var.exp()
    nll = 0.5 * (log_var + (target - mean) ** 2 / var)
    return (nll * var.detach() ** beta).mean() if beta else nll.mean()


def ensemble_speed(speeds, stds) -> tuple[np.ndarray, np.ndarray]:
    """The equal-weight ensemble of M odometers (a deep ensemble: Lakshminarayanan et al., 2017): ``speeds`` and
    ``stds`` [M, K] (m/s) -> the mean speed [K] and the std of the Gaussian mixture [K],
    ``sqrt(mean(std^2) + var(speed))``: the members' own uncertainty plus their disagreement, which a single
    network's std cannot know of (population variance over the members)."""
    v, s = np.asarray(speeds, dtype=float), np.asarray(stds, dtype=float)
    if v.ndim != 2 or v.shape != s.shape or v.shape[0] < 2:
        raise DataError("odometer", "ensemble", "speeds and stds [M, K] of at least 2 members", f"{v.shape}, {s.shape}")
    return v.mean(axis=0), np.sqrt((s ** 2).mean(axis=0) + v.var(axis=0))


def calibration_factor(residuals, std) -> float:
    """The one factor on a predicted std that makes the normalized residuals' mean square 1 on held-out windows
    (NIS = 1 for a scalar measurement): ``sqrt(mean((r / std)^2))``; non-finite pairs are left out."""
    r, s = np.asarray(residuals, dtype=float), np.asarray(std, dtype=float)
    ok = np.isfinite(r) & np.isfinite(s) & (s > 0)
    if not ok.any():
        raise DataError("odometer", "calibration", "held-out residuals with a positive std", "none")
    return float(np.sqrt(np.mean((r[ok] / s[ok]) ** 2)))

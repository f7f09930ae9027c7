"""The fleet's drives made comparable before a learned odometer trains on some and is tested on others.

Each step returns its numbers per drive (:data:`PREPARATION_COLUMNS`):

- mounting: the CSV loader already turns the IMU into the body frame by ``meta.yaml``'s ``imu_mounting_deg``
  (:func:`bgfn.data.csv_drive.rotate_imu`); the angles are recorded;
- levelling, accelerometer scale and gyro bias from the drive's standstills (reference speed under
  ``stationary_max_speed_mps`` for at least ``stationary_min_s``): the gyro's mean there is its bias; the
  accelerometer is scaled so that the specific force's mean norm there is ``gravity_mps2``; the IMU is rotated by
  the roll and pitch that turn that mean to ``[0, 0, -g]`` (the tilt of the mount, with the mean road slope of the
  standstills). A drive without a standstill is left as it is, said so (``standstill_s`` 0);
- one sample rate (``rate_hz``, null: the lowest of the fleet; :func:`scipy.signal.resample_poly`, whose
  anti-alias filter cuts at the new Nyquist frequency) and one bandwidth: every drive, the slowest too, low-passed
  at ``bandwidth_fraction`` of that Nyquist frequency (zero-phase Butterworth);
- the platform: a fleet is one vehicle's drives, run with the car's non-holonomic constraint (INS+NHC is the row the
  learned odometer is judged against); a drive whose ``meta.yaml`` names a platform without it (``walker``,
  ``other``: :data:`bgfn.nav.constraints.PLATFORM_AIDS`) is refused, at the profile check when its folder is there,
  else when the drives are loaded, before any preparation;
- the speed label: the reference's horizontal speed, checked against the GNSS speed; a stretch of at least
  ``label_min_s`` where they differ by more than ``label_max_diff_mps`` is left out (``drop``) or labelled from
  the GNSS speed (``gnss``); a drive without GNSS velocities is labelled unchecked.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from fractions import Fraction

import numpy as np
import pandas as pd
from scipy.signal import butter, resample_poly, sosfiltfilt

from bgfn.config import file_setting
from bgfn.data import Drive, dataset_id, load_drive
from bgfn.data.csv_meta import META_FILE, read_meta
from bgfn.data.names import dataset_folder, registered
from bgfn.errors import DataError
from bgfn.nav.constraints import DEFAULT_PLATFORM, PLATFORM_AIDS
from bgfn.nav.transform import dcm_from_euler
from bgfn.schema import ACCEL_COLUMNS, GYRO_COLUMNS

#: Columns of ``tables/fleet_preparation.csv`` (:func:`preparation_table`).
PREPARATION_COLUMNS: tuple[str, ...] = (
    "drive", "duration_s", "mounting_roll_deg", "mounting_pitch_deg", "mounting_yaw_deg", "standstill_s",
    "tilt_roll_deg", "tilt_pitch_deg", "accel_scale", "gyro_bias_x_dps", "gyro_bias_y_dps", "gyro_bias_z_dps",
    "native_rate_hz", "rate_hz", "cutoff_hz", "imu_gaps", "label_checked", "label_disagree_s", "label_action",
    "label_kept_share", "speed_max_mps")
#: Name of piece ``i`` of ``n`` of a drive: a stand-in for a fleet, labelled as what it is.
PIECE_FORMAT = "{name} piece {i} of {n}"


@dataclass
class PreparedDrive:
    """One drive of the fleet after :func:`prepare_fleet`.

    Attributes
    ----------
    name : str
    drive : Drive
        As loaded (the filter runs on it).
    imu : DataFrame
        ``time`` and the six IMU channels, levelled, scaled, de-biased, at the fleet's rate and bandwidth (the
        learned odometer reads it).
    rate_hz : float
    label_time, label_speed : ndarray
        The speed label at the reference's epochs, m/s (NaN: left out).
    facts : dict
        This drive's row of :data:`PREPARATION_COLUMNS`.
    """

    name: str
    drive: Drive
    imu: pd.DataFrame
    rate_hz: float
    label_time: np.ndarray
    label_speed: np.ndarray
    facts: dict = field(default_factory=dict)

    def label_at(self, t) -> np.ndarray:
        """The speed label at ``t`` (s): the nearest earlier reference epoch's (NaN where left out or outside)."""
        t = np.asarray(t, dtype=float)
        i = np.searchsorted(self.label_time, t, side="right") - 1
        ok = (i >= 0) & (t <= self.label_time[-1])
        out = np.full(t.shape, np.nan)
        out[ok] = self.label_speed[i[ok]]
        return out


#: The key of a profile that names the fleet's drives (the errors name it).
DRIVES_KEY = "fleet.drives"


def nhc_platform(platform: str) -> bool:
    """Whether ``platform`` takes the car's non-holonomic constraint (:data:`bgfn.nav.constraints.PLATFORM_AIDS`)."""
    return bool(PLATFORM_AIDS.get(str(platform), (False, False))[0])


def folder_platform(entry: str, profile: str | None = None) -> str | None:
    """The platform a fleet entry names before it is loaded: its folder's ``meta.yaml`` ``platform`` (the default,
    a car, when it says none or for a built-in dataset); None when the folder is not there (the loader names it)."""
    if registered(entry):                               # every shipped drive is a car's
        return DEFAULT_PLATFORM
    folder = dataset_folder(entry, profile)
    if folder is None:
        return None
    return str(read_meta(folder / META_FILE).get("platform") or DEFAULT_PLATFORM)


def platform_refusal(platforms: dict[str, str | None]) -> tuple[str, str] | None:
    """``(expected, found)`` when a drive of ``platforms`` (``{drive id: platform}``, None: not known yet) is no
    vehicle with the non-holonomic constraint; None when every known one is."""
    bad = {d: p for d, p in platforms.items() if p is not None and not nhc_platform(p)}
    if not bad:
        return None
    takes = ", ".join(p for p in PLATFORM_AIDS if nhc_platform(p))
    return (f"drives of one vehicle with the non-holonomic constraint (platform: {takes} in meta.yaml): the fleet's "
            "filter runs INS+NHC and its odometer learns a vehicle's forward speed",
            "; ".join(f"drive {d!r} with platform: {p}" for d, p in bad.items()))


def check_platforms(drives: list[Drive], source: str = "fleet") -> None:
    """One DataError (naming ``source`` and :data:`DRIVES_KEY`) when a loaded drive's platform is no vehicle with the
    non-holonomic constraint (:func:`platform_refusal`)."""
    refused = platform_refusal({d.meta.get("piece_of", d.name): str(d.meta.get("platform") or DEFAULT_PLATFORM)
                                for d in drives})
    if refused is not None:
        raise DataError(source, DRIVES_KEY, *refused)


def fleet_drives(fleet: dict, profile: str | None = None, loader=load_drive) -> list[Drive]:
    """The drives a profile's ``fleet:`` section names, loaded (``loader(name, profile=...)``); with ``pieces`` its
    one drive cut into that many contiguous pieces of equal time (:data:`PIECE_FORMAT`). A drive of no vehicle with
    the non-holonomic constraint is refused before any is loaded when its ``meta.yaml`` says so
    (:func:`folder_platform`), else once loaded (:func:`check_platforms`)."""
    names = list(fleet["drives"])
    source = file_setting(profile, DRIVES_KEY) if profile else "fleet"
    refused = platform_refusal({dataset_id(n): folder_platform(n, profile) for n in names})
    if refused is not None:
        raise DataError(source, DRIVES_KEY, *refused)
    if fleet.get("pieces"):
        if len(names) != 1:
            raise DataError("fleet", "pieces", "one drive in fleet.drives to cut into pieces", f"{len(names)} drives")
        drive = loader(names[0], profile=profile)
        check_platforms([drive], source)
        return drive_pieces(drive, int(fleet["pieces"]))
    if len(names) < 2:
        raise DataError("fleet", "drives", "at least 2 drives (or one with fleet.pieces)", f"{len(names)}")
    drives = [loader(n, profile=profile) for n in names]
    check_platforms(drives, source)
    return drives


def drive_pieces(drive: Drive, n: int) -> list[Drive]:
    """``drive`` cut into ``n`` contiguous pieces of equal time (:meth:`bgfn.data.Drive.crop`), each renamed."""
    t = drive.reference["time"].to_numpy(float)
    edges = np.linspace(t[0], t[-1], int(n) + 1)
    out = []
    for i in range(int(n)):
        piece = drive.crop(edges[i], edges[i + 1])
        piece.name = PIECE_FORMAT.format(name=drive.name, i=i + 1, n=int(n))
        piece.meta = {**piece.meta, "piece_of": drive.name}
        out.append(piece)
    return out


def imu_rate(imu: pd.DataFrame) -> float:
    """The IMU's rate from its median sample interval, Hz (to 1e-6 Hz: a float's rounding is no other rate)."""
    return round(1.0 / float(np.median(np.diff(imu["time"].to_numpy(float)))), 6)


def reference_speed_at(drive: Drive, t) -> np.ndarray:
    """The reference's horizontal speed at ``t`` (s), m/s."""
    ref = drive.reference
    return np.interp(np.asarray(t, float), ref["time"].to_numpy(float),
                     np.hypot(ref["v_n"].to_numpy(float), ref["v_e"].to_numpy(float)))


def runs_of(mask: np.ndarray, t: np.ndarray, min_s: float) -> list[tuple[int, int]]:
    """The runs ``[i, j)`` of True in ``mask`` (over times ``t``) lasting at least ``min_s`` seconds."""
    m = np.concatenate([[False], np.asarray(mask, bool), [False]])
    d = np.diff(m.astype(np.int8))
    starts, ends = np.flatnonzero(d == 1), np.flatnonzero(d == -1)
    return [(int(a), int(b)) for a, b in zip(starts, ends) if t[b - 1] - t[a] >= min_s]


def standstill_mask(drive: Drive, imu: pd.DataFrame, max_speed: float, min_s: float) -> np.ndarray:
    """The IMU rows inside the drive's standstills (module docstring)."""
    t = imu["time"].to_numpy(float)
    mask = np.zeros(t.size, bool)
    for a, b in runs_of(reference_speed_at(drive, t) < max_speed, t, min_s):
        mask[a:b] = True
    return mask


def level_scale_bias(imu: pd.DataFrame, still: np.ndarray, gravity: float) -> tuple[pd.DataFrame, dict]:
    """The IMU levelled, scaled and de-biased from its standstill rows ``still`` (module docstring), and the numbers:
    ``tilt_roll_deg``, ``tilt_pitch_deg``, ``accel_scale``, ``gyro_bias_*_dps`` (NaN without a standstill)."""
    facts = {"tilt_roll_deg": np.nan, "tilt_pitch_deg": np.nan, "accel_scale": np.nan,
             **{f"gyro_bias_{a}_dps": np.nan for a in "xyz"}}
    if not still.any():
        return imu, facts
    f = imu[list(ACCEL_COLUMNS)].to_numpy(float)
    w = imu[list(GYRO_COLUMNS)].to_numpy(float)
    bias = w[still].mean(axis=0)
    scale = gravity / float(np.linalg.norm(f[still], axis=1).mean())
    f_mean = scale * f[still].mean(axis=0)
    # at rest f_b = C_bl^T [0, 0, -g] = g [sin(pitch), -sin(roll) cos(pitch), -cos(roll) cos(pitch)]
    roll = float(np.arctan2(-f_mean[1], -f_mean[2]))
    pitch = float(np.arctan2(f_mean[0], np.hypot(f_mean[1], f_mean[2])))
    c = dcm_from_euler(roll, pitch, 0.0).reshape(3, 3)                    # body -> levelled
    out = imu.copy()
    out[list(ACCEL_COLUMNS)] = (scale * f) @ c.T
    out[list(GYRO_COLUMNS)] = (w - bias) @ c.T
    facts.update({"tilt_roll_deg": np.degrees(roll), "tilt_pitch_deg": np.degrees(pitch), "accel_scale": scale,
                  **{f"gyro_bias_{a}_dps": float(np.degrees(b)) for a, b in zip("xyz", bias)}})
    return out, facts


def common_rate(imu: pd.DataFrame, rate_hz: float, bandwidth_fraction: float) -> tuple[pd.DataFrame, dict]:
    """The IMU on a uniform grid at ``rate_hz`` (each gap-free stretch interpolated onto its own rate's uniform grid,
    then :func:`scipy.signal.resample_poly`), low-passed at ``bandwidth_fraction`` of ``rate_hz / 2`` (zero-phase
    Butterworth of order 4), and the numbers: ``native_rate_hz``, ``rate_hz``, ``cutoff_hz``, ``imu_gaps`` (time
    gaps over 1.5 sample intervals: the stretches are processed apart, so no window bridges a gap)."""
    t = imu["time"].to_numpy(float)
    native = imu_rate(imu)
    if rate_hz > native * (1 + 1e-6):
        raise DataError("fleet", "rate_hz", f"at most the slowest drive's rate ({native:.4g} Hz)", f"{rate_hz:g}")
    cols = list(ACCEL_COLUMNS + GYRO_COLUMNS)
    ratio = Fraction(float(rate_hz) / native).limit_denominator(1000)
    cutoff = float(bandwidth_fraction) * float(rate_hz) / 2.0
    sos = butter(4, cutoff, btype="low", fs=float(rate_hz), output="sos")
    cuts = np.flatnonzero(np.diff(t) > 1.5 / native) + 1
    parts = []
    for a, b in zip(np.r_[0, cuts], np.r_[cuts, t.size]):
        ts = t[a:b]
        grid = ts[0] + np.arange(int(np.floor((ts[-1] - ts[0]) * native + 1e-6)) + 1) / native
        x = np.column_stack([np.interp(grid, ts, imu[c].to_numpy(float)[a:b]) for c in cols])
        if ratio != 1:
            x = resample_poly(x, ratio.numerator, ratio.denominator, axis=0)
        if len(x) <= 3 * (2 * len(sos) + 1):                # too short to filter: a stretch no window fits in
            continue
        part = pd.DataFrame(sosfiltfilt(sos, x, axis=0), columns=cols)
        part.insert(0, "time", ts[0] + np.arange(len(x)) / float(rate_hz))
        parts.append(part)
    if not parts:
        raise DataError("fleet", "imu", "a gap-free stretch of IMU samples long enough to filter", "none")
    return pd.concat(parts, ignore_index=True), {"native_rate_hz": native, "rate_hz": float(rate_hz),
                                                 "cutoff_hz": cutoff, "imu_gaps": int(cuts.size)}


def speed_label(drive: Drive, max_diff: float, action: str, min_s: float) -> tuple[np.ndarray, np.ndarray, dict]:
    """The speed label at the reference's epochs and its numbers (module docstring): ``label_checked`` (whether
    GNSS velocities checked it), ``label_disagree_s`` (seconds in disagreeing stretches), ``label_action`` and
    ``label_kept_share`` (share of epochs with a label)."""
    ref = drive.reference
    t = ref["time"].to_numpy(float)
    speed = np.hypot(ref["v_n"].to_numpy(float), ref["v_e"].to_numpy(float))
    g = drive.gnss
    tg = g["time"].to_numpy(float)
    have = {"v_n", "v_e"} <= set(g.columns) and np.isfinite(g[["v_n", "v_e"]].to_numpy(float)).any()
    facts = {"label_checked": bool(have), "label_disagree_s": 0.0, "label_action": action,
             "label_kept_share": 1.0}
    if not have:
        return t, speed, facts
    ok = np.isfinite(g["v_n"].to_numpy(float)) & np.isfinite(g["v_e"].to_numpy(float))
    gs = np.hypot(g["v_n"].to_numpy(float), g["v_e"].to_numpy(float))[ok]
    gnss = np.interp(t, tg[ok], gs, left=np.nan, right=np.nan)
    # no check far from a GNSS velocity (a gap): more than two of its median intervals from the nearest
    dt = float(np.median(np.diff(tg[ok]))) if ok.sum() > 1 else np.inf
    near = np.abs(tg[ok][np.clip(np.searchsorted(tg[ok], t), 0, ok.sum() - 1)] - t) <= 2 * dt
    bad = near & np.isfinite(gnss) & (np.abs(speed - gnss) > max_diff)
    label = speed.copy()
    disagree = 0.0
    for a, b in runs_of(bad, t, min_s):
        disagree += float(t[b - 1] - t[a])
        label[a:b] = gnss[a:b] if action == "gnss" else np.nan
    facts.update(label_disagree_s=disagree, label_kept_share=float(np.isfinite(label).mean()))
    return t, label, facts


def prepare_fleet(drives: list[Drive], fleet: dict) -> list[PreparedDrive]:
    """Every drive made comparable (module docstring), in order; names must be distinct, platforms vehicles with
    the non-holonomic constraint (:func:`check_platforms`)."""
    check_platforms(drives)
    names = [d.name for d in drives]
    if len(set(names)) != len(names):
        raise DataError("fleet", "drives", "distinct drive names", ", ".join(names))
    rate = float(fleet["rate_hz"]) if fleet.get("rate_hz") else min(imu_rate(d.imu) for d in drives)
    out = []
    for d in drives:
        still = standstill_mask(d, d.imu, float(fleet["stationary_max_speed_mps"]), float(fleet["stationary_min_s"]))
        imu, lf = level_scale_bias(d.imu, still, float(fleet["gravity_mps2"]))
        imu, rf = common_rate(imu, rate, float(fleet["bandwidth_fraction"]))
        lt, ls, sf = speed_label(d, float(fleet["label_max_diff_mps"]), str(fleet["label_disagree"]),
                                 float(fleet["label_min_s"]))
        mount = np.asarray(d.meta.get("imu_mounting_deg") or [0.0, 0.0, 0.0], dtype=float)
        ti = d.imu["time"].to_numpy(float)
        facts = {"drive": d.name, "duration_s": float(lt[-1] - lt[0]),
                 **dict(zip(("mounting_roll_deg", "mounting_pitch_deg", "mounting_yaw_deg"), map(float, mount))),
                 "standstill_s": float(still.sum() / max(imu_rate(d.imu), 1e-9)) if ti.size else 0.0,
                 **lf, **rf, **sf, "speed_max_mps": float(np.nanmax(ls))}
        out.append(PreparedDrive(d.name, d, imu, rate, lt, ls, facts))
    return out


def preparation_table(prepared: list[PreparedDrive]) -> pd.DataFrame:
    """Each drive's preparation numbers (:data:`PREPARATION_COLUMNS`)."""
    return pd.DataFrame([p.facts for p in prepared], columns=list(PREPARATION_COLUMNS))

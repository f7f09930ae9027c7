"""The gallery's logs through the fleet's preparation (notebook 11): one drive and a walk, not a fleet.

The gallery's phone log (:func:`bgfn.studies.gallery.logs.phone_log`) is the first 240 s of the shipped car drive with
the IMU's axes turned and its clock early, both stated in its ``meta.yaml``; its car log
(:func:`~bgfn.studies.gallery.logs.car_log`) is the whole drive through the CSV path. Both prepared with the fleet's
settings (:func:`bgfn.studies.fleet.drives.prepare_fleet`), what they can show is that the loader and the preparation
undo a phone's mounting and clock:

- ``same_span``: the car log cropped to the phone's span and the phone log, prepared together: the same samples, so
  every number and channel must agree to rounding (a mounting applied twice or a clock offset of the wrong sign
  would show as differences of the signal's size);
- ``whole_log``: the whole car log and the phone log as a fleet would hold them: each is levelled, scaled and
  de-biased from its own standstills (the phone's lie in its 240 s), so they differ by those numbers and nothing
  else; ``whole_log_rest`` is what is left once the differences of the two drives' levelling, scale and gyro bias
  are taken out (:func:`releveled`), away from the phone's ends by :data:`EDGE_S` (the zero-phase filter's
  transient at a drive's end).

The walker (:func:`~bgfn.studies.gallery.logs.walker_log`) is no drive of a vehicle with the non-holonomic
constraint: a fleet refuses it (:func:`bgfn.studies.fleet.drives.check_platforms`).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from bgfn.data import Drive, load_drive
from bgfn.data.names import profile_datasets
from bgfn.nav.transform import dcm_from_euler
from bgfn.schema import ACCEL_COLUMNS, GYRO_COLUMNS
from bgfn.studies.fleet.drives import PreparedDrive, prepare_fleet, preparation_table
from bgfn.studies.gallery.logs import car_log, phone_log

#: The shipped drive the gallery's car and phone logs are made of.
RECORDED = "rtklib-drive0708"
#: The phone's ends left out of the whole-log comparison, s: the zero-phase Butterworth's transient at a drive's end
#: (order 4, cut at 0.8 of Nyquist: its impulse response has died out within a few tens of samples).
EDGE_S = 1.0
#: Same span, same samples: the phone and the car agree when every prepared channel's largest difference is at most
#: this share of the channel's size (RMS, at least 1), and the rows' times within TIME_TOL_S: float rounding only.
SAME_SPAN_RTOL, TIME_TOL_S = 1e-9, 1e-6
#: Columns of :attr:`GalleryCheck.agreement`: per prepared channel (and the speed label, ``speed``), its RMS over
#: the phone's span, the largest difference car-phone there with the same span prepared, with the whole car log
#: prepared, and what is left of that once the two levellings are taken out.
AGREEMENT_COLUMNS: tuple[str, ...] = ("channel", "unit", "rms", "same_span_max_diff", "whole_log_max_diff",
                                      "whole_log_rest_max_diff")
#: ``role`` of :attr:`GalleryCheck.preparation`'s rows: the car log over the phone's span, the phone log, the whole
#: car log (each prepared with the fleet's settings).
ROLES: tuple[str, ...] = ("car_span", "phone", "car_whole")


@dataclass
class GalleryCheck:
    """The car and phone logs prepared (``preparation``: :data:`bgfn.studies.fleet.drives.PREPARATION_COLUMNS`
    with a ``role`` of :data:`ROLES`), their channels compared (``agreement``: :data:`AGREEMENT_COLUMNS`), and
    facts (the phone's stated mounting and clock, its span, the largest time difference of the prepared rows)."""

    preparation: pd.DataFrame
    agreement: pd.DataFrame
    facts: dict = field(default_factory=dict)


def gallery_available(cfg: dict) -> bool:
    """Whether the profile loads the shipped drive the gallery's logs are made of (its fleet or its datasets)."""
    return RECORDED in [*((cfg.get("fleet") or {}).get("drives") or []), *profile_datasets(cfg)]


def write_car_and_phone(recorded: Drive, root: Path) -> tuple[Path, Path]:
    """The gallery's car and phone logs of ``recorded`` as CSV folders under ``root`` (rewritten every time)."""
    root = Path(root)
    return car_log(recorded, root / "car"), phone_log(recorded, root / "phone")


def _channels(p: PreparedDrive, t: np.ndarray) -> pd.DataFrame:
    """The prepared channels of ``p`` at its rows whose times are ``t`` (to 1 us; NaN where it has none), with the
    speed label."""
    imu = p.imu.set_index(np.round(p.imu["time"].to_numpy(float) * 1e6).astype(np.int64))
    out = imu.reindex(np.round(t * 1e6).astype(np.int64))[list(ACCEL_COLUMNS + GYRO_COLUMNS)].reset_index(drop=True)
    return out.assign(speed=p.label_at(t))


def releveled(p: PreparedDrive, to: PreparedDrive, x: pd.DataFrame) -> pd.DataFrame:
    """Channels ``x`` prepared as ``p`` was, turned into how ``to`` was prepared: ``p``'s levelling, scale and gyro
    bias undone and ``to``'s applied (prepared f = s C f_raw, w = C (w_raw - b); C the levelling's roll and pitch)."""
    def dcm(q):
        return dcm_from_euler(np.radians(q.facts["tilt_roll_deg"]), np.radians(q.facts["tilt_pitch_deg"]),
                              0.0).reshape(3, 3)

    def bias(q):
        return np.radians([q.facts[f"gyro_bias_{a}_dps"] for a in "xyz"])

    c = dcm(to) @ dcm(p).T
    out = x.copy()
    out[list(ACCEL_COLUMNS)] = (to.facts["accel_scale"] / p.facts["accel_scale"]) * x[list(ACCEL_COLUMNS)].to_numpy(float) @ c.T
    w = x[list(GYRO_COLUMNS)].to_numpy(float) @ dcm(p) + bias(p) - bias(to)      # C^T w + b, row-wise
    out[list(GYRO_COLUMNS)] = w @ dcm(to).T
    return out


def compare_car_and_phone(car: Drive, phone: Drive, fleet: dict) -> GalleryCheck:
    """The car and phone logs (loaded) prepared with ``fleet``'s settings and compared (module docstring)."""
    t0, t1 = (float(phone.reference["time"].iloc[i]) for i in (0, -1))
    span = car.crop(t0, t1)
    span_car, span_phone = prepare_fleet([span, phone], fleet)
    whole_car, whole_phone = prepare_fleet([car, phone], fleet)
    t = span_phone.imu["time"].to_numpy(float)
    a, b = _channels(span_car, t), _channels(span_phone, t)
    inner = (t >= t[0] + EDGE_S) & (t <= t[-1] - EDGE_S)
    w, wp = _channels(whole_car, t[inner]), _channels(whole_phone, t[inner])
    rest = releveled(whole_car, whole_phone, w)
    units = {**{c: "m/s^2" for c in ACCEL_COLUMNS}, **{c: "rad/s" for c in GYRO_COLUMNS}, "speed": "m/s"}
    rows = [{"channel": c, "unit": u, "rms": float(np.sqrt(np.nanmean(b[c].to_numpy(float) ** 2))),
             "same_span_max_diff": float(np.nanmax(np.abs(a[c] - b[c]))),
             "whole_log_max_diff": float(np.nanmax(np.abs(w[c] - wp[c]))),
             "whole_log_rest_max_diff": float(np.nanmax(np.abs(rest[c] - wp[c])))} for c, u in units.items()]
    prep = pd.concat([preparation_table(x).assign(role=r)
                      for x, r in zip(([span_car], [span_phone], [whole_car]), ROLES)], ignore_index=True)
    span_t = span_car.imu["time"].to_numpy(float)
    facts = {"phone_mounting_deg": list(phone.meta.get("imu_mounting_deg") or [0.0, 0.0, 0.0]),
             "phone_imu_offset_s": float((phone.meta.get("time_shifts_s") or {}).get("imu_time_offset_s") or 0.0),
             "span_s": t1 - t0, "edge_s": EDGE_S, "rows": int(t.size), "car_rows": int(span_t.size),
             "max_time_diff_s": float(np.abs(span_t - t).max()) if span_t.size == t.size else float("nan")}
    facts["same_span_agrees"] = bool(facts["max_time_diff_s"] <= TIME_TOL_S and all(
        r["same_span_max_diff"] <= SAME_SPAN_RTOL * max(1.0, r["rms"]) for r in rows))
    return GalleryCheck(prep, pd.DataFrame(rows, columns=list(AGREEMENT_COLUMNS)), facts)


def gallery_check(recorded: Drive, root: Path, fleet: dict) -> GalleryCheck:
    """The gallery's car and phone logs of ``recorded`` written under ``root``, loaded through the CSV path and
    compared (:func:`compare_car_and_phone`)."""
    car, phone = write_car_and_phone(recorded, root)
    return compare_car_and_phone(load_drive(car), load_drive(phone), fleet)

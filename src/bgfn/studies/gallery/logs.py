"""Three own logs as users have them, written as CSV folders for the book's gallery (notebook 09).

Each is what a user would bring (``data/README.md``): ``imu.csv``, ``gnss.csv``, ``reference.csv`` and a
``meta.yaml`` with the keys real logs need, and a profile of a few lines (:data:`GALLERY`).

=============  ===================================================================================================
log            what it is
=============  ===================================================================================================
``car``        the recorded car drive ``rtklib-drive0708`` (real MEMS IMU, RTK reference without attitude) taken
               through the CSV path: the project's own data as a user's folder, the same error model in
               ``meta.yaml``
``phone``      the first 240 s of the same drive as a phone in a cradle would log it: the IMU's axes turned
               (``imu_mounting_deg``), its clock early (``imu_time_offset_s``), the fixes stamped on arrival
               (a latency and a jitter, ``gnss_latency_s: auto``), no accuracy column (``gnss_std_m``), the
               reference at 10 Hz
``walker``     a synthetic 300 s walk (1.3 m/s, a step bounce of 1.8 Hz, two stops, gentle turns) with a
               consumer MEMS IMU held in the hand and a 1 Hz receiver of 1.5 m noise, ``platform: walker``
=============  ===================================================================================================
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd
import yaml

from bgfn.data.csv_drive import write_csv_drive
from bgfn.data.csv_meta import META_FILE
from bgfn.data.drive import Drive
from bgfn.data.imu_errors import apply_imu_errors, error_params
from bgfn.io import atomic_write_csv, atomic_write_text, shown_path
from bgfn.nav import sim
from bgfn.nav.transform import dcm_from_euler

#: The phone's IMU axes in the car's body frame, deg (roll, pitch, yaw): lying on its back, turned a quarter left.
PHONE_MOUNTING_DEG = [0.0, 0.0, -90.0]
#: The phone's IMU clock runs this much early (its rows stamped before their true time), s.
PHONE_IMU_OFFSET_S = 0.08
#: The phone's fixes are stamped on arrival: this late, with a uniform jitter of +- PHONE_GNSS_JITTER_S, s.
PHONE_GNSS_LATENCY_S, PHONE_GNSS_JITTER_S = 0.25, 0.04
#: Length of the phone log, s.
PHONE_DURATION_S = 240.0
#: The walk: length (s), pace (m/s), step frequency (Hz), stops (start, length; s), seed of its errors.
WALK_DURATION_S, WALK_SPEED_MPS, STEP_HZ = 300.0, 1.3, 1.8
WALK_STOPS_S: tuple[tuple[float, float], ...] = ((0.0, 20.0), (150.0, 15.0))
WALK_SEED = 11


@dataclass(frozen=True)
class GalleryLog:
    """One log of the gallery: its folder's name, kind, the profile a user writes for it (``base`` and the keys it
    sets beyond ``datasets``), and what it shows."""

    name: str
    kind: str
    base: str
    profile: dict = field(default_factory=dict)
    shows: str = ""
    own: bool = False        # a log the running profile names itself: ``base`` is that profile

    def profile_text(self, folder: Path) -> str:
        """The user's ``params/<name>.yaml`` for this log in ``folder`` (relative to the repository); for the running profile's own
        log only its name (the page shows no machine path)."""
        if self.own:
            return f"params/{self.base}.yaml, the profile of this run (its folder: {Path(folder).name})\n"
        # relative to the repository (the notebooks' folder) where the log lies inside it: no machine path on a page
        body = {"base": self.base, "datasets": [shown_path(Path(folder).resolve())], **self.profile}
        return yaml.safe_dump(body, sort_keys=False, default_flow_style=None, width=110)


#: The gallery (module docstring); a walker's speeds need the walker base (params/own-walker.yaml).
GALLERY: tuple[GalleryLog, ...] = (
    GalleryLog("car-drive0708", "car", "own", {},
               "the shipped recorded car drive through the CSV path"),
    GalleryLog("phone-drive0708", "phone in a car", "own", {},
               "a turned IMU, clocks apart, fixes without accuracy"),
    GalleryLog("walk", "walker", "own-walker", {},
               "a pedestrian: no NHC, ZUPT at the stops, walking speeds"),
)


def car_log(recorded: Drive, folder: Path) -> Path:
    """``recorded`` (a shipped drive) written as a user's folder: its IMU and GNSS as they are, its reference at
    10 Hz, ``meta.yaml`` with its lever arm and error model (``platform: car``)."""
    ref = recorded.reference.iloc[::10].reset_index(drop=True)
    drive = Drive("car-drive0708", ref, recorded.imu, recorded.gnss,
                  {**recorded.meta, "source": f"{recorded.name} through the CSV path (bgfn.studies.gallery.logs)"})
    write_csv_drive(drive, folder)
    _add_meta(folder, {"platform": "car"})
    return Path(folder)


def phone_log(recorded: Drive, folder: Path, seed: int = 5) -> Path:
    """The first :data:`PHONE_DURATION_S` of ``recorded`` as a phone logs it (module docstring); ``meta.yaml``
    states the mounting and the IMU's clock, asks for the GNSS latency to be estimated, gives the fixes' std."""
    t0 = float(recorded.imu["time"].iloc[0])
    keep = lambda df: df[df["time"] <= t0 + PHONE_DURATION_S].reset_index(drop=True)   # noqa: E731
    imu, gnss, ref = keep(recorded.imu), keep(recorded.gnss), keep(recorded.reference).iloc[::10]
    c = dcm_from_euler(*np.radians(PHONE_MOUNTING_DEG)).reshape(3, 3)          # phone axes -> body
    for cols in (["gyro_x", "gyro_y", "gyro_z"], ["accel_x", "accel_y", "accel_z"]):
        imu[cols] = imu[cols].to_numpy(float) @ c                              # body -> phone: c^T x per row
    imu["time"] = imu["time"] - PHONE_IMU_OFFSET_S
    rng = np.random.default_rng(seed)
    gnss["time"] = gnss["time"] + PHONE_GNSS_LATENCY_S + rng.uniform(-1, 1, len(gnss)) * PHONE_GNSS_JITTER_S
    gnss = gnss[gnss["time"] < float(imu["time"].iloc[-1])]
    meta = {k: v for k, v in recorded.meta.items() if k != "imu_errors"}    # a phone's maker gives no error model
    drive = Drive("phone-drive0708", ref.reset_index(drop=True), imu, gnss.reset_index(drop=True),
                  {**meta, "lever_arm_m": [0.0, 0.0, 0.0],
                   "source": f"the first {PHONE_DURATION_S:g} s of {recorded.name} as a phone logs it "
                             "(bgfn.studies.gallery.logs)"})
    write_csv_drive(drive, folder)
    # the receiver reports neither an accuracy nor a velocity: its file has positions only
    atomic_write_csv(Path(folder) / "gnss.csv", drive.gnss[["time", "lat", "lon", "h"]], float_format="%.17g")
    _add_meta(folder, {"platform": "car", "imu_mounting_deg": PHONE_MOUNTING_DEG,
                       "imu_time_offset_s": PHONE_IMU_OFFSET_S, "gnss_latency_s": "auto",
                       "gnss_std_m": [2.0, 2.0, 4.0]})
    return Path(folder)


def walk_trajectory(duration_s: float = WALK_DURATION_S, rate_hz: float = 100.0,
                    stops=WALK_STOPS_S) -> pd.DataFrame:
    """A pedestrian's trajectory: :data:`WALK_SPEED_MPS` with a step bounce (forward speed +-0.15 m/s and vertical
    speed +-0.4 m/s at :data:`STEP_HZ`, a sway of the hand in roll and pitch), gentle turns, standing through
    ``stops`` (each eased in and out over 1.5 s). Reference schema, GPS time of week from 300000 s."""
    t = np.arange(int(round(duration_s * rate_hz)) + 1) / rate_hz
    pace = np.ones_like(t)
    for start, length in stops:
        x = np.clip(np.maximum(start - t, t - start - length) / 1.5, 0.0, 1.0)   # 0 inside the stop, 1 beyond 1.5 s
        pace *= x * x * (3.0 - 2.0 * x)
    phase = 2 * np.pi * STEP_HZ * t
    speed = pace * (WALK_SPEED_MPS + 0.15 * np.sin(phase))
    yaw_rate = pace * (0.02 + 0.06 * np.sin(2 * np.pi * t / 90.0))
    yaw = 0.4 + np.concatenate([[0.0], np.cumsum(0.5 * (yaw_rate[1:] + yaw_rate[:-1]) / rate_hz)])
    v = np.stack([speed * np.cos(yaw), speed * np.sin(yaw), -pace * 0.4 * np.cos(phase)], axis=-1)
    pos = sim.positions_from_velocity(t, v, np.radians(45.06), np.radians(7.66), 240.0)
    return pd.DataFrame({"time": t + 300000.0, "lat": pos[:, 0], "lon": pos[:, 1], "h": pos[:, 2],
                         "v_n": v[:, 0], "v_e": v[:, 1], "v_d": v[:, 2],
                         "roll": 0.05 * pace * np.sin(phase / 2), "pitch": 0.03 * pace * np.sin(phase),
                         "yaw": np.angle(np.exp(1j * yaw))})


def walker_log(folder: Path, seed: int = WALK_SEED, duration_s: float = WALK_DURATION_S) -> Path:
    """:func:`walk_trajectory` (``duration_s`` long, the stops inside it) with a consumer MEMS IMU (the MPU-6000 profile's noise and bias instability, its
    gyro turn-on bias calibrated at boot, no vehicle vibration) and 1 Hz fixes of 1.5 m / 3 m; the reference at
    5 Hz without attitude (an RTK rover's); ``platform: walker``."""
    truth = walk_trajectory(duration_s, stops=[(a, b) for a, b in WALK_STOPS_S if a + b < duration_s])
    params = error_params("mpu6000", {"vibration_gyro_std": [0.0] * 3, "vibration_accel_std": [0.0] * 3,
                                      "accel_turn_on_bias_std": [0.05] * 3})
    speed = np.hypot(truth["v_n"], truth["v_e"]).to_numpy()[1:]
    imu, errors, _ = apply_imu_errors(sim.imu_from_trajectory(truth, source="walk"), params, seed, speed=speed)
    gnss = sim.gnss_from_trajectory(truth, 1.0, 1.5, 3.0, [0.0, 0.0, 0.0], seed=seed + 1)
    ref = truth.iloc[::20].reset_index(drop=True).assign(roll=np.nan, pitch=np.nan, yaw=np.nan)
    drive = Drive("walk", ref, imu, gnss, {"lever_arm_m": [0.0, 0.0, 0.0], "imu_errors": errors,
                                           "source": "a synthetic walk (bgfn.studies.gallery.logs)"})
    write_csv_drive(drive, folder)
    _add_meta(folder, {"platform": "walker"})
    return Path(folder)


def _add_meta(folder: Path, keys: dict) -> None:
    """Set ``keys`` in the folder's ``meta.yaml`` (written by :func:`bgfn.data.csv_drive.write_csv_drive`)."""
    path = Path(folder) / META_FILE
    meta = yaml.safe_load(path.read_text(encoding="utf-8")) or {}
    meta.update(keys)
    atomic_write_text(path, yaml.safe_dump(meta, sort_keys=True))


def write_gallery(recorded: Drive, root: Path) -> dict[str, Path]:
    """Every log of :data:`GALLERY` under ``root`` (one folder each; rewritten every time)."""
    root = Path(root)
    writers = {"car-drive0708": lambda f: car_log(recorded, f), "phone-drive0708": lambda f: phone_log(recorded, f),
               "walk": walker_log}
    return {g.name: writers[g.name](root / g.name) for g in GALLERY}

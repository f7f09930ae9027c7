"""Write an example own log (a CSV folder as a logger leaves it) and a profile that names it by its absolute path.

``python tools/demo_log.py FOLDER PROFILE [--walker] [--duration S]`` writes a synthetic car drive of ``S`` seconds
(default 60 s: a short phone-like log) into ``FOLDER`` (``imu.csv`` at a jittery ~100 Hz, ``gnss.csv`` at 1 Hz with a
lever arm, ``reference.csv`` at 5 Hz, ``meta.yaml``; GPS time of week) and ``params/<PROFILE>.yaml``: the README's two
lines with the absolute path (``base: own``) and the smallest budget, nothing else: the profile check's run plan
(:mod:`bgfn.run_plan`) fits the outages, margins and the sweep to the log or switches off what it cannot hold, so that
``make reproduce PROFILE=<PROFILE>`` runs the whole chain on it in a few minutes. CI runs exactly that
(``.ci/run``): the documented own-log path by absolute path, end to end, every notebook and the book. With
``--walker`` the log is the gallery's synthetic walk instead (:func:`bgfn.studies.gallery.logs.walker_log`, ``platform:
walker``, default 134 s) and the profile is based on ``params/own-walker.yaml``.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np
import pandas as pd

from bgfn.config import PARAMS_DIR
from bgfn.data import Drive, write_csv_drive
from bgfn.data import imu_errors as ie
from bgfn.studies.gallery.logs import walker_log
from bgfn.nav import sim

T0 = 243000.0                    # GPS time of week of the first epoch, s
DURATION_S = 240.0
LEVER = [-0.4, 0.0, -1.0]        # GNSS antenna in the body frame, m
#: The CLI's default lengths: a car log of a minute, a walk of 134 s (the logs notebook 09's own-log runs are made for).
CLI_CAR_S, CLI_WALK_S = 60.0, 134.0
#: The smallest budget of the demo profiles (the numbers mean nothing; the chain runs through).
BUDGET = ("train: {methods: [bgfn, transformer, mlp], seeds: [0], size: smoke, lr_search: {grid: null},\n"
          "        optimizer: {epochs: 2, max_train_windows: 64, max_val_windows: 32}}\n"
          "variant_runs: {methods: [bgfn], seeds: [0]}\n")


def demo_log(folder: Path, name: str = "demo-car", seed: int = 7, source: str = "tools/demo_log.py (synthetic)",
             duration_s: float = DURATION_S) -> Path:
    """The drive of the module docstring, written in the CSV schema (atomically per file); ``name`` in its
    ``meta.yaml``; ``duration_s`` long. The IMU's white noise and the filter's error model agree
    (std x sqrt(0.01 s) = density); the biases are the model's turn-on biases."""
    truth = sim.demo_trajectory(duration_s, 400.0)
    truth["time"] = truth["time"] + T0
    rng = np.random.default_rng(seed)
    fine = sim.imu_from_trajectory(truth)                      # 2.5 ms rows; a logger's steps of 7.5-12.5 ms
    steps = rng.choice([3, 4, 5], size=len(fine) // 3 + 1, p=[0.25, 0.5, 0.25])
    ends = np.cumsum(steps)
    ends = ends[ends <= len(fine)]
    cols = [c for c in fine.columns if c != "time"]
    cum = np.vstack([np.zeros(len(cols)), np.cumsum(fine[cols].to_numpy(float), axis=0)])
    imu = pd.DataFrame(np.diff(cum[np.concatenate([[0], ends])], axis=0) / np.diff(np.concatenate([[0], ends]))[:, None],
                       columns=cols)
    imu.insert(0, "time", truth["time"].to_numpy(float)[ends])
    noise = rng.standard_normal((len(imu), 6)) * ([2e-4] * 3 + [2e-3] * 3)          # white noise, rad/s and m/s^2
    imu[cols] = imu[cols].to_numpy() + noise + [1e-4, -1e-4, 5e-5, 0.01, -0.01, 0.005]  # and constant biases
    gnss = sim.gnss_from_trajectory(truth, 1.0, 0.5, 1.0, LEVER, seed=seed + 1)
    errors = ie.error_params("ekinox-d", {"gyro_noise_density": 2e-5, "accel_noise_density": 2e-4,
                                          "gyro_turn_on_bias_std": 2e-4, "accel_turn_on_bias_std": 0.02})
    drive = Drive(name, truth.iloc[::80].reset_index(drop=True), imu, gnss,
                  {"lever_arm_m": LEVER, "imu_errors": errors, "source": source})
    return write_csv_drive(drive, folder)


def demo_profile(name: str, folder: Path) -> Path:
    """``params/<name>.yaml`` naming ``folder`` by its absolute path, the smallest budget and a four-start sweep
    (module docstring)."""
    path = PARAMS_DIR / f"{name}.yaml"
    path.write_text(f'base: own\ndatasets: ["{Path(folder).resolve()}"]\n' + BUDGET
                    + "evaluate: {methods: [bgfn, transformer, mlp], sweep: {n_starts: 4}}\n", encoding="utf-8")
    return path


def walker_profile(name: str, folder: Path) -> Path:
    """``params/<name>.yaml`` for the walk in ``folder``: ``base: own-walker``, the smallest budget, a short sweep."""
    path = PARAMS_DIR / f"{name}.yaml"
    path.write_text(f'base: own-walker\ndatasets: ["{Path(folder).resolve()}"]\n' + BUDGET
                    + "evaluate: {methods: [bgfn, transformer, mlp], sweep: {n_starts: 4}}\n", encoding="utf-8")
    return path


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("folder")
    p.add_argument("profile")
    p.add_argument("--walker", action="store_true", help="the gallery's synthetic walk (platform walker)")
    p.add_argument("--duration", type=float, help=f"the log's length, s (default {CLI_CAR_S:g}; a walk {CLI_WALK_S:g})")
    a = p.parse_args(argv)
    if a.walker:
        log = walker_log(Path(a.folder), duration_s=a.duration or CLI_WALK_S)
        print("wrote", log, "and", walker_profile(a.profile, Path(a.folder)))
    else:
        log = demo_log(Path(a.folder), duration_s=a.duration or CLI_CAR_S)
        print("wrote", log, "and", demo_profile(a.profile, Path(a.folder)))
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""Compile the navigation's numba kernels (and BGFN's LIF kernels) into numba's cache before the notebooks call them.

Every kernel of the filter engine and its aids is ``numba.njit(cache=True)``: compiled on its first call, then
loaded by every later process in a fraction of a second. :func:`compile_kernels` calls every path of the notebooks
once on a short synthetic drive (the GPS-aided filter with the vehicle constraints, the standalone INS, INS+NHC and
an odometer in one outage), and :func:`compile_lif_kernels` one forward and backward pass of the LIF layers on one
thread and on two, so that the same functions are compiled for the same argument types. ``make reproduce`` runs it
in the background (``python -m bgfn kernels``) from the data step on, beside the profile check and notebook 01.
Nothing here changes a result: a kernel missing from the cache is compiled where it is first called.
"""

from __future__ import annotations

import time

import numpy as np
import torch

from bgfn.data import Drive
from bgfn.data import imu_errors as ie
from bgfn.evaluate.hybrid import navigation_context, run_outages
from bgfn.models.lif import make_lif
from bgfn.nav import baseline, sim
from bgfn.nav import odometer as no
from bgfn.train.speed import torch_threads

#: The synthetic drive: length, s; rest at its start, s (ZUPT and the at-rest alignment see a still IMU); the
#: outage (start, duration), s after its first row.
DRIVE_S, REST_S, OUTAGE = 120.0, 20.0, (70.0, 20.0)


def warmup_drive(imu: str = "mpu6000") -> Drive:
    """A 120 s car drive of :func:`bgfn.nav.sim.demo_trajectory` (20 s at rest first) with the ``imu`` error
    profile and 1 Hz GNSS fixes (seeded), in the schema of every drive."""
    ref = sim.demo_trajectory(DRIVE_S, rest_s=REST_S)
    params = ie.error_params(imu)
    speed = np.hypot(ref["v_n"], ref["v_e"]).to_numpy()[1:]
    imu_table, errs, _ = ie.apply_imu_errors(sim.imu_from_trajectory(ref), params, seed=0, speed=speed)
    gnss = sim.gnss_from_trajectory(ref, 1.0, 1.0, 2.0, seed=1)
    meta = {"lever_arm_m": [0.0, 0.0, 0.0], "imu_errors": errs, "gnss_rate_hz": 1.0, "imu_rate_hz": 100.0,
            "platform": "car"}
    return Drive("kernel-warmup", ref, imu_table, gnss, meta)


def compile_kernels(nav_section: dict | None = None) -> float:
    """Run the notebooks' navigation paths once on :func:`warmup_drive` (with the profile's ``nav:`` section, so
    that the same aids run) and return the wall time, s. The numbers are thrown away."""
    t0 = time.perf_counter()
    drive = warmup_drive()
    start = float(drive.imu["time"].iloc[0]) + OUTAGE[0]
    window = [(start, OUTAGE[1])]
    baseline.run_baseline(drive, baseline.nav_config(nav_section), window, keep=False)   # GPS/INS, INS and INS+NHC
    ctx = navigation_context(drive, nav_section, [start])                     # the evaluation's context
    epochs = np.arange(start - 5.0, start + OUTAGE[1] + 5.0, 1.0)
    track = no.SpeedTrack(epochs, np.full(epochs.size, 8.0), np.full(epochs.size, 0.5))
    run_outages(ctx, window, None, "INS", None, None, aids=[ctx.constraints, no.Odometer(ctx.constraints, track)])
    compile_lif_kernels()
    return time.perf_counter() - t0


def compile_lif_kernels() -> None:
    """One forward and backward pass of a fused LIF layer on one thread and on two (the numbers are thrown away)."""
    for threads in (1, 2):
        with torch_threads(threads):
            x = torch.ones(2, 3, 4, requires_grad=True)
            make_lif()(x).sum().backward()

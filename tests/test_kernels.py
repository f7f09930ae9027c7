"""The numba warm-up (bgfn.evaluate.kernels, ``python -m bgfn kernels``) compiles what the notebooks call, for the
argument types they call it with: after it, a run on another drive finds every kernel it needs (compiled, or
loaded from numba's cache) and adds none. Checked in a fresh process, which no other test has warmed up."""

from __future__ import annotations

import json
import subprocess
import sys
from pathlib import Path

CHECK = r'''
import importlib, json, pkgutil, sys
from numba.core.registry import CPUDispatcher
import bgfn.nav
from bgfn.evaluate import kernels
from bgfn.evaluate.hybrid import navigation_context, run_outages
from bgfn.nav import baseline
from bgfn.profile_schema import load_profile
sys.path.insert(0, sys.argv[1])
from synthetic_drive import demo_drive

def signatures():
    out = {}
    for info in pkgutil.iter_modules(bgfn.nav.__path__):
        mod = importlib.import_module(f"bgfn.nav.{info.name}")
        for name, obj in vars(mod).items():
            if isinstance(obj, CPUDispatcher) and obj.__module__ == mod.__name__:
                out[f"{mod.__name__}.{name}"] = [str(s) for s in obj.signatures]
    return out

nav = load_profile("quick")["nav"]
before = signatures()
kernels.compile_kernels(nav)
warm = signatures()
drive = demo_drive(duration=100.0)                 # another drive, another IMU, the notebooks' paths
start = float(drive.imu["time"].iloc[0]) + 60.0
baseline.run_baseline(drive, baseline.nav_config(nav), [(start, 20.0)])
run_outages(navigation_context(drive, nav, [start]), [(start, 20.0)], None, "INS", None, None)
print(json.dumps({"before": before, "warm": warm, "after": signatures()}))
'''


def test_the_warm_up_compiles_what_a_drive_then_needs():
    tests = Path(__file__).resolve().parent
    done = subprocess.run([sys.executable, "-c", CHECK, str(tests)], capture_output=True, text=True, timeout=600)
    assert done.returncode == 0, done.stderr[-3000:]
    sig = json.loads(done.stdout.strip().splitlines()[-1])
    assert not any(sig["before"].values())                       # a fresh process: nothing compiled or loaded yet
    # the filter engine's and the aids' kernels that Python calls (the others are inlined into them)
    for name in ("bgfn.nav.engine.propagate_steps", "bgfn.nav.engine.fuse", "bgfn.nav.gnss_aid.position_measurement",
                 "bgfn.nav.constraints.nhc_measurement",
                 "bgfn.nav.constraints.vehicle_velocity_rows"):
        assert sig["warm"][name], name
    assert sig["after"] == sig["warm"]                           # nothing new to compile for the drive

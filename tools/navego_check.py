"""NaveGo v1.4 run beside ours: its INS-only errors in the paper's outages and its GPS-aided accuracy.

``make navego-check`` (or ``python tools/navego_check.py``) exports each drive to NaveGo's ``imu``/``gnss`` structs,
removes the fixes inside the profile's outages (as NaveGo's ``gnss_outage.m`` does), runs NaveGo's own
``ins_gnss.m`` under GNU Octave (Debian packages ``octave`` and ``octave-control``), and compares its trajectory
with the drive's reference: the max |east| and |north| error in each outage and the horizontal RMS outside them.
The numbers go to ``data/measured/navego_check.csv`` with the date, the commit and the versions, which the book
reads (the *NaveGo* rows beside our ``navego`` setup, :mod:`bgfn.studies.ins_fidelity.ins_setups`).

NaveGo's source is read from ``../shared/navego-v1.4/`` (LGPL-3.0) at run time; nothing of it is copied here. It
is a tool, not part of the package: the artifact never needs Octave.

Settings, each chosen to compare like with like (listed in the CSV's ``setting`` column):

- the IMU error parameters are the drive's ``meta['imu_errors']`` in NaveGo's names (``arw``, ``vrw``, ``gb_sta`` =
  ``*_bias_fixed``, ``gb_dyn`` = ``*_bias_instability``, ``gb_corr``, ``gb_psd = gb_dyn / sqrt(gb_corr)`` as
  NaveGo's ``imu_si_errors.m``), times the profile's ``nav.noise_scale``;
- ``position only`` (default): NaveGo fuses the fixes' velocity too; ours does not, so the velocity rows get a std
  of 100 m/s (they carry nothing). ``--fuse-velocity`` keeps the file's velocity (NaveGo's own way) where it has
  one;
- the initial attitude is the reference's at the first fix, its std the profile's ``nav.init``; ZUPT off
  (``zupt_th = 0``: our INS row has none).

Two runs per drive (the CSV's ``variant`` column, :data:`VARIANTS`):

- ``as released``: NaveGo v1.4 as mirrored;
- ``bias feedback consistent``: a diagnostic. v1.4's ``ins_gnss.m`` (Version 011) zeroes only the error states 1-9
  before an update (line 363) and takes the *negative* of the carried bias states as the whole bias estimate (lines
  408-409), while its prediction ``xi = A xp`` counts those states once more. The innovation then holds the whole
  true bias at every fix, whatever has been estimated: the accelerometer states integrate it without bound, and
  the gyro states settle at about half of it. This run copies NaveGo into a temporary folder, applies
  :data:`BIAS_FEEDBACK_PATCH` there (all 15 states zeroed before an update, the estimates corrected by the states
  with the signs of NaveGo's own ``F``: gyro ``gb -= x``, accelerometer ``ab += x``, since ``F_update.m`` drives
  the velocity error with ``+C_bn x_a``) and runs that copy. Nothing of NaveGo is written into this project.

The bias states step by step go to ``data/measured/navego_bias_trace.csv`` (:data:`TRACE_COLUMNS`): every run's bias
estimates at its fixes of the first :data:`TRACE_S` seconds, beside our filter under NaveGo's setup and the drive's
true biases at the same fixes. ``--datasets`` runs some drives and keeps the others' rows in both files.
"""

from __future__ import annotations

import argparse
import datetime
import shutil
import subprocess
import sys
import tempfile
from pathlib import Path

import numpy as np
import pandas as pd
import scipy.io

from bgfn.config import PROJECT_ROOT, git_commit
from bgfn.data import load_drive
from bgfn.io import atomic_write_csv
from bgfn.nav.baseline import nav_config, run_drive
from bgfn.nav.earth import curvature_radii, lla_to_ned
from bgfn.nav.outages import outage_windows
from bgfn.studies.ins_fidelity.ins_setups import NAVEGO_CHECK_COLUMNS, NAVEGO_CHECK_FILE, NAVEGO_VARIANTS
from bgfn.profile_schema import load_profile

NAVEGO_DIR = PROJECT_ROOT.parent / "shared" / "navego-v1.4"
#: The file the diagnostic variant changes, and its three lines: (as in v1.4, as run). Each must occur exactly once.
PATCHED_FILE = Path("ins-gnss") / "ins_gnss.m"
BIAS_FEEDBACK_PATCH: tuple[tuple[str, str], ...] = (
    ("kf.xp(1:9) = 0.0;", "kf.xp(1:15) = 0.0;"),                     # line 363: every error state starts at zero
    ("gb_dyn   = -kf.xp(10:12);", "gb_dyn   = gb_dyn - kf.xp(10:12);"),   # line 408: the estimate corrected
    ("ab_dyn   = -kf.xp(13:15);", "ab_dyn   = ab_dyn + kf.xp(13:15);"),   # line 409: +, the sign of F's C_bn x_a
)
#: NaveGo's runs per drive: as released, and with its bias feedback made consistent (module docstring).
VARIANTS: tuple[str, ...] = tuple(NAVEGO_VARIANTS)      # the CSV's variant column, read by bgfn.studies.ins_fidelity.ins_setups
#: The bias states step by step: NaveGo's estimates at every fix of each run's first TRACE_S seconds,
#: beside our filter under NaveGo's setup and the drive's true biases (a simulated drive's), at the same fixes.
TRACE_FILE = PROJECT_ROOT / "data" / "measured" / "navego_bias_trace.csv"
TRACE_S = 120.0
OURS = "ours, navego setup"
TRUTH = "truth"
_BIAS = ("gyro_bias_x", "gyro_bias_y", "gyro_bias_z", "accel_bias_x", "accel_bias_y", "accel_bias_z")
TRACE_COLUMNS: tuple[str, ...] = ("dataset", "source", "time_s", *(c + ("_dps" if c.startswith("gyro") else "_mps2")
                                                                  for c in _BIAS), "date", "commit")
DATASETS = ("turin-sim-ekinox", "turin-sim-mpu6000")
#: The velocity std that makes NaveGo's velocity rows carry nothing (position-only, as our filter), m/s.
NO_VELOCITY_STD = 100.0


def _vec(x) -> np.ndarray:
    return np.broadcast_to(np.asarray(x, dtype=float), (3,)).astype(float)


def patched_navego(navego: Path, into: Path) -> Path:
    """A copy of NaveGo's source ``navego`` under ``into`` with :data:`BIAS_FEEDBACK_PATCH` applied; its path.

    Raises ``ValueError`` naming the file and the line when a line to change is not there exactly once (another
    NaveGo version): the diagnostic then says nothing rather than run something else.
    """
    dst = Path(into) / "navego-bias-feedback"
    shutil.copytree(navego, dst)
    f = dst / PATCHED_FILE
    text = f.read_text(encoding="utf-8")
    for old, new in BIAS_FEEDBACK_PATCH:
        if text.count(old) != 1:
            raise ValueError(f"{Path(navego) / PATCHED_FILE}: expected the line `{old}` exactly once (NaveGo v1.4, "
                             f"ins_gnss.m Version 011), found it {text.count(old)} times")
        text = text.replace(old, new)
    f.write_text(text, encoding="utf-8")
    return dst


def export(drive, windows, nav: dict, fuse_velocity: bool) -> tuple[dict, dict, str]:
    """NaveGo's ``imu`` and ``gnss`` structs of ``drive`` (module docstring) and the setting in words."""
    g = drive.gnss.reset_index(drop=True)
    t_fix = g["time"].to_numpy(float)
    imu = drive.imu[drive.imu["time"] >= t_fix[0] - 1e-9].reset_index(drop=True)     # starts at the first fix
    lat, h = g["lat"].to_numpy(float), g["h"].to_numpy(float)
    r_m, r_n = curvature_radii(lat)
    has_vel = np.isfinite(g[["v_n", "v_e", "v_d"]].to_numpy(float)).all()
    if fuse_velocity and has_vel:
        vel, stdv, setting = g[["v_n", "v_e", "v_d"]].to_numpy(float), np.full(3, 0.1), "velocity fused (file's)"
    else:     # position only: the velocity from the fixes, carrying nothing (std 100 m/s)
        ned = lla_to_ned(lat, g["lon"].to_numpy(float), h, lat[0], g["lon"].iloc[0], h[0])
        vel = np.column_stack([np.gradient(ned[:, k], t_fix) for k in range(3)])
        stdv, setting = np.full(3, NO_VELOCITY_STD), "position only"
    keep = np.ones(len(g), bool)
    for s, d in windows:                                   # gnss_outage.m: the fixes inside the outages removed
        keep &= ~((t_fix > s) & (t_fix < s + d))
    e = drive.meta["imu_errors"]
    scale = float(nav.get("noise_scale") if isinstance(nav.get("noise_scale"), (int, float)) else 1.0)
    ref = drive.reference
    t_ref = ref["time"].to_numpy(float)
    att0 = [float(np.interp(imu["time"].iloc[0], t_ref, np.unwrap(ref[c].to_numpy(float)) if c == "yaw"
                            else ref[c].to_numpy(float))) for c in ("roll", "pitch", "yaw")]
    init = nav["init"]
    std_m = np.median(g[["std_n", "std_e", "std_d"]].to_numpy(float), axis=0)
    freq = 1.0 / float(np.median(np.diff(imu["time"].to_numpy(float))))
    gb_dyn, ab_dyn = _vec(e["gyro_bias_instability"]), _vec(e["accel_bias_instability"])
    gb_corr, ab_corr = _vec(e["gyro_bias_corr_time"]), _vec(e["accel_bias_corr_time"])
    imu_s = {"t": imu["time"].to_numpy(float)[:, None],
             "fb": imu[["accel_x", "accel_y", "accel_z"]].to_numpy(float),
             "wb": imu[["gyro_x", "gyro_y", "gyro_z"]].to_numpy(float),
             "arw": scale * _vec(e["gyro_noise_density"]), "vrw": scale * _vec(e["accel_noise_density"]),
             "g_std": scale * _vec(e["gyro_noise_density"]) * np.sqrt(freq),
             "a_std": scale * _vec(e["accel_noise_density"]) * np.sqrt(freq),
             "gb_sta": _vec(e["gyro_bias_fixed"]), "ab_sta": _vec(e["accel_bias_fixed"]),
             "gb_dyn": gb_dyn, "ab_dyn": ab_dyn, "gb_corr": gb_corr, "ab_corr": ab_corr,
             "gb_psd": gb_dyn / np.sqrt(gb_corr), "ab_psd": ab_dyn / np.sqrt(ab_corr), "freq": freq,
             "ini_align": np.array(att0),
             "ini_align_err": np.radians([init["level_std_deg"], init["level_std_deg"], init["azimuth_std_deg"]])}
    gnss_s = {"t": t_fix[keep][:, None], "lat": lat[keep][:, None], "lon": g["lon"].to_numpy(float)[keep][:, None],
              "h": h[keep][:, None], "vel": vel[keep],
              "std": np.array([std_m[0] / (r_m[0] + h[0]), std_m[1] / ((r_n[0] + h[0]) * np.cos(lat[0])), std_m[2]]),
              "stdm": std_m, "stdv": stdv, "larm": _vec(drive.meta.get("lever_arm_m", [0, 0, 0]))[:, None],
              "freq": 1.0 / float(np.median(np.diff(t_fix))), "zupt_th": 0.0, "zupt_win": 0.0,
              # a fix is fused at the IMU epoch within half an interval of it (NaveGo's examples use a third, but
              # the Ekinox fixes lie half an IMU interval off the IMU grid: with a third none would ever be fused)
              "eps": 0.5 * float(np.median(np.diff(imu["time"].to_numpy(float))))}
    return imu_s, gnss_s, setting


def errors(nav_file: Path, drive, windows) -> list[dict]:
    """NaveGo's max |east| / |north| error per outage and its horizontal RMS outside the outages (m)."""
    m = scipy.io.loadmat(nav_file)
    t, lat, lon, h = (np.asarray(m[k], float).ravel() for k in ("t", "lat", "lon", "h"))
    ref = drive.reference
    t_ref = ref["time"].to_numpy(float)
    lat_r, lon_r = np.interp(t, t_ref, ref["lat"].to_numpy(float)), np.interp(t, t_ref, ref["lon"].to_numpy(float))
    r_m, r_n = curvature_radii(lat_r)
    north, east = (lat - lat_r) * (r_m + h), (lon - lon_r) * (r_n + h) * np.cos(lat_r)
    out_of = np.zeros(t.size, bool)
    rows = []
    for k, (s, d) in enumerate(windows, 1):
        sel = (t >= s) & (t <= s + d)
        out_of |= sel
        rows.append({"outage": k, "start_s": s, "duration_s": d, "max_east_m": float(np.abs(east[sel]).max()),
                     "max_north_m": float(np.abs(north[sel]).max())})
    aided = ~out_of & (t > t[0] + 60.0)              # after a minute of convergence
    rms = float(np.sqrt(np.mean(north[aided] ** 2 + east[aided] ** 2)))
    # the filters' bias states step by step: NaveGo's largest bias estimates against the drive's true biases
    b = np.abs(np.asarray(m["b"], float)) if "b" in m else np.full((1, 6), np.nan)
    gyro_est, accel_est = float(np.degrees(b[:, :3].max())), float(b[:, 3:].max())
    return [{**r, "aided_rms_h_m": rms, "max_gyro_bias_est_dps": gyro_est, "max_accel_bias_est_mps2": accel_est}
            for r in rows]


def _trace_rows(name: str, source: str, t: np.ndarray, t0: float, bias: np.ndarray) -> list[dict]:
    """Rows of :data:`TRACE_COLUMNS` (without date and commit): ``bias`` [n, 6] rad/s and m/s^2 at times ``t``."""
    b = np.asarray(bias, float).copy()
    b[:, :3] = np.degrees(b[:, :3])
    return [{"dataset": name, "source": source, "time_s": float(ti - t0), **dict(zip(TRACE_COLUMNS[3:9], map(float, r)))}
            for ti, r in zip(t, b)]


def navego_trace(nav_file: Path, name: str, variant: str, trace_s: float = TRACE_S) -> list[dict]:
    """NaveGo's bias estimates (``nav_e.b``) at its fixes of the first ``trace_s`` seconds, as trace rows."""
    m = scipy.io.loadmat(nav_file)
    tg, b = np.asarray(m["tg"], float).ravel(), np.asarray(m["b"], float)
    keep = tg <= tg[0] + trace_s
    return _trace_rows(name, f"NaveGo, {variant}", tg[keep], tg[0], b[keep])


def our_trace(drive, nav_section: dict, times: np.ndarray) -> list[dict]:
    """Our filter under NaveGo's setup (``nav.ins_tuning: navego``) and the drive's true biases at ``times`` (s;
    the first is the trace's zero), as trace rows; the truth only where the drive has one (a simulated IMU)."""
    t0 = float(times[0])
    est = run_drive(drive, {**(nav_section or {}), "ins_tuning": "navego"}).bias
    rows = _trace_rows(drive.name, OURS, times, t0, np.column_stack(
        [np.interp(times, est["time"].to_numpy(float), est[c].to_numpy(float)) for c in _BIAS]))
    if drive.imu_bias is not None:
        tb = drive.imu_bias
        rows += _trace_rows(drive.name, TRUTH, times, t0, np.column_stack(
            [np.interp(times, tb["time"].to_numpy(float), tb[c].to_numpy(float)) for c in _BIAS]))
    return rows


def merged(path: Path, new: pd.DataFrame, datasets) -> pd.DataFrame:
    """``new`` after the rows of ``path`` (when it exists) whose dataset was not run now: a run of some drives keeps
    the others' measurements."""
    if not Path(path).is_file():
        return new
    old = pd.read_csv(path)
    old = old[~old["dataset"].isin(list(datasets))]
    return pd.concat([old.reindex(columns=new.columns), new], ignore_index=True)


def octave_version(octave: str) -> str:
    out = subprocess.run([octave, "--version"], capture_output=True, text=True, timeout=60).stdout
    return out.splitlines()[0].strip() if out else "unknown"


def main(argv=None) -> int:
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--profile", default="quick")
    p.add_argument("--datasets", nargs="*", default=list(DATASETS))
    p.add_argument("--octave", default="octave")
    p.add_argument("--navego", default=str(NAVEGO_DIR), help="NaveGo's source (default ../shared/navego-v1.4)")
    p.add_argument("--fuse-velocity", action="store_true", help="NaveGo fuses the file's velocity (its own way)")
    p.add_argument("--variants", nargs="*", default=list(VARIANTS), choices=list(VARIANTS))
    p.add_argument("--out", default=str(NAVEGO_CHECK_FILE))
    p.add_argument("--trace-out", default=str(TRACE_FILE))
    p.add_argument("--trace-s", type=float, default=TRACE_S, help="seconds of the bias trace from the first fix")
    a = p.parse_args(argv)
    octave = shutil.which(a.octave)
    if octave is None:
        print("error: GNU Octave not found -- install it with `apt-get install -y octave octave-control` "
              "(Debian/Ubuntu), then run `make navego-check` again", file=sys.stderr)
        return 2
    if not (Path(a.navego) / "ins-gnss" / "ins_gnss.m").is_file():
        print(f"error: NaveGo's source not found in {a.navego} (expected ins-gnss/ins_gnss.m)", file=sys.stderr)
        return 2
    cfg = load_profile(a.profile)
    nav = nav_config(cfg["nav"])
    rows, trace, version = [], [], octave_version(octave)
    stamp = {"date": datetime.date.today().isoformat(), "commit": git_commit() or "unknown"}
    for name in a.datasets:
        drive = load_drive(name, profile=a.profile)
        windows = outage_windows(cfg, drive, name)
        imu_s, gnss_s, setting = export(drive, windows, nav, a.fuse_velocity)
        for variant in a.variants:
            with tempfile.TemporaryDirectory() as tmp:
                tmp = Path(tmp)
                navego = Path(a.navego).resolve()
                if variant != VARIANTS[0]:
                    navego = patched_navego(navego, tmp)
                scipy.io.savemat(tmp / "in.mat", {"imu": imu_s, "gnss": gnss_s, "att_mode": "quaternion"})
                print(f"==> {name}: NaveGo's ins_gnss ({variant}) under {version} ({len(imu_s['t'])} IMU rows, "
                      f"{len(gnss_s['t'])} fixes, {setting})", flush=True)
                cmd = [octave, "--no-gui", "--quiet", "--no-window-system", "--eval",
                       f"addpath('{PROJECT_ROOT / 'tools'}'); navego_check('{tmp / 'in.mat'}', '{tmp / 'out.mat'}', "
                       f"'{navego}')"]
                subprocess.run(cmd, check=True, cwd=tmp)     # Octave writes a crash dump (octave-workspace) where it runs
                trace += navego_trace(tmp / "out.mat", name, variant, a.trace_s)
                for r in errors(tmp / "out.mat", drive, windows):
                    rows.append({"dataset": name, **r, "setting": setting, "navego": "v1.4 (ins_gnss.m Version 011)",
                                 "variant": variant, "octave": version, **stamp})
                    print(f"    outage {r['outage']}: max |E| {r['max_east_m']:.2f} m, max |N| {r['max_north_m']:.2f} "
                          f"m; GPS-aided RMS {r['aided_rms_h_m']:.2f} m; largest bias estimates "
                          f"{r['max_gyro_bias_est_dps']:.3g} deg/s, {r['max_accel_bias_est_mps2']:.3g} m/s^2")
        fixes = np.array(sorted({r["time_s"] for r in trace if r["dataset"] == name}))
        trace += our_trace(drive, cfg["nav"], fixes + float(gnss_s["t"][0, 0]))
    table = merged(a.out, pd.DataFrame(rows, columns=list(NAVEGO_CHECK_COLUMNS)), a.datasets)
    atomic_write_csv(a.out, table, float_format="%.4f")
    print(f"wrote {a.out}")
    steps = merged(a.trace_out, pd.DataFrame([{**r, **stamp} for r in trace], columns=list(TRACE_COLUMNS)), a.datasets)
    atomic_write_csv(a.trace_out, steps, float_format="%.6g")
    print(f"wrote {a.trace_out}")
    return 0


if __name__ == "__main__":
    sys.exit(main())

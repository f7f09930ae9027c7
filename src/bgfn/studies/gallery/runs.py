"""The gallery of own logs (notebook 09): each log of :data:`bgfn.studies.gallery.logs.GALLERY` loaded through the CSV path
and run through the navigation part of the chain with the profile a user would write for it.

For each log: what the loader decided (the clocks: the GNSS-IMU offset it estimated or applied; the mounting it
rotated out; the platform), what the filter decided (self-alignment, noise scale, which aids run and why: notebook
02's facts, :class:`bgfn.nav.baseline.Baseline`), the outages its profile's rule picked, and the results:
the GPS-aided horizontal RMS and max against the reference, the standalone INS and the INS with the platform's aids
in those outages. The networks' rows of such a log come from ``make reproduce PROFILE=<its profile>`` (the whole
chain, minutes to tens of minutes); the gallery keeps to what runs in seconds so that every build shows it.
:mod:`bgfn.report.gallery_words` puts the decisions in words.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from bgfn.data import dataset_id, load_drive
from bgfn.data.csv_meta import META_FILE, read_meta
from bgfn.data.names import dataset_folder
from bgfn.studies.gallery.logs import GalleryLog
from bgfn.nav.baseline import Baseline, nav_config, run_baseline
from bgfn.nav.constraints import DEFAULT_PLATFORM, platform_aids
from bgfn.nav.outage_rules import PickedOutages
from bgfn.nav.outages import outage_windows, picked_outages

#: Columns of ``tables/gallery.csv``.
GALLERY_COLUMNS: tuple[str, ...] = ("log", "kind", "platform", "duration_s", "imu_rows", "gnss_fixes", "noise_scale",
                                    "gps_rms_h_m", "gps_max_h_m", "outage", "start_s", "method", "max_h_m")


@dataclass
class GalleryRun:
    """One log's run: its profile text, ``meta.yaml``, its rows (:data:`GALLERY_COLUMNS`), the loaded drive with its
    outages (for the figures), and what the loader and the filter decided (the drive's ``meta``, the KF baseline
    run, what the profile's rule picked, None for a list; :func:`bgfn.report.gallery_words.gallery_decisions`
    words them). ``entry`` is the drive's name in the profile (its id)."""

    log: GalleryLog
    profile_text: str
    meta_text: str
    rows: pd.DataFrame
    drive: object = None
    windows: list | None = None
    baseline: Baseline | None = None
    picked: PickedOutages | None = None
    entry: str = ""


def run_log(log: GalleryLog, folder: Path, cfg: dict) -> GalleryRun:
    """Load ``folder`` by its absolute path and run the GPS-aided filter and its outages under ``cfg`` (the loaded
    profile the log's :meth:`~bgfn.studies.gallery.logs.GalleryLog.profile_text` describes)."""
    folder = Path(folder).resolve()
    drive = load_drive(folder)
    windows = outage_windows(cfg, drive, drive.name)      # the profile names an own log by its id (its drive's name)
    b = run_baseline(drive, nav_config(cfg["nav"]), windows, keep=False)   # a gallery log: read once
    base = {"log": drive.name, "kind": log.kind, "platform": drive.meta.get("platform", DEFAULT_PLATFORM),
            "duration_s": float(drive.imu["time"].iloc[-1] - drive.imu["time"].iloc[0]), "imu_rows": len(drive.imu),
            "gnss_fixes": len(drive.gnss), "noise_scale": float(b.setup.noise_scale) if b.setup is not None else 1.0,
            "gps_rms_h_m": float(b.rms.loc["horizontal", "rms"]),        # GPS-aided, against the reference, m
            "gps_max_h_m": float(b.rms.loc["horizontal", "max_abs"])}
    rows = []
    aided = _aided_label(base["platform"])
    for k, (start, _) in enumerate(windows, start=1):
        for _, r in b.outage_table[b.outage_table["outage"] == f"outage_{k}"].iterrows():
            rows.append({**base, "outage": k, "start_s": float(start),
                         "method": "INS" if r["method"] == "INS" else aided, "max_h_m": float(r["max_horizontal"])})
    meta_text = (folder / "meta.yaml").read_text(encoding="utf-8")
    return GalleryRun(log, log.profile_text(folder), meta_text, pd.DataFrame(rows, columns=list(GALLERY_COLUMNS)),
                      drive, list(windows), b, picked_outages(cfg, drive, drive.name), drive.name)


def own_logs(cfg: dict) -> list[tuple[GalleryLog, Path]]:
    """The CSV folders the profile names itself (``data.datasets``), as logs of the page with their folders: notebook
    09 shows them rather than the built-in gallery; [] for a profile of the shipped drives."""
    out = []
    for name in cfg["data"]["datasets"]:
        folder = dataset_folder(name, cfg["profile"])      # a loaded profile names its folders by id
        if folder is None:
            continue
        meta = read_meta(folder / META_FILE)
        platform = str(meta.get("platform", DEFAULT_PLATFORM))
        out.append((GalleryLog(dataset_id(name), platform, cfg["profile"], {}, "this profile's own log", own=True),
                    folder))
    return out


def _aided_label(platform: str) -> str:
    """The aided row's name for a platform: ``INS+NHC`` for a car (the project's name, ZUPT included), else the
    aids it takes (``INS+ZUPT`` for a walker; ``INS`` again for ``other``, which takes none)."""
    if platform == "car":
        return "INS+NHC"
    aids = platform_aids(platform)
    return "+".join(("INS", *aids)) if aids else "INS (no aid)"


def gallery_table(runs: list[GalleryRun]) -> pd.DataFrame:
    """All runs' rows, one table (``tables/gallery.csv``)."""
    return pd.concat([r.rows for r in runs], ignore_index=True) if runs else pd.DataFrame(columns=list(GALLERY_COLUMNS))


def gallery_pivot(table: pd.DataFrame) -> pd.DataFrame:
    """One row per log: its GPS-aided RMS and max, and per outage the max horizontal error of the INS alone and with
    the platform's aids (``aided row`` names them)."""
    rows = []
    for log, g in table.groupby("log", sort=False):
        first = g.iloc[0]
        row = {"log": log, "kind": first["kind"], "platform": first["platform"], "noise scale": first["noise_scale"],
               "GPS/INS RMS (m)": first["gps_rms_h_m"], "GPS/INS max (m)": first["gps_max_h_m"],
               "aided row": next((m for m in g["method"] if m != "INS"), "-")}
        for k, go in g.groupby("outage", sort=True):
            ins = go.loc[go["method"] == "INS", "max_h_m"]
            aid = go.loc[go["method"] != "INS", "max_h_m"]
            row[f"outage {k}: INS (m)"] = float(ins.iloc[0]) if len(ins) else np.nan
            row[f"outage {k}: aided (m)"] = float(aid.iloc[0]) if len(aid) else np.nan
        rows.append(row)
    return pd.DataFrame(rows)

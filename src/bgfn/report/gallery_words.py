"""The gallery of own logs in words (notebook 09): what the loader and the filter decided for each log."""

from __future__ import annotations

import numpy as np

from bgfn.report.data_checks import clock_offset_line
from bgfn.report.nav_words import baseline_lines, window_lines
from bgfn.studies.gallery.runs import GalleryRun


def gallery_decisions(run: GalleryRun) -> list[str]:
    """What was decided for one log (:class:`bgfn.studies.gallery.runs.GalleryRun`), one line each: the clocks (the
    GNSS-IMU offset estimated or applied), the mounting rotated out, the outages (and the rule's picks), then the
    filter's decisions (:func:`bgfn.report.nav_words.baseline_lines`)."""
    drive, decisions = run.drive, []
    if "gnss_offset" in drive.meta:            # the clocks (with gnss_latency_s: auto, the latency taken off)
        decisions.append(clock_offset_line(drive.meta["gnss_offset"], drive.name))
    mounting = drive.meta.get("imu_mounting_deg") or [0.0, 0.0, 0.0]
    if np.any(mounting):
        decisions.append(f"{drive.name}: IMU rows rotated into the body frame by the mounting "
                         f"{[float(x) for x in mounting]} deg (roll, pitch, yaw) of meta.yaml")
    return decisions + window_lines(run.entry, run.windows, run.picked) + baseline_lines(run.baseline)

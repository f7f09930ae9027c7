"""The KF baseline in words (notebooks 01, 02 and 09): the outage windows a drive gets, the self-alignment, the
noise search, the NIS verdict and the aids of the ``INS+NHC`` rows."""

from __future__ import annotations

import numpy as np

from bgfn.nav import constraints as cn
from bgfn.nav.alignment import Alignment
from bgfn.nav.baseline import Baseline, FilterSetup
from bgfn.nav.consistency import nis_summary
from bgfn.nav.outage_rules import PickedOutages
from bgfn.nav.outages import outage_windows, picked_outages
from bgfn.nav.tuning import NoiseTuning
from bgfn.report.aid_words import aid_label, constraint_words


def picked_outage_lines(picked: PickedOutages) -> list[str]:
    """One line per window a rule picked: its kind, time, mean speed and mean |yaw rate|."""
    return [f"outage {k + 1} ({r.kind}): {picked.rule['duration_s']:g} s from {r.start_s:.1f} s, mean speed "
            f"{r.mean_speed_mps:.1f} m/s, mean |yaw rate| {r.mean_abs_yaw_rate_dps:.1f} deg/s"
            for k, r in enumerate(picked.scores.itertuples(index=False))]


def describe_windows(profile: dict, drive, dataset: str | None = None) -> list[str]:
    """Lines for a notebook: the outages of one drive and, for a rule, what it picked and why."""
    name = dataset if dataset is not None else drive.name     # the profile's entry (an own log: its folder's path)
    return window_lines(drive.name, outage_windows(profile, drive, name), picked_outages(profile, drive, name))


def window_lines(name: str, windows, picked: PickedOutages | None) -> list[str]:
    """The outages ``windows`` of drive ``name`` and, when a rule ``picked`` them, what it picked and why."""
    head = f"{name}: outages (start, duration) s {[list(w) for w in windows]}"
    if picked is None:
        return [head + " (listed in the profile)"]
    return [head + f" (rule {picked.rule['rule']})"] + [f"  {line}" for line in picked_outage_lines(picked)]


def alignment_line(alignment: Alignment, name: str = "") -> str:
    """One plain sentence: when and how the filter was aligned (:mod:`bgfn.nav.alignment`)."""
    a = alignment
    rest = f"rest until {a.rest_end:.1f} s" if a.rest_end is not None else "no rest at the start"
    return (f"{name + ': ' if name else ''}aligned at {a.state.time:.2f} s ({rest}; level from "
            f"{a.level_source.replace('_', ' ')}, heading from the {a.course_source.replace('_', ' ')} "
            f"since {a.moving_from:.1f} s): roll {np.degrees(a.roll):.2f}, pitch "
            f"{np.degrees(a.pitch):.2f}, yaw {np.degrees(a.yaw):.2f} deg (std level "
            f"{np.degrees(a.level_std):.2f}, azimuth {np.degrees(a.azimuth_std):.2f} deg)")


def tuning_line(tuning: NoiseTuning, name: str = "") -> str:
    """One plain sentence of the noise search (:mod:`bgfn.nav.tuning`): the factor found and the mean NIS before
    and after."""
    t = tuning
    what = "white noise and bias walk" if t.bias_walk else "white noise"
    bound = " (at the bound of nav.noise_search.range)" if t.at_bound else ""
    return (f"{name + ': ' if name else ''}noise scale auto: {what} x {t.scale:.3g}{bound} after "
            f"{len(t.runs)} filter runs; mean NIS {t.mean_nis_at_one:.2f} -> {t.mean_nis:.2f} "
            f"(dof {t.dof:.0f})")


def setup_lines(setup: FilterSetup, name: str) -> list[str]:
    """Plain sentences for notebook 02: the alignment and the noise search, when there were any."""
    out = [alignment_line(setup.alignment, name)] if setup.alignment is not None else []
    return out + ([tuning_line(setup.tuning, name)] if setup.tuning is not None else [])


def nis_line(name: str, summary: dict) -> str:
    """One plain sentence of a :func:`bgfn.nav.consistency.nis_summary`."""
    if not summary["fixes"]:
        return f"{name}: no GNSS fixes fused, no NIS"
    hint = {"overconfident": ": the filter trusts its prediction more than the fixes allow (IMU noise too low "
                             "for this drive, or GNSS stds too small? try nav.noise_scale: auto)",
            "underconfident": ": the innovations are smaller than the filter expects (GNSS stds or IMU noise set "
                              "larger than the drive's)"}.get(summary["verdict"], "")
    return (f"{name}: mean NIS {summary['mean_nis']:.2f} over {summary['fixes']} GNSS fixes (dof "
            f"{summary['dof']:.0f}; {100 * summary['above_chi2_95']:.0f} % above the chi-square 95 % quantile, "
            f"5 % expected): {summary['verdict']}{hint}")


def baseline_aid_lines(baseline: Baseline) -> list[str]:
    """Which aids the ``INS+NHC`` rows ran (named by them: ``INS+ZUPT`` on a walker), and why (the drive's
    platform), with their epoch counts."""
    c = baseline.constraints
    if not c:
        return []
    platform = c.get("platform", cn.DEFAULT_PLATFORM)
    what = constraint_words(cn.ConstraintConfig(platform=platform))
    return [f"{baseline.drive_name}: the {aid_label('INS+NHC', platform)} rows' aids -- {what}; {c['aid_epochs']} "
            f"aid epochs over the drive, {c['zupt_epochs']} of them ZUPT "
            f"(still {100 * c['still_fraction']:.0f} % of the IMU rows)"]


def baseline_lines(baseline: Baseline) -> list[str]:
    """Notebook 02's sentences of a KF baseline run (:class:`bgfn.nav.baseline.Baseline`): the self-alignment and
    the noise search (when they ran), the NIS verdict of the GPS-aided run (:func:`nis_line`) and the aids."""
    setup = setup_lines(baseline.setup, baseline.drive_name) if baseline.setup is not None else []
    return setup + [nis_line(baseline.drive_name, nis_summary(baseline.full.updates))] + baseline_aid_lines(baseline)

"""The fleet study's words (notebook 11): its tables' labels, the lines under them and the learning curve's figure,
made from :mod:`bgfn.studies.fleet`'s numbers."""

from __future__ import annotations

import math

import matplotlib.pyplot as plt
import pandas as pd

from bgfn.paper import nhc_label
from bgfn.studies.fleet.protocol import LEARNED
from bgfn.studies.fleet.summary import POOLED
from bgfn.studies.odometer.bars import HOLD, odometer_label
from bgfn.studies.odometer.section import odometer_table
from bgfn.report.sample_words import INPUT_WORDS

#: The ``speed_range`` codes in words.
RANGE_WORDS = {"all": "every outage", "in": "outages inside the training drives' speeds and turn rates",
               "out": "outages outside the training drives' speeds or turn rates"}
#: The pooled rows' name in words.
POOLED_WORDS = "all test drives (pooled)"


def drive_words(name: str) -> str:
    """A drive's name as a table shows it (the pooled rows in words)."""
    return POOLED_WORDS if name == POOLED else name


#: What a network reads (``fleet.inputs``, ``evaluate.odometer.inputs``) in words.


def fleet_title(facts: dict) -> str:
    """What the fleet is, in one line: pieces of one drive are said to be that; and what each network reads."""
    reads = "".join(f" {odometer_label(m)} reads {INPUT_WORDS.get(i, i)}." for m, i in (facts.get("inputs") or {}).items())
    if facts.get("pieces"):
        return (f"A stand-in for a fleet: one drive cut into {facts['pieces']} contiguous pieces (pieces of one drive, "
                "one mount and one day, not drives of a fleet); protocol "
                f"{facts['protocol'].replace('_', '-')}, at {facts['rate_hz']:g} Hz.{reads}")
    return f"A fleet of drives; protocol {facts['protocol'].replace('_', '-')}, at {facts['rate_hz']:g} Hz.{reads}"


def _num(v, fmt: str = ".2f") -> str:
    return "n/a" if v is None or (isinstance(v, float) and math.isnan(v)) else format(v, fmt)


def _pct(v) -> str:
    return "n/a" if v is None or (isinstance(v, float) and math.isnan(v)) else f"{100.0 * v:.0f} %"


def preparation_lines(prep: pd.DataFrame) -> list[str]:
    """Per drive: how it was made comparable (levelling, scale, gyro bias, rate, bandwidth, label)."""
    lines = []
    for r in prep.itertuples():
        if r.standstill_s > 0:
            level = (f"levelled by roll {r.tilt_roll_deg:+.2f} deg and pitch {r.tilt_pitch_deg:+.2f} deg, accelerometer "
                     f"scaled by {r.accel_scale:.4f} and gyro de-biased by ({r.gyro_bias_x_dps:+.3f}, "
                     f"{r.gyro_bias_y_dps:+.3f}, {r.gyro_bias_z_dps:+.3f}) deg/s from {r.standstill_s:.0f} s standing")
        else:
            level = "no standstill long enough: not levelled, scaled or de-biased"
        label = ("its speed label unchecked (no GNSS velocity)" if not r.label_checked else
                 "its speed label agreeing with the GNSS speed throughout" if r.label_disagree_s == 0 else
                 f"{r.label_disagree_s:.0f} s where the reference and GNSS speeds disagree "
                 + ("left out" if r.label_action == "drop" else "labelled from the GNSS speed"))
        rate = (f"resampled from {r.native_rate_hz:g} Hz to {r.rate_hz:g} Hz" if abs(r.native_rate_hz - r.rate_hz) > 1e-6
                else f"at {r.rate_hz:g} Hz")
        if r.imu_gaps:
            rate += f" ({r.imu_gaps} IMU gap{'s' if r.imu_gaps > 1 else ''} kept as gaps)"
        lines.append(f"{r.drive} ({r.duration_s / 60:.1f} min, up to {r.speed_max_mps:.1f} m/s): {level}; {rate}, "
                     f"low-passed at {r.cutoff_hz:g} Hz; {label}.")
    return lines


def fleet_markdown(summary: pd.DataFrame, speed_range: str = "all") -> str:
    """The odometer table of the fleet (median max horizontal error, m, per test drive and pooled, a column per
    duration) for one speed range, as Markdown."""
    s = summary[summary["speed_range"] == speed_range]
    if s.empty:
        return f"No rows for {RANGE_WORDS[speed_range]}."
    wide = odometer_table(s.drop(columns=["speed_range"]))
    drives = [d for d in dict.fromkeys(s["dataset"]) if d != POOLED] + [POOLED]        # the pooled rows last
    wide = wide.iloc[sorted(range(len(wide)), key=lambda i: (drives.index(wide.index[i][0]), i))]
    head = "| test drive | method | " + " | ".join(wide.columns) + " |"
    body = [f"| {drive_words(ds)} | {m} | " + " | ".join(_num(v, ".1f") for v in r) + " |"
            for (ds, m), r in wide.iterrows()]
    return "\n".join([f"Median max horizontal error (m), {RANGE_WORDS[speed_range]}:", "", head,
                      "|---" * (len(wide.columns) + 2) + "|", *body])


def verdict_lines(summary: pd.DataFrame, offsets: pd.DataFrame) -> list[str]:
    """Per test drive and pooled, at the longest duration, for every learned odometer of the table (RIDGE-ODO, each
    network, each ensemble): its median max error against INS+NHC (ratio, Wilcoxon p, Holm-adjusted p), its offset
    per outage against the held speed's, and its sigma judged on the epochs and on the outages' means."""
    s = summary[summary["speed_range"] == "all"]
    if s.empty:
        return []
    d = float(s["duration_s"].max())
    lines = []
    for ds, g in s[s["duration_s"] == d].groupby("dataset", sort=False):
        n = g[g["method"] == nhc_label("INS")]
        if n.empty:
            continue
        n = n.iloc[0]
        o = offsets[(offsets["speed_range"] == "all") & (offsets["dataset"] == ds) & (offsets["duration_s"] == d)]
        held = o.loc[o["method"] == HOLD, "offset_rms_mps"]
        for method in (m for m in LEARNED if m in set(g["method"])):
            r = g[g["method"] == method].iloc[0]
            own = o[o["method"] == method]
            off_text = (f"; its offset per outage {own['offset_rms_mps'].iloc[0]:.2f} m/s RMS against the held "
                        f"speed's {held.iloc[0]:.2f} m/s" if len(own) and len(held) else "")
            if len(own) and "mean_within_2sigma" in own:
                off_text += (f"; within its 2 sigma: {_pct(own['epoch_within_2sigma'].iloc[0])} of the epochs' "
                             f"speed errors, {_pct(own['mean_within_2sigma'].iloc[0])} of the outages' mean errors "
                             "(the mean's sigma as the filter weighs it)")
            lines.append(f"{drive_words(ds)}, {d:g} s outages ({int(r['runs'])}): {method} {r['max_h_m']:.1f} m "
                         f"against {nhc_label('INS')} {n['max_h_m']:.1f} m (median per-start ratio "
                         f"{r['ratio_to_nhc']:.2f}, Wilcoxon p {_num(r['p_vs_nhc'])}, Holm-adjusted "
                         f"{_num(r['p_vs_nhc_holm'])}){off_text}.")
    return lines


def coverage_lines(motion: pd.DataFrame, flags: pd.DataFrame) -> list[str]:
    """Per test drive: its speeds and turn rates against its training drives', and the outages out of range (by
    speed, by turn rate)."""
    lines = []
    for test, g in motion.groupby("test_drive", sort=False):
        t, tr = g[g["role"] == "test"].iloc[0], g[g["role"] == "training"].iloc[0]
        f = flags[(flags["dataset"] == test) & (flags["duration_s"] == flags["duration_s"].max())]
        turn = (f"turn rate (the mean over the odometer's window) 95th percentile {t.turn_p95_dps:.1f}, max "
                f"{t.turn_max_dps:.1f} against {tr.turn_p95_dps:.1f}, {tr.turn_max_dps:.1f} deg/s")
        lines.append(f"{test}: speed median {t.speed_p50_mps:.1f}, 95th percentile {t.speed_p95_mps:.1f}, max "
                     f"{t.speed_max_mps:.1f} m/s against the training drives' {tr.speed_p50_mps:.1f}, "
                     f"{tr.speed_p95_mps:.1f}, {tr.speed_max_mps:.1f} m/s; {turn}; of {len(f)} outages of "
                     f"{f['duration_s'].max():g} s, {int(f['speed_out_of_range'].sum())} outside the training speeds "
                     f"and {int(f['turn_out_of_range'].sum())} outside their turn rates.")
    return lines


def curve_lines(curve: pd.DataFrame) -> list[str]:
    """The learning curve per learned odometer and number of training drives: the median over test drives, training
    sets and seeds."""
    if curve.empty:
        return []
    lines = []
    for method, c in curve.groupby("method", sort=False):
        g = c.groupby("n_train").agg(minutes=("train_min", "median"), offset=("offset_rms_mps", "median"),
                                     rmse=("speed_rmse_mps", "median"), maxh=("median_max_h_m", "median"),
                                     sets=("offset_rms_mps", "size"))
        lines.append(f"{method} against its training data (median over the test drives, training sets and seeds): "
                     + "; ".join(f"{n} drive{'s' if n > 1 else ''} ({r.minutes:.1f} min, {int(r.sets)} sets): offset "
                                 f"per outage {r.offset:.2f} m/s, speed RMSE {r.rmse:.2f} m/s, median max error "
                                 f"{r.maxh:.1f} m" for n, r in g.iterrows()) + ".")
    return lines


def plot_curve(curve: pd.DataFrame):
    """The learning curve: the offset per outage, the speed RMSE and the median max error against training minutes,
    a dot per training set (and seed), a line per test drive and learned odometer through the medians per number of
    training drives."""
    fig, axes = plt.subplots(1, 3, figsize=(10, 3.2))
    cols = [("offset_rms_mps", "offset per outage, RMS (m/s)"), ("speed_rmse_mps", "speed RMSE (m/s)"),
            ("median_max_h_m", "median max error (m)")]
    methods = list(dict.fromkeys(curve["method"]))
    styles = dict(zip(methods, ["-", "--", ":", "-."] * len(methods)))
    for ax, (c, label) in zip(axes, cols):
        for (test, method), g in curve.groupby(["test_drive", "method"], sort=False):
            # each training set a dot, the line through the median per number of training drives
            med = g.groupby("n_train")[["train_min", c]].median()
            name = test if len(methods) == 1 else f"{test}, {method}"
            line = ax.plot(med["train_min"], med[c], styles[method], lw=1.2, label=name)[0]
            ax.plot(g["train_min"], g[c], "o", ms=3, alpha=0.6, color=line.get_color())
        ax.set_xlabel("training minutes")
        ax.set_ylabel(label)
        ax.set_ylim(bottom=0)
    axes[0].legend(fontsize=6)
    who = methods[0] if len(methods) == 1 else "The learned odometers"
    fig.suptitle(f"{who} on drives never seen, against the minutes trained on", fontsize=9)
    fig.tight_layout()
    return fig


#: The rows of the gallery's check (:data:`bgfn.studies.fleet.gallery.ROLES`) in words.
ROLE_WORDS = {"car_span": "car log, over the phone's span", "phone": "phone log", "car_whole": "car log, whole drive"}
#: The gallery check's agreement columns (:data:`bgfn.studies.fleet.gallery.AGREEMENT_COLUMNS`) as the table heads them.
AGREEMENT_HEADS = {"channel": "prepared channel", "unit": "unit", "rms": "RMS over the phone's span",
                   "same_span_max_diff": "max |car - phone|, same span prepared",
                   "whole_log_max_diff": "max |car - phone|, whole car log prepared",
                   "whole_log_rest_max_diff": "the same, levellings taken out"}


def gallery_tables(check) -> tuple[pd.DataFrame, pd.DataFrame]:
    """The gallery check's preparation (a column per log, its rows the numbers) and agreement tables, headed in
    words."""
    prep = check.preparation.assign(role=check.preparation["role"].map(ROLE_WORDS)).set_index("role")
    keep = [c for c in prep.columns if c.startswith(("mounting_", "tilt_", "gyro_bias_"))
            or c in ("duration_s", "standstill_s", "accel_scale", "rate_hz", "cutoff_hz", "label_checked")]
    agree = check.agreement.rename(columns=AGREEMENT_HEADS).set_index(AGREEMENT_HEADS["channel"])
    return prep[keep].T.rename_axis(None, axis=1), agree


def no_gallery_line() -> str:
    """What notebook 11 says when the profile does not load the drive the gallery's logs are made of."""
    return ("The gallery's car and phone logs are made of the shipped real drive (rtklib-drive0708), which this "
            "profile does not load: their check is not shown.")


def _agree(diff: float, unit: str) -> str:
    """How closely two prepared numbers agree: exactly, or to their largest difference (unknown: rows differ)."""
    if math.isnan(diff):
        return "not row for row: their rows differ"
    return "exactly" if diff == 0 else f"to {diff:.1g}{' ' + unit if unit else ''}"


def gallery_lines(check) -> list[str]:
    """What the gallery's logs show through the fleet's preparation (:func:`bgfn.studies.fleet.gallery.gallery_check`):
    what they are (one drive and a walk, not a fleet), the phone's mounting and clock undone, and the whole car log's
    own levelling."""
    f, prep = check.facts, check.preparation.set_index("role")
    agree = check.agreement.set_index("channel")
    imu = agree.drop(index="speed")
    accel, gyro = imu[imu["unit"] == "m/s^2"], imu[imu["unit"] == "rad/s"]
    car, phone, whole = prep.loc["car_span"], prep.loc["phone"], prep.loc["car_whole"]
    keys = ["tilt_roll_deg", "tilt_pitch_deg", "accel_scale", *(f"gyro_bias_{a}_dps" for a in "xyz")]
    worst = max(abs(float(phone[k]) - float(car[k])) for k in keys)
    mount = ", ".join(f"{v:g}" for v in f["phone_mounting_deg"])
    return [
        "The gallery's logs are one drive and a walk, not a fleet: the phone log is the car drive's first "
        f"{f['span_s']:.0f} s, its IMU turned by ({mount}) deg and its clock {f['phone_imu_offset_s']:g} s early, both "
        "stated in its meta.yaml; the walker is a pedestrian, and a fleet refuses it (fleet.drives: a fleet is drives "
        "of a vehicle with the non-holonomic constraint, which a walker's sideways steps break).",
        ("What they show is that the preparation undoes a phone's mounting and clock: prepared with the fleet's "
         if f.get("same_span_agrees") else
         "They show that the preparation did NOT undo the phone's mounting or clock (more than float rounding "
         "apart): prepared with the fleet's ")
        + f"settings over the same span, the phone's {f['rows']} and the car's {f['car_rows']} rows lie on the same "
        f"times ({_agree(f['max_time_diff_s'], 's')}), their accelerometer channels agree "
        f"({_agree(accel['same_span_max_diff'].max(), 'm/s^2')}) and so do their gyro channels "
        f"({_agree(gyro['same_span_max_diff'].max(), 'rad/s')}), their tilt, accelerometer scale and gyro bias "
        f"({_agree(worst, '')}) and their speed labels ({_agree(agree.loc['speed', 'same_span_max_diff'], 'm/s')}; "
        "the car's checked against its GNSS speed, the phone's unchecked: its fixes carry no velocity).",
        f"As a fleet holds them, the whole car log is levelled from its {whole['standstill_s']:.0f} s standing, the "
        f"phone log from the {phone['standstill_s']:.0f} s of its span: their tilts differ by "
        f"{whole['tilt_roll_deg'] - phone['tilt_roll_deg']:+.2f} deg in roll and "
        f"{whole['tilt_pitch_deg'] - phone['tilt_pitch_deg']:+.2f} deg in pitch (the road's slope where each stood, "
        "which levelling from standstills cannot tell from a mount's tilt), so their channels differ by up to "
        f"{accel['whole_log_max_diff'].max():.2f} m/s^2 and {gyro['whole_log_max_diff'].max():.4f} rad/s; with the two "
        f"levellings, scales and gyro biases taken out, {max(accel['whole_log_rest_max_diff'].max(), 0.0):.1g} m/s^2 "
        f"and {max(gyro['whole_log_rest_max_diff'].max(), 0.0):.1g} rad/s are left (more than {f['edge_s']:g} s from "
        "the phone's ends).",
    ]


__all__ = ["RANGE_WORDS", "POOLED_WORDS", "drive_words", "fleet_title", "preparation_lines", "fleet_markdown",
           "verdict_lines", "coverage_lines", "curve_lines", "plot_curve", "ROLE_WORDS", "AGREEMENT_HEADS", "gallery_tables",
           "no_gallery_line", "gallery_lines"]

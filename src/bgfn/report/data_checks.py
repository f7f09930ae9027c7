"""Notebook 01's checks in words: the fixes against the reference, the reference's attitude, the GNSS-IMU clock.

The numbers come from :func:`bgfn.data.reference_check.drive_checks` (the offsets and the lag,
:mod:`bgfn.data.reference_check`; the attitude, :mod:`bgfn.nav.reference_attitude`; the clock decision of a CSV
drive, :func:`bgfn.data.time_offset.decide_clock`).
"""

from __future__ import annotations

#: The likely cause of a median offset beyond the tolerance, in words (``cause`` codes of the reference check).
CAUSE_WORDS = {
    "latency": "a clock offset between the fixes and the reference (the along-track offset follows the speed): "
               "gnss_latency_s in meta.yaml, or the files' time bases",
    "lever_arm_or_datum": "a constant offset, not a lag: the antenna's lever_arm_m, the reference's point "
                          "(reference_lever_arm_m) or a datum between the two",
}
#: Why a reference attitude is not the filter's start (``reason`` codes of the attitude check).
ATTITUDE_WORDS = {
    "yaw_vs_course": "its yaw is off the course while driving straight",
    "level_vs_imu": "its roll/pitch is off the IMU's own levelling at rest",
}
#: What became of an estimated clock offset (``status`` codes of the clock decision).
CLOCK_WORDS = {
    "applied": "the two agree: their weighted mean taken off the fixes' stamps",
    "not_asked": "not applied (meta.yaml states the latency)",
    "not_estimable": "not estimable from the turn rates (too few turns while moving faster than 2 m/s): nothing "
                     "applied",
    "not_significant": "within its uncertainty of zero: nothing applied",
    "unconfirmed": "not applied: no independent reference to confirm it",
    "disagrees": "not applied: the reference's lag disagrees",
    "refused_by_key": "refused: a latency gnss_latency_s refuses when typed (negative, or beyond 5 s)",
    "worse": "not applied: it widens the fixes' along-track error against the reference",
}


def _pm(x, s, unit: str = "s") -> str:
    if x is None:
        return "none"
    return f"{x:+.2f} {unit}" + (f" +- {s:.2f} {unit}" if s is not None else "")


def _estimate_words(offset: dict) -> str:
    """The turn-rate estimate of a clock decision's record, as notebook 01 said it at load."""
    corr = "none" if offset["correlation"] is None else f"{offset['correlation']:.2f}"
    if offset["turn_rate_s"] is None:
        return (f"GNSS-IMU clock offset: not estimable ({offset['fixes']} moving fixes, best correlation {corr} of "
                "the turn rates)")
    return (f"GNSS-IMU clock offset: the fixes' stamps are {offset['turn_rate_s']:+.2f} s late against the IMU's "
            f"(turn rates correlate {corr} over {offset['fixes']} moving fixes)")


def clock_offset_line(offset: dict, name: str | None = None, platform: str | None = None) -> str:
    """A CSV drive's clocks as decided at load (``meta["gnss_offset"]``,
    :meth:`bgfn.data.time_offset.ClockDecision.record`) in one sentence: the turn-rate estimate, and with
    ``gnss_latency_s: auto`` the latency taken off and why (its status code); ``name:`` before it and ``; platform
    <platform>`` after it when given."""
    text = _estimate_words(offset)
    if offset["status"] != "not_asked":                 # gnss_latency_s: auto
        text = (f"GNSS latency {offset['applied_s']:.2f} s taken off (gnss_latency_s: auto, {offset['status']}); "
                f"estimated: {text}")
    return (f"{name}: " if name else "") + text + (f"; platform {platform}" if platform else "")


def reference_lines(name: str, checks: dict) -> list[str]:
    """The checks of one drive (:func:`bgfn.data.reference_check.drive_checks`), one sentence each."""
    ref, att, clock = checks["reference"], checks["attitude"], checks["clock"]
    out = []
    if ref["equals_gnss"]:
        out.append(f"{name}: the reference equals the GNSS fixes (every fix within millimetres, "
                   "bgfn.data.reference_check.EQUAL_TOLERANCE_M): an error against it measures how closely a solution "
                   "follows the fixes, not its accuracy")
    elif ref["along_median_m"] is None:
        out.append(f"{name}: fixes against the reference: too few moving fixes ({ref['fixes']}) to compare")
    else:
        out.append(f"{name}: {ref['fixes']} moving fixes against the reference: along track median "
                   f"{ref['along_median_m']:+.2f} m (scaled MAD {ref['along_mad_m']:.2f} m, 5-95 % "
                   f"{ref['along_p05_m']:+.2f} to {ref['along_p95_m']:+.2f} m), across track median "
                   f"{ref['cross_median_m']:+.2f} m (scaled MAD {ref['cross_mad_m']:.2f} m); the lag that best "
                   f"explains the along-track offsets {_pm(ref['lag_s'], ref['lag_std_s'])}")
    if att is not None:
        yaw, level = att["yaw_minus_course_deg"], att["level_minus_imu_deg"]
        facts = []
        if yaw is not None:
            facts.append(f"yaw minus course {yaw[0]:+.1f} deg (5-95 % {yaw[1]:+.1f} to {yaw[2]:+.1f}) while driving "
                         "straight")
        if level is not None:
            facts.append(f"roll/pitch minus the IMU's levelling at rest {level[0]:+.1f}/{level[1]:+.1f} deg")
        verdict = ("used as the filter's initial attitude (nav.alignment.mode: auto)" if att["usable"] else
                   f"not used as the filter's initial attitude: {ATTITUDE_WORDS[att['reason']]} by more than "
                   f"{att['tolerance_deg']:g} deg; the filter aligns itself from the IMU and the GNSS")
        out.append(f"{name}: reference attitude " + ("(" + "; ".join(facts) + ") " if facts else "") + verdict)
    if clock is not None:
        est = (f"turn rates {_pm(clock['turn_rate_s'], clock['turn_rate_std_s'])}"
               if clock["turn_rate_s"] is not None else "turn rates: none")
        lag = (f"the reference's lag {_pm(clock['reference_lag_s'], clock['reference_std_s'])}"
               if clock["reference_lag_s"] is not None else "no lag from the reference")
        text = f"{name}: GNSS-IMU clock offset ({est}; {lag}): {CLOCK_WORDS[clock['status']]}"
        if clock["status"] == "applied":
            text += f" ({_pm(clock['combined_s'], clock['combined_std_s'])})"
        if clock.get("rms_without_m") is not None:
            text += (f"; along-track RMS against the reference {clock['rms_without_m']:.2f} m without it, "
                     f"{clock['rms_with_m']:.2f} m with it")
        out.append(text)
    return out


def reference_warning(name: str, checks: dict) -> str | None:
    """The one warning of a drive whose fixes sit off the reference beyond the tolerance, its likely cause named;
    None otherwise."""
    ref = checks["reference"]
    if not ref["exceeds"] or ref["cause"] not in CAUSE_WORDS:
        return None
    lag = f" (a lag of {_pm(ref['lag_s'], ref['lag_std_s'])} explains it)" if ref["cause"] == "latency" else ""
    return (f"{name}: the GNSS fixes sit {ref['along_median_m']:+.1f} m along and {ref['cross_median_m']:+.1f} m "
            f"across the track from the reference (median; tolerance {ref['tolerance_m']:g} m, "
            f"data.reference_tolerance_m): likely {CAUSE_WORDS[ref['cause']]}{lag}. Errors against "
            "this reference include that offset.")

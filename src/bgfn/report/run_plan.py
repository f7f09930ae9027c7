"""The run plan in words (:mod:`bgfn.run_plan`, ``results/<profile>/run_plan.json``): per drive its span, its
outages as run (moved onto the IMU epochs where asked off them), what the outage rule made of it, and what the plan
scaled to the drives or switched off, and why. The profile check prints these lines, notebook 01 shows them."""

from __future__ import annotations

#: What each switched-off part is, in words.
PART_WORDS = {
    "evaluate.sweep.datasets": "the outage sweep (notebook 06; evaluate.sweep.datasets: [])",
    "evaluate.odometer.datasets": "the learned-odometer bars (notebook 07; evaluate.odometer.datasets: [])",
    "ins_drift": "the INS drift from the sweep's starts (notebook 08)",
    "nees_scan": "the NEES scan from the sweep's starts (notebook 08)",
}


def _windows(pairs) -> str:
    return "[" + ", ".join(f"[{s:.3f}, {d:g}]" for s, d in pairs) + "]"


def drive_lines(name: str, facts: dict) -> list[str]:
    """A drive of the plan: its span after the filter's start, its outages as run, the rule's thresholds, the
    split's windows."""
    run = [o["run"] for o in facts["outages"]]
    lines = [f"{name}: {facts['span_s']:.1f} s from the filter's start {facts['t_first']:.2f} s; outages "
             f"(start, duration) s {_windows(run)}; {facts['train_windows']} training and {facts['val_windows']} "
             "validation windows outside them (notebook 03)"]
    moved = [o for o in facts["outages"] if o["asked"] != o["run"]]
    for o in moved:
        lines.append(f"  outage asked as {_windows([o['asked']])[1:-1]} runs as {_windows([o['run']])[1:-1]}: both "
                     "edges on the drive's IMU epochs (the filter steps from epoch to epoch)")
    rule = facts.get("rule")
    if rule:
        pct = rule.get("percentile_dps")
        own = (f"the lower of manoeuvre_min_yaw_rate_dps and the drive's own percentile of |yaw rate| "
               f"({pct:.2f} deg/s)" if pct is not None else "manoeuvre_min_yaw_rate_dps")
        lines.append(f"  rule: warm-up counted from the filter's start (earliest start {rule['earliest_s']:.1f} s); "
                     f"manoeuvre threshold {rule['manoeuvre_dps']:.2f} deg/s ({own}); cruise at most "
                     f"{rule['cruise_dps']:.2f} deg/s")
    return lines


def scaled_line(entry: dict) -> str:
    """One scaled key: asked, planned and why."""
    why = {"short_log": (f"the log is short: its times scaled by {entry.get('factor', 1.0):g} so that it holds them"
                         if "factor" in entry else
                         f"the log is short: {entry.get('room_s', 0.0):g} s after the filter's start"),
           "sweep_durations": "no longer than the sweep's longest duration"}.get(entry.get("reason"),
                                                                                  entry.get("reason", ""))
    return f"{entry['key']}: {entry['asked']} -> {entry['planned']} ({why})"


def off_line(entry: dict) -> str:
    """One switched-off part and why."""
    what = PART_WORDS.get(entry["part"], entry["part"])
    why = {"sweep_off": "the outage sweep is off, and it rides on the sweep's starts",
           "no_room": (f"no room for its starts: {entry.get('room_s', '?')} s after the filter's start, warm-up "
                       f"{entry.get('warmup_s', '?')} s, durations {entry.get('durations_s', '?')} s"
                       if "room_s" in entry else f"no room for the sweep's starts in {entry.get('datasets')}"),
           "fold_training": "its folds leave their networks too few training windows outside the outages",
           "fold_windows": (f"{entry.get('fold')} of {entry.get('dataset')} leaves fewer than 2 training and 1 "
                            "validation speed window outside its outages")}.get(entry.get("reason"), entry.get("reason", ""))
    return f"off: {what}: {why}"


def _as_dict(plan) -> dict:
    return plan if isinstance(plan, dict) else vars(plan)


def part_off_line(plan, part: str) -> str:
    """The line of a switched-off part of the plan (a :class:`bgfn.run_plan.RunPlan` or its dict)."""
    entry = next((e for e in _as_dict(plan)["off"] if e["part"] == part), {"part": part, "reason": "off"})
    return off_line(entry)


def plan_lines(plan) -> list[str]:
    """The whole plan (a :class:`bgfn.run_plan.RunPlan` or its dict; None: no plan written)."""
    if plan is None:
        return ["run plan: none written (the profile check writes it: python -m bgfn.profile_schema <profile>)"]
    plan = _as_dict(plan)
    lines = []
    for name, facts in plan["drives"].items():
        lines += drive_lines(name, facts)
    lines += [f"scaled: {scaled_line(e)}" for e in plan["scaled"]]
    lines += [off_line(e) for e in plan["off"]]
    if not plan["scaled"] and not plan["off"]:
        lines.append("run plan: every notebook runs as the profile asks; nothing scaled or switched off")
    return lines

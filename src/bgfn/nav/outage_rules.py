"""Outage windows chosen by a rule written in the profile, from a drive's reference (not typed-in times).

The paper's field test has two 30 s outages: one while the car cruises, and one "during a vehicle maneuvering
phase characterized by significant changes in direction" (Sec. 4.2). On a drive of our own the same choice is
made by a rule, so that no window is picked by hand after looking at the results. A profile entry such as::

    outage_windows:
      default: [[138906.0, 30.0], [139170.0, 30.0]]
      rtklib-drive0708: {rule: cruise_and_manoeuvre, duration_s: 30.0, ...}

is read by :func:`bgfn.nav.outages.outage_windows`, which calls :func:`pick_windows` with the drive.

Rule ``cruise_and_manoeuvre`` (:func:`cruise_and_manoeuvre`), on a grid of ``step_s`` (candidate starts at
whole multiples of ``step_s``, GPS time of week):

- the reference's horizontal speed and its *yaw rate*, the rate of the course ``atan2(v_e, v_n)`` between two
  grid epochs (a car does not slide, so course rate and yaw rate agree; the course needs no reference
  attitude, which a recorded drive may lack). A step where either epoch is slower than ``min_speed_mps``
  counts as no turn: there the course is noise, and a car turning on the spot does not exist;
- the earliest start is ``warmup_s`` after the filter's start (``t_first``: the reference's first row, or the
  end of a self-alignment, which waits for motion; the filter converges and the network needs its input window
  before the outage); a window ends by the last reference epoch;
- *manoeuvre*: the window with the highest mean |yaw rate|; it must reach the manoeuvre threshold: the drive's
  own ``manoeuvre_yaw_rate_percentile``-th percentile of |yaw rate| over its moving steps, capped at
  ``manoeuvre_min_yaw_rate_dps`` (a drive that turns gently, a highway, still has its sharpest turns; one whose
  sharpest window passes the fixed value keeps its windows, since the rule takes the sharpest window anyway);
- *cruise*: among windows at least ``gap_s`` apart from the manoeuvre window and with mean |yaw rate| at most
  ``cruise_max_yaw_rate_dps`` (and no more than the manoeuvre threshold), the one with the highest mean speed
  (the manoeuvre is chosen first: it is the rarer of the two, so the cruise cannot take its place);
- the GPS-available time left to training (the reference span minus both windows widened by the training
  margin ``train.margin_s``) must be at least ``min_training_s``.

Ties go to the earliest start, so the same drive and rule always give the same windows. The windows are
returned in the paper's order, whichever comes first in time: outage 1 cruising, outage 2 manoeuvring (its
Table ``tab-real``, whose rows stand beside ours); :attr:`PickedOutages.kinds` names them.
"""

from __future__ import annotations

from dataclasses import dataclass, field

import numpy as np
import pandas as pd

from .. import settings
from ..errors import DataError
from . import transform

#: The rules a profile may name, with the defaults of their parameters (a profile entry may leave keys out; each
#: key's meaning and default: :class:`bgfn.settings.OutageRule`).
RULE_DEFAULTS: dict[str, dict[str, float]] = {"cruise_and_manoeuvre": settings.defaults_of(settings.OutageRule)}
#: Kinds of window a rule picks, in the order of its ``kinds``.
KINDS: tuple[str, ...] = ("cruise", "manoeuvre")


@dataclass
class PickedOutages:
    """What a rule chose on one drive.

    Attributes
    ----------
    windows : list of (float, float)
        ``(start, duration)``, s: the cruise, then the manoeuvre (:data:`KINDS`).
    kinds : list of str
        ``cruise`` or ``manoeuvre`` for each window, in the same order.
    scores : DataFrame
        Per window (same order): ``start_s``, ``kind``, ``mean_speed_mps``, ``mean_abs_yaw_rate_dps``.
    training_s : float
        GPS-available time left outside the windows widened by the training margin, s.
    rule : dict
        The rule with its defaults filled in.
    thresholds : dict
        What the drive made of the rule: ``manoeuvre_dps`` (the threshold applied), ``percentile_dps`` (the
        drive's percentile of |yaw rate|, None without one), ``cruise_dps`` (the cruise's cap applied),
        ``t_first`` (s, what the warm-up counts from) and ``earliest_s`` (the earliest start).
    """

    windows: list
    kinds: list
    scores: pd.DataFrame
    training_s: float
    rule: dict = field(default_factory=dict)
    thresholds: dict = field(default_factory=dict)


def rule_params(rule: dict, source: str = "outage_windows") -> dict:
    """``rule`` with the defaults of its ``rule:`` filled in; unknown rules and keys are errors.

    Raises
    ------
    DataError
        No ``rule`` key, an unknown rule name, an unknown parameter, or a non-positive duration or step.
    """
    name = rule.get("rule") if isinstance(rule, dict) else None
    if name not in RULE_DEFAULTS:
        raise DataError(source, "rule", f"one of {', '.join(RULE_DEFAULTS)}", repr(name))
    defaults = RULE_DEFAULTS[name]
    unknown = sorted(set(rule) - set(defaults) - {"rule"})
    if unknown:
        raise DataError(source, unknown[0], f"a parameter of rule {name}: {', '.join(defaults)}", "unknown key")
    params = {"rule": name, **defaults, **{k: (None if v is None else float(v)) for k, v in rule.items()
                                           if k != "rule"}}
    for key in ("duration_s", "step_s"):
        if not params[key] > 0:
            raise DataError(source, key, "a positive time, s", repr(params[key]))
    return params


def motion_series(reference: pd.DataFrame, step_s: float, min_speed_mps: float) -> pd.DataFrame:
    """Horizontal speed and yaw rate of a reference on a grid of ``step_s``.

    Parameters
    ----------
    reference : DataFrame
        ``time`` (s, increasing), ``v_n``, ``v_e`` (m/s).
    step_s : float
        Grid step, s; the grid holds the whole multiples of ``step_s`` inside the reference's span.
    min_speed_mps : float
        A step whose either end is slower counts as yaw rate 0.

    Returns
    -------
    DataFrame
        ``time`` (s), ``speed_mps``, ``yaw_rate_dps`` (deg/s, signed; row ``k`` holds the rate over
        ``(time[k-1], time[k]]``, row 0 holds 0).
    """
    t = reference["time"].to_numpy(float)
    k = np.arange(np.ceil(t[0] / step_s - 1e-9), np.floor(t[-1] / step_s + 1e-9) + 1)
    grid = k * step_s + 0.0                             # [G]; + 0.0: no -0.0
    v_n = np.interp(grid, t, reference["v_n"].to_numpy(float))
    v_e = np.interp(grid, t, reference["v_e"].to_numpy(float))
    speed = np.hypot(v_n, v_e)
    course = np.arctan2(v_e, v_n)                     # yaw of a car that does not slide (clockwise from north)
    rate = np.zeros_like(grid)
    moving = speed >= min_speed_mps
    rate[1:] = np.where(moving[1:] & moving[:-1], transform.wrap_angle(np.diff(course)) / step_s, 0.0)
    return pd.DataFrame({"time": grid, "speed_mps": speed, "yaw_rate_dps": np.degrees(rate)})


def window_scores(motion: pd.DataFrame, duration_s: float, step_s: float) -> pd.DataFrame:
    """Mean speed and mean |yaw rate| of every window ``[start, start + duration_s]`` on the grid of ``motion``.

    Returns
    -------
    DataFrame
        ``start_s``, ``mean_speed_mps`` (over the ``n + 1`` grid epochs inside), ``mean_abs_yaw_rate_dps``
        (over its ``n`` steps), ``n = duration_s / step_s``; one row per start whose window fits the grid.
    """
    n = int(round(duration_s / step_s))
    speed = motion["speed_mps"].to_numpy(float)
    rate = np.abs(motion["yaw_rate_dps"].to_numpy(float))
    m = len(speed) - n                                  # starts whose window ends on the grid
    if n < 1 or m < 1:
        return pd.DataFrame({"start_s": [], "mean_speed_mps": [], "mean_abs_yaw_rate_dps": []})
    cs = np.concatenate([[0.0], np.cumsum(speed)])
    cr = np.concatenate([[0.0], np.cumsum(rate)])
    k = np.arange(m)
    return pd.DataFrame({"start_s": motion["time"].to_numpy(float)[:m],
                         "mean_speed_mps": (cs[k + n + 1] - cs[k]) / (n + 1),
                         "mean_abs_yaw_rate_dps": (cr[k + n + 1] - cr[k + 1]) / n})


def training_time(t_first: float, t_last: float, windows, margin_s: float) -> float:
    """Time of ``[t_first, t_last]`` outside every window widened by ``margin_s`` on both sides, s."""
    spans = sorted((max(t_first, s - margin_s), min(t_last, s + d + margin_s)) for s, d in windows)
    covered, end = 0.0, -np.inf
    for a, b in spans:                                  # union of the widened windows
        a = max(a, end)
        if b > a:
            covered += b - a
        end = max(end, b)
    return (t_last - t_first) - covered


def manoeuvre_threshold(motion: pd.DataFrame, fixed_dps: float, percentile: float | None,
                        min_speed_mps: float) -> tuple[float, float | None]:
    """The manoeuvre threshold of a drive: ``min(fixed_dps, P)``, P the ``percentile``-th percentile of |yaw rate|
    over the steps of ``motion`` (:func:`motion_series`) whose both ends move at ``min_speed_mps`` or more (a
    standing step is no turn, and is left out). Returns ``(threshold, P)``; P is None when ``percentile`` is None
    or no step moves (then the fixed value alone)."""
    speed = motion["speed_mps"].to_numpy(float)
    rate = np.abs(motion["yaw_rate_dps"].to_numpy(float))
    steps = rate[1:][(speed[1:] >= min_speed_mps) & (speed[:-1] >= min_speed_mps)]
    if percentile is None or steps.size == 0:
        return float(fixed_dps), None
    p = float(np.percentile(steps, float(percentile)))
    return min(float(fixed_dps), p), p


def cruise_and_manoeuvre(reference: pd.DataFrame, rule: dict, margin_s: float = 0.0,
                         source: str = "outage_windows", t_first: float | None = None) -> PickedOutages:
    """The rule ``cruise_and_manoeuvre`` on one drive (see the module's docstring).

    Parameters
    ----------
    reference : DataFrame
        The drive's reference: ``time`` (s), ``v_n``, ``v_e`` (m/s).
    rule : dict
        The profile's entry (:func:`rule_params` fills the defaults).
    margin_s : float
        Training margin around each outage (``train.margin_s``), s.
    source : str
        Named in error messages (the drive and the profile key).
    t_first : float, optional
        The filter's start, s (:func:`bgfn.nav.baseline.filter_start`); default the reference's first row.

    Raises
    ------
    DataError
        The vehicle never moves, no window fits after the warm-up, no window turns enough, no cruise window
        lies apart from the manoeuvre, or too little GPS time is left to training.
    """
    p = rule_params(rule, source)
    dur, step = p["duration_s"], p["step_s"]
    motion = motion_series(reference, step, p["min_speed_mps"])
    moving = motion["time"][motion["speed_mps"] >= p["min_speed_mps"]]
    if moving.empty:
        raise DataError(source, "min_speed_mps", "a drive that reaches this speed",
                        f"top speed {motion['speed_mps'].max():.2f} m/s")
    start = float(reference["time"].iloc[0]) if t_first is None else max(float(t_first),
                                                                          float(reference["time"].iloc[0]))
    earliest = start + p["warmup_s"]
    scores = window_scores(motion, dur, step)
    scores = scores[scores["start_s"] >= earliest - 1e-9].reset_index(drop=True)
    if scores.empty:
        raise DataError(source, "warmup_s", f"a {dur:g} s window between {earliest:.1f} s (the filter's start "
                        "+ warm-up) and the end of the drive",
                        f"the drive ends at {float(motion['time'].iloc[-1]):.1f} s")
    threshold, pct = manoeuvre_threshold(motion, p["manoeuvre_min_yaw_rate_dps"],
                                         p["manoeuvre_yaw_rate_percentile"], p["min_speed_mps"])
    man = scores.iloc[int(np.argmax(scores["mean_abs_yaw_rate_dps"].to_numpy()))]   # first maximum: earliest
    if man["mean_abs_yaw_rate_dps"] < threshold:
        raise DataError(source, "manoeuvre_min_yaw_rate_dps", "a window turning at least "
                        f"{threshold:.2f} deg/s (mean |yaw rate|: this key or the drive's "
                        f"{p['manoeuvre_yaw_rate_percentile']}th percentile of its |yaw rate|, the lower)",
                        f"at most {man['mean_abs_yaw_rate_dps']:.2f} deg/s")
    cruise_cap = min(p["cruise_max_yaw_rate_dps"], threshold)
    apart = (scores["start_s"] - man["start_s"]).abs() >= dur + p["gap_s"] - 1e-9
    calm = scores["mean_abs_yaw_rate_dps"] <= cruise_cap
    cruise_candidates = scores[apart & calm]
    if cruise_candidates.empty:
        raise DataError(source, "cruise_max_yaw_rate_dps", f"a window at least gap_s = {p['gap_s']:g} s apart "
                        f"from the manoeuvre at {man['start_s']:.1f} s turning at most this fast",
                        f"none among {int(apart.sum())} windows apart from it")
    cru = cruise_candidates.iloc[int(np.argmax(cruise_candidates["mean_speed_mps"].to_numpy()))]
    picked = pd.DataFrame([cru, man]).assign(kind=list(KINDS)).reset_index(drop=True)   # the paper's order
    picked = picked[["start_s", "kind", "mean_speed_mps", "mean_abs_yaw_rate_dps"]]
    windows = [(float(s), dur) for s in picked["start_s"]]
    t = reference["time"].to_numpy(float)
    left = training_time(float(t[0]), float(t[-1]), windows, margin_s)
    if left < p["min_training_s"]:
        raise DataError(source, "min_training_s", f"at least this much GPS time outside the outages +- "
                        f"{margin_s:g} s (train.margin_s) for training", f"{left:.1f} s")
    return PickedOutages(windows, picked["kind"].tolist(), picked, float(left), p,
                         {"manoeuvre_dps": threshold, "percentile_dps": pct, "cruise_dps": cruise_cap,
                          "t_first": start, "earliest_s": earliest})


#: Rule name -> the function that applies it.
RULES = {"cruise_and_manoeuvre": cruise_and_manoeuvre}


def pick_windows(rule: dict, reference: pd.DataFrame, margin_s: float = 0.0,
                 source: str = "outage_windows", t_first: float | None = None) -> PickedOutages:
    """Apply the profile's rule entry ``rule`` (its ``rule:`` key names it) to a drive's reference; the warm-up
    counts from ``t_first`` (the filter's start; default the reference's first row)."""
    return RULES[rule_params(rule, source)["rule"]](reference, rule, margin_s, source, t_first)

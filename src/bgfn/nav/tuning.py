"""The filter's IMU noise from the drive itself: the factor on the noise densities that makes its GNSS innovations
consistent.

In a car, vibration adds noise many times the datasheet's, and a filter with the datasheet's ``Q`` is
overconfident. For a consistent filter the mean normalized innovation squared of the fixes equals their degrees of
freedom (:mod:`bgfn.nav.consistency`). ``nav.noise_scale: auto`` scales the white-noise densities of ``Q`` (with
``nav.noise_search.bias_walk``, the bias driving noise too) by the factor whose GPS-aided run has that mean NIS: a
root in ``log s`` over ``nav.noise_search.range``, bracketed by the local log-log slope and found by false position
(Illinois) in a few filter runs. A root outside the range returns the bound and says so.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Callable

from .. import settings

#: Defaults of the ``nav.noise_search`` profile section.
NOISE_SEARCH_DEFAULTS: dict = settings.defaults("nav.noise_search")   # their home: bgfn.settings.NoiseSearch

#: The log-log slope assumed before two runs give one, d log(mean NIS) / d log(s): position innovations grow
#: about linearly with the noise density when the IMU noise dominates them.
DEFAULT_SLOPE = 1.0
#: Largest factor between two successive trial scales while no root is bracketed.
MAX_STEP = 100.0


@dataclass(frozen=True)
class NoiseTuning:
    """Outcome of :func:`search_noise_scale`.

    Attributes
    ----------
    scale : float
        The chosen factor on the noise densities.
    mean_nis : float
        Mean NIS of the GNSS fixes of the run with ``scale``.
    mean_nis_at_one : float
        The same with the factor 1 (the drive's IMU error parameters as given).
    dof : float
        Mean degrees of freedom of the fixes (the target of the mean NIS).
    runs : list of (float, float)
        Every ``(scale, mean NIS)`` tried, in order.
    at_bound : bool
        The root lies outside ``range``: ``scale`` is the bound nearest to it.
    bias_walk : bool
        Whether the bias driving noise was scaled too.
    """

    scale: float
    mean_nis: float
    mean_nis_at_one: float
    dof: float
    runs: list = field(default_factory=list)
    at_bound: bool = False
    bias_walk: bool = False

    def record(self) -> dict:
        """JSON-ready record (``kf_baseline.json``)."""
        return {"scale": self.scale, "mean_nis": self.mean_nis, "mean_nis_at_one": self.mean_nis_at_one,
                "dof": self.dof, "runs": [[s, n] for s, n in self.runs], "at_bound": self.at_bound,
                "bias_walk": self.bias_walk}


def search_noise_scale(mean_nis: Callable[[float], tuple[float, float]], options: dict | None = None) -> NoiseTuning:
    """The factor ``s`` whose run has ``mean NIS = dof`` (module docstring).

    Parameters
    ----------
    mean_nis : callable
        ``mean_nis(s) -> (mean NIS, mean dof)`` of the GPS-aided run with the noise densities times ``s``; must
        fall as ``s`` grows.
    options : dict, optional
        The ``nav.noise_search`` section (:data:`NOISE_SEARCH_DEFAULTS` fill the missing keys).

    Returns
    -------
    NoiseTuning
    """
    o = {**NOISE_SEARCH_DEFAULTS, **(options or {})}
    lo, hi = (float(x) for x in o["range"])
    tol = math.log1p(float(o["tolerance"]))
    runs: list[tuple[float, float]] = []
    dof = [float("nan")]

    def f(log_s: float) -> float:
        """log(mean NIS / dof) at log_s, recorded."""
        s = math.exp(log_s)
        nis, d = mean_nis(s)
        runs.append((s, float(nis)))
        dof[0] = float(d)
        return math.log(max(float(nis), 1e-300) / float(d))

    a_x = min(max(0.0, math.log(lo)), math.log(hi))                  # s = 1 unless the range excludes it
    a_f = f(a_x)
    nis_at_one = runs[0][1] if a_x == 0.0 else float("nan")
    b_x = b_f = None
    slope = DEFAULT_SLOPE
    # bracket: step in the direction of the root with the local slope until the sign changes
    while abs(a_f) > tol and b_x is None and len(runs) < int(o["max_runs"]):
        step = min(abs(a_f) / slope, math.log(MAX_STEP))
        x = min(max(a_x + math.copysign(step, a_f), math.log(lo)), math.log(hi))
        if x == a_x:                                                 # at a bound, root beyond it
            break
        fx = f(x)
        slope = min(max(abs((fx - a_f) / (x - a_x)), 0.25), 4.0)
        if (fx > 0) != (a_f > 0):
            b_x, b_f = x, fx
        else:
            a_x, a_f = x, fx
    # false position (Illinois) inside the bracket; a_f, b_f are halved by the rule, so the test is on each run
    side, last = 0, b_f
    while b_x is not None and abs(last) > tol and len(runs) < int(o["max_runs"]):
        x = b_x - b_f * (b_x - a_x) / (b_f - a_f)
        fx = last = f(x)
        if (fx > 0) == (b_f > 0):
            b_x, b_f = x, fx
            if side == -1:
                a_f *= 0.5
            side = -1
        else:
            a_x, a_f = x, fx
            if side == 1:
                b_f *= 0.5
            side = 1
    target = dof[0]
    best_s, best_nis = min(runs, key=lambda r: abs(math.log(max(r[1], 1e-300) / target)))
    at_bound = b_x is None and abs(math.log(max(best_nis, 1e-300) / target)) > tol and (
        math.isclose(best_s, lo) or math.isclose(best_s, hi))
    return NoiseTuning(float(best_s), float(best_nis), float(nis_at_one), float(target), runs, bool(at_bound),
                       bool(o["bias_walk"]))

"""Navigation error metrics: error time series against the reference, per-outage numbers (paper Tables 1-2).

Errors are *computed minus reference*, position errors in metres in the local NED frame of the reference
point (exact, via ECEF), attitude errors wrapped to (-pi, pi] (NaN where the reference has no attitude).

A drive may name spans where its reference is not trusted (``Drive.meta["reference_excluded_s"]``, e.g. the
epochs of an RTK reference that are not fixed); every comparison with the reference leaves the rows inside them
out, through the one helper :func:`reference_rows`.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from ..errors import DataError
from . import earth, transform
from .outage_window import OutageWindow

#: Columns of :func:`navigation_errors`.
ERROR_COLUMNS = ["time", "north", "east", "down", "horizontal", "v_n", "v_e", "v_d", "roll", "pitch", "yaw"]
#: Key of ``Drive.meta``: ``[[t0, t1], ...]`` (s), spans where the reference is not trusted.
REFERENCE_EXCLUDED_KEY = "reference_excluded_s"


def excluded_spans(meta: dict | None) -> list[tuple[float, float]]:
    """The spans of ``meta[REFERENCE_EXCLUDED_KEY]`` (none when absent), as ``(t0, t1)`` in s."""
    spans = (meta or {}).get(REFERENCE_EXCLUDED_KEY) or []
    out = []
    for span in spans:
        if len(span) != 2 or not float(span[0]) <= float(span[1]):
            raise DataError("meta", REFERENCE_EXCLUDED_KEY, "spans [t0, t1] with t0 <= t1, s", repr(span))
        out.append((float(span[0]), float(span[1])))
    return out


def reference_rows(time, excluded_s=()) -> np.ndarray:
    """Which epochs may be compared with the reference: False inside any excluded span ``[t0, t1]``.

    Parameters
    ----------
    time : array_like
        s.
    excluded_s : sequence of (t0, t1) or dict
        Spans, s, or a drive's ``meta`` (:func:`excluded_spans`).

    Returns
    -------
    ndarray of bool
    """
    t = np.asarray(time, dtype=float)
    spans = excluded_spans(excluded_s) if isinstance(excluded_s, dict) else excluded_s
    keep = np.ones(t.shape, dtype=bool)
    for t0, t1 in spans:
        keep &= ~((t >= float(t0)) & (t <= float(t1)))
    return keep


def align(trajectory: pd.DataFrame, reference: pd.DataFrame, tol: float = 1e-6, source="trajectory"):
    """Reference rows at the trajectory's times (exact match within ``tol`` s).

    Returns
    -------
    DataFrame
        Reference rows, one per trajectory row, same order.

    Raises
    ------
    DataError
        A trajectory time without a reference row.
    """
    t = trajectory["time"].to_numpy(dtype=float)
    tr = reference["time"].to_numpy(dtype=float)
    i = np.clip(np.searchsorted(tr, t - tol), 0, tr.size - 1)
    bad = np.abs(tr[i] - t) > tol
    if bad.any():
        raise DataError(source, "time", f"reference rows at every trajectory time (within {tol} s)",
                        f"{int(bad.sum())} times without, first {t[bad][0]}")
    return reference.iloc[i].reset_index(drop=True)


def navigation_errors(trajectory: pd.DataFrame, reference: pd.DataFrame, excluded_s=()) -> pd.DataFrame:
    """Position (NED, m), velocity (m/s) and attitude (rad) errors of a trajectory.

    Parameters
    ----------
    trajectory, reference : DataFrame
        Reference schema; every trajectory time must have a reference row.
    excluded_s : sequence of (t0, t1) or dict
        Spans where the reference is not trusted, or the drive's ``meta`` holding them
        (:func:`reference_rows`); their rows are left out.

    Returns
    -------
    DataFrame
        Columns ``ERROR_COLUMNS``; ``horizontal = hypot(north, east)``.
    """
    keep = reference_rows(trajectory["time"].to_numpy(float), excluded_s)
    if not keep.all():
        trajectory = trajectory.loc[keep].reset_index(drop=True)
    ref = align(trajectory, reference)
    ned = earth.lla_to_ned(trajectory["lat"].to_numpy(), trajectory["lon"].to_numpy(),
                           trajectory["h"].to_numpy(), ref["lat"].to_numpy(), ref["lon"].to_numpy(),
                           ref["h"].to_numpy())
    out = pd.DataFrame({"time": trajectory["time"].to_numpy(), "north": ned[:, 0], "east": ned[:, 1],
                        "down": ned[:, 2], "horizontal": np.hypot(ned[:, 0], ned[:, 1])})
    for col in ("v_n", "v_e", "v_d"):
        out[col] = trajectory[col].to_numpy() - ref[col].to_numpy()
    for col in ("roll", "pitch", "yaw"):
        out[col] = transform.wrap_angle(trajectory[col].to_numpy() - ref[col].to_numpy())
    return out


def outage_metrics(errors: pd.DataFrame, window: OutageWindow) -> dict:
    """Error numbers over one outage window ``[start, end]``.

    Parameters
    ----------
    errors : DataFrame
        Output of :func:`navigation_errors`.
    window : OutageWindow

    Returns
    -------
    dict
        ``start``, ``duration`` (s), ``max_abs_east``, ``max_abs_north`` (m, paper Tables 1-2),
        ``rmse_horizontal``, ``max_horizontal`` (m), ``end_east``, ``end_north``, ``end_horizontal`` (m,
        error at the last epoch of the window).
    """
    t = errors["time"].to_numpy()
    m = (t >= window.start - 1e-6) & (t <= window.end + 1e-6)
    if not m.any():
        raise DataError("errors", "time", f"epochs inside the outage [{window.start}, {window.end}]", "none")
    e = errors[m]
    last = e.iloc[-1]
    return {"start": window.start, "duration": window.duration,
            "max_abs_east": float(np.abs(e["east"]).max()), "max_abs_north": float(np.abs(e["north"]).max()),
            "rmse_horizontal": float(np.sqrt(np.mean(e["horizontal"] ** 2))),
            "max_horizontal": float(e["horizontal"].max()),
            "end_east": float(last["east"]), "end_north": float(last["north"]),
            "end_horizontal": float(last["horizontal"])}


def rms_table(errors: pd.DataFrame, mask=None) -> pd.DataFrame:
    """RMS and max-abs of every error column (optionally over ``mask`` rows).

    Returns
    -------
    DataFrame
        Index = error quantity (``north``... ``yaw``), columns ``rms``, ``max_abs``, ``unit``.
    """
    e = errors if mask is None else errors[np.asarray(mask)]
    cols = ERROR_COLUMNS[1:]
    units = ["m"] * 4 + ["m/s"] * 3 + ["rad"] * 3
    return pd.DataFrame({"rms": [float(np.sqrt(np.mean(e[c] ** 2))) for c in cols],
                         "max_abs": [float(np.abs(e[c]).max()) for c in cols], "unit": units},
                        index=pd.Index(cols, name="quantity"))

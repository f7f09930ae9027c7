"""The profile's outage windows of a drive (:func:`outage_windows`, the one reader): its list, or what its rule
picks from the drive (:mod:`bgfn.nav.outage_rules`, the warm-up counted from the filter's start,
:func:`bgfn.nav.baseline.filter_start`), moved onto the drive's IMU epochs (:func:`snap_windows`).

The windows themselves, the pseudo-GPS hook and the checks live in :mod:`bgfn.nav.outage_window` (below the
filter, which imports them) and are re-exported here.
"""

from __future__ import annotations

from ..config import DEFAULT_DATASET_KEY
from ..errors import DataError
from . import outage_rules
from .baseline import filter_start
from .outage_window import (TIME_TOL, IncrementPseudoGps, OutageWindow, PseudoFix, PseudoGpsContext,  # noqa: F401
                            PseudoGpsSource, SnappedWindow, TablePseudoGps, check_windows, epochs_before, snap_windows)

def outage_entry(profile: dict, dataset: str | None = None):
    """The profile's ``outage_windows`` entry for ``dataset``: a list of ``[start, duration]`` or a rule mapping.

    ``outage_windows`` is either one list (every dataset) or a mapping from dataset name to a list or a rule
    (:mod:`bgfn.nav.outage_rules`), where ``default`` answers for the datasets it does not name (and for
    ``dataset=None``).

    Raises
    ------
    DataError
        The key is missing or empty, or the mapping has neither ``dataset`` nor ``default``.
    """
    where = f"profile {profile.get('profile')!r}"
    spec = profile.get("outage_windows")
    if isinstance(spec, dict):
        key = dataset if dataset in spec else DEFAULT_DATASET_KEY
        if key not in spec:
            raise DataError(where, f"outage_windows.{dataset if dataset is not None else DEFAULT_DATASET_KEY}",
                            f"an entry for this dataset or a '{DEFAULT_DATASET_KEY}' entry", f"keys {sorted(spec)}")
        spec = spec[key]
    if not spec:
        raise DataError(where, "outage_windows", "the evaluation outages: a list of [start, duration] in s, or a "
                        "mapping dataset -> list or rule with a 'default' entry", repr(spec))
    return spec


def default_windows(profile: dict) -> list[tuple[float, float]] | None:
    """The windows of the profile's one list or ``default`` list; None when ``default`` is a rule or missing
    (then every dataset has its own entry). What a reader without a drive, e.g. a run description, shows."""
    spec = profile.get("outage_windows")
    entry = spec.get(DEFAULT_DATASET_KEY) if isinstance(spec, dict) else spec
    if not entry or is_rule(entry):
        return None
    return [(float(s), float(d)) for s, d in entry]


def is_rule(entry) -> bool:
    """Whether an ``outage_windows`` entry is a rule (a mapping with ``rule:``) rather than a list of windows."""
    return isinstance(entry, dict)


def outage_windows(profile: dict, drive=None, dataset: str | None = None) -> list[tuple[float, float]]:
    """The evaluation outages ``[(start, duration), ...]`` (s) of one drive: the profile's ``outage_windows``.

    The one reader of this fact: notebook 01 draws the windows, 02 runs the standalone INS in them, 03 keeps
    them (and a margin) out of training, 04 evaluates every method in them, and ``make``'s profile check
    (:func:`bgfn.profile_schema.check_with_drives`) checks them against each drive.

    Parameters
    ----------
    profile : dict
        A profile (:func:`bgfn.config.load_profile`), which checked the key's form.
    drive : bgfn.data.Drive, optional
        When given, the windows are checked against its time span (:func:`check_windows`); a rule entry needs
        it (the rule picks the windows from the drive's reference).
    dataset : str, optional
        The dataset's name in the profile (its key in a per-dataset mapping); default ``drive.name``; neither:
        the ``default`` entry.

    Returns
    -------
    list of (float, float)
        In the profile's order, a rule's in its own (``Outage k`` is the k-th everywhere).

    Raises
    ------
    DataError
        No entry (:func:`outage_entry`), a rule without a drive, a rule that finds no windows, or windows
        outside the drive.
    """
    name = dataset if dataset is not None else getattr(drive, "name", None)
    if drive is None:
        entry = outage_entry(profile, name)
        if is_rule(entry):
            raise DataError(f"profile {profile.get('profile')!r}", f"outage_windows.{name}",
                            "the drive as well: a rule picks the windows from its reference", f"rule {entry}")
        return [(float(s), float(d)) for s, d in entry]
    return [w.window for w in snapped_outages(profile, drive, name)]


def snapped_outages(profile: dict, drive, dataset: str | None = None) -> list[SnappedWindow]:
    """The outages of one drive as the profile asks them (its list, or what its rule picks) and as they run, on
    the drive's IMU epochs (:func:`snap_windows`), checked against its span; :func:`outage_windows` returns the
    latter, and the notebooks and the profile check all read them through it."""
    name = dataset if dataset is not None else getattr(drive, "name", None)
    entry = outage_entry(profile, name)
    source = f"{name}: profile outage_windows" if name is not None else "profile outage_windows"
    if is_rule(entry):
        pairs = picked_outages(profile, drive, name).windows
    else:
        pairs = [(float(s), float(d)) for s, d in entry]
    t = drive.imu["time"].to_numpy(dtype=float)
    snapped = snap_windows(pairs, t)
    check_windows([w.window for w in snapped], float(drive.reference["time"].iloc[0]), float(t[-1]), source)
    return snapped


def picked_outages(profile: dict, drive, dataset: str | None = None):
    """What the profile's rule for ``dataset`` picks on ``drive`` (:class:`bgfn.nav.outage_rules.PickedOutages`),
    or None when its entry is a list. The training margin of the rule's check is ``train.margin_s``; the warm-up
    counts from the filter's start under the profile's ``nav:`` (:func:`bgfn.nav.baseline.filter_start`)."""
    name = dataset if dataset is not None else getattr(drive, "name", None)
    entry = outage_entry(profile, name)
    if not is_rule(entry):
        return None
    margin = float(profile["train"]["margin_s"])
    return outage_rules.pick_windows(entry, drive.reference, margin, f"{name}: profile outage_windows",
                                     t_first=filter_start(drive, profile.get("nav")))


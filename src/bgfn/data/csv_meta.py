"""``meta.yaml`` of a user's CSV drive: its keys, their defaults, one clear error for anything else.

Every key is optional, and so is the file (``data/README.md`` lists them for a user): the dataset's ``name``, the
antenna's ``lever_arm_m``, the ``source``, the ``imu_errors`` the filter uses (laid over the profile ``base``,
default :data:`DEFAULT_IMU_PROFILE`: the consumer-MEMS :data:`bgfn.data.imu_errors.MPU6000`, the grade of the
paper's field-test IMU), the ``platform`` (which aids run, :data:`bgfn.nav.constraints.PLATFORM_AIDS`), the IMU's
``imu_mounting_deg`` and ``imu_time_offset_s``, the fixes' ``gnss_latency_s`` (a number, or ``auto``: estimated,
applied only when :func:`bgfn.data.time_offset.decide_clock` holds) and ``gnss_std_m``, and the reference's ``reference_lever_arm_m``. An unknown key, at
the top level or inside ``imu_errors``, is a :class:`bgfn.errors.DataError` naming the file, the key and the closest
valid key: a misspelt noise density never silently becomes a default.
"""

from __future__ import annotations

import difflib
import re
from pathlib import Path

import numpy as np
import yaml

from bgfn.config import safe_yaml
from bgfn.data.imu_errors import OPTIONAL_VECTOR_KEYS, PROFILES, SCALAR_KEYS, VECTOR_KEYS, error_params
from bgfn.errors import DataError

#: The file name inside a CSV drive's folder.
META_FILE = "meta.yaml"
#: A dataset id (a meta file's ``name``, and every id :func:`bgfn.data.names.dataset_id` gives): letters, digits,
#: ``_``, ``-`` and ``.``, starting with a letter or digit.
ID_PATTERN = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_.-]*$")
#: Error profile of :mod:`bgfn.data.imu_errors` used when ``meta.yaml`` gives no ``imu_errors`` (or no ``base``).
DEFAULT_IMU_PROFILE = "mpu6000"
#: Top-level keys of ``meta.yaml``.
META_KEYS: tuple[str, ...] = ("name", "lever_arm_m", "source", "imu_errors", "platform", "imu_mounting_deg",
                              "imu_time_offset_s", "gnss_latency_s", "gnss_std_m", "reference_lever_arm_m")
#: ``platform`` values (the aids of each: :data:`bgfn.nav.constraints.PLATFORM_AIDS`).
PLATFORMS: tuple[str, ...] = ("car", "walker", "other")
#: Largest time shift a meta key may state, s: beyond it the log's clocks disagree by more than a delay.
MAX_TIME_SHIFT_S = 5.0
#: Keys of its ``imu_errors`` mapping: the error parameters, the profile they override, a label.
IMU_ERROR_KEYS: tuple[str, ...] = VECTOR_KEYS + OPTIONAL_VECTOR_KEYS + SCALAR_KEYS + ("base", "model")


def _unknown_key(path: Path, key, valid, prefix: str = "") -> DataError:
    close = [prefix + k for k in difflib.get_close_matches(str(key), list(valid), n=1, cutoff=0.6)]
    if not close and not prefix:       # an error parameter written at the top level belongs under imu_errors:
        close = ["imu_errors." + k for k in difflib.get_close_matches(str(key), IMU_ERROR_KEYS, n=1, cutoff=0.6)]
    hint = f" (did you mean {close[0]}?)" if close else ""
    return DataError(path, f"{prefix}{key}", f"one of the keys {', '.join(valid)}{hint}", "unknown key")


def _load(path: Path) -> dict:
    """The parsed YAML mapping of ``path`` ({} for an empty file)."""
    try:
        meta = safe_yaml(path.read_text(encoding="utf-8"), path)        # aliases that nest: one error
    except (yaml.YAMLError, UnicodeDecodeError) as exc:
        raise DataError(path, "<yaml>", "valid YAML", str(exc).replace("\n", " ")) from None
    if meta is None:
        return {}
    if not isinstance(meta, dict):
        raise DataError(path, "<top level>", "a mapping of keys " + ", ".join(META_KEYS), type(meta).__name__)
    for key in meta:
        if key not in META_KEYS:
            raise _unknown_key(path, key, META_KEYS)
    return meta


def _checked_name(path: Path, meta: dict) -> str | None:
    name = meta.get("name")
    if name is None:
        return None
    if not isinstance(name, str) or not ID_PATTERN.match(name):
        raise DataError(path, "name", "a dataset id of letters, digits, '_', '-', '.' (it names the result files)",
                        repr(name))
    return name


def read_meta_name(path: str | Path) -> str | None:
    """The ``name`` of a ``meta.yaml`` (None when the file or the key is absent); checked as in :func:`read_meta`."""
    path = Path(path)
    return _checked_name(path, _load(path)) if path.is_file() else None


def imu_errors_from(path: str | Path, section) -> tuple[dict, str]:
    """The validated error parameters of an ``imu_errors`` mapping (None: the default profile).

    Returns
    -------
    params : dict
        :func:`bgfn.data.imu_errors.error_params` of ``base`` with the mapping's keys laid over it.
    origin : str
        In words, where the parameters came from (``meta["imu_errors_source"]``).
    """
    path = Path(path)
    if section is None:
        return (error_params(DEFAULT_IMU_PROFILE),
                f"default: the {DEFAULT_IMU_PROFILE} profile of bgfn.data.imu_errors ({path.name} gives no imu_errors)")
    if not isinstance(section, dict):
        raise DataError(path, "imu_errors", "a mapping of error parameters (keys of bgfn.data.imu_errors)",
                        type(section).__name__)
    for key in section:
        if key not in IMU_ERROR_KEYS:
            raise _unknown_key(path, key, IMU_ERROR_KEYS, "imu_errors.")
    base = section.get("base", DEFAULT_IMU_PROFILE)
    if base not in PROFILES:
        raise DataError(path, "imu_errors.base", f"an error profile of bgfn.data.imu_errors: {', '.join(PROFILES)}",
                        repr(base))
    overrides = {k: v for k, v in section.items() if k != "base"}
    try:
        params = error_params(base, overrides)
    except (DataError, TypeError, ValueError) as exc:
        field = getattr(exc, "field", "")
        expected = getattr(exc, "expected", "numbers (a list of 3 per axis x, y, z, or one number)")
        found = getattr(exc, "found", str(exc))
        raise DataError(path, f"imu_errors.{field}".rstrip("."), expected, found) from None
    given = sorted(k for k in overrides if k != "model")
    return params, f"{path.name}: the {base} profile" + (f" with {', '.join(given)}" if given else "")


def read_meta(path: str | Path) -> dict:
    """Read and check a CSV drive's ``meta.yaml`` (module docstring); a missing file gives the defaults.

    Parameters
    ----------
    path : str or Path
        The ``meta.yaml`` file (need not exist).

    Returns
    -------
    dict
        ``name`` (str or None: the folder's name), ``lever_arm_m`` (list of 3 floats, m), ``source`` (str or
        None), ``imu_errors`` (:func:`bgfn.data.imu_errors.error_params` output), ``imu_errors_source`` (str),
        ``platform``, ``imu_mounting_deg`` (list of 3), ``imu_time_offset_s``, ``gnss_latency_s`` (s),
        ``gnss_std_m`` (list of 3 or None).

    Raises
    ------
    DataError
        Naming the file and the key: unreadable YAML, unknown key (with the closest valid one), bad value.
    """
    path = Path(path)
    meta = _load(path) if path.is_file() else {}
    name = _checked_name(path, meta)
    larm = _vector(path, meta, "lever_arm_m", [0.0, 0.0, 0.0], "3 finite numbers [x, y, z], m (antenna in the body "
                   "frame)")
    ref_lever = _vector(path, meta, "reference_lever_arm_m", [0.0, 0.0, 0.0], "3 finite numbers [x, y, z], m (the "
                        "reference's point in the body frame)")
    mounting = _vector(path, meta, "imu_mounting_deg", [0.0, 0.0, 0.0], "3 finite numbers [roll, pitch, yaw], deg "
                       "(the IMU's axes in the body frame)")
    if np.any(np.abs(mounting) > 360.0):
        raise DataError(path, "imu_mounting_deg", "angles in degrees within [-360, 360]", str(mounting.tolist()))
    std = meta.get("gnss_std_m")
    if std is not None:
        std = _vector(path, meta, "gnss_std_m", None, "3 positive numbers [north, east, down], m")
        if (std <= 0).any():
            raise DataError(path, "gnss_std_m", "3 positive numbers [north, east, down], m", str(std.tolist()))
    platform = meta.get("platform", PLATFORMS[0])
    if platform not in PLATFORMS:
        raise DataError(path, "platform", f"one of {', '.join(PLATFORMS)} (which aids apply)", repr(platform))
    shifts = {}
    for key in ("imu_time_offset_s", "gnss_latency_s"):
        value = meta.get(key, 0.0)
        if key == "gnss_latency_s" and value == "auto":      # estimated at load (bgfn.data.time_offset)
            shifts[key] = "auto"
            continue
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not np.isfinite(value):
            raise DataError(path, key, "a number of seconds", repr(value))
        if abs(value) > MAX_TIME_SHIFT_S or (key == "gnss_latency_s" and value < 0):
            raise DataError(path, key, f"a delay of at most {MAX_TIME_SHIFT_S:g} s" + (" and >= 0" if key ==
                            "gnss_latency_s" else "") + " (larger: the clocks differ, e.g. by the 18 s between GPS "
                            "time and UTC; convert the times instead)", repr(value))
        shifts[key] = float(value)
    source = meta.get("source")
    if source is not None and not isinstance(source, str):
        raise DataError(path, "source", "free text", type(source).__name__)
    imu_errors, origin = imu_errors_from(path, meta.get("imu_errors"))
    return {"name": name, "lever_arm_m": larm.tolist(), "source": source, "imu_errors": imu_errors,
            "imu_errors_source": origin, "platform": platform, "imu_mounting_deg": mounting.tolist(),
            "gnss_std_m": None if std is None else std.tolist(), "reference_lever_arm_m": ref_lever.tolist(),
            **shifts}


def _vector(path: Path, meta: dict, key: str, default, expected: str) -> np.ndarray:
    """``meta[key]`` (or ``default``) as 3 finite floats; one error naming the file and key otherwise."""
    raw = meta.get(key, default)
    try:
        vec = np.asarray(raw, dtype=float).ravel()
    except (TypeError, ValueError):
        vec = np.array([np.nan])
    if vec.size != 3 or not np.isfinite(vec).all():
        raise DataError(path, key, expected, str(raw))
    return vec

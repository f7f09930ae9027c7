"""``meta.yaml`` of a user's CSV drive: its keys, their defaults, one clear error for anything else.

=================  ====================================================================================
key                meaning (all optional; the file itself is optional)
=================  ====================================================================================
``name``           dataset id naming the result files (:func:`bgfn.data.names.dataset_id`): letters,
                   digits, ``_``, ``-``, ``.``; default: the folder's name
``lever_arm_m``    GNSS antenna in the body frame [x, y, z], m; default [0, 0, 0]
``source``         free text (where the log comes from); default ``CSV drive <folder>``
``imu_errors``     the IMU error parameters the Kalman filter uses (its Q and P0,
                   :func:`bgfn.nav.state.noise_from_imu_errors`): a mapping of keys of
                   :mod:`bgfn.data.imu_errors` laid over the profile ``base`` (``mpu6000`` or
                   ``ekinox-d``; default :data:`DEFAULT_IMU_PROFILE`), plus ``model`` (a free label)
=================  ====================================================================================

Without ``meta.yaml``, or without ``imu_errors``, the filter uses the consumer-MEMS profile
:data:`bgfn.data.imu_errors.MPU6000` (InvenSense MPU-6000 datasheet noise densities, the paper's turn-on biases
5 deg/s and 60 mg, bias instability 0.01 deg/s and 0.5 mg with 100 s correlation time): the grade of the
paper's field-test IMU and of most phones and autopilots. ``meta["imu_errors_source"]`` says which was used.
A recorded IMU is usually noisier while driving than its datasheet (vibration); the filter's mean NIS, printed
by notebook 02, shows it.

An unknown key, at the top level or inside ``imu_errors``, is a :class:`bgfn.errors.DataError` naming the file,
the key and the closest valid key: a misspelt noise density never silently becomes a default.
"""

from __future__ import annotations

import difflib
import re
from pathlib import Path

import numpy as np
import yaml

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
META_KEYS: tuple[str, ...] = ("name", "lever_arm_m", "source", "imu_errors")
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
        meta = yaml.safe_load(path.read_text(encoding="utf-8"))
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
        None), ``imu_errors`` (:func:`bgfn.data.imu_errors.error_params` output), ``imu_errors_source`` (str).

    Raises
    ------
    DataError
        Naming the file and the key: unreadable YAML, unknown key (with the closest valid one), bad value.
    """
    path = Path(path)
    meta = _load(path) if path.is_file() else {}
    name = _checked_name(path, meta)
    larm_raw = meta.get("lever_arm_m", [0.0, 0.0, 0.0])
    try:
        larm = np.asarray(larm_raw, dtype=float).ravel()
    except (TypeError, ValueError):
        larm = np.array([np.nan])
    if larm.size != 3 or not np.isfinite(larm).all():
        raise DataError(path, "lever_arm_m", "3 finite numbers [x, y, z], m (antenna in the body frame)",
                        str(larm_raw))
    source = meta.get("source")
    if source is not None and not isinstance(source, str):
        raise DataError(path, "source", "free text", type(source).__name__)
    imu_errors, origin = imu_errors_from(path, meta.get("imu_errors"))
    return {"name": name, "lever_arm_m": larm.tolist(), "source": source, "imu_errors": imu_errors,
            "imu_errors_source": origin}

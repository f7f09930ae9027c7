"""Where trained networks live, and how their file names are built and read back.

One network = one ``(dataset, method, seed)`` of a profile (a fold ``k`` for the outage sweep's networks)::

    results/<profile>/models/<dataset id>/[fold<k>/]<method>_seed<seed>.pt     best checkpoint (bgfn.train)
                                                 <method>_seed<seed>.json      its card (metrics, config hash)
                                                 <method>_seed<seed>.last.pt   while training: resumable state

A variant's networks live under ``models/variants/<variant>/<dataset id>/`` (:func:`variant_models_dir`). Every
module builds these names with :func:`checkpoint_path` or :func:`checkpoint_name` and reads them back with
:func:`parse_checkpoint`; the folder is the dataset's id, so a drive named by a path never writes outside
``results/<profile>/``.
"""

from __future__ import annotations

import pickle
import re
import zipfile
from pathlib import Path
from typing import Any, NamedTuple

import torch

from bgfn import config
from bgfn.config import results_dir
from bgfn.data.names import dataset_id
from bgfn.errors import DataError

#: Suffixes of the three files of one network.
BEST_SUFFIX, CARD_SUFFIX, LAST_SUFFIX = ".pt", ".json", ".last.pt"
_NAME_RE = re.compile(r"^(?P<method>[A-Za-z0-9_]+?)_seed(?P<seed>\d+)(?P<suffix>\.last\.pt|\.pt|\.json)$")
_FOLD_RE = re.compile(r"^fold(?P<fold>\d+)$")


class Checkpoint(NamedTuple):
    """What a checkpoint's path says: ``method`` id, training ``seed`` and sweep ``fold`` (None: notebook 03's)."""

    method: str
    seed: int
    fold: int | None = None


def checkpoint_name(method: str, seed: int, suffix: str = BEST_SUFFIX) -> str:
    """``<method>_seed<seed><suffix>`` (suffix :data:`BEST_SUFFIX`, :data:`CARD_SUFFIX` or :data:`LAST_SUFFIX`)."""
    return f"{method}_seed{int(seed)}{suffix}"


def models_dir(profile: str, dataset: str, fold: int | None = None, create: bool = True) -> Path:
    """``results/<profile>/models/<dataset id>/`` (``.../fold<k>/`` for a sweep fold), created unless ``create``
    is False; ``dataset`` may be a registered name, a CSV folder path or an id (:func:`bgfn.data.names.dataset_id`)."""

    d = results_dir(profile, create=create) / "models" / dataset_id(dataset)
    return _made(d / f"fold{int(fold)}" if fold is not None else d, create)


def _made(folder: Path, create: bool) -> Path:
    """``folder``, created (with its parents) when ``create``; an error when it would lie outside
    ``results/`` (a dataset given by its folder path must never become a path here)."""
    if not folder.resolve().is_relative_to(config.RESULTS_ROOT.resolve()):
        raise DataError("models", "folder", f"a folder under {config.RESULTS_ROOT}", str(folder))
    if create:
        folder.mkdir(parents=True, exist_ok=True)
    return folder


#: Folder of ``results/<profile>/models/`` that holds the variants' networks (:func:`variant_models_dir`).
VARIANTS_DIR = "variants"


def variant_models_dir(profile: str, variant: str, dataset: str, create: bool = True) -> Path:
    """``results/<profile>/models/variants/<variant>/<dataset id>/`` (a variant's networks), created unless
    ``create`` is False."""
    return _made(results_dir(profile, create=create) / "models" / VARIANTS_DIR / variant / dataset_id(dataset),
                 create)


#: Folder of ``results/<profile>/models/`` that holds the runs trained again on all windows (:mod:`bgfn.train.recheck`).
ALL_WINDOWS_DIR = "all_windows"


def all_windows_models_dir(profile: str, dataset: str, create: bool = True) -> Path:
    """``results/<profile>/models/all_windows/<dataset id>/`` (runs trained again on all their training windows),
    created unless ``create`` is False."""

    return _made(results_dir(profile, create=create) / "models" / ALL_WINDOWS_DIR / dataset_id(dataset), create)


#: Folder of a sweep fold's models that holds its learned odometers (:mod:`bgfn.studies.odometer.bars`).
ODOMETER_DIR = "odometer"


def odometer_models_dir(profile: str, dataset: str, fold: int, create: bool = True) -> Path:
    """``results/<profile>/models/<dataset id>/fold<k>/odometer/`` (the networks trained as odometers on that
    fold), created unless ``create`` is False."""
    return _made(models_dir(profile, dataset, fold, create) / ODOMETER_DIR, create)


def checkpoint_path(profile: str, dataset: str, method: str, seed: int, fold: int | None = None,
                    create: bool = True) -> Path:
    """``results/<profile>/models/<dataset id>/[fold<k>/]<method>_seed<seed>.pt``."""
    return models_dir(profile, dataset, fold, create) / checkpoint_name(method, seed)


def card_path(checkpoint: str | Path) -> Path:
    """The JSON card beside a best checkpoint ``<stem>.pt``."""
    p = Path(checkpoint)
    return p.with_name(p.name[: -len(BEST_SUFFIX)] + CARD_SUFFIX)


def last_path(checkpoint: str | Path) -> Path:
    """The resumable state beside a best checkpoint ``<stem>.pt``."""
    p = Path(checkpoint)
    return p.with_name(p.name[: -len(BEST_SUFFIX)] + LAST_SUFFIX)


def parse_checkpoint(path: str | Path) -> Checkpoint:
    """Method, seed and fold of a network's file (``.pt``, ``.json`` or ``.last.pt``).

    Raises
    ------
    ValueError
        The name is not ``<method>_seed<k>`` with one of the three suffixes.
    """
    p = Path(path)
    m = _NAME_RE.match(p.name)
    if m is None:
        raise ValueError(f"{p}: not a network file <method>_seed<k>{{{BEST_SUFFIX},{CARD_SUFFIX},{LAST_SUFFIX}}}")
    fold = _FOLD_RE.match(p.parent.name)
    return Checkpoint(m["method"], int(m["seed"]), int(fold["fold"]) if fold else None)


def cards(folder: str | Path) -> list[Path]:
    """The cards ``<method>_seed<k>.json`` directly in ``folder`` (sorted; fold folders not entered)."""
    folder = Path(folder)
    return sorted(p for p in folder.glob(f"*{CARD_SUFFIX}") if _NAME_RE.match(p.name))


def read_checkpoint(path: str | Path, map_location: Any = "cpu") -> dict:
    """A checkpoint of :mod:`bgfn.train` (best or resumable state), loaded with ``weights_only=True``: tensors,
    numbers, strings, lists and dicts only, never arbitrary pickled code from a file under ``results/``.

    Raises
    ------
    bgfn.errors.DataError
        The file is corrupt, truncated or not one of ours; the message names it and how to train it again.
    """
    path = Path(path)
    try:
        ck = torch.load(path, map_location=map_location, weights_only=True)
    except (pickle.UnpicklingError, RuntimeError, EOFError, zipfile.BadZipFile, ValueError, OSError, IndexError,
            KeyError, TypeError, AttributeError) as exc:       # a truncated pickle fails in any of these ways
        raise DataError(path, "checkpoint", f"a checkpoint written by bgfn.train (to train it again, delete it and "
                        f"the executed notebook that trains it, so that make runs that notebook and every later one "
                        f"again: `{retrain_command(path)}`)",
                        f"{type(exc).__name__}: {str(exc).splitlines()[0][:200] if str(exc) else 'unreadable'}") from None
    if not isinstance(ck, dict):
        raise DataError(path, "checkpoint", "a dict written by bgfn.train", type(ck).__name__)
    return ck


def writer_notebook(path: str | Path) -> str:
    """The notebook that trains the network at ``path`` (under ``results/<profile>/models/``): a sweep fold's
    learned odometers 07, a sweep fold's networks 06, every other (the profile's own, its variants, the
    all-windows rechecks, their learning-rate searches) 03."""
    parts = Path(path).parts
    folds = [i for i, p in enumerate(parts) if _FOLD_RE.match(p)]
    if folds and ODOMETER_DIR in parts[folds[-1]:]:
        return "07_learned_odometer"
    return "06_outage_sweep" if folds else "03_bgfn_training"


def retrain_command(path: str | Path) -> str:
    """The shell line that trains the network at ``path`` again: delete it and the executed notebook that trains it
    (:func:`writer_notebook`; make then reruns it and what follows), then ``make reproduce`` (paths relative to the
    repository)."""
    profile = _profile_of(Path(path))
    executed = config.RESULTS_ROOT / profile / "notebooks" / f"{writer_notebook(path)}.ipynb"

    def shown(p: Path) -> str:
        try:
            return p.resolve().relative_to(config.PROJECT_ROOT.resolve()).as_posix()
        except ValueError:
            return p.as_posix()

    return f"rm -f {shown(Path(path))} {shown(executed)} && make reproduce PROFILE={profile}"


def _profile_of(path: Path) -> str:
    """The profile whose ``results/<profile>/`` holds ``path`` (``<profile>`` when it lies elsewhere)."""
    try:
        return path.resolve().relative_to(config.RESULTS_ROOT.resolve()).parts[0]
    except ValueError:
        return "<profile>"

"""Dataset names and dataset ids: what a profile writes, and the safe id every result file is named by.

A profile names a drive by a registered dataset (:data:`bgfn.data.DATASETS`) or by a folder in the CSV schema
(:mod:`bgfn.data.csv_drive`; absolute, or relative to the repository root, else to the current directory). Result
files are named by :func:`dataset_id`, never by the path, so outputs stay under ``results/<profile>/`` and no file
name holds a folder path: a registered dataset keeps its name, a CSV folder takes its ``meta.yaml`` ``name`` or its
own name made safe. :func:`dataset_id` is idempotent, so a name read back from a result file gives the same file.
:func:`with_dataset_ids` maps a loaded profile's drive entries to their ids once, so that every table, record and
file downstream names an own log by its id; :func:`dataset_folder` with the profile finds the folder of an id again.
"""

from __future__ import annotations

import hashlib
import re
from pathlib import Path

from bgfn.config import DATASET_KEYS, DEFAULT_DATASET_KEY, PROJECT_ROOT, read_profile
from bgfn.data.csv_meta import ID_PATTERN, META_FILE, read_meta_name
from bgfn.data.registry import DATASETS
from bgfn.errors import DataError

_UNSAFE = re.compile(r"[^A-Za-z0-9_.-]+")
#: The id of a folder whose name has no safe character at all.
FALLBACK_ID = "drive"


def registered(name) -> bool:
    """True when ``name`` is a dataset of :data:`bgfn.data.registry.DATASETS`."""

    return isinstance(name, str) and name in DATASETS


def dataset_folder(name: str | Path, profile: str | None = None) -> Path | None:
    """The CSV folder a dataset name denotes, or None (a registered dataset, or no such folder).

    An absolute path is taken as is; a relative one relative to the repository root
    (:data:`bgfn.config.PROJECT_ROOT`, where ``make`` runs the notebooks), else to the current directory. With
    ``profile``, an id (:func:`dataset_id`) of a folder the profile's file names is that folder first.
    """
    if registered(name) or not str(name).strip():
        return None
    entry = profile_entry(name, profile) if profile is not None else None
    if entry is not None:
        return dataset_folder(entry)
    path = Path(str(name)).expanduser()
    if path.is_absolute():
        return path if path.is_dir() else None
    for base in (PROJECT_ROOT, Path.cwd()):
        if (base / path).is_dir():
            return (base / path).resolve()
    return None


def profile_entry(name: str | Path, profile: str) -> str | None:
    """The entry of ``profile``'s file (a folder's path, as written) whose id (:func:`dataset_id`) is ``name``, when
    ``name`` is not that entry itself; None otherwise."""
    if registered(name):
        return None
    for entry in profile_entries(read_profile(profile)):           # as the file names them (paths)
        if entry != str(name) and not registered(entry) and dataset_id(entry) == str(name):
            return entry
    return None


def safe_id(text: str) -> str:
    """``text`` with every run of characters outside ``[A-Za-z0-9_.-]`` replaced by ``-`` (and no leading
    ``.``, ``-`` or ``_``); :data:`FALLBACK_ID` when nothing is left."""
    out = _UNSAFE.sub("-", str(text)).lstrip("._-")
    return out or FALLBACK_ID


def dataset_id(name: str | Path) -> str:
    """The safe id that names a dataset's result files (module docstring).

    Parameters
    ----------
    name : str or Path
        A registered dataset, a CSV folder (absolute or relative path), or an id.

    Returns
    -------
    str
        Matches :data:`ID_PATTERN`; a registered name is returned unchanged.

    Raises
    ------
    DataError
        The folder's ``meta.yaml`` is unreadable or its ``name`` is not a safe id (naming the file).
    """
    if registered(name):
        return str(name)
    folder = dataset_folder(name)
    if folder is not None:
        meta_name = read_meta_name(folder / META_FILE)
        return meta_name if meta_name is not None else safe_id(folder.name)
    text = str(name)
    if ID_PATTERN.match(text):
        return text
    return safe_id(Path(text.rstrip("/\\")).name)


def unique_ids(names, source: str | Path = "profile") -> dict[str, str]:
    """``{name: dataset_id(name)}``; a DataError naming ``source`` when two names share one id (their result
    files would overwrite each other)."""
    ids: dict[str, str] = {}
    seen: dict[str, str] = {}
    for name in dict.fromkeys(str(n) for n in names):
        i = dataset_id(name)
        if (registered(i) and not registered(name)) or i == DEFAULT_DATASET_KEY:
            # the id would load the built-in drive (or read as the per-dataset settings' default), not this folder
            raise DataError(source, "datasets", "a CSV folder whose id (its meta.yaml 'name', else its folder name) "
                            f"is neither a built-in dataset nor '{DEFAULT_DATASET_KEY}'", f"{name!r} has the id {i!r}")
        if i in seen and seen[i] != name and i not in (name, seen[i]):      # an id beside its folder: one drive
            raise DataError(source, "datasets", "datasets with distinct ids (a CSV folder's id is its meta.yaml "
                            "'name', else its folder name)", f"{seen[i]!r} and {name!r} both have the id {i!r}")
        if i != name or i not in seen:
            seen[i] = name
        ids[name] = i
    return ids


#: Mappings keyed by dataset (with a ``default``) whose keys name drives as the datasets' lists do.
KEYED_BY_DATASET: tuple[str, ...] = ("outage_windows", "nav.noise_scale", "evaluate.odometer.network_seeds")


def with_dataset_ids(cfg: dict, source: str | Path = "profile") -> dict:
    """``cfg`` (a profile as read) with every drive entry an id (:func:`dataset_id`): the lists of
    :data:`bgfn.config.DATASET_KEYS`, ``energy.dataset`` and the keys of :data:`KEYED_BY_DATASET`; a registered
    dataset keeps its name, so a profile of the shipped drives comes back equal. The one place where a CSV folder's
    path becomes its id: everything read from the profile after it (tables, records, file names) names the drive by
    its id (:func:`dataset_folder` with the profile finds the folder again).

    Raises
    ------
    DataError
        Two entries share one id (naming ``source``), or a folder's ``meta.yaml`` is unreadable.
    """
    unique_ids(profile_entries(cfg), source)
    out = dict(cfg)

    def node_at(path: str):
        *parents, key = path.split(".")
        node = out
        for k in parents:                          # copy the sections on the way, so that cfg is not changed
            if not isinstance(node.get(k), dict):
                return None, key
            node[k] = dict(node[k])
            node = node[k]
        return node, key

    for path in ("datasets", *DATASET_KEYS):
        node, key = node_at(path)
        if node is not None and isinstance(node.get(key), list):
            node[key] = [dataset_id(d) if isinstance(d, (str, Path)) else d for d in node[key]]
    node, key = node_at("energy.dataset")
    if node is not None and isinstance(node.get(key), str):
        node[key] = dataset_id(node[key])
    for path in KEYED_BY_DATASET:
        node, key = node_at(path)
        if node is not None and isinstance(node.get(key), dict):
            ids = [dataset_id(k) if isinstance(k, str) and k != DEFAULT_DATASET_KEY else k for k in node[key]]
            repeated = sorted({str(i) for i in ids if ids.count(i) > 1})
            if repeated:                                   # two keys of one drive: one would silently win
                raise DataError(source, path, "each drive once", f"two keys with the id {repeated[0]!r}")
            node[key] = dict(zip(ids, node[key].values()))
    return out


def profile_entries(cfg: dict, fleet: bool = True) -> list[str]:
    """Every drive entry of a profile as written, each once: the lists of ``datasets`` and
    :data:`bgfn.config.DATASET_KEYS`, ``energy.dataset`` and the keys of :data:`KEYED_BY_DATASET` (but
    ``default``), the set :func:`with_dataset_ids` names by id, and, with ``fleet``, ``fleet.drives`` (loaded as
    written; only the fleet study reads them)."""
    def at(path: str):
        node = cfg
        for k in path.split("."):
            node = node.get(k) if isinstance(node, dict) else None
        return node

    lists = ("datasets", *DATASET_KEYS) + (("fleet.drives",) if fleet else ())
    found = [d for path in lists if isinstance(at(path), list) for d in at(path)]
    found += [at("energy.dataset")] if isinstance(at("energy.dataset"), str) else []
    found += [k for path in KEYED_BY_DATASET if isinstance(at(path), dict) for k in at(path)
              if k != DEFAULT_DATASET_KEY]
    return list(dict.fromkeys(str(d) for d in found if isinstance(d, (str, Path))))


def profile_datasets(cfg: dict) -> list[str]:
    """Every dataset a notebook of a profile loads (``data``, ``nav``, ``train``, ``evaluate`` and its sweep), in
    order, each once, as the profile names it."""
    ev = cfg.get("evaluate") or {}
    return list(dict.fromkeys(
        [d for sec in ("data", "nav", "train", "evaluate") for d in (cfg.get(sec) or {}).get("datasets") or []]
        + ((ev.get("sweep") or {}).get("datasets") or [])))


def data_fingerprint(names) -> str:
    """A hash of the files of every CSV folder among ``names`` (each file's name, size and modification time), so
    that ``make`` reruns a profile whose drive was edited (or touched); the registered datasets are checksummed by
    :mod:`bgfn.data.acquire` and not part of it. The hash of nothing when no name is a folder."""
    h = hashlib.sha256()
    for name in names:
        folder = dataset_folder(name)
        if folder is None:
            continue
        h.update(str(folder).encode())
        for f in sorted(p for p in folder.iterdir() if p.is_file()):
            st = f.stat()
            h.update(f"{f.name}\0{st.st_size}\0{st.st_mtime_ns}\n".encode())
    return h.hexdigest()[:16]


def drive_fingerprints(cfg: dict) -> tuple[str, str]:
    """``(drives, fleet)``: :func:`data_fingerprint` of the CSV drives notebooks 01-10 read, and of the fleet's
    (``fleet.drives``, read by notebook 11 only). A fleet drive that another list names by its id (a drive's id
    beside its folder is one drive) is among the former too, and so is one whose id cannot be read."""
    own = profile_entries(cfg, fleet=False)
    fleet = [str(d) for d in (cfg.get("fleet") or {}).get("drives") or []]

    def id_of(name):
        try:
            return dataset_id(name)
        except DataError:
            return None

    ids = {id_of(e) for e in own} | {None}
    shared = [d for d in fleet if id_of(d) in ids]
    return data_fingerprint(own + shared), data_fingerprint(fleet)

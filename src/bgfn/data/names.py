"""Dataset names and dataset ids: what a profile writes, and the safe id every result file is named by.

A profile names a drive by a registered dataset (:data:`bgfn.data.DATASETS`) or by a folder in the CSV schema
(:mod:`bgfn.data.csv_drive`; absolute, or relative to the repository root, else to the current directory). Result
files are named by :func:`dataset_id`, never by the path, so outputs stay under ``results/<profile>/`` and no file
name holds a folder path: a registered dataset keeps its name, a CSV folder takes its ``meta.yaml`` ``name`` or its
own name made safe. :func:`dataset_id` is idempotent, so a name read back from a result file gives the same file.
"""

from __future__ import annotations

import hashlib
import re
from pathlib import Path

from bgfn.config import PROJECT_ROOT
from bgfn.data.csv_meta import ID_PATTERN, META_FILE, read_meta_name
from bgfn.data.registry import DATASETS
from bgfn.errors import DataError

_UNSAFE = re.compile(r"[^A-Za-z0-9_.-]+")
#: The id of a folder whose name has no safe character at all.
FALLBACK_ID = "drive"


def registered(name) -> bool:
    """True when ``name`` is a dataset of :data:`bgfn.data.registry.DATASETS`."""

    return isinstance(name, str) and name in DATASETS


def dataset_folder(name: str | Path) -> Path | None:
    """The CSV folder a dataset name denotes, or None (a registered dataset, or no such folder).

    An absolute path is taken as is; a relative one relative to the repository root
    (:data:`bgfn.config.PROJECT_ROOT`, where ``make`` runs the notebooks), else to the current directory.
    """
    if registered(name) or not str(name).strip():
        return None
    path = Path(str(name)).expanduser()
    if path.is_absolute():
        return path if path.is_dir() else None
    for base in (PROJECT_ROOT, Path.cwd()):
        if (base / path).is_dir():
            return (base / path).resolve()
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
        if i in seen and seen[i] != name:
            raise DataError(source, "datasets", "datasets with distinct ids (a CSV folder's id is its meta.yaml "
                            "'name', else its folder name)", f"{seen[i]!r} and {name!r} both have the id {i!r}")
        seen[i] = name
        ids[name] = i
    return ids


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

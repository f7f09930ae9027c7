"""Atomic file output: write to a temporary file in the same folder, then rename.

A crash or a bad input never leaves a half-written table, figure or cache entry behind. Also the fingerprint of
source files (:func:`sources_hash`) that decides whether a cached dataset or a trained network is still current,
and results computed once and kept on disk under a key of their inputs (:func:`cached`).
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import hashlib
import json
import os
import pickle
import shutil
import tempfile
from pathlib import Path
from typing import Any, Callable, Iterator, TypeVar

import numpy as np
import pandas as pd


#: Errors of a full disk (or quota): reported with the file that could not be written.
_FULL = (errno.ENOSPC, errno.EDQUOT)


def shown_path(path: str | Path) -> str:
    """``path`` as a message shows it: relative to the current folder (the repository root under ``make``) when
    inside it, so that no machine path is printed where a short one says the same."""
    path = Path(path).absolute()
    try:
        return path.relative_to(Path.cwd()).as_posix()
    except ValueError:
        return str(path)


def _nearly_full(folder: Path) -> bool:
    try:
        return shutil.disk_usage(folder).free < 1 << 20
    except OSError:
        return False


@contextlib.contextmanager
def atomic_path(path: str | Path) -> Iterator[Path]:
    """Yield a temporary path beside ``path``; rename it onto ``path`` only if the block succeeds. A full disk
    raises ``OSError(ENOSPC)`` naming ``path`` (:func:`shown_path`), not the temporary file or nothing."""
    path = Path(path)
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.name}.", suffix=".tmp" + path.suffix, dir=path.parent)
        os.close(fd)
        tmp = Path(tmp)
        # mkstemp creates owner-only files; give outputs the usual permissions (0666 minus the umask).
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, 0o666 & ~umask)
        yield tmp
        os.replace(tmp, path)
        _log_output(path)
    except Exception as exc:        # torch.save reports a full disk as a RuntimeError: the free space tells
        if getattr(exc, "errno", None) not in _FULL and not _nearly_full(path.parent):
            raise
        code = getattr(exc, "errno", None) or errno.ENOSPC
        raise OSError(code, f"{os.strerror(code)}: {shown_path(path)} could not be written (the previous copy, if "
                      f"any, is kept; free some space and run again) [{type(exc).__name__}]") from None
    finally:
        if tmp is not None and tmp.exists():
            tmp.unlink()


#: Environment variable naming a file to which every completed output's absolute path is appended (one line each):
#: ``make`` sets it per notebook, so that a notebook that fails has its own outputs removed and not those of a
#: notebook running beside it.
OUTPUT_LOG_ENV = "BGFN_OUTPUT_LOG"


def _log_output(path: Path) -> None:
    log = os.environ.get(OUTPUT_LOG_ENV)
    if log:
        with open(log, "a", encoding="utf-8") as fh:    # one short line per write: appends do not interleave
            fh.write(os.path.abspath(path) + "\n")


def atomic_write_bytes(path: str | Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` atomically."""
    with atomic_path(path) as tmp:
        tmp.write_bytes(data)
    return Path(path)


def atomic_write_text(path: str | Path, text: str) -> Path:
    """Write ``text`` (UTF-8) to ``path`` atomically."""
    return atomic_write_bytes(path, text.encode("utf-8"))


def atomic_write_json(path: str | Path, obj: Any) -> Path:
    """Write ``obj`` as indented, key-sorted JSON (deterministic bytes) to ``path`` atomically."""
    return atomic_write_text(path, json.dumps(obj, indent=2, sort_keys=True, default=_json_default) + "\n")


def atomic_write_csv(path: str | Path, frame, **kwargs) -> Path:
    """Write a pandas DataFrame to CSV atomically (``index=False`` unless given)."""
    kwargs.setdefault("index", False)
    with atomic_path(path) as tmp:
        frame.to_csv(tmp, **kwargs)
    return Path(path)


def save_figure(fig, path: str | Path, dpi: int = 150) -> Path:
    """Save a matplotlib figure atomically; the format follows the suffix (.png, .svg)."""
    path = Path(path)
    with atomic_path(path) as tmp:
        fig.savefig(tmp, dpi=dpi, bbox_inches="tight", format=path.suffix.lstrip("."),
                    metadata={"Software": None} if path.suffix == ".png" else None)
    return path


def _json_default(obj: Any) -> Any:
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    if isinstance(obj, Path):
        return str(obj)
    raise TypeError(f"not JSON serializable: {type(obj).__name__}")


def update_json(path: str | Path, updates: dict) -> dict:
    """Merge ``updates`` (nested keys allowed as dicts) into the JSON file at ``path``, atomically.

    Used by the benchmarks, which each add their own keys to ``results/bench.json``.
    """
    path = Path(path)
    data = json.loads(path.read_text()) if path.exists() else {}

    def merge(dst: dict, src: dict) -> None:
        for key, value in src.items():
            if isinstance(value, dict) and isinstance(dst.get(key), dict):
                merge(dst[key], value)
            else:
                dst[key] = value

    merge(data, updates)
    atomic_write_json(path, data)
    return data


def sources_hash(paths) -> str:
    """SHA-256 (hex) of the bytes of ``paths`` in the given order, files that do not exist skipped: the fingerprint
    of the code a cache entry or a trained network was made by (:mod:`bgfn.data.drives`, :mod:`bgfn.models`)."""
    h = hashlib.sha256()
    for p in map(Path, paths):
        if p.is_file():
            h.update(p.read_bytes())
    return h.hexdigest()


#: Environment variable naming the folder of :func:`cached` (``make`` sets ``results/<profile>/cache``); unset, every
#: result is computed where it is asked for.
CACHE_DIR_ENV = "BGFN_CACHE_DIR"
T = TypeVar("T")


def content_hash(obj: Any) -> str:
    """SHA-256 (hex) of a value's content: mappings (key order aside), sequences, numbers, strings, numpy arrays
    (dtype, shape and bytes) and pandas frames and series (columns, dtypes, index and every value), nested."""
    h = hashlib.sha256()
    _feed(h, obj)
    return h.hexdigest()


def _feed(h, obj: Any) -> None:
    if isinstance(obj, dict):
        h.update(b"{")
        for key in sorted(obj, key=str):
            _feed(h, str(key))
            _feed(h, obj[key])
        h.update(b"}")
    elif isinstance(obj, (list, tuple)):
        h.update(b"[")
        for item in obj:
            _feed(h, item)
        h.update(b"]")
    elif isinstance(obj, np.ndarray):
        if obj.dtype == object:
            _feed(h, obj.tolist())
        else:
            h.update(f"a{obj.dtype.str}{obj.shape}".encode())
            h.update(np.ascontiguousarray(obj).tobytes())
    elif isinstance(obj, (pd.DataFrame, pd.Series)):
        columns = list(obj.columns) if isinstance(obj, pd.DataFrame) else [obj.name]
        dtypes = list(obj.dtypes) if isinstance(obj, pd.DataFrame) else [obj.dtype]
        h.update(f"p{type(obj).__name__}{list(map(str, columns))}{list(map(str, dtypes))}".encode())
        h.update(pd.util.hash_pandas_object(obj, index=True).to_numpy().tobytes())
    elif isinstance(obj, float):
        h.update(b"f" + np.float64(obj).tobytes())
    elif isinstance(obj, np.generic):
        _feed(h, obj.item())
    else:
        h.update(f"{type(obj).__name__}:{obj!r}".encode())
    h.update(b";")


def cached(kind: str, key: Any | Callable[[], Any], compute: Callable[[], T]) -> T:
    """``compute()``, kept on disk under ``<$BGFN_CACHE_DIR>/<kind>/<hash of key>.pkl`` and read back (the same
    object, bit for bit) when asked for again with the same ``key``. ``key`` must hold every input of the result
    (its data's :func:`content_hash`, its settings, the version of the code: :func:`sources_hash`); None, or no
    ``BGFN_CACHE_DIR``: computed every time. ``key`` may be a function returning it: then called only when there is
    a cache. A cache entry is only ever written by this code (results/<profile>/cache/): it is unpickled, so it is
    never a user's file."""
    root = os.environ.get(CACHE_DIR_ENV)
    if root and callable(key):
        key = key()
    if not root or key is None:
        return compute()
    digest = content_hash({"kind": kind, "key": key})
    path = Path(root) / kind / f"{digest[:32]}.pkl"
    found = _read_entry(path, digest)
    if found is not None:
        return found[0]
    # Two notebooks side by side (make -j) may ask for the same entry at once: the second waits for the first's
    # result instead of computing it again (a computation never asks for its own entry, so no two wait for each other).
    with locked(path.with_suffix(".lock")):
        found = _read_entry(path, digest)
        if found is not None:
            return found[0]
        value = compute()
        try:
            blob = pickle.dumps((digest, value), protocol=pickle.HIGHEST_PROTOCOL)
        except Exception:       # a result that cannot be pickled is simply not kept
            return value
        atomic_write_bytes(path, blob)
    return value


@contextlib.contextmanager
def locked(path: str | Path) -> Iterator[None]:
    """Hold an exclusive lock on the file ``path`` (created, with its folder) for the block; another process that asks
    for it waits. Released when the block ends or its holder does, even killed. On a file system without locks (some
    network mounts) the block runs unlocked."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    with open(path, "a+b") as lock:
        try:
            fcntl.flock(lock, fcntl.LOCK_EX)
        except OSError:
            pass
        yield


def _read_entry(path: Path, digest: str) -> tuple[Any] | None:
    """``(value,)`` of the cache entry at ``path`` when it holds ``digest``'s; None when absent or not readable."""
    if not path.is_file():
        return None
    try:
        stored_digest, value = pickle.loads(path.read_bytes())
    except Exception:   # a truncated or foreign file: computed again and replaced
        return None
    return (value,) if stored_digest == digest else None

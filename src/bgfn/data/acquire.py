"""Resolve the four NaveGo v1.4 Turin-drive files: ``data/raw`` -> local mirror -> pinned URL.

Every file is verified before use (SHA-256 where published, else its git blob id), including a file that
is already in ``data/raw``. A file from the mirror or from the network is copied into ``data/raw`` only
after it verifies, atomically (temporary file, then rename), so ``data/raw`` never holds a bad or
half-written file.

Locations (all configurable, so that tests never touch the repository's ``data/``):

- data folder: argument ``data_dir``, else env ``BGFN_DATA_DIR``, else ``<repo>/data``;
  raw files in ``<data>/raw``, processed datasets in ``<data>/processed``.
- mirror folder: argument ``mirror``, else env ``BGFN_DATA_MIRROR``, else ``<repo>/../shared/data/navego``
  when that folder exists.
"""

from __future__ import annotations

import hashlib
import logging
import os
import urllib.error
import urllib.request
from dataclasses import dataclass
from pathlib import Path

from bgfn.errors import ChecksumError, DataError
from bgfn.io import atomic_write_bytes as _atomic_write_bytes

log = logging.getLogger(__name__)

#: NaveGo git tag whose example data is used (commit 24d9488).
NAVEGO_TAG = "v1.4"
#: Pinned download URL pattern of the NaveGo example data.
NAVEGO_URL = "https://github.com/rodralez/NaveGo/raw/" + NAVEGO_TAG + "/examples/real-data/{file}"
#: Repository root (``src/bgfn/data/acquire.py`` -> three levels up).
REPO_ROOT = Path(__file__).resolve().parents[3]


@dataclass(frozen=True)
class RawFile:
    """A pinned raw file.

    Attributes
    ----------
    name : str
        File name, e.g. ``"ref.mat"``.
    sha256 : str or None
        Published SHA-256 (hex), or None when unknown.
    git_blob : str
        Git blob id (SHA-1 of ``b"blob <len>\\0" + data``) at tag v1.4.
    required : bool
        Whether the simulated datasets need it (``ref``, ``ekinox_gnss``) or it is optional (real IMUs).
    """

    name: str
    sha256: str | None
    git_blob: str
    required: bool


#: The four NaveGo files with their checksums (``../shared/data/navego/README.md``).
NAVEGO_FILES: dict[str, RawFile] = {
    f.name: f
    for f in (
        RawFile("ref.mat", "a1e68052b4126c1af2f93deb44a4301ab54ef0693310d59e523a37a2732dbfab",
                "9b51398f4e716b2f6feb7c6cb0e335c853a9bf06", True),
        RawFile("ekinox_gnss.mat", "13f8a2611ad6df24cb875593dac00702b31cb9125e69eb6ebd9b2c276a9bcd9c",
                "5ca747a00d20b864fd348e83efdd33a5c000610b", True),
        RawFile("ekinox_imu.mat", "b49466ed36c5b7de343e555ecd5822ce0cc47896911224d23ee6226f0ef526c5",
                "d2f570044e0b209454bf2fcf4679749fae5bab48", False),
        RawFile("mpu6000_imu.mat", None, "830d521b115ca2c5117a0cb0af575a573e4753f4", False),
    )
}

_reported_missing: set[str] = set()


class MissingFileError(DataError, FileNotFoundError):
    """A NaveGo file is in none of ``data/raw``, the mirror and the pinned URL."""


def data_dir(data_dir: str | Path | None = None) -> Path:
    """Data folder: ``data_dir`` if given, else env ``BGFN_DATA_DIR``, else ``<repo>/data``."""
    if data_dir is not None:
        return Path(data_dir)
    env = os.environ.get("BGFN_DATA_DIR")
    return Path(env) if env else REPO_ROOT / "data"


def raw_dir(data_dir_: str | Path | None = None) -> Path:
    """Folder of the verified raw files, ``<data>/raw``."""
    return data_dir(data_dir_) / "raw"


def processed_dir(data_dir_: str | Path | None = None) -> Path:
    """Folder of the cached processed datasets, ``<data>/processed``."""
    return data_dir(data_dir_) / "processed"


def mirror_dir(mirror: str | Path | None = None) -> Path | None:
    """Local mirror folder: ``mirror``, else env ``BGFN_DATA_MIRROR``, else ``<repo>/../shared/data/navego``.

    Returns None when no mirror is configured and the default folder does not exist.
    """
    if mirror is not None:
        return Path(mirror)
    env = os.environ.get("BGFN_DATA_MIRROR")
    if env:
        return Path(env)
    default = REPO_ROOT.parent / "shared" / "data" / "navego"
    return default if default.is_dir() else None


def git_blob_id(data: bytes) -> str:
    """Git blob id of ``data``: ``sha1(b"blob " + len + b"\\0" + data)`` (hex)."""
    return hashlib.sha1(b"blob " + str(len(data)).encode() + b"\0" + data).hexdigest()


def verify_bytes(data: bytes, spec: RawFile, source: str | Path) -> str:
    """Check ``data`` against the pinned checksum of ``spec``.

    Parameters
    ----------
    data : bytes
        File content.
    spec : RawFile
        The pinned file.
    source : str or Path
        Where the bytes came from (named in the error).

    Returns
    -------
    str
        The checksum that verified, as ``"sha256:<hex>"`` or ``"git-blob:<hex>"``.

    Raises
    ------
    ChecksumError
        If the checksum differs.
    """
    if spec.sha256 is not None:
        found = hashlib.sha256(data).hexdigest()
        if found != spec.sha256:
            raise ChecksumError(source, "sha256", f"{spec.sha256} (NaveGo {NAVEGO_TAG} {spec.name})",
                                f"{found} ({len(data)} bytes): corrupted or truncated file, not used")
        return "sha256:" + found
    found = git_blob_id(data)
    if found != spec.git_blob:
        raise ChecksumError(source, "git blob id", f"{spec.git_blob} (NaveGo {NAVEGO_TAG} {spec.name})",
                            f"{found} ({len(data)} bytes): corrupted or truncated file, not used")
    return "git-blob:" + found


def atomic_write_bytes(path: Path, data: bytes) -> Path:
    """Atomic write (bgfn.io), then make the file world-readable like any other data file."""
    _atomic_write_bytes(path, data)
    path.chmod(0o644)
    return path


def _download(url: str, timeout_s: float) -> bytes:
    try:
        with urllib.request.urlopen(url, timeout=timeout_s) as resp:  # noqa: S310 (pinned https URL)
            return resp.read()
    except (urllib.error.URLError, OSError, TimeoutError) as exc:
        raise ConnectionError(f"download of {url} failed: {exc}") from exc


@dataclass(frozen=True)
class Resolved:
    """Outcome of resolving one file.

    Attributes
    ----------
    name : str
        File name.
    path : Path or None
        Verified file in ``data/raw`` (None when it could not be had).
    origin : str
        ``"raw"``, ``"mirror"``, ``"download"`` or ``"missing"``.
    checksum : str or None
        The checksum that verified.
    detail : str
        Where it came from, or why it is missing.
    """

    name: str
    path: Path | None
    origin: str
    checksum: str | None
    detail: str


def resolve(name: str, *, data_dir: str | Path | None = None, mirror: str | Path | None = None,
            download: bool = True, timeout_s: float = 30.0) -> Resolved:
    """Find, verify and install one NaveGo file into ``<data>/raw``.

    Order: ``<data>/raw`` -> mirror folder -> pinned URL (``NAVEGO_URL``). A file already in ``raw``
    is verified too; a mismatch anywhere raises (the bad file is never used nor copied).

    Parameters
    ----------
    name : str
        One of ``NAVEGO_FILES`` (``"ref.mat"``, ``"ekinox_gnss.mat"``, ``"ekinox_imu.mat"``,
        ``"mpu6000_imu.mat"``).
    data_dir : str or Path, optional
        Data folder (see :func:`data_dir`).
    mirror : str or Path, optional
        Mirror folder (see :func:`mirror_dir`).
    download : bool
        Whether to try the pinned URL as the last resort.
    timeout_s : float
        Network timeout, s.

    Returns
    -------
    Resolved
        ``origin == "missing"`` (and ``path is None``) when the file is nowhere to be had.

    Raises
    ------
    ChecksumError
        A file was found but does not match its pinned checksum.
    DataError
        ``name`` is not a NaveGo file.
    """
    if name not in NAVEGO_FILES:
        raise DataError("bgfn.data.acquire", "name", f"one of {sorted(NAVEGO_FILES)}", repr(name))
    spec = NAVEGO_FILES[name]
    target = raw_dir(data_dir) / name
    if target.is_file():
        checksum = verify_bytes(target.read_bytes(), spec, target)
        return Resolved(name, target, "raw", checksum, str(target))
    tried = [f"{target} (absent)"]
    mdir = mirror_dir(mirror)
    if mdir is not None and (mdir / name).is_file():
        data = (mdir / name).read_bytes()
        checksum = verify_bytes(data, spec, mdir / name)
        atomic_write_bytes(target, data)
        return Resolved(name, target, "mirror", checksum, str(mdir / name))
    tried.append(f"{mdir / name if mdir is not None else 'no mirror (BGFN_DATA_MIRROR unset)'} (absent)")
    if download:
        url = NAVEGO_URL.format(file=name)
        try:
            data = _download(url, timeout_s)
        except ConnectionError as exc:
            tried.append(str(exc))
        else:
            checksum = verify_bytes(data, spec, url)
            atomic_write_bytes(target, data)
            return Resolved(name, target, "download", checksum, url)
    else:
        tried.append("download disabled")
    return Resolved(name, None, "missing", None, "; ".join(tried))


def require(name: str, **kwargs) -> Path:
    """Path of a verified NaveGo file in ``<data>/raw``; raise when it cannot be had.

    Parameters
    ----------
    name : str
        NaveGo file name.
    **kwargs
        Passed to :func:`resolve`.

    Returns
    -------
    Path

    Raises
    ------
    MissingFileError
        The file is in none of raw, mirror, URL (the message lists what was tried).
    ChecksumError
        A copy was found but does not verify.
    """
    res = resolve(name, **kwargs)
    if res.path is None:
        raise MissingFileError(name, "file", f"NaveGo {NAVEGO_TAG} file {name} in data/raw, the mirror "
                               f"or {NAVEGO_URL.format(file=name)}", f"nothing: {res.detail}")
    return res.path


def report_missing_once(name: str, detail: str) -> None:
    """Log (once per process and file) that an optional real-IMU file is absent."""
    if name not in _reported_missing:
        _reported_missing.add(name)
        log.warning("optional NaveGo file %s is not available (%s); the simulated datasets "
                    "turin-sim-ekinox / turin-sim-mpu6000 stand in for the real IMU", name, detail)


def fetch_all(*, data_dir: str | Path | None = None, mirror: str | Path | None = None,
              download: bool = True, timeout_s: float = 30.0) -> list[Resolved]:
    """Resolve all four NaveGo files (see :func:`resolve`); an absent optional file is logged once.

    Returns
    -------
    list of Resolved
        One entry per file, in ``NAVEGO_FILES`` order. A checksum mismatch raises.
    """
    out = []
    for name, spec in NAVEGO_FILES.items():
        res = resolve(name, data_dir=data_dir, mirror=mirror, download=download, timeout_s=timeout_s)
        if res.path is None and not spec.required:
            report_missing_once(name, res.detail)
        out.append(res)
    return out

"""Resolve the raw files of the shipped drives: ``data/raw`` -> local mirror -> pinned URL.

The four NaveGo v1.4 Turin-drive files and the three of the RTKLIB-logged car drive ``rtklib-drive0708``
(:data:`RTKLIB_FILES`); every file names its source, its pinned URL and its mirror folder, and is verified before
use (SHA-256 where published, else its git blob id), one already in ``data/raw`` included. A file from the mirror
or the network is copied into ``data/raw`` only after it verifies, atomically, so ``data/raw`` never holds a bad or
half-written file. The data folder (``BGFN_DATA_DIR``) and the mirrors (``BGFN_DATA_MIRROR``,
``BGFN_RTKLIB_MIRROR``, else ``<repo>/../shared/data/...``) are configurable, so tests never touch ``data/``.
"""

from __future__ import annotations

import datetime
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
#: Commit of ``rtklibexplorer/GNSS_IMU`` whose ``data/drive_0708`` files are used.
RTKLIB_COMMIT = "8235ee6c5f349db529bf43ad556a3769b346b5a1"
#: Pinned download URL pattern of the RTKLIB drive's files.
RTKLIB_URL = ("https://raw.githubusercontent.com/rtklibexplorer/GNSS_IMU/" + RTKLIB_COMMIT
              + "/data/drive_0708/{file}")
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
    url : str
        Pinned download URL pattern (``{file}``).
    mirror_folder : str
        Name of its mirror folder beside the repository (``<repo>/../shared/data/<mirror_folder>``).
    mirror_env : str
        Environment variable that may name the mirror folder.
    source : str
        Where it comes from, in words (named in the messages).
    when_missing : str
        What stands in when an optional file cannot be had.
    """

    name: str
    sha256: str | None
    git_blob: str
    required: bool
    url: str = NAVEGO_URL
    mirror_folder: str = "navego"
    mirror_env: str = "BGFN_DATA_MIRROR"
    source: str = f"NaveGo {NAVEGO_TAG}"
    when_missing: str = "the simulated datasets turin-sim-ekinox / turin-sim-mpu6000 stand in for the real IMU"


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

_RTKLIB = {"url": RTKLIB_URL, "mirror_folder": "rtklib-drive0708", "mirror_env": "BGFN_RTKLIB_MIRROR",
           "source": f"rtklibexplorer/GNSS_IMU {RTKLIB_COMMIT[:7]} data/drive_0708",
           "when_missing": "the dataset rtklib-drive0708 cannot be built; the other datasets are unaffected"}
#: The three files of the RTKLIB-logged car drive (``../shared/data/rtklib-drive0708/README.md``); required:
#: the shipped profiles use the dataset ``rtklib-drive0708``.
RTKLIB_FILES: dict[str, RawFile] = {
    f.name: f
    for f in (
        RawFile("imu_1934.csv", "f1126bf3b36efc4bef2dd2c7d93bb2a0e1b4ce714005cbea00a9218ad0b3b7a9",
                "f74142a151c63d83f50797deaf40f40929bb369e", True, **_RTKLIB),
        RawFile("imu_1934.csv.tag", "d30d13d5641df367559472b91b48325601a87c986bf2bb6af368684a36b5ec96",
                "c79867904df17050fb69470b5da68aac466700c8", True, **_RTKLIB),
        RawFile("gnss_1934_sf.pos", "618fba5c7193e8eb448faf95c79c0d198233d5f4e5ad8ffec652893911ff7133",
                "dc0ca25783ebb20d5e1e9f4fac590b72be551951", True, **_RTKLIB),
    )
}


def raw_files() -> dict[str, RawFile]:
    """Every pinned raw file by name: ``NAVEGO_FILES`` then ``RTKLIB_FILES`` (read at each call)."""
    return {**NAVEGO_FILES, **RTKLIB_FILES}


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


def mirror_dir(mirror: str | Path | None = None, spec: RawFile | None = None) -> Path | None:
    """Local mirror folder of ``spec`` (default: a NaveGo file): ``mirror``, else its environment variable
    (``BGFN_DATA_MIRROR`` for NaveGo), else ``<repo>/../shared/data/<its folder>`` (``navego``).

    Returns None when no mirror is configured and the default folder does not exist.
    """
    spec = spec or next(iter(NAVEGO_FILES.values()))
    if mirror is not None:
        return Path(mirror)
    env = os.environ.get(spec.mirror_env)
    if env:
        return Path(env)
    default = REPO_ROOT.parent / "shared" / "data" / spec.mirror_folder
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
            raise ChecksumError(source, "sha256", f"{spec.sha256} ({spec.source} {spec.name})",
                                f"{found} ({len(data)} bytes): corrupted or truncated file, not used")
        return "sha256:" + found
    found = git_blob_id(data)
    if found != spec.git_blob:
        raise ChecksumError(source, "git blob id", f"{spec.git_blob} ({spec.source} {spec.name})",
                            f"{found} ({len(data)} bytes): corrupted or truncated file, not used")
    return "git-blob:" + found


def atomic_write_bytes(path: Path, data: bytes) -> Path:
    """Atomic write (bgfn.io), then make the file world-readable like any other data file."""
    _atomic_write_bytes(path, data)
    path.chmod(0o644)
    return path


#: Beside an optional file in ``data/raw`` after its download failed: the date and the error. Every later run skips
#: the download (a network that is down, or a file that moved, stays so: a retry each run costs a timeout and a
#: line); ``python -m bgfn.data fetch --retry`` (or deleting it) tries again.
FAILED_MARK = ".{file}.download-failed"


def failed_mark(name: str, data_dir_: str | Path | None = None) -> Path:
    """The marker of a failed download of the optional file ``name`` (:data:`FAILED_MARK`)."""
    return raw_dir(data_dir_) / FAILED_MARK.format(file=name)


def failed_on(name: str, data_dir_: str | Path | None = None) -> str | None:
    """The date (``YYYY-MM-DD``, UTC) the download of ``name`` failed and was marked, or None."""
    mark = failed_mark(name, data_dir_)
    if not mark.is_file():
        return None
    first = mark.read_text(encoding="utf-8", errors="replace").split(maxsplit=1)
    return first[0] if first else "an earlier run"


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
            download: bool = True, timeout_s: float = 30.0, retry: bool = False) -> Resolved:
    """Find, verify and install one pinned file into ``<data>/raw``.

    Order: ``<data>/raw`` -> mirror folder -> pinned URL (``NAVEGO_URL``, ``RTKLIB_URL``). A file already in
    ``raw`` is verified too; a mismatch anywhere raises (the bad file is never used nor copied).

    Parameters
    ----------
    name : str
        One of :func:`raw_files`: ``NAVEGO_FILES`` (``"ref.mat"``, ``"ekinox_gnss.mat"``, ``"ekinox_imu.mat"``,
        ``"mpu6000_imu.mat"``) or ``RTKLIB_FILES``.
    data_dir : str or Path, optional
        Data folder (see :func:`data_dir`).
    mirror : str or Path, optional
        Mirror folder of this file (see :func:`mirror_dir`).
    download : bool
        Whether to try the pinned URL as the last resort.
    timeout_s : float
        Network timeout, s.
    retry : bool
        Try the download of an optional file again though an earlier one failed (:data:`FAILED_MARK`; without it
        that download is skipped, and a failed one is marked).

    Returns
    -------
    Resolved
        ``origin == "missing"`` (and ``path is None``) when the file is nowhere to be had.

    Raises
    ------
    ChecksumError
        A file was found but does not match its pinned checksum.
    DataError
        ``name`` is not a pinned file.
    """
    files = raw_files()
    if name not in files:
        raise DataError("bgfn.data.acquire", "name", f"one of {sorted(files)}", repr(name))
    spec = files[name]
    target = raw_dir(data_dir) / name
    if target.is_file():
        checksum = verify_bytes(target.read_bytes(), spec, target)
        return Resolved(name, target, "raw", checksum, str(target))
    tried = [f"{target} (absent)"]
    mdir = mirror_dir(mirror, spec)
    if mdir is not None and (mdir / name).is_file():
        data = (mdir / name).read_bytes()
        checksum = verify_bytes(data, spec, mdir / name)
        atomic_write_bytes(target, data)
        return Resolved(name, target, "mirror", checksum, str(mdir / name))
    tried.append(f"{mdir / name if mdir is not None else f'no mirror ({spec.mirror_env} unset)'} (absent)")
    mark = failed_mark(name, data_dir)
    if download and not spec.required and not retry and mark.is_file():
        tried.append(f"download skipped: it failed on {failed_on(name, data_dir)} ({mark.name})")
    elif download:
        url = spec.url.format(file=name)
        try:
            data = _download(url, timeout_s)
        except ConnectionError as exc:
            tried.append(str(exc))
            if not spec.required:          # an optional file: not again each run (FAILED_MARK)
                day = datetime.datetime.now(datetime.timezone.utc).date().isoformat()
                atomic_write_bytes(mark, f"{day} {exc}\n".encode("utf-8"))
        else:
            checksum = verify_bytes(data, spec, url)
            atomic_write_bytes(target, data)
            mark.unlink(missing_ok=True)
            return Resolved(name, target, "download", checksum, url)
    else:
        tried.append("download disabled")
    return Resolved(name, None, "missing", None, "; ".join(tried))


def require(name: str, **kwargs) -> Path:
    """Path of a verified pinned file in ``<data>/raw``; raise when it cannot be had.

    Parameters
    ----------
    name : str
        A name of :func:`raw_files`.
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
        spec = raw_files()[name]
        raise MissingFileError(name, "file", f"{spec.source} file {name} in data/raw, the mirror "
                               f"or {spec.url.format(file=name)}", f"nothing: {res.detail}")
    return res.path


def fetch_all(*, data_dir: str | Path | None = None, mirror: str | Path | None = None,
              rtklib_mirror: str | Path | None = None, download: bool = True,
              timeout_s: float = 30.0, retry: bool = False) -> list[Resolved]:
    """Resolve all pinned files (see :func:`resolve`); what was tried for an absent optional file is logged at the
    debug level (its absence is the caller's one line).

    Parameters
    ----------
    mirror, rtklib_mirror : str or Path, optional
        Mirror folder of the NaveGo files, of the RTKLIB drive's files (:func:`mirror_dir`).
    retry : bool
        Try again the downloads of optional files that failed before (:func:`resolve`).

    Returns
    -------
    list of Resolved
        One entry per file, in :func:`raw_files` order (NaveGo, then RTKLIB). A checksum mismatch raises.
    """
    out = []
    for name, spec in raw_files().items():
        folder = rtklib_mirror if name in RTKLIB_FILES else mirror
        res = resolve(name, data_dir=data_dir, mirror=folder, download=download, timeout_s=timeout_s, retry=retry)
        if res.path is None and not spec.required:   # the caller says so in one line (python -m bgfn.data fetch)
            log.debug("optional %s file %s is not available (%s)", spec.source, name, res.detail)
        out.append(res)
    return out

"""Acquisition of the NaveGo files: order raw -> mirror -> URL, checksums, atomic install, CLI."""

from __future__ import annotations

import datetime
import hashlib
import logging

import pytest

from bgfn.data import acquire
from bgfn.data.__main__ import main as cli_main
from bgfn.errors import ChecksumError, DataError

pytestmark = pytest.mark.usefixtures("repo_untouched")


@pytest.fixture(autouse=True)
def _isolated_env(monkeypatch):
    monkeypatch.delenv("BGFN_DATA_MIRROR", raising=False)

    def no_network(url, timeout_s):
        raise ConnectionError(f"download of {url} failed: network disabled in tests")

    monkeypatch.setattr(acquire, "_download", no_network)


def test_git_blob_id_matches_git():
    # `printf 'hello\n' | git hash-object --stdin`
    assert acquire.git_blob_id(b"hello\n") == "ce013625030ba8dba906f756967f9e9ca394464a"


def test_pinned_url_and_checksums_follow_the_readme():
    assert acquire.NAVEGO_URL.format(file="ref.mat") == \
        "https://github.com/rodralez/NaveGo/raw/v1.4/examples/real-data/ref.mat"
    assert [f.required for f in acquire.NAVEGO_FILES.values()] == [True, True, False, False]
    assert acquire.NAVEGO_FILES["mpu6000_imu.mat"].sha256 is None  # verified by git blob id


def test_resolve_mirror_then_raw(tmp_path, mirror):
    res = acquire.resolve("ref.mat", data_dir=tmp_path, mirror=mirror, download=False)
    assert res.origin == "mirror" and res.path == tmp_path / "raw" / "ref.mat"
    assert hashlib.sha256(res.path.read_bytes()).hexdigest() == acquire.NAVEGO_FILES["ref.mat"].sha256
    assert res.checksum == "sha256:" + acquire.NAVEGO_FILES["ref.mat"].sha256
    again = acquire.resolve("ref.mat", data_dir=tmp_path, mirror=tmp_path / "nowhere", download=False)
    assert again.origin == "raw"
    assert sorted(p.name for p in (tmp_path / "raw").iterdir()) == ["ref.mat"]  # no temporary left


def test_env_vars_locate_data_and_mirror(tmp_path, mirror, monkeypatch):
    monkeypatch.setenv("BGFN_DATA_DIR", str(tmp_path / "d"))
    monkeypatch.setenv("BGFN_DATA_MIRROR", str(mirror))
    assert acquire.raw_dir() == tmp_path / "d" / "raw"
    assert acquire.processed_dir() == tmp_path / "d" / "processed"
    res = acquire.resolve("ekinox_gnss.mat", download=False)
    assert res.origin == "mirror" and res.path == tmp_path / "d" / "raw" / "ekinox_gnss.mat"


@pytest.mark.parametrize("damage", ["truncate", "flip"])
def test_corrupted_mirror_file_is_refused_and_not_copied(tmp_path, mirror, damage):
    bad_mirror = tmp_path / "mirror"
    bad_mirror.mkdir()
    data = bytearray((mirror / "ref.mat").read_bytes())
    if damage == "truncate":
        data = data[: len(data) // 2]
    else:
        data[1000] ^= 0xFF
    (bad_mirror / "ref.mat").write_bytes(bytes(data))
    with pytest.raises(ChecksumError) as exc:
        acquire.resolve("ref.mat", data_dir=tmp_path / "data", mirror=bad_mirror, download=False)
    assert str(bad_mirror / "ref.mat") in str(exc.value) and exc.value.field == "sha256"
    assert not (tmp_path / "data" / "raw" / "ref.mat").exists()
    assert not (tmp_path / "data" / "raw").exists() or not any((tmp_path / "data" / "raw").iterdir())


def test_corrupted_file_in_raw_is_an_error_and_left_alone(tmp_path, mirror):
    raw = tmp_path / "raw"
    raw.mkdir()
    bad = (mirror / "ekinox_gnss.mat").read_bytes()[:-10]
    (raw / "ekinox_gnss.mat").write_bytes(bad)
    with pytest.raises(ChecksumError, match="ekinox_gnss.mat"):
        acquire.resolve("ekinox_gnss.mat", data_dir=tmp_path, mirror=mirror, download=False)
    assert (raw / "ekinox_gnss.mat").read_bytes() == bad  # not silently replaced


def test_git_blob_verification_for_files_without_sha256():
    spec = acquire.RawFile("x.mat", None, acquire.git_blob_id(b"abc"), False)
    assert acquire.verify_bytes(b"abc", spec, "x.mat") == "git-blob:" + acquire.git_blob_id(b"abc")
    with pytest.raises(ChecksumError) as exc:
        acquire.verify_bytes(b"abd", spec, "somewhere/x.mat")
    assert exc.value.field == "git blob id" and "somewhere/x.mat" in str(exc.value)


def test_download_is_last_resort_and_verified(tmp_path, monkeypatch, mirror):
    urls = []
    good = (mirror / "ref.mat").read_bytes()

    def fake_download(url, timeout_s):
        urls.append(url)
        return good

    monkeypatch.setattr(acquire, "_download", fake_download)
    res = acquire.resolve("ref.mat", data_dir=tmp_path, mirror=tmp_path / "empty")
    assert res.origin == "download" and urls == [acquire.NAVEGO_URL.format(file="ref.mat")]
    assert res.path.read_bytes() == good

    monkeypatch.setattr(acquire, "_download", lambda url, timeout_s: good[:100])
    with pytest.raises(ChecksumError, match="github.com"):
        acquire.resolve("ekinox_gnss.mat", data_dir=tmp_path, mirror=tmp_path / "empty")
    assert not (tmp_path / "raw" / "ekinox_gnss.mat").exists()


def test_missing_file_reports_what_was_tried(tmp_path):
    res = acquire.resolve("ref.mat", data_dir=tmp_path, mirror=tmp_path / "empty")
    assert res.origin == "missing" and res.path is None
    assert "network disabled" in res.detail and str(tmp_path / "raw" / "ref.mat") in res.detail
    with pytest.raises(acquire.MissingFileError) as exc:
        acquire.require("ref.mat", data_dir=tmp_path, mirror=tmp_path / "empty")
    assert isinstance(exc.value, DataError) and "ref.mat" in str(exc.value)
    with pytest.raises(DataError, match="name"):
        acquire.resolve("other.mat", data_dir=tmp_path)


def test_absent_optional_files_cost_one_line_and_no_warning(tmp_path, mirror, caplog, capsys):
    with caplog.at_level(logging.WARNING, logger="bgfn.data.acquire"):
        first = acquire.fetch_all(data_dir=tmp_path, mirror=mirror, download=False)
        assert cli_main(["fetch", "--data-dir", str(tmp_path), "--mirror", str(mirror), "--no-download"]) == 0
    origins = {r.name: r.origin for r in first}
    assert origins["ref.mat"] in ("mirror", "raw") and origins["ekinox_gnss.mat"] in ("mirror", "raw")
    absent = [n for n in ("ekinox_imu.mat", "mpu6000_imu.mat") if origins[n] == "missing"]
    lines = [line for line in capsys.readouterr().out.splitlines() if any(n in line for n in absent)]
    assert caplog.records == [] and len(lines) == (1 if absent else 0), lines
    assert all(n in lines[0] and "stand in" in lines[0] for n in absent)


def test_cli_exit_status(tmp_path, mirror, capsys):
    assert cli_main(["fetch", "--data-dir", str(tmp_path / "a"), "--mirror", str(mirror), "--no-download"]) == 0
    out = capsys.readouterr().out
    assert "ref.mat" in out and "mirror" in out
    assert cli_main(["fetch", "--data-dir", str(tmp_path / "a"), "--mirror", str(tmp_path), "--no-download"]) == 0
    assert "raw" in capsys.readouterr().out  # second run: already verified in data/raw
    assert cli_main(["fetch", "--data-dir", str(tmp_path / "b"), "--mirror", str(tmp_path / "none"),
                     "--no-download"]) == 1
    assert "REQUIRED, missing" in capsys.readouterr().out


def test_a_failed_optional_download_is_marked_once_and_skipped_until_a_retry(tmp_path, monkeypatch, capsys):
    """No network (the download is faked): one failure per optional file, then one line per run and no attempt."""
    tried = []

    def offline(url, timeout_s):
        tried.append(url.rsplit("/", 1)[-1])
        raise ConnectionError(f"download of {url} failed: network disabled in tests")

    monkeypatch.setattr(acquire, "_download", offline)
    data, empty = tmp_path / "data", tmp_path / "empty"
    first = {r.name: r for r in acquire.fetch_all(data_dir=data, mirror=empty, rtklib_mirror=empty)}
    optional = [n for n, f in acquire.raw_files().items() if not f.required]
    required = [n for n, f in acquire.raw_files().items() if f.required]
    assert sorted(tried) == sorted(acquire.raw_files())                    # every file tried once
    today = datetime.datetime.now(datetime.timezone.utc).date().isoformat()
    for name in optional:
        assert first[name].path is None and acquire.failed_on(name, data) == today
        assert "network disabled" in acquire.failed_mark(name, data).read_text()
    assert not any(acquire.failed_mark(n, data).exists() for n in required)   # a needed file is tried each run

    tried.clear()
    assert cli_main(["fetch", "--data-dir", str(data), "--mirror", str(empty), "--rtklib-mirror", str(empty)]) == 1
    assert sorted(tried) == sorted(required)                                # the optional ones: not again
    lines = [line for line in capsys.readouterr().out.splitlines() if line.startswith("optional, absent")]
    assert len(lines) == 1 and all(n in lines[0] for n in optional)
    assert f"failed on {today} and is skipped since (to retry: python -m bgfn.data fetch --retry)" in lines[0]
    again = acquire.resolve(optional[0], data_dir=data, mirror=empty)
    assert again.origin == "missing" and f"download skipped: it failed on {today}" in again.detail

    # --retry tries again; a download that then succeeds (a file of this test's own, pinned) clears its mark
    spec = acquire.RawFile("extra.mat", None, acquire.git_blob_id(b"abc"), False)
    monkeypatch.setitem(acquire.NAVEGO_FILES, "extra.mat", spec)
    assert acquire.resolve("extra.mat", data_dir=data, mirror=empty).origin == "missing"
    assert acquire.failed_mark("extra.mat", data).is_file()
    monkeypatch.setattr(acquire, "_download", lambda url, timeout_s: b"abc")
    assert acquire.resolve("extra.mat", data_dir=data, mirror=empty).origin == "missing"          # skipped
    res = acquire.resolve("extra.mat", data_dir=data, mirror=empty, retry=True)
    assert res.origin == "download" and res.path.read_bytes() == b"abc"
    assert not acquire.failed_mark("extra.mat", data).exists()

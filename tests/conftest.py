"""Fixtures shared by the tests: data folders, the NaveGo mirror, a private copy of the shipped profiles."""

import shutil
import subprocess

import pytest

from bgfn.data import acquire

#: The two public NaveGo files every simulated dataset needs.
REQUIRED = ("ref.mat", "ekinox_gnss.mat")


@pytest.fixture
def repo_untouched(tmp_path, monkeypatch):
    """Default data/ and results/ locations point to sentinels that must stay absent.

    (The repository's own data/ and results/ are shared with concurrent runs, so they are not diffed.)
    """
    from bgfn import config

    monkeypatch.setenv("BGFN_DATA_DIR", str(tmp_path / "default-data"))
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path / "default-results")
    yield
    assert not (tmp_path / "default-data").exists(), "a test wrote to the default data folder"
    assert not (tmp_path / "default-results").exists(), "a test wrote to the default results folder"


@pytest.fixture(scope="module")
def mirror():
    """A folder holding verified copies of the two public files (data/raw or the shared mirror), else skip."""
    for folder in (acquire.raw_dir(), acquire.mirror_dir()):
        if folder is not None and all((folder / f).is_file() for f in REQUIRED):
            return folder
    pytest.skip("NaveGo mirror not available (set BGFN_DATA_MIRROR)")


@pytest.fixture()
def params(tmp_path, monkeypatch):
    """A private ``params/`` folder holding copies of the shipped profiles (``smoke`` derives from ``quick``, so a
    test's own profile can say ``base: smoke``), and ``bgfn.config`` reading from it."""
    from bgfn import config

    folder = tmp_path / "params"
    folder.mkdir()
    for path in config.PARAMS_DIR.glob("*.yaml"):
        shutil.copy(path, folder / path.name)
    monkeypatch.setattr(config, "PARAMS_DIR", folder)
    return folder


def shipped_profiles() -> list[str]:
    """The profiles of ``params/`` that git tracks: a user's own, unfinished profile beside them (untracked) is not
    the tests' to check (``python -m bgfn.profile_schema <name>`` checks it). Outside a git checkout: every one."""
    from bgfn import config

    res = subprocess.run(["git", "ls-files", "--", "*.yaml"], cwd=config.PARAMS_DIR, capture_output=True, text=True)
    tracked = {line.rsplit("/", 1)[-1][:-len(".yaml")] for line in res.stdout.splitlines()}
    return [p for p in config.available_profiles() if res.returncode != 0 or p in tracked]

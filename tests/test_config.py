"""Profiles and results layout (bgfn.config)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest
import yaml

from bgfn import config, settings
from bgfn.errors import DataError
from bgfn.profile_schema import load_profile


def _section_keys(cfg: dict) -> dict[str, set[str]]:
    return {key: set(cfg[key]) for key in config.SECTION_KEYS}


def test_project_root_holds_the_artifact():
    root = config.PROJECT_ROOT
    assert (root / "pyproject.toml").is_file()
    assert (root / "params").is_dir()
    assert (root / "src" / "bgfn" / "config.py").is_file()


def test_project_root_is_independent_of_cwd(tmp_path):
    # A fresh interpreter started elsewhere finds the same root.
    env = {k: v for k, v in os.environ.items() if k != "BGFN_ROOT"}
    out = subprocess.run([sys.executable, "-c", "from bgfn.config import PROJECT_ROOT; print(PROJECT_ROOT)"],
                         cwd=tmp_path, capture_output=True, text=True, check=True, env=env)
    assert Path(out.stdout.strip()) == config.PROJECT_ROOT


@pytest.mark.parametrize("profile", config.PROFILES)
def test_shipped_profiles_load(profile):
    cfg = load_profile(profile)
    assert cfg["profile"] == profile
    assert isinstance(cfg["seed"], int)
    assert cfg["description"].strip()
    for key in config.SECTION_KEYS:
        assert isinstance(cfg[key], dict)


def test_profiles_define_the_same_keys():
    cfgs = {p: load_profile(p) for p in config.PROFILES}
    top = {p: set(c) for p, c in cfgs.items()}
    assert len({frozenset(k) for k in top.values()}) == 1, f"top-level keys differ: {top}"
    # A notebook reads the same keys whatever the profile: sections must agree one level down, too.
    sections = {p: _section_keys(c) for p, c in cfgs.items()}
    ref_name, ref = next(iter(sections.items()))
    for name, keys in sections.items():
        for section in config.SECTION_KEYS:
            assert keys[section] == ref[section], (
                f"section '{section}': params/{name}.yaml has {sorted(keys[section])}, "
                f"params/{ref_name}.yaml has {sorted(ref[section])}")


def test_unknown_profile_names_the_file():
    with pytest.raises(DataError) as err:
        load_profile("no_such_profile")
    msg = str(err.value)
    assert str(config.PARAMS_DIR / "no_such_profile.yaml") in msg
    assert "unknown profile" in msg
    assert "quick" in msg  # lists what is available
    assert isinstance(err.value, ValueError)


@pytest.mark.parametrize("bad", ["../quick", "", "a/b", ".hidden", "-rf", "quick\n", "a;b"])
def test_profile_names_cannot_escape_params(bad):
    with pytest.raises(DataError):
        load_profile(bad)
    with pytest.raises(DataError):
        config.results_dir(bad, create=False)


def _write_profile(tmp_path, monkeypatch, name, cfg):
    monkeypatch.setattr(config, "PARAMS_DIR", tmp_path)
    path = tmp_path / f"{name}.yaml"
    path.write_text(yaml.safe_dump(cfg) if not isinstance(cfg, str) else cfg)
    return path


def _complete(name):
    return {"profile": name, "description": "d", "seed": 1, "outage_windows": [[100.0, 30.0]],
            "data": None, "nav": {}, "train": {"window": 2}, "evaluate": {}, "energy": {}}


def test_missing_required_key_names_file_and_key(tmp_path, monkeypatch):
    cfg = _complete("mine")
    del cfg["outage_windows"]
    path = _write_profile(tmp_path, monkeypatch, "mine", cfg)
    with pytest.raises(DataError) as err:
        load_profile("mine")
    assert err.value.source == str(path)
    assert err.value.field == "outage_windows"


def test_an_empty_or_left_out_section_reads_as_its_defaults(tmp_path, monkeypatch):
    cfg = _complete("mine")
    del cfg["energy"]
    _write_profile(tmp_path, monkeypatch, "mine", cfg)
    cfg = load_profile("mine")
    assert cfg["data"] == settings.defaults("data") and cfg["energy"] == settings.defaults("energy")
    assert cfg["train"] == {**settings.defaults("train"), "window": 2}
    cfg["train"]["window"] = 99  # a caller's edit must not leak into the next load
    assert load_profile("mine")["train"]["window"] == 2


@pytest.mark.parametrize("field,value", [("seed", "7"), ("seed", -1), ("seed", True), ("nav", [1, 2]),
                                         ("profile", "other"), ("description", 3), ("outage_windows", []),
                                         ("outage_windows", [[100.0]]), ("outage_windows", [[100.0, 0.0]]),
                                         ("outage_windows", [["a", 30.0]]), ("outage_windows", None)])
def test_bad_values_are_rejected(tmp_path, monkeypatch, field, value):
    cfg = _complete("mine")
    cfg[field] = value
    _write_profile(tmp_path, monkeypatch, "mine", cfg)
    with pytest.raises(DataError) as err:
        load_profile("mine")
    assert err.value.field.split("[")[0] == field


@pytest.mark.parametrize("section,key,value", [("nav", "outage_starts", [1.0]), ("nav", "outage_duration_s", 20.0),
                                               ("train", "outage_windows", [[1.0, 2.0]]),
                                               ("evaluate", "outage_windows", [[1.0, 2.0]])])
def test_a_moved_outage_key_names_the_new_one(tmp_path, monkeypatch, section, key, value):
    # the outages have one home (the top-level outage_windows); the keys of earlier versions fail by name,
    # also in a variant's own file, so that no notebook silently evaluates other outages than another
    _write_profile(tmp_path, monkeypatch, "mine", _complete("mine"))
    path = _write_profile(tmp_path, monkeypatch, "variant", {"profile": "variant", "base": "mine",
                                                             "description": "v", section: {key: value}})
    with pytest.raises(DataError, match="top-level key 'outage_windows'") as err:
        load_profile("variant")
    assert err.value.source == str(path) and err.value.field == f"{section}.{key}"


def test_invalid_yaml_names_the_file(tmp_path, monkeypatch):
    path = _write_profile(tmp_path, monkeypatch, "mine", "profile: [unclosed\n")
    with pytest.raises(DataError) as err:
        load_profile("mine")
    assert str(path) in str(err.value)


def test_results_dir_layout(tmp_path, monkeypatch):
    monkeypatch.setattr(config, "RESULTS_ROOT", tmp_path / "results")
    assert not config.results_dir("quick", create=False).exists()
    out = config.results_dir("quick")
    assert out == tmp_path / "results" / "quick"
    assert sorted(p.name for p in out.iterdir()) == ["figures", "models", "notebooks", "tables"]
    (out / "tables" / "keep.csv").write_text("a\n1\n")
    assert config.results_dir("quick") == out  # idempotent, keeps content
    assert (out / "tables" / "keep.csv").read_text() == "a\n1\n"


def test_results_dir_default_is_under_project_root():
    assert config.results_dir("smoke", create=False) == config.PROJECT_ROOT / "results" / "smoke"


def test_run_metadata_is_deterministic_and_complete():
    a = config.run_metadata("smoke")
    b = config.run_metadata("smoke")
    assert a == b
    assert a["profile"] == "smoke"
    assert a["seed"] == load_profile("smoke")["seed"]
    assert a["params_file"] == "params/smoke.yaml"
    assert len(a["params_sha256"]) == 64
    assert a["packages"]["numpy"] is not None
    assert a["git_commit"] is None or len(a["git_commit"]) == 40
    flat = repr(a).lower()
    assert "time" not in flat and "date" not in flat  # no timestamps: identical tables on rerun
    lines = config.metadata_header("smoke")
    assert "# profile: smoke" in lines


def test_a_variant_profile_holds_only_its_changes(tmp_path, monkeypatch):
    base = _complete("mine")
    base["train"] = {"window": 2, "lr": {"bgfn": 1e-3, "mlp": 1e-3}, "extra_channels": ["v_n"]}
    base["data"] = {"seed": 5}
    _write_profile(tmp_path, monkeypatch, "mine", base)
    _write_profile(tmp_path, monkeypatch, "variant", {"profile": "variant", "base": "mine", "description": "v",
                                                      "data": None, "train": {"lr": {"mlp": 3e-3},
                                                                              "extra_channels": []}})
    cfg = load_profile("variant")
    assert cfg["profile"] == "variant" and cfg["description"] == "v" and cfg["seed"] == 1 and "base" not in cfg
    # mappings merge key by key, lists and scalars replace, an empty section changes nothing
    lr = {**settings.defaults("train")["lr"], "bgfn": 1e-3, "mlp": 3e-3}     # over the defaults, as over a base
    assert cfg["train"] == {**settings.defaults("train"), "window": 2, "lr": lr, "extra_channels": []}
    assert cfg["data"] == {**settings.defaults("data"), "seed": 5}
    assert load_profile("mine")["train"]["lr"]["mlp"] == 1e-3            # the base is untouched
    assert [p.name for p in config.profile_chain("variant")] == ["variant.yaml", "mine.yaml"]


def test_a_variant_never_inherits_its_description_and_needs_a_real_base(tmp_path, monkeypatch):
    _write_profile(tmp_path, monkeypatch, "mine", _complete("mine"))
    # a derived profile without a description says what it is (the base's own text would describe the base)
    _write_profile(tmp_path, monkeypatch, "nodesc", {"profile": "nodesc", "base": "mine"})
    assert load_profile("nodesc")["description"] == "profile 'nodesc': 'mine' with its own settings"
    # a profile without a base must describe itself
    path = _write_profile(tmp_path, monkeypatch, "bare", {k: v for k, v in _complete("bare").items()
                                                            if k != "description"})
    with pytest.raises(DataError) as err:
        load_profile("bare")
    assert err.value.source == str(path) and err.value.field == "description"
    _write_profile(tmp_path, monkeypatch, "orphan", {"profile": "orphan", "base": "nosuch", "description": "o"})
    with pytest.raises(DataError, match="nosuch") as err:
        load_profile("orphan")
    assert err.value.field == "base"
    _write_profile(tmp_path, monkeypatch, "a", {"profile": "a", "base": "b", "description": "a"})
    _write_profile(tmp_path, monkeypatch, "b", {"profile": "b", "base": "a", "description": "b"})
    with pytest.raises(DataError, match="a -> b -> a"):
        load_profile("a")


def test_quick_heading_differs_from_quick_only_where_it_says():
    quick, variant = load_profile("quick"), load_profile("quick-heading")
    changed = {k for k in quick["train"] if quick["train"][k] != variant["train"][k]}
    assert changed == {"yaw_encoding", "target_frame", "extra_channels", "sizes"}
    for section in ("outage_windows", "data", "nav", "evaluate", "energy"):
        assert quick[section] == variant[section]
    for method, sizes in variant["train"]["sizes"].items():
        for size, kw in sizes.items():
            extra = {k: v for k, v in kw.items() if quick["train"]["sizes"][method][size].get(k) != v}
            assert extra == ({"encoder_neurons": 8} if method in ("bgfn", "transformer") else {})


def test_a_full_disk_names_the_file_that_could_not_be_written_relative_to_the_repository(tmp_path, monkeypatch):
    import errno

    from bgfn import io

    monkeypatch.chdir(tmp_path)
    target = tmp_path / "results" / "p" / "tables" / "t.csv"
    target.parent.mkdir(parents=True)
    target.write_text("old\n")

    def full(*_, **__):
        raise OSError(errno.ENOSPC, "No space left on device")

    with pytest.raises(OSError) as err, io.atomic_path(target) as tmp:
        tmp.write_text("half")
        full()
    assert err.value.errno == errno.ENOSPC and "results/p/tables/t.csv could not be written" in str(err.value)
    assert str(tmp_path) not in str(err.value)                   # no machine path
    assert target.read_text() == "old\n" and sorted(p.name for p in target.parent.iterdir()) == ["t.csv"]
    with pytest.raises(RuntimeError), io.atomic_path(target):    # anything else, on a disk with room: as it was
        raise RuntimeError("a bug")

"""A bad profile fails when it is loaded, before anything runs, naming the YAML file, the key and the value."""

from __future__ import annotations


import pytest

from bgfn import config
from bgfn.config import odometer_network_seeds
from bgfn.errors import DataError
from bgfn import settings
from bgfn.profile_schema import load_profile, with_overrides

pytestmark = pytest.mark.usefixtures("repo_untouched")

#: The variant cases train these methods (a variant_runs method must be one of them).
T = "train: {methods: [bgfn, mlp]}\n"
# variant text over the shipped smoke profile -> (key path named, words of the message)
BAD = {
    "top-level typo": ("trian: {window: 50}", "trian", "did you mean train?"),
    "train key typo": ("train: {windw: 200}", "train.windw", "did you mean train.window?"),
    "energy key typo": ("energy: {e_mac_p: 3.0}", "energy.e_mac_p", "did you mean energy.e_mac_pj?"),
    "data key typo": ("data: {t_strat: 138800.0}", "data.t_strat", "did you mean data.t_start?"),
    "optimizer key typo": ("train: {optimizer: {epoch: 3}}", "train.optimizer.epoch", "did you mean"),
    "window not a number": ("train: {window: abc}", "train.window", "'abc'"),
    "window longer than the data": ("train: {window: 1000000}", "train.window", "shorter than the data"),
    "negative outage": ("outage_windows: [[138906.0, -30.0]]", "outage_windows[0]", "-30"),
    "overlapping outages": ("outage_windows: [[138906.0, 30.0], [138920.0, 30.0]]", "outage_windows",
                            "do not overlap"),
    "outage outside the data": ("outage_windows: [[139250.0, 30.0]]", "outage_windows[0]", "inside the data"),
    "bad choice": ("nav: {bias_model: randomwalk}", "nav.bias_model", "'random_walk', 'gauss_markov'"),
    "fraction out of range": ("train: {val_fraction: 1.5}", "train.val_fraction", "1.5"),
    "more folds than starts": ("evaluate: {sweep: {n_starts: 2, folds: 3}}", "evaluate.sweep.folds", "at most"),
    "unknown method": ("train: {methods: [bgfn, lstm]}", "train.methods", "'lstm'"),
    "size block missing": ("train: {size: huge}", "train.size", "'huge'"),
    "energy dataset not trained": ("energy: {dataset: turin-sim-other}", "energy.dataset", "train.datasets"),
    "boolean as a number": ("seed: true", "seed", "True"),
    "noise scale word": ("nav: {noise_scale: fast}", "nav.noise_scale", "'auto'"),
    "noise scale zero": ("nav: {noise_scale: 0}", "nav.noise_scale", "positive number"),
    "alignment mode": ("nav: {alignment: {mode: compass}}", "nav.alignment.mode", "'reference', 'gnss', 'auto'"),
    "alignment key typo": ("nav: {alignment: {heading_s: 5.0}}", "nav.alignment.heading_s", "heading_time_s"),
    "noise search range": ("nav: {noise_search: {range: [10.0, 1.0]}}", "nav.noise_search.range", "low < high"),
    # per-drive keys, model sizes, bounds on counts and on the runs at a time, the scheduler's address
    "drive vector of 2": ("data: {turin-sim-mpu6000: {lever_arm_m: [0.1, 0.2]}}",
                          "data.turin-sim-mpu6000.lever_arm_m", "exactly 3 numbers"),
    "drive key typo": ("data: {turin-sim-mpu6000: {gnss_rate: 1.0}}", "data.turin-sim-mpu6000.gnss_rate",
                       "did you mean data.turin-sim-mpu6000.gnss_rate_hz?"),
    "drive key another drive takes": ("data: {turin-sim-ekinox: {lever_arm_m: [0.0, 0.0, 0.0]}}",
                                      "data.turin-sim-ekinox.lever_arm_m", "unknown key"),
    "IMU error key typo": ("data: {turin-sim-mpu6000: {imu_errors: {gyro_bias_instabilty: 0.1}}}",
                           "data.turin-sim-mpu6000.imu_errors.gyro_bias_instabilty", "unknown key"),
    "drive name typo": ("data: {turin-sim-mpu600: {seed: 1}}", "data.turin-sim-mpu600",
                        "did you mean data.turin-sim-mpu6000?"),
    "size key typo": ("train: {sizes: {bgfn: {smoke: {dimm: 16}}}}", "train.sizes.bgfn.smoke.dimm",
                      "did you mean train.sizes.bgfn.smoke.dim?"),
    "size of zero": ("train: {sizes: {mlp: {smoke: {hidden: 0}}}}", "train.sizes.mlp.smoke.hidden", "from 1 to"),
    "fold size key typo": ("evaluate: {sweep: {train: {sizes: {bgfn: {smoke: {deph: 1}}}}}}",
                           "evaluate.sweep.train.sizes.bgfn.smoke.deph", "did you mean"),
    "epochs without bound": ("train: {optimizer: {epochs: 1000000000000}}", "train.optimizer.epochs",
                             "<= 1,000,000"),
    "jobs without bound": ("parallel: {jobs: 100000}", "parallel.jobs", "<= 1,024"),
    "scheduler not an address": ("parallel: {backend: dask, scheduler: garbage}", "parallel.scheduler",
                                 "tcp://host:port"),
    # variants (their own train: overrides merged like a base profile) and variant_runs
    "misspelt key": (T + "variants: {mine: {train: {protocl: leaky}}}", "variants.mine.train.protocl",
                     "did you mean variants.mine.train.protocol?"),
    "bad value": (T + "variants: {mine: {train: {protocol: sloppy}}}", "variants.mine.train.protocol", "'sloppy'"),
    "not a train key": (T + "variants: {mine: {evaluate: {seeds: [0]}}}", "variants.mine.evaluate", "unknown key"),
    "merged profile breaks a cross-field fact": (T + "variants: {mine: {train: {size: huge}}}",
                                                 "variants.mine.train.size", "'huge'"),
    "the main networks' name": (T + "variants: {main: {train: {protocol: leaky}}}", "variants.main", "'main'"),
    "runs set inside a variant": (T + "variants: {mine: {train: {seeds: [1]}}}", "variants.mine.train.seeds",
                                  "variant_runs.seeds"),
    "runs of an unknown method": (T + "variant_runs: {methods: [mlp, lstm]}", "variant_runs.methods", "'lstm'"),
}


@pytest.mark.parametrize("case", list(BAD))
def test_a_bad_variant_names_its_file_the_key_and_the_value(params, case):
    text, key, words = BAD[case]
    path = params / "mine.yaml"
    path.write_text(f"profile: mine\nbase: smoke\ndescription: a variant\n{text}\n")
    with pytest.raises(DataError) as err:
        load_profile("mine")
    assert err.value.source == str(path), str(err.value)
    assert err.value.field == key and words in str(err.value), str(err.value)


def test_a_top_level_drive_list_covers_the_variants_and_the_odometers_too(params):
    # quick (smoke's base) names its own drives for the variants and the network odometers: one's own list wins
    (params / "mine.yaml").write_text("profile: mine\nbase: smoke\ndescription: v\ndatasets: [rtklib-drive0708]\n")
    cfg = load_profile("mine")
    assert cfg["variant_runs"]["datasets"] == ["rtklib-drive0708"] == cfg["evaluate"]["sweep"]["datasets"]
    assert cfg["evaluate"]["odometer"]["datasets"] == cfg["evaluate"]["odometer"]["network_datasets"] == [
        "rtklib-drive0708"]


def test_a_variant_list_naming_a_drive_not_trained_names_the_file_that_set_it(params):
    (params / "mine.yaml").write_text("profile: mine\nbase: smoke\ndescription: v\n"
                                      "train: {datasets: [turin-sim-mpu6000]}\n"
                                      "variant_runs: {datasets: [rtklib-drive0708]}\n")
    with pytest.raises(DataError) as err:
        load_profile("mine")
    assert err.value.source == str(params / "mine.yaml") and err.value.field == "variant_runs.datasets"
    assert "['turin-sim-mpu6000']" in str(err.value) and "variant_runs: {datasets: null}" in str(err.value)


def test_network_odometers_on_a_drive_without_odometer_bars_fail_by_name(params):
    (params / "mine.yaml").write_text("profile: mine\nbase: quick\ndescription: v\n"
                                      "evaluate: {odometer: {network_datasets: [rtklib-drive0780]}}\n")   # misspelt
    with pytest.raises(DataError) as err:
        load_profile("mine")
    assert err.value.source == str(params / "mine.yaml")
    assert err.value.field == "evaluate.odometer.network_datasets" and "rtklib-drive0780" in str(err.value)


def test_noise_scale_auto_and_alignment_options_are_accepted(params):
    (params / "mine.yaml").write_text("profile: mine\nbase: smoke\ndescription: v\n"
                                      "nav: {noise_scale: auto, alignment: {mode: gnss, heading_time_s: 5.0}}\n")
    nav = load_profile("mine")["nav"]
    assert nav["noise_scale"] == "auto" and nav["alignment"]["mode"] == "gnss"
    assert nav["alignment"]["speed_threshold_mps"] == load_profile("smoke")["nav"]["alignment"][
        "speed_threshold_mps"]                                   # sections merge key by key


def test_an_error_in_the_base_names_the_base_file(params):
    quick = params / "quick.yaml"                                 # mine -> smoke -> quick, which sets batch_size
    quick.write_text(quick.read_text().replace("batch_size: 32", "batch_size: 0"))
    (params / "mine.yaml").write_text("profile: mine\nbase: smoke\ndescription: v\ntrain: {window: 40}\n")
    with pytest.raises(DataError) as err:
        load_profile("mine")
    assert err.value.source == str(quick) and err.value.field == "train.optimizer.batch_size"
    assert "a number >= 1" in str(err.value)


def test_every_shipped_profile_loads_and_the_modules_defaults_are_the_settings():
    # one home for every default: the modules' tables of defaults are the settings' own, not copies that may drift
    from bgfn.evaluate import EVALUATE_DEFAULTS
    from bgfn.learning import LEARNING_DEFAULTS
    from bgfn.nav import constraints as cn
    from bgfn.nav.baseline import NAV_DEFAULTS
    from bgfn.nav.outage_rules import RULE_DEFAULTS
    from bgfn.parallel import PARALLEL_DEFAULTS
    from bgfn.train import LR_SEARCH_DEFAULTS, OPTIMIZER_DEFAULTS, VARIANT_RUN_DEFAULTS

    from conftest import shipped_profiles

    for name in shipped_profiles():     # a user's own untracked profile, unfinished, is not the suite's to fail on
        load_profile(name)
    d = settings.defaults()
    assert NAV_DEFAULTS == d["nav"] and EVALUATE_DEFAULTS == d["evaluate"] and PARALLEL_DEFAULTS == d["parallel"]
    assert LEARNING_DEFAULTS == {k: d["train"][k] for k in LEARNING_DEFAULTS}
    assert OPTIMIZER_DEFAULTS == d["train"]["optimizer"] and LR_SEARCH_DEFAULTS == d["train"]["lr_search"]
    assert VARIANT_RUN_DEFAULTS == d["variant_runs"]
    assert RULE_DEFAULTS["cruise_and_manoeuvre"] == settings.defaults_of(settings.OutageRule)
    assert cn.NHC_DEFAULTS == d["nav"]["nhc"] and cn.ZUPT_DEFAULTS == d["nav"]["zupt"]


def test_the_settings_choices_are_the_modules_choices():
    from typing import get_args

    from bgfn.learning.odometry import ODOMETER_INPUTS
    from bgfn.nav import constraints as cn, navego_setup
    from bgfn.paper import METHOD_LABELS
    from bgfn.parallel import BACKENDS

    def choices(model, key):
        return set(get_args(model.model_fields[key].annotation))

    assert choices(settings.Nhc, "mounting") == set(cn.MOUNTINGS)
    assert choices(settings.Nhc, "mounting_weight") == set(cn.MOUNTING_WEIGHTS)
    assert set(get_args(settings.OdometerInput)) == set(ODOMETER_INPUTS)
    assert choices(settings.Nav, "ins_tuning") == set(navego_setup.INS_TUNINGS)
    assert choices(settings.Parallel, "backend") == set(BACKENDS)
    assert set(get_args(settings.Method)) == set(METHOD_LABELS) == set(settings.METHODS)


def test_a_misspelt_key_in_the_profile_file_gets_did_you_mean(params):
    (params / "mine.yaml").write_text("profile: mine\nbase: quick\ndescription: v\n"
                                      "evaluate: {odometer: {corelation: false}}\n")
    with pytest.raises(DataError) as err:
        load_profile("mine")
    assert err.value.source == str(params / "mine.yaml") and err.value.field == "evaluate.odometer.corelation"
    assert "did you mean evaluate.odometer.correlation?" in str(err.value)


def test_a_wrong_type_names_the_dotted_key_the_file_and_what_was_expected(params):
    (params / "mine.yaml").write_text("profile: mine\nbase: quick\ndescription: v\n"
                                      "nav: {zupt: {window_s: two}}\nenergy: {batch_size: 1.5}\n")
    with pytest.raises(DataError) as err:
        load_profile("mine")
    assert err.value.source == str(params / "mine.yaml") and err.value.field == "nav.zupt.window_s"
    assert "a number" in str(err.value) and "'two'" in str(err.value)
    (params / "mine.yaml").write_text("profile: mine\nbase: quick\ndescription: v\nenergy: {batch_size: 1.5}\n")
    with pytest.raises(DataError, match="energy.batch_size.*an integer.*1.5"):
        load_profile("mine")


def test_a_fold_networks_train_section_is_checked_as_a_train_section(params):
    (params / "mine.yaml").write_text("profile: mine\nbase: quick\ndescription: v\n"
                                      "evaluate: {sweep: {train: {optimizer: {epoch: 3}}}}\n")
    with pytest.raises(DataError) as err:
        load_profile("mine")
    assert err.value.field == "evaluate.sweep.train.optimizer.epoch" and "did you mean" in str(err.value)


def test_a_profile_without_a_base_gets_the_defaults_quick_no_longer_lists(params):
    # quick lists only what differs; a key it leaves out has its old value as the default
    (params / "bare.yaml").write_text("profile: bare\ndescription: v\nseed: 1\noutage_windows: [[138906.0, 30.0]]\n")
    bare, quick = load_profile("bare"), load_profile("quick")
    for section in ("nav", "energy", "parallel"):
        assert bare[section] == quick[section], section
    assert bare["evaluate"]["odometer"]["correlation"] is True and bare["evaluate"]["sweep"]["datasets"] == [
        "rtklib-drive0708"]
    assert bare["train"]["optimizer"]["epochs"] == 1000 != quick["train"]["optimizer"]["epochs"]   # quick's reduction
    assert bare["data"]["seed"] is None and bare["data"]["imu_rate_hz"] == quick["data"]["imu_rate_hz"] == 100.0


def test_quick_lists_only_what_differs_from_the_defaults():
    import yaml

    text = (config.PARAMS_DIR / "quick.yaml").read_text()
    assert len(text.splitlines()) <= 80
    d = settings.defaults()

    def same(own, base, where):
        for key, value in own.items():
            if isinstance(value, dict) and isinstance(base.get(key), dict):
                same(value, base[key], f"{where}{key}.")
            else:
                assert base.get(key, object()) != value, f"{where}{key} repeats its default"

    same({k: v for k, v in yaml.safe_load(text).items() if k in d}, d, "")


def test_notebook_parameters_are_checked_like_the_profile():
    cfg = load_profile("smoke")
    out = with_overrides(cfg, {"train.methods": ["mlp"], "train.seeds": None, "evaluate.sweep.datasets": []})
    assert out["train"]["methods"] == ["mlp"] and out["train"]["seeds"] == cfg["train"]["seeds"]
    assert out["evaluate"]["sweep"]["datasets"] == [] and cfg["train"]["methods"] != ["mlp"]   # a copy
    with pytest.raises(DataError) as err:
        with_overrides(cfg, {"train.methods": ["lstm"]})
    assert err.value.source == "notebook parameters" and err.value.field == "train.methods"
    with pytest.raises(DataError, match="evaluate.real_imu"):
        with_overrides(cfg, {"evaluate.real_imu": "yes"})


def test_odometer_network_seeds_per_drive_need_a_default(params):
    (params / "mine.yaml").write_text("profile: mine\nbase: smoke\ndescription: v\n"
                                      "evaluate: {odometer: {network_seeds: {rtklib-drive0708: [0, 1]}}}\n")
    with pytest.raises(DataError) as err:
        load_profile("mine")
    assert err.value.field == "evaluate.odometer.network_seeds" and "'default'" in str(err.value)
    # per drive: the drive's own list, else the default's; a list holds for every drive
    oc = {"network_seeds": {"default": [0], "rtklib-drive0708": [0, 1, 2]}}
    assert odometer_network_seeds(oc, "rtklib-drive0708") == [0, 1, 2]
    assert odometer_network_seeds(oc, "turin-sim-ekinox") == [0]
    assert odometer_network_seeds({"network_seeds": [3, 4]}, "any drive") == [3, 4]


@pytest.mark.parametrize("jobs", ["abc", "0", "-1", "2.5"])
def test_a_bad_jobs_value_fails_the_first_check_naming_the_variable(jobs, monkeypatch):
    from bgfn.profile_schema import check_keys

    monkeypatch.setenv("BGFN_JOBS", jobs)
    with pytest.raises(DataError, match=f"BGFN_JOBS.*positive integer.*{jobs!r}"):
        check_keys("smoke")


def test_more_jobs_than_the_machine_takes_are_capped_and_said(monkeypatch):
    from bgfn import parallel
    from bgfn.profile_schema import check_keys

    monkeypatch.setattr(parallel, "machine_cores", lambda: 2)
    monkeypatch.setenv("BGFN_JOBS", "64")
    runner = parallel.Runner.of(load_profile("smoke"))
    assert runner.jobs == 8 == parallel.JOBS_PER_CORE * 2 and runner.asked == 64
    assert "8 processes" in check_keys("smoke")[0] and "64 asked" in check_keys("smoke")[0]
    monkeypatch.setenv("BGFN_JOBS", "3")
    assert parallel.Runner.of(load_profile("smoke")).asked is None


@pytest.mark.parametrize("address, ok", [("garbage", False), ("tcp://", False), ("http://h:8786", False),
                                         ("tcp://10.0.0.5:8786", True), ("sched.local:8786", True)])
def test_the_dask_scheduler_variable_must_be_an_address(address, ok, monkeypatch):
    from bgfn.profile_schema import check_keys

    monkeypatch.setenv("DASK_SCHEDULER", address)
    if ok:
        assert address in check_keys("smoke")[0]
    else:
        with pytest.raises(DataError, match="DASK_SCHEDULER.*tcp://host:port"):
            check_keys("smoke")


def test_a_binary_or_huge_profile_is_one_error_naming_the_file(params):
    path = params / "mine.yaml"
    path.write_bytes(b"profile: mine\nbase: smoke\n\xff\xfe\x00\x01 binary")
    with pytest.raises(DataError) as err:
        load_profile("mine")
    assert err.value.source == str(path) and "UTF-8" in str(err.value) and "0xff" in str(err.value)
    path.write_text("profile: mine\nbase: smoke\n" + "# padding\n" * 200_000)
    with pytest.raises(DataError, match=r"at most 1,000,000 bytes, found 2,000,0\d\d bytes") as err:
        load_profile("mine")
    assert err.value.source == str(path)


def _alias_bomb(levels: int = 9) -> str:
    """YAML of a few hundred bytes whose aliases nest: 10 ** ``levels`` strings once expanded ("billion laughs")."""
    lines = ['l0: &l0 ["lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol", "lol"]']
    lines += [f"l{k}: &l{k} [" + ", ".join([f"*l{k - 1}"] * 10) + "]" for k in range(1, levels + 1)]
    return "\n".join(lines) + "\n"


def test_an_alias_bomb_is_one_early_error_naming_the_file(params, tmp_path):
    from bgfn.data.csv_meta import read_meta

    path = params / "mine.yaml"
    path.write_text("profile: mine\nbase: smoke\n" + _alias_bomb())
    assert path.stat().st_size < 1_000
    # l0 holds 1 + 10 values, l_k 1 + 10 l_(k-1): 11, 111, ..., 11,111,111,111, summed 12,345,679,010; with the
    # mapping, its 12 keys and the two names: 12,345,679,025
    with pytest.raises(DataError, match=r"at most 100,000 values once its aliases .* found 12,345,679,025 values"
                       ) as err:
        load_profile("mine")                         # refused from the parsed nodes, before any value is built
    assert err.value.source == str(path) and err.value.field == "<yaml>"
    path.write_text("profile: mine\nbase: smoke\ndescription: &d [1, *d]\n")
    with pytest.raises(DataError, match="contains itself through an alias"):
        load_profile("mine")
    path.write_text("profile: mine\nbase: smoke\ndescription: " + "[" * 100_000)       # 100 kB of nesting
    with pytest.raises(DataError, match="a nesting too deep to parse"):
        load_profile("mine")
    # a log's meta.yaml, the other settings file a user writes, likewise
    meta = tmp_path / "log" / "meta.yaml"
    meta.parent.mkdir()
    meta.write_text(_alias_bomb())
    with pytest.raises(DataError, match="once its aliases"):
        read_meta(meta)
    # anchors and merge keys of a real size still read (params/quick.yaml's variants use them)
    path.write_text("profile: mine\nbase: smoke\ndescription: &d a walk\nseed: 3\n")
    assert load_profile("mine")["seed"] == 3


def test_an_unfinished_profile_of_ones_own_does_not_fail_the_suite(params, monkeypatch):
    import subprocess

    from conftest import shipped_profiles

    subprocess.run(["git", "init", "-q"], cwd=params.parent, check=True)
    subprocess.run(["git", "add", "smoke.yaml", "quick.yaml"], cwd=params, check=True)
    (params / "mine.yaml").write_text("base: smoke\ntrain: {windw: 3}\n")     # untracked, half-written
    assert "mine" not in shipped_profiles() and {"smoke", "quick"} <= set(shipped_profiles())


def test_the_key_check_of_the_command_line_prints_its_lines_and_passes(capsys):
    # what `make reproduce` runs first: no data, no run plan
    from bgfn.profile_schema import main
    assert main(["smoke", "--keys"]) == 0
    assert "profile smoke: every key checked; independent runs" in capsys.readouterr().out

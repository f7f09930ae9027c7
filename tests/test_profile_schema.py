"""A bad profile fails when it is loaded, before anything runs, naming the YAML file, the key and the value."""

from __future__ import annotations


import pytest

from bgfn import config
from bgfn.config import odometer_network_seeds
from bgfn.errors import DataError
from bgfn.profile_schema import SCHEMA, load_profile, with_overrides

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
    quick = params / "quick.yaml"                                 # mine -> smoke -> quick, which sets margin_s
    quick.write_text(quick.read_text().replace("  margin_s: 30.0", "  margin_s: -1.0"))
    (params / "mine.yaml").write_text("profile: mine\nbase: smoke\ndescription: v\ntrain: {window: 40}\n")
    with pytest.raises(DataError) as err:
        load_profile("mine")
    assert err.value.source == str(quick) and err.value.field == "train.margin_s"


def test_every_shipped_profile_uses_only_schema_keys():
    # and the schema knows every key the code reads defaults for (no drift between schema and defaults)
    from bgfn.evaluate import EVALUATE_DEFAULTS
    from bgfn.learning import LEARNING_DEFAULTS
    from bgfn.nav.baseline import NAV_DEFAULTS
    from bgfn.train import LR_SEARCH_DEFAULTS, OPTIMIZER_DEFAULTS

    for name in config.available_profiles():
        load_profile(name)
    f = SCHEMA.fields
    assert set(NAV_DEFAULTS) <= set(f["nav"].fields)
    assert set(EVALUATE_DEFAULTS) <= set(f["evaluate"].fields)
    assert set(EVALUATE_DEFAULTS["sweep"]) <= set(f["evaluate"].fields["sweep"].fields)
    assert set(LEARNING_DEFAULTS) <= set(f["train"].fields)
    assert set(OPTIMIZER_DEFAULTS) == set(f["train"].fields["optimizer"].fields)
    assert set(LR_SEARCH_DEFAULTS) == set(f["train"].fields["lr_search"].fields)


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
    # quick: three seeds on the real drive, one on every other; a list holds for every drive
    oc = load_profile("quick")["evaluate"]["odometer"]
    assert odometer_network_seeds(oc, "rtklib-drive0708") == [0, 1, 2]
    assert odometer_network_seeds(oc, "turin-sim-ekinox") == [0]
    assert odometer_network_seeds({"network_seeds": [3, 4]}, "any drive") == [3, 4]

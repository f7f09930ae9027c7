"""Profiles (``params/<profile>.yaml``) and the paths every notebook writes to.

A *profile* fixes the size of a run: ``smoke`` (CI, a minute), ``quick`` (default, minutes on a laptop), ``paper``
(the paper's settings). Every notebook starts with a ``parameters`` cell (``profile = "quick"``) that papermill
overrides, then ``cfg = load_profile(profile)`` (:mod:`bgfn.profile_schema`) and ``out = results_dir(profile)``
(``results/<profile>/``), and writes its tables, figures and records there through :mod:`bgfn.io`. This module finds
and merges profiles (:func:`read_profile`: the ``base:`` chain over the defaults of :mod:`bgfn.settings`) and knows
the paths: a core fact, it imports nothing of the package above it.
"""

from __future__ import annotations

import copy
import hashlib
import os
import re
import subprocess
import sys
from importlib import metadata
from pathlib import Path
from typing import Any

import yaml

from bgfn import settings, settings_check
from bgfn.errors import DataError


def _find_project_root() -> Path:
    """Repository root, independent of the current directory.

    ``BGFN_ROOT`` (environment) wins; else the checkout this file lives in (editable install:
    ``<root>/src/bgfn/config.py``); else the first parent of the current directory holding ``params/``.
    """
    env = os.environ.get("BGFN_ROOT")
    if env:
        return Path(env).expanduser().resolve()
    here = Path(__file__).resolve().parents[2]
    if (here / "params").is_dir() and (here / "src" / "bgfn").is_dir():
        return here
    cwd = Path.cwd().resolve()
    for candidate in (cwd, *cwd.parents):
        if (candidate / "params").is_dir() and (candidate / "pyproject.toml").is_file():
            return candidate
    return here


PROJECT_ROOT: Path = _find_project_root()
PARAMS_DIR: Path = PROJECT_ROOT / "params"
RESULTS_ROOT: Path = PROJECT_ROOT / "results"
DATA_DIR: Path = PROJECT_ROOT / "data"

#: Profiles shipped with the artifact (users may add their own ``params/<name>.yaml``).
PROFILES: tuple[str, ...] = ("smoke", "quick", "full", "paper")
#: Top-level keys a profile's chain must set (``outage_windows``: the evaluation outages, one list or per dataset a
#: list or a rule, read by :func:`bgfn.nav.outages.outage_windows`, shared by notebooks 01-04); every other key has
#: its default in :mod:`bgfn.settings`.
REQUIRED_KEYS: tuple[str, ...] = settings.REQUIRED
#: One section per notebook: 01 data, 02 nav (KF baseline), 03 train, 04 evaluate, 05 energy.
SECTION_KEYS: tuple[str, ...] = ("data", "nav", "train", "evaluate", "energy")
#: Files of ``results/<profile>/`` that one notebook writes and a later notebook or the results page reads: the
#: one place their names are spelled. Run records (``results/<profile>/<name>``):
RUN_RECORDS: dict[str, str] = {
    "kf_baseline": "kf_baseline.json",          # notebook 02
    "training": "training.json",                # notebook 03
    "evaluation": "outage_evaluation.json",     # notebook 04
    "energy": "energy.json",                    # notebook 05
    "sweep": "outage_sweep.json",               # notebook 06: the sweep's sizes and wall times
    "odometer": "outage_odometer.json",         # notebook 07: the learned odometer's wall times
    "ins_fidelity": "ins_fidelity.json",        # notebook 08: the INS row under NaveGo's setup
    "findings": "findings.md",                  # notebook 10: the lines the book's first page includes
}
#: ... and shared tables (``results/<profile>/tables/<name>``).
SHARED_TABLES: dict[str, str] = {
    "training_runs": "training_runs.csv",       # notebook 03
    "training_summary": "training_summary.csv",
    "training_times": "training_times.csv",     # wall clock, apart from the deterministic tables
    "training_variants": "training_variants.csv",   # the variants' networks (inputs, protocol)
    "training_all_windows": "training_all_windows.csv",   # runs that never learned, trained again on all windows
    "sweep": "outage_sweep.csv",                # notebook 06
    "sweep_summary": "outage_sweep_summary.csv",
    "sweep_pairs": "outage_sweep_pairs.csv",
    "kf_ins_tuning": "kf_ins_tuning.csv",       # notebook 08: the INS row under each filter setup
    "kf_ins_drift": "kf_ins_drift.csv",         # notebook 08: INS drift over the sweep's starts, drive by drive
    "kf_ins_drift_runs": "kf_ins_drift_runs.csv",
    "kf_nees_scan": "kf_nees_scan.csv",         # notebook 08: INS consistency vs the gyro bias instability
    "kf_imu_twin": "kf_imu_twin.csv",           # notebook 08: the recorded IMU against its trajectory twin
    "oracle": "outage_oracle.csv",              # notebook 06: the oracle rows (bgfn.studies.outage_sweep.oracle)
    "oracle_breakeven": "outage_oracle_breakeven.csv",
    "oracle_runs": "outage_oracle_runs.csv",
    "odometer": "outage_odometer.csv",          # notebook 07: the bars of a learned odometer (bgfn.studies.odometer.bars)
    "odometer_summary": "outage_odometer_summary.csv",
    "odometer_paper": "outage_odometer_paper.csv",  # ... and in each drive's two evaluation outages
    "odometer_networks": "outage_odometer_networks.csv",  # ... each network odometer: validation against outages
    "odometer_curve": "outage_odometer_curve.csv",  # ... the ridge's speed error against its training windows
    "odometer_uncertainty": "outage_odometer_uncertainty.csv",  # ... each network's predicted std against its error
    "odometer_errors": "outage_odometer_errors.csv",  # ... each odometer's error: offset per outage and fluctuation
    "nees": "outage_nees.csv",                  # notebook 06: the filter's consistency in outages (bgfn.studies.ins_fidelity.nees)
    "variants": "outage_variants.csv",          # notebook 06: the learning-problem variants in the two outages
    "energy_odometer": "energy_odometer.csv",   # notebook 07: the learned odometers' energy (bgfn.studies.odometer.energy)
}
#: Where a top-level ``datasets:`` puts its list (the datasets of every notebook, their variants and odometers),
#: unless the same file or a later one in the ``base:`` chain sets that section's own ``datasets``.
DATASET_KEYS: tuple[str, ...] = ("data.datasets", "nav.datasets", "train.datasets", "evaluate.datasets",
                                 "evaluate.sweep.datasets", "variant_runs.datasets", "evaluate.odometer.datasets",
                                 "evaluate.odometer.network_datasets")


def odometer_datasets(odometer: dict | None, sweep_datasets) -> list[str]:
    """The drives of the learned-odometer bars: ``evaluate.odometer.datasets``, null meaning the sweep's (one rule
    for notebook 04, which runs them, and notebook 05, which measures their networks)."""
    names = (odometer or {}).get("datasets")
    return list(sweep_datasets or []) if names is None else list(names)


#: The entry of a per-dataset setting that holds for every dataset it does not name (``outage_windows``,
#: ``nav.noise_scale``, ``evaluate.odometer.network_seeds``; per network: ``evaluate.odometer.inputs``).
DEFAULT_DATASET_KEY = settings.DEFAULT_DATASET_KEY


def odometer_network_seeds(odometer: dict | None, dataset: str) -> list[int]:
    """The seeds the odometer networks of ``dataset`` train with: ``evaluate.odometer.network_seeds``, one list for
    every drive or per drive with a ``default`` list for every drive not named (one rule for notebook 04, which
    trains them, and notebook 05, which measures the first)."""
    seeds = odometer["network_seeds"]
    if isinstance(seeds, dict):
        seeds = seeds.get(dataset, seeds.get(DEFAULT_DATASET_KEY))
    if not seeds:
        raise DataError("evaluate.odometer", "network_seeds", f"seeds for {dataset} (or a 'default' list)",
                        repr(odometer["network_seeds"]))
    return [int(s) for s in seeds]


def odometer_inputs(odometer: dict, method: str) -> str:
    """What the odometer network ``method`` reads: ``evaluate.odometer.inputs``, one choice for every network or per
    network with a ``default`` for those not named (``{default: band_frames, bgfn: imu}``)."""
    inputs = odometer["inputs"]
    return str(inputs.get(method, inputs.get(DEFAULT_DATASET_KEY)) if isinstance(inputs, dict) else inputs)


#: Keys of earlier versions that now live elsewhere: ``section.key`` -> the key to set instead.
MOVED_KEYS: dict[str, str] = {
    "nav.outage_starts": "outage_windows",
    "nav.outage_duration_s": "outage_windows",
    "train.outage_windows": "outage_windows",
    "evaluate.outage_windows": "outage_windows",
}
#: A profile's ``variants:``: named overrides of the profile (each checked as a whole profile). Their names, the
#: name of the profile's own networks among them, and the keys that ``variant_runs:`` alone sets.
VARIANT_NAME = r"^[A-Za-z0-9][A-Za-z0-9_-]*$"
MAIN_VARIANT = "main"
VARIANT_RUN_KEYS = ("datasets", "methods", "seeds")
#: Subfolders of ``results/<profile>/``.
RESULT_SUBDIRS: tuple[str, ...] = ("tables", "figures", "notebooks", "models")

_NAME_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9._-]*$")   # as the Makefile checks PROFILE

#: Distributions whose versions are recorded in :func:`run_metadata`.
_PACKAGES: tuple[str, ...] = (
    "bgfn", "numpy", "scipy", "pandas", "torch", "spikingjelly", "numba", "matplotlib", "python-ins",
)


def _check_name(profile: str) -> str:
    if not isinstance(profile, str) or not _NAME_RE.fullmatch(profile):   # fullmatch: no "name\n"
        raise DataError(PARAMS_DIR, "profile", "a profile name of letters, digits, '.', '_' or '-' "
                        f"(one of {', '.join(PROFILES)} or params/<name>.yaml)", repr(profile))
    return profile


def profile_path(profile: str) -> Path:
    """Path of ``params/<profile>.yaml`` (not checked for existence)."""
    return PARAMS_DIR / f"{_check_name(profile)}.yaml"


def available_profiles() -> list[str]:
    """Names of all ``params/*.yaml`` files, sorted."""
    return sorted(p.stem for p in PARAMS_DIR.glob("*.yaml"))


def merge_sections(base: dict, override: dict) -> dict:
    """``override`` laid over ``base``: mappings merge key by key (recursively); any other value, lists
    included, replaces the base's. Neither argument is modified (:func:`bgfn.settings_check.merge`)."""
    return settings_check.merge(base, override)


#: A profile file is a page of settings: one larger than this is refused before it is parsed (a YAML parser may take
#: minutes over a huge file).
MAX_PROFILE_BYTES = 1_000_000


#: The most values (keys, items, scalars) a settings file may hold once its aliases (``*name``) are expanded. The
#: parser shares an alias's value, but every later walk over the settings (the check, a merge, a JSON record) visits
#: it once per use, so a file of a few kB whose aliases nest ("billion laughs") would run it out of memory; a real
#: profile holds a few hundred values.
MAX_YAML_VALUES = 100_000


def _yaml_children(node: yaml.Node) -> list:
    if isinstance(node, yaml.SequenceNode):
        return list(node.value)
    if isinstance(node, yaml.MappingNode):
        return [n for pair in node.value for n in pair]
    return []


def _expanded_values(root: yaml.Node, path: Path) -> int:
    """How many values ``root`` holds with every alias expanded: counted over the parsed nodes (each once, so in
    time linear in the file); a value that contains itself through an alias is refused."""
    size: dict[int, int] = {}
    open_nodes: set[int] = set()
    stack = [(root, False)]
    while stack:
        node, closing = stack.pop()
        key = id(node)
        if closing:
            open_nodes.discard(key)
            size[key] = 1 + sum(size[id(c)] for c in _yaml_children(node))
            continue
        if key in size:
            continue
        if key in open_nodes:
            raise DataError(path, "<yaml>", "settings without a value that contains itself through an alias",
                            f"a recursive alias at line {node.start_mark.line + 1}")
        open_nodes.add(key)
        stack.append((node, True))
        stack.extend((c, False) for c in _yaml_children(node) if id(c) not in size)
    return size[id(root)]


def safe_yaml(text: str, path: str | Path, max_values: int = MAX_YAML_VALUES):
    """``text`` (the YAML of the settings file ``path``) parsed like :func:`yaml.safe_load`, after its size with every
    alias expanded is checked (:data:`MAX_YAML_VALUES`; one :class:`bgfn.errors.DataError` naming the file, before any
    value is built). Raises :class:`yaml.YAMLError` for text that is no YAML."""
    loader = yaml.SafeLoader(text)
    try:
        try:
            node = loader.get_single_node()
        except RecursionError:
            raise DataError(path, "<yaml>", "settings nested a few levels deep",
                            "a nesting too deep to parse") from None
        if node is None:
            return None
        values = _expanded_values(node, Path(path))
        if values > max_values:
            raise DataError(path, "<yaml>", f"at most {max_values:,} values once its aliases (*name) are expanded",
                            f"{values:,} values (aliases that nest: a file that would exhaust the memory)")
        return loader.construct_document(node)
    finally:
        loader.dispose()


def _read_profile_file(path: Path) -> dict:
    size = path.stat().st_size
    if size > MAX_PROFILE_BYTES:
        raise DataError(path, "<file>", f"a profile of at most {MAX_PROFILE_BYTES:,} bytes", f"{size:,} bytes")
    try:
        cfg = safe_yaml(path.read_bytes().decode("utf-8"), path)
    except UnicodeDecodeError as exc:
        raise DataError(path, "<file>", "a YAML text file in UTF-8", f"a byte {exc.object[exc.start]:#04x} that is "
                        f"not UTF-8 at offset {exc.start} (a binary file?)") from None
    except yaml.YAMLError as exc:
        raise DataError(path, "<yaml>", "valid YAML", str(exc).replace("\n", " ")) from exc
    if not isinstance(cfg, dict):
        raise DataError(path, "<top level>", "a mapping of keys", type(cfg).__name__)
    return cfg


def _read_chain(profile: str) -> list[tuple[Path, dict]]:
    """``(file, parsed YAML)`` of the profile, then of each profile in its ``base:`` chain."""
    chain: list[tuple[Path, dict]] = []
    name = profile
    while name is not None:
        path = profile_path(name)
        seen = [p for p, _ in chain]
        if not path.is_file():
            known = ", ".join(available_profiles()) or "none"
            raise DataError(seen[-1] if seen else path, "base" if seen else "profile",
                            f"an existing profile file (available: {known})", f"unknown profile {name!r}: no such file")
        if path in seen:
            raise DataError(seen[0], "base", "a chain of profiles that does not lead back to itself",
                            " -> ".join(p.stem for p in seen + [path]))
        own = _read_profile_file(path)
        chain.append((path, own))
        name = own.get("base")
        if name is not None and not isinstance(name, str):
            raise DataError(path, "base", "the name of another profile", repr(name))
    return chain


def own_settings(profile: str) -> dict:
    """What the profile's own file says (parsed, no base merged, no default filled): the keys its author typed."""
    return _read_chain(profile)[0][1]


def profile_chain(profile: str) -> list[Path]:
    """The profile's file followed by the files of its ``base:`` chain (``params/<base>.yaml``, ...)."""
    return [path for path, _ in _read_chain(profile)]


def read_profile(profile: str) -> dict[str, Any]:
    """Read ``params/<profile>.yaml``, merge its ``base:`` chain over the defaults and check every key
    (:func:`bgfn.settings_check.complete`); :func:`bgfn.profile_schema.load_profile` adds the facts that tie keys together:
    call it where a checked profile is needed.

    A profile may name another one as ``base:``; it then holds only what differs: its sections are laid
    over the base's key by key (:func:`merge_sections`), so ``params/quick-heading.yaml`` lists only the
    settings it changes in ``params/quick.yaml``. ``profile`` and ``description`` are always the file's own
    (``profile`` may be left out: it is the file's name; so may a derived profile's ``description``). A
    top-level ``datasets:`` list sets the datasets of every notebook (:data:`DATASET_KEYS`) over the base's; a
    section's own ``datasets`` in the same file wins. So a user's drive needs three lines (README, "Your own
    log")::

        base: quick
        datasets: [/home/me/logs/drive-0501]      # a CSV folder (data/README.md)
        outage_windows: [[243100.0, 30.0], [243400.0, 30.0]]

    Parameters
    ----------
    profile : str
        Profile name (``smoke``, ``quick``, ``paper`` or a user file ``params/<name>.yaml``).

    Returns
    -------
    dict
        The parsed YAML merged over its bases and the defaults: ``profile`` (str, equal to the file name),
        ``description`` (str), ``seed`` (int), ``outage_windows`` (a list of [start, duration], s, or a mapping
        dataset -> such a list or a rule, with ``default``) and every section with every key
        (:class:`bgfn.settings.Profile`). A fresh copy on every call.

    Raises
    ------
    bgfn.errors.DataError
        Unknown profile (missing file), unreadable YAML, a missing required top-level key, a key that moved
        (:data:`MOVED_KEYS`, the message names the new one), a ``base:`` that does not exist or leads back to the
        profile, a key unknown or of the wrong type (the closest valid key suggested). The message names the
        file that set the key.
    """
    chain = _read_chain(profile)
    path = chain[0][0]
    for file, own in chain:
        _check_moved_keys(file, own)
    cfg: dict = {}
    for i, (_, own) in enumerate(reversed(chain)):   # the furthest base first, the profile's own file last
        own = {k: v for k, v in own.items() if k != "base"}
        if i == len(chain) - 1:
            own.setdefault("profile", profile)     # the file's name unless it says otherwise
            if len(chain) > 1:                     # a derived profile may leave its description out
                own.setdefault("description", f"profile '{profile}': '{chain[0][1]['base']}' with its own settings")
        if cfg:   # the base's name and description are not inherited; a comments-only section changes nothing
            cfg = {k: v for k, v in cfg.items() if k not in ("profile", "description")}
            own = {k: v for k, v in own.items() if not (k in SECTION_KEYS and v is None)}
        cfg = merge_sections(cfg, _spread_datasets(own.get("datasets")))
        cfg = merge_sections(cfg, own)

    missing = [key for key in REQUIRED_KEYS if key not in cfg]
    if missing:
        raise DataError(path, missing[0], f"required top-level keys {', '.join(REQUIRED_KEYS)}",
                        f"missing {', '.join(missing)}")
    if cfg["profile"] != profile:
        raise DataError(path, "profile", f"the file's own name {profile!r}", repr(cfg["profile"]))
    try:
        return settings_check.complete(cfg)
    except settings_check.ProfileError as exc:
        raise DataError(file_setting(profile, exc.path), exc.path, exc.expected, exc.found) from None


def variant_config(cfg: dict, name: str) -> dict:
    """The profile ``cfg`` with variant ``name``'s overrides merged over it (:func:`merge_sections`, as a ``base:``
    chain merges), without the ``variants`` and ``variant_runs`` keys; not checked."""
    own = {k: v for k, v in cfg.items() if k not in ("variants", "variant_runs")}
    return merge_sections(own, (cfg.get("variants") or {})[name] or {})


def _spread_datasets(datasets) -> dict:
    """A top-level ``datasets:`` as the sections' keys of :data:`DATASET_KEYS` (``{}`` when not a non-empty list:
    the schema check then names the bad value)."""
    if not isinstance(datasets, list) or not datasets:
        return {}
    out: dict = {}
    for path in DATASET_KEYS:
        *parents, key = path.split(".")
        node = out
        for k in parents:
            node = node.setdefault(k, {})
        node[key] = list(datasets)
    return out


def set_keys(cfg: dict, overrides: dict[str, Any]) -> dict:
    """A copy of ``cfg`` with the non-None ``overrides`` (``{"section.key": value}``, dotted paths) set, as YAML would
    give them (tuples as lists, numpy scalars as numbers); not checked (:func:`bgfn.profile_schema.with_overrides`
    checks them)."""
    out = copy.deepcopy(cfg)
    for path, value in overrides.items():
        if value is None:
            continue
        *parents, key = path.split(".")
        node = out
        for k in parents:
            node = node.setdefault(k, {})
        node[key] = _plain(value)
    return out


def _plain(value: Any) -> Any:
    """``value`` as YAML would give it: tuples as lists, numpy scalars as Python numbers (a copy)."""
    if isinstance(value, dict):
        return {k: _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if hasattr(value, "item") and getattr(value, "ndim", None) == 0:      # numpy scalar
        return value.item()
    return copy.deepcopy(value)


def file_setting(profile: str, path: str) -> Path:
    """The file of a profile chain that sets ``path`` (a dotted key, ``[i]`` list items ignored): the profile's
    own file when it holds the key, else the nearest base that does; the profile's file when none does."""
    chain = _read_chain(profile)
    keys = [k for k in path.split("[")[0].split(".") if k]
    for depth in range(len(keys), 0, -1):
        for file, own in chain:
            node = own
            for k in keys[:depth]:
                if not isinstance(node, dict) or k not in node:
                    break
                node = node[k]
            else:
                return file
    return chain[0][0]


def _check_moved_keys(path: Path, own: dict) -> None:
    """A key that moved (:data:`MOVED_KEYS`) fails by name, so that no setting is silently ignored."""
    for old, new in MOVED_KEYS.items():
        section, key = old.split(".")
        if isinstance(own.get(section), dict) and key in own[section]:
            raise DataError(path, old, f"the top-level key {new!r} instead (a list of [start, duration] in s, "
                            "or per dataset a list or a rule; shared by every notebook)", f"{old}: {own[section][key]!r}")


def results_dir(profile: str, create: bool = True) -> Path:
    """``results/<profile>/``, with ``tables/``, ``figures/``, ``notebooks/``, ``models/`` created.

    Parameters
    ----------
    profile : str
        Profile name.
    create : bool
        Create the folders (default). With ``False`` only the path is returned.
    """
    root = RESULTS_ROOT / _check_name(profile)
    if create:
        for sub in RESULT_SUBDIRS:
            (root / sub).mkdir(parents=True, exist_ok=True)
    return root


def _git(*args: str) -> str | None:
    try:
        # GIT_OPTIONAL_LOCKS=0: `git status` must not rewrite the index (read-only query)
        env = {**os.environ, "GIT_OPTIONAL_LOCKS": "0"}
        res = subprocess.run(["git", *args], cwd=PROJECT_ROOT, capture_output=True, text=True, timeout=10,
                             env=env)
    except (OSError, subprocess.SubprocessError):
        return None
    return res.stdout.strip() if res.returncode == 0 else None


def git_commit(short: bool = True) -> str | None:
    """The checkout's commit (short form by default); None outside a git checkout."""
    return _git("rev-parse", *(["--short"] if short else []), "HEAD")


def run_metadata(profile: str) -> dict[str, Any]:
    """What produced a table: profile, seed, code and package versions. No timestamps.

    Two runs of the same profile on the same checkout and environment give the same dict, so tables that
    embed it stay byte-identical.

    Returns
    -------
    dict
        ``profile``, ``seed``, ``params_file`` (relative path), ``params_sha256`` (of the YAML bytes of the
        file and of its ``base:`` chain),
        ``git_commit`` (``None`` outside a git checkout), ``git_dirty`` (tracked files modified; ``None``
        without git), ``python`` (``major.minor.micro``) and ``packages`` (name -> version, ``None`` if
        not installed).
    """
    cfg = read_profile(profile)
    path = profile_path(profile)
    commit = _git("rev-parse", "HEAD")
    status = _git("status", "--porcelain", "--untracked-files=no") if commit else None
    packages: dict[str, str | None] = {}
    for name in _PACKAGES:
        try:
            packages[name] = metadata.version(name)
        except metadata.PackageNotFoundError:
            packages[name] = None
    return {
        "profile": cfg["profile"],
        "seed": cfg["seed"],
        "params_file": path.relative_to(PROJECT_ROOT).as_posix(),
        "params_sha256": hashlib.sha256(b"".join(p.read_bytes() for p in profile_chain(profile))).hexdigest(),
        "git_commit": commit,
        "git_dirty": (bool(status) if status is not None else None),
        "python": ".".join(str(v) for v in sys.version_info[:3]),
        "packages": packages,
    }


def metadata_header(profile: str) -> list[str]:
    """:func:`run_metadata` as ``# key: value`` lines, for a comment header above a CSV table."""
    meta = run_metadata(profile)
    lines = [f"# {k}: {v}" for k, v in meta.items() if k != "packages"]
    lines += [f"# {k}: {v}" for k, v in meta["packages"].items()]
    return lines

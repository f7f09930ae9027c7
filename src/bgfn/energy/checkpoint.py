"""The checkpoint audit: which trained networks the energy estimate measures (BGFN and its Transformer twin of
one dataset and seed) and on which evaluation windows (BGFN's validation windows, evenly subsampled).
"""

from __future__ import annotations

import json
import shlex
from dataclasses import dataclass
from pathlib import Path

import numpy as np
from torch import nn

from bgfn.config import PROJECT_ROOT, read_profile
from bgfn.data.names import dataset_id
from bgfn.errors import DataError
from bgfn.learning import WindowSet
from bgfn.train import TrainedModel, even_subset, load_trained, prepare_learning_data
from bgfn.train.checkpoints import card_path, checkpoint_path, parse_checkpoint, retrain_command

# ---------------------------------------------------------------------------------------------------
# Which trained networks the energy estimate measures: BGFN and its Transformer twin of one dataset and seed.
# ---------------------------------------------------------------------------------------------------
#: The networks compared: the SNN and its ANN twin (method ids of :data:`bgfn.models.MODELS`).
MEASURED = ("bgfn", "transformer")


#: The networks whose energy depends on training (their firing rates): refused untrained (:func:`check_trained`).
SPIKING: tuple[str, ...] = ("bgfn",)


def energy_checkpoint(profile: str, method: str, cfg: dict | None = None, dataset: str | None = None,
                      seed: int | None = None, must_exist: bool = True) -> Path:
    """The checkpoint of the energy estimate (:func:`bgfn.train.checkpoints.checkpoint_path`).

    ``dataset``/``seed`` default to the profile's ``energy.dataset``/``energy.seed`` and, when those are
    null, to :func:`energy_dataset` and to :func:`median_seed` over ``train.seeds``.

    Raises
    ------
    FileNotFoundError
        The checkpoint is missing (``must_exist``); the message names the file and the notebook that writes it.
    """
    cfg = cfg if cfg is not None else read_profile(profile)
    ecfg, tcfg = cfg.get("energy") or {}, cfg.get("train") or {}
    dataset = dataset or ecfg.get("dataset") or energy_dataset(profile, tcfg)
    if dataset is None:
        raise ValueError(f"profile {profile!r}: no dataset (energy.dataset and train.datasets are empty)")
    seed = seed if seed is not None else ecfg.get("seed")
    seed = seed if seed is not None else median_seed(profile, dataset, tcfg["seeds"])
    path = checkpoint_path(profile, dataset, method, int(seed), create=False)
    if must_exist and not path.is_file():
        raise FileNotFoundError(
            f"trained {method} model not found: {path} -- notebook 03_bgfn_training.ipynb writes it "
            f"(`python -m bgfn train --profile {profile} --dataset {shlex.quote(str(dataset))} --method {method} "
            f"--seed {int(seed)}` "
            f"trains it alone; or `{retrain_command(path)}` runs notebook 03 and every later one again)")
    return path


def energy_dataset(profile: str, train_cfg: dict, method: str = "bgfn") -> str | None:
    """The first of ``train.datasets`` where some seed's ``method`` network improved on its initial network
    (``best_epoch >= 1`` in its card), so that one dataset the networks could not learn does not stop the estimate;
    the first dataset when none has such a card (its network is then refused), None without datasets."""
    datasets = list(train_cfg.get("datasets") or [])
    for dataset in datasets:
        cards = (_card(profile, dataset, method, seed) for seed in train_cfg["seeds"])
        if any(c is not None and int(c.get("best_epoch", 1)) >= 1 for c in cards):
            return dataset
    return datasets[0] if datasets else None


def median_seed(profile: str, dataset: str, seeds, method: str = "bgfn") -> int:
    """The seed whose ``method`` network has the median validation RMSE (the lower median; ties: the smaller
    seed) among the cards of ``seeds`` whose best epoch is at least 1 (training improved on the initial network),
    among all cards when none is; the first seed when no card is there yet."""
    scored, trained = [], []
    for seed in seeds:
        c = _card(profile, dataset, method, seed)
        if c is not None:
            scored.append((float(c.get("val_rmse_m", float("inf"))), int(seed)))
            if int(c.get("best_epoch", 1)) >= 1:
                trained.append(scored[-1])
    pool = sorted(trained or scored)
    return pool[(len(pool) - 1) // 2][1] if pool else int(list(seeds)[0])


def _card(profile: str, dataset: str, method: str, seed) -> dict | None:
    """The training card of ``method``'s network of ``dataset`` and ``seed``; None when it is not there."""
    card = card_path(checkpoint_path(profile, dataset, method, int(seed), create=False))
    return json.loads(card.read_text()) if card.is_file() else None


def improved(card: dict) -> bool:
    """Whether training improved on the initial network: the card's ``best_epoch`` is at least 1 (epoch 0 is the
    initial network, validated before training; :mod:`bgfn.train.loop`). A card without the field (written
    before it) counts as improved."""
    return int(card.get("best_epoch", 1)) >= 1


def check_trained(card: dict, card_file: str | Path, allow_untrained: bool = False) -> None:
    """Refuse a network whose best epoch is 0 (the initial network: training never improved on it): its firing
    rates would be those of an untrained network.

    Raises
    ------
    bgfn.errors.DataError
        Naming the card, unless ``allow_untrained`` (``energy.allow_untrained`` of the profile).
    """
    if not allow_untrained and not improved(card):
        raise DataError(card_file, "best_epoch", "a network that training improved on its initial weights (best epoch >= 1; "
                        "epoch 0 is the initial network) "
                        "-- its firing rates decide the energy; train longer (train.optimizer.epochs, patience), set energy.dataset to a dataset whose BGFN "
                        "learned, energy.seed to a trained seed, or energy.allow_untrained: true", "0")


@dataclass
class MeasuredModels:
    """The trained networks of the energy estimate (:func:`load_measured`).

    Attributes
    ----------
    profile, dataset : str
    seed : int
        Training seed, read back from the checkpoint name (:func:`bgfn.train.checkpoints.parse_checkpoint`).
    paths : dict
        Method -> best checkpoint.
    trained : dict
        Method -> :class:`bgfn.train.TrainedModel` (eval mode, CPU).
    cards : dict
        Method -> its training card (``{}`` when missing).
    """

    profile: str
    dataset: str
    seed: int
    paths: dict[str, Path]
    trained: dict[str, TrainedModel]
    cards: dict[str, dict]

    @property
    def models(self) -> dict[str, nn.Module]:
        """Method -> the network (eval mode)."""
        return {m: t.model for m, t in self.trained.items()}

    @property
    def size_cfgs(self) -> dict[str, dict]:
        """Method -> size configuration of the trained network (``dim``, ``depth``, ``time_steps``, ...)."""
        return {m: t.size_cfg for m, t in self.trained.items()}

    @property
    def time_steps(self) -> int:
        """BGFN's ``T_s`` (SNN steps per IMU sample)."""
        return int(self.trained["bgfn"].size_cfg.get("time_steps", 4))

    @property
    def improved(self) -> dict[str, bool]:
        """Method -> whether training improved on its initial network (:func:`improved`): an energy of BGFN that
        did not is an untrained network's, and no saving is claimed from it."""
        return {m: improved(c) for m, c in self.cards.items()}

    def relative_paths(self) -> dict[str, str]:
        """Method -> checkpoint path relative to the project root (as ``energy.json`` records it)."""
        return {m: p.relative_to(PROJECT_ROOT).as_posix() if p.is_relative_to(PROJECT_ROOT) else str(p)
                for m, p in self.paths.items()}


def load_measured(profile: str, cfg: dict | None = None, methods=MEASURED) -> MeasuredModels:
    """Load the networks of the energy estimate (:func:`energy_checkpoint`) on the CPU.

    Raises
    ------
    FileNotFoundError
        A checkpoint is missing; the message names the file and the notebook that writes it.
    bgfn.errors.DataError
        BGFN's best epoch is 0 (:func:`check_trained`; the Transformer twin is not checked: its operation count,
        hence its energy, does not depend on its weights).
    """
    paths = {m: energy_checkpoint(profile, m, cfg) for m in methods}
    trained = {m: load_trained(p, device="cpu") for m, p in paths.items()}
    for t in trained.values():
        t.model.eval()
    cards = {m: json.loads(card_path(p).read_text()) if card_path(p).exists() else {} for m, p in paths.items()}
    cfg = cfg if cfg is not None else read_profile(profile)
    allow = bool(cfg["energy"]["allow_untrained"])
    for m in methods:
        if m in SPIKING:        # firing rates depend on the weights; the twin's MAC count does not
            check_trained(cards[m], card_path(paths[m]), allow)
    first = paths[methods[0]]
    # the dataset as the profile names it (a CSV drive by its folder path), the checkpoints' folder being its id
    names = [d for d in (cfg.get("train") or {}).get("datasets") or [] if dataset_id(d) == first.parent.name]
    return MeasuredModels(profile, names[0] if names else first.parent.name, parse_checkpoint(first).seed, paths,
                          trained, cards)


# ---------------------------------------------------------------------------------------------------
# The evaluation windows that give the firing rates: BGFN's validation windows, evenly subsampled.
# ---------------------------------------------------------------------------------------------------
def window_indices(n_windows: int, max_windows: int | None) -> np.ndarray:
    """Indices of the evaluation windows among ``n_windows``: ``max_windows`` evenly spaced ones, all when
    ``max_windows`` is null or 0 (``energy.max_windows``)."""
    return even_subset(n_windows, int(max_windows) if max_windows else None)


@dataclass
class EvaluationWindows:
    """The windows measured, raw and as each network reads them.

    Attributes
    ----------
    windows : WindowSet
        The selected validation windows (raw units).
    x : dict
        Method -> normalized windows, float32 [M, N, C].
    n_validation : int
        Validation windows before the subsampling.
    """

    windows: WindowSet
    x: dict[str, np.ndarray]
    n_validation: int


def evaluation_windows(cfg: dict, measured: MeasuredModels) -> EvaluationWindows:
    """The validation windows of ``measured.dataset``, subsampled and normalized per network.

    Raises
    ------
    DataError
        A network was trained with other learning options than the profile's (retrain with notebook 03).
    """
    data = prepare_learning_data(cfg, measured.dataset)
    for m, tm in measured.trained.items():
        if dict(tm.options) != dict(data.options):
            raise DataError(measured.paths[m], "options",
                            f"the learning options of params/{measured.profile}.yaml {data.options}",
                            f"{tm.options} (retrain with notebook 03)")
    n_val = len(data.val)
    ws = data.val.subset(window_indices(n_val, (cfg.get("energy") or {}).get("max_windows")))
    x = {m: tm.norm.x(ws.x).astype(np.float32) for m, tm in measured.trained.items()}
    return EvaluationWindows(ws, x, n_val)

"""The residual stream of BGFN's spiking blocks: how many spike trains the layers that read it merge.

A spiking block computes ``x = x + SSA(x)`` then ``x = x + MLP(x)`` (Spikformer; :class:`bgfn.models.bgfn.Block`),
so its input is not binary: it is the sum of the embedding's spikes and of every earlier block's SSA and MLP
outputs, ``n = 1 + 2 l`` binary trains at the input of block ``l`` (read by its Q, K, V layers) and
``n = 2 + 2 l`` after its attention (read by its first MLP layer). Spikformer and the syops counter count a
residual value ``k`` as ``k`` spikes, so such a layer does ``n * r * T * FLOPs`` synaptic operations with ``r``
the mean rate of the ``n`` merged trains (:mod:`bgfn.energy.rules`).

:class:`ResidualStream` follows the stream through forward hooks and checks its spike total at every step, so
that a changed block wiring raises instead of being miscounted.
"""

from __future__ import annotations

import torch
from torch import nn

from bgfn.energy.passes import is_binary


def _total(t: torch.Tensor) -> float:
    return float(t.detach().double().sum())


class ResidualStream:
    """The tensor the spiking blocks pass on, and the number ``n`` of binary spike trains it sums.

    Attributes
    ----------
    n : int
        Spike trains merged into the stream so far (0 before the first block of a forward pass).
    total : float
        Its spike total (checked against every block input and output).
    tensor : torch.Tensor or None
        The stream tensor [T, B, N, D] a layer may read right now (the object, compared by identity).
    """

    def __init__(self):
        self.reset()

    def reset(self) -> None:
        """Start of a forward pass: no stream yet."""
        self.n, self.total, self.tensor = 0, 0.0, None

    def trains_of(self, x: torch.Tensor) -> int | None:
        """``n`` if ``x`` is the stream tensor (a layer reading it merges ``n`` trains), else None."""
        return self.n if x is self.tensor else None

    def follow(self, name: str, block: nn.Module) -> list:
        """Hooks on a spiking :class:`~bgfn.models.bgfn.Block` (``attn``, ``mlp``) that follow the stream.

        Returns
        -------
        list of RemovableHandle
        """

        def block_input(_m, inputs):
            x = inputs[0]                                    # [T, B, N, D]
            if self.n == 0:                                  # first block: the stream is the embedding's spikes
                if not is_binary(x):
                    raise ValueError(f"{name}: the input of the first block is not binary spikes")
                self.n, self.total = 1, _total(x)
            elif _total(x) != self.total:
                raise ValueError(f"{name}: block input is not the residual sum tracked so far; "
                                 "bgfn.energy must follow the changed block wiring")
            self.tensor = x

        def added(part):
            def fn(_m, _inp, out):                           # SSA or MLP output, added to the stream
                if not is_binary(out):
                    raise ValueError(f"{name}.{part}: output added to the residual stream is not binary spikes")
                self.n += 1
                self.total += _total(out)
                self.tensor = None
            return fn

        def mlp_input(_m, inputs):
            if _total(inputs[0]) != self.total:
                raise ValueError(f"{name}.mlp: MLP input is not x + attn(x); bgfn.energy must follow the block "
                                 "wiring")
            self.tensor = inputs[0]

        def block_output(_m, _inp, out):
            if _total(out) != self.total:
                raise ValueError(f"{name}: block output is not x + attn(x) + mlp(.); "
                                 "bgfn.energy must follow the block wiring")
            self.tensor = None

        return [block.register_forward_pre_hook(block_input),
                block.attn.register_forward_hook(added("attn")),
                block.mlp.register_forward_pre_hook(mlp_input),
                block.mlp.register_forward_hook(added("mlp")),
                block.register_forward_hook(block_output)]

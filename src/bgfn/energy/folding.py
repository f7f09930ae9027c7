"""BatchNorm folding: the inference form of a network, in which BatchNorm costs nothing.

At inference a BatchNorm is an affine map with fixed statistics, so it merges exactly into the Linear/Conv
before it; an inference deployment runs the folded network. The energy convention therefore counts no
BatchNorm operation, for either model, and the SpikingJelly cross-check counts the folded copy (otherwise its
counter counts BN as MACs).
"""

from __future__ import annotations

import copy

from torch import nn
from torch.nn.utils.fusion import fuse_conv_bn_eval, fuse_linear_bn_eval


def fold_batchnorm(model: nn.Module) -> nn.Module:
    """A copy of ``model`` (eval mode) with every BatchNorm folded into the Linear/Conv registered just before it.

    ``W' = W * g / sqrt(var + eps)``, ``b' = (b - mean) * g / sqrt(var + eps) + beta`` (exact at inference);
    the BatchNorm is replaced by ``nn.Identity``. A BatchNorm without such a predecessor is left in place.
    """
    m = copy.deepcopy(model).eval()
    for parent in m.modules():
        names = list(parent._modules)
        for prev, cur in zip(names[:-1], names[1:]):
            a, b = parent._modules[prev], parent._modules[cur]
            if not isinstance(b, nn.modules.batchnorm._BatchNorm) or not b.track_running_stats:
                continue
            if isinstance(a, nn.Linear) and a.out_features == b.num_features:
                parent._modules[prev] = fuse_linear_bn_eval(a, b)
            elif isinstance(a, (nn.Conv1d, nn.Conv2d, nn.Conv3d)) and a.out_channels == b.num_features:
                parent._modules[prev] = fuse_conv_bn_eval(a, b)
            else:
                continue
            parent._modules[cur] = nn.Identity()
    return m

"""Baselines of paper Sec. 4: MLP, attention LSTM (AT-LSTM), and an ANN Transformer twin of BGFN.

All take the same normalized input window ``x [B, N, C]`` (Eq. eq21) and return ``[B, 2]`` (north, east increment,
normalized). :class:`MLP` is static (the paper's "MLP ... static"): it sees the ``n_recent`` latest samples only.
:class:`ATLSTM` follows the attention-LSTM error-compensation model the paper cites (Chen et al. 2024): an LSTM
over the window, additive temporal attention over its hidden states and a linear head. :class:`TransformerTwin` has
BGFN's structure with real-valued activations (the same temporal convolution, embedding, ``depth`` blocks of
softmax attention and feed-forward of the same widths, mean over tokens, head): the ANN reference of the energy
comparison.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F
from torch import nn


class MLP(nn.Module):
    """Static MLP on the ``n_recent`` most recent samples. [B, N, C] -> [B, 2]."""

    spiking = False

    def __init__(self, in_channels: int = 9, n_recent: int = 1, hidden: int = 128, layers: int = 2,
                 out_dim: int = 2, dropout: float = 0.0):
        super().__init__()
        self.n_recent = n_recent
        dims = [in_channels * n_recent] + [hidden] * layers
        mods: list[nn.Module] = []
        for a, b in zip(dims[:-1], dims[1:]):
            mods += [nn.Linear(a, b), nn.ReLU()] + ([nn.Dropout(dropout)] if dropout else [])
        mods.append(nn.Linear(dims[-1], out_dim))
        self.net = nn.Sequential(*mods)

    def forward(self, x):                                # [B, N, C]
        return self.net(x[:, -self.n_recent:].flatten(1))   # [B, n_recent*C] -> [B, 2]


class ATLSTM(nn.Module):
    """LSTM with temporal attention over the window. [B, N, C] -> [B, 2]."""

    spiking = False

    def __init__(self, in_channels: int = 9, hidden: int = 64, layers: int = 1, attn_dim: int | None = None,
                 out_dim: int = 2, dropout: float = 0.0):
        super().__init__()
        attn_dim = attn_dim or hidden
        self.lstm = nn.LSTM(in_channels, hidden, num_layers=layers, batch_first=True,
                            dropout=dropout if layers > 1 else 0.0)
        self.attn_w = nn.Linear(hidden, attn_dim)
        self.attn_v = nn.Linear(attn_dim, 1, bias=False)
        self.head = nn.Linear(2 * hidden, out_dim)

    def forward(self, x):                                # [B, N, C]
        h, _ = self.lstm(x)                              # [B, N, H]
        e = self.attn_v(torch.tanh(self.attn_w(h)))      # [B, N, 1]
        a = torch.softmax(e, dim=1)                      # temporal attention weights, sum to 1 over N
        c = (a * h).sum(dim=1)                           # [B, H] context
        return self.head(torch.cat([c, h[:, -1]], dim=-1))   # [B, 2]


class TwinBlock(nn.Module):
    """Pre-LayerNorm Transformer block: x + MHSA(LN(x)), then + FFN(LN(.)). [B, N, D] -> [B, N, D]."""

    def __init__(self, dim: int, ffn_dim: int, heads: int, dropout: float):
        super().__init__()
        if dim % heads:
            raise ValueError(f"dim {dim} is not divisible by heads {heads}")
        self.heads = heads
        self.ln1 = nn.LayerNorm(dim)
        self.qkv = nn.Linear(dim, 3 * dim)
        self.proj = nn.Linear(dim, dim)
        self.ln2 = nn.LayerNorm(dim)
        self.ffn = nn.Sequential(nn.Linear(dim, ffn_dim), nn.GELU(), nn.Linear(ffn_dim, dim))
        self.dropout = dropout

    def forward(self, x):                                # [B, N, D]
        B, N, D = x.shape
        q, k, v = self.qkv(self.ln1(x)).reshape(B, N, 3, self.heads, D // self.heads).permute(2, 0, 3, 1, 4)
        a = F.scaled_dot_product_attention(q, k, v, dropout_p=self.dropout if self.training else 0.0)
        x = x + self.proj(a.transpose(1, 2).reshape(B, N, D))   # softmax attention, [B, N, D]
        return x + self.ffn(self.ln2(x))                 # [B, N, D]


class TransformerTwin(nn.Module):
    """ANN twin of BGFN (same encoder kernels, widths and depth; real-valued). [B, N, C] -> [B, 2]."""

    spiking = False

    def __init__(self, in_channels: int = 9, dim: int = 256, ffn_dim: int = 256, depth: int = 4, heads: int = 8,
                 time_steps: int = 4, kernel_size: int = 3, readout: str = "mean", out_dim: int = 2,
                 dropout: float = 0.0, encoder_neurons: int = 1):
        super().__init__()
        if readout not in ("mean", "last"):
            raise ValueError(f"readout must be 'mean' or 'last', got {readout!r}")
        self.readout = readout
        width = in_channels * encoder_neurons * time_steps     # BGFN's encoder currents, as features
        self.conv = nn.Conv1d(in_channels, width, kernel_size, padding=kernel_size // 2, groups=in_channels)
        self.bn = nn.BatchNorm1d(width)
        self.embed = nn.Linear(width, dim)
        self.blocks = nn.ModuleList([TwinBlock(dim, ffn_dim, heads, dropout) for _ in range(depth)])
        self.ln = nn.LayerNorm(dim)
        self.head = nn.Linear(dim, out_dim)

    def forward(self, x):                                # [B, N, C]
        z = F.gelu(self.bn(self.conv(x.transpose(1, 2))))   # [B, C*K*T_s, N]
        z = self.embed(z.transpose(1, 2))                # [B, N, D]
        for blk in self.blocks:
            z = blk(z)                                   # [B, N, D]
        z = self.ln(z)
        z = z.mean(1) if self.readout == "mean" else z[:, -1]   # [B, D]
        return self.head(z)                              # [B, 2]

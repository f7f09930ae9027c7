"""BGFN: the spiking Transformer of paper Sec. 3.2 (Eqs. eq:bgfn_net, eq:spike_input, eq:spiking_embedding).

Data flow (T = T_s SNN steps per IMU step, B batch, N window length, C = 9 channels, D embedding width)::

    x [B, N, C] --spike_encoder--> [T, B, N, C*K] spikes      Eq. (eq:spike_input)  S = SN(BN(Conv(S_k)))
      --embedding--> [T, B, N, D] spikes                       Eq. (eq:spiking_embedding)  S_emb = SN(Linear(S))
      --L x Block (SSA + spiking MLP, residuals)--> [T, B, N, D]
      --mean over T and N--> [B, D] --Linear--> [B, 2]         delta_p_gps (north, east), Eq. (eq:bgfn_net)

The encoder is SeqSNN's convolutional spike encoder (Lv et al. 2024), with each channel's own ``T_s`` kernels (the
nine channels differ in units and dynamics); ``encoder_neurons`` K > 1 is a population code, not the paper's. The
blocks follow Spikformer: attention without softmax, evaluated as ``Q (K^T V)`` (the same result, cheaper). The
membranes are reset at the start of every forward pass.
"""

from __future__ import annotations

import torch
from spikingjelly.activation_based import functional
from torch import nn

from .lif import DEFAULT_ALPHA, DEFAULT_ATTN_THRESHOLD, DEFAULT_TAU, DEFAULT_THRESHOLD, make_lif


def _bn(bn: nn.BatchNorm1d, x: torch.Tensor) -> torch.Tensor:
    """BatchNorm over the last axis of ``x`` [..., D] (statistics over all leading axes: T, B, N)."""
    shape = x.shape
    return bn(x.reshape(-1, shape[-1])).reshape(shape)


class LinearBNLIF(nn.Module):
    """SN(BN(Linear(x))): the basic spiking layer of Spikformer. [T, B, N, Din] -> [T, B, N, Dout] spikes.

    The Linear has no bias, as Spikformer's convolutions before a BatchNorm: BN subtracts the batch mean (in
    training) or the running mean (in evaluation), which cancels any constant the Linear adds.
    """

    def __init__(self, d_in: int, d_out: int, tau: float, v_threshold: float, alpha: float):
        super().__init__()
        self.linear = nn.Linear(d_in, d_out, bias=False)
        self.bn = nn.BatchNorm1d(d_out)
        self.lif = make_lif(tau, v_threshold, alpha)

    def forward(self, x):                               # [T, B, N, Din]
        return self.lif(_bn(self.bn, self.linear(x)))   # [T, B, N, Dout]


class SpikeEncoder(nn.Module):
    """Convolutional spike encoder, Eq. (eq:spike_input): S = SN(BN(Conv(S_k))). [B, N, C] -> [T_s, B, N, C*K].

    ``neurons`` = K spiking neurons per input channel (1: the paper's encoder).
    """

    def __init__(self, in_channels: int, time_steps: int, kernel_size: int, tau: float, v_threshold: float,
                 alpha: float, neurons: int = 1):
        super().__init__()
        self.in_channels, self.time_steps, self.neurons = in_channels, time_steps, neurons
        self.out_channels = in_channels * neurons
        # T_s kernels per channel and neuron (groups=C); 'same' padding keeps one token per IMU sample
        # no bias: the BatchNorm after it cancels one (LinearBNLIF)
        self.conv = nn.Conv1d(in_channels, self.out_channels * time_steps, kernel_size, padding=kernel_size // 2,
                              groups=in_channels, bias=False)
        self.bn = nn.BatchNorm1d(self.out_channels * time_steps)
        self.lif = make_lif(tau, v_threshold, alpha)

    def forward(self, x):                                # [B, N, C]
        B, N, C = x.shape
        cur = self.bn(self.conv(x.transpose(1, 2)))      # [B, C*K*T, N]  (channel-major: (c*K + k)*T + t)
        cur = cur.reshape(B, self.out_channels, self.time_steps, N)   # [B, C*K, T, N]
        cur = cur.permute(2, 0, 3, 1).contiguous()       # [T, B, N, C*K]
        return self.lif(cur)                             # [T, B, N, C*K] spikes


class SpikingEmbedding(nn.Module):
    """Channel-wise spiking embedding, Eq. (eq:spiking_embedding): S_emb = SN(BN(Linear(S))).

    The paper writes SN(Linear(S)); a BatchNorm is added, as in every other spiking layer, so that the LIF input
    is at unit scale and the neurons fire from the first step of training.
    """

    def __init__(self, in_channels: int, dim: int, tau: float, v_threshold: float, alpha: float):
        super().__init__()
        self.layer = LinearBNLIF(in_channels, dim, tau, v_threshold, alpha)

    def forward(self, s):                                # [T, B, N, C]
        return self.layer(s)                             # [T, B, N, D]


class SSA(nn.Module):
    """Spiking self-attention (Spikformer): SN(BN(Linear(SN_attn(Q K^T V * scale)))), no softmax."""

    def __init__(self, dim: int, heads: int, scale: float, tau: float, v_threshold: float,
                 attn_threshold: float, alpha: float):
        super().__init__()
        if dim % heads:
            raise ValueError(f"dim {dim} is not divisible by heads {heads}")
        self.heads, self.scale = heads, scale
        self.q = LinearBNLIF(dim, dim, tau, v_threshold, alpha)
        self.k = LinearBNLIF(dim, dim, tau, v_threshold, alpha)
        self.v = LinearBNLIF(dim, dim, tau, v_threshold, alpha)
        self.attn_lif = make_lif(tau, attn_threshold, alpha)
        self.proj = LinearBNLIF(dim, dim, tau, v_threshold, alpha)

    def _split(self, x):                                 # [T, B, N, D]
        T, B, N, D = x.shape
        return x.reshape(T, B, N, self.heads, D // self.heads).transpose(2, 3)   # [T, B, H, N, dh]

    @staticmethod
    def kv_first(n_tokens: int, head_dim: int) -> bool:
        """Product order of :meth:`attend`: Q (K^T V) when the head is narrower than the window (cheaper).

        The energy count (:mod:`bgfn.energy`) follows the same order.
        """
        return head_dim < n_tokens

    def attend(self, q, k, v):
        """Q K^T V * scale per head, no softmax. q, k, v: [T, B, H, N, dh] -> [T, B, H, N, dh]."""
        N, dh = q.shape[-2], q.shape[-1]
        if self.kv_first(N, dh):
            return (q @ (k.transpose(-2, -1) @ v)) * self.scale    # K^T V: [T, B, H, dh, dh]
        return ((q @ k.transpose(-2, -1)) @ v) * self.scale         # Q K^T: [T, B, H, N, N]

    def forward(self, x):                                # [T, B, N, D]
        T, B, N, D = x.shape
        q, k, v = self._split(self.q(x)), self._split(self.k(x)), self._split(self.v(x))  # [T, B, H, N, dh]
        a = self.attend(q, k, v)                         # [T, B, H, N, dh]
        a = a.transpose(2, 3).reshape(T, B, N, D)        # [T, B, N, D]
        return self.proj(self.attn_lif(a))               # [T, B, N, D] spikes


class SpikingMLP(nn.Module):
    """Spiking feed-forward block: SN(BN(Linear(SN(BN(Linear(x)))))). [T, B, N, D] -> [T, B, N, D]."""

    def __init__(self, dim: int, hidden: int, tau: float, v_threshold: float, alpha: float):
        super().__init__()
        self.fc1 = LinearBNLIF(dim, hidden, tau, v_threshold, alpha)
        self.fc2 = LinearBNLIF(hidden, dim, tau, v_threshold, alpha)

    def forward(self, x):                                # [T, B, N, D]
        return self.fc2(self.fc1(x))                     # [T, B, N, D]


class Block(nn.Module):
    """Spiking Transformer block: x + SSA(x), then + SpikingMLP(.). [T, B, N, D] -> [T, B, N, D]."""

    def __init__(self, dim: int, ffn_dim: int, heads: int, scale: float, tau: float, v_threshold: float,
                 attn_threshold: float, alpha: float):
        super().__init__()
        self.attn = SSA(dim, heads, scale, tau, v_threshold, attn_threshold, alpha)
        self.mlp = SpikingMLP(dim, ffn_dim, tau, v_threshold, alpha)

    def forward(self, x):                                # [T, B, N, D]
        x = x + self.attn(x)                             # residual (integer-valued, as in Spikformer)
        return x + self.mlp(x)                           # [T, B, N, D]


class BGFN(nn.Module):
    """Brain-inspired GPS/INS fusion network, Eq. (eq:bgfn_net): IMU window -> delta_p_gps.

    Parameters
    ----------
    in_channels : int
        Input channels per IMU sample (9, Eq. eq21).
    dim : int
        Embedding width D (paper: 256).
    ffn_dim : int
        Hidden width of the spiking MLP (paper: 256).
    depth : int
        Number of spiking Transformer blocks L (paper: 4).
    heads : int
        Attention heads; must divide ``dim`` (paper: 6, which does not divide 256; default 8).
    time_steps : int
        T_s, SNN steps per IMU step (not given in the paper; default 4).
    kernel_size : int
        Temporal kernel of the spike encoder (odd).
    attn_scale : float
        Scale of Q K^T V (Spikformer: 0.125).
    tau, v_threshold, attn_threshold, alpha : float
        LIF time constant (beta = 1 - 1/tau), thresholds, ATan steepness.
    readout : {'mean', 'last'}
        Average over T_s and all tokens, or over T_s at the last token only.
    encoder_neurons : int
        K spiking neurons per input channel in the spike encoder (1: the paper's; module docstring).
    out_dim : int
        2 outputs: north and east increment.
    """

    spiking = True

    def __init__(self, in_channels: int = 9, dim: int = 256, ffn_dim: int = 256, depth: int = 4, heads: int = 8,
                 time_steps: int = 4, kernel_size: int = 3, attn_scale: float = 0.125, tau: float = DEFAULT_TAU,
                 v_threshold: float = DEFAULT_THRESHOLD, attn_threshold: float = DEFAULT_ATTN_THRESHOLD,
                 alpha: float = DEFAULT_ALPHA, readout: str = "mean", out_dim: int = 2, encoder_neurons: int = 1):
        super().__init__()
        if readout not in ("mean", "last"):
            raise ValueError(f"readout must be 'mean' or 'last', got {readout!r}")
        self.readout = readout
        self.spike_encoder = SpikeEncoder(in_channels, time_steps, kernel_size, tau, v_threshold, alpha,
                                          neurons=encoder_neurons)
        self.embedding = SpikingEmbedding(self.spike_encoder.out_channels, dim, tau, v_threshold, alpha)
        self.blocks = nn.ModuleList([Block(dim, ffn_dim, heads, attn_scale, tau, v_threshold, attn_threshold, alpha)
                                     for _ in range(depth)])
        self.head = nn.Linear(dim, out_dim)

    def features(self, x):                               # [B, N, C]
        functional.reset_net(self)                       # membrane state starts at 0 for every batch
        s = self.spike_encoder(x)                        # [T, B, N, C*K]
        s = self.embedding(s)                            # [T, B, N, D]
        for blk in self.blocks:
            s = blk(s)                                   # [T, B, N, D]
        return s

    def forward(self, x):                                # [B, N, C]
        s = self.features(x)                             # [T, B, N, D]
        z = s.mean(dim=(0, 2)) if self.readout == "mean" else s[:, :, -1].mean(0)   # [B, D]
        return self.head(z)                              # [B, 2]

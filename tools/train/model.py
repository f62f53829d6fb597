"""The two-head CNN of seed 004 §III.D (Fig. 1), sized for CPU training here.

Backbone: torchvision MobileNetV3-Small (weights=None: nothing can be downloaded) with a
1-channel stem, then global average pooling and batch normalisation, dropout 0.2, and
- attitude head: one fully connected layer to the m classes (softmax at export);
- position head: fully connected 128 then 3, tanh, times l/2 (offset inside the ROI).
The paper used MobileNetV3-Large at 224; Small at 64 is what fits 2 shared CPU cores.
"""

from __future__ import annotations

import torch
import torch.nn.functional as F
from torch import nn
from torchvision.models import mobilenet_v3_small


class PoseNet(nn.Module):
    """Returns (attitude logits [B,m], position offset [B,3] in metres)."""

    def __init__(self, classes: int, roi_side_m: float, width_mult: float = 0.5,
                 dropout: float = 0.2):
        super().__init__()
        net = mobilenet_v3_small(weights=None, width_mult=width_mult)
        stem = net.features[0][0]
        net.features[0][0] = nn.Conv2d(1, stem.out_channels, kernel_size=stem.kernel_size,
                                       stride=stem.stride, padding=stem.padding, bias=False)
        self.features = net.features
        channels = net.features[-1].out_channels
        self.pool = nn.AdaptiveAvgPool2d(1)
        self.norm = nn.BatchNorm1d(channels)
        self.dropout = nn.Dropout(dropout)
        self.attitude = nn.Linear(channels, classes)
        self.position = nn.Sequential(nn.Linear(channels, 128), nn.ReLU(inplace=True),
                                      nn.Linear(128, 3))
        self.half_side = roi_side_m / 2
        nn.init.kaiming_normal_(self.features[0][0].weight, mode="fan_out")  # as torchvision
        # torchvision's MobileNetV3 uses BN momentum 0.01, tuned for long ImageNet runs: over a
        # few hundred steps the running statistics lag far behind and eval mode is garbage.
        for mod in self.modules():
            if isinstance(mod, (nn.BatchNorm1d, nn.BatchNorm2d)):
                mod.momentum = 0.1

    def forward(self, depth: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        f = self.dropout(self.norm(torch.flatten(self.pool(self.features(depth)), 1)))
        return self.attitude(f), torch.tanh(self.position(f)) * self.half_side


class ExportNet(nn.Module):
    """The ONNX contract: depth [1,1,N,N] -> probs [1,m] (softmax), pos [1,3] (m)."""

    def __init__(self, net: PoseNet):
        super().__init__()
        self.net = net

    def forward(self, depth: torch.Tensor) -> tuple[torch.Tensor, torch.Tensor]:
        logits, pos = self.net(depth)
        return F.softmax(logits, dim=1), pos


def loss_eq16(logits: torch.Tensor, pos: torch.Tensor, labels: torch.Tensor,
              pos_true: torch.Tensor, lam: float) -> tuple[torch.Tensor, torch.Tensor, torch.Tensor]:
    """Eq. (16): -Σ l̄_i log l_i + λ ||Δp̄ - Δp||² / 3, averaged over the batch.

    Returns (total, attitude part, position part)."""
    ce = F.cross_entropy(logits, labels)  # soft targets: -Σ l̄ log softmax
    mse = ((pos - pos_true) ** 2).sum(dim=1).mean() / 3
    return ce + lam * mse, ce, mse


def count_parameters(net: nn.Module) -> int:
    return sum(p.numel() for p in net.parameters())

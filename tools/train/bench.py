"""Time one training step (augmentation + forward + backward + AdamW) on random images.

    python tools/train/bench.py --size 64 --classes 618 --width 0.5 --threads 1
"""

from __future__ import annotations

import argparse
import time

import torch

from augment import AugmentConfig, augment
from model import PoseNet, count_parameters, loss_eq16


def main() -> None:
    p = argparse.ArgumentParser()
    p.add_argument("--size", type=int, default=64)
    p.add_argument("--classes", type=int, default=618)
    p.add_argument("--width", type=float, default=0.5)
    p.add_argument("--threads", type=int, default=1)
    p.add_argument("--batch", type=int, default=128)
    p.add_argument("--steps", type=int, default=15)
    a = p.parse_args()
    torch.set_num_threads(a.threads)
    torch.set_num_interop_threads(1)
    torch.manual_seed(0)
    gen = torch.Generator().manual_seed(1)
    net = PoseNet(a.classes, 4.0, width_mult=a.width).to(memory_format=torch.channels_last)
    opt = torch.optim.AdamW(net.parameters(), lr=1e-3)
    x0 = (torch.rand(a.batch, 1, a.size, a.size) > 0.6) * torch.rand(a.batch, 1, a.size, a.size)
    labels = torch.softmax(torch.randn(a.batch, a.classes), 1)
    pos0 = torch.randn(a.batch, 3) * 0.3
    times = []
    for i in range(a.steps + 3):
        t = time.perf_counter()
        x, pos = augment(x0, pos0, AugmentConfig(), gen)
        logits, p_ = net(x.contiguous(memory_format=torch.channels_last))
        loss, _, _ = loss_eq16(logits, p_, labels, pos, 10.0)
        opt.zero_grad()
        loss.backward()
        opt.step()
        if i >= 3:
            times.append(time.perf_counter() - t)
    times.sort()
    ms = [1000 * t / a.batch for t in times]
    print(f"size {a.size} width {a.width} classes {a.classes} threads {a.threads} batch "
          f"{a.batch} params {count_parameters(net)}: ms/image median {ms[len(ms) // 2]:.2f} "
          f"min {ms[0]:.2f} max {ms[-1]:.2f}")


if __name__ == "__main__":
    main()

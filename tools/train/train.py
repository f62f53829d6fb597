"""Train the seed 004 two-head CNN on a `spacepose dataset` directory and export it to ONNX.

    python tools/train/train.py --data /work/data/deos-train --val /work/data/deos-val \
        --out services/core/cnn/models/deos --epochs 30 --threads 1 --max-minutes 70

Writes <out>/model.onnx (contract: notes/acq-design.md), <out>/model.json (the dataset's
meta.json + training metrics) and <out>/training-log.txt. See tools/train/README.md.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import shlex
import signal
import sys
import time
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import onnxruntime
import torch
import torchvision
from tqdm import tqdm

from augment import AugmentConfig, augment
from dataset import Dataset, check_compatible, open_dataset, sanity_check
from export import OPSET, check_contract, export_onnx, verify_onnxruntime
from metrics import oracle_error_deg, summarise
from model import PoseNet, count_parameters, loss_eq16

CL = torch.channels_last


def parse_args(argv: list[str] | None = None) -> argparse.Namespace:
    p = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawTextHelpFormatter)
    p.add_argument("--data", required=True, help="training set directory")
    p.add_argument("--val", required=True, help="validation set directory")
    p.add_argument("--out", required=True, help="output directory (model.onnx, model.json, log)")
    p.add_argument("--epochs", type=int, default=40)
    p.add_argument("--threads", type=int, default=1,
                   help="torch intra-op threads; under load 1 beats 2 (README)")
    p.add_argument("--max-minutes", type=float, default=None,
                   help="wall-time budget of the whole run; training stops early (the LR "
                        "schedule is compressed to end on time) and the model is still exported")
    p.add_argument("--batch", type=int, default=128)
    p.add_argument("--lr", type=float, default=2e-3, help="AdamW peak learning rate")
    p.add_argument("--weight-decay", type=float, default=0.02)
    p.add_argument("--warmup", type=float, default=0.03, help="warm-up fraction of training")
    p.add_argument("--lam", type=float, default=10.0, help="λ of Eq. (16)")
    p.add_argument("--width", type=float, default=0.75, help="MobileNetV3-Small width_mult")
    p.add_argument("--dropout", type=float, default=0.2)
    p.add_argument("--no-augment", action="store_true", help="disable the §IV.B augmentations")
    p.add_argument("--train-limit", type=int, default=None, help="use the first K images only")
    p.add_argument("--seed", type=int, default=0)
    return p.parse_args(argv)


class Log:
    """Lines to <out>/training-log.txt (flushed) and to the terminal above the progress bar."""

    def __init__(self, path: Path):
        self.file = path.open("w", encoding="utf-8")

    def __call__(self, line: str = "") -> None:
        tqdm.write(line)
        self.file.write(line + "\n")
        self.file.flush()


@dataclass
class Clock:
    """Wall-time budget and the compressed cosine schedule."""

    start: float
    train_start: float = 0.0
    train_budget_s: float | None = None
    stop_requested: bool = False
    history: list = field(default_factory=list)

    def elapsed(self) -> float:
        return time.monotonic() - self.start

    def progress(self, step: int, total_steps: int) -> float:
        """max(step fraction, time fraction): with a budget the schedule ends on time."""
        p = step / total_steps
        if self.train_budget_s is not None:
            p = max(p, (time.monotonic() - self.train_start) / self.train_budget_s)
        return p


def lr_at(progress: float, peak: float, warmup: float) -> float:
    """Linear warm-up then cosine decay to 1% of the peak."""
    final = 0.01 * peak
    if progress < warmup:
        return peak * (0.1 + 0.9 * progress / warmup)
    q = min((progress - warmup) / max(1.0 - warmup, 1e-9), 1.0)
    return final + (peak - final) * 0.5 * (1 + math.cos(math.pi * q))


def seed_everything(seed: int) -> torch.Generator:
    random.seed(seed)
    np.random.seed(seed)
    torch.manual_seed(seed)
    torch.use_deterministic_algorithms(True, warn_only=True)
    return torch.Generator().manual_seed(seed + 1)


def evaluate(net: PoseNet, ds: Dataset, lam: float, batch: int = 256) -> dict:
    """Val loss of Eq. (16) and the monitors of metrics.summarise, no augmentation."""
    net.eval()
    probs, pos = [], []
    loss_sum = ce_sum = mse_sum = 0.0
    with torch.no_grad():
        for start in range(0, ds.count, batch):
            idx = np.arange(start, min(start + batch, ds.count))
            depth, labels, pos_true = ds.batch(idx)
            x = torch.from_numpy(depth).unsqueeze(1).contiguous(memory_format=CL)
            logits, p = net(x)
            loss, ce, mse = loss_eq16(logits, p, torch.from_numpy(labels),
                                      torch.from_numpy(pos_true), lam)
            loss_sum += float(loss) * len(idx)
            ce_sum += float(ce) * len(idx)
            mse_sum += float(mse) * len(idx)
            probs.append(torch.softmax(logits, 1).numpy())
            pos.append(p.numpy())
    net.train()
    n = ds.count
    out = {"loss": loss_sum / n, "loss_att": ce_sum / n, "loss_pos": mse_sum / n}
    out.update(summarise(np.concatenate(probs), np.asarray(ds.labels), np.concatenate(pos),
                         np.asarray(ds.pos_offset), np.asarray(ds.attitude),
                         ds.class_quaternions, int(ds.meta["symmetry_order"])))
    return out


def fmt_val(v: dict) -> str:
    return (f"val loss {v['loss']:.4f} (att {v['loss_att']:.4f} pos {v['loss_pos']:.5f}) "
            f"top1 {100 * v['top1']:.1f}% top5 {100 * v.get('top5', float('nan')):.1f}% "
            f"att(argmax) mean {v['att_err_deg_mean']:.1f} med {v['att_err_deg_median']:.1f} deg "
            f"<15deg {100 * v['att_within_15deg']:.1f}% pos mean {v['pos_err_cm_mean']:.1f} cm")


def train(args: argparse.Namespace) -> int:
    clock = Clock(start=time.monotonic())
    out = Path(args.out)
    out.mkdir(parents=True, exist_ok=True)
    log = Log(out / "training-log.txt")
    torch.set_num_threads(args.threads)
    torch.set_num_interop_threads(1)
    gen = seed_everything(args.seed)
    rng = np.random.default_rng(args.seed)

    def on_signal(signum, _frame):
        clock.stop_requested = True
        tqdm.write(f"signal {signum}: stopping after this step, then exporting")

    signal.signal(signal.SIGTERM, on_signal)

    tr, va = open_dataset(args.data), open_dataset(args.val)
    check_compatible(tr, va)
    n_train = tr.count if args.train_limit is None else min(args.train_limit, tr.count)
    n, m, side = tr.image_size, tr.classes, tr.roi_side_m
    order = int(tr.meta["symmetry_order"])
    log(f"# spacepose CNN training, {time.strftime('%Y-%m-%d %H:%M:%S %Z')}")
    log(f"command: python {shlex.join(sys.argv)}")
    log(f"torch {torch.__version__}, torchvision {torchvision.__version__}, onnxruntime "
        f"{onnxruntime.__version__}, threads {args.threads}, seed {args.seed}")
    log(f"train: {sanity_check(tr)}; using {n_train}")
    log(f"val:   {sanity_check(va)}")
    log(f"meta: {json.dumps(tr.meta)}")
    oracle = oracle_error_deg(np.asarray(va.labels), np.asarray(va.attitude),
                              va.class_quaternions, order)
    log(f"val floor of the argmax monitor (argmax of the true soft label vs truth, d_sym): "
        f"mean {oracle.mean():.2f} deg, max {oracle.max():.2f} deg")

    lab = np.asarray(va.labels)
    entropy = -(lab * np.log(np.clip(lab, 1e-12, 1.0))).sum(axis=1).mean()
    log(f"floor of the attitude loss (mean entropy of the val soft labels): {entropy:.3f}; "
        f"uniform prediction: {math.log(m):.3f}")
    net = PoseNet(m, side, width_mult=args.width, dropout=args.dropout).to(memory_format=CL)
    log(f"model: MobileNetV3-Small width {args.width}, 1-channel stem, input {n}x{n}, "
        f"{count_parameters(net)} parameters, channels_last")
    opt = torch.optim.AdamW(net.parameters(), lr=args.lr, weight_decay=args.weight_decay)
    aug = AugmentConfig()
    log(f"loss Eq. (16), lambda {args.lam}; AdamW lr {args.lr} wd {args.weight_decay}, "
        f"batch {args.batch}, warm-up {args.warmup} then cosine; augment "
        f"{'off' if args.no_augment else json.dumps(aug.to_dict())}")

    steps_per_epoch = n_train // args.batch
    if steps_per_epoch == 0:
        raise SystemExit(f"--batch {args.batch} larger than the training set ({n_train})")
    total_steps = steps_per_epoch * args.epochs
    t_val = time.monotonic()
    val0 = evaluate(net, va, args.lam)
    val_s = time.monotonic() - t_val
    log(f"epoch 0 (untrained): {fmt_val(val0)} [val {val_s:.1f} s]")
    clock.train_start = time.monotonic()
    if args.max_minutes is not None:
        reserve = 30.0 + 2 * val_s  # final validation, export, onnxruntime check
        clock.train_budget_s = args.max_minutes * 60 - clock.elapsed() - reserve
        if clock.train_budget_s <= 0:
            raise SystemExit(f"--max-minutes {args.max_minutes}: no time left to train")
        log(f"time budget: {args.max_minutes} min, training until "
            f"{clock.train_budget_s / 60:.1f} min from now")

    step, stopped_by, val, best = 0, None, val0, None
    net.train()
    for epoch in range(1, args.epochs + 1):
        perm = rng.permutation(n_train)
        sums = np.zeros(3)
        seen = 0
        t_epoch = time.monotonic()
        bar = tqdm(range(steps_per_epoch), desc=f"epoch {epoch}/{args.epochs}", unit="step",
                   dynamic_ncols=True, mininterval=2.0)
        try:
            for b in bar:
                progress = clock.progress(step, total_steps)
                if progress >= 1.0 or clock.stop_requested:
                    stopped_by = "signal" if clock.stop_requested else "time budget"
                    break
                lr = lr_at(progress, args.lr, args.warmup)
                for g in opt.param_groups:
                    g["lr"] = lr
                depth, labels, pos_true = tr.batch(perm[b * args.batch:(b + 1) * args.batch])
                x = torch.from_numpy(depth).unsqueeze(1)
                pos_t = torch.from_numpy(pos_true)
                if not args.no_augment:
                    x, pos_t = augment(x, pos_t, aug, gen)
                x = x.contiguous(memory_format=CL)
                logits, pos = net(x)
                loss, ce, mse = loss_eq16(logits, pos, torch.from_numpy(labels), pos_t, args.lam)
                opt.zero_grad(set_to_none=True)
                loss.backward()
                opt.step()
                step += 1
                sums += (loss.item(), ce.item(), mse.item())
                seen += 1
                if seen % 20 == 0:
                    bar.set_postfix(loss=f"{sums[0] / seen:.3f}", lr=f"{lr:.2e}")
        except KeyboardInterrupt:
            stopped_by = "interrupt"
        bar.close()
        dt = time.monotonic() - t_epoch
        if seen:
            val = evaluate(net, va, args.lam)
            ms = 1000 * dt / (seen * args.batch)
            row = {"epoch": epoch, "steps": seen, "train_loss": sums[0] / seen,
                   "train_loss_att": sums[1] / seen, "train_loss_pos": sums[2] / seen,
                   "lr_end": lr, "epoch_s": dt, "ms_per_image": ms, "val": val}
            clock.history.append(row)
            if best is None or val["loss"] < best["val"]["loss"]:
                best = row
            log(f"epoch {epoch}{'' if seen == steps_per_epoch else f' (partial, {seen} steps)'}: "
                f"train loss {row['train_loss']:.4f} (att {row['train_loss_att']:.4f} pos "
                f"{row['train_loss_pos']:.5f}) lr {lr:.2e} | {fmt_val(val)} | "
                f"{dt:.0f} s, {ms:.2f} ms/img, elapsed {clock.elapsed() / 60:.1f} min")
        if stopped_by:
            log(f"stopped by {stopped_by} at step {step}/{total_steps}")
            break

    return finish(args, log, clock, net, tr, va, val, best, step, total_steps, steps_per_epoch,
                  stopped_by, aug, n_train)


def finish(args, log, clock, net, tr, va, val, best, step, total_steps, steps_per_epoch,
           stopped_by, aug, n_train) -> int:
    """Export, check against onnxruntime, write model.json; files replaced only on success."""
    out = Path(args.out)
    net.eval()
    tmp = out / "model.onnx.tmp"
    export_onnx(net, tr.image_size, tmp)
    check_contract(tmp, tr.image_size, tr.classes)
    probe = np.concatenate([np.asarray(va.depth[:6]),
                            np.random.default_rng(args.seed).random((2, tr.image_size,
                                                                     tr.image_size),
                                                                    dtype=np.float32)])
    ort_check = verify_onnxruntime(net, tmp, probe)
    os.replace(tmp, out / "model.onnx")
    onnx_bytes = (out / "model.onnx").stat().st_size
    log(f"exported {out / 'model.onnx'} ({onnx_bytes / 1e6:.2f} MB, opset {OPSET}); "
        f"onnxruntime vs torch on {ort_check['images']} images: max |diff| "
        f"probs {ort_check['max_abs_diff']['probs']:.2e} pos {ort_check['max_abs_diff']['pos']:.2e}")
    wall = clock.elapsed()
    doc = dict(tr.meta)
    doc["model"] = {"arch": "mobilenet_v3_small", "width_mult": args.width, "stem_channels": 1,
                    "parameters": count_parameters(net), "input": "depth",
                    "outputs": ["probs", "pos"], "opset": OPSET, "onnx_bytes": onnx_bytes}
    doc["training"] = {
        "command": "python " + shlex.join(sys.argv),
        "train_set": str(Path(args.data).resolve()), "train_seed": tr.meta.get("seed"),
        "train_images": n_train, "val_set": str(Path(args.val).resolve()),
        "val_seed": va.meta.get("seed"), "val_images": va.count,
        "epochs_planned": args.epochs, "epochs_completed": round(step / steps_per_epoch, 3),
        "steps": step, "steps_planned": total_steps, "batch": args.batch,
        "optimizer": "AdamW", "lr_peak": args.lr, "weight_decay": args.weight_decay,
        "schedule": f"linear warm-up {args.warmup} then cosine to 1%",
        "lambda": args.lam, "dropout": args.dropout,
        "augment": None if args.no_augment else aug.to_dict(),
        "seed": args.seed, "threads": args.threads, "max_minutes": args.max_minutes,
        "stopped_by": stopped_by, "wall_time_s": round(wall, 1),
        "torch_version": torch.__version__, "torchvision_version": torchvision.__version__,
        "onnxruntime_version": onnxruntime.__version__,
    }
    doc["metrics"] = {"final_val": val, "best_epoch": best["epoch"] if best else None,
                      "best_val": best["val"] if best else None,
                      "onnxruntime_check": ort_check,
                      "per_epoch": [{k: v for k, v in r.items()} for r in clock.history]}
    tmp_json = out / "model.json.tmp"
    tmp_json.write_text(json.dumps(doc, indent=2) + "\n")
    os.replace(tmp_json, out / "model.json")
    log(f"final: {fmt_val(val)}")
    log(f"wall time {wall / 60:.1f} min ({step} steps, {step / steps_per_epoch:.2f} epochs, "
        f"{args.threads} thread(s)); wrote model.onnx, model.json")
    return 0


if __name__ == "__main__":
    sys.exit(train(parse_args()))

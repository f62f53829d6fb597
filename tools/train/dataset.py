"""Reading a dataset written by `spacepose dataset` (contract: notes/acq-design.md).

DIR/meta.json, class_quaternions.npy [m,4] (w,x,y,z), depth.npy [count,N,N] in [0,1],
labels.npy [count,m] (soft labels L_sym, seed 004 Eq. 15), pos_offset.npy [count,3] (m),
attitude.npy [count,4], range_m.npy [count]. Arrays are opened with numpy memmap.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

META_KEYS = ("count", "image_size", "roi_side_m", "classes", "symmetry_order")
# Keys that must agree between the training and the validation set.
MATCH_KEYS = ("target", "image_size", "roi_side_m", "classes", "roll_step_deg", "sigma_deg",
              "symmetry_order")


class DatasetError(Exception):
    """A dataset directory is missing a file or is inconsistent with its meta.json."""


@dataclass
class Dataset:
    """One dataset directory, arrays memory-mapped (nothing is read until indexed)."""

    root: Path
    meta: dict
    depth: np.ndarray
    labels: np.ndarray
    pos_offset: np.ndarray
    attitude: np.ndarray
    class_quaternions: np.ndarray

    @property
    def count(self) -> int:
        return int(self.depth.shape[0])

    @property
    def image_size(self) -> int:
        return int(self.meta["image_size"])

    @property
    def classes(self) -> int:
        return int(self.meta["classes"])

    @property
    def roi_side_m(self) -> float:
        return float(self.meta["roi_side_m"])

    def batch(self, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
        """Depth [B,N,N], labels [B,m], pos [B,3] of the given indices (copied into RAM)."""
        order = np.sort(idx)  # sorted reads are kinder to the memmap
        return (np.asarray(self.depth[order], dtype=np.float32),
                np.asarray(self.labels[order], dtype=np.float32),
                np.asarray(self.pos_offset[order], dtype=np.float32))


def _load(root: Path, name: str, shape: tuple[int, ...]) -> np.ndarray:
    path = root / name
    if not path.is_file():
        raise DatasetError(f"{path}: missing")
    try:
        arr = np.load(path, mmap_mode="r")
    except ValueError as err:  # truncated or corrupt header
        raise DatasetError(f"{path}: cannot read ({err})") from err
    if arr.dtype != np.float32:
        raise DatasetError(f"{path}: dtype {arr.dtype}, expected float32")
    if tuple(arr.shape) != shape:
        raise DatasetError(f"{path}: shape {tuple(arr.shape)}, expected {shape}")
    return arr


def open_dataset(root: str | Path) -> Dataset:
    """Open DIR, checking every array against meta.json."""
    root = Path(root)
    meta_path = root / "meta.json"
    if not meta_path.is_file():
        raise DatasetError(f"{meta_path}: missing")
    meta = json.loads(meta_path.read_text())
    for key in META_KEYS:
        if key not in meta:
            raise DatasetError(f"{meta_path}: no key {key!r}")
    count, n, m = int(meta["count"]), int(meta["image_size"]), int(meta["classes"])
    if count <= 0 or n <= 0 or m <= 0:
        raise DatasetError(f"{meta_path}: count {count}, image_size {n}, classes {m}")
    ds = Dataset(
        root=root,
        meta=meta,
        depth=_load(root, "depth.npy", (count, n, n)),
        labels=_load(root, "labels.npy", (count, m)),
        pos_offset=_load(root, "pos_offset.npy", (count, 3)),
        attitude=_load(root, "attitude.npy", (count, 4)),
        class_quaternions=np.asarray(_load(root, "class_quaternions.npy", (m, 4))),
    )
    return ds


def check_compatible(train: Dataset, val: Dataset) -> None:
    """The validation set must share N, l, m, Δα, σ and the symmetry with the training set."""
    for key in MATCH_KEYS:
        if train.meta.get(key) != val.meta.get(key):
            raise DatasetError(
                f"{key}: train {train.meta.get(key)!r} != val {val.meta.get(key)!r}")
    if not np.allclose(train.class_quaternions, val.class_quaternions, atol=1e-6):
        raise DatasetError("class_quaternions differ between train and val")


def sanity_check(ds: Dataset, rows: int = 256) -> str:
    """Cheap checks on the first rows: depth in [0,1], labels sum to 1, no NaN.

    Returns a one-line summary for the log."""
    k = min(rows, ds.count)
    depth, labels, pos = ds.batch(np.arange(k))
    for name, arr in (("depth", depth), ("labels", labels), ("pos_offset", pos)):
        if not np.isfinite(arr).all():
            raise DatasetError(f"{ds.root}: {name} has non-finite values")
    if depth.min() < 0.0 or depth.max() > 1.0:
        raise DatasetError(f"{ds.root}: depth outside [0,1]: {depth.min()}..{depth.max()}")
    sums = labels.sum(axis=1)
    if np.abs(sums - 1.0).max() > 1e-3:
        raise DatasetError(f"{ds.root}: label rows sum to {sums.min()}..{sums.max()}, not 1")
    # An offset beyond l/2 cannot be reached by the tanh head; it is legal but worth a note.
    beyond = float((np.abs(pos) > ds.roi_side_m / 2).any(axis=1).mean())
    filled = float((depth > 0).mean())
    return (f"{ds.root}: {ds.count} images {ds.image_size}x{ds.image_size}, {ds.classes} classes,"
            f" first {k}: filled pixels {100 * filled:.1f}%, |pos| max {np.abs(pos).max():.3f} m,"
            f" beyond l/2 {100 * beyond:.1f}%")

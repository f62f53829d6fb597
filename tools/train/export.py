"""ONNX export per the contract (notes/acq-design.md) and the onnxruntime check."""

from __future__ import annotations

import copy
import warnings
from pathlib import Path

import numpy as np
import onnx
import onnxruntime as ort
import torch

from model import ExportNet, PoseNet

OPSET = 17


class ExportError(Exception):
    """The exported graph breaks the contract or disagrees with torch."""


def export_onnx(net: PoseNet, image_size: int, path: Path) -> None:
    """Write depth [1,1,N,N] -> probs [1,m], pos [1,3] at opset 17 (TorchScript exporter)."""
    wrapped = ExportNet(copy.deepcopy(net).to(memory_format=torch.contiguous_format)).eval()
    dummy = torch.rand(1, 1, image_size, image_size)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the TorchScript exporter's deprecation notice
        torch.onnx.export(wrapped, (dummy,), str(path), input_names=["depth"],
                          output_names=["probs", "pos"], opset_version=OPSET, dynamo=False)


def check_contract(path: Path, image_size: int, classes: int) -> None:
    """Names, shapes and opset of the graph."""
    model = onnx.load(str(path))
    onnx.checker.check_model(model)

    def dims(v) -> list[int]:
        return [d.dim_value for d in v.type.tensor_type.shape.dim]

    ins = {v.name: dims(v) for v in model.graph.input}
    outs = {v.name: dims(v) for v in model.graph.output}
    want_in = {"depth": [1, 1, image_size, image_size]}
    want_out = {"probs": [1, classes], "pos": [1, 3]}
    if ins != want_in or outs != want_out:
        raise ExportError(f"graph io {ins} -> {outs}, expected {want_in} -> {want_out}")
    opset = max(o.version for o in model.opset_import if o.domain in ("", "ai.onnx"))
    if opset != OPSET:
        raise ExportError(f"opset {opset}, expected {OPSET}")


def verify_onnxruntime(net: PoseNet, path: Path, images: np.ndarray,
                       tol: float = 1e-4) -> dict:
    """Run torch and onnxruntime on each image [k,N,N]; return the max abs differences."""
    wrapped = ExportNet(net).eval()
    opts = ort.SessionOptions()
    opts.intra_op_num_threads = 1
    sess = ort.InferenceSession(str(path), opts, providers=["CPUExecutionProvider"])
    worst = {"probs": 0.0, "pos": 0.0}
    with torch.no_grad():
        for img in images:
            x = np.ascontiguousarray(img[None, None], dtype=np.float32)
            probs_t, pos_t = (t.numpy() for t in wrapped(torch.from_numpy(x)))
            probs_o, pos_o = sess.run(["probs", "pos"], {"depth": x})
            worst["probs"] = max(worst["probs"], float(np.abs(probs_t - probs_o).max()))
            worst["pos"] = max(worst["pos"], float(np.abs(pos_t - pos_o).max()))
            if abs(float(probs_o.sum()) - 1.0) > 1e-4:
                raise ExportError(f"onnxruntime probs sum to {probs_o.sum()}")
    if max(worst.values()) > tol:
        raise ExportError(f"onnxruntime differs from torch: {worst}")
    return {"images": int(len(images)), "max_abs_diff": worst}

"""Validation monitors. The authoritative decode (Algorithm 1, Γ_sym) lives in Rust
(services/core/cnn); here the attitude error uses the argmax class only, as a monitor."""

from __future__ import annotations

import numpy as np


def quat_mul(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Hamilton product of (w,x,y,z) quaternions, broadcasting."""
    aw, ax, ay, az = np.moveaxis(a, -1, 0)
    bw, bx, by, bz = np.moveaxis(b, -1, 0)
    return np.stack((aw * bw - ax * bx - ay * by - az * bz,
                     aw * bx + ax * bw + ay * bz - az * by,
                     aw * by - ax * bz + ay * bw + az * bx,
                     aw * bz + ax * by - ay * bx + az * bw), axis=-1)


def symmetry_quaternions(order: int) -> np.ndarray:
    """{Rx(2πk/order)}: the roll-axis symmetries (body x, seed 004 Fig. 5) as [order,4]."""
    order = max(int(order), 1)
    half = np.pi * np.arange(order) / order
    return np.stack((np.cos(half), np.sin(half), 0 * half, 0 * half), axis=-1)


def d_sym_deg(q_est: np.ndarray, q_true: np.ndarray, order: int) -> np.ndarray:
    """Eq. (14): min_k d(R_est, R_true S_k), Eq. (12) via quaternions, in degrees. [B]."""
    q_est = q_est / np.linalg.norm(q_est, axis=-1, keepdims=True)
    q_true = q_true / np.linalg.norm(q_true, axis=-1, keepdims=True)
    cands = quat_mul(q_true[:, None, :], symmetry_quaternions(order)[None, :, :])
    dots = np.abs((cands * q_est[:, None, :]).sum(-1)).max(axis=1)
    return np.degrees(2 * np.arccos(np.clip(dots, 0.0, 1.0)))


def summarise(probs: np.ndarray, labels: np.ndarray, pos: np.ndarray, pos_true: np.ndarray,
              attitude: np.ndarray, class_q: np.ndarray, order: int) -> dict:
    """Top-1/top-5 against the argmax of the soft label, argmax-decode attitude error,
    position error (cm)."""
    pred = probs.argmax(axis=1)
    truth = labels.argmax(axis=1)
    top5 = np.argpartition(-probs, 5, axis=1)[:, :5] if probs.shape[1] > 5 else None
    att = d_sym_deg(class_q[pred], attitude, order)
    pos_err_cm = 100 * np.linalg.norm(pos - pos_true, axis=1)
    out = {
        "top1": float((pred == truth).mean()),
        "att_err_deg_mean": float(att.mean()),
        "att_err_deg_median": float(np.median(att)),
        "att_within_15deg": float((att < 15).mean()),
        "pos_err_cm_mean": float(pos_err_cm.mean()),
        "pos_err_cm_median": float(np.median(pos_err_cm)),
    }
    if top5 is not None:
        out["top5"] = float((top5 == truth[:, None]).any(axis=1).mean())
    return out


def oracle_error_deg(labels: np.ndarray, attitude: np.ndarray, class_q: np.ndarray,
                     order: int) -> np.ndarray:
    """Attitude error of the argmax of the true soft label: the floor of the monitor, and a
    check that the label, class table and attitude conventions agree."""
    return d_sym_deg(class_q[labels.argmax(axis=1)], attitude, order)

#!/usr/bin/env python3
"""How well two motion models extrapolate the true relative attitude of a
simulated run (docs/design/sensor-frame-rate.md), from its truth.csv:

- constant relative rate (seed 000 Eq. 9): the rate of the last frame pair,
  constant in the target frame;
- two rates: one constant in the target frame, one in the sensor frame,
  fitted to the last `--fit` frames by Gauss-Newton.

Both start from the true attitude at frame k and predict frame k + n.
Pure Python (no numpy on the flight machine).
    spacepose sim --target deos --scenario tumbling --frames 120 --seed 2023 --out /tmp/run
    docs/results/extrapolation.py /tmp/run/truth.csv
"""
import argparse
import csv
import math


def qmul(a, b):
    w1, x1, y1, z1 = a
    w2, x2, y2, z2 = b
    return (w1 * w2 - x1 * x2 - y1 * y2 - z1 * z2,
            w1 * x2 + x1 * w2 + y1 * z2 - z1 * y2,
            w1 * y2 - x1 * z2 + y1 * w2 + z1 * x2,
            w1 * z2 + x1 * y2 - y1 * x2 + z1 * w2)


def qinv(a):
    return (a[0], -a[1], -a[2], -a[3])


def log(a):
    w, x, y, z = a
    if w < 0:
        w, x, y, z = -w, -x, -y, -z
    s = math.sqrt(x * x + y * y + z * z)
    if s < 1e-12:
        return (2 * x, 2 * y, 2 * z)
    ang = 2 * math.atan2(s, w)
    return (x / s * ang, y / s * ang, z / s * ang)


def exp(v):
    a = math.sqrt(sum(c * c for c in v))
    if a < 1e-12:
        return (1.0, v[0] / 2, v[1] / 2, v[2] / 2)
    s = math.sin(a / 2) / a
    return (math.cos(a / 2), v[0] * s, v[1] * s, v[2] * s)


def angle_deg(a):
    return math.degrees(math.sqrt(sum(c * c for c in log(a))))


def two_rates(q0, w, big_w, dt):
    """Exp(-Ω dt) R0 Exp(ω dt)."""
    return qmul(qmul(exp([-c * dt for c in big_w]), q0), exp([c * dt for c in w]))


def solve(a, b):
    n = len(b)
    m = [row[:] + [b[i]] for i, row in enumerate(a)]
    for i in range(n):
        p = max(range(i, n), key=lambda r: abs(m[r][i]))
        m[i], m[p] = m[p], m[i]
        for r in range(n):
            if r != i:
                f = m[r][i] / m[i][i]
                for c in range(i, n + 1):
                    m[r][c] -= f * m[i][c]
    return [m[i][n] / m[i][i] for i in range(n)]


def fit_two_rates(q, t, k, frames, start):
    def residuals(x):
        out = []
        for j in range(k - frames, k):
            pred = two_rates(q[k], x[:3], x[3:], t[j] - t[k])
            out += list(log(qmul(qinv(pred), q[j])))
        return out

    x = start[:]
    for _ in range(10):
        r = residuals(x)
        jac = []
        for i in range(6):
            xp = x[:]
            xp[i] += 1e-6
            rp = residuals(xp)
            jac.append([(rp[j] - r[j]) / 1e-6 for j in range(len(r))])
        jtj = [[sum(jac[a][j] * jac[b][j] for j in range(len(r))) + (1e-9 if a == b else 0.0)
                for b in range(6)] for a in range(6)]
        jtr = [-sum(jac[a][j] * r[j] for j in range(len(r))) for a in range(6)]
        x = [xi + di for xi, di in zip(x, solve(jtj, jtr))]
    return x


def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("truth_csv")
    ap.add_argument("--fit", type=int, default=3, help="frames the two rates are fitted to")
    args = ap.parse_args()
    rows = list(csv.DictReader(open(args.truth_csv)))
    q = [tuple(float(r[c]) for c in ("qw", "qx", "qy", "qz")) for r in rows]
    t = [float(r["scan_end_s"]) for r in rows]
    first = max(args.fit, 1) + 1
    for n in (1, 3, 5, 10):
        one, two = [], []
        for k in range(first, len(q) - n):
            u = [c / (t[k] - t[k - 1]) for c in log(qmul(qinv(q[k - 1]), q[k]))]
            pred = qmul(q[k], exp([c * (t[k + n] - t[k]) for c in u]))
            one.append(angle_deg(qmul(qinv(pred), q[k + n])))
            x = fit_two_rates(q, t, k, args.fit, u + [0.0, 0.0, 0.0])
            pred = two_rates(q[k], x[:3], x[3:], t[k + n] - t[k])
            two.append(angle_deg(qmul(qinv(pred), q[k + n])))
        print(f"{n:2} frames ahead: constant relative rate mean {sum(one) / len(one):.2f} / "
              f"max {max(one):.2f} deg; two rates mean {sum(two) / len(two):.2f} / max {max(two):.2f} deg")


if __name__ == "__main__":
    main()

#!/usr/bin/env python3
"""Writes the generality-test meshes in tests/fixtures/meshes/ (ASCII STL).

These are targets nobody tuned on: simple stand-ins, built here with the
standard library only (no internet, so no public model collection), for
the two shapes issue 24 reports failing or never tried:

- telescope.stl: a 13.2 m x 4.2 m space-telescope-like body (32-sided
  cylinder, an open aperture door, two 5.6 m x 2.5 m solar wings on masts,
  two antenna booms), 17.6 m across the wings. Written in MILLIMETRES, so it must be
  prepared with --scale 0.001.
- relay.stl: a relay-satellite-like body in metres (2.4 x 2.4 x 3.6 m box
  bus, two 7 m solar arrays on yokes, a 2.2 m dish on a tower, a small
  thruster block), about 17 m tip to tip.

- comsat.stl: a box-wing geostationary satellite (2 x 2.2 x 3.2 m bus, two
  four-panel wings, two reflectors), about 25 m across, metres.
- probe.stl: a small probe (0.6 x 0.5 x 0.4 m box, 0.7 m dish, 0.7 m
  boom), about 1.3 m across, metres.

telescope and relay were used while developing target packages (their
failures drove the length unit and the unscaled lever-arm holds); comsat
and probe were added afterwards and only measured.

Run: python3 tools/meshes/make_meshes.py (deterministic output).
"""
import math
import os

def box(c, h, rot=None):
    """Triangles of a box centred at c with half extents h, optional rotation (3x3 rows)."""
    corners = []
    for sx in (-1, 1):
        for sy in (-1, 1):
            for sz in (-1, 1):
                p = [sx * h[0], sy * h[1], sz * h[2]]
                if rot:
                    p = [sum(rot[i][j] * p[j] for j in range(3)) for i in range(3)]
                corners.append([c[i] + p[i] for i in range(3)])
    quads = [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]
    tris = []
    for a, b, cc, d in quads:
        tris.append((corners[a], corners[b], corners[cc]))
        tris.append((corners[a], corners[cc], corners[d]))
    return tris

def cylinder_x(x0, x1, r, n, closed=(True, True)):
    tris = []
    ring = [(r * math.cos(2 * math.pi * k / n), r * math.sin(2 * math.pi * k / n)) for k in range(n)]
    for k in range(n):
        (y0, z0), (y1, z1) = ring[k], ring[(k + 1) % n]
        a, b, c, d = [x0, y0, z0], [x1, y0, z0], [x1, y1, z1], [x0, y1, z1]
        tris += [(a, b, c), (a, c, d)]
        if closed[0]:
            tris.append(([x0, 0, 0], [x0, y1, z1], [x0, y0, z0]))
        if closed[1]:
            tris.append(([x1, 0, 0], [x1, y0, z0], [x1, y1, z1]))
    return tris

def cone_z(z0, z1, r0, r1, n):
    tris = []
    for k in range(n):
        a0, a1 = 2 * math.pi * k / n, 2 * math.pi * (k + 1) / n
        p = lambda a, r, z: [r * math.cos(a), r * math.sin(a), z]
        tris += [(p(a0, r0, z0), p(a1, r0, z0), p(a1, r1, z1)), (p(a0, r0, z0), p(a1, r1, z1), p(a0, r1, z1))]
    return tris

def rot_y(deg):
    a = math.radians(deg)
    return [[math.cos(a), 0, math.sin(a)], [0, 1, 0], [-math.sin(a), 0, math.cos(a)]]

def telescope():
    t = cylinder_x(-6.6, 4.0, 2.1, 32) + cylinder_x(4.0, 6.6, 2.2, 32, closed=(False, True))
    # Aperture door, hinged at the front rim and open at 60 degrees.
    t += box([7.2, 0.0, 2.9], [0.04, 1.9, 1.2], rot_y(-30.0))
    # Solar wings on masts at x = -2, along +-y, slightly canted about y.
    for s in (-1, 1):
        t += box([-2.0, s * 2.65, 0.0], [0.08, 0.55, 0.08])
        t += box([-2.0, s * 6.0, 0.0], [1.25, 2.8, 0.02], rot_y(8.0 * s))
    # Antenna booms (different lengths, so the body is not symmetric).
    t += box([-1.0, 0.0, -3.4], [0.06, 0.06, 1.3])
    t += box([2.0, 0.0, 3.0], [0.06, 0.06, 0.9])
    return [[[1000.0 * c for c in v] for v in tri] for tri in t]

def relay():
    t = box([0, 0, 0], [1.2, 1.2, 1.8])
    for s in (-1, 1):
        t += box([0, s * 1.9, 0.2], [0.05, 0.7, 0.05])
        t += box([0, s * 5.6, 0.2], [1.1, 3.0, 0.02])
    t += box([0, 0, 2.3], [0.15, 0.15, 0.5])
    t += cone_z(2.8, 3.3, 0.2, 1.1, 24)
    t += box([0.9, -0.7, -2.0], [0.2, 0.2, 0.2])
    return t

def rot_x(deg):
    a = math.radians(deg)
    return [[1, 0, 0], [0, math.cos(a), -math.sin(a)], [0, math.sin(a), math.cos(a)]]

def comsat():
    """A box-wing geostationary communications satellite, about 25 m across."""
    t = box([0, 0, 0], [1.0, 1.1, 1.6])
    for s in (-1, 1):
        t += box([0, s * 1.6, 0], [0.05, 0.5, 0.05])
        for k in range(4):
            t += box([0, s * (2.6 + 2.55 * k), 0], [1.2, 1.2, 0.02], rot_x(3.0 * s))
    for s in (-1, 1):
        t += [[[v[0] * s + s * 1.6, v[1], v[2] * 0.5 + 0.6] for v in tri] for tri in cone_z(0.0, 0.5, 0.1, 1.1, 20)]
    t += box([0, 0, 1.9], [0.3, 0.3, 0.3])
    return t

def probe():
    """A small science probe, about 1.3 m across: a box, a dish, one boom."""
    t = box([0, 0, 0], [0.3, 0.25, 0.2])
    t += [[[v[0], v[1], v[2] + 0.2] for v in tri] for tri in cone_z(0.0, 0.12, 0.05, 0.35, 16)]
    t += box([0.65, 0.0, -0.1], [0.35, 0.015, 0.015])
    t += box([-0.3, 0.2, -0.25], [0.08, 0.05, 0.05])
    return t

def write_stl(path, name, tris):
    with open(path, "w") as f:
        f.write(f"solid {name}\n")
        for a, b, c in tris:
            u = [b[i] - a[i] for i in range(3)]
            v = [c[i] - a[i] for i in range(3)]
            n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
            norm = math.sqrt(sum(x * x for x in n)) or 1.0
            f.write("  facet normal %.6e %.6e %.6e\n    outer loop\n" % tuple(x / norm for x in n))
            for p in (a, b, c):
                f.write("      vertex %.6f %.6f %.6f\n" % tuple(p))
            f.write("    endloop\n  endfacet\n")
        f.write(f"endsolid {name}\n")

if __name__ == "__main__":
    out = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "fixtures", "meshes")
    os.makedirs(out, exist_ok=True)
    write_stl(os.path.join(out, "telescope.stl"), "telescope", telescope())
    write_stl(os.path.join(out, "relay.stl"), "relay", relay())
    write_stl(os.path.join(out, "comsat.stl"), "comsat", comsat())
    write_stl(os.path.join(out, "probe.stl"), "probe", probe())

#!/usr/bin/env python3
"""Writes a room lit only by N small emissive lamps: lamps.py N OUT_DIR [QUADS].

The room is 12 x 4 x 12 (y up) with two boxes on the floor and a dividing wall; the lamps are
0.08 x 0.08 quads facing down, scattered with a fixed seed over heights 2.2..3.9 and the whole
floor plan, their radiance scaled so that the total emitted power is the same for every N: what
changes with N is only how many emitters share it. With QUADS (>= N), QUADS quads are placed and
only the first N emit (the others are black): the geometry, and so the cost of every ray, is
the same for every N. Writes OUT_DIR/lamps-N[-of-QUADS].obj, .mtl and a sidecar .toml with the
camera.
"""
import os
import random
import sys


def quad(out, corners, material):
    out.append(("usemtl", material))
    out.append(("f", corners))


def main():
    n = int(sys.argv[1])
    out_dir = sys.argv[2]
    quads = int(sys.argv[3]) if len(sys.argv) > 3 else n
    assert quads >= n, "QUADS must be at least N"
    os.makedirs(out_dir, exist_ok=True)
    rng = random.Random(41)
    vertices = []
    faces = []

    def v(p):
        vertices.append(p)
        return len(vertices)

    def face(ps, material):
        ids = [v(p) for p in ps]
        faces.append((material, ids))

    def box(x0, y0, z0, x1, y1, z1, material):
        c = [(x, y, z) for x in (x0, x1) for y in (y0, y1) for z in (z0, z1)]
        # Outward-facing quads (counter-clockwise seen from outside).
        for q in [(0, 1, 3, 2), (4, 6, 7, 5), (0, 4, 5, 1), (2, 3, 7, 6), (0, 2, 6, 4), (1, 5, 7, 3)]:
            face([c[i] for i in q], material)

    # The room, seen from inside: its faces point inwards.
    s, h = 6.0, 4.0
    face([(-s, 0, -s), (-s, 0, s), (s, 0, s), (s, 0, -s)], "floor")
    face([(-s, h, -s), (s, h, -s), (s, h, s), (-s, h, s)], "wall")
    face([(-s, 0, -s), (s, 0, -s), (s, h, -s), (-s, h, -s)], "wall")
    face([(-s, 0, s), (-s, h, s), (s, h, s), (s, 0, s)], "wall")
    face([(-s, 0, -s), (-s, h, -s), (-s, h, s), (-s, 0, s)], "red")
    face([(s, 0, -s), (s, 0, s), (s, h, s), (s, h, -s)], "green")
    box(-3.0, 0.0, -2.0, -1.5, 1.5, -0.5, "wall")
    box(1.0, 0.0, 0.5, 2.5, 2.5, 2.0, "wall")
    box(-0.1, 0.0, -6.0, 0.1, 2.0, -2.5, "wall")
    half = 0.04
    total_power = 400.0  # radiance x area x N, kept fixed
    radiance = total_power / (n * (2 * half) ** 2)
    for i in range(quads):
        x = rng.uniform(-s + 0.2, s - 0.2)
        z = rng.uniform(-s + 0.2, s - 0.2)
        y = rng.uniform(2.2, 3.9)
        # Facing down: counter-clockwise seen from below.
        face([(x - half, y, z - half), (x + half, y, z - half), (x + half, y, z + half), (x - half, y, z + half)],
             "lamp" if i < n else "dark")
    stem = f"lamps-{n}" if quads == n else f"lamps-{n}-of-{quads}"
    base = os.path.join(out_dir, stem)
    with open(base + ".mtl", "w") as f:
        for name, kd in [("floor", (0.7, 0.7, 0.7)), ("wall", (0.6, 0.6, 0.6)), ("red", (0.6, 0.1, 0.1)),
                         ("green", (0.1, 0.6, 0.1))]:
            f.write(f"newmtl {name}\nKd {kd[0]} {kd[1]} {kd[2]}\nKs 0 0 0\n\n")
        f.write(f"newmtl lamp\nKd 0 0 0\nKs 0 0 0\nKe {radiance:.6g} {radiance * 0.9:.6g} {radiance * 0.75:.6g}\n\n")
        f.write("newmtl dark\nKd 0.05 0.05 0.05\nKs 0 0 0\n")
    with open(base + ".obj", "w") as f:
        f.write(f"mtllib {stem}.mtl\n")
        for p in vertices:
            f.write(f"v {p[0]:.6g} {p[1]:.6g} {p[2]:.6g}\n")
        current = None
        for material, ids in faces:
            if material != current:
                f.write(f"usemtl {material}\n")
                current = material
            f.write("f " + " ".join(str(i) for i in ids) + "\n")
    with open(base + ".toml", "w") as f:
        f.write("[camera]\nposition = [5.2, 1.6, 5.2]\ntarget = [-2.0, 1.2, -2.0]\nup = [0.0, 1.0, 0.0]\n"
                "vfov_degrees = 70.0\n")


if __name__ == "__main__":
    main()

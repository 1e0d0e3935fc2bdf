#!/usr/bin/env python3
"""Writes a city block the way a modelling tool exports one: OBJ, MTL and a daylight JSON scene.

Sixteen box buildings (20 m square, 9 to 30 m tall) in a 4 x 4 grid on a 120 m asphalt ground,
every face cut into 5 m quads and each quad exported as two triangles with their own vertices
(no shared indices), wound outward, `Kd 1 1 1` concrete (which the reader clamps to 0.99, with a
warning) and `Kd 0.1` asphalt; each building's bottom lies on the ground face to face; one wall
triangle is wound the other way (a flipped face, as exports have). The JSON puts a uniform sky
of radiance 100 over it (z up).

    python3 benchmarks/exported_block.py OUTDIR    # OUTDIR/block.obj, block.mtl, daylight.json
    python3 benchmarks/exported_block.py --turn OUTDIR   # each building turned about its centre

With --turn, building b is turned by 11 b degrees (mod 90) about its vertical axis, as the
buildings of a real city stand (the ground is cut as before, so its facets lie partly under them).

3 744 triangles. Session 37 found three defects with it as a user (docs/VIEW_FACTORS.md, "The
sky view factor"; find_inconsistent_winding()); session 38 measured the automatic method choice
on it meshed finely (docs/HIERARCHICAL.md, "The automatic method choice";
benchmarks/element_accuracy.py).
"""
import json
import math
import os
import sys

HEIGHTS = [12, 12, 18, 30, 9, 9, 30, 18, 12, 12, 30, 30, 30, 12, 12, 12]
LOWER = [-55, -25, 5, 35]  # each building spans [lower, lower + 20] in x and in y
CELL = 5.0


def main():
    args = sys.argv[1:]
    turn = "--turn" in args
    args = [a for a in args if a != "--turn"]
    if len(args) != 1:
        raise SystemExit(__doc__)
    out = args[0]
    os.makedirs(out, exist_ok=True)
    vertices, faces = [], []  # faces: (group, material, [vertex numbers])

    def triangle(group, material, a, b, c):
        first = len(vertices) + 1
        vertices.extend([a, b, c])
        faces.append((group, material, [first, first + 1, first + 2]))

    def quad(group, material, a, b, c, d, flip_second=False):
        """a b c d counter-clockwise seen from the front: triangles a b c and a c d."""
        triangle(group, material, a, b, c)
        if flip_second:
            triangle(group, material, a, d, c)
        else:
            triangle(group, material, a, c, d)

    cells = int(120 / CELL)
    for i in range(cells):
        for j in range(cells):
            x, y = -60 + CELL * i, -60 + CELL * j
            quad("ground", "asphalt", (x, y, 0), (x + CELL, y, 0), (x + CELL, y + CELL, 0), (x, y + CELL, 0))

    for b, h in enumerate(HEIGHTS):
        x0, y0 = LOWER[b // 4], LOWER[b % 4]
        x1, y1 = x0 + 20, y0 + 20
        name = f"b{b}"
        angle = math.radians((11 * b) % 90) if turn else 0.0
        cx, cy = x0 + 10, y0 + 10

        def turned(a, b_, c, d, flip_second=False, group=None, material="concrete"):
            """quad() with each corner turned about the building's centre."""
            def t(p):
                dx, dy = p[0] - cx, p[1] - cy
                return (cx + math.cos(angle) * dx - math.sin(angle) * dy,
                        cy + math.sin(angle) * dx + math.cos(angle) * dy, p[2])
            quad(group, material, t(a), t(b_), t(c), t(d), flip_second)
        for i in range(4):
            for j in range(4):
                x, y = x0 + CELL * i, y0 + CELL * j
                turned((x, y, h), (x + CELL, y, h), (x + CELL, y + CELL, h), (x, y + CELL, h), group=name + "_roof")
        dz = h / 4
        # Each side from its start corner along its direction, outward normal by the right hand.
        sides = [((x0, y0), (1, 0)), ((x1, y0), (0, 1)), ((x1, y1), (-1, 0)), ((x0, y1), (0, -1))]
        if b == len(HEIGHTS) - 1:
            # The last building's east side (x = x1, facing +x) last, so that the flipped
            # triangle is the block's last face.
            sides = [sides[0], sides[2], sides[3], sides[1]]
        for s, ((sx, sy), (ux, uy)) in enumerate(sides):
            for i in range(4):
                for k in range(4):
                    ax, ay = sx + ux * CELL * i, sy + uy * CELL * i
                    bx, by = ax + ux * CELL, ay + uy * CELL
                    z = dz * k
                    flip = b == len(HEIGHTS) - 1 and s == 3 and i == 3 and k == 3
                    turned((ax, ay, z), (bx, by, z), (bx, by, z + dz), (ax, ay, z + dz), flip, group=name + "_wall")
        turned((x0, y0, 0), (x0, y1, 0), (x1, y1, 0), (x1, y0, 0), group=name + "_bottom")

    with open(os.path.join(out, "block.mtl"), "w") as f:
        f.write("newmtl concrete\nKd 1 1 1\nnewmtl asphalt\nKd 0.1 0.1 0.1\n")
    with open(os.path.join(out, "block.obj"), "w") as f:
        f.write("# exported\nmtllib block.mtl\n")
        for v in vertices:
            f.write("v %.4f %.4f %.4f\n" % v)
        group = None
        for g, material, index in faces:
            if g != group:
                f.write(f"g {g}\nusemtl {material}\n")
                group = g
            f.write("f %d %d %d\n" % tuple(index))
    scene = {"version": 1, "surfaces": [{"type": "obj", "file": "block.obj"}],
             "lights": [{"type": "sky", "intensity": 100, "zenith": [0, 0, 1]}]}
    with open(os.path.join(out, "daylight.json"), "w") as f:
        json.dump(scene, f, indent=2)
        f.write("\n")
    print(f"wrote {len(faces)} triangles to {out}/block.obj (and block.mtl, daylight.json)")


if __name__ == "__main__":
    main()

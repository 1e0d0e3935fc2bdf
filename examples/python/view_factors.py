#!/usr/bin/env python3
"""View factors between a scene's polygons with the radiosity Python module (docs/PYTHON.md).

    PYTHONPATH=build/python /usr/bin/python3 examples/python/view_factors.py [SCENE] [OUT.npz]

(PYTHONPATH is not needed once the module is installed; /usr/bin/python3 is the interpreter the
module was built for on Debian, see docs/PYTHON.md.)

Loads SCENE (default: tests/data/view3d/cube.vs3, a closed 2 m cube), computes the polygon-to-
polygon view-factor matrix with ray-cast factors, prints each row's sum and sky view factor
(the part of the hemisphere in which no polygon lies, estimated by rays; not 1 - row sum, which
also holds what sees back faces or is covered: docs/VIEW_FACTORS.md), and writes the matrix to
OUT.npz (default view_factors.npz) with scipy.sparse.save_npz; scipy.sparse.load_npz reads it
back.
"""
import pathlib
import sys

import numpy as np
import scipy.sparse

import radiosity

root = pathlib.Path(__file__).resolve().parents[2]
path = sys.argv[1] if len(sys.argv) > 1 else root / "tests" / "data" / "view3d" / "cube.vs3"
out = sys.argv[2] if len(sys.argv) > 2 else "view_factors.npz"

scene = radiosity.load_scene(path)
print(f"{path}: {len(scene.polygons)} polygons, {len(scene.groups)} groups")

f, info = radiosity.view_factor_matrix(scene, level="polygon", method="ray-cast", return_info=True)
row_sums = np.asarray(f.sum(axis=1)).ravel()
print(f"{f.shape[0]} x {f.shape[1]} matrix, {f.nnz} factors, {info['method']}, {info['seconds']:.3f} s")
print(" polygon  group           area   row sum   sky")
for row, polygon_id in enumerate(info["ids"]):
    polygon = scene.polygons[int(polygon_id)]
    print(f" {polygon_id:7d}  {polygon.group:12s} {info['area'][row]:8.4g}  {row_sums[row]:.5f}  {info['sky'][row]:.5f}")

scipy.sparse.save_npz(out, f)
print(f"wrote {out}")

"""Shared fixtures of the Python tests: the test data folder and a unit cube from NumPy arrays."""
import os
import pathlib

import numpy as np
import pytest

import radiosity


@pytest.fixture(scope="session")
def data_dir():
    """tests/data of the source tree (ctest passes RADIOSITY_TEST_DATA)."""
    default = pathlib.Path(__file__).resolve().parents[2] / "tests" / "data"
    return pathlib.Path(os.environ.get("RADIOSITY_TEST_DATA", default))


def unit_cube_arrays():
    """A unit cube of 6 quads facing inward, in order -x, +x, -y, +y, -z, +z (opposite faces are
    2k and 2k + 1), and the inward normals."""
    vertices = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    # Vertex index = 4x + 2y + z. Each face is counter-clockwise seen from inside the cube.
    faces = np.array([
        [0, 2, 3, 1],  # x = 0, normal +x
        [4, 5, 7, 6],  # x = 1, normal -x
        [0, 1, 5, 4],  # y = 0, normal +y
        [2, 6, 7, 3],  # y = 1, normal -y
        [0, 4, 6, 2],  # z = 0, normal +z
        [1, 3, 7, 5],  # z = 1, normal -z
    ])
    normals = np.array([[1, 0, 0], [-1, 0, 0], [0, 1, 0], [0, -1, 0], [0, 0, 1], [0, 0, -1]], dtype=float)
    return vertices, faces, normals


@pytest.fixture
def cube():
    vertices, faces, _ = unit_cube_arrays()
    return radiosity.Scene(vertices, faces, groups=["x0", "x1", "y0", "y1", "z0", "z1"])

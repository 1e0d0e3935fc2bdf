"""view_factor_matrix(): the unit cube against Howell's closed forms, the corrections, and the
scipy.sparse result."""
import numpy as np
import pytest
import scipy.sparse

import radiosity

# Howell's catalogue, unit cube: C-11 (opposite faces) and C-14 (faces sharing an edge).
OPPOSITE = 0.1998249
ADJACENT = 0.2000438
# Ray-cast factors integrate each element adaptively: a coarse mesh (4 elements per face) keeps
# them exact and the tests fast.
COARSE = dict(max_patch_area=1.0, max_element_area=0.25)


def expected_cube_matrix():
    f = np.full((6, 6), ADJACENT)
    np.fill_diagonal(f, 0.0)
    for k in range(3):
        f[2 * k, 2 * k + 1] = f[2 * k + 1, 2 * k] = OPPOSITE
    return f


def test_cube_ray_cast_matches_howell_and_rows_sum_to_1(cube):
    f = radiosity.view_factor_matrix(cube, method="ray-cast", **COARSE)
    assert isinstance(f, scipy.sparse.csr_matrix)
    assert f.shape == (6, 6)
    assert f.dtype == np.float64
    dense = f.toarray()
    expected = expected_cube_matrix()
    off = expected > 0
    np.testing.assert_allclose(dense[off], expected[off], rtol=5e-3)
    assert np.all(np.diag(dense) == 0)
    np.testing.assert_allclose(dense.sum(axis=1), np.ones(6), rtol=5e-3)


def test_enclosure_correction_closes_rows_and_keeps_reciprocity(cube):
    f, info = radiosity.view_factor_matrix(cube, method="ray-cast", correction="enclosure", return_info=True,
                                           **COARSE)
    dense = f.toarray()
    np.testing.assert_allclose(dense.sum(axis=1), np.ones(6), atol=1e-6)
    area = info["area"]
    np.testing.assert_allclose(area[:, None] * dense, (area[:, None] * dense).T, atol=1e-6)
    np.testing.assert_allclose(info["sky"], np.zeros(6), atol=1e-6)
    assert info["level"] == "polygon"
    np.testing.assert_array_equal(info["ids"], np.arange(6))
    assert info["method"] == "ray-cast"
    assert info["row_standard_error"] is None
    assert info["correction"]["name"] == "enclosure"
    assert info["correction"]["row_sum_error_before"] < 5e-3
    assert info["seconds"] >= 0 and not info["cancelled"]
    assert info["warnings"] == [] and info["notes"] == []


def test_reciprocity_correction_and_float32_values(cube):
    f, info = radiosity.view_factor_matrix(cube, correction="reciprocity", dtype=np.float32, return_info=True,
                                           **COARSE)
    assert f.dtype == np.float32
    # method 'auto' (the default): the exact mode on a scene this small, and why.
    assert info["method"] == "ray-cast"
    assert info["method_reason"].startswith("automatic: the exact mode, about ")
    dense = f.toarray().astype(float)
    area = info["area"]
    np.testing.assert_allclose(area[:, None] * dense, (area[:, None] * dense).T, atol=1e-6)


def test_monte_carlo_states_row_errors_and_group_level_names_rows(cube):
    f, info = radiosity.view_factor_matrix(cube, method="monte-carlo", hemisphere_rays=4096, seed=7,
                                           return_info=True, **COARSE)
    assert info["row_standard_error"].shape == (6,)
    # Each face is one element here or many: the rows of a closed cube sum to 1 exactly.
    np.testing.assert_allclose(np.asarray(f.sum(axis=1)).ravel(), np.ones(6), atol=1e-6)
    g, ginfo = radiosity.view_factor_matrix(cube, "group", groups=["x0", "x1"], return_info=True, **COARSE)
    assert g.shape == (2, 2)
    assert ginfo["names"] == ["x0", "x1"]
    assert g[0, 1] == pytest.approx(OPPOSITE, rel=5e-3)


def test_hierarchical_links_per_polygon_are_reciprocal_and_match_howell(cube):
    # The links' rows (the transpose of their gather), made reciprocal even without a correction.
    f, info = radiosity.view_factor_matrix(cube, method="hierarchical", epsilon=0.05, return_info=True,
                                           max_patch_area=1.0, max_element_area=1.0 / 16)
    assert info["method"] == "hierarchical"
    dense = f.toarray()
    expected = expected_cube_matrix()
    off = expected > 0
    np.testing.assert_allclose(dense[off], expected[off], rtol=1e-2)
    np.testing.assert_allclose(dense.sum(axis=1), np.ones(6), atol=1e-2)
    area = info["area"]
    np.testing.assert_allclose(area[:, None] * dense, (area[:, None] * dense).T, rtol=1e-6)


def test_view_factors_of_a_loaded_view3d_cube(data_dir):
    scene = radiosity.load_scene(data_dir / "view3d" / "cube.vs3")
    f = radiosity.view_factor_matrix(scene, threads=1, max_patch_area=4.0, max_element_area=1.0)
    dense = f.toarray()
    np.testing.assert_allclose(dense.sum(axis=1), np.ones(6), rtol=5e-3)
    assert dense[0, 1] == pytest.approx(OPPOSITE, rel=5e-3)  # floor to ceiling


def test_view_factor_errors(cube):
    with pytest.raises(ValueError, match="method: 'bogus' is not one of"):
        radiosity.view_factor_matrix(cube, method="bogus")
    with pytest.raises(radiosity.Error, match="nowhere"):
        radiosity.view_factor_matrix(cube, groups=["nowhere"])
    with pytest.raises(radiosity.Error):
        radiosity.view_factor_matrix(cube, method="monte-carlo", hemisphere_rays=1)


def test_rows_that_see_no_surface_are_told_apart(data_dir):
    # A block standing on a ground (an STL, z up): its roof sees only the sky (a note, not a
    # warning: the model is not wound outward), its bottom lies on the ground (in contact).
    scene = radiosity.load_scene(str(data_dir / "ground_zup.stl"))
    _, info = radiosity.view_factor_matrix(scene, return_info=True)
    assert info["warnings"] == []
    assert any(n.startswith("2 rows see only the sky") for n in info["notes"])


def test_memory_budget_refuses_up_front():
    # The Cornell box's element rows by Monte Carlo take about 7.8 MiB; under 1 MiB the size
    # estimated from a sample of rows is refused before the rest are made.
    box = radiosity.cornell_box()
    with pytest.raises(radiosity.Error, match="estimated from 256 of its") as e:
        radiosity.view_factor_matrix(box, "element", method="monte-carlo", memory_budget_bytes=1 << 20)
    assert e.value.code == "memory_budget"

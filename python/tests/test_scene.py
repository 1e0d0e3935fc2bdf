"""Scenes: load_scene(), Scene from NumPy arrays, cornell_box(), and their errors."""
import numpy as np
import pytest

import radiosity
from conftest import unit_cube_arrays


def test_load_scene_reads_obj_groups_and_materials(data_dir):
    scene = radiosity.load_scene(data_dir / "two_quads.obj")
    assert len(scene.polygons) == 2
    assert scene.groups == ["floor", "light"]
    np.testing.assert_allclose(scene.polygon_areas(), [1.0, 1.0], rtol=1e-6)
    floor, light = scene.polygons
    assert floor.group == "floor" and light.group == "light"
    assert floor.vertices.shape == (4, 3)
    assert scene.materials[light.material]["emission"].max() > 0
    assert scene.materials[floor.material]["emission"].max() == 0


def test_load_scene_reads_view3d_and_accepts_str_paths(data_dir):
    scene = radiosity.load_scene(str(data_dir / "view3d" / "cube.vs3"), strict=True)
    assert len(scene.polygons) == 6
    np.testing.assert_allclose(scene.polygon_areas(), np.full(6, 4.0), rtol=1e-6)
    assert scene.total_area() == pytest.approx(24.0)
    lower, upper = scene.bounds()
    np.testing.assert_allclose(lower, [0, 0, 0])
    np.testing.assert_allclose(upper, [2, 2, 2])

    np.testing.assert_array_equal(scene.origin, [0, 0, 0])


def test_load_scene_moves_a_georeferenced_model_to_a_local_origin(data_dir):
    # The 2 m cube at UTM coordinates (x.3, y.7, z.1): held relative to its rounded centre.
    scene = radiosity.load_scene(data_dir / "view3d" / "cube_utm.vs3")
    np.testing.assert_array_equal(scene.origin, [512341.0, 5701232.0, 31.0])
    lower, upper = scene.bounds()
    np.testing.assert_allclose(lower, [-0.7, -1.3, -0.9], atol=1e-6)
    np.testing.assert_allclose(upper, [1.3, 0.7, 1.1], atol=1e-6)
    # Its view factors are the cube's at home (Howell C-14: 0.199825 opposite).
    home = radiosity.view_factor_matrix(radiosity.load_scene(data_dir / "view3d" / "cube.vs3"), level="polygon")
    moved = radiosity.view_factor_matrix(scene, level="polygon")
    np.testing.assert_allclose(moved.toarray(), home.toarray(), atol=1e-6)
    kept = radiosity.load_scene(data_dir / "view3d" / "cube_utm.vs3", local_origin=False)
    np.testing.assert_array_equal(kept.origin, [0, 0, 0])
    assert any("coordinates reach" in w for w in kept.warnings)


def test_load_scene_errors_are_radiosity_errors_with_the_library_message(data_dir):
    with pytest.raises(radiosity.Error) as info:
        radiosity.load_scene(data_dir / "no_such_file.obj")
    assert isinstance(info.value, RuntimeError)
    assert info.value.code == "file_not_found"
    assert "no_such_file.obj" in str(info.value)
    with pytest.raises(radiosity.Error, match="bad_index.obj"):
        radiosity.load_scene(data_dir / "bad_index.obj")


def test_scene_from_numpy_quads_has_areas_normals_and_a_polygon_sequence():
    vertices, faces, normals = unit_cube_arrays()
    scene = radiosity.Scene(vertices, faces, groups=["x0", "x1", "y0", "y1", "z0", "z1"],
                            reflectance=[0.5, 0.5, 0.5])
    assert len(scene.polygons) == 6
    np.testing.assert_allclose(scene.polygon_areas(), np.ones(6), rtol=1e-6)
    np.testing.assert_allclose(scene.polygon_normals(), normals, atol=1e-6)
    assert scene.groups == ["x0", "x1", "y0", "y1", "z0", "z1"]
    np.testing.assert_array_equal(scene.polygon_group_ids(), np.arange(6))
    # The sequence: len, indexing (negative too), iteration, IndexError past the end.
    polygons = scene.polygons
    assert [p.group for p in polygons] == scene.groups
    assert polygons[-1].group == "z1"
    np.testing.assert_allclose(polygons[1].normal, [-1, 0, 0], atol=1e-6)
    np.testing.assert_allclose(polygons[0].vertices, vertices[faces[0]])
    assert polygons[0].area == pytest.approx(1.0)
    assert not polygons[0].obstruction_only
    with pytest.raises(IndexError):
        polygons[6]
    # One material: every face has the same reflectance and emission.
    assert len(scene.materials) == 1
    np.testing.assert_allclose(scene.materials[0]["reflectance"], [0.5, 0.5, 0.5])


def test_scene_from_numpy_shares_materials_per_distinct_value():
    vertices, faces, _ = unit_cube_arrays()
    reflectance = np.array([[0.2, 0.3, 0.4]] * 3 + [[0.5, 0.5, 0.5]] * 3)
    emission = np.zeros((6, 3))
    emission[5] = 10.0
    scene = radiosity.Scene(vertices, faces, reflectance=reflectance, emission=emission)
    assert len(scene.materials) == 3
    np.testing.assert_array_equal(scene.polygon_material_ids(), [0, 0, 0, 1, 1, 2])
    assert scene.groups == ["default"]


def test_scene_from_numpy_triangles_is_a_mesh_with_the_callers_vertices():
    vertices, quads, _ = unit_cube_arrays()
    triangles = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    scene = radiosity.Scene(vertices, triangles.astype(np.int32), groups="cube")
    assert len(scene.polygons) == 12
    assert scene.polygon_areas().sum() == pytest.approx(6.0)
    assert scene.mesh_count == 1
    mesh = scene.mesh(0)
    np.testing.assert_allclose(mesh["positions"], vertices)
    np.testing.assert_array_equal(mesh["triangles"], triangles)
    np.testing.assert_array_equal(mesh["triangle_polygons"], np.arange(12))
    # Groups in several runs: one mesh per run, polygons still in face order.
    groups = ["a"] * 4 + ["b"] * 4 + ["a"] * 4
    scene = radiosity.Scene(vertices, triangles, groups=groups)
    assert scene.mesh_count == 3
    assert [p.group for p in scene.polygons] == groups
    np.testing.assert_allclose(scene.mesh(1)["positions"], vertices[np.unique(triangles[4:8])])


def test_scene_from_numpy_rejects_bad_input_naming_the_face():
    vertices, faces, _ = unit_cube_arrays()
    bad = faces.copy()
    bad[2, 1] = 8
    with pytest.raises(radiosity.Error, match=r"faces\[2, 1\]: vertex index 8 out of range") as info:
        radiosity.Scene(vertices, bad)
    assert info.value.code == "invalid_scene"
    flat = faces.copy()
    flat[3] = [0, 1, 1, 0]
    with pytest.raises(radiosity.Error, match=r"faces\[3\]"):
        radiosity.Scene(vertices, flat)
    bent = vertices.copy()
    bent[7] = [1.2, 1.3, 1.1]  # corner 7 off the planes of its three faces
    with pytest.raises(radiosity.Error, match="planar and convex"):
        radiosity.Scene(bent, faces)
    degenerate = np.array([[0, 1, 1]])
    with pytest.raises(radiosity.Error):
        radiosity.Scene(vertices, degenerate)
    with pytest.raises(radiosity.Error, match="reflectance"):
        radiosity.Scene(vertices, faces, reflectance=[1.5, 0.5, 0.5])
    with pytest.raises(ValueError, match="faces"):
        radiosity.Scene(vertices, faces[:, :2])
    with pytest.raises(TypeError, match="integers"):
        radiosity.Scene(vertices, faces.astype(float))
    with pytest.raises(ValueError, match="groups"):
        radiosity.Scene(vertices, faces, groups=["a", "b"])


def test_cornell_box_has_its_groups():
    scene = radiosity.cornell_box()
    assert set(scene.groups) == {"floor", "ceiling", "back_wall", "red_wall", "green_wall", "light",
                                 "short_block", "tall_block"}
    assert len(scene.polygons) == len(scene.polygon_areas()) > 0
    assert "polygons" in repr(scene)


def test_find_inconsistent_winding_names_a_flipped_triangle_of_a_mesh(data_dir):
    # A box exported as a triangle mesh with triangle 13 flipped, on a ground.
    scene = radiosity.load_scene(data_dir / "flipped_face.obj")
    assert radiosity.find_inconsistent_winding(scene) == [13]
    scene.reverse_winding([13])
    assert radiosity.find_inconsistent_winding(scene) == []


def test_reverse_winding_turns_the_polygons_found_facing_outward(data_dir):
    # A room as an exporter writes it: walls and floor wound outwards, a box standing on the
    # floor wound as it should be.
    scene = radiosity.load_scene(data_dir / "messy" / "exported_room.obj")
    found = radiosity.find_polygons_facing_outward(scene)
    assert found == [0, 1, 2, 3, 4, 5]  # the room, not the box's bottom on its floor
    floor_normal = scene.polygons[0].normal.copy()
    np.testing.assert_allclose(floor_normal, [0, -1, 0], atol=1e-6)
    scene.reverse_winding(np.array(found))  # any sequence of ids
    np.testing.assert_allclose(scene.polygons[0].normal, [0, 1, 0], atol=1e-6)
    assert radiosity.find_polygons_facing_outward(scene) == []
    before = [p.vertices.copy() for p in scene.polygons]
    scene.reverse_winding()
    scene.reverse_winding()
    for p, v in zip(scene.polygons, before):
        np.testing.assert_array_equal(p.vertices, v)
    with pytest.raises(radiosity.Error, match="polygon 99 does not exist"):
        scene.reverse_winding([99])

"""solve(): the furnace test on a closed cube, the Cornell box's energy balance, progress,
cancel and errors."""
from pathlib import Path

import numpy as np
import pytest

import radiosity
from conftest import unit_cube_arrays

EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "scenes"


def test_furnace_closed_cube_gives_e_over_1_minus_rho():
    vertices, faces, _ = unit_cube_arrays()
    scene = radiosity.Scene(vertices, faces, reflectance=[0.5, 0.6, 0.7], emission=[1.0, 2.0, 3.0])
    solution = radiosity.solve(scene, "gauss-seidel", tolerance=1e-7, max_patch_area=0.25)
    assert solution.status == "converged"
    expected = np.array([1.0, 2.0, 3.0]) / (1 - np.array([0.5, 0.6, 0.7]))
    b = solution.polygon_radiosity()
    assert b.shape == (6, 3)
    np.testing.assert_allclose(b, np.tile(expected, (6, 1)), rtol=1e-3)
    e = solution.element_radiosity()
    assert e.shape == (len(solution.element_areas()), 3)
    np.testing.assert_allclose(e, np.tile(expected, (len(e), 1)), rtol=1e-3)
    assert solution.element_areas().sum() == pytest.approx(6.0)


def test_cornell_box_solution_is_finite_and_balances_energy():
    scene = radiosity.cornell_box()
    phases = []
    solution = radiosity.solve(scene, progress=lambda p: phases.append(p["phase"]))
    assert solution.status == "converged"
    assert solution.method in ("gauss-seidel", "hierarchical")
    assert solution.iterations > 0 and solution.residual < 1e-3 and solution.seconds > 0
    assert "form_factors" in phases
    b = solution.polygon_radiosity()
    assert b.shape == (len(scene.polygons), 3)
    assert np.all(np.isfinite(b)) and np.all(b >= 0)
    is_light = scene.polygon_group_ids() == scene.groups.index("light")
    assert b[is_light].sum(axis=1).min() > 10 * b[~is_light].sum(axis=1).max()
    np.testing.assert_allclose(solution.group_radiosity("light"), b[is_light][0], rtol=1e-3)
    # Emitted = absorbed + escaped (the box is open at the front).
    r = solution.report
    np.testing.assert_allclose(r["emitted_power"], r["absorbed_power"] + r["escaped_power"], rtol=1e-3)
    assert np.all(r["escaped_power"] > 0)
    irradiance = solution.element_values("irradiance")
    assert irradiance.shape == solution.element_radiosity().shape
    assert np.all(solution.element_polygons() < len(scene.polygons))


def test_form_factor_method_names_the_estimator_that_ran_and_none_for_hierarchical():
    scene = radiosity.cornell_box()
    matrix = radiosity.solve(scene, "gauss-seidel", max_patch_area=40000)
    assert matrix.form_factor_method in ("monte-carlo", "ray-cast")
    assert matrix.report["form_factor_method"] == matrix.form_factor_method
    links = radiosity.solve(scene, "hierarchical", max_patch_area=40000)
    assert links.method == "hierarchical"
    assert links.form_factor_method is None
    assert links.report["form_factor_method"] is None
    assert links.report["link_count"] > 0


def test_mesh_vertex_values_on_a_triangle_scene():
    vertices, quads, _ = unit_cube_arrays()
    triangles = np.concatenate([quads[:, [0, 1, 2]], quads[:, [0, 2, 3]]])
    scene = radiosity.Scene(vertices, triangles, reflectance=[0.5] * 3, emission=[1.0] * 3)
    solution = radiosity.solve(scene, tolerance=1e-6, max_patch_area=0.25)
    values = solution.mesh_vertex_values(0)
    assert values.shape == (8, 3)
    np.testing.assert_allclose(values, np.full((8, 3), 2.0), rtol=5e-3)  # interpolated
    assert solution.mesh_triangle_values(0, "irradiance").shape == (12, 3)


def test_progress_can_cancel_and_its_exceptions_propagate(cube):
    vertices, faces, _ = unit_cube_arrays()
    scene = radiosity.Scene(vertices, faces, emission=[1.0] * 3)
    cancelled = radiosity.solve(scene, progress=lambda p: False)
    assert cancelled.status == "cancelled"

    def fail(progress):
        raise KeyError("from the callback")

    with pytest.raises(KeyError, match="from the callback"):
        radiosity.solve(scene, progress=fail)


def test_glazed_window_lets_the_sun_in_by_default_and_not_at_depth_0():
    # The sunlit room with its window glazed: the extended first pass is taken for the glass,
    # and the lights' shadow rays pass the pane (floor B 30.0 in red, 34.6 unglazed); at
    # specular_depth=0 the pane keeps the sun and the sky out (the lamp alone: 2.2).
    scene = radiosity.load_scene(str(EXAMPLES / "sunlit_room_glazed.json"))
    default = radiosity.solve(scene, max_patch_area=0.5)
    assert default.report["specular_depth"] == 1
    assert default.report["specular_depth_choice"] == "1 (automatic: the scene has mirror or glass materials)"
    assert default.form_factor_method == "monte-carlo"
    assert 25 < default.group_radiosity("floor")[0] < 40
    classic = radiosity.solve(scene, max_patch_area=0.5, specular_depth=0)
    assert classic.report["specular_depth"] == 0
    assert classic.report["specular_depth_choice"] == ""
    assert 1 < classic.group_radiosity("floor")[0] < 3.5
    # A hierarchical solve carries no specular paths: it is left at 0.
    links = radiosity.solve(scene, "hierarchical", max_patch_area=0.5).report
    assert links["specular_depth"] == 0
    assert links["specular_depth_choice"].startswith("0 (automatic: the hierarchical links carry no")


def test_solve_errors():
    scene = radiosity.cornell_box()
    with pytest.raises(radiosity.Error, match="tolerance") as info:
        radiosity.solve(scene, tolerance=-1.0)
    assert info.value.code == "invalid_argument"
    with pytest.raises(ValueError, match="method"):
        radiosity.solve(scene, "newton")
    with pytest.raises(ValueError, match="quantity"):
        radiosity.solve(radiosity.Scene(*unit_cube_arrays()[:2], emission=[1.0] * 3),
                        max_patch_area=1.0).polygon_values("heat")


def test_concurrent_solves_from_python_threads_agree():
    # The GIL is released while solving and taken back for the progress callback: two threads
    # solving at once finish, and give what one solve gives.
    import threading

    vertices, faces, _ = unit_cube_arrays()
    emission = np.zeros((6, 3))
    emission[5] = 1.0
    scene = radiosity.Scene(vertices, faces, emission=emission)
    reference = radiosity.solve(scene, max_patch_area=0.25, threads=1).element_radiosity()
    results, calls = [None, None], [0, 0]

    def work(k):
        def count(progress):
            calls[k] += 1

        results[k] = radiosity.solve(scene, max_patch_area=0.25, threads=1, progress=count).element_radiosity()

    threads = [threading.Thread(target=work, args=(k,)) for k in range(2)]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    for k in range(2):
        assert calls[k] > 0
        np.testing.assert_array_equal(results[k], reference)


def test_turned_buildings_sliver_stays_within_the_sky_and_hierarchical_agrees_with_gauss_seidel(tmp_path):
    """An exported block with its buildings turned (benchmarks/exported_block.py --turn): the
    ground is cut along the buildings' feet, which leaves slivers of ground open beside them and
    pieces wholly under them. Until session 39 the hierarchical solver gave one sliver 402 W/m^2
    under a sky of 100 (Gauss-Seidel: 62), what a link into its mostly buried cluster brought,
    pushed by 1 / exposure; its element RMS against Gauss-Seidel was 10 %. Until session 41 the
    slivers under 1 m^2 were 6.7 % off (the rest 1.4 %): they shared leaf clusters with the
    buried pieces beside them, which the cluster tree now leaves out. Measured against the mean
    of 8 Gauss-Seidel solves: 1.35 % element RMS (power over area), the slivers 1.7 %."""
    import subprocess
    import sys
    script = Path(__file__).resolve().parents[2] / "benchmarks" / "exported_block.py"
    subprocess.run([sys.executable, str(script), "--turn", str(tmp_path)], check=True, capture_output=True)
    scene = radiosity.load_scene(tmp_path / "daylight.json")

    def power_over_area(solution):
        return solution.element_radiosity().mean(axis=1) * solution.element_exposure()

    # The reference: the mean of 4 Gauss-Seidel solves with their own seeds (one solve's element
    # spread is about 1 %, the mean's half of it).
    references = []
    for seed in range(2, 6):
        solution = radiosity.solve(scene, "gauss-seidel", form_factors="monte-carlo", seed=seed)
        irradiance = solution.element_values("irradiance").mean(axis=1)
        assert irradiance.max() < 1.2 * 100.0  # the sky's horizontal irradiance is 100 W/m^2
        references.append(power_over_area(solution))
    reference = np.mean(references, axis=0)
    solution = radiosity.solve(scene, "hierarchical", epsilon=0.05)
    assert solution.element_values("irradiance").mean(axis=1).max() < 1.2 * 100.0
    areas = solution.element_areas()
    kept = reference > 0.1 * reference.mean()
    relative = (power_over_area(solution) - reference) / np.where(kept, reference, 1.0)
    slivers = kept & (areas < 1.0)
    assert slivers.sum() > 100
    assert np.sqrt(np.mean(relative[kept] ** 2)) < 0.02
    assert np.sqrt(np.mean(relative[slivers] ** 2)) < 0.035

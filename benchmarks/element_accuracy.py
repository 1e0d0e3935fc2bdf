#!/usr/bin/env python3
"""Element accuracy of the solvers on any scene file, against the mean of independent solves.

The reference is the mean of K Gauss-Seidel solves over Monte Carlo rows, each with its own seed
(so the lights' first shot and the rows are independent draws): its own error is one solve's
spread over sqrt(K), printed, and taken out of the figures in quadrature. Then each method named
solves once (seed 1) and prints its wall time, the element RMS relative difference to the
reference over the elements whose reference exceeds a tenth of the mean (power over area,
radiosity x exposure, in luminance: the mean of the three channels), and the area-weighted
mean's difference.

    PYTHONPATH=build/python python3 benchmarks/element_accuracy.py SCENE --max-element-area 1 \\
        --reference-solves 12 --methods gauss-seidel,hierarchical:0.05,hierarchical:0.02,auto

Used for the automatic method choice on a finely meshed exported block (docs/HIERARCHICAL.md,
"The automatic method choice"). Times are wall times of one run each: compare them as ratios on
a quiet machine.
"""
import argparse
import time

import numpy as np

import radiosity


def luminance(solution):
    """Power over area per element (radiosity x exposure, luminance: the mean of the channels).

    A partly buried element's radiosity is its open part's, over an exposure each solve estimates
    itself (docs/HIERARCHICAL.md, "Buried parts"): the ground under a turned building's edge,
    an eighth open, then differs by several times between two solves that agree on its power.
    """
    return solution.element_radiosity().mean(axis=1) * solution.element_exposure()


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("scene")
    parser.add_argument("--max-element-area", type=float, default=0.0)
    parser.add_argument("--reference-solves", type=int, default=12, help="K, at least 2")
    parser.add_argument("--methods", default="gauss-seidel,hierarchical:0.05,auto",
                        help="comma-separated: gauss-seidel, hierarchical[:EPSILON], auto")
    parser.add_argument("--save-reference", help="write the K solves' element luminance (.npy)")
    parser.add_argument("--reference", help="read them instead of solving")
    a = parser.parse_args()
    scene = radiosity.load_scene(a.scene)

    if a.reference:
        solves = np.load(a.reference)
    else:
        solves = []
        for k in range(a.reference_solves):
            t = time.time()
            s = radiosity.solve(scene, method="gauss-seidel", form_factors="monte-carlo", seed=101 + k,
                                tolerance=1e-5, max_element_area=a.max_element_area)
            solves.append(luminance(s))
            print(f"reference solve {k + 1}/{a.reference_solves}: {time.time() - t:.1f} s", flush=True)
        solves = np.array(solves)
        if a.save_reference:
            np.save(a.save_reference, solves)
    k = len(solves)
    if k < 2:
        raise SystemExit("element_accuracy: at least 2 reference solves")
    ref = solves.mean(axis=0)
    kept = ref > 0.1 * ref.mean()
    spread = np.sqrt(np.mean((solves[:, kept] - ref[kept]) ** 2 / ref[kept] ** 2) * k / (k - 1))
    own = spread / np.sqrt(k)
    print(f"{kept.sum()} of {len(ref)} elements above a tenth of the mean; one solve's RMS spread "
          f"{100 * spread:.2f} %, the reference's own error {100 * own:.2f} %")

    for name in a.methods.split(","):
        method, _, epsilon = name.partition(":")
        options = {"method": method}
        if method == "gauss-seidel":
            options["form_factors"] = "monte-carlo"
        if epsilon:
            options["epsilon"] = float(epsilon)
        t = time.time()
        s = radiosity.solve(scene, max_element_area=a.max_element_area, **options)
        seconds = time.time() - t
        value = luminance(s)
        if len(value) != len(ref):
            raise SystemExit(f"element_accuracy: {name} has {len(value)} elements, the reference {len(ref)}")
        rel = (value[kept] - ref[kept]) / ref[kept]
        rms = np.sqrt(np.mean(rel ** 2))
        area = s.element_areas()
        mean = np.sum(area * value) / np.sum(area * ref) - 1.0
        print(f"{name}: {seconds:.1f} s ({s.method}), element RMS {100 * rms:.2f} % "
              f"({100 * np.sqrt(max(rms ** 2 - own ** 2, 0.0)):.2f} % without the reference's own error), "
              f"area-weighted mean {100 * mean:+.2f} %", flush=True)


if __name__ == "__main__":
    main()

"""Refinement from Python: Model.refine carries the solution to the children exactly, adaptive
solves (by the error estimate and by stress) report their rounds, octree meshing fills the same
volume with fewer elements, and bad requests raise polydg.Error."""
import os

import numpy as np
import pytest

import polydg

TESTDATA = os.environ["POLYDG_TESTDATA"]
BEAM = os.path.join(TESTDATA, "beam.obj")  # [0, 10] x [0, 1] x [0, 1]
LOADS = {"E": 1000, "nu": 0.3, "clamp": [{"plane": [1, 0, 0, 0]}],
         "traction": [{"plane": [1, 0, 0, 10], "traction": [0, 0, -1]}]}


def beam():
    return polydg.mesh(polydg.read_surface(BEAM), cells=10)


@pytest.mark.parametrize("split", ["octants", "halves"])
def test_refine_keeps_the_solution_and_the_volume(split):
    model = beam()
    model.solve(degree=2, **LOADS)
    volume, n = model.element_volumes.sum(), model.num_elements
    displacement = model.element_displacements.copy()
    report = model.refine([0, 3, 9], split=split, validate="full")
    children = 8 if split == "octants" else 2
    assert model.num_elements == n + 3 * (children - 1)
    assert report["solution_exact"] == model.num_elements
    assert abs(model.element_volumes.sum() - volume) < 1e-12 * volume
    # Every child's mean displacement is its parent's polynomial's mean over the child: the
    # volume-weighted means of the children give the parent's.
    assert model.element_displacements is not None
    total = (model.element_displacements * model.element_volumes[:, None]).sum(axis=0)
    before = (displacement * (volume / n)).sum(axis=0)
    assert np.abs(total - before).max() < 1e-10 * np.abs(before).max()


def test_adaptive_solves_report_their_rounds():
    model = beam()
    report = model.solve(degree=1, adapt={"by": "stress", "split": "halves", "max_rounds": 2},
                         **LOADS)
    rounds = report["adapt"]["rounds"]
    assert report["adapt"]["criterion"] == "stress" and len(rounds) == 3
    assert rounds[0]["elements"] == 10 and rounds[-1]["elements"] == model.num_elements
    assert rounds[-1]["stop"] is not None and rounds[0]["marked"] > 0
    model = beam()
    report = model.solve(degree=2, adapt={"target_error": 0.2, "max_rounds": 4}, **LOADS)
    rounds = report["adapt"]["rounds"]
    assert rounds[-1]["relative_estimate"] <= 0.2 or len(rounds) == 5
    assert all(r["estimate"] > 0 for r in rounds)
    assert report["estimate"]["total"] == pytest.approx(rounds[-1]["estimate"])


def test_octree_meshing_fills_the_volume_with_fewer_elements():
    surface = polydg.read_surface(os.path.join(TESTDATA, "ball.obj"))
    uniform = polydg.mesh(surface, cells=24)
    octree = polydg.mesh(surface, cells=24, adaptive=True)
    assert octree.num_elements < uniform.num_elements
    assert octree.report["octree"]["levels"] >= 2
    v = uniform.element_volumes.sum()
    assert abs(octree.element_volumes.sum() - v) < 1e-10 * v


def test_bad_requests_raise():
    model = beam()
    with pytest.raises(polydg.Error):
        model.refine([10**6])
    with pytest.raises(polydg.Error):
        model.refine([1, 1])
    with pytest.raises(polydg.Error):
        model.refine([1], split="thirds")
    with pytest.raises(polydg.Error):
        model.refine([1], split="halves")  # no solution to take the directions from
    with pytest.raises(polydg.Error):
        model.solve(degree=1, adapt={"by": "stress", "bulk": 2}, **LOADS)
    assert model.num_elements == 10


def test_coarsen_merges_the_children_back_keeping_the_integral():
    model = beam()
    model.solve(degree=1, **LOADS)
    box_min, box_max = np.array([4, 0, 0]), np.array([5, 1, 1])  # element [4, 5] x [0, 1]^2
    inside = lambda c: bool(np.all(c > box_min) and np.all(c < box_max))
    parent = [e for e, c in enumerate(model.element_centroids) if inside(c)]
    assert len(parent) == 1
    model.refine(parent)
    children = [e for e, c in enumerate(model.element_centroids) if inside(c)]
    assert len(children) == 8
    model.solve(degree=1, **LOADS)  # on the refined mesh: the children differ
    total = (model.element_displacements * model.element_volumes[:, None]).sum(axis=0)
    report = model.coarsen([children], validate="full")
    assert model.num_elements == 10 and report["solution_projected"] == 1
    after = (model.element_displacements * model.element_volumes[:, None]).sum(axis=0)
    assert np.abs(after - total).max() < 1e-12 * np.abs(total).max()
    with pytest.raises(polydg.Error):
        model.coarsen([[0]])

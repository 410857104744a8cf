"""The MLS embedding from Python: the weights W as a scipy-free sparse triple that maps the DG
coefficients to the surface's displacement, the deformed surface as arrays, and a scene with an
embedded surface and obstacles (contacts reported, the deformed surface in the time series,
readable by VTK)."""
import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import vtk

import polydg

TESTDATA = os.environ["POLYDG_TESTDATA"]
BEAM = os.path.join(TESTDATA, "beam.obj")  # [0, 10] x [0, 1] x [0, 1]
MATERIAL = {"E": 1000, "nu": 0.3, "density": 1}


def solved_beam(degree):
    """The beam, clamped at x = 0, under its weight; the model and the solve's report."""
    model = polydg.mesh(polydg.read_surface(BEAM), cells=10)
    report = model.solve(degree=degree, E=1000, nu=0.3, gravity=[0, 0, -1],
                         clamp=[{"plane": [1, 0, 0, 0]}])
    return model, report


@pytest.mark.parametrize("degree", [1, 2])
def test_the_weights_map_the_coefficients_to_the_deformed_surface(degree):
    model, report = solved_beam(degree)
    w = model.embedding_weights()  # the surface the mesh was sliced from
    assert w["surface"] == BEAM and w["degree"] == degree
    points, triangles = w["points"], w["triangles"]
    assert points.shape[1] == 3 and triangles.shape[1] == 3 and triangles.max() < len(points)
    coefficients = model.coefficients
    assert w["shape"] == (3 * len(points), len(coefficients))
    assert w["rows"].dtype == np.int64 and w["values"].dtype == np.float64
    u = np.zeros(w["shape"][0])
    np.add.at(u, w["rows"], w["values"] * coefficients[w["cols"]])
    deformed = model.deformed_surface()
    assert np.array_equal(deformed["points"], points)
    assert np.abs(u.reshape(-1, 3) - deformed["displacement"]).max() < 1e-12 * np.abs(u).max()
    # The free end sags as a cantilever under its weight q = 1 should (Timoshenko: q L^4 / 8EI +
    # q L^2 / 2kGA = 15.16): measured 2026-12-04 at the beam's 4 end corners -16.786 (+10.8%,
    # p = 1: one element through the thickness, and the IP lambda lifting on the clamp's
    # triangles, which also bends it sideways) and -14.921 (-1.6%, p = 2).
    tip = points[:, 0] > 9.99
    assert tip.sum() == 4
    g = 1000 / 2.6
    timoshenko = 10**4 / (8 * 1000 / 12) + 10**2 / (2 * 5 / 6 * g)
    sag = -deformed["displacement"][tip, 2].mean()
    assert abs(sag / timoshenko - 1) < {1: 0.12, 2: 0.02}[degree], (sag, timoshenko)
    # The surface rides on the mesh: at the corners, which are mesh vertices too, the MLS fit
    # and the mesh's vertex means (eq. 17) agree (measured 0 and 1.4e-6 relative).
    mesh = model.to_meshio()
    corners = mesh.points[:, 0] == 10
    assert abs(mesh.point_data["displacement"][corners, 2].mean() / sag + 1) < 1e-5
    # Clapeyron: the energy 1/2 u.F is half the work of gravity on the element means.
    work = -(model.element_volumes * model.element_displacements[:, 2]).sum()
    assert work / 2 == pytest.approx(report["energy"], rel=1e-12)


def test_a_deformed_surface_needs_a_solution():
    model = polydg.mesh(polydg.read_surface(BEAM), cells=10)
    with pytest.raises(polydg.Error, match="solve first"):
        model.deformed_surface()


def test_a_scene_with_an_embedded_surface_and_the_ground(tmp_path):
    model = polydg.mesh(polydg.read_surface(BEAM), cells=10)
    scene = {"material": MATERIAL, "dt": 0.02, "steps": 25, "gravity": [0, 0, -9.81],
             "damping": {"stiffness": 0.01}, "fixed": [],
             "embed": True, "obstacles": [{"below": [0, 0, 1, -0.05]}],
             "contact": {"stiffness": 1e5, "friction": 0.3}, "output": {"every": 5}}
    report = model.simulate(scene, output=tmp_path)
    assert report["embedding"]["surface"] == BEAM
    assert report["embedding"]["weight_nonzeros"] > 0
    assert report["contact"]["points"] == "surface"
    steps = report["steps"]
    touching = [s for s in steps if s["contacts"] > 0]
    assert touching, "the beam never reached the ground"
    assert all(s["deepest_penetration"] >= 0 for s in steps)
    # Energy never grows beyond the work of gravity (the gravity potential is in the total).
    initial = report["initial"]
    e0 = initial["kinetic"] + initial["elastic"] + initial["gravity"]
    for s in steps:
        assert s["kinetic"] + s["elastic"] + s["gravity"] + s["contact_energy"] <= e0 + 1e-9
    # The time series lists the deformed surface beside each mesh frame.
    collection = ET.parse(tmp_path / "scene.pvd").getroot()
    parts = [(d.get("part"), d.get("file")) for d in collection.iter("DataSet")]
    surfaces = [f for part, f in parts if part == "1"]
    assert len(surfaces) == len(report["frames"]) and surfaces[-1].endswith(".vtp")
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(str(tmp_path / surfaces[-1]))
    reader.Update()
    data = reader.GetOutput()
    assert data.GetNumberOfPoints() == report["embedding"]["points"]
    assert data.GetNumberOfPolys() == report["embedding"]["triangles"]
    displacement = data.GetPointData().GetArray("displacement")
    assert displacement.GetNumberOfComponents() == 3
    # The points are the deformed ones: the lowest sits at the ground, within the penetration.
    lowest = min(data.GetPoint(i)[2] for i in range(data.GetNumberOfPoints()))
    assert lowest > -0.05 - 0.05 and lowest < 0.0

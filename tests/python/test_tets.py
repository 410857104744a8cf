"""The tet methods from Python (issue 33): polydg.read of TetGen's and Gmsh's files, Model.solve
and Model.simulate with "fem" and "fs-fem", against closed forms and against the command line's
reports for the same inputs."""
import json
import os
import subprocess

import numpy as np
import pytest

import polydg

TESTDATA = os.environ["POLYDG_TESTDATA"]
POLYDG = os.environ["POLYDG"]
# The unit cube as tets (testdata/cube_tets.geo and .poly): Gmsh's 24 on 14 nodes, TetGen's 68.
FILES = [os.path.join(TESTDATA, name) for name in ("cube_tets.msh", "cube_tets.1.ele")]
TETS = [24, 68]
# Uniaxial tension with nu = 0: u = (t x / E, 0, 0), reproduced exactly by both methods.
E, T = 200.0, 3.0
CLAMP, TRACTION = {"axis": "x", "value": 0}, {"axis": "x", "value": 1, "traction": [T, 0, 0]}


def element_corners(model):
    """Each element's corners (sorted point indices) from the model's face arrays."""
    f = model.faces
    corners = [set() for _ in range(model.num_elements)]
    for face in range(model.num_faces):
        points = f["vertices"][f["loop_offsets"][f["face_loops"][face]]:
                               f["loop_offsets"][f["face_loops"][face + 1]]]
        for e in f["elements"][face]:
            if e >= 0:
                corners[e].update(points.tolist())
    return [sorted(c) for c in corners]


@pytest.mark.parametrize("path, tets", zip(FILES, TETS))
def test_a_tet_mesh_reads_as_a_model_of_its_tets(path, tets):
    model = polydg.read(path)
    assert model.num_elements == tets
    assert model.volume == pytest.approx(1.0, rel=1e-14)
    assert model.report["provenance_restored"] is False


@pytest.mark.parametrize("method", ["fem", "fs-fem"])
def test_solve_gives_the_uniaxial_field_and_the_command_lines_report(method, tmp_path):
    model = polydg.read(FILES[0])
    report = model.solve(method=method, E=E, nu=0, clamp=CLAMP, traction=TRACTION)
    assert report["method"] == method and report["tets"] == 24 and report["nodes"] == 14
    assert "eta" not in report and "max_jump" not in report
    # Element means of a field linear on each tet: t / E times the tets' centroids' x.
    centroids = model.element_centroids
    u = model.element_displacements
    np.testing.assert_allclose(u[:, 0], T / E * centroids[:, 0], rtol=0, atol=1e-14)
    np.testing.assert_allclose(u[:, 1:], 0.0, atol=1e-14)
    assert report["max_displacement"] == pytest.approx(T / E, rel=1e-13)
    assert report["energy"] == pytest.approx(T * T / (2 * E), rel=1e-13)  # sigma^2 V / (2 E)
    # The command line, same input and options: the same figures.
    cli = tmp_path / "cli.json"
    subprocess.run([POLYDG, "solve", FILES[0], "-o", tmp_path / "cli.vtu", "--method", method,
                    "--E", str(E), "--nu", "0", "--clamp", "x=0", "--traction",
                    "x=1:%g,0,0" % T, "--report", cli, "--quiet"], check=True)
    theirs = json.loads(cli.read_text())
    for key in ("method", "tets", "nodes", "held_nodes", "dofs", "nonzeros", "energy",
                "max_displacement", "max_von_mises"):
        assert report[key] == theirs[key], key


def test_dg_options_are_refused_with_a_tet_method():
    model = polydg.read(FILES[0])
    for extra, word in (({"degree": 2}, "degree"), ({"estimate": True}, "estimate"),
                        ({"adapt": True}, "adapt")):
        with pytest.raises(polydg.Error, match=word):
            model.solve(method="fem", clamp=CLAMP, **extra)


def test_a_clamp_that_selects_nothing_is_named():
    model = polydg.read(FILES[0])
    with pytest.raises(polydg.Error, match="the clamp .* selects no boundary face"):
        model.solve(method="fs-fem", clamp={"axis": "x", "value": 7})
    report = model.solve(method="fs-fem", clamp=CLAMP, traction=TRACTION)
    # Gmsh split each side of the cube in 4 triangles about its centre (14 nodes: 8 + 6).
    assert report["clamps"][0]["faces"] == 4 and report["tractions"][0]["faces"] == 4


def test_simulate_moves_the_tets_as_the_command_line_does(tmp_path):
    scene = {"material": {"E": E, "nu": 0.3, "density": 2}, "method": "fs-fem",
             "integrator": "newmark", "dt": 0.01, "steps": 15, "gravity": [0, 0, -9.81],
             "fixed": [CLAMP], "solver": "cholesky"}
    model = polydg.read(FILES[0])
    report = model.simulate(scene)
    assert report["scene"]["method"] == "fs-fem" and len(report["steps"]) == 15
    # The model's solution is the final displacement: each element's mean is its corners'.
    path = tmp_path / "scene.json"
    path.write_text(json.dumps(scene))
    out, cli = tmp_path / "frames", tmp_path / "cli.json"
    subprocess.run([POLYDG, "simulate", FILES[0], "--scene", path, "-o", out, "--report", cli,
                    "--quiet"], check=True)
    theirs = json.loads(cli.read_text())
    for mine, their in zip(report["steps"], theirs["steps"]):
        for key in ("t", "kinetic", "elastic", "gravity", "momentum", "centre_of_mass"):
            assert mine[key] == their[key], key
    import meshio
    last = meshio.read(out / theirs["frames"][-1]["file"])
    nodal = last.point_data["displacement"]
    u = model.element_displacements
    for e, corners in enumerate(element_corners(model)):
        assert len(corners) == 4
        np.testing.assert_allclose(u[e], nodal[corners].mean(axis=0), rtol=0, atol=1e-13)
    assert np.abs(u[:, 2]).max() > 1e-3  # it sagged


def test_a_polyhedral_model_is_refused_by_the_tet_methods():
    model = polydg.mesh(polydg.read_surface(os.path.join(TESTDATA, "cube.obj")), cells=2)
    with pytest.raises(polydg.Error, match="is not a tetrahedron"):
        model.solve(method="fs-fem", clamp=CLAMP)

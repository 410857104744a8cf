"""The Python module over the model API: arrays in and out, reports equal to the command line's
JSON for the same input, one exception per class of bad input."""
import json
import os
import subprocess

import numpy as np
import pytest

import polydg

TESTDATA = os.environ["POLYDG_TESTDATA"]
TORUS = os.path.join(TESTDATA, "torus.obj")
TIMING = ("time_s", "timings_s", "seconds", "wall", "dg_seconds", "read", "write")


def without_timings(value):
    """The report without wall times (they differ from run to run)."""
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items()
                if k not in TIMING and not k.endswith("_seconds")}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


def polydg_cli(*args):
    r = subprocess.run([os.environ["POLYDG"], *args, "--quiet"], capture_output=True, text=True)
    return r.returncode, r.stderr.strip()


def test_a_surface_from_arrays_meshes_as_from_its_file():
    surface = polydg.read_surface(TORUS)
    assert surface.V.shape == (2048, 3) and surface.F.shape == (4096, 3)
    from_file = polydg.mesh(surface, cells=12)
    from_arrays = polydg.mesh(polydg.Surface(surface.V, surface.F), cells=12)
    assert from_arrays.num_elements == from_file.num_elements
    assert from_arrays.volume == from_file.volume
    np.testing.assert_array_equal(from_arrays.points, from_file.points)
    np.testing.assert_array_equal(from_arrays.element_volumes, from_file.element_volumes)
    assert from_file.element_volumes.sum() == pytest.approx(from_file.volume, rel=1e-14)
    assert from_file.element_centroids.shape == (from_file.num_elements, 3)


def test_every_operation_reports_what_the_command_line_reports(tmp_path):
    mesh_json, cut_json, check_json, solve_json = (tmp_path / f"{n}.json" for n in
                                                   ("mesh", "cut", "check", "solve"))
    m, c = tmp_path / "m.vtu", tmp_path / "c.vtu"
    assert polydg_cli("mesh", TORUS, "--cells", "10", "-o", str(m), "--report",
                      str(mesh_json))[0] == 0
    assert polydg_cli("cut", str(m), "-o", str(c), "--plane", "0.3,1,0.2,0.1", "--report",
                      str(cut_json))[0] == 0
    assert polydg_cli("check", str(c), "--report", str(check_json))[0] == 0
    assert polydg_cli("solve", str(c), "-o", str(tmp_path / "s.vtu"), "--degree", "1",
                      "--clamp-below", "0,0,1,-0.2", "--gravity", "0,0,-1", "--report",
                      str(solve_json))[0] == 0

    model = polydg.mesh(polydg.read_surface(TORUS), cells=10, source=TORUS)
    cli_mesh = json.loads(mesh_json.read_text())
    for key in ("grid", "output", "validation", "volume_rel_error"):
        expected = without_timings(cli_mesh[key])
        got = without_timings(model.report[key])
        if key == "output":
            expected.pop("file", None)
            got.pop("file", None)
        assert got == expected, key
    model.write(tmp_path / "py.vtu")
    model = polydg.read(tmp_path / "py.vtu")  # as the CLI's cut reads its input
    cut = model.cut(plane=[0.3, 1, 0.2, 0.1])
    cli_cut = json.loads(cut_json.read_text())["operations"][0]
    # The patch test's residual is a sum at round-off level whose last bit depends on how many
    # threads summed it (a Dask test earlier in the process limits them): equal to 1e-12.
    got_patch = cut["validation"].pop("patch_test_error")
    expected_patch = cli_cut["validation"].pop("patch_test_error")
    assert got_patch == pytest.approx(expected_patch, rel=1e-12, abs=1e-30)
    assert without_timings(cut) == without_timings(cli_cut)
    check = model.check()
    cli_check = json.loads(check_json.read_text())
    assert {k: v for k, v in without_timings(check).items() if k in cli_check} == \
        {k: v for k, v in without_timings(cli_check).items() if k in check}
    # The same input as the command: the cut mesh as written (an edited model's moments are
    # summed from its faces in another order, equal to the last bit or two).
    solve = polydg.read(c).solve(degree=1, clamp={"below": [0, 0, 1, -0.2]}, gravity=[0, 0, -1])
    cli_solve = json.loads(solve_json.read_text())
    for key in ("dofs", "dirichlet_faces", "nonzeros"):
        assert solve[key] == cli_solve[key], key
    # CHOLMOD's factorization runs OpenBLAS kernels chosen per process (the command sets
    # OPENBLAS_CORETYPE for this CPU; a Python process keeps OpenBLAS's own choice): the same
    # figures to round-off. This checks that the two front ends agree; the figures themselves
    # are checked against closed forms in test_uniaxial_bar.py (a bar in tension, both front
    # ends) and tests/model/model_test.cpp (a column under its own weight).
    for key in ("energy", "max_displacement", "max_von_mises", "max_jump"):
        assert solve[key] == pytest.approx(cli_solve[key], rel=1e-12), key


def test_each_class_of_bad_input_raises_one_line():
    surface = polydg.read_surface(TORUS)
    cases = [
        (lambda: polydg.read_surface("/nonexistent/x.obj"), polydg.Error, "x.obj"),
        (lambda: polydg.Surface(np.zeros((3, 2)), np.zeros((1, 3), dtype=np.int64)),
         polydg.Error, "n x 3"),
        (lambda: polydg.Surface(np.zeros((3, 3)), np.array([[0, 1, 5]])), polydg.Error,
         "refers to vertex 5"),
        (lambda: polydg.Surface(np.array([[0, 0, np.nan]] * 3), np.array([[0, 1, 2]])),
         polydg.Error, "not finite"),
        (lambda: polydg.mesh(surface), polydg.Error, "exactly one of"),
        (lambda: polydg.mesh(surface, cells=4, repair="glue"), polydg.Error, "'glue'"),
        (lambda: polydg.mesh(polydg.Surface(np.eye(3), np.array([[0, 1, 2]])), cells=4),
         polydg.Error, "closed"),
        (lambda: polydg.read("/nonexistent/m.vtu"), polydg.Error, "m.vtu"),
    ]
    for call, kind, words in cases:
        with pytest.raises(kind) as caught:
            call()
        assert words in str(caught.value) and "\n" not in str(caught.value), str(caught.value)

    model = polydg.mesh(surface, cells=6)
    with pytest.raises(polydg.Error, match="nothing holds the body"):
        model.solve(gravity=[0, 0, -1])
    with pytest.raises(polydg.Error, match="selects no boundary face"):
        model.solve(clamp={"below": [0, 0, 1, -5]})
    with pytest.raises(polydg.Error, match="plane"):
        model.cut(plane=[0, 0, 0, 1])
    with pytest.raises(polydg.CheckFailure, match="left no element"):
        model.cut(plane=[0, 0, 1, 5], remove_side="-")
    assert issubclass(polydg.CheckFailure, polydg.Error)


def test_progress_is_reported():
    seen = []
    polydg.mesh(polydg.read_surface(TORUS), cells=16, progress=seen.append)
    assert seen and 0.0 <= min(seen) and max(seen) <= 1.0 and seen == sorted(seen)


def test_a_progress_callback_that_raises_stops_the_meshing_with_its_own_exception():
    class Stop(Exception):
        pass

    calls = []

    def stop(fraction):
        calls.append(fraction)
        raise Stop(f"stopped at {fraction}")

    with pytest.raises(Stop, match="stopped at"):
        polydg.mesh(polydg.read_surface(TORUS), cells=16, progress=stop)
    assert len(calls) == 1  # the first call stopped it


def test_faces_and_solution_arrays():
    model = polydg.mesh(polydg.read_surface(TORUS), cells=8)
    faces = model.faces
    points = model.points
    assert faces["face_loops"][-1] == len(faces["loop_offsets"]) - 1
    assert faces["loop_offsets"][-1] == len(faces["vertices"])
    assert faces["elements"].shape == (model.num_faces, 2)
    # The divergence theorem over the faces' loops: the volume of the mesh.
    volume = 0.0
    front = faces["elements"][:, 0]
    for f in range(model.num_faces):
        for j in range(faces["face_loops"][f], faces["face_loops"][f + 1]):
            loop = points[faces["vertices"][faces["loop_offsets"][j]:faces["loop_offsets"][j + 1]]]
            area = sum(np.cross(loop[i] - loop[0], loop[i + 1] - loop[0])
                       for i in range(1, len(loop) - 1))
            scale = 1.0 if faces["elements"][f, 1] < 0 else 0.0  # interior faces cancel
            volume += scale * np.dot(area, loop[0]) / 6.0
    assert volume == pytest.approx(model.volume, rel=1e-12)
    assert (front >= 0).all()

    assert model.element_displacements is None
    model.solve(degree=1, gravity=[0, 0, -1], clamp={"below": [0, 0, 1, -0.2]})
    u = model.element_displacements
    assert u.shape == (model.num_elements, 3) and (u[:, 2] <= 1e-12).all()
    assert model.element_von_mises.shape == (model.num_elements,)


def test_bz_superpenalty_is_chosen_by_name_and_does_not_depend_on_the_models_scale():
    # The superpenalty's factor (L/h)^(2p) is dimensionless: the same surface scaled by 1e-6
    # (at the origin) and by 1e6 (moved 3e6 away) gives the same factor.
    surface = polydg.read_surface(TORUS)
    factors = []
    for scale, offset in ((1.0, 0.0), (1e-6, 0.0), (1e6, 3e6)):
        s = polydg.Surface(surface.V * scale + offset, surface.F)
        model = polydg.mesh(s, cells=4)
        lowest = float(np.min(s.V[:, 2]))
        height = float(np.ptp(s.V[:, 2]))
        report = model.solve(method="bz", bz_penalty="super", degree=2, gravity=[0, 0, -1],
                             clamp={"below": [0, 0, 1, lowest + 0.2 * height]})
        assert report["bz_penalty"] == "super"
        factors.append(report["bz_factor"])
    assert factors[0] > 1.0
    assert factors[1] == pytest.approx(factors[0], rel=1e-9)
    assert factors[2] == pytest.approx(factors[0], rel=1e-9)

    model = polydg.mesh(surface, cells=4)
    clamp = {"below": [0, 0, 1, float(np.min(surface.V[:, 2])) + 0.2]}
    with pytest.raises(polydg.Error, match="'huge'") as caught:
        model.solve(method="bz", bz_penalty="huge", clamp=clamp)
    assert "\n" not in str(caught.value)
    with pytest.raises(polydg.Error, match="for the BZ method"):
        model.solve(bz_penalty="super", clamp=clamp)

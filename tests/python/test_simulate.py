"""Model.simulate() from Python: scenes as dicts or files, the report as a dict, the progress
callback (called without holding up the run, and able to stop it), the time series on disk and
the model's state afterwards."""
import json
import os
import pathlib

import numpy as np
import pytest

import polydg

TESTDATA = os.environ["POLYDG_TESTDATA"]
BEAM = os.path.join(TESTDATA, "beam.obj")  # [0, 10] x [0, 1] x [0, 1]
BEAM_CUT_SCENE = os.path.join(TESTDATA, os.pardir, "examples", "scenes", "beam_cut.json")
MATERIAL = {"E": 1000, "nu": 0.3, "density": 1}
DT, STEPS, G = 0.01, 20, -9.81
# CHOLMOD: the fall then follows backward Euler to round-off (CG, the default for corotated
# steps, to its tolerance: 1.2e-9 of the displacement here).
FREE_FALL = {"material": MATERIAL, "dt": DT, "steps": STEPS, "gravity": [0, 0, G], "fixed": [],
             "solver": "cholesky"}
TIMING = ("seconds", "timings_s", "time_s")


def beam():
    return polydg.mesh(polydg.read_surface(BEAM), cells=20)


def without_timings(value):
    if isinstance(value, dict):
        return {k: without_timings(v) for k, v in value.items()
                if k not in TIMING and not k.endswith("_seconds")}
    if isinstance(value, list):
        return [without_timings(v) for v in value]
    return value


def test_a_free_fall_follows_backward_euler_exactly():
    model = beam()
    mass = model.volume * MATERIAL["density"]
    assert mass == pytest.approx(10.0, rel=1e-12)
    report = model.simulate(FREE_FALL)

    assert report["elements"] == model.num_elements and report["dofs"] > 0
    assert report["scene"]["dt"] == DT and report["frames"] == [] and report["pvd"] is None
    steps = report["steps"]
    assert len(steps) == STEPS
    z0 = report["initial"]["centre_of_mass"][2]
    assert z0 == pytest.approx(0.5, rel=1e-12)
    for n, step in enumerate(steps, start=1):
        t = n * DT
        assert step["t"] == pytest.approx(t, rel=1e-12)
        # Backward Euler: v_n = n dt g, x_n = x_0 + dt^2 g n (n + 1) / 2, exactly (a free body
        # under gravity does not deform).
        assert step["centre_of_mass"][2] - z0 == pytest.approx(G * DT**2 * n * (n + 1) / 2,
                                                               rel=1e-9)
        assert step["momentum"][2] == pytest.approx(G * t * mass, rel=1e-9)
        assert step["momentum"][0] == pytest.approx(0, abs=1e-9)
        assert step["momentum"][1] == pytest.approx(0, abs=1e-9)
        assert step["centre_of_mass"][:2] == pytest.approx([5.0, 0.5], rel=1e-12)
        assert step["kinetic"] == pytest.approx(0.5 * mass * (G * t) ** 2, rel=1e-9)
        assert step["elastic"] == pytest.approx(0, abs=1e-9)
    assert steps[-1]["centre_of_mass"][2] - z0 == pytest.approx(G * DT**2 * STEPS * (STEPS + 1) / 2,
                                                                rel=1e-9)

    # The model keeps the final displacement as its solution: the same everywhere.
    u = model.element_displacements
    assert u.shape == (model.num_elements, 3)
    np.testing.assert_allclose(u[:, 2], G * DT**2 * STEPS * (STEPS + 1) / 2, rtol=1e-9)
    np.testing.assert_allclose(u[:, :2], 0, atol=1e-9)
    assert model.element_von_mises.shape == (model.num_elements,)


def test_a_scene_file_runs_as_its_dict(tmp_path):
    path = tmp_path / "fall.json"
    path.write_text(json.dumps(FREE_FALL))
    from_dict = without_timings(beam().simulate(FREE_FALL))
    assert without_timings(beam().simulate(path)) == from_dict  # os.PathLike
    assert without_timings(beam().simulate(str(path))) == from_dict


def test_a_bad_scene_is_refused_naming_the_key():
    model = beam()
    cases = [
        ({"material": MATERIAL, "dt": 0.1, "steps": 1, "gravty": [0, 0, -1]}, ["gravty"]),
        ({"material": MATERIAL, "dt": 0.1, "steps": 1, "duration": 1}, ["duration", "steps"]),
        ({"material": MATERIAL, "dt": -0.1, "steps": 1}, ["scene: dt"]),
        ({"material": MATERIAL, "dt": float("nan"), "steps": 1}, ["not finite"]),
        ({"dt": 0.1, "steps": 1}, ["material"]),
        ([1, 2], ["scene"]),
        ("/nonexistent/scene.json", ["/nonexistent/scene.json"]),
        ({"material": MATERIAL, "dt": 0.1, "steps": 1, "fixed": [{"below": [0, 0, 1, -5]}]},
         ["selects no boundary face"]),
    ]
    for scene, words in cases:
        with pytest.raises(polydg.Error) as caught:
            model.simulate(scene)
        message = str(caught.value)
        assert all(w in message for w in words) and "\n" not in message, message
        assert not isinstance(caught.value, polydg.CheckFailure), message
    with pytest.raises(TypeError, match="progress"):
        model.simulate(FREE_FALL, progress=3)
    # Nothing ran: the model is as it was.
    assert model.element_displacements is None
    assert model.simulate(FREE_FALL)["steps"][-1]["t"] == pytest.approx(STEPS * DT)


def test_progress_is_called_after_each_step():
    seen = []
    report = beam().simulate(FREE_FALL, progress=lambda *args: seen.append(args))
    assert [s for s, _, _ in seen] == list(range(1, STEPS + 1))
    assert all(n == STEPS for _, n, _ in seen)
    assert [t for _, _, t in seen] == [s["t"] for s in report["steps"]]


def test_an_exception_in_the_progress_callback_stops_the_run():
    class Stop(Exception):
        pass

    seen = []

    def stop_at_3(step, steps, t):
        seen.append(step)
        if step == 3:
            raise Stop(f"stopped at {step} of {steps}")

    model = beam()
    with pytest.raises(Stop, match="stopped at 3 of 20"):
        model.simulate(FREE_FALL, progress=stop_at_3)
    assert seen == [1, 2, 3]
    # The model was not broken by the interruption: it runs again.
    assert len(model.simulate(FREE_FALL)["steps"]) == STEPS


def test_the_time_series_is_written(tmp_path):
    import meshio  # a test requirement (Debian's python3-meshio), as in the README's example

    out = tmp_path / "series"
    scene = dict(FREE_FALL, output={"every": 5})
    report = beam().simulate(scene, output=out)
    assert report["pvd"] == str(out / "scene.pvd")
    pvd = (out / "scene.pvd").read_text()
    frames = report["frames"]
    assert [f["step"] for f in frames] == [0, 5, 10, 15, 20]
    for frame in frames:
        assert f'file="{frame["file"]}"' in pvd
        mesh = meshio.read(out / frame["file"])
        u, v = mesh.point_data["displacement"], mesh.point_data["velocity"]
        assert u.shape == v.shape == (len(mesh.points), 3)
        n = frame["step"]
        np.testing.assert_allclose(u[:, 2], G * DT**2 * n * (n + 1) / 2, atol=1e-9)
        np.testing.assert_allclose(v[:, 2], G * DT * n, atol=1e-9)
    assert sorted(p.name for p in out.iterdir()) == sorted(["scene.pvd"] +
                                                           [f["file"] for f in frames])


def test_the_example_cut_scene_runs_from_its_file(tmp_path):
    model = beam()
    before = model.num_elements
    report = model.simulate(pathlib.Path(BEAM_CUT_SCENE))
    assert len(report["cuts"]) == 1
    cut = report["cuts"][0]
    assert cut["operation"]["validation"]["passed"] is True
    assert cut["time"] == pytest.approx(1.0)
    assert cut["elements_before"] == before == report["elements"]
    assert model.num_elements == cut["elements_after"] > before
    assert len(report["steps"]) == 60  # duration 3 / dt 0.05
    assert model.element_displacements.shape == (model.num_elements, 3)
    assert model.write(tmp_path / "after.vtu")["with_solution"] is True

"""A bar in uniaxial tension against its closed form, from Python and from the command line:
[0, 4] x [0, 1] x [0, 1], E = 1000, nu = 0, clamped at x = 0, traction (10, 0, 0) at x = 4.
The exact solution u = (sigma / E) (x, 0, 0), sigma = 10, is linear, so IP DG of any degree
reproduces it to round-off: end displacement 0.04, von Mises 10 in every element, no jump
between elements, energy sigma^2 / (2 E) x volume = 0.2. (With nu = 0 the clamp on the whole
face x = 0 does not constrain a lateral contraction: there is none.)"""
import json
import os
import subprocess

import numpy as np
import pytest

import polydg

LENGTH, E, SIGMA = 4.0, 1000.0, 10.0
STRAIN = SIGMA / E
END_DISPLACEMENT = STRAIN * LENGTH  # 0.04
ENERGY = 0.5 * SIGMA * STRAIN * LENGTH  # 0.2 (unit cross-section)
# Round-off, relative to the figure: measured 2.2e-14 at most (the element displacements, p = 2;
# the stresses 1.3e-14, the end displacement 8.4e-15, the energy 2e-15, the largest jump 1.7e-15
# of the end displacement).
ROUNDOFF = 1e-13


def bar_surface():
    """The box [0, 4] x [0, 1] x [0, 1], two outward triangles per side."""
    points = np.array([[x, y, z] for x in (0, LENGTH) for y in (0, 1) for z in (0, 1)], float)
    # Point 4 ix + 2 iy + iz.
    triangles = np.array([[0, 1, 3], [0, 3, 2], [4, 6, 7], [4, 7, 5], [0, 4, 5], [0, 5, 1],
                          [2, 3, 7], [2, 7, 6], [0, 2, 6], [0, 6, 4], [1, 5, 7], [1, 7, 3]])
    return polydg.Surface(points, triangles)


def expect_closed_form(report):
    assert report["max_displacement"] == pytest.approx(END_DISPLACEMENT, rel=ROUNDOFF)
    assert report["max_von_mises"] == pytest.approx(SIGMA, rel=ROUNDOFF)
    assert report["max_jump"] <= ROUNDOFF * END_DISPLACEMENT
    assert report["energy"] == pytest.approx(ENERGY, rel=ROUNDOFF)


@pytest.mark.parametrize("degree", [1, 2])
def test_a_bar_in_uniaxial_tension_has_its_closed_form_solution(degree):
    model = polydg.mesh(bar_surface(), cells=8)
    assert model.num_elements == 32 and model.volume == pytest.approx(LENGTH, rel=1e-15)
    report = model.solve(degree=degree, E=E, nu=0, clamp=[{"plane": [1, 0, 0, 0]}],
                         traction=[{"plane": [1, 0, 0, LENGTH], "traction": [SIGMA, 0, 0]}])
    expect_closed_form(report)
    # Every element: von Mises 10, and its mean displacement the exact field at its centroid.
    np.testing.assert_allclose(model.element_von_mises, SIGMA, rtol=ROUNDOFF)
    exact = np.zeros((model.num_elements, 3))
    exact[:, 0] = STRAIN * model.element_centroids[:, 0]
    np.testing.assert_allclose(model.element_displacements, exact, rtol=0,
                               atol=ROUNDOFF * END_DISPLACEMENT)


def test_the_command_line_solves_the_bar_to_the_same_closed_form(tmp_path):
    surface = bar_surface()
    obj = tmp_path / "bar.obj"
    obj.write_text("".join(f"v {x} {y} {z}\n" for x, y, z in surface.V) +
                   "".join(f"f {a + 1} {b + 1} {c + 1}\n" for a, b, c in surface.F))
    polydg_binary = os.environ["POLYDG"]
    for args in (["mesh", str(obj), "--cells", "8", "-o", str(tmp_path / "bar.vtu")],
                 ["solve", str(tmp_path / "bar.vtu"), "-o", str(tmp_path / "solved.vtu"),
                  "--degree", "1", "--E", "1000", "--nu", "0", "--clamp", "x=0",
                  "--traction", "x=4:10,0,0", "--report", str(tmp_path / "solve.json")]):
        run = subprocess.run([polydg_binary, *args, "--quiet"], capture_output=True, text=True)
        assert run.returncode == 0, run.stderr
    expect_closed_form(json.loads((tmp_path / "solve.json").read_text()))

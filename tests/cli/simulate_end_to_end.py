#!/usr/bin/env python3
"""`polydg simulate`'s scene keys end to end through the binary, each against a closed form:
a free body's momentum, angular momentum and centre of mass, free fall under each integrator
(checked in the report and, for backward Euler, in the written frames read back with VTK), and
a moving obstacle that reaches the body at the step the kinematics say.

The body is a bar [0, 4] x [0, 1] x [0, 1] sliced by `polydg mesh --cells 8` (32 elements), with
density 2: mass m = 8, inertia about its centre I = m/12 diag(1 + 1, 16 + 1, 16 + 1).

The tet methods ("method": "fem", "fs-fem", group tets) move the same bar as 96 distorted tets
read from Gmsh's MSH (tests/cli/solve_end_to_end.py makes them), with lumped masses computed
here from the file's points.

Groups (one ctest each): initial, integrators, frames, phases, obstacle, tets.
Usage: simulate_end_to_end.py GROUP POLYDG WORKDIR
"""
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from end_to_end_support import (Vtu, box_obj, check, close, equal, main, np, read_json,  # noqa
                                read_pvd, run)

DENSITY = 2.0
MASS = 4.0 * DENSITY
CENTRE = np.array([2.0, 0.5, 0.5])
INERTIA = MASS / 12.0 * np.diag([2.0, 17.0, 17.0])
MATERIAL = {"E": 1000, "nu": 0.3, "density": DENSITY}
G = 9.81
# Round-off of these small runs (a rigid motion in a 32-element DG space): measured at most
# 2.2e-15 relative on momenta and centres of mass; the bound leaves a factor of 100 or more.
ROUNDOFF = 1e-12


def bar_mesh(polydg, work):
    obj = box_obj(work / "bar.obj", (0.0, 0.0, 0.0), (4.0, 1.0, 1.0))
    mesh = work / "bar.vtu"
    run([polydg, "mesh", obj, "--cells", 8, "-o", mesh, "--quiet"])
    return mesh


def simulate(polydg, work, mesh, name, scene):
    path, report, out = work / (name + ".json"), work / (name + "_report.json"), work / name
    path.write_text(json.dumps(scene))
    run([polydg, "simulate", mesh, "--scene", path, "-o", out, "--report", report, "--quiet"])
    return read_json(report), out


def vector_close(name, got, reference, tolerance, scale):
    close(name, float(np.abs(np.asarray(got) - np.asarray(reference)).max()), 0.0,
          tolerance * scale, relative=False)


# --- initial -------------------------------------------------------------------------------

def initial(polydg, work):
    """initial.velocity v and initial.angular_velocity w on a free body without gravity: the
    momentum is m v, the angular momentum I w (about the centre of mass, which moves along v,
    parallel to the momentum), the kinetic energy m v^2 / 2 + w.I w / 2; the momentum and the
    centre of mass's motion c0 + v t hold at every step to round-off (no force acts), and each
    integrator keeps the angular momentum to its own accuracy."""
    mesh = bar_mesh(polydg, work)
    v = np.array([0.3, -0.2, 0.5])
    w = np.array([0.2, -0.1, 0.3])
    dt, steps = 0.01, 20
    # The largest relative change of the angular momentum over the 20 steps (|w| dt = 0.0037),
    # measured 2026-12-04: euler 3.4e-7, bdf2 1.9e-5, newmark 4.8e-6 (corotation, corrected
    # solves). Bounds: 3x those.
    angular_drift = {"euler": 1e-6, "bdf2": 6e-5, "newmark": 1.5e-5}
    for integrator in ("euler", "bdf2", "newmark"):
        scene = {"material": MATERIAL, "dt": dt, "steps": steps, "fixed": [],
                 "integrator": integrator,
                 "initial": {"velocity": v.tolist(), "angular_velocity": w.tolist()}}
        r, _ = simulate(polydg, work, mesh, "spin_" + integrator, scene)
        name = integrator + ": "
        equal(name + "scene's integrator", r["scene"]["integrator"], integrator)
        s0 = r["initial"]
        vector_close(name + "initial momentum against m v", s0["momentum"], MASS * v,
                     ROUNDOFF, MASS)
        vector_close(name + "initial angular momentum against I w", s0["angular_momentum"],
                     INERTIA @ w, ROUNDOFF, np.abs(INERTIA @ w).max())
        close(name + "initial kinetic energy m v^2 / 2 + w.I w / 2", s0["kinetic"],
              0.5 * MASS * v @ v + 0.5 * w @ INERTIA @ w, ROUNDOFF)
        vector_close(name + "initial centre of mass", s0["centre_of_mass"], CENTRE, ROUNDOFF,
                     4.0)
        equal(name + "steps", len(r["steps"]), steps)
        momentum = max(np.abs(np.asarray(s["momentum"]) - MASS * v).max() for s in r["steps"])
        close(name + "momentum against m v, worst step", momentum, 0.0, ROUNDOFF * MASS,
              relative=False)
        centre = max(np.abs(np.asarray(s["centre_of_mass"]) - CENTRE - v * s["t"]).max()
                     for s in r["steps"])
        close(name + "centre of mass against c0 + v t, worst step", centre, 0.0, ROUNDOFF * 4,
              relative=False)
        reference = INERTIA @ w
        drift = max(np.linalg.norm(np.asarray(s["angular_momentum"]) - reference) /
                    np.linalg.norm(reference) for s in r["steps"])
        close(name + "angular momentum's largest relative change", drift, 0.0,
              angular_drift[integrator], relative=False)


# --- integrators ---------------------------------------------------------------------------

def bdf2_fall(g, dt, steps):
    """BDF2's centre-of-mass height change under a constant acceleration -g from rest: a
    backward Euler step, then (3 x_{n+1} - 4 x_n + x_{n-1}) / (2 dt) = v_{n+1} and the same for
    v with -g."""
    u, v = [0.0], [0.0]
    v.append(v[0] - dt * g)
    u.append(u[0] + dt * v[1])
    c = 2.0 * dt / 3.0
    for _ in range(steps - 1):
        v.append((4 * v[-1] - v[-2]) / 3 - c * g)
        u.append((4 * u[-1] - u[-2]) / 3 + c * v[-1])
    return u, v


def integrators(polydg, work):
    """Free fall from rest under gravity: the body does not deform, and each integrator moves
    its centre of mass as its scalar recurrence does: backward Euler z_n - z0 = -g dt^2 n (n+1)
    / 2, Newmark (average acceleration) exactly -g t^2 / 2, BDF2 its own recurrence after a
    first backward Euler step. The momentum is m times the matching velocity."""
    mesh = bar_mesh(polydg, work)
    dt, steps = 0.01, 12
    bdf2_u, bdf2_v = bdf2_fall(G, dt, steps)
    expected = {
        "euler": lambda n: (-G * dt * dt * n * (n + 1) / 2, -G * dt * n),
        "newmark": lambda n: (-G * (n * dt) ** 2 / 2, -G * n * dt),
        "bdf2": lambda n: (bdf2_u[n], bdf2_v[n]),
    }
    for integrator, law in expected.items():
        scene = {"material": MATERIAL, "dt": dt, "steps": steps, "fixed": [],
                 "integrator": integrator, "gravity": [0, 0, -G]}
        r, _ = simulate(polydg, work, mesh, "fall_" + integrator, scene)
        z0 = r["initial"]["centre_of_mass"][2]
        worst_z = worst_p = worst_e = 0.0
        for n, s in enumerate(r["steps"], start=1):
            z, vz = law(n)
            worst_z = max(worst_z, abs(s["centre_of_mass"][2] - z0 - z) / abs(z))
            worst_p = max(worst_p, abs(s["momentum"][2] - MASS * vz) / abs(MASS * vz))
            worst_e = max(worst_e, abs(s["kinetic"] - 0.5 * MASS * vz * vz) / (MASS * vz * vz))
        # Measured 2026-12-04: at most 4.7e-14 relative on the fall (the first steps' small
        # drops), 9e-16 on momentum and kinetic energy, 5.8e-15 elastic energy; bounds 20-100x.
        close(integrator + ": centre of mass's fall against the recurrence, worst relative",
              worst_z, 0.0, 1e-12, relative=False)
        close(integrator + ": momentum m v_n, worst relative", worst_p, 0.0, 1e-13,
              relative=False)
        close(integrator + ": kinetic energy m v_n^2 / 2, worst relative", worst_e, 0.0, 1e-13,
              relative=False)
        close(integrator + ": elastic energy (no deformation), largest",
              max(abs(s["elastic"]) for s in r["steps"]), 0.0, 1e-12, relative=False)
    # The three differ: Newmark's fall after 12 steps is exact, Euler's is (n+1)/n longer,
    # BDF2's in between. (Guards against an integrator key that does nothing.)
    n = steps
    check(bdf2_u[n] < expected["newmark"](n)[0] and expected["euler"](n)[0] < bdf2_u[n],
          "the three recurrences differ at step %d: euler %.6g < bdf2 %.6g < newmark %.6g" %
          (n, expected["euler"](n)[0], bdf2_u[n], expected["newmark"](n)[0]))


# --- frames --------------------------------------------------------------------------------

def frames(polydg, work):
    """The written time series (OUTDIR/scene.pvd and a VTU per frame), read back with VTK,
    against backward Euler's fall: at frame n every point's displacement is (0, 0, -g dt^2
    n (n+1) / 2) and its velocity (0, 0, -g n dt), at the time n dt the collection gives."""
    mesh = bar_mesh(polydg, work)
    dt, steps, every = 0.02, 9, 2
    # CHOLMOD: the fall then holds to round-off (CG, the default for corotated steps, holds it
    # to its tolerance, 1e-8 of the right-hand side).
    scene = {"material": MATERIAL, "dt": dt, "steps": steps, "fixed": [],
             "gravity": [0, 0, -G], "output": {"every": every}, "solver": "cholesky"}
    r, out = simulate(polydg, work, mesh, "frames", scene)
    collection = read_pvd(out / "scene.pvd")
    # Frames at step 0, every 2 steps and at the end.
    expected_steps = [0, 2, 4, 6, 8, 9]
    equal("frames in the report", [f["step"] for f in r["frames"]], expected_steps)
    equal("frames in scene.pvd", [f for _, _, f in collection],
          [f["file"] for f in r["frames"]])
    reference = Vtu(mesh)
    for (t, part, name), n in zip(collection, expected_steps):
        equal("frame %s: part" % name, part, 0)
        close("frame %s: time n dt" % name, t, n * dt, 1e-14, relative=False)
        vtu = Vtu(out / name)
        check(np.array_equal(vtu.points, reference.points),
              "frame %s: the points are the mesh's (undeformed) points" % name)
        u, v = vtu.point_data["displacement"], vtu.point_data["velocity"]
        z, vz = -G * dt * dt * n * (n + 1) / 2, -G * n * dt
        scale = max(abs(z), 1e-300)
        # The mean of the points' displacement (the body's, all equal) and the worst point;
        # measured 2026-12-04 at most 2.7e-15 and 4.4e-14 relative (velocity): bounds 20-40x.
        close("frame %s: mean displacement z against -g dt^2 n (n+1) / 2" % name,
              u[:, 2].mean(), z, 1e-13 if n else 0.0, relative=bool(n))
        close("frame %s: worst point's displacement difference" % name,
              np.abs(u - [0, 0, z]).max(), 0.0, 1e-13 * scale, relative=False)
        close("frame %s: worst point's velocity difference against -g n dt" % name,
              np.abs(v - [0, 0, vz]).max(), 0.0, 1e-12 * max(abs(vz), 1e-300),
              relative=False)
        equal("frame %s: cell data von_mises per element" % name,
              len(vtu.cell_data["von_mises"]), len(reference.cells))


# --- phases --------------------------------------------------------------------------------

# The phases of the report's timings_s that together make its wall time (surface is a part of
# output; read happens before the run's clock starts).
PHASES = ["setup", "rotation", "assembly", "solve", "state", "cut", "output", "finish"]


def phases(polydg, work):
    """The report's phase times add up to its wall time within 5% (issue 31): a clamped bar
    under gravity on 256 elements, cut mid-run, a frame every 5 steps; every phase that ran is
    counted once (the cut's new solver in cut, not again in setup); each step's preconditioner
    time lies within its solve, and the cut's latency names the next step's."""
    obj = box_obj(work / "long_bar.obj", (0.0, 0.0, 0.0), (4.0, 1.0, 1.0))
    mesh = work / "long_bar.vtu"
    run([polydg, "mesh", obj, "--cells", 16, "-o", mesh, "--quiet"])
    scene = {"material": MATERIAL, "dt": 0.01, "steps": 30, "gravity": [0, 0, -G],
             "fixed": [{"plane": [1, 0, 0, 0]}], "output": {"every": 5},
             "cuts": [{"time": 0.15, "plane": [1, 0, 0, 2.1], "remove_side": "none"}]}
    r, _ = simulate(polydg, work, mesh, "phases", scene)
    t = r["timings_s"]
    for key in PHASES:
        check(t[key] >= 0.0, "timings_s.%s = %.3g s, not negative" % (key, t[key]))
    check(t["cut"] > 0.0 and r["cuts"][0]["cut_seconds"]["solver"] > 0.0,
          "the cut ran (%.3g s, its new solver %.3g s)" % (t["cut"],
                                                           r["cuts"][0]["cut_seconds"]["solver"]))
    check(t["surface"] <= t["output"], "surface %.3g s within output %.3g s" % (t["surface"],
                                                                                 t["output"]))
    close("the phases' sum against the wall time", sum(t[k] for k in PHASES), t["wall"], 0.05)
    steps = sum(s["rotation_seconds"] + s["assembly_seconds"] + s["solve_seconds"]
                for s in r["steps"])
    close("the steps' phases against rotation + assembly + solve", steps,
          t["rotation"] + t["assembly"] + t["solve"], 1e-9)
    for s in r["steps"]:
        check(0.0 <= s["preconditioner_seconds"] <= s["solve_seconds"],
              "t = %g: preconditioner %.3g s within the solve's %.3g s"
              % (s["t"], s["preconditioner_seconds"], s["solve_seconds"]))
    latency = r["cuts"][0]["cut_seconds"]
    after = next(s for s in r["steps"] if s["t"] > 0.15 + 1e-9)
    check(latency["next_step_preconditioner"] == after["preconditioner_seconds"] > 0.0
          and latency["next_step_preconditioner"] <= latency["next_step"],
          "the cut's next step built its preconditioner in %.3g s of %.3g s"
          % (latency["next_step_preconditioner"], latency["next_step"]))


# --- obstacle ------------------------------------------------------------------------------

def obstacle(polydg, work):
    """A mesh obstacle with a velocity: a slab whose face starts 0.97 beyond the bar's free end
    (x = 4.97) and moves at -1 along x reaches the resting bar at t = 0.97, so with dt = 0.04
    the first step with contacts is step 25 (t = 1.00; at step 24, t = 0.96, the gap is still
    0.01) and every node of the end face (3 x 3) is then in contact; the bar is then pushed
    along -x. The same slab at rest never touches."""
    mesh = bar_mesh(polydg, work)
    box_obj(work / "slab.obj", (4.97, -0.5, -0.5), (5.97, 1.5, 1.5))
    dt, steps = 0.04, 27
    for velocity in ([-1.0, 0.0, 0.0], [0.0, 0.0, 0.0]):
        scene = {"material": MATERIAL, "dt": dt, "steps": steps, "fixed": [],
                 "obstacles": [{"mesh": "slab.obj", "velocity": velocity}],
                 "contact": {"points": "nodes"}}
        r, _ = simulate(polydg, work, mesh, "obstacle", scene)
        contacts = [s["contacts"] for s in r["steps"]]
        if velocity[0] == 0.0:
            equal("slab at rest: steps with contacts", sum(c > 0 for c in contacts), 0)
            continue
        first = next((n for n, c in enumerate(contacts, start=1) if c > 0), None)
        equal("moving slab: first step with contacts (t = %.2f)" % (25 * dt), first, 25)
        equal("moving slab: contacts at step 25, the end face's 3 x 3 nodes", contacts[24], 9)
        before = r["steps"][:24]
        close("moving slab: momentum before contact, largest",
              max(np.abs(s["momentum"]).max() for s in before), 0.0, 1e-12, relative=False)
        deepest = r["steps"][24]["deepest_penetration"]
        check(0.0 < deepest <= 0.03, "step 25: penetration %.3g within the slab's advance past "
              "the end in the step (0.03)" % deepest)
        pushed = [s["momentum"][0] for s in r["steps"][24:]]
        check(all(p < 0 for p in pushed) and pushed[-1] < pushed[0],
              "the slab pushes the bar along -x: momentum %s" % ", ".join(
                  "%.3g" % p for p in pushed))


# --- tets ----------------------------------------------------------------------------------

def lumped_masses(points, cells):
    """Each node's lumped mass: a quarter of each of its tets' mass."""
    e = points[cells[:, 1:]] - points[cells[:, :1]]
    volumes = np.einsum("ij,ij->i", e[:, 0], np.cross(e[:, 1], e[:, 2])) / 6.0
    m = np.zeros(len(points))
    np.add.at(m, cells.ravel(), np.repeat(DENSITY * volumes / 4.0, 4))
    return m


def tets_free(polydg, work, mesh, points, m):
    """Free bodies: each method falls as each integrator's recurrence, undeformed; an initial
    velocity v and angular velocity w give momentum m v and angular momentum J w with J the
    lumped masses' inertia about their centre, and (no force) the momentum stays."""
    dt, steps = 0.01, 12
    bdf2_u, bdf2_v = bdf2_fall(G, dt, steps)
    laws = {"euler": lambda n: (-G * dt * dt * n * (n + 1) / 2, -G * dt * n),
            "newmark": lambda n: (-G * (n * dt) ** 2 / 2, -G * n * dt),
            "bdf2": lambda n: (bdf2_u[n], bdf2_v[n])}
    for method in ("fem", "fs-fem"):
        for integrator, law in laws.items():
            name = "%s, %s" % (method, integrator)
            scene = {"material": MATERIAL, "method": method, "dt": dt, "steps": steps,
                     "fixed": [], "integrator": integrator, "gravity": [0, 0, -G],
                     "solver": "cholesky"}
            r, _ = simulate(polydg, work, mesh, "tet_fall", scene)
            equal(name + ": the report's method", r["scene"]["method"], method)
            z0 = r["initial"]["centre_of_mass"][2]
            worst_z = worst_p = 0.0
            for n, s in enumerate(r["steps"], start=1):
                z, vz = law(n)
                worst_z = max(worst_z, abs(s["centre_of_mass"][2] - z0 - z) / abs(z))
                worst_p = max(worst_p, abs(s["momentum"][2] - MASS * vz) / abs(MASS * vz))
            # Measured 2026-12-05: at most 6e-14 and 1e-15; bounds 20x and more.
            close(name + ": the fall against the recurrence, worst relative", worst_z, 0.0,
                  1e-12, relative=False)
            close(name + ": momentum m v_n, worst relative", worst_p, 0.0, 1e-13,
                  relative=False)
            close(name + ": elastic energy (no deformation), largest",
                  max(abs(s["elastic"]) for s in r["steps"]), 0.0, 1e-12, relative=False)
    centre = (m[:, None] * points).sum(axis=0) / m.sum()
    q = points - centre
    inertia = (m[:, None, None] * (np.einsum("ij,ij->i", q, q)[:, None, None] * np.eye(3) -
                                   q[:, :, None] * q[:, None, :])).sum(axis=0)
    v, w = np.array([0.3, -0.2, 0.5]), np.array([0.4, 1.0, -0.7])
    for method in ("fem", "fs-fem"):
        scene = {"material": MATERIAL, "method": method, "dt": 0.01, "steps": 20, "fixed": [],
                 "integrator": "bdf2", "solver": "cholesky",
                 "initial": {"velocity": v.tolist(), "angular_velocity": w.tolist()}}
        r, _ = simulate(polydg, work, mesh, "tet_spin", scene)
        start = r["initial"]
        vector_close(method + ": initial momentum against m v", start["momentum"], MASS * v,
                     1e-14, np.abs(MASS * v).max())
        vector_close(method + ": initial angular momentum against J w (lumped masses)",
                     start["angular_momentum"], inertia @ w, 1e-13, np.abs(inertia @ w).max())
        vector_close(method + ": centre of mass against the lumped masses'",
                     start["centre_of_mass"], centre, 1e-14, 4.0)
        vector_close(method + ": momentum kept over 20 steps, worst",
                     max((np.abs(np.asarray(s["momentum"]) - MASS * v).max(), s["momentum"])
                         for s in r["steps"])[1], MASS * v, 1e-12, np.abs(MASS * v).max())


def tets_frames(polydg, work, mesh, points, cells):
    """The frames of a backward Euler fall read back with VTK: the tets' points, each point's
    displacement (0, 0, -g dt^2 n (n+1) / 2) and velocity, von_mises per tet."""
    dt, steps = 0.02, 5
    scene = {"material": MATERIAL, "method": "fs-fem", "dt": dt, "steps": steps, "fixed": [],
             "gravity": [0, 0, -G], "output": {"every": 2}, "solver": "cholesky"}
    r, out = simulate(polydg, work, mesh, "tet_frames", scene)
    collection = read_pvd(out / "scene.pvd")
    equal("tet frames in the report", [f["step"] for f in r["frames"]], [0, 2, 4, 5])
    for (t, _, name), n in zip(collection, [0, 2, 4, 5]):
        close("tet frame %s: time n dt" % name, t, n * dt, 1e-14, relative=False)
        vtu = Vtu(out / name)
        check(np.array_equal(vtu.points, points), "tet frame %s: the points are the file's" % name)
        equal("tet frame %s: cells" % name, len(vtu.cells), len(cells))
        u, v = vtu.point_data["displacement"], vtu.point_data["velocity"]
        z, vz = -G * dt * dt * n * (n + 1) / 2, -G * n * dt
        close("tet frame %s: worst point's displacement against the fall" % name,
              np.abs(u - [0, 0, z]).max(), 0.0, 1e-13 * max(abs(z), 1e-300), relative=False)
        close("tet frame %s: worst point's velocity against the fall" % name,
              np.abs(v - [0, 0, vz]).max(), 0.0, 1e-12 * max(abs(vz), 1e-300), relative=False)
        close("tet frame %s: largest von Mises (no deformation)" % name,
              float(np.abs(vtu.cell_data["von_mises"]).max()), 0.0, 1e-9, relative=False)


def tets_settle(polydg, work, mesh):
    """Clamped at x = 0, pulled by a traction 10 on x = 4, with nu = 0 and mass damping: the
    bar settles on the uniaxial field u = (10 x / E, 0, 0), which both methods reproduce exactly
    on any tets, linear or corotated (a stretch: every polar rotation is the identity)."""
    for method in ("fem", "fs-fem"):
        for corotational in (False, True):
            name = "%s%s" % ("corotational " if corotational else "", method)
            scene = {"material": {"E": 1000, "nu": 0, "density": DENSITY}, "method": method,
                     "corotational": corotational, "dt": 0.1, "steps": 400,
                     "damping": {"mass": 3}, "fixed": [{"axis": "x", "value": 0}],
                     "loads": [{"traction": [10, 0, 0], "on": {"axis": "x", "value": 4}}],
                     "output": {"every": 400}}
            r, out = simulate(polydg, work, mesh, "tet_settle", scene)
            equal(name + ": fixed and loaded boundary faces", [r["fixed_faces"], r["load_faces"]],
                  [[8], [8]])
            last = Vtu(out / r["frames"][-1]["file"])
            exact = np.zeros_like(last.points)
            exact[:, 0] = 10.0 * last.points[:, 0] / 1000.0
            # Measured 2026-12-05: at most 6.8e-16 (of the end's 0.04): bound 50x.
            close(name + ": worst point against u = (sigma x / E, 0, 0)",
                  np.abs(last.point_data["displacement"] - exact).max(), 0.0, 1e-12 * 0.04,
                  relative=False)
            close(name + ": kinetic energy at rest", r["steps"][-1]["kinetic"], 0.0, 1e-20,
                  relative=False)


def tets_refused(polydg, work, mesh):
    """What the tet methods do not have is refused with one line, before anything runs."""
    base = {"material": MATERIAL, "method": "fem", "dt": 0.01, "steps": 2, "fixed": []}
    cases = [({"cuts": [{"time": 0.01, "plane": [1, 0, 0, 2]}]}, "cuts"),
             ({"degree": 2}, "degree"),
             ({"fixed": [{"axis": "x", "value": 7}]}, "selects no boundary face"),
             ({"method": "fs-femm"}, "is not one of ip, bz, fem, fs-fem")]
    for extra, words in cases:
        path = work / "bad_scene.json"
        path.write_text(json.dumps(dict(base, **extra)))
        _, err = run([polydg, "simulate", mesh, "--scene", path, "-o", work / "bad"], expect=2)
        check(words in err and len(err.strip().splitlines()) == 1,
              "%s refused in one line: %s" % (json.dumps(extra), err.strip()))
    path = work / "bad_scene.json"
    path.write_text(json.dumps(base))
    _, err = run([polydg, "simulate", bar_mesh(polydg, work), "--scene", path, "-o",
                  work / "bad"], expect=2)
    check("is not a tetrahedron" in err, "a hexahedral mesh refused: " + err.strip())


def tets(polydg, work):
    """The tet methods through `polydg simulate` (issue 33): free bodies, frames, a loaded
    bar settling on the closed form, refusals."""
    from solve_end_to_end import bar_tets, write_msh
    points, cells = bar_tets()
    mesh = work / "bar.msh"
    write_msh(mesh, points, cells)
    m = lumped_masses(points, cells)
    close("the lumped masses sum to the bar's mass", m.sum(), MASS, 1e-14)
    tets_free(polydg, work, mesh, points, m)
    tets_frames(polydg, work, mesh, points, cells)
    tets_settle(polydg, work, mesh)
    tets_refused(polydg, work, mesh)
    # polydg mesh --tets makes a tet mesh simulate takes: the sliced bar's tets fall as backward
    # Euler's recurrence says.
    sliced = work / "bar_sliced_tets.vtu"
    run([polydg, "mesh", box_obj(work / "bar.obj", (0.0, 0.0, 0.0), (4.0, 1.0, 1.0)), "--cells",
         8, "--tets", "-o", sliced, "--quiet"])
    dt, steps = 0.01, 5
    r, _ = simulate(polydg, work, sliced, "sliced_fall",
                    {"material": MATERIAL, "method": "fs-fem", "dt": dt, "steps": steps,
                     "fixed": [], "gravity": [0, 0, -G], "solver": "cholesky"})
    check(r["elements"] > 32, "the sliced bar's %d tets simulate" % r["elements"])
    fall = r["steps"][-1]["centre_of_mass"][2] - r["initial"]["centre_of_mass"][2]
    close("the sliced bar's tets: fall after %d steps against -g dt^2 n (n+1) / 2" % steps,
          fall, -G * dt * dt * steps * (steps + 1) / 2, 1e-12)
    t = r["timings_s"]
    close("the tets' phases against the wall time", sum(t[k] for k in PHASES), t["wall"], 0.05)
    check(t["rotation"] > 0.0, "the tets' rotations are timed (%.3g s)" % t["rotation"])


GROUPS = {"initial": initial, "integrators": integrators, "frames": frames,
          "phases": phases, "obstacle": obstacle, "tets": tets}

if __name__ == "__main__":
    main(GROUPS, sys.argv)

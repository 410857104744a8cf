#!/usr/bin/env python3
"""`polydg mesh` end to end through the binary: octree slicing (--adaptive) against the
surface's enclosed volume and the uniform grid, the determinism docs/guide.md claims (the same
VTU bytes run after run, on one thread or two), the Python module giving the CLI's results
to the last digit, and --tets (the mesh written as tets of the same volume, solved by the tet
methods).

Groups (one ctest each): adaptive, determinism, python, tets.
Usage: mesh_end_to_end.py GROUP POLYDG WORKDIR (python: with the module on PYTHONPATH)
"""
import filecmp
import os
import shutil
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from end_to_end_support import (CheckFailed, Vtu, check, close, equal, main, np,  # noqa: E402
                                obj_volume, read_json, run)

TESTDATA = Path(__file__).resolve().parents[2] / "testdata"


def mesh(polydg, work, surface, name, *options):
    out, report = work / (name + ".vtu"), work / (name + ".json")
    run([polydg, "mesh", surface, "-o", out, "--report", report, "--quiet", *options])
    return read_json(report), out


# --- adaptive ------------------------------------------------------------------------------

def levels_of(vtu, coarse, levels):
    """Each element's octree level from its geometry: a whole cell of size coarse / 2^k (its
    volume its bounding cube's) is at level k; a piece the surface cuts is at the finest level
    (octree slicing refines every element the surface passes to the finest cells)."""
    lo, hi = vtu.cell_boxes()
    extent = hi - lo
    volumes = vtu.cell_volumes()
    out = np.full(len(vtu.cells), levels)
    for c in range(len(vtu.cells)):
        for k in range(levels + 1):
            size = coarse / 2**k
            if (np.abs(extent[c] - size).max() <= 1e-12 * size and
                    abs(volumes[c] - size**3) <= 1e-12 * size**3):
                out[c] = k
    return out


def adaptive(polydg, work):
    """testdata/ball.obj (a sphere of diameter 1) at 16 cells, octree against uniform: the
    elements' volumes (computed here from the written faces) sum to the surface's enclosed
    volume (computed here from its triangles), the checks pass, the finest cells are the
    uniform grid's 1/16, there are fewer elements than the uniform grid's, the levels per
    element add up to the report's, and face neighbours differ by at most one level (2:1)."""
    ball = TESTDATA / "ball.obj"
    enclosed = obj_volume(ball)
    octree, octree_vtu = mesh(polydg, work, ball, "octree", "--cells", 16, "--adaptive")
    uniform, _ = mesh(polydg, work, ball, "uniform", "--cells", 16)
    check(octree["validation"]["passed"] is True, "octree: the report's validation passed")
    vtu = Vtu(octree_vtu)
    volumes = vtu.cell_volumes()
    close("octree: element volumes (divergence theorem) sum to the enclosed volume",
          volumes.sum(), enclosed, 1e-12)
    close("octree: the report's volume", octree["output"]["volume"], enclosed, 1e-12)
    close("octree: volumes against the file's own", np.abs(volumes - vtu.cell_data["volume"])
          .max(), 0.0, 1e-15, relative=False)
    check(volumes.min() > 0, "octree: every element has a positive volume (%.3g)" %
          volumes.min())
    info = octree["octree"]
    levels = info["levels"]
    close("octree: finest cell = coarse / 2^levels", info["finest_cell_size"],
          info["coarse_cell_size"] / 2**levels, 1e-15)
    close("octree: finest cell = uniform's (1/16 of the diameter)", info["finest_cell_size"],
          uniform["grid"]["cell_size"], 1e-15)
    n = octree["output"]["elements"]
    equal("octree: elements written", len(vtu.cells), n)
    equal("octree: elements per level add up", sum(info["elements_per_level"]), n)
    check(n < uniform["output"]["elements"], "octree: fewer elements than the uniform grid at "
          "the same finest cell: %d < %d" % (n, uniform["output"]["elements"]))
    close("octree and uniform: the same volume", octree["output"]["volume"],
          uniform["output"]["volume"], 1e-12)
    level = levels_of(vtu, info["coarse_cell_size"], levels)
    equal("octree: elements per level from the geometry",
          [int(np.sum(level == k)) for k in range(levels + 1)], info["elements_per_level"])
    # Face neighbours: faces on the same point ids (interior faces are split so that both
    # sides hold identical ones: no hanging nodes).
    owners = {}
    for c, faces in enumerate(vtu.cells):
        for f in faces:
            owners.setdefault(tuple(sorted(f)), []).append(c)
    pairs = [o for o in owners.values() if len(o) == 2]
    check(len(pairs) > 0 and all(len(o) <= 2 for o in owners.values()),
          "octree: %d interior faces, none shared by more than two elements" % len(pairs))
    jump = max(abs(int(level[a]) - int(level[b])) for a, b in pairs)
    equal("octree: largest level difference across a face (2:1 rule)", jump, 1)


# --- determinism ---------------------------------------------------------------------------

def determinism(polydg, work):
    """docs/guide.md, Meshing: the mesh depends only on the input and the options (the same mesh
    on one thread or on all), and so does the VTU (the same bytes from one run to the next).
    polydg has no thread option: TBB takes its threads from the CPU affinity, so taskset -c 0
    runs it on one thread and -c 0,1 on two."""
    cpus = sorted(os.sched_getaffinity(0))
    check(len(cpus) >= 2, "at least two CPUs to compare one thread with two: %s" % cpus)
    if shutil.which("taskset") is None:
        raise CheckFailed("taskset is missing: install Debian's util-linux")
    cases = [("torus, 24 cells", TESTDATA / "torus.obj", ["--cells", 24]),
             ("ball, octree at 16 cells", TESTDATA / "ball.obj", ["--cells", 16, "--adaptive"])]
    for name, surface, options in cases:
        outputs = []
        for k, cores in enumerate(["%d" % cpus[0], "%d,%d" % (cpus[0], cpus[1]), None]):
            out = work / ("%s_%d.vtu" % (surface.stem, k))
            prefix = ["taskset", "-c", cores] if cores else []
            run(prefix + [polydg, "mesh", surface, "-o", out, "--quiet", *options])
            outputs.append(out)
        size = outputs[0].stat().st_size
        check(filecmp.cmp(outputs[0], outputs[1], shallow=False),
              "%s: one thread and two write the same %d bytes" % (name, size))
        check(filecmp.cmp(outputs[1], outputs[2], shallow=False),
              "%s: run again, the same %d bytes" % (name, size))


# --- python --------------------------------------------------------------------------------

def python(polydg, work):
    """The Python module and the binary on the same inputs: element counts, the total volume
    and the written file equal to the last digit (one library underneath), every element's
    volume to round-off, for uniform and octree slicing, and a solve's figures to the last
    digit."""
    try:
        import polydg as module
    except ImportError as error:
        raise CheckFailed("cannot import polydg (%s): run with build/python on PYTHONPATH" %
                          error)
    for surface, options, kwargs in ((TESTDATA / "torus.obj", ["--cells", 12], {"cells": 12}),
                                     (TESTDATA / "ball.obj", ["--cells", 8, "--adaptive"],
                                      {"cells": 8, "adaptive": True})):
        name = "%s %s" % (surface.name, " ".join(str(o) for o in options))
        report, out = mesh(polydg, work, surface, "cli", *options)
        model = module.mesh(module.read_surface(str(surface)), **kwargs)
        equal(name + ": elements, Python against the CLI", model.num_elements,
              report["output"]["elements"])
        equal(name + ": the meshing report's volume, Python's against the CLI's (bits)",
              model.report["output"]["volume"], report["output"]["volume"])
        # Model.volume sums the element volumes, the report's volume is the validation's (its
        # own sum): one ulp apart at most.
        close(name + ": Model.volume against the CLI's", model.volume,
              report["output"]["volume"], 4e-16)
        # The same file, byte for byte, written from Python.
        mine = work / "python.vtu"
        model.write(str(mine))
        check(filecmp.cmp(out, mine, shallow=False),
              name + ": Python's written VTU is the CLI's, byte for byte (%d bytes)" %
              out.stat().st_size)
        # Python's element volumes (the moment cache) against the file's (the writer's own
        # signed volumes, cells in the file's order: polydg_element maps them back).
        vtu = Vtu(out)
        elements = vtu.field_data["polydg_element"].astype(np.int64)
        python_volumes = model.element_volumes[elements]
        close(name + ": element volumes, Python's against the written file's, largest relative "
              "difference", np.abs(python_volumes / vtu.cell_data["volume"] - 1).max(), 0.0,
              1e-13, relative=False)
        close(name + ": element volumes, Python's against the divergence theorem here, largest "
              "relative difference", np.abs(python_volumes / vtu.cell_volumes() - 1).max(), 0.0,
              1e-12, relative=False)
    # A solve of the CLI's mesh, read by Python: B3's beam under its weight.
    bar = TESTDATA / "beam.obj"  # [0, 10] x [0, 1] x [0, 1]
    report, out = mesh(polydg, work, bar, "beam", "--cells", 10)
    solved = work / "solved.json"
    run([polydg, "solve", out, "-o", work / "solved.vtu", "--degree", 2, "--E", 1000, "--nu",
         0.3, "--gravity", "0,0,-1", "--clamp", "x=0", "--report", solved, "--quiet"])
    cli = read_json(solved)
    model = module.read(str(out))
    r = model.solve(degree=2, E=1000, nu=0.3, gravity=[0, 0, -1],
                    clamp=[{"axis": "x", "value": 0}])
    equal("beam solve: energy, max |u| and DOFs, Python against the CLI (bits)",
          (r["energy"], r["max_displacement"], r["dofs"]),
          (cli["energy"], cli["max_displacement"], cli["dofs"]))


# --- tets ----------------------------------------------------------------------------------

def tet_volumes(points, tets):
    """Each tet's signed volume, about its first corner."""
    a = points[tets[:, 0]]
    return np.einsum("ij,ij->i", points[tets[:, 1]] - a,
                     np.cross(points[tets[:, 2]] - a, points[tets[:, 3]] - a)) / 6.0


def u_obj(path):
    """A U-shaped prism: the outline (0,0) (3,0) (3,3) (2,3) (2,1) (1,1) (1,3) (0,3) extruded over
    z in [0, 1] (volume 7), its top and bottom cut into triangles along y = 1; outward."""
    outline = [(0, 0), (3, 0), (3, 1), (3, 3), (2, 3), (2, 1), (1, 1), (1, 3), (0, 3), (0, 1)]
    k = {p: i + 1 for i, p in enumerate(outline)}  # OBJ's 1-based index at z = 0
    n = len(outline)
    # Counter-clockwise seen from +z: the base (a hexagon with collinear corners), then the arms.
    caps = [((0, 0), (3, 0), (3, 1)), ((0, 0), (3, 1), (2, 1)), ((0, 0), (2, 1), (1, 1)),
            ((0, 0), (1, 1), (0, 1)), ((0, 1), (1, 1), (1, 3)), ((0, 1), (1, 3), (0, 3)),
            ((2, 1), (3, 1), (3, 3)), ((2, 1), (3, 3), (2, 3))]
    with open(path, "w") as out:
        for z in (0, 1):
            out.writelines("v %d %d %d\n" % (x, y, z) for x, y in outline)
        for a, b, c in caps:
            out.write("f %d %d %d\n" % (k[a], k[c], k[b]))  # the bottom, facing -z
            out.write("f %d %d %d\n" % (k[a] + n, k[b] + n, k[c] + n))
        for i in range(1, n + 1):
            j = i % n + 1
            out.write("f %d %d %d\nf %d %d %d\n" % (i, j, j + n, i, j + n, i + n))


def tets(polydg, work):
    """`polydg mesh --tets`: the torus (non-convex pieces), a U-shaped prism (one element that
    is not star-shaped) and the beam written as tets. meshio reads VTK_TETRA cells only, the
    polyhedral mesh's points first and in order; the tets' volumes (computed here) are positive
    and sum to the polyhedral mesh's; polydg check accepts the files; the tets solve, the beam's
    uniaxial tension with --method fem and fs-fem to round-off; one thread and two write the
    same bytes."""
    try:
        import meshio
    except ImportError as error:
        raise CheckFailed("cannot import meshio (%s): install Debian's python3-meshio" % error)
    torus = TESTDATA / "torus.obj"
    poly, poly_vtu = mesh(polydg, work, torus, "torus_poly", "--cells", 12)
    report, out = mesh(polydg, work, torus, "torus_tets", "--cells", 12, "--tets")
    t = report["tets"]
    check(poly["tets"] is None, "without --tets the report's tets is null")
    check(t is not None, "with --tets the report has its tets object")
    check(report["validation"]["passed"] is True, "the polyhedral mesh's checks passed")
    equal("elements: the polyhedral mesh's, with --tets or without",
          report["output"]["elements"], poly["output"]["elements"])
    equal("elements as cones and by TetGen add up", t["cone_elements"] + t["tetgen_elements"],
          report["output"]["elements"])
    close("the report's tet volume against the polyhedral mesh's", t["volume"],
          report["output"]["volume"], 1e-12)
    close("the report's relative difference", t["volume_rel_difference"], 0.0, 1e-12,
          relative=False)
    written = meshio.read(str(out))
    equal("meshio: cell blocks", [block.type for block in written.cells], ["tetra"])
    cells = written.cells[0].data
    equal("meshio: tets", len(cells), t["tets"])
    equal("meshio: points", len(written.points), t["vertices"])
    polyhedral = Vtu(poly_vtu).points
    n = t["vertices"] - t["steiner_points"]
    equal("the polyhedral mesh's points (no copies in a sliced mesh)", len(polyhedral), n)
    check(np.array_equal(written.points[:n], polyhedral),
          "the first %d points are the polyhedral mesh's, in order, bit for bit" % n)
    volumes = tet_volumes(written.points, cells)
    check(volumes.min() > 0, "every tet is positive (smallest volume %.3g)" % volumes.min())
    close("the tets' volumes, summed here, against the polyhedral mesh's", volumes.sum(),
          report["output"]["volume"], 1e-12)
    close("against the surface's enclosed volume", volumes.sum(), obj_volume(torus), 1e-12)
    check_report = work / "check.json"
    run([polydg, "check", out, "--report", check_report, "--quiet"])
    checked = read_json(check_report)
    check(checked["passed"], "polydg check accepts the tets")
    equal("polydg check: elements", checked["elements"], t["tets"])
    close("polydg check: volume", checked["volume"], report["output"]["volume"], 1e-12)
    stdout, _ = run([polydg, "mesh", torus, "-o", work / "printed.vtu", "--cells", 12, "--tets"])
    line = [x for x in stdout.splitlines() if "written as tets" in x]
    check(len(line) == 1 and ("%d tets" % t["tets"]) in line[0],
          "the summary's tets line: %s" % line)
    # One thread and two: the same file (taskset: TBB takes its threads from the affinity).
    cpus = sorted(os.sched_getaffinity(0))
    check(len(cpus) >= 2 and shutil.which("taskset") is not None, "two CPUs and taskset")
    one = work / "one_thread.vtu"
    run(["taskset", "-c", cpus[0], polydg, "mesh", torus, "-o", one, "--cells", 12, "--tets",
         "--quiet"])
    check(filecmp.cmp(one, out, shallow=False), "one thread writes the same %d bytes as two" %
          out.stat().st_size)

    # A U-shaped prism in one grid cell: one element, not star-shaped, split by TetGen; the
    # tets fill its volume, 7, and solve.
    u = work / "u.obj"
    u_obj(u)
    report, out = mesh(polydg, work, u, "u_tets", "--cells", 1, "--tets")
    t = report["tets"]
    equal("U: one element, split by TetGen", (report["output"]["elements"], t["tetgen_elements"],
                                              t["cone_elements"]), (1, 1, 0))
    written = meshio.read(str(out))
    volumes = tet_volumes(written.points, written.cells[0].data)
    check(volumes.min() > 0, "U: every tet is positive (smallest volume %.3g)" % volumes.min())
    close("U: the tets' volumes, summed here", volumes.sum(), 7.0, 1e-15)
    run([polydg, "check", out, "--quiet"])
    run([polydg, "solve", out, "-o", work / "u_solved.vtu", "--method", "fem", "--clamp", "y=0",
         "--traction", "y=3:0,1,0", "--quiet"])

    # The beam [0, 10] x [0, 1] x [0, 1] in tets, pulled along x at x = 10 and clamped at x = 0
    # (nu = 0): u = (T x / E, 0, 0) is linear, which both tet methods reproduce exactly.
    beam = TESTDATA / "beam.obj"
    report, out = mesh(polydg, work, beam, "beam_tets", "--cells", 20, "--tets")
    close("beam: the tets' volume", report["tets"]["volume"], 10.0, 1e-14)
    for method in ("fem", "fs-fem"):
        solved = work / ("beam_%s.json" % method)
        run([polydg, "solve", out, "-o", work / ("beam_%s.vtu" % method), "--method", method,
             "--E", 1000, "--nu", 0, "--clamp", "x=0", "--traction", "x=10:10,0,0", "--report",
             solved, "--quiet"])
        r = read_json(solved)
        equal("beam, %s: tets solved" % method, r["tets"], report["tets"]["tets"])
        close("beam, %s: end displacement T L / E" % method, r["max_displacement"], 0.1, 1e-9)


GROUPS = {"adaptive": adaptive, "determinism": determinism, "python": python, "tets": tets}

if __name__ == "__main__":
    main(GROUPS, sys.argv)

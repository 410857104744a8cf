#!/usr/bin/env python3
"""`polydg export --format openfoam` end to end, checked by OpenFOAM itself (Debian's openfoam:
checkMesh, foamToVTK; the tests set WM_PROJECT_DIR themselves): bundled models sliced and cut
say "Mesh OK"; where checkMesh fails a model, it fails exactly the checks, with exactly the
figures, that polydg's report predicted; foamToVTK gives back the cells, volumes, points and
boundary areas; named patches; refusals; the pipeline step and Model.export.

Groups (one ctest each): checkmesh, quality, roundtrip, patches, refusals, pipeline, python.
Usage: export_end_to_end.py GROUP POLYDG WORKDIR (python: with the module on PYTHONPATH)
"""
import filecmp
import json
import os
import re
import shutil
import subprocess
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from end_to_end_support import (CheckFailed, Vtu, check, close, equal, main, np,  # noqa: E402
                                obj_area, obj_volume, read_json, read_xml, run)
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402
from vtkmodules.vtkIOXML import (vtkXMLPolyDataReader,  # noqa: E402
                                 vtkXMLUnstructuredGridReader)

TESTDATA = Path(__file__).resolve().parents[2] / "testdata"
FOAM_ENV = dict(os.environ, WM_PROJECT_DIR="/usr/share/openfoam")


def foam_tool(tool, case, *args):
    """Runs an OpenFOAM tool on `case`; its output."""
    if shutil.which(tool) is None:
        raise CheckFailed(tool + " not found; scripts/setup.sh installs Debian's openfoam")
    done = subprocess.run([tool, "-case", str(case), *args], capture_output=True, text=True,
                          env=FOAM_ENV)
    return done.stdout + done.stderr


def check_mesh(case):
    """checkMesh's verdict and figures, parsed from its output."""
    out = foam_tool("checkMesh", case)
    figures = {"output": out}
    m = re.search(r"Failed (\d+) mesh checks", out)
    figures["failed"] = int(m.group(1)) if m else 0
    figures["ok"] = "\nMesh OK." in out
    for key, pattern in [("cells", r"cells:\s+(\d+)"),
                         ("total_volume", r"Total volume = ([-+.\deE]+)"),
                         ("max_non_orthogonality", r"non-orthogonality Max: ([-+.\deE]+)"),
                         ("average_non_orthogonality", r"average: ([-+.\deE]+)"),
                         ("max_skewness", r"Max skewness = ([-+.\deE]+)"),
                         ("max_aspect_ratio", r"Max aspect ratio = ([-+.\deE]+)"),
                         ("skew_faces", r"skewness = [-+.\deE]+, (\d+) highly skew"),
                         ("non_orthogonality_errors", r"non-orthogonality errors: (\d+)"),
                         ("severely_non_orthogonal_faces", r"severely non-orthogonal.*?: (\d+)"),
                         ("wrong_oriented_faces", r"(\d+) faces are incorrectly oriented")]:
        m = re.search(pattern, out)
        figures[key] = float(m.group(1).rstrip(".")) if m else 0.0
    return figures


def mesh(polydg, work, surface, cells, name, *cuts, merge=None):
    """polydg mesh at `cells` (--cell if a float; no DG checks; --merge-slivers `merge` if
    given), then the cut planes given; the VTU's path. `surface`: in testdata/, or a path."""
    out = work / (name + ".vtu")
    size = ["--cell", cells] if isinstance(cells, float) else ["--cells", cells]
    run([polydg, "mesh", TESTDATA / surface, *size, "--no-dg", "-o", out, "--quiet",
         *(["--merge-slivers", merge] if merge is not None else [])])
    if cuts:
        sliced, out = out, work / (name + "_cut.vtu")
        args = [polydg, "cut", sliced, "-o", out, "--quiet"]
        for plane in cuts:
            args += ["--plane", plane]
        run(args)
    return out


def holed_block(path, nx=9, ny=9, nz=4):
    """A block of nx x ny x nz unit voxels without the columns at odd (i, j): 16 square
    through-holes along z, volume 260 for the defaults. Its boundary, as outward quads split
    into triangles on shared vertices; the block's volume."""
    full = {(i, j, k) for i in range(nx) for j in range(ny) for k in range(nz)
            if not (i % 2 == 1 and j % 2 == 1)}
    index, vertices, triangles = {}, [], []

    def vertex(p):
        if p not in index:
            index[p] = len(vertices) + 1
            vertices.append(p)
        return index[p]

    for voxel in sorted(full):
        for axis in range(3):
            u, w = [(1, 2), (2, 0), (0, 1)][axis]
            for side in (0, 1):
                beyond = list(voxel)
                beyond[axis] += 1 if side else -1
                if tuple(beyond) in full:
                    continue
                base = list(voxel)
                base[axis] += side
                corners = []
                for du, dw in ((0, 0), (1, 0), (1, 1), (0, 1)):
                    p = list(base)
                    p[u] += du
                    p[w] += dw
                    corners.append(tuple(p))
                a, b, c, d = (vertex(p) for p in (corners if side else corners[::-1]))
                triangles += [(a, b, c), (a, c, d)]
    with open(path, "w") as f:
        f.writelines("v %d %d %d\n" % p for p in vertices)
        f.writelines("f %d %d %d\n" % t for t in triangles)
    return float(len(full))


def export(polydg, work, vtu, name, *options):
    case, report = work / name, work / (name + ".json")
    run([polydg, "export", vtu, "--format", "openfoam", "-o", case, "--report", report,
         "--quiet", *options])
    return case, read_json(report)


# --- checkmesh -----------------------------------------------------------------------------

MODELS_OK = [("cube.obj", 8), ("Lprism.ply", 8), ("beam.obj", 8), ("two_cubes.obj", 8),
             ("instanced_cubes.gltf", 8), ("octahedron.stl", 8)]


def checkmesh(polydg, work):
    """Bundled models sliced, and cut by planes, and a block with 16 square through-holes at
    cells half the holes' side, in ASCII and binary: checkMesh says "Mesh OK" with no failed
    check, and polydg's report said so before."""
    cases = [(m, n, ()) for m, n in MODELS_OK]
    # Without sliver merging, whose non-convex unions checkMesh can refuse (see quality).
    for model, cells in [("octahedron.stl", 16), ("tetra.off", 8)]:
        vtu = mesh(polydg, work, model, cells, "unmerged_" + model.split(".")[0], merge=0)
        case, report = export(polydg, work, vtu, "unmerged_" + model.split(".")[0] + "_case")
        check(check_mesh(case)["ok"] and report["quality"]["check_mesh"] == "Mesh OK",
              "%s at %d cells, --merge-slivers 0: checkMesh says Mesh OK" % (model, cells))
    cases += [("cube.obj", 8, ("0,0,1,0.45",)), ("Lprism.ply", 8, ("1,0,0,0.3", "0,1,0,0.7")),
              ("beam.obj", 8, ("1,0,0,2.05",))]
    holes = work / "holes.obj"
    holed_block(holes)
    cases += [(holes, 0.5, ())]
    for k, (model, cells, cuts) in enumerate(cases):
        vtu = mesh(polydg, work, model, cells, "m%d" % k, *cuts)
        for binary in (False, True):
            case, report = export(polydg, work, vtu, "c%d%s" % (k, "b" if binary else ""),
                                  *(["--binary"] if binary else []))
            what = "%s at %s cells%s%s" % (Path(model).name, cells, " cut " + ";".join(cuts) if cuts else "",
                                           ", binary" if binary else "")
            figures = check_mesh(case)
            check(figures["ok"] and figures["failed"] == 0,
                  what + ": checkMesh says Mesh OK" +
                  ("" if figures["ok"] else "\n" + figures["output"][-3000:]))
            equal(what + ": polydg's report", report["quality"]["check_mesh"], "Mesh OK")
            equal(what + ": checkMesh's cells", int(figures["cells"]), report["cells"])
            if cuts:
                names = [p["name"] for p in report["patches"]]
                equal(what + ": patches", names, ["wall"] + ["cut%d" % i for i in range(len(cuts))])


# --- quality -------------------------------------------------------------------------------

def quality(polydg, work):
    """Models checkMesh fails (curved surfaces: their pieces of input triangles are far from
    the centres of cells they bound; the octahedron at 16 cells: merged slivers whose centres
    see faces edge-on; the tetrahedron: pieces of its faces in corner cells; the holed block at
    cell 0.45: thin L-shaped cut cells around the holes' corners, whose centre lies behind a
    wall's plane, but no skewed face: each cell's pieces of one flat wall go out as one face):
    polydg's report names the same failed checks with the same figures as checkMesh prints (to
    its 6 digits), and lists the worst faces."""
    holes = work / "holes.obj"
    holed_block(holes)
    for model, cells, failing in [("torus.obj", 12, ["skewness"]), ("ball.obj", 8, ["skewness"]),
                                  ("octahedron.stl", 16,
                                   ["non-orthogonality", "face pyramids", "skewness"]),
                                  ("tetra.off", 8, ["skewness"]),
                                  (holes, 0.45, ["face pyramids"])]:
        name = Path(model).stem
        vtu = mesh(polydg, work, model, cells, name)
        case, report = export(polydg, work, vtu, name + "_case")
        q = report["quality"]
        figures = check_mesh(case)
        what = "%s at %s cells" % (name, cells)
        equal(what + ": failed checks, checkMesh's against the report's", figures["failed"],
              len(q["failed_checks"]))
        equal(what + ": the checks the report says checkMesh fails", q["failed_checks"], failing)
        for key in ["total_volume", "max_non_orthogonality", "average_non_orthogonality",
                    "max_skewness", "max_aspect_ratio"]:
            close(what + ": " + key, q[key], figures[key], 5e-6)
        for key in ["skew_faces", "non_orthogonality_errors", "severely_non_orthogonal_faces",
                    "wrong_oriented_faces"]:
            equal(what + ": " + key, q[key], int(figures[key]))
        worst = q["worst_faces"]
        check(len(worst) == min(20, q["skew_faces"] + q["wrong_oriented_faces"]) or
              len(worst) == 20, what + ": the report lists the worst faces")
        if q["skew_faces"]:
            check(max(w["skewness"] for w in worst) == q["max_skewness"],
                  what + ": the worst faces include the most skewed")
        check(any("small pieces of the input's triangles" in a for a in q["advice"]) ==
              (q["skew_boundary_faces"] > 0), what + ": the advice names the skewed pieces")
        check(any("--merge-slivers 0" in a for a in q["advice"]) ==
              (q["wrong_oriented_faces"] + q["non_orthogonality_errors"] > 0),
              what + ": the advice names non-convex merged cells where they are")


# --- roundtrip -----------------------------------------------------------------------------

def foam_vtk(case):
    """foamToVTK's internal mesh (points, per-cell faces) and its boundary patches' areas."""
    foam_tool("foamToVTK", case)
    vtk_dir = next((case / "VTK").glob("*_0"))
    grid = read_xml(vtkXMLUnstructuredGridReader, vtk_dir / "internal.vtu",
                    lambda g: g.GetNumberOfCells())
    points = vtk_to_numpy(grid.GetPoints().GetData()).astype(float)
    cells = []
    for c in range(grid.GetNumberOfCells()):
        cell = grid.GetCell(c)
        faces = []
        for k in range(cell.GetNumberOfFaces()):
            f = cell.GetFace(k)
            faces.append([f.GetPointId(i) for i in range(f.GetNumberOfPoints())])
        cells.append(faces)
    areas = {}
    for vtp in (vtk_dir / "boundary").glob("*.vtp"):
        data = read_xml(vtkXMLPolyDataReader, vtp, lambda d: d.GetNumberOfCells())
        p = vtk_to_numpy(data.GetPoints().GetData()).astype(float)
        conn = vtk_to_numpy(data.GetPolys().GetConnectivityArray()).tolist()
        offsets = vtk_to_numpy(data.GetPolys().GetOffsetsArray()).tolist()
        total = 0.0
        for a, b in zip(offsets[:-1], offsets[1:]):
            f = p[conn[a:b]]
            total += 0.5 * np.linalg.norm(np.cross(f[1:-1] - f[0], f[2:] - f[0]).sum(axis=0))
        areas[vtp.stem] = total
    return points, cells, areas


def foam_volumes(case):
    """OpenFOAM's own cell volumes (postProcess -func writeCellVolumes), written at the 17
    digits of the exported controlDict's writePrecision: cell i is polydg's element i."""
    foam_tool("postProcess", case, "-func", "writeCellVolumes")
    text = (case / "constant" / "V").read_text()
    body = text[text.index("List<scalar>"):]
    count = int(body.split()[1])
    values = body[body.index("(") + 1:body.index(")")].split()
    equal("V's length", len(values), count)
    return np.array([float(v) for v in values])


def roundtrip(polydg, work):
    """The torus at 12 cells, and the same cut by a plane, in ASCII and binary, read back by
    OpenFOAM: its own cell volumes (writeCellVolumes, 17 digits) are polydg's elements' (from
    polydg's VTU, computed here) to 1e-12 of each cell, in polydg's element order, and sum to
    the surface's enclosed volume (its triangles, computed here) to 1e-12; foamToVTK gives back
    as many cells, and the wall's area is the input surface's to foamToVTK's float32
    round-off (1e-6). The same for a block with 16 through-holes at cells larger than the
    holes, whose faces with holes are written as triangles."""
    holes = work / "holes.obj"
    volume = holed_block(holes)
    vtu = mesh(polydg, work, holes, 2.7, "holes")
    ours = Vtu(vtu)
    reference = np.empty(len(ours.cells))
    reference[ours.field_data["polydg_element"].astype(np.int64)] = ours.cell_volumes()
    case, report = export(polydg, work, vtu, "holes_case", "--binary")
    check(report["split_faces"] > 0, "the holed block at cell 2.7: %d faces with holes written as "
          "triangles" % report["split_faces"])
    got = foam_volumes(case)
    worst = np.max(np.abs(got - reference) / np.abs(reference))
    check(len(got) == len(reference) and worst <= 1e-12,
          "holed block: OpenFOAM's volume of each cell the element's, worst %.3g" % worst)
    close("holed block: total volume", got.sum(), volume, 1e-12)
    torus = TESTDATA / "torus.obj"
    enclosed, area = obj_volume(torus), obj_area(torus)
    for cuts in [(), ("0,1,0,0.3",)]:
        vtu = mesh(polydg, work, "torus.obj", 12, "torus%d" % len(cuts), *cuts)
        ours = Vtu(vtu)
        reference = np.empty(len(ours.cells))
        reference[ours.field_data["polydg_element"].astype(np.int64)] = ours.cell_volumes()
        for binary in (False, True):
            name = "torus%d%s" % (len(cuts), "b" if binary else "")
            case, report = export(polydg, work, vtu, name, *(["--binary"] if binary else []))
            what = "torus%s%s" % (" cut" if cuts else "", ", binary" if binary else "")
            got = foam_volumes(case)
            equal(what + ": OpenFOAM's cells", len(got), len(reference))
            worst = np.max(np.abs(got - reference) / np.abs(reference))
            check(worst <= 1e-12, what + ": OpenFOAM's volume of each cell the element's, "
                  "worst %.3g" % worst)
            points, cells, areas = foam_vtk(case)
            equal(what + ": foamToVTK's cells", len(cells), len(reference))
            if not cuts:
                close(what + ": total volume", got.sum(), enclosed, 1e-12)
                close(what + ": wall area (foamToVTK, float32)", areas["wall"], area, 1e-6)
            else:
                check(set(areas) == {"wall", "cut0"}, what + ": patches wall and cut0")
                check(areas["wall"] < area and areas["cut0"] > 0,
                      what + ": the cut's faces are patch cut")


# --- patches -------------------------------------------------------------------------------

def patches(polydg, work):
    """The unit cube at 4 cells with --patch bottom=z=0 --patch top=below:0,0,-1,-1 --patch
    side=box:...: each patch holds exactly its faces (areas from foamToVTK), before wall, which
    holds the rest; checkMesh says Mesh OK."""
    vtu = mesh(polydg, work, "cube.obj", 4, "cube")
    case, report = export(polydg, work, vtu, "cube_case", "--patch", "bottom=z=0",
                          "--patch", "top=below:0,0,-1,-1", "--patch", "side=box:-1,-1,-1,0,2,2")
    equal("patches", [p["name"] for p in report["patches"]], ["bottom", "top", "side", "wall"])
    faces = {p["name"]: p["faces"] for p in report["patches"]}
    check(faces["bottom"] == faces["top"] == faces["side"] and faces["wall"] == 3 * faces["top"],
          "each side of the cube holds as many faces: %s" % faces)
    _, _, areas = foam_vtk(case)
    for name, a in [("bottom", 1.0), ("top", 1.0), ("side", 1.0), ("wall", 3.0)]:
        close("area of " + name + " (foamToVTK, float32)", areas[name], a, 1e-6)
    check(check_mesh(case)["ok"], "checkMesh says Mesh OK with named patches")
    boundary = (case / "constant" / "polyMesh" / "boundary").read_text()
    check("bottom\n{\n    type            wall;" in boundary, "the boundary file names bottom")
    # Two cuts by two commands (the cuts travel in the VTU): each its own patch, both sides.
    once = mesh(polydg, work, "cube.obj", 8, "cube8", "0,0,1,0.45")
    twice = work / "cube8_twice.vtu"
    run([polydg, "cut", once, "-o", twice, "--plane", "1,0,0,0.3", "--quiet"])
    out, _ = run([polydg, "info", twice, "--report", work / "info.json", "--quiet"])
    equal("the cuts in the VTU's provenance", read_json(work / "info.json")["provenance"]["cuts"],
          [[0, 0, 1, 0.45], [1, 0, 0, 0.3]])
    case, report = export(polydg, work, twice, "cube_cuts")
    equal("patches of two cuts", [p["name"] for p in report["patches"]], ["wall", "cut0", "cut1"])
    _, _, areas = foam_vtk(case)
    for name, a in [("wall", 6.0), ("cut0", 2.0), ("cut1", 2.0)]:
        close("area of " + name + " (foamToVTK, float32)", areas[name], a, 1e-6)
    check(check_mesh(case)["ok"], "checkMesh says Mesh OK with two cuts' patches")
    # An oblique cut: its points are its exact intersections rounded, all still on its patch.
    oblique = mesh(polydg, work, "torus.obj", 12, "torus_oblique", "1,1,3,0.25")
    case, report = export(polydg, work, oblique, "torus_oblique_case")
    equal("patches of an oblique cut", [p["name"] for p in report["patches"]], ["wall", "cut0"])


# --- refusals ------------------------------------------------------------------------------

def refusals(polydg, work):
    """One line and exit 2 (an input error), nothing written or lost: a patch that selects nothing, a name
    OpenFOAM cannot read, a name given twice, an output folder that is not a case; an
    existing case is replaced whole."""
    vtu = mesh(polydg, work, "cube.obj", 4, "cube")
    before = vtu.read_bytes()
    for args, words in [(["--patch", "far=x=5"], "patch 'far' (the plane x = 5) selects no "
                         "boundary face"),
                        (["--patch", "a b=x=0"], "is not an OpenFOAM word"),
                        (["--patch", "a=x=0", "--patch", "a=x=1"], "is given twice"),
                        (["--patch", "a=side:1,2"], "is not a region"),
                        (["--patch", "wall=x=0"], "is one of the default patches")]:
        case = work / "refused"
        _, err = run([polydg, "export", vtu, "-o", case, *args], expect=2)
        lines = [line for line in err.strip().splitlines() if line]
        check(words in err and len(lines) <= 2, "refused: %s: %s" % (" ".join(args), err.strip()))
        check(not case.exists() and not list(work.glob("refused.tmp-*")),
              "nothing written for " + " ".join(args))
    equal("the input unchanged", vtu.read_bytes(), before)
    plain = work / "plain"
    plain.mkdir()
    (plain / "keep.txt").write_text("mine")
    _, err = run([polydg, "export", vtu, "-o", plain], expect=2)
    check("is not an OpenFOAM case" in err and (plain / "keep.txt").read_text() == "mine",
          "a folder that is not a case is refused and left as it was")
    case = work / "again"
    run([polydg, "export", vtu, "-o", case, "--quiet"])
    (case / "constant" / "polyMesh" / "stale").write_text("old")
    run([polydg, "export", vtu, "-o", case, "--quiet"])
    check(not (case / "constant" / "polyMesh" / "stale").exists(),
          "an existing case is replaced whole")


# --- pipeline ------------------------------------------------------------------------------

def pipeline(polydg, work):
    """A pipeline (mesh, cut, export with a patch) over the cube and beam: each input's case
    says Mesh OK, its patches are as asked, and the result lists the export's figures."""
    for name in ["cube.obj", "beam.obj"]:
        shutil.copy(TESTDATA / name, work / name)
    spec = {"inputs": ["cube.obj", "beam.obj"], "steps": [
        {"step": "mesh", "cells": 8, "dg_checks": False},
        {"step": "cut", "plane": [0, 0, 1, 0.45]},
        {"step": "export", "path": "{stem}_case", "binary": True,
         "patches": [{"name": "bottom", "below": [0, 0, 1, 0]}]}]}
    (work / "p.json").write_text(json.dumps(spec))
    run([polydg, "run", work / "p.json", "--out", work / "out", "--quiet"])
    for stem in ["cube", "beam"]:
        found = list((work / "out").rglob(stem + "_case"))
        check(len(found) == 1, stem + ": the export step wrote its case")
        figures = check_mesh(found[0])
        check(figures["ok"], stem + ": checkMesh says Mesh OK")
        points = (found[0] / "constant" / "polyMesh" / "points").read_bytes()
        check(b"format      binary;" in points[:400], stem + ": written in binary, as asked")
        boundary = (found[0] / "constant" / "polyMesh" / "boundary").read_text()
        check(boundary.index("bottom") < boundary.index("wall") < boundary.index("cut0"),
              stem + ": patches bottom, wall, cut0 in that order")


# --- python --------------------------------------------------------------------------------

def python(polydg, work):
    """Model.export gives the CLI's files byte for byte, and the same report."""
    import polydg as pd
    vtu = mesh(polydg, work, "torus.obj", 12, "torus", "0,1,0,0.3")
    case, report = export(polydg, work, vtu, "cli_case", "--patch", "low=below:0,0,1,-0.2")
    r = pd.read(str(vtu)).export(work / "py_case", patches={"low": {"below": [0, 0, 1, -0.2]}})
    for f in ["points", "faces", "owner", "neighbour", "boundary"]:
        check(filecmp.cmp(case / "constant/polyMesh" / f, work / "py_case/constant/polyMesh" / f,
                          shallow=False), "constant/polyMesh/%s: the CLI's bytes" % f)
    equal("the report's quality", r["quality"], report["quality"])
    equal("the report's patches", r["patches"], report["patches"])


if __name__ == "__main__":
    main({"checkmesh": checkmesh, "quality": quality, "roundtrip": roundtrip,
          "patches": patches, "refusals": refusals, "pipeline": pipeline, "python": python},
         sys.argv)

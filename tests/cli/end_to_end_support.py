"""Shared helpers of the end-to-end scripts (tests/cli/*_end_to_end.py): running the polydg
binary as a user does, writing small surfaces, reading what it wrote with VTK (Debian's
python3-vtk9, independent of polydg) and asserting numbers against references.

Every check prints what it measured, so a passing run documents the figures too; a failing one
raises CheckFailed, which the scripts turn into exit code 1 with the check's line.
"""
import json
import subprocess
import sys
import xml.etree.ElementTree as ET


class CheckFailed(Exception):
    pass


def need(module, package):
    """Imports `module` or fails naming the Debian package that provides it (never a skip)."""
    try:
        return __import__(module)
    except ImportError as error:
        raise CheckFailed("cannot import %s (%s): install Debian's %s (scripts/setup.sh)" %
                          (module, error, package))


np = need("numpy", "python3-numpy")
need("vtkmodules", "python3-vtk9")
# The few VTK modules used (importing all of vtk costs 0.3 s of CPU per script).
from vtkmodules.util.numpy_support import vtk_to_numpy  # noqa: E402  (after the check above)
from vtkmodules.vtkCommonDataModel import VTK_POLYHEDRON  # noqa: E402
from vtkmodules.vtkIOXML import (vtkXMLPolyDataReader,  # noqa: E402
                                 vtkXMLUnstructuredGridReader)


def run(command, expect=0, env=None):
    """Runs `command` (a list), returns (stdout, stderr); fails unless it exits with `expect`."""
    done = subprocess.run([str(c) for c in command], capture_output=True, text=True, env=env)
    if done.returncode != expect:
        raise CheckFailed("exit %d (expected %d): %s\n%s%s" %
                          (done.returncode, expect, " ".join(str(c) for c in command),
                           done.stdout, done.stderr))
    return done.stdout, done.stderr


def read_json(path):
    with open(path) as f:
        return json.load(f)


def check(condition, message):
    """Asserts `condition`, printing `message` either way."""
    print(("ok    " if condition else "FAIL  ") + message, flush=True)
    if not condition:
        raise CheckFailed(message)


def close(name, got, reference, tolerance, relative=True):
    """|got - reference| <= tolerance (times |reference| if relative), printed either way."""
    difference = abs(got - reference)
    bound = tolerance * abs(reference) if relative else tolerance
    check(difference <= bound,
          "%s: %.17g against %.17g, difference %.3g (bound %.3g)" %
          (name, got, reference, difference, bound))


def equal(name, got, reference):
    """got == reference exactly (numbers, lists, strings), printed either way."""
    check(got == reference, "%s: %r, expected exactly %r" % (name, got, reference))


def box_obj(path, lo, hi):
    """The box [lo, hi] as 12 outward triangles (vertex k = 4 ix + 2 iy + iz, 1-based)."""
    corners = [(x, y, z) for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])]
    faces = [(1, 2, 4), (1, 4, 3), (5, 7, 8), (5, 8, 6), (1, 5, 6), (1, 6, 2),
             (3, 4, 8), (3, 8, 7), (1, 3, 7), (1, 7, 5), (2, 6, 8), (2, 8, 4)]
    with open(path, "w") as out:
        for c in corners:
            out.write("v %r %r %r\n" % c)
        for f in faces:
            out.write("f %d %d %d\n" % f)
    return path


def sphere_obj(path, centre, radius, rings=8, segments=12):
    """A closed UV sphere (outward triangles)."""
    c = np.asarray(centre, dtype=float)
    vertices = [c + [0.0, 0.0, radius]]
    for i in range(1, rings):
        theta = np.pi * i / rings
        for j in range(segments):
            phi = 2.0 * np.pi * j / segments
            vertices.append(c + radius * np.array([np.sin(theta) * np.cos(phi),
                                                   np.sin(theta) * np.sin(phi), np.cos(theta)]))
    vertices.append(c + [0.0, 0.0, -radius])
    bottom = len(vertices) - 1
    ring = lambda i, j: 1 + (i - 1) * segments + j % segments  # noqa: E731
    triangles = [(0, ring(1, j), ring(1, j + 1)) for j in range(segments)]
    for i in range(1, rings - 1):
        for j in range(segments):
            triangles += [(ring(i, j), ring(i + 1, j), ring(i + 1, j + 1)),
                          (ring(i, j), ring(i + 1, j + 1), ring(i, j + 1))]
    triangles += [(ring(rings - 1, j), bottom, ring(rings - 1, j + 1)) for j in range(segments)]
    with open(path, "w") as out:
        for v in vertices:
            out.write("v %r %r %r\n" % tuple(v))
        for t in triangles:
            out.write("f %d %d %d\n" % tuple(k + 1 for k in t))
    return np.array(vertices)


def read_obj(path):
    """The vertices (n x 3) and triangles (m x 3, 0-based) of an OBJ of triangles."""
    vertices, triangles = [], []
    with open(path) as f:
        for line in f:
            parts = line.split()
            if parts and parts[0] == "v":
                vertices.append([float(x) for x in parts[1:4]])
            elif parts and parts[0] == "f":
                triangles.append([int(x.split("/")[0]) - 1 for x in parts[1:4]])
    return np.array(vertices), np.array(triangles)


def obj_volume(path):
    """Enclosed volume of an OBJ of triangles (divergence theorem), independent of polydg."""
    v, t = read_obj(path)
    return np.einsum("ij,ij->", v[t[:, 0]], np.cross(v[t[:, 1]], v[t[:, 2]])) / 6.0


def obj_area(path):
    """Surface area of an OBJ of triangles, independent of polydg."""
    v, t = read_obj(path)
    return 0.5 * np.linalg.norm(np.cross(v[t[:, 1]] - v[t[:, 0]], v[t[:, 2]] - v[t[:, 0]]),
                                axis=1).sum()


def read_xml(reader_type, path, size):
    """The dataset a VTK XML reader of `reader_type` reads from `path`; CheckFailed if it reports
    an error or `size` of the dataset is 0."""
    reader = reader_type()
    reader.SetFileName(str(path))
    reader.Update()
    data = reader.GetOutput()
    if reader.GetErrorCode() != 0 or data is None or size(data) == 0:
        raise CheckFailed("VTK could not read %s" % path)
    return data


def arrays_of(attributes):
    """A VTK point or cell data's arrays by name, as float numpy arrays."""
    arrays = {}
    for k in range(attributes.GetNumberOfArrays()):
        a = attributes.GetArray(k)
        arrays[a.GetName()] = vtk_to_numpy(a).astype(float)
    return arrays


class Vtu:
    """A VTU file read by VTK: points, each cell's faces (lists of point ids), point, cell and
    (numeric) field data as numpy arrays."""

    def __init__(self, path):
        grid = read_xml(vtkXMLUnstructuredGridReader, path, lambda g: g.GetNumberOfCells())
        self.points = vtk_to_numpy(grid.GetPoints().GetData()).astype(float)
        self.point_data = arrays_of(grid.GetPointData())
        self.cell_data = arrays_of(grid.GetCellData())
        self.field_data = {}
        for k in range(grid.GetFieldData().GetNumberOfArrays()):
            a = grid.GetFieldData().GetArray(k)
            if a is not None:
                self.field_data[a.GetName()] = vtk_to_numpy(a)
        # Each cell's faces from the grid's face stream (nFaces, then nPoints and the point ids
        # of each face), read as one array: per-cell VTK calls would cost seconds on 10^4 cells.
        for c in range(grid.GetNumberOfCells()):
            if grid.GetCellType(c) != VTK_POLYHEDRON:
                raise CheckFailed("%s: cell %d is not a polyhedron" % (path, c))
        stream = vtk_to_numpy(grid.GetFaces()).tolist()
        self.cells = []
        for at in vtk_to_numpy(grid.GetFaceLocations()).tolist():
            faces, count = [], stream[at]
            at += 1
            for _ in range(count):
                n = stream[at]
                faces.append(stream[at + 1:at + 1 + n])
                at += n + 1
            self.cells.append(faces)

    def cell_volumes(self):
        """Signed volume of each cell by the divergence theorem over its faces: the sum of the
        tetrahedra from a point of the cell (its first face's first point, shifted to the mean
        of its face points to keep round-off small) to the fan triangles of each face."""
        cell, a, b, c = [], [], [], []
        for k, faces in enumerate(self.cells):
            for f in faces:
                for i in range(1, len(f) - 1):
                    cell.append(k)
                    a.append(f[0])
                    b.append(f[i])
                    c.append(f[i + 1])
        cell = np.asarray(cell)
        counts = np.bincount(cell, minlength=len(self.cells))
        centre = np.zeros((len(self.cells), 3))
        np.add.at(centre, cell, self.points[a])
        centre /= counts[:, None]
        pa = self.points[a] - centre[cell]
        pb = self.points[b] - centre[cell]
        pc = self.points[c] - centre[cell]
        out = np.zeros(len(self.cells))
        np.add.at(out, cell, np.einsum("ij,ij->i", pa, np.cross(pb, pc)))
        return out / 6.0

    def cell_boxes(self):
        """Each cell's bounding box as (lo, hi) arrays of shape (cells, 3)."""
        lo = np.empty((len(self.cells), 3))
        hi = np.empty((len(self.cells), 3))
        for c, faces in enumerate(self.cells):
            p = self.points[np.unique(np.concatenate([np.asarray(f) for f in faces]))]
            lo[c], hi[c] = p.min(axis=0), p.max(axis=0)
        return lo, hi


def read_vtp(path):
    """Points and point data of a VTP surface, read by VTK."""
    data = read_xml(vtkXMLPolyDataReader, path, lambda d: d.GetNumberOfPoints())
    return vtk_to_numpy(data.GetPoints().GetData()).astype(float), arrays_of(data.GetPointData())


def read_pvd(path):
    """(timestep, part, file) of each DataSet of a ParaView collection."""
    root = ET.parse(path).getroot()
    return [(float(d.get("timestep")), int(d.get("part", "0")), d.get("file"))
            for d in root.iter("DataSet")]


def main(groups, argv, keep=()):
    """Usage: SCRIPT GROUP POLYDG WORKDIR: runs groups[GROUP](polydg, workdir) in WORKDIR,
    emptied first unless GROUP is in `keep` (groups that check what another group wrote)."""
    if len(argv) != 4 or argv[1] not in groups:
        sys.exit("usage: %s {%s} POLYDG WORKDIR" % (argv[0], "|".join(groups)))
    import pathlib
    import shutil
    work = pathlib.Path(argv[3])
    if argv[1] not in keep:
        shutil.rmtree(work, ignore_errors=True)
        work.mkdir(parents=True)
    try:
        groups[argv[1]](argv[2], work)
    except CheckFailed as failure:
        sys.exit("end-to-end check failed: %s" % failure)

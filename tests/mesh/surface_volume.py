#!/usr/bin/python3
"""Prints the volume enclosed by a surface model, computed independently of polydg.

Usage: /usr/bin/python3 tests/mesh/surface_volume.py [--verbose] MODEL.{obj,ply,off,stl}

Which reader reads the model (the extension's letter case does not matter):

  .obj .ply .off .stl   meshio (Debian's python3-meshio 5), in double precision: meshio keeps
                        the file's values (ASCII text parsed to float64; binary STL and PLY
                        float32 values widened exactly to float64), and the volume is the
                        divergence-theorem sum over a fan of each polygon, in numpy float64
                        (exact for planar polygons, convex or not).
  .obj .ply .stl        if meshio cannot read the file, VTK instead (Debian's python3-vtk9:
                        vtkOBJReader, vtkPLYReader, vtkSTLReader, then vtkTriangleFilter and
                        vtkMassProperties). VTK 9.1 stores points in single precision, so its
                        volume carries a relative error of about 1e-8 for coordinates that float32
                        cannot represent. meshio 5.0 cannot read, for example, OBJ files whose
                        `vn`/`vt` counts differ from their `v` count, PLY lists declared
                        `uint8 int32`, or PLY headers with `comment` before `format`.
  .off                  meshio only (VTK has no OFF reader); meshio 5.0 reads only `OFF` headers
                        and triangular faces, so other OFF files fail.

The volume is printed as one JSON number on stdout. It is the magnitude of the volume, so
compare it with the absolute value of polydg's signed volume; it is meaningful only for closed
surfaces. --verbose also names the reader used on stderr ("meshio" or "vtk"). Exits with
status 1 and a one-line message on stderr if no reader can read the file, or the file holds no
polygons. VTK and meshio are Debian packages that only the system interpreter /usr/bin/python3
can import.
"""

import contextlib
import io
import json
import os
import re
import sys

MESHIO_FORMATS = {".obj": "obj", ".ply": "ply", ".off": "off", ".stl": "stl"}
VTK_EXTENSIONS = (".obj", ".ply", ".stl")


def fail(message):
    print(f"surface_volume.py: {message}", file=sys.stderr)
    sys.exit(1)


def first_line(error):
    text = str(error)
    return text.splitlines()[0] if text.strip() else type(error).__name__


class MeshioCannotRead(Exception):
    pass


def meshio_volume(path, extension):
    """|sum over polygons of fan triangles (a, b, c) of a . (b x c)| / 6, in double precision.

    Raises MeshioCannotRead if meshio cannot import or read the file."""
    try:
        import meshio
        import numpy
    except ImportError as e:
        raise MeshioCannotRead(f"cannot import meshio ({e}); install python3-meshio")
    # The format's own reader: meshio.read() prints reader errors on stdout and calls
    # sys.exit() when no reader succeeds. Anything else a reader prints is kept off stdout too.
    reader = getattr(meshio, MESHIO_FORMATS[extension])
    printed = io.StringIO()
    try:
        with contextlib.redirect_stdout(printed):
            mesh = reader.read(path)
    except (Exception, SystemExit) as e:  # meshio raises many kinds
        raise MeshioCannotRead(f"meshio cannot read it ({first_line(e)})")
    points = numpy.asarray(mesh.points, dtype=numpy.float64)
    if points.ndim != 2 or points.shape[1] != 3 or len(points) == 0:
        raise MeshioCannotRead("meshio read no 3D points from it")
    centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
    p = points - centre
    total = 0.0
    polygons = 0
    for block in mesh.cells:
        if block.type in ("vertex", "line"):
            continue
        if block.type == "polygon" and isinstance(block.data, list):  # ragged polygons
            faces = [numpy.asarray(face) for face in block.data]
        else:
            faces = [numpy.asarray(block.data)]
        for data in faces:
            data = data.reshape(-1, data.shape[-1])
            polygons += len(data)
            for k in range(1, data.shape[1] - 1):
                a, b, c = p[data[:, 0]], p[data[:, k]], p[data[:, k + 1]]
                total += numpy.einsum("ij,ij->", a, numpy.cross(b, c))
    if polygons == 0:
        fail(f"{path}: meshio read no polygons from it")
    return abs(total) / 6.0


def vtk_volume(path, extension):
    """vtkMassProperties' volume of the triangulated polygons VTK reads from the file."""
    try:
        from vtkmodules.vtkCommonCore import vtkCommand, vtkLogger, vtkOutputWindow
        from vtkmodules.vtkFiltersCore import vtkMassProperties, vtkTriangleFilter
        from vtkmodules.vtkIOGeometry import vtkOBJReader, vtkSTLReader
        from vtkmodules.vtkIOPLY import vtkPLYReader
    except ImportError as e:
        fail(f"cannot import VTK ({e}); run with /usr/bin/python3 and install python3-vtk9")

    readers = {".obj": vtkOBJReader, ".stl": vtkSTLReader, ".ply": vtkPLYReader}

    # Collect VTK's error messages instead of letting its output window and logger print them.
    vtkOutputWindow.GetInstance().SetDisplayModeToNever()
    vtkLogger.SetStderrVerbosity(vtkLogger.VERBOSITY_OFF)
    errors = []

    def on_error(caller, event, message=None):
        # "ERROR: In FILE, line N\nvtkClass (0x...): what went wrong\n": keep what went wrong.
        lines = [line for line in str(message or event).splitlines() if line.strip()]
        errors.append(re.sub(r"^\w+ \(0x[0-9a-fA-F]+\): ", "", lines[-1] if lines else str(event)))

    on_error.CallDataType = "string0"

    reader = readers[extension]()
    reader.SetFileName(path)
    reader.AddObserver(vtkCommand.ErrorEvent, on_error)
    reader.Update()
    if errors or reader.GetErrorCode() != 0:
        reason = errors[0] if errors else f"error code {reader.GetErrorCode()}"
        fail(f"{path}: VTK cannot read it ({reason})")
    polydata = reader.GetOutput()
    if polydata.GetNumberOfPolys() + polydata.GetNumberOfStrips() == 0:
        fail(f"{path}: VTK read no polygons from it")

    triangles = vtkTriangleFilter()
    triangles.SetInputData(polydata)
    triangles.PassVertsOff()
    triangles.PassLinesOff()
    triangles.AddObserver(vtkCommand.ErrorEvent, on_error)
    mass = vtkMassProperties()
    mass.SetInputConnection(triangles.GetOutputPort())
    mass.AddObserver(vtkCommand.ErrorEvent, on_error)
    mass.Update()
    if errors:
        fail(f"{path}: VTK cannot compute its volume ({errors[0]})")
    return mass.GetVolume()


def main(argv):
    args = argv[1:]
    verbose = "--verbose" in args
    args = [a for a in args if a != "--verbose"]
    if len(args) != 1:
        fail("usage: surface_volume.py [--verbose] MODEL.{obj,ply,off,stl}")
    path = args[0]
    if not os.path.isfile(path):
        fail(f"{path}: no such file")
    extension = os.path.splitext(path)[1].lower()
    if extension not in MESHIO_FORMATS:
        fail(f"{path}: the volume check reads .obj, .ply, .off and .stl files only")

    try:
        volume, used = meshio_volume(path, extension), "meshio"
    except MeshioCannotRead as e:
        if extension not in VTK_EXTENSIONS:
            fail(f"{path}: {e}; VTK has no reader for {extension} files")
        volume, used = vtk_volume(path, extension), "vtk"
    if verbose:
        print(used, file=sys.stderr)
    print(json.dumps(volume))


if __name__ == "__main__":
    main(sys.argv)

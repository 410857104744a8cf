#!/usr/bin/python3
"""Prints the volume enclosed by a surface model, computed independently of polydg with VTK.

Usage: /usr/bin/python3 tests/mesh/surface_volume.py MODEL.{obj,stl,ply}

Reads the model with VTK's reader for its extension (vtkOBJReader, vtkSTLReader,
vtkPLYReader), splits polygons into triangles (vtkTriangleFilter) and prints the volume from
vtkMassProperties as one JSON number on stdout. vtkMassProperties returns the magnitude of the
volume, so compare it with the absolute value of polydg's signed volume; it is meaningful only
for closed surfaces. Exits with status 1 and a one-line message on stderr if VTK cannot read
the file or it holds no polygons. Needs Debian's python3-vtk9, which only the system
interpreter /usr/bin/python3 can import.
"""

import json
import os
import re
import sys


def fail(message):
    print(f"surface_volume.py: {message}", file=sys.stderr)
    sys.exit(1)


def main(argv):
    if len(argv) != 2:
        fail("usage: surface_volume.py MODEL.{obj,stl,ply}")
    path = argv[1]
    if not os.path.isfile(path):
        fail(f"{path}: no such file")

    try:
        from vtkmodules.vtkCommonCore import vtkCommand, vtkLogger, vtkOutputWindow
        from vtkmodules.vtkFiltersCore import vtkMassProperties, vtkTriangleFilter
        from vtkmodules.vtkIOGeometry import vtkOBJReader, vtkSTLReader
        from vtkmodules.vtkIOPLY import vtkPLYReader
    except ImportError as e:
        fail(f"cannot import VTK ({e}); run with /usr/bin/python3 and install python3-vtk9")

    readers = {".obj": vtkOBJReader, ".stl": vtkSTLReader, ".ply": vtkPLYReader}
    extension = os.path.splitext(path)[1].lower()
    if extension not in readers:
        fail(f"{path}: VTK volume check supports .obj, .stl and .ply files only")

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
        fail(f"{path}: VTK cannot read it ({errors[0] if errors else 'error code %d' % reader.GetErrorCode()})")
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
    print(json.dumps(mass.GetVolume()))


if __name__ == "__main__":
    main(sys.argv)

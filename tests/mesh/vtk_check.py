#!/usr/bin/python3
"""Checks polydg's VTU files with VTK and meshio, independently of polydg, and writes VTU test
files with VTK itself for polydg's reader.

Sample runs (Debian's interpreter, which has python3-vtk9 and python3-meshio):
  /usr/bin/python3 tests/mesh/vtk_check.py out/grid.vtu 6.12 --cells 12
  /usr/bin/python3 tests/mesh/vtk_check.py out/cut_boxes.vtu 2 --cells 2 --regions 2
  /usr/bin/python3 tests/mesh/vtk_check.py out/field_data_ascii.vtu 6.12 --field-data \
      out/field_data.json
  /usr/bin/python3 tests/mesh/vtk_check.py --write-vtk build/vtk_cells.vtu

Check mode: opens FILE with VTK 9.1 (vtkXMLUnstructuredGridReader) and with meshio 5. Every cell
must be a polyhedron. With VTK, each cell's faces become a vtkPolyData, triangulated by
vtkTriangleFilter, measured by vtkMassProperties (unsigned volume; the sign comes from its
projected volume). With meshio, each cell's volume is the divergence theorem over its face
lists (numpy). Each volume must match the file's `volume` cell data to 1e-9 relative, and the
totals must match EXPECTED_TOTAL_VOLUME to 1e-9 relative. With --regions N, the cells must form
N connected regions through shared points (VTK: vtkConnectivityFilter; meshio: cells joined by
common point ids), which is how the two sides of a cut are told apart. With --field-data
EXPECTED.json, the file's field data must be, for both VTK and meshio, polydg's restore arrays
(polydg_face_*, polydg_element*, polydg_point_*) plus exactly the expected arrays: each number
array a Float64 array with the same values bit for bit, each text NAME a UInt8 array
NAME.utf8 holding the text's bytes. EXPECTED.json, written by vtu_io_test's WriteForVtkCheck, is
{"numbers": {NAME_HEX: [HEX_FLOAT, ...]}, "strings": {NAME_HEX: BYTES_HEX}}: names and text as
hex of their UTF-8 bytes, numbers as C99 hex floats (printf "%a"), so that no JSON escaping
stands between the test and this check. Exits 1 with a message otherwise.

--write-vtk OUT.vtu: writes, with vtkXMLUnstructuredGridWriter, a mesh of three polyhedra:
cell 0 the unit cube, cell 1 an L-shaped (non-convex) prism of volume 3 sharing the cube's
x = 1 face, cell 2 a pyramid of volume 1/3 on the cube's top (19 points, 18 distinct faces).
Beside OUT.vtu (writer defaults: appended, base64, zlib, UInt32 headers, Int64 ids) it writes
variants STEM_SUFFIX.vtu:
  _raw                 appended raw binary, zlib, UInt64 headers
  _binary              inline base64, zlib
  _ascii               ascii
  _uncompressed        appended raw, uncompressed, Int32 ids, Float32 points
  _binary_uncompressed inline base64, uncompressed, UInt64 headers
  _inverted            every face reversed (volumes negative), defaults
  _leaky               the L prism's top face removed, defaults
  _linear              one cell of each 3D linear type (tetra 1/6, voxel 1, hexahedron 2,
                       wedge 1/2, pyramid 1/3, pentagonal prism 3, hexagonal prism 6) and a
                       polyhedral unit cube, defaults
and checks with VTK that the cells have these volumes (polyhedra as in check mode, linear cells
with vtkCellSizeFilter) and that vtkCellValidator accepts the linear cells (but the voxel, which
it always rejects). OUT.vtu and its first five variants (not _inverted, _leaky, _linear) carry
the field data of add_field_data(), which vtu_io_test's VtkWrittenFile.ReturnsItsFieldData
expects.
"""

import argparse
import json
import os
import struct
import sys

import numpy as np
import vtk

RELATIVE_TOLERANCE = 1e-9


class CheckFailed(Exception):
    pass


def close(a, b, scale):
    return abs(a - b) <= RELATIVE_TOLERANCE * max(abs(scale), 1e-300)


def signed_volume(points, faces):
    """Divergence theorem: sum over faces of (fan triangles) det / 6, about the centroid."""
    ids = np.unique(np.concatenate([np.asarray(f, dtype=np.int64) for f in faces]))
    centre = points[ids].mean(axis=0)
    total = 0.0
    for face in faces:
        p = points[np.asarray(face, dtype=np.int64)] - centre
        total += np.einsum("ij,ij->", np.broadcast_to(p[0], p[1:-1].shape),
                           np.cross(p[1:-1], p[2:]))
    return total / 6.0


# ---------------------------------------------------------------------------------------------
# Check mode
# ---------------------------------------------------------------------------------------------


class ErrorObserver:
    """Collects VTK error events instead of letting VTK print and carry on."""

    def __init__(self):
        self.messages = []

    def __call__(self, caller, event):
        self.messages.append(f"{caller.GetClassName()}: {event}")


def polyhedron_volume(grid, c, face_stream=None):
    """Signed volume of polyhedral cell c: its faces as a vtkPolyData, vtkTriangleFilter,
    vtkMassProperties. (vtkCellSizeFilter is wrong for non-convex polyhedra in VTK 9.1.)"""
    face_stream = face_stream or vtk.vtkIdList()
    grid.GetFaceStream(c, face_stream)
    polys = vtk.vtkCellArray()
    at = 1
    for _ in range(face_stream.GetId(0)):
        n = face_stream.GetId(at)
        polys.InsertNextCell(n, [face_stream.GetId(at + 1 + i) for i in range(n)])
        at += n + 1
    surface = vtk.vtkPolyData()
    surface.SetPoints(grid.GetPoints())
    surface.SetPolys(polys)
    triangles = vtk.vtkTriangleFilter()
    triangles.SetInputData(surface)
    mass = vtk.vtkMassProperties()
    mass.SetInputConnection(triangles.GetOutputPort())
    mass.Update()
    volume, projected = mass.GetVolume(), mass.GetVolumeProjected()
    # VTK's own test for a closed, consistently oriented triangle surface; GetVolume() is
    # unsigned, the projected volume carries the orientation.
    if not close(volume, abs(projected), volume):
        raise CheckFailed(f"VTK: cell {c} is not closed (volume {volume}, projected {projected})")
    return volume if projected >= 0 else -volume


def vtk_cell_volumes(path):
    """(computed, stored) volume per cell, read with VTK."""
    reader = vtk.vtkXMLUnstructuredGridReader()
    observer = ErrorObserver()
    reader.AddObserver("ErrorEvent", observer)
    reader.GetExecutive().AddObserver("ErrorEvent", observer)
    reader.SetFileName(path)
    reader.Update()
    grid = reader.GetOutput()
    if observer.messages or reader.GetErrorCode() != 0 or grid is None:
        raise CheckFailed(f"VTK could not read {path}: {observer.messages}")
    stored = grid.GetCellData().GetArray("volume")
    if stored is None:
        raise CheckFailed(f"VTK: {path} has no 'volume' cell data")
    results = []
    face_stream = vtk.vtkIdList()
    for c in range(grid.GetNumberOfCells()):
        if grid.GetCellType(c) != vtk.VTK_POLYHEDRON:
            raise CheckFailed(f"VTK: cell {c} has type {grid.GetCellType(c)}, not a polyhedron")
        results.append((polyhedron_volume(grid, c, face_stream), stored.GetValue(c)))
    return results


def meshio_cell_volumes(path):
    """(computed, stored) volume per cell, read with meshio."""
    import meshio

    try:
        mesh = meshio.read(path, file_format="vtu")
    except Exception as error:  # meshio raises many kinds
        raise CheckFailed(f"meshio could not read {path}: {type(error).__name__}: {error}")
    if "volume" not in mesh.cell_data:
        raise CheckFailed(f"meshio: {path} has no 'volume' cell data")
    for name in ("polydg_face_group", "polydg_face_reversed", "polydg_face_origin"):
        if name not in mesh.field_data:
            raise CheckFailed(f"meshio: field data '{name}' is missing")
    # meshio 5 puts polyhedra in blocks "polyhedronN" by point count, in order of first
    # appearance, but their cell data in order of increasing N: match them up by N.
    sizes = []
    for block in mesh.cells:
        if not block.type.startswith("polyhedron"):
            raise CheckFailed(f"meshio: unexpected cell block {block.type}")
        sizes.append(int(block.type[len("polyhedron"):]))
    data_index = {n: i for i, n in enumerate(sorted(set(sizes)))}
    points = np.asarray(mesh.points, dtype=np.float64)
    results = []
    for block, n in zip(mesh.cells, sizes):
        stored = np.asarray(mesh.cell_data["volume"][data_index[n]]).ravel()
        if len(stored) != len(block.data):
            raise CheckFailed(f"meshio: block {block.type} has {len(block.data)} cells but "
                              f"{len(stored)} volumes")
        for faces, value in zip(block.data, stored):
            results.append((signed_volume(points, faces), float(value)))
    records = sum(len(faces) for block in mesh.cells for faces in block.data)
    groups = len(mesh.field_data["polydg_face_group"])
    if groups != records:
        raise CheckFailed(f"meshio: polydg_face_group has {groups} entries for {records} face "
                          "records")
    return results


def vtk_regions(path):
    """Connected regions of the cells through shared points, with vtkConnectivityFilter."""
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    connectivity = vtk.vtkConnectivityFilter()
    connectivity.SetInputConnection(reader.GetOutputPort())
    connectivity.SetExtractionModeToAllRegions()
    connectivity.Update()
    return connectivity.GetNumberOfExtractedRegions()


def meshio_regions(path):
    """Connected regions of the cells through shared point ids, read with meshio."""
    import meshio

    mesh = meshio.read(path, file_format="vtu")
    parent = {}

    def find(x):
        while parent.setdefault(x, x) != x:
            parent[x] = parent[parent[x]]
            x = parent[x]
        return x

    cell = 0
    for block in mesh.cells:
        for faces in block.data:
            for face in faces:
                for p in np.asarray(face, dtype=np.int64):
                    a, b = find(("cell", cell)), find(("point", int(p)))
                    if a != b:
                        parent[a] = b
            cell += 1
    return len({find(("cell", c)) for c in range(cell)})


RESTORE_PREFIXES = ("polydg_face_", "polydg_element", "polydg_point_")
TEXT_SUFFIX = ".utf8"


def expected_field_data(json_path):
    """{file array name: ("numbers", [float]) or ("text", bytes)} from EXPECTED.json."""
    with open(json_path, encoding="ascii") as f:
        spec = json.load(f)
    expected = {}
    for name_hex, values in spec["numbers"].items():
        expected[bytes.fromhex(name_hex).decode("utf-8")] = (
            "numbers", [float.fromhex(v) for v in values])
    for name_hex, text_hex in spec["strings"].items():
        expected[bytes.fromhex(name_hex).decode("utf-8") + TEXT_SUFFIX] = (
            "text", bytes.fromhex(text_hex))
    return expected


def bits(values):
    return struct.pack(f"<{len(values)}d", *values)


def compare_field_data(reader, found, expected):
    """`found`: {name: ("numbers" | "text" | type name, values or bytes)} as a reader saw it."""
    names = {n for n in found if not n.startswith(RESTORE_PREFIXES)}
    if names != set(expected):
        raise CheckFailed(f"{reader}: field data {sorted(names)}, expected {sorted(expected)}")
    for name, (kind, value) in expected.items():
        found_kind, found_value = found[name]
        if found_kind != kind:
            raise CheckFailed(f"{reader}: field data {name!r} is {found_kind}, expected {kind}")
        if kind == "numbers" and bits(found_value) != bits(value):
            raise CheckFailed(f"{reader}: field data {name!r} is {found_value!r}, expected "
                              f"{value!r}")
        if kind == "text" and found_value != value:
            raise CheckFailed(f"{reader}: field data {name!r} holds {found_value!r}, expected "
                              f"{value!r}")


def vtk_field_data(path):
    reader = vtk.vtkXMLUnstructuredGridReader()
    observer = ErrorObserver()
    reader.AddObserver("ErrorEvent", observer)
    reader.AddObserver("WarningEvent", observer)
    reader.SetFileName(path)
    reader.Update()
    if observer.messages or reader.GetErrorCode() != 0:
        raise CheckFailed(f"VTK could not read {path}: {observer.messages}")
    field = reader.GetOutput().GetFieldData()
    found = {}
    for i in range(field.GetNumberOfArrays()):
        array = field.GetAbstractArray(i)
        values = [array.GetValue(k) for k in range(array.GetNumberOfValues())]
        if isinstance(array, vtk.vtkDoubleArray):
            found[array.GetName()] = ("numbers", values)
        elif isinstance(array, vtk.vtkUnsignedCharArray):
            found[array.GetName()] = ("text", bytes(values))
        else:
            found[array.GetName()] = (array.GetClassName(), values)
    return found


def meshio_field_data(path):
    import meshio

    try:
        mesh = meshio.read(path, file_format="vtu")
    except BaseException as error:  # meshio raises many kinds, and SystemExit for some files
        raise CheckFailed(f"meshio could not read {path}: {type(error).__name__}: {error}")
    found = {}
    for name, data in mesh.field_data.items():
        data = np.asarray(data)
        if data.dtype == np.float64:
            found[name] = ("numbers", [float(v) for v in data.ravel()])
        elif data.dtype == np.uint8:
            found[name] = ("text", data.tobytes())
        else:
            found[name] = (str(data.dtype), data.tolist())
    return found


def check_field_data(path, json_path):
    expected = expected_field_data(json_path)
    for reader, read in (("VTK", vtk_field_data), ("meshio", meshio_field_data)):
        compare_field_data(reader, read(path), expected)
        print(f"vtk_check: {reader}: {len(expected)} field data arrays as written: ok")


def check(path, expected_total, expected_cells, expected_regions=None):
    for reader, volumes in (("VTK", vtk_cell_volumes), ("meshio", meshio_cell_volumes)):
        results = volumes(path)
        if expected_cells is not None and len(results) != expected_cells:
            raise CheckFailed(f"{reader}: {len(results)} cells, expected {expected_cells}")
        for c, (computed, stored) in enumerate(results):
            if not close(computed, stored, stored):
                raise CheckFailed(f"{reader}: cell {c} has volume {computed!r}, the file says "
                                  f"{stored!r}")
        total = sum(computed for computed, _ in results)
        if not close(total, expected_total, expected_total):
            raise CheckFailed(f"{reader}: total volume {total!r}, expected {expected_total!r}")
        print(f"vtk_check: {reader}: {len(results)} cells, total volume {total!r}: ok")
    if expected_regions is not None:
        for reader, regions in (("VTK", vtk_regions), ("meshio", meshio_regions)):
            found = regions(path)
            if found != expected_regions:
                raise CheckFailed(f"{reader}: {found} connected regions, expected "
                                  f"{expected_regions}")
            print(f"vtk_check: {reader}: {found} connected regions: ok")


# ---------------------------------------------------------------------------------------------
# --write-vtk mode
# ---------------------------------------------------------------------------------------------


class MeshBuilder:
    """Points by coordinates (shared when equal) and cells as lists of faces of points."""

    def __init__(self):
        self.points = []
        self.index = {}
        self.cells = []  # (vtk type, point ids or faces)

    def point(self, xyz):
        key = tuple(float(v) for v in xyz)
        if key not in self.index:
            self.index[key] = len(self.points)
            self.points.append(key)
        return self.index[key]

    def polyhedron(self, faces):
        self.cells.append((vtk.VTK_POLYHEDRON, [[self.point(p) for p in f] for f in faces]))

    def linear(self, cell_type, points):
        self.cells.append((cell_type, [self.point(p) for p in points]))

    def grid(self, point_type=vtk.VTK_DOUBLE):
        points = vtk.vtkPoints()
        points.SetDataType(point_type)
        for p in self.points:
            points.InsertNextPoint(*p)
        grid = vtk.vtkUnstructuredGrid()
        grid.SetPoints(points)
        for cell_type, ids in self.cells:
            if cell_type == vtk.VTK_POLYHEDRON:
                stream = [len(ids)]
                for face in ids:
                    stream += [len(face)] + face
                id_list = vtk.vtkIdList()
                for i in stream:
                    id_list.InsertNextId(i)
                grid.InsertNextCell(cell_type, id_list)
            else:
                grid.InsertNextCell(cell_type, len(ids), ids)
        return grid


def prism_faces(polygon, z0, z1):
    """Outward faces of the prism over a counter-clockwise polygon."""
    bottom = [(x, y, z0) for x, y in reversed(polygon)]
    top = [(x, y, z1) for x, y in polygon]
    sides = []
    for i, (x0, y0) in enumerate(polygon):
        x1, y1 = polygon[(i + 1) % len(polygon)]
        sides.append([(x0, y0, z0), (x1, y1, z0), (x1, y1, z1), (x0, y0, z1)])
    return [bottom] + sides + [top]


UNIT_SQUARE = [(0, 0), (1, 0), (1, 1), (0, 1)]
# L shape, counter-clockwise, with (1, 1) on its x = 1 side so that it shares the cube's face.
L_SHAPE = [(1, 0), (3, 0), (3, 1), (2, 1), (2, 2), (1, 2), (1, 1)]
POLYHEDRA_VOLUMES = [1.0, 3.0, 1.0 / 3.0]


def polyhedra_faces():
    cube = prism_faces(UNIT_SQUARE, 0, 1)
    l_prism = prism_faces(L_SHAPE, 0, 1)
    apex = (0.5, 0.5, 2.0)
    pyramid = [[(x, y, 1) for x, y in reversed(UNIT_SQUARE)]]
    for i, (x0, y0) in enumerate(UNIT_SQUARE):
        x1, y1 = UNIT_SQUARE[(i + 1) % 4]
        pyramid.append([(x0, y0, 1), (x1, y1, 1), apex])
    return [cube, l_prism, pyramid]


def linear_cells(builder):
    """One cell of each 3D linear type, positively oriented in VTK's numbering, at x offsets."""
    def shift(points, dx):
        return [(x + dx, y, z) for x, y, z in points]

    builder.linear(vtk.VTK_TETRA, shift([(0, 0, 0), (1, 0, 0), (0, 1, 0), (0, 0, 1)], 0))
    voxel = [(x, y, z) for z in (0, 1) for y in (0, 1) for x in (0, 1)]  # x fastest
    builder.linear(vtk.VTK_VOXEL, shift(voxel, 2))
    builder.linear(vtk.VTK_HEXAHEDRON,
                   shift([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0),
                          (0, 0, 2), (1, 0, 2), (1, 1, 2), (0, 1, 2)], 4))
    # VTK's wedge: the normal of (0, 1, 2) points away from (3, 4, 5).
    builder.linear(vtk.VTK_WEDGE,
                   shift([(0, 0, 0), (0, 1, 0), (1, 0, 0), (0, 0, 1), (0, 1, 1), (1, 0, 1)], 6))
    builder.linear(vtk.VTK_PYRAMID,
                   shift([(0, 0, 0), (1, 0, 0), (1, 1, 0), (0, 1, 0), (0.5, 0.5, 1)], 8))
    pentagon = [(0, 0), (2, 0), (2, 1), (1, 2), (0, 1)]  # area 3
    builder.linear(vtk.VTK_PENTAGONAL_PRISM,
                   shift([(x, y, 0) for x, y in pentagon] + [(x, y, 1) for x, y in pentagon], 10))
    hexagon = [(0, 0), (2, 0), (3, 1), (2, 2), (0, 2), (-1, 1)]  # area 6
    builder.linear(vtk.VTK_HEXAGONAL_PRISM,
                   shift([(x, y, 0) for x, y in hexagon] + [(x, y, 1) for x, y in hexagon], 14))
    builder.polyhedron([[(x + 18, y, z) for x, y, z in f] for f in prism_faces(UNIT_SQUARE, 0, 1)])
    return [1.0 / 6.0, 1.0, 2.0, 0.5, 1.0 / 3.0, 3.0, 6.0, 1.0]


def add_field_data(grid):
    """Field data of the kinds VTK writes, which polydg's reader must return (see
    VtkWrittenFile.ReturnsItsFieldData): doubles, floats, two-component ints, unsigned chars
    that are not text, 64-bit ids, a string with XML's special characters, non-ASCII letters, a
    newline and a tab, two strings in one array, text by polydg's convention (UInt8 NAME.utf8),
    and a bit array, which polydg skips."""
    field = grid.GetFieldData()

    def add(array, name, values, components=1):
        array.SetName(name)
        array.SetNumberOfComponents(components)
        for v in values:
            array.InsertNextValue(v)
        field.AddArray(array)

    add(vtk.vtkDoubleArray(), "cell_size", [0.125])
    add(vtk.vtkFloatArray(), "scale", [0.25])
    add(vtk.vtkIntArray(), "counts", [1, 2, 3, -4], components=2)
    add(vtk.vtkUnsignedCharArray(), "mask", [0, 1, 255])
    add(vtk.vtkIdTypeArray(), "ids", [-7, 2**31 - 1])  # the _uncompressed copy has Int32 ids
    add(vtk.vtkStringArray(), "note", ['a "q" <b> & \u00e9\nx\ttab'])
    add(vtk.vtkStringArray(), "tags", ["first", "second"])
    add(vtk.vtkUnsignedCharArray(), "input_file" + TEXT_SUFFIX, list("torus \u00fc.obj".encode()))
    add(vtk.vtkBitArray(), "flags", [1, 0, 1])


def vtk_validity(grid, c):
    """vtkCellValidator's state of linear cell c (0: valid), checked on its own."""
    single = vtk.vtkUnstructuredGrid()
    single.SetPoints(grid.GetPoints())
    single.InsertNextCell(grid.GetCellType(c), grid.GetCell(c).GetPointIds())
    validator = vtk.vtkCellValidator()
    validator.SetInputData(single)
    validator.Update()
    return validator.GetOutput().GetCellData().GetArray("ValidityState").GetValue(0)


def check_with_vtk(grid, volumes, name, expect_valid):
    """Checks VTK's volume of each cell (polyhedra: polyhedron_volume; linear cells:
    vtkCellSizeFilter) and, if `expect_valid`, that vtkCellValidator accepts the linear cells.
    Polyhedra and voxels are not validated: VTK 9.1's validator rejects every non-convex
    polyhedron and every voxel."""
    sizes = vtk.vtkCellSizeFilter()
    sizes.SetInputData(grid)
    sizes.Update()
    linear_sizes = sizes.GetOutput().GetCellData().GetArray("Volume")
    for c, expected in enumerate(volumes):
        cell_type = grid.GetCellType(c)
        if cell_type == vtk.VTK_POLYHEDRON:
            computed = polyhedron_volume(grid, c)
        else:
            computed = linear_sizes.GetValue(c)
            if expect_valid and cell_type != vtk.VTK_VOXEL and vtk_validity(grid, c) != 0:
                raise CheckFailed(f"{name}: vtkCellValidator rejects cell {c}")
        if not close(computed, expected, expected):
            raise CheckFailed(f"{name}: VTK gives cell {c} volume {computed}, expected {expected}")


def write_grid(grid, path, configure=None):
    writer = vtk.vtkXMLUnstructuredGridWriter()
    writer.SetFileName(path)
    writer.SetInputData(grid)
    if configure:
        configure(writer)
    if writer.Write() != 1:
        raise CheckFailed(f"VTK could not write {path}")


def write_vtk(out):
    stem, _ = os.path.splitext(out)
    directory = os.path.dirname(out)
    if directory:
        os.makedirs(directory, exist_ok=True)

    def build(faces_per_cell):
        builder = MeshBuilder()
        for faces in faces_per_cell:
            builder.polyhedron(faces)
        return builder

    cells = polyhedra_faces()
    builder = build(cells)
    grid = builder.grid()
    add_field_data(grid)
    if len(builder.points) != 19:
        raise CheckFailed(f"expected 19 points, built {len(builder.points)}")
    check_with_vtk(grid, POLYHEDRA_VOLUMES, out, expect_valid=False)

    write_grid(grid, out)
    def raw_uint64(writer):
        writer.EncodeAppendedDataOff()
        writer.SetHeaderTypeToUInt64()

    write_grid(grid, f"{stem}_raw.vtu", raw_uint64)
    write_grid(grid, f"{stem}_binary.vtu", lambda w: w.SetDataModeToBinary())
    write_grid(grid, f"{stem}_ascii.vtu", lambda w: w.SetDataModeToAscii())

    def small_types(writer):
        writer.EncodeAppendedDataOff()
        writer.SetCompressorTypeToNone()
        writer.SetHeaderTypeToUInt32()
        writer.SetIdTypeToInt32()

    float_grid = builder.grid(vtk.VTK_FLOAT)
    add_field_data(float_grid)
    write_grid(float_grid, f"{stem}_uncompressed.vtu", small_types)

    def inline_uncompressed(writer):
        writer.SetDataModeToBinary()
        writer.SetCompressorTypeToNone()
        writer.SetHeaderTypeToUInt64()

    write_grid(grid, f"{stem}_binary_uncompressed.vtu", inline_uncompressed)

    inverted = build([[list(reversed(f)) for f in faces] for faces in cells]).grid()
    check_with_vtk(inverted, [-v for v in POLYHEDRA_VOLUMES], "inverted", expect_valid=False)
    write_grid(inverted, f"{stem}_inverted.vtu")

    leaky_cells = [cells[0], cells[1][:-1], cells[2]]  # the L prism's last face is its top
    write_grid(build(leaky_cells).grid(), f"{stem}_leaky.vtu")

    linear = MeshBuilder()
    volumes = linear_cells(linear)
    linear_grid = linear.grid()
    check_with_vtk(linear_grid, volumes, "linear", expect_valid=True)
    write_grid(linear_grid, f"{stem}_linear.vtu")
    print(f"vtk_check: wrote {out} and its variants")


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("file", nargs="?", help="VTU file to check")
    parser.add_argument("expected_total_volume", nargs="?", type=float)
    parser.add_argument("--cells", type=int, help="expected number of cells")
    parser.add_argument("--regions", type=int,
                        help="expected number of regions connected through shared points")
    parser.add_argument("--field-data", metavar="EXPECTED.json",
                        help="the field data polydg wrote into FILE")
    parser.add_argument("--write-vtk", metavar="OUT.vtu", help="write test files with VTK")
    args = parser.parse_args()
    try:
        if args.write_vtk:
            write_vtk(args.write_vtk)
        elif args.file is not None and args.expected_total_volume is not None:
            check(args.file, args.expected_total_volume, args.cells, args.regions)
            if args.field_data:
                check_field_data(args.file, args.field_data)
        else:
            parser.error("give FILE and EXPECTED_TOTAL_VOLUME, or --write-vtk OUT.vtu")
    except CheckFailed as failure:
        print(f"vtk_check: FAIL: {failure}", file=sys.stderr)
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())

"""polydg from Python: surfaces in, polyhedral DG simulation meshes out, cut, checked and solved.

The same library operations as the ``polydg`` command line (one implementation of each):

    import polydg
    surface = polydg.read_surface("part.stl")           # or polydg.Surface(V, F)
    model = polydg.mesh(surface, cells=32)               # a Model: mesh + integrals + provenance
    report = model.cut(plane=[0, 0, 1, 0.5], remove_side="+")
    model.check()
    model.solve(degree=2, E=1e6, nu=0.3, gravity=[0, 0, -9.81], clamp=[{"below": [0, 0, 1, 0.1]}])
    model.write("part.vtu")

Every operation returns its report as a dict with the keys of the command line's JSON report.
Bad input raises ``polydg.Error`` with the command line's one-line message; a result that fails
a check raises ``polydg.CheckFailure`` (a subclass). ``polydg.batch`` runs a pipeline over many
inputs, locally or on a Dask cluster.
"""

import os as _os


def _match_blas_kernels():
    """Debian 12's OpenBLAS (0.3.21) does not know recent Intel CPUs and falls back to its SSE3
    kernels, which make CHOLMOD's factorizations 1.5-2x slower. OpenBLAS reads
    OPENBLAS_CORETYPE when it is loaded: set it for this CPU's kernels before the module loads
    OpenBLAS (as the `polydg` binary does), unless the user set it. Processes started from this
    one (Dask's local workers) inherit it. No effect if OpenBLAS is already loaded (numpy
    imported first with Debian's OpenBLAS): the kernels OpenBLAS chose stay."""
    if "OPENBLAS_CORETYPE" in _os.environ:
        return
    try:
        with open("/proc/cpuinfo", encoding="ascii", errors="replace") as f:
            flags = next((line.split(":", 1)[1].split() for line in f
                          if line.startswith("flags")), [])
    except OSError:
        return
    if {"avx512f", "avx512dq", "avx512bw", "avx512vl"} <= set(flags):
        _os.environ["OPENBLAS_CORETYPE"] = "SkylakeX"
    elif {"avx2", "fma"} <= set(flags):
        _os.environ["OPENBLAS_CORETYPE"] = "Haswell"


_match_blas_kernels()

from . import _polydg  # noqa: E402  (after the kernels are chosen)
from ._polydg import CheckFailure, Error, Surface  # noqa: E402
from .batch import batch  # noqa: E402

__version__ = _polydg.__version__

__all__ = [
    "CheckFailure",
    "Error",
    "Model",
    "Surface",
    "batch",
    "mesh",
    "read",
    "read_surface",
]


def read_surface(path):
    """Reads a triangle surface from a file (OBJ, STL, PLY, OFF with CGAL; glTF, FBX and the rest
    with assimp), welding vertices by exact position.

    Returns a ``Surface``; lines of the file that were skipped are in ``surface.warnings`` (a list
    of "FILE:LINE: what" strings), the file in ``surface.source`` (which ``mesh`` records as the
    model's source: the surface an embedding carries by default). Raises ``Error`` for a file
    that cannot be read.
    """
    surface, warnings = _polydg.read_surface(_os.fspath(path))
    surface.warnings = warnings
    surface.source = _os.fspath(path)
    return surface


def mesh(surface, cells=None, cell=None, repair="none", merge_slivers=None, dg_checks=None,
         progress=None, source="", adaptive=None):
    """Meshes a closed surface into a ``Model`` of polyhedral elements (``polydg mesh``).

    surface: a ``Surface`` (from ``read_surface`` or ``Surface(V, F)``).
    cells: about this many grid cells along the bounding box's longest side; or
    cell: the grid cell's edge length (model units). Give exactly one.
    repair: "none", "fill" (close holes) or "wrap" (alpha-wrap any soup).
    merge_slivers: slivers are merged: elements below this fraction T of a cell's volume, or with
    6 volume / area below T^(1/3) of a cell edge (thin slabs) (default 0.01).
    dg_checks: run the element-local DG checks of the result (default True).
    progress: a callable taking the slicing progress in [0, 1], or None.
    source: the name recorded in the model's provenance (the file it came from).
    adaptive: octree slicing (``polydg mesh --adaptive``): cells/cell give the finest cells, used
    only where the surface passes; inside, cells as coarse as a one-level jump between face
    neighbours allows.

    Returns the Model; its ``report`` attribute holds the command line's mesh report as a dict.
    Raises ``Error`` for a surface it refuses (naming the defect), ``CheckFailure`` if the new
    mesh fails its validation or DG checks.
    """
    kwargs = {"cells": cells, "cell": cell, "repair": repair, "merge_slivers": merge_slivers,
              "dg_checks": dg_checks, "adaptive": adaptive}
    model, report = _polydg.mesh(surface, kwargs, source=source or getattr(surface, "source", ""),
                                 progress=progress)
    model.report = report
    return model


def read(path):
    """Reads a simulation mesh (VTU) into a ``Model``, with its provenance if polydg wrote it;
    or a tet mesh (TetGen .ele with its .node, Gmsh MSH 4.1 .msh), each tet an element, for
    the tet methods ("fem", "fs-fem" in ``solve`` and in scenes). Raises ``Error`` for a file it
    cannot read (a tet mesh's bad tet named)."""
    model, report = _polydg.read(_os.fspath(path))
    model.report = report
    return model


Model = _polydg.Model


def _to_meshio(self):
    """The mesh as a ``meshio.Mesh`` (polyhedron cells, with the solution's fields if solved),
    by way of a VTU file that meshio reads."""
    import tempfile

    import meshio

    with tempfile.TemporaryDirectory(prefix="polydg-") as folder:
        path = _os.path.join(folder, "model.vtu")
        self.write(path)
        return meshio.read(path)


def _given(**kwargs):
    return {k: v for k, v in kwargs.items() if v is not None}


def _cut(self, plane=None, remove_side=None, polygon=None, validate="local",
         sliver_fraction=None):
    """Cuts the model in place (``polydg cut``) and validates the operation.

    plane: [nx, ny, nz, d], the plane {x : n.x = d} (n need not be unit length); or
    polygon: [[x, y, z], ...], a convex planar blade (elements whose section lies inside it are
    split; those at its edge stay whole). Give exactly one.
    remove_side: "+" deletes what lies where n.x > d, "-" the other side, None keeps both.
    validate: "none", "local" (the touched elements and one ring) or "full".
    sliver_fraction: new pieces below this fraction of the reference volume are merged
    (default: the mesh's sliver rule, see ``provenance``).

    Returns the operation's report (elements_split, pieces_created, elements_removed,
    volume_removed, sliver_threshold, slivers_merged, faces_reintegrated, validation, ...).
    Raises ``Error`` for bad arguments, ``CheckFailure`` if the validation fails or the cut leaves
    nothing (the model must then not be used further).
    """
    return self._cut(**_given(plane=plane, polygon=polygon, remove_side=remove_side,
                              validate=validate, sliver_fraction=sliver_fraction))


def _merge_slivers(self, fraction=None, validate="local"):
    """Merges elements below ``fraction`` (default: the mesh's sliver rule) of the reference
    volume into the neighbour they share the most face area with; validated like a cut.
    Returns the operation's report."""
    return self._merge_slivers(**_given(fraction=fraction, validate=validate))


def _check(self, degree=1):
    """The checks of ``polydg check``: geometric validation, the element-local DG checks (patch
    test, rigid modes, definiteness) of the given degree (1-3), and the global zero-mode count up
    to 25k DOFs. Returns the report; ``report["passed"]`` says whether all passed."""
    return self._check(degree=degree)


def _solve(self, method="ip", degree=None, E=None, nu=None, density=None, gravity=None,
           clamp=None, traction=None, solver=None, penalty=None, eta=None, adapt=None,
           estimate=None, bz_penalty=None):
    """Static linear elasticity (``polydg solve``) on the model; keeps the solution for
    ``write``.

    method: DG, "ip" (interior penalty) or "bz" (Babuska-Zlamal), with degree 1-3 (default 1);
    or on a model of tetrahedra (``read`` of a .msh, .ele or a VTU of tets) "fem" (linear FEM)
    or "fs-fem" (the face-based smoothed FEM), which clamp every corner of a clamp's faces and
    take no DG option (degree, bz_penalty, penalty, eta, adapt, estimate). Their solution,
    linear on each tet, is the model's as DG degree 1.
    bz_penalty: with method="bz", "super" (the default: the superpenalty ~h^-(2p+1), converges
    at rate >= p, with a stiffer system) or "fixed" (penalty ~1/h, cheap, but its error does not
    fall under refinement: the report's "warnings" says so).
    E: Young's modulus (default 1), nu: Poisson's ratio in (-1, 0.5) (default 0.3),
    density: mass density (default 1; with gravity), gravity: [gx, gy, gz] (acceleration).
    clamp: where u = 0 (weakly); a region or a list of regions (at least one). A region is a dict:
    {"below": [a, b, c, d]} (boundary faces with (a, b, c).x <= d), {"plane": [a, b, c, d]},
    {"box": [[x0, y0, z0], [x1, y1, z1]]} or {"axis": "z", "value": 0}.
    traction: a region dict with "traction": [tx, ty, tz] (force per area), or a list of them.
    solver: "auto", "cholesky" or "cg"; penalty: "bound", "doubling" or "fixed" (with eta).
    adapt: solve adaptively (``polydg solve --adapt``), refining the model in place: True, or a
    dict of "by" ("error": the a posteriori estimate, or "stress": the largest principal
    stress), "split" ("octants" 1-to-8 or "halves" 1-to-2), "target_error" (stop below this
    fraction of the energy norm), "max_dofs", "max_rounds" (default 3), "bulk" (share of the
    squared estimate to refine, default 0.5), "stress_fraction" (default 0.5), "max_level" (how
    often stress may split an element, default 1). The report's
    "adapt" holds every round.
    estimate: add the a posteriori error estimate to the report (IP only).

    Returns the solve's report (dofs, energy, max_displacement, max_von_mises, solver, ...).
    Raises ``Error`` for bad arguments or a region that selects no face, ``CheckFailure`` for an
    invalid mesh or a body that is not held (singular stiffness).
    """
    if isinstance(clamp, dict):
        clamp = [clamp]
    if isinstance(traction, dict):
        traction = [traction]
    material = _given(E=E, nu=nu, density=density)
    return self._solve(**_given(method=method, degree=degree, material=material or None,
                                gravity=gravity, clamp=clamp, traction=traction, solver=solver,
                                penalty=penalty, eta=eta, adapt=adapt, estimate=estimate,
                                bz_penalty=bz_penalty))


def _refine(self, elements, split="octants", directions=None, merge_slivers=None,
            validate="local"):
    """Refines the model in place: each element in ``elements`` (ids) is split by the three
    mid-planes of its bounding box ("octants", 1-to-8) or by the plane through its centroid across
    a direction ("halves", 1-to-2; ``directions`` one [x, y, z] per element, default: the last
    solution's largest principal stress direction). The new faces are interior faces; neighbours'
    faces are split so faces stay shared exactly. The last solution, if any, goes to the children
    exactly and stays the model's solution. Validated like a cut (``validate``: "none", "local",
    "full"). Returns the operation's report (with "solution_exact")."""
    return self._refine(**_given(elements=[int(e) for e in elements], split=split,
                                 directions=directions, merge_slivers=merge_slivers,
                                 validate=validate))


def _coarsen(self, groups, validate="local"):
    """Merges each group of element ids (two or more, face-connected, e.g. the children of a
    refinement) back into one element; the last solution, if any, is projected onto the merged
    elements (L2: mass and momentum kept exactly). Validated like a cut. Returns the operation's
    report (with "solution_projected")."""
    return self._coarsen([[int(e) for e in g] for g in groups], validate=validate)


def _simulate(self, scene, output=None, progress=None):
    """Moves the body in time (``polydg simulate``): dynamic DG elasticity through the steps of
    ``scene``, with its cuts made at their times on this model. Afterwards the model holds the
    cut mesh and, as its solution, the final displacement (``element_displacements``, ``write``).
    With "method": "fem" or "fs-fem" a model of tetrahedra moves by the tet method instead
    (no cuts, embedding, obstacles or adaptivity).

    scene: a dict in the scene format of docs/guide.md (material, dt, steps or duration, gravity,
    fixed, loads, initial, cuts, embed, obstacles, contact, ...), or the path (str or
    os.PathLike) of a scene JSON file (files it names are relative to its folder; a dict's,
    to the working directory). Every key is checked before the run starts.
    output: a folder for the ParaView time series (scene.pvd and one VTU per frame, with point
    data "displacement" and "velocity"; with "embed", also the deformed surface as a VTP per
    frame with point data "displacement"), created if missing; None writes no file.
    progress: a callable progress(step, steps, t), called after each step; an exception it
    raises stops the simulation and reaches the caller. None: no calls.

    Returns the report: scene (every key explicit), elements, dofs, steps (per step: t, kinetic,
    elastic, gravity, momentum, angular_momentum, centre_of_mass, cg_iterations, ...; with
    obstacles contacts, deepest_penetration, contact_energy, collision_seconds), cuts (each
    with its operation's report), frames, pvd (None without output), embedding and contact
    (with "embed" or obstacles), timings_s.
    Raises ``Error`` for a bad scene (naming the key, e.g. "scene: dt: ...") or a region that
    selects no face, ``CheckFailure`` for an invalid mesh, a step whose solve fails, or a cut that
    fails its validation (the model must then not be used further, as after ``cut``).
    """
    if isinstance(scene, (str, bytes, _os.PathLike)):
        scene = _os.fsdecode(scene)
    if progress is not None and not callable(progress):
        raise TypeError(f"progress must be callable or None, not {type(progress).__name__}")
    return self._simulate(scene, "" if output is None else _os.fsdecode(output), progress)


def _surface_arg(surface):
    return "" if surface is None else _os.fsdecode(surface)


def _embedding_weights(self, surface=None, degree=None, support=2.0):
    """The MLS embedding of a surface's vertices into the DG displacement (paper section 8,
    eq. 19), as a sparse matrix in triplet form, without scipy.

    surface: a surface file (any format ``read_surface`` reads), or None for the surface the
    mesh was sliced from (its provenance's source). degree: of the DG basis (default: the last
    solution's, else 1). support: the kernels' support in element sizes (docs/guide.md, "Embedded surfaces and collisions").

    Returns a dict: rows, cols (int64) and values (float64), the nonzeros of W with shape
    ``shape`` = (3 V, dofs), so that the surface's displacement is u = W @ U
    (u[3 v + d] component d of vertex v; U as ``coefficients``), e.g.
    ``scipy.sparse.coo_matrix((values, (rows, cols)), shape)``; points (V x 3, undeformed)
    and triangles (T x 3) of the surface; surface (its file), degree, setup_seconds.
    """
    return self._embed(_surface_arg(surface), 0 if degree is None else int(degree),
                       float(support), False)


def _deformed_surface(self, surface=None, support=2.0):
    """The surface carried by the last solution (``solve`` or ``simulate``): a dict with points
    (V x 3, undeformed), displacement (V x 3, by the MLS embedding), triangles (T x 3), surface
    (its file), degree and setup_seconds. ``points + displacement`` is the deformed surface.
    surface: as in ``embedding_weights``. Raises ``Error`` before a solve."""
    return self._embed(_surface_arg(surface), 0, float(support), True)


def _write(self, path, solution=True):
    """Writes the model as a VTU file (every cell a VTK_POLYHEDRON) with its provenance and, if
    ``solution`` and the model was solved, the displacement (per point and per element), von
    Mises stress and largest jump. Atomic: the file appears complete or not at all. Returns the
    write report."""
    return self._write(_os.fspath(path), solution)


def _export(self, folder, format="openfoam", binary=None, patches=None):
    """Writes the mesh as an OpenFOAM case folder (``polydg export --format openfoam``):
    constant/polyMesh and the system/ dictionaries checkMesh needs, never half-written.
    binary: OpenFOAM's binary format instead of ASCII. patches: boundary patches before the
    default ``wall`` and ``cut``, a dict ``{name: region}`` (a region as in ``solve``'s clamp,
    e.g. ``{"below": [0, 0, 1, 0.1]}``). Returns the report: counts, patches and, under
    ``quality``, the figures OpenFOAM's checkMesh computes (``quality["check_mesh"]`` is
    "Mesh OK" or "failed", with ``failed_checks`` and the worst faces)."""
    if patches is not None:
        patches = [dict(region, name=name) for name, region in patches.items()]
    return self._export(_os.fspath(folder), **_given(format=format, binary=binary, patches=patches))


Model.export = _export
Model.cut = _cut
Model.write = _write
Model.merge_slivers = _merge_slivers
Model.check = _check
Model.solve = _solve
Model.refine = _refine
Model.coarsen = _coarsen
Model.simulate = _simulate
Model.embedding_weights = _embedding_weights
Model.deformed_surface = _deformed_surface
Model.to_meshio = _to_meshio

#!/usr/bin/python3
"""Renders the README's pictures from real runs of the polydg binary.

Sample runs (from the repository's root, after scripts/build.sh):
    scripts/render_images.py                     # docs/images/*.png, about three minutes on 2 cores
    scripts/render_images.py --quick --out /tmp/images   # smaller runs, the same three files
    scripts/render_images.py --polydg /opt/polydg/bin/polydg

It runs polydg for real, in a scratch folder under /tmp (nothing is written into the
repository but the PNGs), and renders three pictures of 800 x 500 pixels:

    sliced_and_cut.png  testdata/torus.obj sliced at 12 cells (`polydg mesh`), then cut by a
                        plane oblique to the grid, one side removed (`polydg cut`): every element drawn shrunk
                        towards its centre, with its edges, so the polyhedral cells show.
    beam_cut.png        examples/scenes/beam_cut.json (B10: the beam cut through while it sags)
                        run by `polydg simulate` on testdata/beam.obj sliced at 40 cells; its
                        last frame, deformed by its displacement and coloured by the cells'
                        von Mises stress.
    accuracy.png        `polydg bench --suite accuracy --skip-sliced`: B1's L2 error against
                        the number of unknowns, IP, BZ fixed and BZ super, degrees 1-3,
                        log-log (the suite's own accuracy_hex.svg plots it against time).

Requirements: Debian 12's /usr/bin/python3 with python3-vtk9 (VTK 9.1), and an X display.

Offscreen rendering: Debian's VTK 9.1 is built for X only (its render window is
vtkXOpenGLRenderWindow; there is no EGL or OSMesa window in python3-vtk9), so even with
SetOffScreenRendering(1) it needs an X server to open its OpenGL context. Without DISPLAY the
script runs itself again under `xvfb-run -a` (Debian packages xvfb and xauth, both in
scripts/setup.sh): a virtual X server in memory, where Mesa's llvmpipe renders on the CPU.
Nothing appears on any screen either way.
"""
import argparse
import csv
import json
import os
import shutil
import subprocess
import sys
import tempfile

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
WIDTH, HEIGHT = 800, 500


def under_x_server():
    """Runs this script again under xvfb-run when there is no X display (see the docstring)."""
    if os.environ.get("DISPLAY") or os.environ.get("POLYDG_RENDER_UNDER_XVFB"):
        return
    xvfb_run = shutil.which("xvfb-run")
    if xvfb_run is None:
        sys.exit("render_images: no X display and no xvfb-run; install Debian's xvfb and xauth "
                 "(scripts/setup.sh does) or set DISPLAY")
    os.environ["POLYDG_RENDER_UNDER_XVFB"] = "1"
    os.execv(xvfb_run, [xvfb_run, "-a", "-s", "-screen 0 1280x1024x24", sys.executable,
                        os.path.abspath(__file__)] + sys.argv[1:])


def run_polydg(polydg, *args):
    """Runs `polydg ARGS`, printing the command; stops the script if it fails."""
    command = [polydg, *args, "--quiet"]
    print("+", " ".join(command[:-1]), flush=True)
    done = subprocess.run(command, cwd=ROOT, capture_output=True, text=True)
    if done.returncode != 0:
        sys.exit(f"render_images: polydg failed ({done.returncode}): {done.stderr.strip()}")


# --- rendering helpers -------------------------------------------------------------------------

def read_vtu(path):
    import vtk
    reader = vtk.vtkXMLUnstructuredGridReader()
    reader.SetFileName(path)
    reader.Update()
    return reader.GetOutput()


def offscreen_window(renderer):
    import vtk
    window = vtk.vtkRenderWindow()
    window.SetOffScreenRendering(1)
    window.SetSize(WIDTH, HEIGHT)
    window.SetMultiSamples(8)
    window.AddRenderer(renderer)
    return window


def write_png(window, path):
    import vtk
    window.Render()
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(window)
    grab.ReadFrontBufferOff()
    grab.Update()
    writer = vtk.vtkPNGWriter()
    writer.SetFileName(path)
    writer.SetInputConnection(grab.GetOutputPort())
    writer.Write()
    print("wrote", os.path.relpath(path, os.getcwd()), flush=True)


def light_background(renderer):
    import vtk
    kit = vtk.vtkLightKit()
    kit.SetKeyLightIntensity(0.9)
    kit.AddLightsToRenderer(renderer)
    renderer.GradientBackgroundOn()
    renderer.SetBackground(0.93, 0.94, 0.96)
    renderer.SetBackground2(1.0, 1.0, 1.0)


def cells_with_edges(grid, shrink, colour=None):
    """Every cell shrunk towards its centre by `shrink`, as a surface with its element edges.

    Returns (faces actor, edges actor, faces mapper). The edges are the feature edges of each
    shrunk cell's surface (angle 20 degrees), so the triangles of a boundary face made from the
    input surface do not clutter the picture.
    """
    import vtk
    shrunk = vtk.vtkShrinkFilter()
    shrunk.SetInputData(grid)
    shrunk.SetShrinkFactor(shrink)
    surface = vtk.vtkDataSetSurfaceFilter()
    surface.SetInputConnection(shrunk.GetOutputPort())
    normals = vtk.vtkPolyDataNormals()
    normals.SetInputConnection(surface.GetOutputPort())
    normals.SetFeatureAngle(30)
    normals.SplittingOn()
    mapper = vtk.vtkPolyDataMapper()
    mapper.SetInputConnection(normals.GetOutputPort())
    faces = vtk.vtkActor()
    faces.SetMapper(mapper)
    if colour is not None:
        mapper.ScalarVisibilityOff()
        faces.GetProperty().SetColor(*colour)
    faces.GetProperty().SetSpecular(0.2)
    faces.GetProperty().SetSpecularPower(20)
    edges = vtk.vtkFeatureEdges()
    edges.SetInputConnection(surface.GetOutputPort())
    edges.BoundaryEdgesOn()
    edges.FeatureEdgesOn()
    edges.SetFeatureAngle(20)
    edges.ManifoldEdgesOff()
    edges.NonManifoldEdgesOn()
    edges.ColoringOff()
    edge_mapper = vtk.vtkPolyDataMapper()
    edge_mapper.SetInputConnection(edges.GetOutputPort())
    edge_mapper.ScalarVisibilityOff()
    edge_actor = vtk.vtkActor()
    edge_actor.SetMapper(edge_mapper)
    edge_actor.GetProperty().SetColor(0.12, 0.12, 0.16)
    edge_actor.GetProperty().SetLineWidth(1.2)
    return faces, edge_actor, mapper


def caption(renderer, text, position=(12, 12), size=15):
    import vtk
    actor = vtk.vtkTextActor()
    actor.SetInput(text)
    actor.SetPosition(*position)
    actor.GetTextProperty().SetFontSize(size)
    actor.GetTextProperty().SetColor(0.15, 0.15, 0.2)
    renderer.AddViewProp(actor)


# --- the three pictures ------------------------------------------------------------------------

def sliced_and_cut(polydg, work, out, quick):
    """testdata/torus.obj sliced, then cut by a plane oblique to the grid, one side removed."""
    import vtk
    cells = "8" if quick else "12"
    meshed = os.path.join(work, "torus.vtu")
    cut = os.path.join(work, "torus_cut.vtu")
    run_polydg(polydg, "mesh", "testdata/torus.obj", "--cells", cells, "-o", meshed)
    # A plane oblique to the grid, its + side removed: the cut face shows the cells' sections.
    run_polydg(polydg, "cut", meshed, "-o", cut, "--plane", "1,1,3,0.25", "--remove-side", "+")
    grid = read_vtu(cut)
    renderer = vtk.vtkRenderer()
    light_background(renderer)
    faces, edges, _ = cells_with_edges(grid, 0.86, colour=(0.55, 0.71, 0.86))
    renderer.AddActor(faces)
    renderer.AddActor(edges)
    camera = renderer.GetActiveCamera()
    camera.SetFocalPoint(0, 0, 0)
    camera.SetPosition(2.2, -3.6, 3.0)
    camera.SetViewUp(0, 0, 1)
    renderer.ResetCamera()
    camera.Zoom(1.45)
    caption(renderer, f"testdata/torus.obj sliced at {cells} cells, cut by the plane x + y + 3z = 0.25: "
            f"{grid.GetNumberOfCells()} polyhedral elements (drawn shrunk)")
    write_png(offscreen_window(renderer), os.path.join(out, "sliced_and_cut.png"))


def simulated_scene(polydg, work, out, quick):
    """examples/scenes/beam_cut.json on the beam; its last frame coloured by von Mises stress."""
    import vtk
    cells = "20" if quick else "40"
    beam = os.path.join(work, "beam.vtu")
    frames = os.path.join(work, "beam_cut")
    run_polydg(polydg, "mesh", "testdata/beam.obj", "--cells", cells, "-o", beam)
    run_polydg(polydg, "simulate", beam, "--scene", "examples/scenes/beam_cut.json",
               "-o", frames)
    with open(os.path.join(frames, "scene.pvd"), encoding="utf-8") as f:
        files = [line.split('file="')[1].split('"')[0] for line in f if 'file="' in line]
    last = read_vtu(os.path.join(frames, files[-1]))
    with open(os.path.join(ROOT, "examples", "scenes", "beam_cut.json"), encoding="utf-8") as f:
        scene = json.load(f)
    steps = round(scene["duration"] / scene["dt"]) if "duration" in scene else scene["steps"]
    t_end = steps * scene["dt"]

    warp = vtk.vtkWarpVector()
    warp.SetInputData(last)
    warp.SetInputArrayToProcess(0, 0, 0, vtk.vtkDataObject.FIELD_ASSOCIATION_POINTS,
                                "displacement")
    warp.SetScaleFactor(1.0)
    warp.Update()
    deformed = warp.GetOutput()
    deformed.GetCellData().SetActiveScalars("von_mises")

    renderer = vtk.vtkRenderer()
    light_background(renderer)
    faces, edges, mapper = cells_with_edges(deformed, 0.94)
    low, high = deformed.GetCellData().GetArray("von_mises").GetRange()
    lut = vtk.vtkColorTransferFunction()  # ParaView's "Cool to Warm"
    lut.SetColorSpaceToDiverging()
    lut.AddRGBPoint(0.0, 0.230, 0.299, 0.754)
    lut.AddRGBPoint(0.5 * high, 0.865, 0.865, 0.865)
    lut.AddRGBPoint(high, 0.706, 0.016, 0.150)
    mapper.SetLookupTable(lut)
    mapper.SetScalarModeToUseCellData()
    mapper.SetScalarRange(0.0, high)
    mapper.ScalarVisibilityOn()
    renderer.AddActor(faces)
    renderer.AddActor(edges)

    # The undeformed beam as a thin outline, for scale.
    outline = vtk.vtkOutlineFilter()
    outline.SetInputData(last)
    outline_mapper = vtk.vtkPolyDataMapper()
    outline_mapper.SetInputConnection(outline.GetOutputPort())
    outline_actor = vtk.vtkActor()
    outline_actor.SetMapper(outline_mapper)
    outline_actor.GetProperty().SetColor(0.55, 0.55, 0.6)
    renderer.AddActor(outline_actor)

    bar = vtk.vtkScalarBarActor()
    bar.SetLookupTable(lut)
    bar.SetTitle("von Mises")
    bar.SetNumberOfLabels(5)
    bar.SetLabelFormat("%.3g")
    bar.SetOrientationToHorizontal()
    bar.SetWidth(0.42)
    bar.SetHeight(0.11)
    bar.GetPositionCoordinate().SetValue(0.55, 0.84)
    for prop in (bar.GetTitleTextProperty(), bar.GetLabelTextProperty()):
        prop.SetColor(0.15, 0.15, 0.2)
        prop.ShadowOff()
        prop.ItalicOff()
        prop.BoldOff()
    bar.UnconstrainedFontSizeOn()
    bar.GetTitleTextProperty().SetFontSize(15)
    bar.GetLabelTextProperty().SetFontSize(13)
    renderer.AddViewProp(bar)

    camera = renderer.GetActiveCamera()
    camera.SetFocalPoint(5, 0.5, -1.0)
    camera.SetPosition(6.5, -12.0, 2.5)
    camera.SetViewUp(0, 0, 1)
    renderer.ResetCamera()
    camera.Zoom(1.15)
    caption(renderer, f"examples/scenes/beam_cut.json: clamped at x = 0, cut at x = 5.1 at "
            f"t = 1 under gravity; t = {t_end:g}, {last.GetNumberOfCells()} elements")
    write_png(offscreen_window(renderer), os.path.join(out, "beam_cut.png"))


def accuracy_plot(polydg, work, out, quick):
    """B1 from `polydg bench --suite accuracy`: L2 error against DOFs, log-log.

    DOFs rather than time: the figure is then the same on any machine and under any load (the
    bench's own SVG plots the error against time).
    """
    import vtk
    bench = os.path.join(work, "bench")
    run_polydg(polydg, "bench", "--suite", "accuracy", "--skip-sliced", "--out", bench,
               *(["--quick"] if quick else []))
    with open(os.path.join(bench, "accuracy.csv"), encoding="utf-8") as f:
        rows = [r for r in csv.DictReader(f) if r["mesh"] == "hex"]

    view = vtk.vtkContextView()
    view.GetRenderWindow().SetOffScreenRendering(1)
    view.GetRenderWindow().SetSize(WIDTH, HEIGHT)
    view.GetRenderWindow().SetMultiSamples(8)
    view.GetRenderer().SetBackground(1, 1, 1)
    chart = vtk.vtkChartXY()
    view.GetScene().AddItem(chart)
    chart.SetShowLegend(True)
    chart.GetLegend().SetHorizontalAlignment(vtk.vtkChartLegend.LEFT)
    chart.GetLegend().SetVerticalAlignment(vtk.vtkChartLegend.BOTTOM)
    chart.GetLegend().GetLabelProperties().SetFontSize(13)
    chart.SetTitle("B1 on hex grids n^3: L2 error against DOFs (polydg bench --suite accuracy)")
    chart.GetTitleProperties().SetFontSize(15)

    colours = {1: (31, 119, 180), 2: (255, 127, 14), 3: (44, 160, 44)}
    series = [("ip", "", "IP", vtk.vtkPlotPoints.CIRCLE, 2.0),
              ("bz", "fixed", "BZ fixed", vtk.vtkPlotPoints.SQUARE, 1.0),
              ("bz", "super", "BZ super", vtk.vtkPlotPoints.DIAMOND, 1.0)]
    for method, penalty, label, marker, width in series:
        for degree in (1, 2, 3):
            points = sorted(
                (int(r["dofs"]), float(r["l2_error"]))
                for r in rows if r["method"] == method and int(r["degree"]) == degree and
                (r["bz_penalty"] or "fixed") == (penalty or "fixed"))
            if not points:
                continue
            table = vtk.vtkTable()
            for name in ("DOFs", label):
                column = vtk.vtkDoubleArray()
                column.SetName(f"{name} p = {degree}" if name == label else name)
                table.AddColumn(column)
            table.SetNumberOfRows(len(points))
            for i, (t, e) in enumerate(points):
                table.SetValue(i, 0, t)
                table.SetValue(i, 1, e)
            line = chart.AddPlot(vtk.vtkChart.LINE)
            line.SetInputData(table, 0, 1)
            line.SetColor(*colours[degree], 255)
            line.SetWidth(width)
            line.SetMarkerStyle(marker)
            line.SetMarkerSize(7)
            if method == "bz":
                line.GetPen().SetLineType(vtk.vtkPen.DASH_LINE)
    for axis_id, title in ((vtk.vtkAxis.BOTTOM, "degrees of freedom"),
                           (vtk.vtkAxis.LEFT, "L2 error of the displacement")):
        axis = chart.GetAxis(axis_id)
        axis.SetLogScale(True)
        axis.SetTitle(title)
        axis.GetTitleProperties().SetFontSize(14)
        axis.GetLabelProperties().SetFontSize(13)
        axis.SetNotation(vtk.vtkAxis.SCIENTIFIC_NOTATION)
        axis.SetPrecision(0)
    write_png(view.GetRenderWindow(), os.path.join(out, "accuracy.png"))


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    parser.add_argument("--polydg", default=os.path.join("build", "cli", "polydg"),
                        help="the polydg binary (default: build/cli/polydg, from the "
                             "repository's root)")
    parser.add_argument("--out", default=os.path.join(ROOT, "docs", "images"),
                        help="folder for the PNGs (default: docs/images)")
    parser.add_argument("--quick", action="store_true",
                        help="smaller runs (coarser meshes, bench --quick): seconds, not minutes")
    parser.add_argument("--keep", metavar="DIR",
                        help="run polydg in DIR and keep its outputs (default: a temporary "
                             "folder under /tmp, removed at the end)")
    args = parser.parse_args()
    under_x_server()
    polydg = os.path.abspath(os.path.join(ROOT, args.polydg))
    if not os.access(polydg, os.X_OK):
        sys.exit(f"render_images: no polydg binary at {polydg}; build it (scripts/build.sh) or "
                 "pass --polydg PATH")
    out = os.path.abspath(args.out)
    os.makedirs(out, exist_ok=True)
    if args.keep:
        work = os.path.abspath(args.keep)
        os.makedirs(work, exist_ok=True)
    else:
        work = tempfile.mkdtemp(prefix="polydg-images-", dir="/tmp")
    try:
        sliced_and_cut(polydg, work, out, args.quick)
        simulated_scene(polydg, work, out, args.quick)
        accuracy_plot(polydg, work, out, args.quick)
    finally:
        if not args.keep:
            shutil.rmtree(work, ignore_errors=True)


if __name__ == "__main__":
    main()

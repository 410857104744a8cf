#!/usr/bin/python3
"""Figures of a file polydg wrote, computed independently of polydg with VTK (Debian's
python3-vtk9), printed as one line of JSON for the C++ tests (tests/support/written_figures.h).

  written_figures.py SOLVED.vtu  -> {"cells", "volume", "displacement_integral": [x, y, z],
                                     "max_point_displacement"}
  written_figures.py SURFACE.vtp -> {"points", "max_point_displacement"}
  written_figures.py FILE FILE... -> a JSON list, one object per file (one interpreter start)

displacement_integral is sum over cells of volume x mean_displacement (the cell data a solve
writes): the integral of the displacement over the body, so that for a load by gravity g on
density rho, rho g . displacement_integral / 2 is the work of the load / 2, which Clapeyron's
theorem equates with the strain energy 1/2 u^T K u for any Galerkin solution.
"""
import json
import sys
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
from end_to_end_support import CheckFailed, Vtu, np, read_vtp  # noqa: E402


def main(path):
    if path.endswith(".vtp"):
        points, data = read_vtp(path)
        return {"points": len(points),
                "max_point_displacement": float(np.linalg.norm(data["displacement"],
                                                               axis=1).max())}
    vtu = Vtu(path)
    volume = vtu.cell_volumes()
    integral = (volume[:, None] * vtu.cell_data["mean_displacement"]).sum(axis=0)
    return {"cells": len(vtu.cells), "volume": float(volume.sum()),
            "displacement_integral": [float(x) for x in integral],
            "max_point_displacement": float(np.linalg.norm(vtu.point_data["displacement"],
                                                           axis=1).max())}


if __name__ == "__main__":
    try:
        figures = [main(path) for path in sys.argv[1:]]
        print(json.dumps(figures[0] if len(figures) == 1 else figures))
    except CheckFailed as failure:
        sys.exit(str(failure))

"""The ParaView recipe of docs/animation.md ("Opening it in ParaView"), step by step, in pvpython:

    pvpython cases/animation/paraview_recipe.py RUN/animation.pvd [--time T]

Builds the same pipeline as the page (reader, Tube, Threshold + Extract Surface + Tube, Glyph
arrows and spheres, shapes) and prints, as one JSON line, what each filter gives at time T (cells,
points, bounds, the field data names), so a test can check the recipe works as written. Needs
ParaView's Python (pvpython, Debian package python3-paraview); renders nothing.
"""
import argparse
import json
import os
import sys

# A ParaView unpacked beside another VTK (docs/animation.md) puts its modules first with this.
for _path in reversed(os.environ.get("PARAVIEW_PYTHONPATH", "").split(os.pathsep)):
    if _path:
        sys.path.insert(0, _path)

from paraview import servermanager  # noqa: E402
from paraview import simple  # noqa: E402


def threshold(source, code):
    """Step 3: Threshold on the cell field `part`, lower = upper = code."""
    t = simple.Threshold(Input=source)
    t.Scalars = ["CELLS", "part"]
    t.LowerThreshold = code
    t.UpperThreshold = code
    if hasattr(t, "ThresholdMethod"):  # ParaView 5.10 and later
        t.ThresholdMethod = "Between"
    return t


def summary(proxy, time):
    proxy.UpdatePipeline(time)
    data = servermanager.Fetch(proxy)
    fd = data.GetFieldData()
    names = {}
    for k in range(fd.GetNumberOfArrays()):
        a = fd.GetAbstractArray(k)
        names[a.GetName()] = [a.GetValue(i) for i in range(a.GetNumberOfValues())]
    return {"class": data.GetClassName(), "cells": data.GetNumberOfCells(), "points": data.GetNumberOfPoints(),
            "bounds": list(data.GetBounds()), "field_data": names}


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("pvd")
    ap.add_argument("--time", type=float, default=0.0)
    ap.add_argument("--tube-radius", type=float, default=0.005)
    ap.add_argument("--scale-factor", type=float, default=3e-5)
    a = ap.parse_args()
    # 1. File > Open animation.pvd.
    reader = simple.PVDReader(FileName=a.pvd)
    times = list(reader.TimestepValues) if reader.TimestepValues else [0.0]
    # 2. Lines as tubes: Tube on the reader.
    tubes = simple.Tube(Input=reader)
    tubes.Radius = a.tube_radius
    # 3. One part: Threshold part 5 (force elements), Extract Surface, Tube.
    springs = simple.Tube(Input=simple.ExtractSurface(Input=threshold(reader, 5)))
    springs.Radius = a.tube_radius
    # 4. Force vectors: Threshold part 6, Glyph Arrow oriented and scaled by force_vector.
    arrows = simple.Glyph(Input=threshold(reader, 6), GlyphType="Arrow")
    arrows.OrientationArray = ["POINTS", "force_vector"]
    arrows.ScaleArray = ["POINTS", "force_vector"]
    arrows.ScaleFactor = a.scale_factor
    # 5. Joints: Threshold part 3, Glyph Sphere, no scale array, Scale Factor 0.02.
    joints = simple.Glyph(Input=threshold(reader, 3), GlyphType="Sphere")
    joints.ScaleArray = ["POINTS", "No scale array"]
    joints.ScaleFactor = 0.02
    # 6. Shapes: Threshold part 7.
    shapes = threshold(reader, 7)
    out = {"times": times}
    for name, proxy in (("reader", reader), ("tubes", tubes), ("springs", springs), ("arrows", arrows),
                        ("joints", joints), ("shapes", shapes)):
        out[name] = summary(proxy, a.time)
    print(json.dumps(out))


if __name__ == "__main__":
    main()

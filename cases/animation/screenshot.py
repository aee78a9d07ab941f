#!/usr/bin/python3
"""Renders one frame of an mbdae animation headless with VTK, the way docs/animation.md shows it
in ParaView: lines as tubes (Tube), force elements coloured by |force|, force vectors as arrows
(Glyph), joints and cuts as spheres, shapes as translucent surfaces.

    /usr/bin/python3 cases/animation/screenshot.py RUN/animation.pvd OUT.png [--time T] [--size 900x700]

VTK's Debian build renders through X: without a display the script runs itself again under
xvfb-run (Debian package xvfb).
"""
import argparse
import math
import os
import shutil
import sys

import vtk

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
from video import AXIS, BODY_LINE, CUT, FORCE_LINE, FORCE_VECTOR, GROUND, JOINT, SHAPE, read_pvd  # noqa: E402


_KEEP = []  # pipeline sources referenced only by their output ports stay alive


def part(source, lo, hi=None):
    """The cells whose `part` is in [lo, hi], as polydata (ParaView: Threshold)."""
    t = vtk.vtkThreshold()
    t.SetInputConnection(source.GetOutputPort())
    t.SetInputArrayToProcess(0, 0, 0, vtk.vtkDataObject.FIELD_ASSOCIATION_CELLS, "part")
    t.SetLowerThreshold(lo - 0.5)
    t.SetUpperThreshold((lo if hi is None else hi) + 0.5)
    t.SetThresholdFunction(vtk.vtkThreshold.THRESHOLD_BETWEEN)
    g = vtk.vtkGeometryFilter()
    g.SetInputConnection(t.GetOutputPort())
    return g


def actor(port, color=None, lut=None, array=None, opacity=1.0):
    m = vtk.vtkPolyDataMapper()
    m.SetInputConnection(port.GetOutputPort())
    if lut is not None:
        m.SetLookupTable(lut)
        m.SetScalarModeToUseCellFieldData()
        m.SelectColorArray(array)
        m.SetScalarRange(lut.GetRange())
        m.ScalarVisibilityOn()
    else:
        m.ScalarVisibilityOff()
    a = vtk.vtkActor()
    a.SetMapper(m)
    if color:
        a.GetProperty().SetColor(*color)
    a.GetProperty().SetOpacity(opacity)
    return a


def tube(port, radius):
    t = vtk.vtkTubeFilter()
    t.SetInputConnection(port.GetOutputPort())
    t.SetRadius(radius)
    t.SetNumberOfSides(12)
    return t


def spheres(port, radius):
    s = vtk.vtkSphereSource()
    s.SetRadius(radius)
    _KEEP.append(s)
    g = vtk.vtkGlyph3D()
    g.SetInputConnection(port.GetOutputPort())
    g.SetSourceConnection(s.GetOutputPort())
    g.SetScaleModeToDataScalingOff()
    return g


def arrows(port, scale):
    g = vtk.vtkGlyph3D()
    g.SetInputConnection(port.GetOutputPort())
    _KEEP.append(vtk.vtkArrowSource())
    g.SetSourceConnection(_KEEP[-1].GetOutputPort())
    g.SetInputArrayToProcess(1, 0, 0, vtk.vtkDataObject.FIELD_ASSOCIATION_POINTS, "force_vector")
    g.SetVectorModeToUseVector()
    g.SetScaleModeToScaleByVector()
    g.SetScaleFactor(scale)
    return g


def render(pvd, out, time=None, size=(900, 700), azimuth=-60.0, elevation=20.0):
    entries = read_pvd(pvd)
    t, path = min(entries, key=lambda e: abs(e[0] - time)) if time is not None else entries[len(entries) // 2]
    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    data = reader.GetOutput()
    b = data.GetBounds()
    extent = max(b[1] - b[0], b[3] - b[2], b[5] - b[4])
    fmax = data.GetCellData().GetArray("force_magnitude").GetRange()[1]
    vmax = data.GetPointData().GetArray("force_vector").GetMaxNorm()
    force_lut = vtk.vtkLookupTable()
    force_lut.SetRange(0, fmax if fmax > 0 else 1)
    force_lut.SetHueRange(0.66, 0.0)
    force_lut.Build()
    axis_lut = vtk.vtkLookupTable()
    axis_lut.SetNumberOfTableValues(3)
    axis_lut.SetRange(0, 2)
    for k, c in enumerate([(0.85, 0.1, 0.1), (0.1, 0.65, 0.1), (0.1, 0.3, 0.9)]):
        axis_lut.SetTableValue(k, *c, 1.0)
    r = vtk.vtkRenderer()
    r.SetBackground(1, 1, 1)
    r.AddActor(actor(part(reader, SHAPE), (0.55, 0.6, 0.7), opacity=0.35))
    r.AddActor(actor(tube(part(reader, BODY_LINE), 0.006 * extent), (0.25, 0.25, 0.25)))
    r.AddActor(actor(tube(part(reader, AXIS), 0.003 * extent), lut=axis_lut, array="axis"))
    r.AddActor(actor(tube(part(reader, FORCE_LINE), 0.012 * extent), lut=force_lut, array="force_magnitude"))
    r.AddActor(actor(tube(part(reader, GROUND), 0.006 * extent), (0.55, 0.3, 0.1)))
    r.AddActor(actor(spheres(part(reader, JOINT), 0.012 * extent), (0, 0, 0)))
    r.AddActor(actor(spheres(part(reader, CUT), 0.016 * extent), (1.0, 0.5, 0.0)))
    if vmax > 0:
        r.AddActor(actor(arrows(part(reader, FORCE_VECTOR), 0.25 * extent / vmax), (0.85, 0.1, 0.1)))
    bar = vtk.vtkScalarBarActor()
    bar.SetLookupTable(force_lut)
    bar.SetTitle("|force| [N]")
    bar.SetWidth(0.08)
    bar.GetTitleTextProperty().SetColor(0, 0, 0)
    bar.GetLabelTextProperty().SetColor(0, 0, 0)
    r.AddActor2D(bar)
    text = vtk.vtkTextActor()
    text.SetInput(f"t = {t:.4f} s")
    text.GetTextProperty().SetColor(0, 0, 0)
    text.GetTextProperty().SetFontSize(18)
    text.SetPosition(10, size[1] - 30)
    r.AddActor2D(text)
    # Seen from azimuth/elevation about the world z axis (as matplotlib's view_init), z up.
    az, el = math.radians(azimuth), math.radians(elevation)
    centre = [(b[0] + b[1]) / 2, (b[2] + b[3]) / 2, (b[4] + b[5]) / 2]
    camera = r.GetActiveCamera()
    camera.SetFocalPoint(*centre)
    camera.SetPosition(*(c + 4 * extent * d for c, d in zip(centre, (math.cos(el) * math.cos(az),
                                                                    math.cos(el) * math.sin(az), math.sin(el)))))
    camera.SetViewUp(0, 0, 1)
    r.ResetCamera()
    win = vtk.vtkRenderWindow()
    win.SetOffScreenRendering(1)
    win.AddRenderer(r)
    win.SetSize(*size)
    win.Render()
    grab = vtk.vtkWindowToImageFilter()
    grab.SetInput(win)
    grab.Update()
    png = vtk.vtkPNGWriter()
    png.SetFileName(out)
    png.SetInputConnection(grab.GetOutputPort())
    png.Write()
    return t


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("pvd")
    ap.add_argument("out")
    ap.add_argument("--time", type=float, help="the frame nearest this time (default: the middle frame)")
    ap.add_argument("--size", default="900x700")
    ap.add_argument("--azimuth", type=float, default=-60.0)
    ap.add_argument("--elevation", type=float, default=20.0)
    a = ap.parse_args()
    if not os.environ.get("DISPLAY") and not os.environ.get("MBDAE_XVFB"):
        if not shutil.which("xvfb-run"):
            sys.exit("screenshot.py: no display and no xvfb-run (apt-get install -y xvfb)")
        os.environ["MBDAE_XVFB"] = "1"
        os.execvp("xvfb-run", ["xvfb-run", "-a", "-s", "-screen 0 1280x1024x24", sys.executable, *sys.argv])
    w, h = (int(x) for x in a.size.lower().split("x"))
    t = render(a.pvd, a.out, a.time, (w, h), a.azimuth, a.elevation)
    print(f"{a.out}: frame at t = {t:g} s")


if __name__ == "__main__":
    main()

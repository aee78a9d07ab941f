#!/usr/bin/python3
"""Quick-look video of an mbdae animation (docs/animation.md), without ParaView.

    /usr/bin/python3 cases/animation/video.py RUN/animation.pvd RUN/animation.mp4 [--fps 30]
        [--start T] [--end T] [--max-frames N] [--size 640x480] [--elev 20] [--azim -60]

Reads the .pvd collection and its .vtp frames back with VTK's own XML reader (python3-vtk9) and
draws each frame with matplotlib in a 3D view with fixed axes and the time in the corner: body
axes (x red, y green, z blue), body lines, joints and cuts, force elements coloured by their
force, point and contact forces as arrows, the ground under a wheel, shapes as faces. Writes an MP4 (ffmpeg) or, for a
.gif name, an animated GIF (Pillow). animate() and animation() are the same from Python.
"""
import argparse
import contextlib
import io
import json
import math
import os
import xml.etree.ElementTree as ET

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from matplotlib import animation as mpl_animation  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection  # noqa: E402

# Cell "part" codes (cases/output/animation_sink.h, legend.json).
AXIS, BODY_LINE, BODY_POINT, JOINT, CUT, FORCE_LINE, FORCE_VECTOR, SHAPE, GROUND = range(9)

# Frames per second of video at most. GIF frame delays are whole hundredths of a second and
# viewers play delays under 2 cs as 10 cs, so a GIF holds at most 50 frames per second.
MAX_FPS = {"gif": 50, "mp4": 60}


def gif_delays(frames, fps):
    """Frame delays in milliseconds (whole centiseconds, at least 2) for `frames` frames shown
    at `fps` frames per second: each frame's delay rounded so that the time of frame k stays
    within half a centisecond of k / fps (30 fps: 3, 4, 3, 3, 4, 3, ... cs)."""
    if not 0 < fps <= MAX_FPS["gif"]:  # also NaN
        raise ValueError(f"a GIF plays at most {MAX_FPS['gif']} frames per second (its frame delays are "
                         f"hundredths of a second and viewers slow delays under 2 cs), got fps={fps}")
    at = [round(100 * k / fps) for k in range(frames + 1)]
    return [10 * (at[k + 1] - at[k]) for k in range(frames)]


class _GifWriter:
    """Grabs matplotlib frames and writes a GIF with gif_delays(): matplotlib's PillowWriter gives
    every frame int(1000 / fps) ms, which Pillow cuts to whole centiseconds (60 fps: 1 cs, which
    viewers play as 10 cs, six times too slow)."""

    def __init__(self, fps):
        self.fps = fps
        self.frames = []

    @contextlib.contextmanager
    def saving(self, fig, out, dpi):
        self.fig, self.dpi = fig, dpi
        yield self
        self.frames[0].save(out, save_all=True, append_images=self.frames[1:], loop=0,
                            duration=gif_delays(len(self.frames), self.fps))

    def grab_frame(self):
        from PIL import Image

        buf = io.BytesIO()
        self.fig.savefig(buf, format="rgba", dpi=self.dpi)
        w, h = int(round(self.fig.get_figwidth() * self.dpi)), int(round(self.fig.get_figheight() * self.dpi))
        self.frames.append(Image.frombuffer("RGBA", (w, h), buf.getbuffer(), "raw", "RGBA", 0, 1).convert("RGB"))


def frame_plan(times, fps=None, gif=False):
    """(indices of the frames to draw, frames per second of video). With fps given, every frame
    at that rate (a GIF at most 50). Without, real time: the frames' own rate when the format
    allows it, else every k-th frame at 1/k of it (a 60 Hz run as a GIF: every second frame at
    30 frames per second)."""
    cap = MAX_FPS["gif" if gif else "mp4"]
    n = len(times)
    if fps is not None:
        if not (fps > 0 and math.isfinite(fps)):
            raise ValueError(f"fps must be a positive number, got {fps}")
        if gif and fps > cap:
            gif_delays(1, fps)  # raises the GIF's error
        return list(range(n)), fps
    span = times[-1] - times[0]
    if n < 2 or span <= 0:
        return list(range(n)), min(30, cap)
    rate = (n - 1) / span  # frames per simulated second
    k = max(1, math.ceil(rate / cap - 1e-9))
    return list(range(0, n, k)), max(1.0, round(rate / k, 6))  # at least 1 frame per second of video


def read_pvd(path):
    """[(time, absolute .vtp path)] in the order of the collection."""
    root = ET.parse(path).getroot()
    folder = os.path.dirname(os.path.abspath(path))
    return [(float(d.get("timestep")), os.path.join(folder, d.get("file"))) for d in root.iter("DataSet")]


def _cells(cell_array):
    from vtk.util.numpy_support import vtk_to_numpy

    offsets = vtk_to_numpy(cell_array.GetOffsetsArray())
    conn = vtk_to_numpy(cell_array.GetConnectivityArray())
    return [conn[offsets[k]:offsets[k + 1]] for k in range(len(offsets) - 1)]


def read_frame(path):
    """One .vtp frame as numpy arrays: points, force_vector, per cell section (verts, lines,
    polys) the point ids and the cell fields, and `names`, the field data's string arrays
    (part_names, body_names, ...), read with vtkXMLPolyDataReader."""
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy

    reader = vtk.vtkXMLPolyDataReader()
    reader.SetFileName(path)
    reader.Update()
    if reader.GetErrorCode() != 0:
        raise RuntimeError(f"{path}: VTK cannot read it")
    data = reader.GetOutput()
    cd = data.GetCellData()
    fields = {cd.GetArrayName(k): vtk_to_numpy(cd.GetArray(k)) for k in range(cd.GetNumberOfArrays())}
    fd = data.GetFieldData()
    names = {}
    for k in range(fd.GetNumberOfArrays()):  # the names the codes stand for (body_names, ...)
        a = fd.GetAbstractArray(k)
        names[a.GetName()] = [a.GetValue(i) for i in range(a.GetNumberOfValues())]
    frame = {"points": vtk_to_numpy(data.GetPoints().GetData()).astype(float),
             "force_vector": vtk_to_numpy(data.GetPointData().GetArray("force_vector")), "names": names}
    start = 0
    for name, section in (("verts", data.GetVerts()), ("lines", data.GetLines()), ("polys", data.GetPolys())):
        cells = _cells(section)
        frame[name] = {"ids": cells, **{f: v[start:start + len(cells)] for f, v in fields.items()}}
        start += len(cells)
    return frame


def _lines(frame, part):
    s = frame["lines"]
    keep = [k for k in range(len(s["ids"])) if s["part"][k] == part]
    return [frame["points"][s["ids"][k]] for k in keep], keep


def _verts(frame, part):
    s = frame["verts"]
    ids = [s["ids"][k][0] for k in range(len(s["ids"])) if s["part"][k] == part]
    return frame["points"][ids] if ids else np.zeros((0, 3)), ids


def _limits(frames):
    pts = np.vstack([f["points"] for f in frames])
    lo, hi = pts.min(axis=0), pts.max(axis=0)
    centre, half = (lo + hi) / 2, max((hi - lo).max() / 2, 1e-9) * 1.05
    return centre - half, centre + half


class _Scene:
    """The artists of one frame, updated in place from frame to frame."""

    def __init__(self, ax, frames, lo, hi):
        self.ax = ax
        forces = [abs(v) for f in frames for v, p in zip(f["lines"]["force"], f["lines"]["part"]) if p == FORCE_LINE]
        self.has_forces = bool(forces) and max(forces) > 0
        self.norm = matplotlib.colors.Normalize(0, max(forces) if self.has_forces else 1.0)
        vmax = max((np.linalg.norm(f["force_vector"], axis=1).max() for f in frames), default=0.0)
        self.vector_scale = 0.25 * (hi - lo).max() / vmax if vmax > 0 else 0.0
        self.shapes = Poly3DCollection([], facecolor=(0.55, 0.6, 0.7, 0.35), edgecolor=(0.3, 0.3, 0.4, 0.4), lw=0.3)
        self.body = Line3DCollection([], colors="0.25", lw=1.6)
        self.axes = Line3DCollection([], lw=1.0)
        self.force = Line3DCollection([], cmap="plasma", norm=self.norm, lw=3.0)
        self.ground = Line3DCollection([], colors="saddlebrown", lw=2.5)
        for a in (self.shapes, self.body, self.axes, self.force, self.ground):
            ax.add_collection3d(a)
        self.joints = ax.scatter([], [], [], s=14, c="k", depthshade=False, label="joints")
        self.cuts = ax.scatter([], [], [], s=22, c="tab:orange", marker="D", depthshade=False, label="cuts")
        self.quiver = None
        self.text = ax.text2D(0.02, 0.95, "", transform=ax.transAxes, family="monospace")

    def update(self, t, frame):
        polys = frame["polys"]
        self.shapes.set_verts([frame["points"][ids] for ids in polys["ids"]])
        self.body.set_segments(_lines(frame, BODY_LINE)[0])
        self.ground.set_segments(_lines(frame, GROUND)[0])
        axes, keep = _lines(frame, AXIS)
        self.axes.set_segments(axes)
        self.axes.set_color([("tab:red", "tab:green", "tab:blue")[int(frame["lines"]["axis"][k])] for k in keep])
        segs, keep = _lines(frame, FORCE_LINE)
        self.force.set_segments(segs)
        self.force.set_array(np.abs(np.asarray(frame["lines"]["force"])[keep]) if keep else np.zeros(0))
        for scatter, part in ((self.joints, JOINT), (self.cuts, CUT)):
            p = _verts(frame, part)[0]
            scatter._offsets3d = (p[:, 0], p[:, 1], p[:, 2])
        if self.quiver is not None:
            self.quiver.remove()
            self.quiver = None
        p, ids = _verts(frame, FORCE_VECTOR)
        if len(ids) and self.vector_scale > 0:
            v = frame["force_vector"][ids] * self.vector_scale
            self.quiver = self.ax.quiver(p[:, 0], p[:, 1], p[:, 2], v[:, 0], v[:, 1], v[:, 2], color="tab:red", lw=2)
        self.text.set_text(f"t = {t:8.4f} s")


def animate(pvd, out, fps=None, start=None, end=None, max_frames=None, size=(640, 480), dpi=80,
            elev=20.0, azim=-60.0, title=None):
    """Draws the frames of `pvd` (within [start, end], at most max_frames of them, evenly
    picked) into `out` (.mp4 or .gif). Returns the number of frames written. fps defaults to
    real time (frame_plan: at most 60 frames per second for an MP4 and 50 for a GIF, denser
    frames thinned evenly); a GIF's frame delays are whole centiseconds, rounded frame by frame
    so that the video keeps the rate (gif_delays)."""
    entries = [(t, f) for t, f in read_pvd(pvd) if (start is None or t >= start) and (end is None or t <= end)]
    if not entries:
        raise ValueError(f"{pvd}: no frames in the time window")
    if max_frames and len(entries) > max_frames:
        entries = [entries[k] for k in np.linspace(0, len(entries) - 1, max_frames).round().astype(int)]
    gif = out.lower().endswith(".gif")
    keep, fps = frame_plan([t for t, _ in entries], fps, gif)
    entries = [entries[k] for k in keep]
    frames = [read_frame(f) for _, f in entries]
    fig = plt.figure(figsize=(size[0] / dpi, size[1] / dpi), dpi=dpi)
    ax = fig.add_subplot(projection="3d")
    lo, hi = _limits(frames)
    ax.set_xlim(lo[0], hi[0]), ax.set_ylim(lo[1], hi[1]), ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect((1, 1, 1))
    ax.set_xlabel("x [m]"), ax.set_ylabel("y [m]"), ax.set_zlabel("z [m]")
    ax.view_init(elev=elev, azim=azim)
    if title:
        ax.set_title(title)
    scene = _Scene(ax, frames, lo, hi)
    if scene.has_forces:
        fig.colorbar(scene.force, ax=ax, shrink=0.5, pad=0.12, label="|force| [N]")
    fig.subplots_adjust(left=0, right=0.95, bottom=0.02, top=0.92 if title else 0.98)
    writer = _GifWriter(fps) if gif else \
        mpl_animation.FFMpegWriter(fps=fps, codec="libx264", extra_args=["-pix_fmt", "yuv420p"])
    with writer.saving(fig, out, dpi=dpi):
        for (t, _), frame in zip(entries, frames):
            scene.update(t, frame)
            writer.grab_frame()
    plt.close(fig)
    return len(frames)


def animation(source, out, **options):
    """`source`: a run folder holding animation.pvd (written by --animation or an AnimationSink),
    or the .pvd itself. Draws it into `out` (.mp4 or .gif) with animate(**options); returns `out`.
    This is what the Python package's Result.animation(out, ...) calls."""
    pvd = os.path.join(source, "animation.pvd") if os.path.isdir(source) else source
    if not os.path.isfile(pvd):
        raise FileNotFoundError(f"{pvd}: no animation (run with --animation, or with an AnimationSink)")
    animate(pvd, out, **options)
    return out


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("pvd")
    ap.add_argument("out", help=".mp4 or .gif")
    ap.add_argument("--fps", type=float)
    ap.add_argument("--start", type=float)
    ap.add_argument("--end", type=float)
    ap.add_argument("--max-frames", type=int)
    ap.add_argument("--size", default="640x480", help="WIDTHxHEIGHT in pixels (even numbers for MP4)")
    ap.add_argument("--elev", type=float, default=20.0)
    ap.add_argument("--azim", type=float, default=-60.0)
    ap.add_argument("--title")
    a = ap.parse_args()
    w, h = (int(x) for x in a.size.lower().split("x"))
    n = animate(a.pvd, a.out, a.fps, a.start, a.end, a.max_frames, (w, h), elev=a.elev, azim=a.azim, title=a.title)
    print(f"{a.out}: {n} frames")


if __name__ == "__main__":
    main()

"""End-to-end checks of the animation output (cases/output/animation_sink.h, cases/animation/video.py).

The .vtp frames are read back with VTK's own XML reader and compared with the run's position
and force_length sensors at the same times, to 1e-12 m. Run by ctest:
    /usr/bin/python3 -m pytest cases/tests/test_animation.py  (MBDAE=build/mbdae)
"""
import json
import os
import subprocess
import sys

import numpy as np
import pytest

ROOT = os.path.abspath(os.path.join(os.path.dirname(__file__), "..", ".."))
sys.path.insert(0, os.path.join(ROOT, "cases", "animation"))
import video  # noqa: E402

MBDAE = os.environ.get("MBDAE", os.path.join(ROOT, "build", "mbdae"))
MODEL = os.path.join(ROOT, "cases", "five_point_suspension", "model.yaml")

# Points compared: (body, point) of the suspension, each with a position sensor per component.
POINTS = [("chassis", "origin"), ("chassis", "bp6"), ("rod1", "origin"), ("rod1", "end"), ("rod5", "end"),
          ("carrier", "origin"), ("carrier", "cp1"), ("carrier", "cp5"), ("wheel", "origin")]


def scene_text(t_end, animation="", analysis=None):
    sensors = "".join(f"  - {{name: {b}_{p}_{c}, type: position, body: {b}, point: {p}, component: {c}}}\n"
                      for b, p in POINTS for c in "xyz")
    names = [f"{b}_{p}_{c}" for b, p in POINTS for c in "xyz"] + ["spring_length", "tyre_force"]
    analysis = analysis or f"""  - {{type: dynamics, t_end: {t_end}, output_step: 0.001, rtol: 1.0e-8, atol: 1.0e-12}}"""
    return f"""model: {MODEL}
coordinates:
  q1: {{mode: locked}}
forces:
  - {{name: tyre, type: wheel_contact, body: wheel, point: origin, axis: [0, 1, 0],
     stiffness: 2.0e5, radius: 0.30, ground: {{type: step, time: 0.05, before: 0.0, after: -0.10}}}}
sensors:
{sensors}output: [{", ".join(names)}]
{animation}
analysis:
  - {{type: assembly, hold: [q4]}}
  - {{type: equilibrium, hold: [q4, q15], release: [q4], unknowns: [suspension.free_length]}}
{analysis}
"""


def run(tmp_path, text, *args, expect=0):
    scene = tmp_path / "scene.yaml"
    scene.write_text(text)
    out = tmp_path / "out"
    p = subprocess.run([MBDAE, "run", str(scene), "--out", str(out), "--quiet", *args], capture_output=True, text=True)
    assert p.returncode == expect, p.stderr
    return out, p


def read_csv(path):
    with open(path) as f:
        header = f.readline().strip().split(",")
    data = np.loadtxt(path, delimiter=",", skiprows=1, ndmin=2)
    return {name: data[:, k] for k, name in enumerate(header)}


def body_points(frame, legend):
    """{(body, point): world position} from the body_point vertices of a frame."""
    verts = frame["verts"]
    out = {}
    for k, ids in enumerate(verts["ids"]):
        if verts["part"][k] == video.BODY_POINT:
            body = legend["bodies"][int(verts["body"][k])]
            out[(body["name"], body["points"][int(verts["index"][k])])] = frame["points"][ids[0]]
    return out


def spring_length(frame, legend):
    lines = frame["lines"]
    for k, ids in enumerate(lines["ids"]):
        if lines["part"][k] == video.FORCE_LINE and legend["forces"][int(lines["index"][k])] == "suspension":
            a, b = frame["points"][ids]
            return np.linalg.norm(b - a), lines["force"][k]
    raise AssertionError("no suspension line")


@pytest.fixture(scope="module")
def dynamics(tmp_path_factory):
    tmp = tmp_path_factory.mktemp("dyn")
    out, _ = run(tmp, scene_text(0.305), "--animation")  # t_end off the frame grid
    return out


def test_frames_match_the_position_and_length_sensors(dynamics):
    legend = json.load(open(dynamics / "animation" / "legend.json"))
    rows = read_csv(dynamics / "results.csv")
    entries = video.read_pvd(dynamics / "animation.pvd")
    worst = 0.0
    for t, path in entries:
        row = int(np.argmin(np.abs(rows["t"] - t)))
        assert abs(rows["t"][row] - t) < 1e-12
        frame = video.read_frame(path)
        pts = body_points(frame, legend)
        for b, p in POINTS:
            sensor = np.array([rows[f"{b}_{p}_{c}"][row] for c in "xyz"])
            worst = max(worst, np.abs(pts[(b, p)] - sensor).max())
        length, _ = spring_length(frame, legend)
        worst = max(worst, abs(length - rows["spring_length"][row]))
    assert worst < 1e-12, worst
    # The tyre's contact force vector is the tyre_force sensor, vertical.
    frame = video.read_frame(entries[-1][1])
    v = frame["force_vector"][frame["force_vector"].any(axis=1)]
    row = int(np.argmin(np.abs(rows["t"] - entries[-1][0])))
    if rows["tyre_force"][row] != 0:
        assert np.allclose(v, [[0, 0, rows["tyre_force"][row]]], rtol=1e-12, atol=0)


def test_frame_times_are_the_first_samples_on_a_60_per_second_grid(dynamics):
    times = np.array([t for t, _ in video.read_pvd(dynamics / "animation.pvd")])
    samples = read_csv(dynamics / "results.csv")["t"]
    grid = np.arange(0, 0.305 + 1e-12, 1 / 60)
    expected = [samples[samples >= g - 1e-9][0] for g in grid]
    if expected[-1] != samples[-1]:
        expected.append(samples[-1])  # the run's last state is always drawn
    assert np.allclose(times, expected, rtol=0, atol=1e-12)


def test_max_frames_caps_the_frame_count(tmp_path):
    out, _ = run(tmp_path, scene_text(0.3, "animation: {max_frames: 20}"), "--animation-rate", "1000")
    times = [t for t, _ in video.read_pvd(out / "animation.pvd")]
    assert len(times) == 20 and times[0] == 0 and abs(times[-1] - 0.3) < 1e-12


def test_static_scene_is_one_frame_at_the_equilibrium(tmp_path):
    out, _ = run(tmp_path, scene_text(0, "animation: {write: true}", analysis=" "))
    entries = video.read_pvd(out / "animation.pvd")
    assert len(entries) == 1
    legend = json.load(open(out / "animation" / "legend.json"))
    summary = json.load(open(out / "summary.json"))
    sensors = summary["steps"][-1]["sensors"]
    frame = video.read_frame(entries[0][1])
    length, tension = spring_length(frame, legend)
    assert abs(length - sensors["spring_length"]) < 1e-12
    pts = body_points(frame, legend)
    assert np.abs(pts[("wheel", "origin")] - [sensors[f"wheel_origin_{c}"] for c in "xyz"]).max() < 1e-12


def test_wheel_shape_is_a_cylinder_of_the_tyre_radius(dynamics):
    legend = json.load(open(dynamics / "animation" / "legend.json"))
    frame = video.read_frame(video.read_pvd(dynamics / "animation.pvd")[-1][1])
    centre = body_points(frame, legend)[("wheel", "origin")]
    ids = np.unique(np.concatenate(frame["polys"]["ids"]))
    d = frame["points"][ids] - centre
    # The wheel frame's y axis (spin axis) from the drawn axis line.
    lines = frame["lines"]
    wheel = [b["name"] for b in legend["bodies"]].index("wheel")
    k = [k for k in range(len(lines["ids"])) if lines["part"][k] == video.AXIS and lines["body"][k] == wheel
         and lines["axis"][k] == 1][0]
    a, b = frame["points"][lines["ids"][k]]
    y = (b - a) / np.linalg.norm(b - a)
    along = d @ y
    radial = np.linalg.norm(d - np.outer(along, y), axis=1)
    assert np.allclose(np.abs(along), 0.10, atol=1e-12) and np.allclose(radial, 0.30, atol=1e-12)


def test_unknown_shape_body_is_an_error_naming_the_line(tmp_path):
    text = scene_text(0.1, "animation:\n  shapes:\n    - {body: wheeel, type: sphere, radius: 0.1}")
    _, p = run(tmp_path, text, expect=2)
    assert "scene.yaml:" in p.stderr and "wheeel" in p.stderr


def test_video_has_the_frames_and_size_asked_for(dynamics, tmp_path):
    pvd = str(dynamics / "animation.pvd")
    mp4, gif = str(tmp_path / "a.mp4"), str(tmp_path / "a.gif")
    assert video.animate(pvd, mp4, max_frames=8, size=(320, 240)) == 8
    probe = subprocess.run(["ffprobe", "-v", "error", "-count_frames", "-select_streams", "v:0", "-show_entries",
                            "stream=nb_read_frames,width,height", "-of", "json", mp4], capture_output=True, text=True)
    s = json.loads(probe.stdout)["streams"][0]
    assert (int(s["nb_read_frames"]), s["width"], s["height"]) == (8, 320, 240)
    n = len(video.read_pvd(pvd))
    assert video.animate(pvd, gif, start=0.1, size=(200, 160)) == sum(1 for t, _ in video.read_pvd(pvd) if t >= 0.1) < n
    from PIL import Image
    with Image.open(gif) as im:
        assert (im.n_frames, im.size) == (sum(1 for t, _ in video.read_pvd(pvd) if t >= 0.1), (200, 160))


def test_animation_of_a_run_folder(dynamics, tmp_path):
    out = str(tmp_path / "b.gif")
    assert video.animation(str(dynamics), out, max_frames=3, size=(120, 100)) == out
    from PIL import Image
    with Image.open(out) as im:
        assert (im.n_frames, im.size) == (3, (120, 100))
    with pytest.raises(FileNotFoundError):
        video.animation(str(tmp_path), str(tmp_path / "c.gif"))


def test_interrupted_run_leaves_a_valid_collection(tmp_path):
    import signal
    import time
    scene = os.path.join(ROOT, "cases", "five_point_suspension", "dynamics_poster.yaml")
    out = tmp_path / "out"
    p = subprocess.Popen([MBDAE, "run", scene, "--out", str(out), "--quiet", "--animation"], stderr=subprocess.PIPE)
    time.sleep(1.0)
    p.send_signal(signal.SIGINT)
    p.communicate(timeout=60)
    assert p.returncode == 130
    summary = json.load(open(out / "summary.json"))
    assert summary["status"] == "interrupted"
    entries = video.read_pvd(out / "animation.pvd")
    assert len(entries) > 1 and abs(entries[-1][0] - summary["steps"][-1]["t_reached"]) < 0.01
    for _, path in entries[-2:]:
        assert video.read_frame(path)["points"].shape[0] > 0
    assert not list((out / "animation").glob("*.tmp"))

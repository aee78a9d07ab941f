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
    assert video.animate(pvd, gif, start=0.1, size=(200, 160), fps=30) == sum(1 for t, _ in video.read_pvd(pvd) if t >= 0.1) < n
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


def test_frames_are_compressed_binary_and_ascii_on_request_gives_the_same_numbers(dynamics, tmp_path):
    first = dynamics / "animation" / "frame_000000.vtp"
    head = first.read_bytes()[:4000]
    assert b'compressor="vtkZLibDataCompressor"' in head and b'format="appended"' in head
    assert b'format="ascii"' not in head and b'<AppendedData encoding="raw">' in first.read_bytes()
    out, _ = run(tmp_path, scene_text(0.305, "animation: {format: ascii}"), "--animation")
    text = (out / "animation" / "frame_000000.vtp").read_bytes()
    assert b'format="ascii"' in text and b"appended" not in text and b"compressor" not in text
    binary, ascii_ = video.read_pvd(dynamics / "animation.pvd"), video.read_pvd(out / "animation.pvd")
    assert [t for t, _ in binary] == [t for t, _ in ascii_]
    for (_, b), (_, a) in zip(binary, ascii_):  # both exact: the same doubles
        fb, fa = video.read_frame(b), video.read_frame(a)
        assert np.array_equal(fb["points"], fa["points"]) and np.array_equal(fb["force_vector"], fa["force_vector"])
        for section in ("verts", "lines", "polys"):
            for key in ("part", "body", "index", "axis", "force"):
                assert np.array_equal(fb[section][key], fa[section][key])
        assert fb["names"] == fa["names"]
    size = sum(os.path.getsize(f) for _, f in binary), sum(os.path.getsize(f) for _, f in ascii_)
    assert size[0] < 0.6 * size[1], size


def test_every_frame_names_its_bodies_joints_and_forces(dynamics):
    legend = json.load(open(dynamics / "animation" / "legend.json"))
    for _, path in video.read_pvd(dynamics / "animation.pvd"):
        names = video.read_frame(path)["names"]
        assert names["body_names"] == [b["name"] for b in legend["bodies"]]
        assert names["joint_names"] == legend["joints"] and names["cut_names"] == legend["cuts"]
        assert names["force_names"] == legend["forces"] and "suspension" in names["force_names"]
        assert names["part_names"] == [legend["parts"][str(k)] for k in range(len(legend["parts"]))]


def test_max_frames_above_the_maximum_is_an_error_naming_the_line(tmp_path):
    _, p = run(tmp_path, scene_text(0.1, "animation:\n  max_frames: 1e7"), "--animation", expect=2)
    assert "scene.yaml:" in p.stderr and "field 'max_frames'" in p.stderr and "2 to 1e5" in p.stderr, p.stderr
    assert not (tmp_path / "out").exists()


def test_animation_over_its_disk_budget_is_refused_before_the_run(tmp_path):
    # 1e5 frames of the suspension: over the default budget of 1000 MB. Nothing is written.
    (tmp_path / "out").mkdir()
    (tmp_path / "out" / "summary.json").write_text("{}")  # an earlier run's: kept
    text = scene_text(100, "animation:\n  frame_rate: 1000\n  max_frames: 100000")
    _, p = run(tmp_path, text, "--animation", expect=2)
    line = text.splitlines().index("  max_frames: 100000") + 1
    assert f"scene.yaml:{line}: field 'max_frames'" in p.stderr and "disk budget of 1 GB" in p.stderr, p.stderr
    assert sorted(os.listdir(tmp_path / "out")) == ["summary.json"]
    # A frame rate that sets the count is named instead; so is the option.
    _, p = run(tmp_path, scene_text(100, "animation:\n  frame_rate: 10\n  disk_budget_mb: 1"), "--animation", expect=2)
    assert "field 'frame_rate'" in p.stderr and "disk budget of 1 MB" in p.stderr, p.stderr
    _, p = run(tmp_path, scene_text(100, "animation:\n  disk_budget_mb: 1"), "--animation-rate", "10", expect=2)
    assert "field '--animation-rate'" in p.stderr, p.stderr
    _, p = run(tmp_path, scene_text(0.1, "animation:\n  disk_budget_mb: 0.5"), "--animation", expect=2)
    assert "field 'disk_budget_mb'" in p.stderr and "from 1 to 1e6" in p.stderr, p.stderr


def test_animation_larger_than_the_free_space_is_refused_before_the_run(tmp_path):
    # Shapes make a frame large: 600 spheres (114 points each), about 10 MB a frame, in 2e4
    # frames are about 0.2 TB, within the budget of 1 TB and more than the free space of the
    # disk (checked with statvfs, exit code 4).
    import shutil
    if shutil.disk_usage(tmp_path).free > 1.5e11:
        pytest.skip("more than 150 GB free: the scene would fit")
    shapes = "".join(f"    - {{body: wheel, type: sphere, radius: 0.01, center: [0, 0, {k * 1e-3}]}}\n"
                     for k in range(600))
    text = scene_text(100, f"animation:\n  frame_rate: 1000\n  max_frames: 20000\n  disk_budget_mb: 1e6\n"
                            f"  shapes:\n{shapes}")
    _, p = run(tmp_path, text, "--animation", expect=4)
    assert "free on its file system" in p.stderr and "output folder" in p.stderr, p.stderr
    assert not (tmp_path / "out").exists()


def test_an_unusable_folder_is_the_same_input_error_with_animation(tmp_path):
    # /proc has no blocks (statvfs: 0 free): the folder check names the folder, exit 2, as without.
    scene = tmp_path / "scene.yaml"
    scene.write_text(scene_text(0.05))
    for args in ([], ["--animation"]):
        p = subprocess.run([MBDAE, "run", str(scene), "--out", "/proc/mbdae_x", "--quiet", *args],
                           capture_output=True, text=True)
        assert p.returncode == 2 and "field '--out'" in p.stderr and "cannot be created" in p.stderr, p.stderr


def test_a_run_without_animation_removes_the_earlier_runs_frames(tmp_path):
    out, _ = run(tmp_path, scene_text(0.8), "--animation-rate", "1000")  # a .pvd over 64 kB
    assert (out / "animation.pvd").stat().st_size > 65536 and list((out / "animation").glob("frame_*.vtp"))
    (out / "animation" / "notes.txt").write_text("mine")  # not mbdae's: stays
    (out / "animation" / "frame_000001.vtp.tmp").write_text("")  # left by a killed run
    run(tmp_path, scene_text(0.05))
    assert not (out / "animation.pvd").exists()
    assert sorted(os.listdir(out / "animation")) == ["notes.txt"]
    (out / "animation" / "notes.txt").unlink()
    run(tmp_path, scene_text(0.05), "--animation")
    run(tmp_path, scene_text(0.05))
    assert not (out / "animation").exists() and not (out / "animation.pvd").exists()
    (out / "animation.pvd").write_text("<my own collection/>")  # a .pvd mbdae did not write stays
    run(tmp_path, scene_text(0.05))
    assert (out / "animation.pvd").read_text() == "<my own collection/>"


def test_gif_frame_delays_follow_the_frame_rate(dynamics, tmp_path):
    from PIL import Image

    def delays(path):
        with Image.open(path) as im:
            out = []
            for k in range(im.n_frames):
                im.seek(k)
                out.append(im.info["duration"])
            return out

    pvd = str(dynamics / "animation.pvd")
    times = [t for t, _ in video.read_pvd(pvd)]
    # 20 frames per second of video: 5 cs each.
    assert video.animate(pvd, str(tmp_path / "a.gif"), fps=20, max_frames=6, size=(80, 60)) == 6
    assert delays(tmp_path / "a.gif") == [50] * 6
    # Real time: the frames are 60 per simulated second, over the 50 a GIF can show: every second
    # frame at 30 per second, delays of 3 and 4 cs that keep the time of every frame.
    n = video.animate(pvd, str(tmp_path / "b.gif"), end=0.2, size=(80, 60))
    d = delays(tmp_path / "b.gif")
    assert n == len(d) == len([t for t in times if t <= 0.2][::2]) and set(d) == {30, 40}
    assert all(abs(sum(d[:k]) - 1000 * k / 30) <= 5 for k in range(n + 1))
    with pytest.raises(ValueError, match="at most 50 frames per second"):
        video.animate(pvd, str(tmp_path / "c.gif"), fps=60)
    assert video.gif_delays(4, 50) == [20] * 4 and video.gif_delays(3, 7) == [140, 150, 140]
    for bad in (0, -1, float("nan"), float("inf")):
        with pytest.raises(ValueError):
            video.animate(pvd, str(tmp_path / "d.mp4"), fps=bad)


def test_interrupted_run_lists_every_frame_it_wrote(tmp_path):
    import signal
    import time
    import xml.etree.ElementTree as ET
    scene = os.path.join(ROOT, "cases", "five_point_suspension", "dynamics_poster.yaml")
    out = tmp_path / "out"
    p = subprocess.Popen([MBDAE, "run", scene, "--out", str(out), "--quiet", "--animation"], stderr=subprocess.PIPE)
    time.sleep(1.5)
    p.send_signal(signal.SIGINT)
    p.communicate(timeout=60)
    assert p.returncode == 130
    root = ET.parse(out / "animation.pvd").getroot()  # whole XML
    listed = sorted(d.get("file") for d in root.iter("DataSet"))
    on_disk = sorted("animation/" + f.name for f in (out / "animation").glob("frame_*.vtp"))
    assert listed == on_disk and len(listed) > 1


def test_the_paraview_recipe_works_as_written(dynamics):
    # docs/animation.md's steps in ParaView's own Python (cases/animation/paraview_recipe.py).
    # MBDAE_PVPYTHON: the command that runs ParaView's Python (docs/animation.md: Debian 12's
    # python3-paraview conflicts with python3-vtk9, which these tests need), else pvpython.
    import shlex
    import shutil
    pvpython = shlex.split(os.environ.get("MBDAE_PVPYTHON", "")) or [shutil.which("pvpython")]
    if pvpython[0] is None:
        pytest.skip("ParaView's pvpython is not installed (set MBDAE_PVPYTHON, docs/animation.md)")
    t = 0.1
    p = subprocess.run([*pvpython, os.path.join(ROOT, "cases", "animation", "paraview_recipe.py"),
                        str(dynamics / "animation.pvd"), "--time", str(t)], capture_output=True, text=True, timeout=300)
    assert p.returncode == 0, p.stderr
    r = json.loads(p.stdout.strip().splitlines()[-1])
    assert r["times"] == [t for t, _ in video.read_pvd(dynamics / "animation.pvd")]
    legend = json.load(open(dynamics / "animation" / "legend.json"))
    assert r["reader"]["field_data"]["body_names"] == [b["name"] for b in legend["bodies"]]
    # The spring as a tube: Threshold part 5, Extract Surface, Tube around the drawn spring line
    # (the frame read at the time ParaView shows: the last frame at or before t).
    frame_t, path = [e for e in video.read_pvd(dynamics / "animation.pvd") if e[0] <= t + 1e-12][-1]
    frame = video.read_frame(path)
    lines = frame["lines"]
    k = [k for k in range(len(lines["ids"])) if lines["part"][k] == video.FORCE_LINE][0]
    a, b = frame["points"][lines["ids"][k]]
    lo, hi = np.minimum(a, b), np.maximum(a, b)
    box = np.array(r["springs"]["bounds"]).reshape(3, 2)
    assert r["springs"]["class"] == "vtkPolyData" and r["springs"]["cells"] > 0
    assert np.all(box[:, 0] <= lo + 1e-6) and np.all(box[:, 1] >= hi - 1e-6)
    assert np.all(box[:, 0] >= lo - 0.005 - 1e-6) and np.all(box[:, 1] <= hi + 0.005 + 1e-6)
    assert r["arrows"]["cells"] > 0 and r["joints"]["cells"] > 0 and r["shapes"]["cells"] == 34
    assert r["tubes"]["cells"] > 0


def test_killed_run_leaves_a_whole_collection_of_written_frames(tmp_path):
    # SIGKILL cannot be caught: the .pvd, appended a line at a time after each frame is renamed
    # into place, still parses and lists only frames that are on disk (at most the last one
    # written is not listed yet).
    import signal
    import time
    import xml.etree.ElementTree as ET
    scene = os.path.join(ROOT, "cases", "five_point_suspension", "dynamics_poster.yaml")
    out = tmp_path / "out"
    p = subprocess.Popen([MBDAE, "run", scene, "--out", str(out), "--quiet", "--animation"], stderr=subprocess.PIPE)
    time.sleep(1.5)
    p.send_signal(signal.SIGKILL)
    p.communicate(timeout=60)
    root = ET.parse(out / "animation.pvd").getroot()
    listed = [d.get("file") for d in root.iter("DataSet")]
    on_disk = sorted("animation/" + f.name for f in (out / "animation").glob("frame_*.vtp"))
    assert len(listed) > 1 and set(listed) <= set(on_disk) and len(on_disk) - len(listed) <= 1
    for f in listed[-2:]:
        assert video.read_frame(str(out / f))["points"].shape[0] > 0

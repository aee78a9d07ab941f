"""Scenes, runs and results from Python against the command-line program."""
import json
import threading

import numpy as np
import pytest

import mbdae
from conftest import PAST_TRAVEL, STEP, SUSPENSION, cli_run, csv_text, needs_analysis_option, needs_overrides, same_columns

ROOT_ERRORS = STEP.parents[2] / "verification" / "engine" / "scenes"


def test_run_equals_cli_results_csv_byte_for_byte(tmp_path):
    code, err = cli_run(STEP, tmp_path, "--rtol", "1e-7")
    assert code == 0, err
    r = mbdae.load(STEP).run(rtol=1e-7)
    assert r.status == "ok" and r.rows > 1000
    assert csv_text(r) == (tmp_path / "results.csv").read_text()
    cli_summary = json.loads((tmp_path / "summary.json").read_text())
    for mine, cli in zip(r.summary["steps"], cli_summary["steps"]):
        assert mine["status"] == cli["status"]
        assert mine.get("statistics", {}).get("steps") == cli.get("statistics", {}).get("steps")
    assert list(r.table.columns) == r.names and np.array_equal(r.table["wheel_z"].to_numpy(), r["wheel_z"])


def test_columns_are_views_not_copies():
    r = mbdae.load(STEP).run(analysis="dynamics", output_step=0.01)
    z = r.columns["wheel_z"]
    assert not z.flags["OWNDATA"] and z.base is not None and not z.flags["WRITEABLE"]
    assert r.columns["wheel_z"].__array_interface__["data"][0] == z.__array_interface__["data"][0]
    del r  # the array keeps the C++ result alive
    assert np.isfinite(z).all() and len(z) == 151


def test_options_are_the_clis(tmp_path):
    code, err = cli_run(STEP, tmp_path, "--formulation", "index1", "--output-step", "0.005", "--atol", "1e-12")
    assert code == 0, err
    r = mbdae.load(STEP).run(formulation="index1", output_step=0.005, atol=1e-12, out=tmp_path / "py")
    assert csv_text(r) == (tmp_path / "results.csv").read_text() == (tmp_path / "py" / "results.csv").read_text()
    assert json.loads((tmp_path / "py" / "summary.json").read_text())["status"] == "ok"
    with pytest.raises(ValueError, match="formulation"):
        mbdae.load(STEP).run(formulation="index7")
    with pytest.raises(ValueError, match="rtol"):
        mbdae.load(STEP).run(rtol=2)


def test_index3_handover_is_the_clis_and_says_so(tmp_path):
    # Below rtol 1e-6 a dynamics step's index3 runs as index2-ggl (docs/formulation.md), from
    # Python as from the CLI; index3-no-handover keeps index3.
    code, err = cli_run(STEP, tmp_path, "--rtol", "1e-7", "--output-step", "0.01")
    assert code == 0, err
    r = mbdae.load(STEP).run(rtol=1e-7, output_step=0.01)
    step = r.summary["steps"][-1]
    assert (step["formulation"], step["formulation_asked"]) == ("index2-ggl", "index3")
    assert any("index3 runs as index2-ggl" in n for n in r.summary["notes"])
    assert csv_text(r) == (tmp_path / "results.csv").read_text()
    kept = mbdae.load(STEP).run(rtol=1e-7, output_step=0.01, formulation="index3-no-handover")
    assert kept.summary["steps"][-1]["formulation"] == "index3-no-handover"
    assert "formulation_asked" not in kept.summary["steps"][-1]
    assert "index3-no-handover" in mbdae.formulations()
    # index1 likewise below rtol 1e-9; index1-no-handover keeps index1.
    assert "index1-no-handover" in mbdae.formulations()
    tight = mbdae.load(STEP).run(formulation="index1", rtol=3e-10, output_step=0.05)
    assert (tight.summary["steps"][-1]["formulation"], tight.summary["steps"][-1]["formulation_asked"]) == \
        ("index2-ggl", "index1")
    own = mbdae.load(STEP).run(formulation="index1-no-handover", rtol=3e-10, output_step=0.05)
    assert own.summary["steps"][-1]["formulation"] == "index1-no-handover"


@needs_analysis_option
def test_analysis_option_stops_after_that_step():
    scene = mbdae.load(STEP)
    assert [s["type"] for s in scene.run(analysis=0).summary["steps"]] == ["assembly"]
    assert [s["type"] for s in scene.run(analysis="equilibrium").summary["steps"]] == ["assembly", "equilibrium"]
    with pytest.raises(ValueError, match="kinematics"):
        scene.run(analysis="kinematics")


def test_scene_error_fields_are_the_clis_lines(tmp_path):
    bad = ROOT_ERRORS / "error_unknown_field.yaml"
    code, err = cli_run(bad, tmp_path)
    assert code == 2
    with pytest.raises(mbdae.SceneError) as e:
        mbdae.load(bad)
    assert str(e.value) == err.rstrip("\n")
    first = err.splitlines()[0]
    assert first.startswith(f"{e.value.file}:{e.value.line}: field '{e.value.field}': ")
    assert e.value.file.endswith("error_unknown_field.yaml") and e.value.line > 0 and e.value.field


def test_scene_from_yaml_and_dict_equal_the_file():
    text = STEP.read_text()
    base = mbdae.load(STEP).run()
    from_text = mbdae.Scene.from_yaml(text, path=str(STEP)).run()
    assert same_columns(base, from_text)
    import yaml
    from_dict = mbdae.Scene.from_dict(yaml.safe_load(text), path=str(STEP)).run()
    assert same_columns(base, from_dict)
    with pytest.raises(mbdae.SceneError) as e:
        mbdae.Scene.from_dict({**yaml.safe_load(text), "colour": "red"}, path=str(STEP))
    assert e.value.field == "colour" and e.value.line > 0


def test_solve_error_keeps_the_partial_result(tmp_path):
    code, err = cli_run(PAST_TRAVEL, tmp_path)
    assert code == 3
    with pytest.raises(mbdae.SolveError) as e:
        mbdae.load(PAST_TRAVEL).run()
    r = e.value.result
    cli_summary = json.loads((tmp_path / "summary.json").read_text())
    assert e.value.status == r.status == cli_summary["status"] == "integration_failed"
    assert r.message == cli_summary["message"]
    assert 100 < r.rows and csv_text(r) == (tmp_path / "results.csv").read_text()
    assert r["t"][-1] < 1.0  # stopped before t_end (the mechanism folds at t = 0.789 s)
    partial = mbdae.load(PAST_TRAVEL).run(raise_on_failure=False)
    assert same_columns(partial, r)


def test_two_runs_in_two_threads_equal_runs_one_by_one():
    scene = mbdae.load(STEP)
    alone = [scene.run(rtol=1e-8), scene.run(formulation="index1", rtol=1e-7)]
    got = [None, None]

    def go(k, kw):
        got[k] = scene.run(**kw)
    threads = [threading.Thread(target=go, args=(0, {"rtol": 1e-8})),
               threading.Thread(target=go, args=(1, {"formulation": "index1", "rtol": 1e-7}))]
    for t in threads:
        t.start()
    for t in threads:
        t.join()
    assert same_columns(got[0], alone[0]) and same_columns(got[1], alone[1])


def test_gil_released_while_solving():
    # While a thread solves, this thread keeps running Python: a held GIL would stop the count.
    scene = mbdae.load(STEP)
    t = threading.Thread(target=lambda: scene.run(rtol=1e-10, atol=1e-15))
    count = 0
    t.start()
    while t.is_alive():
        count += 1
    assert count > 10000


@needs_overrides
def test_overrides_equal_an_edited_scene_file(tmp_path):
    text = STEP.read_text()
    edited = text.replace("stiffness: 2.0e5", "stiffness: 3.5e5").replace("t_end: 1.5", "t_end: 0.7")
    assert edited.count("3.5e5") == 1 and "t_end: 0.7" in edited
    (tmp_path / "model.yaml").write_text((STEP.parent / "model.yaml").read_text())
    (tmp_path / "edited.yaml").write_text(edited)
    want = mbdae.load(tmp_path / "edited.yaml").run()
    scene = mbdae.load(STEP)
    got = scene.with_params({"forces.tyre.stiffness": 3.5e5, "analysis.dynamics.t_end": 0.7}).run()
    assert same_columns(got, want) and got["t"][-1] == 0.7
    assert same_columns(scene.run(), mbdae.load(STEP).run())  # with_params left the scene alone
    scene.set("forces.tyre.stiffness", "3.5e5").set("analysis.dynamics.t_end", 0.7)
    assert same_columns(scene.run(), want)


@needs_overrides
def test_model_parameter_override_equals_an_edited_model_file(tmp_path):
    model = (STEP.parent / "model.yaml").read_text()
    assert model.count("damping: 1400") == 1
    (tmp_path / "model.yaml").write_text(model.replace("damping: 1400", "damping: 2100"))
    (tmp_path / "step.yaml").write_text(STEP.read_text().replace("t_end: 1.5", "t_end: 0.7"))
    want = mbdae.load(tmp_path / "step.yaml").run()
    got = mbdae.load(STEP).with_params({"forces.suspension.damping": 2100, "analysis.dynamics.t_end": 0.7}).run()
    assert same_columns(got, want)


@needs_overrides
def test_bad_overrides_raise_scene_error_with_file_line_field():
    scene = mbdae.load(STEP)
    lines = STEP.read_text().splitlines()
    tyre_line = next(i for i, s in enumerate(lines, 1) if "name: tyre" in s)
    stiffness_line = next(i for i, s in enumerate(lines, 1) if i >= tyre_line and "stiffness:" in s)
    with pytest.raises(mbdae.SceneError) as e:
        scene.set("forces.tyre.stiffness", -1.0)
    assert e.value.file.endswith("dynamics_step.yaml") and e.value.line == stiffness_line
    assert "stiffness" in e.value.field, str(e.value)
    with pytest.raises(mbdae.SceneError) as e:
        scene.set("forces.tyre.stiffness", "[1, 2]")
    assert "stiffness" in e.value.field
    with pytest.raises(mbdae.SceneError) as e:
        scene.set("forces.no_such_force.damping", 1.0)
    assert e.value.file.endswith("dynamics_step.yaml") and "no_such_force" in str(e.value)
    assert same_columns(scene.run(output_step=0.01), mbdae.load(STEP).run(output_step=0.01))  # unchanged


def test_ctrl_c_stops_a_run_in_the_main_thread():
    # A 20 s poster run (1.5 s CPU) interrupted after 0.5 s: KeyboardInterrupt, well before its end.
    import subprocess
    import sys
    code = ("import mbdae, signal, threading, os, time\n"
            "threading.Timer(0.5, lambda: os.kill(os.getpid(), signal.SIGINT)).start()\n"
            "t = time.process_time()\n"
            f"try:\n    mbdae.load({str(STEP.parent / 'dynamics_poster.yaml')!r}).run()\n"
            "except KeyboardInterrupt:\n    print('interrupted', time.process_time() - t)\n")
    p = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, timeout=120)
    assert p.returncode == 0 and p.stdout.startswith("interrupted"), p.stderr
    full = mbdae.load(STEP.parent / "dynamics_poster.yaml").run(output_step=0.1).cpu_seconds()
    assert float(p.stdout.split()[1]) < 0.8 * full


def test_result_animation_draws_the_runs_frames(tmp_path):
    # Scene.run(animation=DIR) writes the ParaView series through the animation sink; its frames
    # hold the wheel centre where the run's sensor has it, and Result.animation draws them.
    import vtk
    from vtk.util.numpy_support import vtk_to_numpy
    r = mbdae.load(STEP).with_params({"analysis.dynamics.t_end": "0.3"}).run(
        analysis="dynamics", output_step=0.01, animation=tmp_path / "anim", animation_rate=20)
    assert r.ok and (tmp_path / "anim" / "animation.pvd").is_file()
    frames = sorted((tmp_path / "anim" / "animation").glob("frame_*.vtp"))
    assert len(frames) == 7  # t = 0, 0.05, ..., 0.3
    with pytest.raises(ValueError):
        mbdae.load(STEP).with_params({"analysis.dynamics.t_end": "0.01"}).run(analysis="dynamics").animation(tmp_path / "x.gif")
    gif = r.animation(tmp_path / "a.gif", size=(160, 120))
    from PIL import Image
    with Image.open(gif) as im:
        assert im.size == (160, 120) and im.n_frames == len(frames)


def test_run_with_animation_true_leaves_no_temporary_folder(tmp_path, monkeypatch):
    # run(animation=True) without `out`: the frames go to a temporary folder that lives as long
    # as the Result (collected, or at exit), and a run that raises leaves none.
    import gc
    import os
    import subprocess
    import sys
    import tempfile
    from pathlib import Path
    monkeypatch.setenv("TMPDIR", str(tmp_path))
    monkeypatch.setattr(tempfile, "tempdir", None)  # tempfile reads TMPDIR again
    scene = mbdae.load(STEP).with_params({"analysis.dynamics.t_end": "0.05"})
    r = scene.run(analysis="dynamics", output_step=0.01, animation=True)
    folder = Path(r.animation_dir)
    assert folder.parent == tmp_path and (folder / "animation.pvd").is_file()
    r.animation(tmp_path / "a.gif", size=(80, 60))
    del r
    gc.collect()
    assert not folder.exists() and not list(tmp_path.glob("mbdae_animation_*"))
    with pytest.raises(ValueError):
        scene.run(analysis="dynamics", animation=True, animation_rate=-1)
    assert not list(tmp_path.glob("mbdae_animation_*"))
    script = (f"import mbdae\nr = mbdae.load({str(STEP)!r}).with_params({{'analysis.dynamics.t_end': '0.05'}})"
              ".run(analysis='dynamics', animation=True)\nprint(r.animation_dir)\n")
    p = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, timeout=120,
                       env={**os.environ, "TMPDIR": str(tmp_path)})
    assert p.returncode == 0, p.stderr
    assert p.stdout.strip().startswith(str(tmp_path)) and not Path(p.stdout.strip()).exists()


def test_normalized_sensitivities_are_the_clis(tmp_path):
    """Result.normalized_sensitivities() (Python) and sensitivities_normalized.csv (the CLI's
    --normalized-sensitivities, cases/run/sensitivities.cpp) apply one rule: the same numbers, to
    the CSV's digits, on Dynamics I with the tyre stiffness and the damping."""
    import pandas as pd
    params = ["forces.tyre.stiffness", "forces.suspension.damping"]
    args = ["--normalized-sensitivities"]
    for p in params:
        args += ["--sensitivity", p]
    code, err = cli_run(STEP, tmp_path, *args)
    assert code == 0, err
    csv = pd.read_csv(tmp_path / "sensitivities_normalized.csv")
    table = mbdae.load(STEP).run(sensitivities=params).normalized_sensitivities()
    assert len(table.columns) == len(csv.columns) - 1 > 0
    for (sensor, param), column in zip(table.columns, csv.columns[1:]):
        assert column == f"d({sensor})/d({param})*p/max|{sensor}|", column
        x, y = table[(sensor, param)].to_numpy(), csv[column].to_numpy()
        assert np.allclose(x, y, rtol=1e-9, atol=1e-12 * np.abs(y).max()), column


def test_static_steps_only_have_empty_sensitivity_tables_as_the_cli(tmp_path):
    """A scene of static steps only has no samples: Result.sensitivities and
    normalized_sensitivities() have every (sensor, parameter) column and no rows, as the CLI's
    sensitivities.csv and sensitivities_normalized.csv (header lines); the step's sensitivities
    are in the summary."""
    import pandas as pd
    scene, path = SUSPENSION / "equilibrium.yaml", "forces.suspension.stiffness"
    code, err = cli_run(scene, tmp_path, "--sensitivity", path, "--normalized-sensitivities")
    assert code == 0, err
    r = mbdae.load(scene).run(sensitivities=[path])
    assert r.rows == 0 and r.sensitivities.shape == (0, len(r.names) - 1)
    norm = r.normalized_sensitivities()
    assert norm.shape == (0, len(r.names) - 1) and list(norm.columns) == list(r.sensitivities.columns)
    assert norm.index.name == "t"
    csv = pd.read_csv(tmp_path / "sensitivities_normalized.csv")
    assert len(csv) == 0
    assert list(csv.columns[1:]) == [f"d({s})/d({p})*p/max|{s}|" for s, p in norm.columns]
    assert len(pd.read_csv(tmp_path / "sensitivities.csv").columns) == len(csv.columns)
    assert "wheel_z" in r.summary["steps"][-1]["sensitivities"]

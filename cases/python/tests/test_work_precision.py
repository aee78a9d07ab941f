"""python3 -m mbdae work-precision on a small case (the fast mechanism, 0.02 s), and the error
options of Scene.run (error_estimate, error_target, error_sensors) with good and hostile values."""
import math
import subprocess
import sys

import numpy as np
import pandas as pd
import pytest

import mbdae
from conftest import ROOT, STEP

FAST = ROOT / "verification" / "fast_mechanism" / "slider_crank_fast.yaml"


def wp(*args):
    return subprocess.run([sys.executable, "-m", "mbdae", "work-precision", *map(str, args)],
                          capture_output=True, text=True, timeout=300)


def test_work_precision_command(tmp_path):
    r = wp(FAST, "--out", tmp_path, "--formulations", "index3,index1", "--tols", "1e-3,1e-5,1e-7",
           "--columns", "pin_y,piston_vx", "--estimate", "--no-progress")
    assert r.returncode == 0, r.stderr
    table = pd.read_csv(tmp_path / "work_precision.csv")
    assert len(table) == 6 and (table["status"] == "ok").all()
    assert (tmp_path / "work_precision_pin_y.png").stat().st_size > 10000
    scene = mbdae.load(FAST)
    reference = scene.run(formulation="index2-ggl", rtol=1e-12)
    for _, row in table.iterrows():  # the table's errors are the runs' own
        alone = scene.run(formulation=row["formulation"], rtol=row["rtol"])
        assert row["err_pin_y"] == pytest.approx(np.max(np.abs(alone["pin_y"] - reference["pin_y"])), rel=1e-12)
        assert row["est_pin_y"] > 0 and row["estimate_cpu_s"] > 0
    # Each curve's slope and floor are printed, one line per formulation and column.
    lines = [l.split() for l in r.stdout.splitlines() if l.startswith(("index3 ", "index1 "))]
    assert len(lines) == 4
    for f, col, runs, slope, *rest in lines:
        rows = table[table["formulation"] == f].sort_values("rtol")
        expect = np.polyfit(np.log10(rows["rtol"]), np.log10(rows[f"err_{col}"]), 1)[0]
        assert float(slope) == pytest.approx(expect, abs=0.006)
    assert "reference: index2-ggl at rtol 1e-12" in r.stdout


def test_work_precision_with_a_reference_csv(tmp_path):
    ref = mbdae.load(FAST).run(formulation="index2-ggl", rtol=1e-12)
    ref.table.to_csv(tmp_path / "ref.csv", index=False)
    r = wp(FAST, "--out", tmp_path / "wp", "--formulations", "index2-ggl", "--tols", "1e-4,1e-6",
           "--reference", tmp_path / "ref.csv", "--no-progress")
    assert r.returncode == 0, r.stderr
    table = pd.read_csv(tmp_path / "wp" / "work_precision.csv")
    assert (table["err_pin_y"] > 0).all() and table["err_pin_y"].iloc[1] < table["err_pin_y"].iloc[0]


@pytest.mark.parametrize("args, message", [
    (["--formulations", "index4"], "--formulations: unknown index4"),
    (["--tols", "1e-3,x"], "--tols: expected numbers"),
    (["--tols", "2"], "--tols: every rtol must be in [1e-14, 0.5]"),
    (["--columns", "pin_yy"], "--columns: no output sensor named 'pin_yy'; did you mean 'pin_y'?"),
    (["--atol-ratio", "-1"], "--atol-ratio: must be a positive number"),
    (["--workers", "0"], "--workers: must be at least 1"),
    (["--reference", "/nonexistent/ref.csv"], "ref.csv"),
])
def test_work_precision_bad_options(tmp_path, args, message):
    r = wp(FAST, "--out", tmp_path / "wp", "--tols", "1e-3", *args)
    assert r.returncode == 1, (r.stdout, r.stderr)
    assert message in r.stderr


def test_work_precision_bad_scene(tmp_path):
    r = wp(tmp_path / "missing.yaml", "--out", tmp_path / "wp")
    assert r.returncode == 2


def test_run_error_estimate_and_target():
    scene = mbdae.load(FAST)
    r = scene.run(error_estimate=True)
    est = r.summary["error_estimate"]
    assert set(est["sensors"]["pin_y"]) >= {"error", "scale", "relative", "exceeded"}
    t = scene.run(error_target=1e-5, error_sensors=["pin_y"])
    target = t.summary["error_target"]
    assert target["met"] and target["sensors"]["pin_y"]["target"] == 1e-5
    assert 3 * target["sensors"]["pin_y"]["estimate"] <= 1e-5


@pytest.mark.parametrize("kwargs, message", [
    ({"error_target": -1}, "error_target expects a number"),
    ({"error_target": math.nan}, "error_target expects a number"),
    ({"error_target": math.inf}, "error_target expects a number"),
    ({"error_target": 1e-6, "error_sensors": ["wheel_zz"]}, "no output sensor named 'wheel_zz'; did you mean 'wheel_z'?"),
    ({"error_target": 1e-6, "error_sensors": []}, "error_sensors expects a list of sensor names"),
    ({"error_sensors": ["wheel_z"]}, "error_sensors needs error_target"),
    ({"error_estimate": "yes"}, "error_estimate expects True or False"),
])
def test_run_error_options_hostile(kwargs, message):
    with pytest.raises(ValueError, match=message.replace("?", r"\?").replace("(", r"\(")):
        mbdae.load(STEP).run(**kwargs)


def test_run_accuracy_not_met_raises():
    with pytest.raises(mbdae.SolveError) as e:
        mbdae.load(FAST).run(error_target=1e-14)
    assert e.value.status == "accuracy_not_met" and e.value.result.rows == 201


def test_run_estimate_warns_unless_told_not_to(capfd):
    scene = mbdae.load(FAST)
    # index3-positions (local errors per step) misses the promise by 1.5e4 to 2.6e4 rtol
    r = scene.run(formulation="index3-positions", error_estimate=True)
    assert "pin_y" in r.summary["error_estimate"]["exceeded"]
    assert "mbdae: warning: sensor pin_y: estimated global error" in capfd.readouterr().err
    r = scene.run(formulation="index3-positions", error_estimate=True, error_warnings=False)
    assert "pin_y" in r.summary["error_estimate"]["exceeded"]
    assert "warning" not in capfd.readouterr().err

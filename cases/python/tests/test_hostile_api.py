"""Issue 25: the Python API checks what `mbdae run` checks (option ranges, the scene before the
folder, the folder's lock), with the CLI's words."""
import fcntl
import json
import os

import pytest

import mbdae
from conftest import STEP, cli_run

WHEEL = """name: wheel
gravity: [0, 0, 0]
bodies:
  - {name: wheel, mass: 1.0, inertia: {xx: 0.3, yy: 0.3, zz: 0.5}}
joints:
  - {name: axle, parent: ground, child: wheel, anchor: [0, 0, 0], chain: [R3], coordinates: [theta]}
coordinates:
  theta: {initial: 0}
forces:
  - {name: motor, type: torque, body: wheel, axis: [0, 0, 1], torque: "TORQUE"}
sensors:
  - {name: angle, type: coordinate, coordinate: theta}
analysis:
  - {type: dynamics, t_end: 0.2, output_step: 0.01}
"""


def wheel(torque="2"):
    return mbdae.Scene.from_yaml(WHEEL.replace("TORQUE", torque), "wheel.yaml")


@pytest.mark.parametrize("kwargs, option", [
    ({"rtol": 1e-300}, "rtol"),
    ({"rtol": 0.9}, "rtol"),
    ({"rtol": float("nan")}, "rtol"),
    ({"rtol": "tight"}, "rtol"),
    ({"atol": -1e-8}, "atol"),
    ({"atol": 0}, "atol"),
    ({"output_step": 1e-12}, "output_step"),
    ({"output_step": -0.1}, "output_step"),
    ({"output_step": float("inf")}, "output_step"),
    ({"formulation": "index7"}, "formulation"),
])
def test_run_options_are_range_checked_like_the_cli(kwargs, option, tmp_path):
    """Each bad option raises ValueError naming it before anything runs or is written; the CLI
    refuses the same value (exit 1) with the same words where it takes the option."""
    out = tmp_path / "out"
    with pytest.raises(ValueError) as e:
        wheel().run(out=out, **kwargs)
    assert str(e.value).startswith(option + ":"), str(e.value)
    assert not out.exists()
    cli = {"rtol": "--rtol", "atol": "--atol", "output_step": "--output-step"}.get(option)
    value = next(iter(kwargs.values()))
    if cli and isinstance(value, float) and value not in (0, ) and value == value and abs(value) != float("inf"):
        scene = tmp_path / "wheel.yaml"
        scene.write_text(WHEEL.replace("TORQUE", "2"))
        code, err = cli_run(scene, tmp_path / "cli", cli, repr(value))
        assert code == 1, err
        assert str(e.value).split(":", 1)[1].strip() in err, (str(e.value), err)


def test_good_options_still_run(tmp_path):
    r = wheel().run(rtol=1e-8, atol=1e-10, output_step=0.05, out=tmp_path / "out")
    assert r.ok and r.rows == 5
    assert json.loads((tmp_path / "out" / "summary.json").read_text())["status"] == "ok"


def test_run_out_takes_the_clis_lock(tmp_path):
    """A folder another run is writing (its lock held) is refused with OSError, and nothing in it
    is touched (the CLI's exit code 4 case)."""
    out = tmp_path / "busy"
    out.mkdir()
    (out / "summary.json").write_text('{"status": "running"}')
    fd = os.open(out / ".mbdae.lock", os.O_RDWR | os.O_CREAT, 0o644)
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
        with pytest.raises(OSError, match="in use by another run"):
            wheel().run(out=out)
        assert (out / "summary.json").read_text() == '{"status": "running"}'
        assert not (out / "results.csv").exists() and not (out / "results.csv.partial").exists()
    finally:
        os.close(fd)
    assert wheel().run(out=out).ok  # free again


def test_refused_scene_leaves_the_folder_as_it_was(tmp_path):
    """A scene refused by the checks of the system (here a load that reads a sensor it may not,
    found while building it) raises SceneError before the folder is claimed."""
    out = tmp_path / "out"
    assert wheel().run(out=out).ok
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    text = WHEEL.replace("TORQUE", "E").replace(
        "sensors:\n", "sensors:\n  - {name: E, type: kinetic_energy}\n")
    with pytest.raises(mbdae.SceneError) as e:
        mbdae.Scene.from_yaml(text, "wheel.yaml").run(out=out)
    assert e.value.field == "torque" and e.value.line == 10 and "cannot drive a load" in e.value.message
    assert {p.name: p.read_bytes() for p in out.iterdir()} == before


def test_nan_load_is_a_solve_error_naming_the_load(tmp_path):
    with pytest.raises(mbdae.SolveError) as e:
        wheel("sqrt(0.05 - t)").run(out=tmp_path / "out")
    assert e.value.status == "non_finite"
    assert "load 'motor' (torque = sqrt(0.05 - t)) is NaN at t = 0.05" in e.value.message
    r = e.value.result
    assert 5 <= r.rows <= 6 and all(t <= 0.05 for t in r["t"])
    summary = json.loads((tmp_path / "out" / "summary.json").read_text())
    assert summary["status"] == "non_finite"


# Issue 24: sensitivities asked from Python get the CLI's checks before anything runs.
@pytest.mark.parametrize("value, words", [
    ([""], "non-empty strings"),
    (["gravity.2", "bodies.wheel.\udcff"], "sensitivities: the path 'bodies.wheel."),
    ("\udcff", "cannot be encoded as UTF-8"),
    (["forces.motr.torque"], "no such parameter"),
    (["bodies.wheel.mas"], "did you mean 'bodies.wheel.mass'"),
    (["gravity"], "not a single number; name one element: gravity.0"),
    (["analysis.dynamics.t_end"], "a setting of the analysis"),
    (["bodies.wheel.mass", "bodies.wheel.mass"], "asked twice"),
])
def test_bad_sensitivity_requests_are_refused(value, words, tmp_path):
    with pytest.raises(ValueError, match=words.replace("(", r"\(").replace(".", r"\.")):
        wheel().run(sensitivities=value, out=tmp_path / "out")
    assert not (tmp_path / "out" / "summary.json").exists()


# A list or tuple of str, or one path as a str; any other type is a TypeError naming the argument
# and what was given (a dict was read as its keys, a set in its own order, bytes byte by byte).
@pytest.mark.parametrize("value, given", [
    (5, "got int 5"),
    ([3.0], "got float 3.0 in list [3.0]"),
    ({"gravity.2": 1}, "got dict {'gravity.2': 1}"),
    ({"gravity.2"}, "got set {'gravity.2'}"),
    (b"gravity.2", "got bytes b'gravity.2'"),
    (["gravity.2", b"gravity.1"], "got bytes b'gravity.1' in list"),
    (iter(["gravity.2"]), "got list_iterator"),
])
def test_sensitivities_of_another_type_are_a_type_error(value, given, tmp_path):
    with pytest.raises(TypeError) as e:
        wheel().run(sensitivities=value, out=tmp_path / "out")
    assert str(e.value).startswith("sensitivities expects") and given in str(e.value), str(e.value)
    assert not (tmp_path / "out" / "summary.json").exists()


def test_sensitivities_as_one_str_a_list_or_a_tuple_are_alike():
    runs = [wheel().run(sensitivities=v).sensitivities for v in ("gravity.1", ["gravity.1"], ("gravity.1",))]
    assert list(runs[0].columns) == [("angle", "gravity.1")]
    assert runs[0].equals(runs[1]) and runs[0].equals(runs[2])


def test_sensitivities_not_with_index3_by_name():
    with pytest.raises(ValueError, match="not with formulation index3"):
        wheel().run(sensitivities=["bodies.wheel.inertia.zz"], formulation="index3")


def test_sensitivities_in_the_result_and_the_folder(tmp_path):
    import pickle
    import numpy as np
    # A constant torque T on inertia J from rest: angle = T t^2 / (2 J), d(angle)/dJ = -T t^2 / (2 J^2).
    r = wheel().run(sensitivities="bodies.wheel.inertia.zz", out=tmp_path / "out", rtol=1e-10)
    s = r.sensitivities[("angle", "bodies.wheel.inertia.zz")]
    t = s.index.to_numpy()
    assert np.allclose(s.to_numpy(), -2 * t ** 2 / (2 * 0.5 ** 2), rtol=0, atol=1e-8)
    assert r.sensitivity_units[("angle", "bodies.wheel.inertia.zz")] == "rad/(kg m^2)"
    assert pickle.loads(pickle.dumps(r)).sensitivities.equals(r.sensitivities)
    assert (tmp_path / "out" / "sensitivities.csv").exists()
    assert r.summary["sensitivities"]["status"] == "ok"
    assert wheel().run().sensitivities is None


def test_sensitivities_to_initial_values():
    import numpy as np
    # Released at theta0 = 0.3 with rate w0 = 10 under a constant torque: theta = theta0 + w0 t + T t^2 / (2 J),
    # so d(theta)/d(w0) = t, d(rate)/d(w0) = 1, d(theta)/d(theta0) = 1, d(rate)/d(theta0) = 0.
    text = WHEEL.replace("TORQUE", "2").replace("theta: {initial: 0}", "theta: {initial: 0.3}").replace(
        "output_step: 0.01}", "output_step: 0.01, rtol: 1.0e-10, initial_velocities: {theta: 10}}")
    text = text.replace("  - {name: angle, type: coordinate, coordinate: theta}",
                        "  - {name: angle, type: coordinate, coordinate: theta}\n"
                        "  - {name: rate, type: coordinate_rate, coordinate: theta}")
    r = mbdae.Scene.from_yaml(text, "wheel.yaml").run(
        sensitivities=["analysis.dynamics.initial_velocities.theta", "coordinates.theta.initial"])
    s = r.sensitivities
    t = s.index.to_numpy()
    w0, th0 = "analysis.dynamics.initial_velocities.theta", "coordinates.theta.initial"
    assert np.abs(s[("angle", w0)] - t).max() < 1e-7
    assert np.abs(s[("rate", w0)] - 1).max() < 1e-6
    assert np.abs(s[("angle", th0)] - 1).max() < 1e-6
    assert np.abs(s[("rate", th0)]).max() < 1e-6

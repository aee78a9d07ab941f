"""Shared paths and helpers of the mbdae package tests (run by ctest with PYTHONPATH set to
BUILD/python and MBDAE_CLI to the command-line program)."""
import os
import subprocess
from pathlib import Path

import numpy as np
import pytest

import mbdae

ROOT = Path(__file__).resolve().parents[3]
SUSPENSION = ROOT / "cases" / "five_point_suspension"
STEP = SUSPENSION / "dynamics_step.yaml"          # Dynamics I
PAST_TRAVEL = ROOT / "verification" / "studies" / "extreme" / "kinematics_past_travel.yaml"  # fails (exit 3)
CLI = Path(os.environ.get("MBDAE_CLI", ROOT / "build" / "mbdae"))


def _overrides_implemented():
    try:
        mbdae.load(STEP).set("forces.tyre.stiffness", 2.0e5)
        return True
    except RuntimeError as e:
        if "not implemented" in str(e):
            return False
        raise


OVERRIDES = _overrides_implemented()
# Tests of parameter overrides: expected to fail with "not implemented" until set_parameter lands
# (cases/run/api.cpp); they run normally from then on.
needs_overrides = pytest.mark.xfail(not OVERRIDES, raises=RuntimeError, strict=True,
                                    reason="mbdae::set_parameter not implemented yet in this build")


def _analysis_option_implemented():
    try:
        mbdae.load(PAST_TRAVEL).run(analysis=0, raise_on_failure=False)
        return True
    except NotImplementedError:
        return False


ANALYSIS_OPTION = _analysis_option_implemented()
# RunOptions::analysis (run the steps up to that one) is the API's; Scene.run raises
# NotImplementedError while mbdae::run ignores it.
needs_analysis_option = pytest.mark.xfail(not ANALYSIS_OPTION, raises=NotImplementedError, strict=True,
                                          reason="RunOptions::analysis not honoured by mbdae::run yet in this build")


def cli_run(scene, out, *args):
    """Runs the CLI; returns its exit code and stderr."""
    p = subprocess.run([str(CLI), "run", str(scene), "--out", str(out), "--quiet", *args],
                       capture_output=True, text=True)
    return p.returncode, p.stderr


def csv_text(result):
    """The Result as the CLI writes results.csv: header, then rows of %.15g values."""
    lines = [",".join(result.names)]
    cols = [result[n] for n in result.names]
    for i in range(result.rows):
        lines.append(",".join(format(float(c[i]), ".15g") for c in cols))
    return "\n".join(lines) + "\n"


def same_columns(a, b):
    """Every column of two Results bit-for-bit equal."""
    return a.names == b.names and all(np.array_equal(a[n], b[n]) for n in a.names)

# Shared fixtures of the Python API's tests (run by CTest as python.api: PYTHONPATH names the
# built package, OBSCURA_BINARY the command line they compare against).
import os
import pathlib
import subprocess

import numpy as np
import pytest

import obscura

REPO = pathlib.Path(__file__).resolve().parents[2]
CORNELL = REPO / "scenes" / "cornell-box" / "cornell-box.gltf"
LIGHT_IN_BOX = REPO / "scenes" / "hard" / "light-in-box.gltf"
# Small frames: the tests check equalities, which hold at any size, and run on lavapipe.
SMALL = dict(width=32, height=24, spp=2)


@pytest.fixture(scope="session", autouse=True)
def no_validation_messages():
    """Every test runs with the validation layer on (OBSCURA_VALIDATE=1): none may complain."""
    yield
    assert obscura.validation_messages() == []


@pytest.fixture(scope="session")
def binary():
    path = os.environ.get("OBSCURA_BINARY")
    if not path or not os.path.exists(path):
        pytest.skip("OBSCURA_BINARY does not name the obscura binary")
    return path


@pytest.fixture(scope="session")
def cornell():
    return obscura.Scene(str(CORNELL))


def run_cli(binary, *args):
    """Runs the command line; its stderr in the failure message when it fails."""
    done = subprocess.run([binary, *map(str, args)], capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    return done


def assert_same(actual, expected, what, rtol=0.0, atol=0.0):
    actual, expected = np.asarray(actual), np.asarray(expected)
    assert actual.shape == expected.shape, f"{what}: shape {actual.shape} != {expected.shape}"
    np.testing.assert_allclose(actual, expected, rtol=rtol, atol=atol, err_msg=what)

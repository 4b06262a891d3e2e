"""Shared scenes and paths of the module's tests (run by ctest with PYTHONPATH=build/python)."""
import os
import pathlib

import pytest

import soak

ROOT = pathlib.Path(__file__).resolve().parents[2]
SCENES = ROOT / "scenes"


def cloth_scene(resolution=12, pin_corners=True, wetting=False):
    """A 0.4 m sheet at y = 0.5, pinned at its four corners, without water."""
    cloth = {"mesh": {"type": "rectangle", "center": [0, 0.5, 0], "size": [0.4, 0.4],
                      "resolution": [resolution, resolution]}}
    if pin_corners:
        cloth["pin"] = {"corners": [0, 1, 2, 3]}
    scene = {"solver": {"dt": 0.01, "substeps": 1, "domain": {"min": [-1, -1, -1], "max": [1, 2, 1]}},
             "cloth": [cloth],
             "output": {"frames": 4, "stepsPerFrame": 2}}
    if wetting:
        scene["wetting"] = {}
    return scene


def one_drop(y=0.5, gravity=-9.81):
    """A single water particle at (0, y, 0), alone: no neighbour, no collider, nothing but gravity."""
    return {"solver": {"dt": 0.01, "substeps": 1, "gravity": [0, gravity, 0],
                       "domain": {"min": [-1, -5, -1], "max": [1, 2, 1]}},
            "emitters": [{"type": "block", "min": [-0.01, y - 0.01, -0.01], "max": [0.01, y + 0.01, 0.01]}]}


@pytest.fixture(autouse=True)
def two_threads():
    soak.set_threads(2)


@pytest.fixture
def soak_binary():
    """The command-line program of the same build (ctest sets SOAK_BINARY)."""
    path = os.environ.get("SOAK_BINARY")
    if not path or not os.path.exists(path):
        pytest.skip("SOAK_BINARY is not set to the soak program")
    return path

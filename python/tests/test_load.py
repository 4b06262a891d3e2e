"""Loading: a file and the same scene as a dict give the same state; overrides; errors as soak.Error."""
import json

import pytest

import soak
from conftest import SCENES, cloth_scene


def test_dict_equals_file():
    path = SCENES / "fig4_absorption.json"
    from_file = soak.load(path)  # a pathlib.Path as well as a str
    from_dict = soak.load_dict(json.loads(path.read_text()), base_dir=SCENES)
    assert from_file.state_hash() == from_dict.state_hash()
    from_file.step(3)
    from_dict.step(3)
    assert from_file.step_count == from_dict.step_count == 3
    assert from_file.state_hash() == from_dict.state_hash()
    assert from_file.name == from_dict.name == "fig4_absorption"


def test_overrides_apply_as_soak_run_set():
    sim = soak.load(str(SCENES / "fig4_absorption.json"), ["solver.dt=0.005", "output.frames=7"])
    assert sim.dt == pytest.approx(0.005)
    assert sim.frames == 7
    d = soak.load_dict(cloth_scene(), overrides=["cloth.0.mesh.resolution=[5, 6]"])
    assert d.num_cloth == 30 == d.num_particles


def test_scalars_of_a_loaded_scene():
    sim = soak.load_dict(cloth_scene(resolution=10))
    assert (sim.time, sim.step_count, sim.num_cloth, sim.steps_per_frame) == (0.0, 0, 100, 2)
    assert sim.collider_names == []
    assert sim.check() == ""
    sim.step()
    assert sim.time == pytest.approx(0.01)


def test_bad_value_names_the_key_and_what_was_expected():
    scene = cloth_scene()
    scene["solver"]["dt"] = -1
    with pytest.raises(soak.Error) as e:
        soak.load_dict(scene)
    assert "<dict>" in str(e.value) and "solver.dt" in str(e.value)


def test_missing_file_names_it():
    with pytest.raises(soak.Error, match="no_such_scene.json"):
        soak.load("no_such_scene.json")


def test_unknown_key_is_refused():
    scene = cloth_scene()
    scene["solver"]["dtt"] = 0.01
    with pytest.raises(soak.Error, match="dtt"):
        soak.load_dict(scene)


def test_error_is_an_exception_class_of_the_module():
    assert issubclass(soak.Error, Exception)
    assert issubclass(soak.DivergedError, soak.Error)

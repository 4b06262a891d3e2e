"""Simulation.run writes what `soak run` writes, calls its progress callback, and stops on divergence."""
import json
import subprocess

import pytest

import soak
from conftest import SCENES, cloth_scene

FIG4 = SCENES / "fig4_absorption.json"


def without_timings(line):
    return {k: v for k, v in json.loads(line).items() if k not in ("ms", "msParts", "msPerStep")}


def test_frames_are_those_of_soak_run(tmp_path, soak_binary):
    cli, module = tmp_path / "cli", tmp_path / "module"
    subprocess.run([soak_binary, "run", str(FIG4), "-o", str(cli), "--frames", "3", "--threads", "2", "--quiet"],
                   check=True)
    calls = []
    last = soak.load(str(FIG4)).run(module, frames=3, progress=lambda f, n: calls.append((f, n)))
    assert calls == [(0, 3), (1, 3), (2, 3), (3, 3)]
    assert last["frame"] == 3
    for frame in range(4):
        for name in (f"cloth_{frame:04d}.obj", f"cloth_{frame:04d}.ply", f"water_{frame:04d}.ply"):
            assert (module / name).read_bytes() == (cli / name).read_bytes(), name
    assert (module / "scene.json").read_text() == (cli / "scene.json").read_text()
    a = (cli / "stats.jsonl").read_text().splitlines()
    b = (module / "stats.jsonl").read_text().splitlines()
    assert len(a) == len(b) == 4
    assert [without_timings(x) for x in a] == [without_timings(x) for x in b]


def test_write_frame_returns_the_stats_line(tmp_path):
    sim = soak.load_dict(cloth_scene())
    sim.step(3)
    line = sim.write_frame(tmp_path, 7)
    assert line["frame"] == 7 and line["steps"] == 3
    assert (tmp_path / "cloth_0007.obj").exists() and (tmp_path / "water_0007.ply").exists()
    assert sim.write_frame(tmp_path, 8)["steps"] == 0  # no step since the last frame


def test_a_full_directory_needs_overwrite(tmp_path):
    (tmp_path / "notes.txt").write_text("mine")
    sim = soak.load_dict(cloth_scene())
    with pytest.raises(soak.Error, match="not empty"):
        sim.run(tmp_path, frames=1)
    sim.run(tmp_path, frames=1, overwrite=True)
    assert (tmp_path / "notes.txt").read_text() == "mine"
    assert len((tmp_path / "stats.jsonl").read_text().splitlines()) == 2


def test_frames_default_to_the_scene_and_progress_can_stop(tmp_path):
    sim = soak.load_dict(cloth_scene())  # output.frames = 4, 2 steps a frame
    sim.run(tmp_path / "all")
    assert sim.step_count == 8
    sim = soak.load_dict(cloth_scene())
    sim.run(tmp_path / "stopped", progress=lambda frame, frames: frame < 2)
    assert sim.step_count == 4
    assert not (tmp_path / "stopped" / "cloth_0003.obj").exists()


def test_an_exception_in_progress_stops_the_run(tmp_path):
    def fail(frame, frames):
        if frame == 1:
            raise KeyError("stop here")

    sim = soak.load_dict(cloth_scene())
    with pytest.raises(KeyError, match="stop here"):
        sim.run(tmp_path, progress=fail)
    assert sim.step_count == 2


def test_divergence_raises_after_writing_the_frame(tmp_path):
    sim = soak.load_dict(cloth_scene(pin_corners=False), overrides=["solver.maxSpeed=0.05"])
    with pytest.raises(soak.DivergedError, match="frame 1"):
        sim.run(tmp_path, frames=4)
    lines = (tmp_path / "stats.jsonl").read_text().splitlines()
    assert len(lines) == 2 and "error" in json.loads(lines[1])
    assert (tmp_path / "cloth_0001.obj").exists()

"""Behaviour through the module: free fall, the water ledger, pinned particles and colliders moved by
a script between steps."""
import numpy as np
import pytest

import soak
from conftest import SCENES, cloth_scene, one_drop


def test_a_lone_drop_falls_as_symplectic_euler_says():
    sim = soak.load_dict(one_drop(y=0.5))
    sim.step()  # the block is emitted by the first step, at rest, and falls in it
    assert sim.num_particles == 1
    g, h = -9.81, 0.01
    for n in range(1, 31):
        if n > 1:
            sim.step()
        # v_n = n h g, y_n = y_0 + h^2 g n (n + 1) / 2 (velocity first, then position), to the
        # float32 rounding of 30 steps
        assert sim.velocities[0, 1] == pytest.approx(n * h * g, rel=1e-5)
        assert sim.positions[0, 1] == pytest.approx(0.5 + h * h * g * n * (n + 1) / 2, abs=1e-5)
    np.testing.assert_allclose(sim.positions[0, [0, 2]], [0, 0], atol=1e-7)


def test_the_ledger_closes_while_the_cloth_soaks():
    sim = soak.load(str(SCENES / "fig4_absorption.json"))
    sim.step(20)
    w = sim.water_mass()
    assert w["heldInCloth"] > 0.01 * w["emitted"]  # the slab has taken water in
    assert w["total"] == pytest.approx(w["emitted"], rel=1e-5)
    free = sim.masses[sim.phases == 0].sum(dtype=np.float64)
    held = sim.cloth_water.sum()
    assert free + held + sim.cloth_buffer.sum() + float(sim.ledger["removedAtBounds"]) == pytest.approx(
        float(sim.ledger["emitted"]), rel=1e-5)


def test_a_pinned_particle_stays_where_the_script_puts_it():
    sim = soak.load_dict(cloth_scene(resolution=12))
    pinned = np.flatnonzero(sim.pinned)
    corner = pinned[0]
    target = sim.positions[corner] + np.array([0.0, 0.15, 0.05], dtype=np.float32)
    sim.move_pinned([corner], [target])
    for _ in range(15):
        sim.step()
        np.testing.assert_array_equal(sim.positions[corner], target)
        assert (sim.velocities[corner] == 0).all()
    # the other corners did not move, and the cloth followed the lifted one: its nearest particle
    # is now higher than the one nearest an unmoved corner
    rest = soak.load_dict(cloth_scene(resolution=12)).positions
    np.testing.assert_array_equal(sim.positions[pinned[1:]], rest[pinned[1:]])
    x = sim.positions
    nearest = lambda i: np.argsort(np.linalg.norm(rest - rest[i], axis=1))[1]
    assert x[nearest(corner), 1] > x[nearest(pinned[1]), 1] + 0.05


def test_writing_a_pinned_position_through_the_view_moves_it_too():
    sim = soak.load_dict(cloth_scene())
    corner = np.flatnonzero(sim.pinned)[0]
    sim.positions[corner] += np.float32(0.1)
    target = sim.positions[corner].copy()
    sim.step(3)
    np.testing.assert_array_equal(sim.positions[corner], target)


def test_only_pinned_particles_are_moved():
    sim = soak.load_dict(cloth_scene())
    free = np.flatnonzero(sim.pinned == 0)[0]
    with pytest.raises(soak.Error, match="not a pinned"):
        sim.move_pinned([free], [[0, 0, 0]])
    with pytest.raises(soak.Error):
        sim.move_pinned([0, 1], [[0, 0, 0]])  # two indices, one position


def floor_and_drop():
    scene = one_drop(y=0.05)
    scene["colliders"] = [{"name": "floor", "type": "box", "halfExtents": [0.5, 0.05, 0.5], "position": [0, -0.05, 0]}]
    return scene


def test_a_collider_moved_by_the_script_pushes_the_particle():
    sim = soak.load_dict(floor_and_drop())
    sim.step(40)  # the drop lands and rests on the box's top face (y = 0) at its contact margin
    resting = sim.positions[0, 1]
    assert 0.0 < resting < 0.02
    t, q = sim.collider_pose("floor")
    np.testing.assert_allclose(t, [0, -0.05, 0])
    np.testing.assert_allclose(q, [1, 0, 0, 0])
    lift = 0.2
    for k in range(1, 21):  # 0.2 m up in 20 steps: 1 m/s
        sim.set_collider_pose("floor", [0, -0.05 + lift * k / 20, 0])
        sim.step()
        np.testing.assert_allclose(sim.collider_pose(0)[0], [0, -0.05 + lift * k / 20, 0], atol=1e-6)
    assert sim.positions[0, 1] == pytest.approx(resting + lift, abs=0.01)
    assert sim.velocities[0, 1] == pytest.approx(1.0, abs=0.2)  # carried at the box's speed
    sim.step(5)  # the box stays where it was put
    np.testing.assert_allclose(sim.collider_pose("floor")[0], [0, 0.15, 0], atol=1e-6)


def test_a_rotation_is_kept_and_colliders_are_named():
    sim = soak.load_dict(floor_and_drop())
    half = np.sqrt(0.5)
    sim.set_collider_pose(0, [0, -0.05, 0], [half, 0, half, 0])  # 90 degrees about y
    sim.step()
    np.testing.assert_allclose(sim.collider_pose(0)[1], [half, 0, half, 0], atol=1e-6)
    sim.set_collider_pose(0, [0, 0, 0])  # no rotation given: the current one stays
    sim.step()
    np.testing.assert_allclose(sim.collider_pose(0)[1], [half, 0, half, 0], atol=1e-6)
    with pytest.raises(soak.Error, match="floor"):
        sim.collider_pose("ceiling")
    with pytest.raises(soak.Error):
        sim.collider_pose(3)

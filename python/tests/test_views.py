"""The state's arrays are numpy views of the engine's memory: no copy, writes seen both ways, the
simulation kept alive by its views, read-only where a write would break the engine's bookkeeping."""
import gc
import warnings

import numpy as np
import pytest

import soak
from conftest import SCENES, cloth_scene, one_drop


def test_shapes_and_types():
    sim = soak.load_dict(cloth_scene(resolution=8, wetting=True))
    n = sim.num_particles
    assert sim.positions.shape == (n, 3) and sim.positions.dtype == np.float32
    assert sim.velocities.shape == (n, 3) and sim.predicted_positions.shape == (n, 3)
    for a in (sim.masses, sim.inv_masses, sim.radii):
        assert a.shape == (n,) and a.dtype == np.float32
    assert sim.phases.dtype == np.int32 and sim.ids.dtype == np.uint32
    assert sim.saturation.shape == (sim.num_cloth,) and sim.saturation.dtype == np.float32
    assert sim.cloth_water.shape == (sim.num_cloth,) and sim.cloth_water.dtype == np.float64
    assert sim.cloth_buffer.shape == (sim.num_cloth,)
    assert sim.pinned.sum() == 4
    assert sim.triangles.shape == (2 * 7 * 7, 3) and sim.triangles.max() == sim.num_cloth - 1
    assert (sim.inv_masses[sim.pinned == 1] == 0).all()


def test_no_copy_two_views_share_memory():
    sim = soak.load_dict(cloth_scene())
    a, b = sim.positions, sim.positions
    assert np.shares_memory(a, b)
    assert a.base is sim or a.base is not None


def test_a_numpy_write_moves_the_particle():
    sim = soak.load_dict(one_drop())
    sim.step()  # the drop is emitted
    sim.velocities[0] = [1.0, 0.0, 0.0]
    assert sim.velocities[0, 0] == 1.0  # a fresh view sees the write
    x0 = sim.positions[0].copy()
    sim.step()
    # one step of 0.01 s at 1 m/s sideways (nothing else acts sideways on a lone drop)
    assert sim.positions[0, 0] - x0[0] == pytest.approx(0.01, rel=1e-5)
    assert sim.positions[0, 2] == x0[2]


def test_a_view_sees_the_engine_write_while_nothing_is_added():
    sim = soak.load_dict(cloth_scene(pin_corners=False))  # cloth only: no particle is added or removed
    y = sim.positions[:, 1]
    before = y.copy()
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # the view is not stale
        sim.step(2)
    assert (y < before).all()  # the same view, the engine's new positions
    np.testing.assert_array_equal(y, sim.positions[:, 1])


def test_a_view_older_than_a_step_that_added_water_is_reported_stale():
    scene = cloth_scene()
    scene["emitters"] = [{"type": "block", "min": [-0.05, 0.6, -0.05], "max": [0.05, 0.7, 0.05], "start": 0.025}]
    sim = soak.load_dict(scene)
    x = sim.positions
    grown_at = None
    for k in range(1, 6):
        n = sim.num_particles
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            sim.step()
        stale = [w for w in caught if issubclass(w.category, RuntimeWarning) and "stale" in str(w.message)]
        if sim.num_particles > n:
            grown_at = k
        assert len(stale) == (1 if grown_at == k else 0), k  # once, when the block arrived
    assert grown_at is not None and x.shape[0] == sim.num_cloth
    assert sim.positions.shape == (sim.num_particles, 3)  # a new view has the water


def test_views_keep_the_simulation_alive():
    sim = soak.load_dict(cloth_scene())
    x = sim.positions
    expected = x.copy()
    del sim
    gc.collect()
    np.testing.assert_array_equal(x, expected)


def test_bookkeeping_arrays_are_read_only():
    sim = soak.load_dict(cloth_scene(wetting=True))
    for a in (sim.masses, sim.inv_masses, sim.radii, sim.phases, sim.ids, sim.saturation, sim.cloth_water,
              sim.pinned, sim.triangles, sim.ledger):
        with pytest.raises(ValueError):
            a[...] = 0


def test_ledger_view_and_water_mass():
    sim = soak.load(str(SCENES / "fig4_absorption.json"))
    ledger = sim.ledger
    assert ledger.shape == () and "heldInCloth" in ledger.dtype.names
    assert float(ledger["emitted"]) == 0.0  # blocks are emitted by the first step
    sim.step(2)
    w = sim.water_mass()
    assert float(ledger["emitted"]) == pytest.approx(w["emitted"]) and w["emitted"] > 0
    assert float(ledger["heldInCloth"]) == pytest.approx(w["heldInCloth"], rel=1e-6)

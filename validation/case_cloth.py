"""Validation case: a 1 m sheet pinned at two corners, at the shipped scenes' cloth settings
(validation/hanging_cloth.json). Targets of issue 22 point 4: at rest the largest edge strain <= 3% and
its 99th percentile <= 1%; <= 5% under a heavy water load; <= 10% with the tethers off, at Fig. 5's 24
small steps and at Fig. 1's and 6's 16; the energy never
rises at rest; and the hanging shape against a converged reference (the same scene at 64 small steps
of 4 iterations a substep, no tethers). The energy is kinetic plus potential: it leaves out
the residual stretch's elastic energy, which the sheet, released from its unstretched shape, trades
with its motion as any spring released at its rest length does (down to twice the static stretch and
back: the sum rises by the weight times that stretch). Counted as springs of the solve's stiffness
(measure()), the stretch takes most of the rise out of the sum; once the release's swing has died
down (1 s) the sum alone no longer rises. At Fig. 1's and 6's 16 small steps (0.47 ms) the swing is
larger: the sum rises once by 1.5e-3 J/kg, at 0.09 s (2.4e-4 with the stretch's energy; the same at
Fig. 6's size, a 2.4 m sheet of 2 cm edges: 1.6e-3 and 8.1e-4), and by at most 4.3e-6 from 1 s on;
at 24 small steps the 2.4 m sheet's rise is 1.3e-4 (4.8e-5 with the stretch's energy). The coarse levels (solver.clothHierarchy, on by default)
carry the pins' load across the sheet in each small step, which holds it near its length without the
tethers and leaves almost no residual stretch to swing on; the passes near the pins (solver.clothPinPasses)
hold the few edges that carry that load into each pin. The same sheet with solver.clothGlobalStretch (a global step
over the edges in each small step, off in the shipped scenes) at 4 small steps and no tethers is held
to the rest targets and its energy to the never-rises one. The flat sheet has nothing to break its
symmetry and stays in its plane, where the bending plays no part; the scenes' sheets fold below the sag
of their top edge (Fig. 1, 5, 6), so the same sheet started 2.9 degrees out of its plane (it swings in
and folds) is held to the rest targets too over the last 0.3 s of 6 s, at the shipped small steps and
at twice as many: its strain is steady from 3 s on while its folds still sway (0.15-0.3 m/s). run(work, save) -> (rows, plot)."""
import json
import os

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import numpy as np

import soakrun

HERE = os.path.dirname(os.path.abspath(__file__))
SCENE = os.path.join(HERE, "hanging_cloth.json")
G = 9.81
FRAMES = 100          # 3 s at 0.03 s a frame: the sheet has stopped swinging
REST_FRAMES = 10      # "at rest": the last 10 frames (0.3 s)
REST_FROM = 1.0       # s: the release's swing has died down to the 1e-4 J/kg scale (docs/models.md, Eq. 8)
NO_TETHERS = "cloth.0.material.tetherSlack=1000"  # a tether 1000 times its rest path never holds
# solver.clothGlobalStretch (off in the shipped scenes): a global step over the edges in each of 4 small steps
GLOBAL = ["solver.clothGlobalStretch=true", "solver.clothSubsteps=4"]
# the folded runs: the top of the sheet 5 cm out of the plane of its pins' vertical (axisV (0, 1, TILT))
TILT = 0.05
TILT_DEGREES = float(np.degrees(np.arctan(TILT)))
# the water load: every cloth particle holds water at S = 0.35 (Eq. 10 with c = 2e-4 m^3/kg), kept still
# (no absorption, diffusion, emission or sticking): 60 kg on the 66 kg sheet. A load spread evenly scales
# every mass alike, which PBD's projections and gravity do not see: this row checks that wet mass leaves
# the strain as dry; a concentrated load (water lying in a fold) is not measured here
WET = {"c": 0.0002, "saturation": {"initial": 0.35, "sticky": 0.12, "emit": 0.35, "max": 0.4},
       "absorption": {"enabled": False}, "diffusion": {"enabled": False}, "emission": {"enabled": False},
       "sticking": {"enabled": False}}


def edges_of(obj_path):
    """the unique edges (i, j), i < j, of the triangles of an OBJ file, 0-based"""
    tris = []
    with open(obj_path) as f:
        for line in f:
            if line.startswith("f "):
                tris.append([int(w.split("/")[0]) - 1 for w in line.split()[1:4]])
    t = np.array(tris)
    e = np.concatenate([t[:, [0, 1]], t[:, [1, 2]], t[:, [2, 0]]])
    return np.unique(np.sort(e, axis=1), axis=0)


def positions(v):
    return np.stack([v["x"], v["y"], v["z"]], axis=1).astype(np.float64)


def cloth_frames(out):
    """(stats line, cloth vertices) of every frame"""
    st = soakrun.stats(out)
    for f in soakrun.frames(out, "cloth"):
        yield st[f], soakrun.read_vertices(os.path.join(out, f"cloth_{f:04d}.ply"))


def small_step():
    """s: the cloth's small step in validation/hanging_cloth.json (dt / substeps / clothSubsteps)"""
    with open(SCENE) as f:
        solver = json.load(f)["solver"]
    return solver["dt"] / solver["substeps"] / solver["clothSubsteps"]


def measure(out):
    """per frame: time, edge strain (max, p99), energy per unit mass (kinetic + potential, J/kg), the
    residual stretch's energy per unit mass counted as springs of the solve's stiffness (J/kg), and the
    first and last frame's positions. Rest lengths are frame 0's (the rest shape). The stiffness: one
    projection a small step h_s holds a force F on an edge whose ends weigh m_a, m_b with a violation
    F h_s^2 (1/m_a + 1/m_b), so k = 1 / ((1/m_a + 1/m_b) h_s^2) (equal masses, pins weightless)."""
    edges = None
    hs = small_step()
    t, smax, s99, energy, stretch, x, x0 = [], [], [], [], [], None, None
    for s, v in cloth_frames(out):
        x = positions(v)
        if edges is None:
            edges = edges_of(os.path.join(out, "cloth_0000.obj"))
            rest = np.linalg.norm(x[edges[:, 0]] - x[edges[:, 1]], axis=1)
            x0 = x
        strain = np.linalg.norm(x[edges[:, 0]] - x[edges[:, 1]], axis=1) / rest - 1.0
        free = v["pinned"] == 0
        vel2 = v["vx"] ** 2 + v["vy"] ** 2 + v["vz"] ** 2
        t.append(s["time"])
        smax.append(float(strain.max()))
        s99.append(float(np.percentile(strain, 99)))
        energy.append(float(np.mean(0.5 * vel2[free] + G * x[free, 1])))  # equal masses: per kg
        ends = free[edges[:, 0]].astype(float) + free[edges[:, 1]]  # m (1/m_a + 1/m_b), per unit mass m
        held = ends > 0  # an edge between two pins holds nothing
        stretch.append(float(np.sum(0.5 * (strain[held] * rest[held]) ** 2 / (ends[held] * hs * hs)))
                       / np.count_nonzero(free))
    return {"t": np.array(t), "max": np.array(smax), "p99": np.array(s99), "energy": np.array(energy),
            "stretch": np.array(stretch), "x": x, "x0": x0}


def at_rest(m):
    """the largest max and p99 strain over the last REST_FRAMES frames"""
    return float(m["max"][-REST_FRAMES:].max()), float(m["p99"][-REST_FRAMES:].max())


def scene_variant(work, name, change):
    """validation/hanging_cloth.json with change(scene) applied, written to WORK/hanging_cloth_NAME.json"""
    with open(SCENE) as f:
        scene = json.load(f)
    change(scene)
    path = os.path.join(work, f"hanging_cloth_{name}.json")
    with open(path, "w") as f:
        json.dump(scene, f, indent=1)
    return path


def wet_scene(work):
    return scene_variant(work, "wet", lambda scene: scene.update(wetting=WET))


def folded_scene(work):
    """the sheet started TILT out of its vertical plane: it swings into the plane and folds below the sag
    of its top edge, as the scenes' sheets do (the planar sheet has nothing to break its symmetry and
    stays flat, where bending plays no part)"""
    return scene_variant(work, "folded", lambda scene: scene["cloth"][0]["mesh"].update(axisV=[0, 1, TILT]))


def strain_rows(name, m, target_max, target_p99=None, when="at rest"):
    smax, s99 = at_rest(m)
    rows = [(f"hanging cloth, {name}: max edge strain {when}", f"<= {100 * target_max:g}%",
             f"{100 * smax:+.2f}%", smax <= target_max)]
    if target_p99 is not None:
        rows.append((f"hanging cloth, {name}: p99 edge strain {when}", f"<= {100 * target_p99:g}%",
                     f"{100 * s99:+.2f}%", s99 <= target_p99))
    return rows


def run(work, save):
    os.makedirs(work, exist_ok=True)
    go = lambda name, scene=SCENE, sets=(): measure(soakrun.run(scene, os.path.join(work, f"cloth_{name}"), sets,
                                                                frames=FRAMES))
    runs = {"rest": go("rest"), "water load": go("wet", wet_scene(work)), "tethers off": go("no_tethers", sets=[NO_TETHERS]),
            "1 substep": go("substep1", sets=["solver.substeps=1", "solver.clothSubsteps=48"]),
            "reference": go("reference", sets=["solver.clothSubsteps=64", "solver.clothIterations=4", NO_TETHERS]),
            "tethers off, 16 small steps": go("no_tethers_16", sets=[NO_TETHERS, "solver.clothSubsteps=16"]),
            "global step, tethers off": go("global", sets=GLOBAL + [NO_TETHERS])}
    folded = folded_scene(work)
    for name, sets in (("folded", ()), ("folded, 48 small steps", ("solver.clothSubsteps=48",))):
        runs[name] = measure(soakrun.run(folded, os.path.join(work, "cloth_" + name.replace(", ", "_").replace(" ", "_")),
                                         sets, frames=2 * FRAMES))
    with open(os.path.join(work, "cloth_wet", "stats.jsonl")) as f:
        held = json.loads(f.readline())["waterMass"]["heldInCloth"]
    rows = strain_rows("default settings", runs["rest"], 0.03, 0.01)
    rows += strain_rows(f"{held:.0f} kg of water held", runs["water load"], 0.05)
    rows += strain_rows("tethers off", runs["tethers off"], 0.10)
    rows += strain_rows("tethers off, 16 small steps (Fig. 1's and 6's)", runs["tethers off, 16 small steps"], 0.10)
    rows += strain_rows("1 substep of 48 small steps (the same 0.31 ms small steps)", runs["1 substep"], 0.03, 0.01)
    last = "over 5.7-6 s"
    rows += strain_rows(f"folded (started {TILT_DEGREES:.1f} degrees out of its plane)", runs["folded"], 0.03, 0.01, last)
    rows += strain_rows("folded, 48 small steps (twice the shipped)", runs["folded, 48 small steps"], 0.03, 0.01, last)
    g = runs["global step, tethers off"]
    rows += strain_rows("solver.clothGlobalStretch at 4 small steps, tethers off", g, 0.03, 0.01)
    g_rise = float(np.max(np.diff(g["energy"])))
    rows.append(("hanging cloth, solver.clothGlobalStretch at 4 small steps, tethers off: energy from frame to frame",
                 "never rises (by more than 1e-4 J/kg)", f"largest change {g_rise:+.2g} J/kg", g_rise <= 1e-4))
    e, t = runs["rest"]["energy"], runs["rest"]["t"]
    rise = float(np.max(np.diff(e))) if len(e) > 1 else 0.0
    with_stretch = float(np.max(np.diff(e + runs["rest"]["stretch"]))) if len(e) > 1 else 0.0
    rows.append(("hanging cloth: energy from frame to frame", "never rises (by more than 1e-4 J/kg)",
                 f"largest change {rise:+.2g} J/kg (of a {e[0] - e[-1]:.3g} J/kg drop; with the stretch's "
                 f"energy {with_stretch:+.2g})", rise <= 1e-4))
    later = t[1:] >= REST_FROM
    rest_rise = float(np.max(np.diff(e)[later])) if later.any() else 0.0
    rows.append((f"hanging cloth: energy from frame to frame from {REST_FROM:g} s on (at rest)",
                 "never rises (by more than 1e-4 J/kg)", f"largest change {rest_rise:+.2g} J/kg", rest_rise <= 1e-4))
    gap = np.linalg.norm(runs["rest"]["x"] - runs["reference"]["x"], axis=1)
    rows.append(("hanging cloth: shape against the converged reference (64 small steps of 4 iterations, no tethers)",
                 "every particle within 2 cm", f"max {100 * gap.max():.2f} cm, mean {100 * gap.mean():.2f} cm",
                 gap.max() <= 0.02))
    return rows, plot(runs, save)


def plot(runs, save):
    fig, ax = plt.subplots(1, 3, figsize=(15, 4.2))
    for name, m in runs.items():
        ax[0].semilogy(m["t"], np.maximum(m["max"], 1e-5), label=f"{name} (max)")
    ax[0].axhline(0.03, color="k", ls="--", lw=0.8, label="targets 3%, 10%")
    ax[0].axhline(0.10, color="k", ls="--", lw=0.8)
    ax[0].set(xlabel="t (s)", ylabel="largest edge strain", title="Edge strain of a two-corner-pinned sheet")
    ax[0].legend(fontsize=7)
    e = runs["rest"]["energy"]
    ax[1].plot(runs["rest"]["t"], e - e[0])
    ax[1].set(xlabel="t (s)", ylabel="E - E(0) (J/kg)", title="Energy at default settings (never rises)")
    for name in ("rest", "1 substep", "reference", "global step, tethers off"):
        x, x0 = runs[name]["x"], runs[name]["x0"]
        mid = np.abs(x0[:, 0]) < 0.006
        order = np.argsort(x0[mid, 1])
        ax[2].plot(x0[mid, 1][order], 1000 * (x0[mid, 1] - x[mid, 1])[order], label=name)
    ax[2].set(xlabel="rest height (m)", ylabel="drop below rest (mm)", title="Middle column at rest: the stretch")
    ax[2].legend()
    return save(fig, "hanging_cloth.png")

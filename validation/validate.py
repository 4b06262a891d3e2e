#!/usr/bin/python3
"""soak's validation suite: runs the scenes of validation/ (and one paper scene) with build/soak,
compares them with experiments and closed forms, and writes docs/validation.md with its plots in
docs/validation/. Each case states its target and the measured error.

usage: validation/validate.py [--out DIR] [--only NAME ...]     (about 20 minutes on 2 cores)
"""
import argparse
import datetime
import inspect
import os
import subprocess
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt
import case_bend
import case_cloth
import case_wicking
import numpy as np
import soakrun

HERE = os.path.dirname(os.path.abspath(__file__))
DOCS = os.path.join(soakrun.ROOT, "docs")
G = 9.81
# Martin & Moyce 1952, square column (n^2 = 1): surge front Z = z/a at T = t sqrt(g/a)
MARTIN_MOYCE = np.loadtxt(os.path.join(HERE, "martin_moyce_1952.csv"), delimiter=",")


def water_frames(out):
    """(stats line, water vertices) of every frame that has water"""
    st = soakrun.stats(out)
    for f in soakrun.frames(out):
        w = soakrun.read_vertices(os.path.join(out, f"water_{f:04d}.ply"))
        if len(w):
            yield st[f], w


def kinetic(w):
    return 0.5 * float(np.sum(w["mass"] * (w["vx"] ** 2 + w["vy"] ** 2 + w["vz"] ** 2)))


def surge_front(out, a=0.3, x0=-0.9):
    """(T, Z) of a dam-break run: T = t sqrt(g/a), Z the farthest particle's distance from the back wall x0 over a"""
    T, Z = [], []
    for s, w in water_frames(out):
        T.append(s["time"] * np.sqrt(G / a))
        Z.append((w["x"].max() - x0) / a)
    return np.array(T), np.array(Z)


def worst_front_error(T, Z):
    """the largest relative error of the front Z(T) against Martin & Moyce over T in [0.4, 3.0], signed"""
    ref = MARTIN_MOYCE[(MARTIN_MOYCE[:, 0] >= 0.4) & (MARTIN_MOYCE[:, 0] <= 3.0)]
    err = np.interp(ref[:, 0], T, Z) / ref[:, 1] - 1.0
    return float(err[np.argmax(np.abs(err))])


def dam_break(work):
    """the surge front against Martin & Moyce at 1, 2 and 4 substeps; target: within 10% over T in [0.4, 3.0].
    Martin & Moyce scale time as T = n t sqrt(g/a) with n^2 = height / width: T = t sqrt(g/a) for the
    square column (t sqrt(2g/a) is their n^2 = 2 column's, and applied to these data shows a false 25% lag).
    The worst point is their second, T = 0.62, where the measured front is slowest (Z rises by 0.58 per
    unit T before it and 1.22 after: the gate's opening): one substep is 10.2% ahead there and within
    7.1% at every other point; the viscosity and the walls' friction hardly move it (water.viscosity
    doubled: 10.1%; water.boundaryFriction 0 / 1: the front at T = 0.6 1% ahead / 3% behind).
    What sets it is how far the density solve converges: one substep iterates to solver.fluidTolerance
    (about 11 iterations a substep), two substeps stop at the least 4. Solved to 32 iterations a substep
    (the dashed line) the front is 10.6%, 9.4% and 10.1% ahead at T = 0.62 with 1, 2 and 4 substeps and
    within 5.6-7.5% elsewhere: the converged, incompressible collapse runs ahead of the experiment at its
    gate-opening point, and 2 substeps (most shipped scenes') are closer to it (4.3%) by their softer solve.
    The solver's default, and this scene's, is 1 substep: its row is the one at default settings.
    Without the hyperviscosity (docs/models.md) 11.0%, 6.9% and 9.6% at 1, 2 and 4 substeps.
    Refined, the collapse runs further ahead, not back: at half the spacing (0.01 m, support 0.02 m, the
    particle mass / 8; 18,000 particles; the dotted line) 11.5% ahead at T = 0.62 with 1 substep, 11.3%
    solved to 32 iterations, 12.3% with 2 substeps, and 3.6-9.1% ahead at every later point. So the miss at
    T = 0.62 is the experiment's release (Martin & Moyce's column starts behind the instantly released one
    and the converged solution does not come back to it), not a solve that falls short; no model of the
    release is in the scene (the paper's release speed is not at hand). Read in time, the runs reach the
    measured Z of the first three points early by 0.06, 0.12 and 0.09 in T (1 substep; half the spacing
    0.10, 0.15, 0.10), as a release taking about 0.1 sqrt(a/g) longer than an instant one would (17 ms
    for this 0.3 m column). Later the 1-substep front comes back to the measured one (3.8% and 2.1% ahead
    at T = 0.97 and 1.14, within 1.3% from 1.29 on), and the half-spacing front's lead grows with the
    distance run (a faster front, not an earlier one).
    The suite's tests/sim/dam_break_test.cpp runs the three substep counts (0.6 s each) and holds their
    fronts within 10.5% of the measured one (8% from T = 0.8 on) and within 6.5% of each other."""
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(MARTIN_MOYCE[:, 0], MARTIN_MOYCE[:, 1], "ko", label="Martin & Moyce 1952")
    rows = []
    for substeps in (1, 2, 4):
        out = soakrun.run(os.path.join(HERE, "dam_break.json"), os.path.join(work, f"dam_break_{substeps}"),
                          [f"solver.substeps={substeps}"])
        T, Z = surge_front(out)
        worst = worst_front_error(T, Z)
        ax.plot(T, Z, label=f"soak, {substeps} substep{'s' if substeps > 1 else ''} (worst {100 * worst:+.1f}%)")
        rows.append((f"dam break front, {substeps} substep(s)", "within 10% for T in [0.4, 3.0]",
                     f"worst {100 * worst:+.1f}%", abs(worst) <= 0.10))
    out = soakrun.run(os.path.join(HERE, "dam_break.json"), os.path.join(work, "dam_break_converged"),
                      ["solver.fluidIterations=32"])
    T, Z = surge_front(out)
    ax.plot(T, Z, "k--", lw=1, label=f"soak, 1 substep of 32 density iterations (worst {100 * worst_front_error(T, Z):+.1f}%)")
    out = soakrun.run(os.path.join(HERE, "dam_break.json"), os.path.join(work, "dam_break_half_spacing"),
                      ["water.spacing=0.01", "water.supportRadius=0.02", "water.particleMass=0.000990375"])
    T, Z = surge_front(out)
    ax.plot(T, Z, "k:", lw=1, label=f"soak, half the spacing, 1 substep (worst {100 * worst_front_error(T, Z):+.1f}%)")
    ax.set(xlabel="T = t sqrt(g/a)", ylabel="Z = z/a", title="Dam break, square column a = 0.3 m", xlim=(0, 3.5))
    ax.legend()
    return rows, save(fig, "dam_break.png")


def rest(work):
    """a settled block: kinetic energy below 1e-3 J per 10k particles within 3 s, density within 1% of 1.
    The density solve stops at a 1% mean compression (solver.fluidTolerance); what kinetic energy it
    leaves is particle-scale noise spread through the block, which the hyperviscosity damps (without
    it 0.018 J at 3 s): docs/models.md, "Eq. 6-7 iterated to a tolerance" and "Hyperviscosity", has the
    measurements and what was tried."""
    out = soakrun.run(os.path.join(HERE, "rest_block.json"), os.path.join(work, "rest"))
    t, ke, rho, its = [], [], [], []
    for s, w in water_frames(out):
        if "fluidIterations" in s:  # not in frame 0's line
            its.append(s["fluidIterations"]["mean"])
        t.append(s["time"])
        ke.append(kinetic(w) * 1e4 / len(w))
        rho.append(s["meanDensityRatio"])
    fig, ax = plt.subplots(1, 2, figsize=(10, 4))
    ax[0].semilogy(t, ke)
    ax[0].axhline(1e-3, color="k", ls="--", label="target 1e-3 J")
    ax[0].set(xlabel="t (s)", ylabel="kinetic energy per 10k particles (J)", title="Settling block")
    ax[0].legend()
    ax[1].plot(t, rho)
    ax[1].axhspan(0.99, 1.01, color="0.9", label="target: within 1%")
    ax[1].set(xlabel="t (s)", ylabel="mean density ratio", title="Compression")
    ax[1].legend()
    at3 = ke[int(np.searchsorted(t, 3.0 - 1e-6))]
    return [("rest: kinetic energy at 3 s", "< 1e-3 J per 10k particles", f"{at3:.3g} J", at3 < 1e-3),
            ("rest: mean density ratio", "within 1% of 1",
             f"{rho[-1]:.4f} ({np.mean(its[len(its) // 2:]):.1f} PBF iterations a substep)",
             abs(rho[-1] - 1) <= 0.01)], \
        save(fig, "rest.png")


def leaks(work):
    """a 0.2 m deep pool (4,000 particles) dropped into the container at 1 substep of 0.015 s and of
    0.03 s: no water may leave it (none splashes over its 0.7 m walls)"""
    rows = []
    for dt in (0.015, 0.03):
        out = soakrun.run(os.path.join(HERE, "rest_block.json"), os.path.join(work, f"leak_{dt}"),
                          [f"solver.dt={dt}", "solver.substeps=1", "output.stepsPerFrame=1",
                           "emitters.0.min=[-0.2, 0.1, -0.2]", "emitters.0.max=[0.2, 0.3, 0.2]"],
                          frames=int(round(1.5 / dt)))
        st = soakrun.stats(out)
        lost = st[-1]["waterMass"]["removedAtBounds"]
        back = sum(s.get("colliderPutBack", 0) for s in st)
        through = wall_crossings(out, half=0.2, rim=0.7)
        rows.append((f"leaks: dropped pool, dt {dt} s, 1 substep, 1.5 s",
                     "no particle passes a wall or the floor (one step a frame)",
                     f"{through} crossings; {lost:.4g} kg left the domain (over the rim); {back} put-backs", through == 0))
    return rows, None


def wall_crossings(out, half, rim):
    """particles that were in the cavity (|x|, |z| <= half, 0 <= y < rim) in one frame and outside its
    footprint or under its floor in the next while below the rim: through a wall, not over it"""
    inside_before, crossings = set(), 0
    for _, w in water_frames(out):
        cavity = (np.abs(w["x"]) <= half) & (np.abs(w["z"]) <= half) & (w["y"] >= 0) & (w["y"] < rim)
        escaped = ~cavity & (w["y"] < rim)
        crossings += int(np.count_nonzero(np.isin(w["id"][escaped], list(inside_before))))
        inside_before = set(w["id"][cavity].tolist())
    return crossings


def free_fall(work):
    """a block's centre against y0 - g t^2 / 2 (symplectic Euler: y0 - g t (t + h) / 2)"""
    out = soakrun.run(os.path.join(HERE, "free_fall.json"), os.path.join(work, "free_fall"))
    t, y = [], []
    for s, w in water_frames(out):
        t.append(s["time"])
        y.append(float(np.mean(w["y"])))
    t, y = np.array(t), np.array(y)
    y0, h = 1.05, 0.015
    drop = y0 - y
    err = float(np.max(np.abs(drop - G * t * (t + h) / 2) / (G * t * t / 2)))
    fig, ax = plt.subplots(figsize=(6, 4))
    ax.plot(t, y, "o", ms=3, label="soak, block centre")
    ax.plot(t, y0 - G * t * t / 2, "k-", label="y0 - g t^2 / 2")
    ax.set(xlabel="t (s)", ylabel="y (m)", title="Free fall")
    ax.legend()
    return [("free fall: drop against the integrator's closed form", "within 0.1%", f"{100 * err:.3f}%",
             err <= 1e-3)], save(fig, "free_fall.png")


def budget(work):
    """the water ledger of a wetting scene: emitted = free + held + buffers + removed + taken"""
    out = soakrun.run(os.path.join(soakrun.ROOT, "scenes", "fig1_jet.json"), os.path.join(work, "budget"), frames=40)
    w = soakrun.stats(out)[-1]["waterMass"]
    gap = abs(w["total"] - w["emitted"]) / w["emitted"]
    return [("water budget, Fig. 1 jet, 40 frames", "closes within 1e-6 of the emitted mass",
             f"{gap:.2g} of {w['emitted']:.3g} kg ({w['heldInCloth']:.3g} kg held)", gap <= 1e-6)], None


def save(fig, name):
    os.makedirs(os.path.join(DOCS, "validation"), exist_ok=True)
    fig.tight_layout()
    fig.savefig(os.path.join(DOCS, "validation", name), dpi=110)
    plt.close(fig)
    return f"validation/{name}"


def hanging_cloth(work):
    return case_cloth.run(work, save)


def wicking(work):
    return case_wicking.run(work, save)


def cantilever(work):
    return case_bend.run(work, save)


hanging_cloth.__doc__ = case_cloth.__doc__
wicking.__doc__ = case_wicking.run.__doc__
cantilever.__doc__ = case_bend.__doc__
CASES = {"dam_break": dam_break, "rest": rest, "leaks": leaks, "free_fall": free_fall, "budget": budget,
         "hanging_cloth": hanging_cloth, "cantilever": cantilever, "wicking": wicking}


def write_report(results):
    commit = subprocess.run(["git", "-C", soakrun.ROOT, "rev-parse", "--short", "HEAD"], capture_output=True,
                            text=True).stdout.strip()
    lines = ["# Validation", "",
             f"Written by `validation/validate.py` on {datetime.date.today()} at commit {commit} (build/soak, 2 threads).",
             "Each row: the case, its target, what soak measured, and whether it holds. Scenes in `validation/`;",
             "`./scripts/validate.sh` installs python3-matplotlib, builds soak and rewrites this page (about 15 minutes).",
             "Targets are issue 22's; a row that does not hold is listed as such, and its case's section below",
             "says what is known of why.",
             "", "| case | target | measured | holds |", "|---|---|---|---|"]
    for name, (rows, _) in results.items():
        for case, target, measured, ok in rows:
            lines.append(f"| {case} | {target} | {measured} | {'yes' if ok else '**no**'} |")
    lines.append("")
    for name, (rows, plot) in results.items():
        if plot:
            lines += [f"## {name.replace('_', ' ')}", "", inspect.cleandoc(CASES[name].__doc__), "", f"![{name}]({plot})", ""]
    with open(os.path.join(DOCS, "validation.md"), "w") as f:
        f.write("\n".join(lines))


def main():
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--out", default=os.path.join(soakrun.ROOT, "out", "validation"), help="run folders")
    ap.add_argument("--only", nargs="*", choices=sorted(CASES), help="run only these cases (the report lists them only)")
    args = ap.parse_args()
    results = {}
    for name in args.only or CASES:
        print(f"validation: {name}", flush=True)
        results[name] = CASES[name](args.out)
        for case, target, measured, ok in results[name][0]:
            print(f"  {case}: {measured} (target {target}) {'ok' if ok else 'NOT MET'}", flush=True)
    write_report(results)
    print(f"validation: wrote {os.path.join(DOCS, 'validation.md')}")


if __name__ == "__main__":
    main()

#!/usr/bin/python3
"""Prints the numbers docs/gallery.md's captions quote, measured on the runs scripts/gallery.sh left in
its work folder, so that a remade gallery's captions can be checked and updated.

usage: scripts/gallery_numbers.py [WORK] [STILL...]
  WORK: gallery.sh's work folder (default /tmp/soak-gallery); STILL: the still names gallery.sh takes
  (default: every one whose runs are there). The OBJ-body comparison is scripts/obj-body.sh's.
"""
import csv
import json
import os
import sys

import numpy as np

ROOT = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))
sys.path.insert(0, os.path.join(ROOT, "validation"))
import soakrun  # noqa: E402


class Runs:
    def __init__(self, work):
        self.work = work

    def has(self, scene):
        return os.path.exists(os.path.join(self.work, scene, "stats.jsonl"))

    def ply(self, scene, kind, frame):
        return soakrun.read_vertices(os.path.join(self.work, scene, f"{kind}_{frame:04d}.ply"))

    def stats(self, scene, frame):
        with open(os.path.join(self.work, scene, "stats.jsonl")) as f:
            for line in f:
                s = json.loads(line)
                if s["frame"] == frame:
                    return s
        raise SystemExit(f"gallery_numbers: {scene} has no frame {frame}: run scripts/gallery.sh again")

    def saturation(self, scene, frame):
        """S / S^MAX of each cloth particle (the scene's wetting.saturation.max, default 0.4)"""
        with open(os.path.join(ROOT, "scenes", scene + ".json")) as f:
            smax = json.load(f).get("wetting", {}).get("saturation", {}).get("max", 0.4)
        return self.ply(scene, "cloth", frame)["saturation"] / smax


def pool_surface(water, clear=0.1, cell=0.05):
    """the pool's level: the median over 5 cm columns of the highest water particle, away from the cloth"""
    keep = np.abs(water["z"]) > clear
    cols = {}
    for x, y, z in zip(water["x"][keep], water["y"][keep], water["z"][keep]):
        key = (int(np.floor(x / cell)), int(np.floor(z / cell)))
        cols[key] = max(cols.get(key, -np.inf), y)
    return float(np.median(list(cols.values())))


def fig1(r):
    s, rest = r.saturation("fig1_jet", 100), r.ply("fig1_jet", "cloth", 0)
    mid_y = 0.5 * (rest["y"].min() + rest["y"].max())
    mid_x, width = 0.5 * (rest["x"].min() + rest["x"].max()), rest["x"].max() - rest["x"].min()
    lower_middle = (rest["y"] < mid_y) & (np.abs(rest["x"] - mid_x) < width / 6)
    print(f"fig1: {100 * np.mean(s > 0.1):.0f}% of the cloth past 10% of S^MAX, the middle of its lower half "
          f"at a median {np.median(s[lower_middle]):.2f} S^MAX (frame 100)")


def fig3a(r):
    st = r.stats("fig3a_cube_on_cloth", 100)
    print(f"fig3a: {st['counts']['water']:,} water particles left (frame 100); "
          f"{st['waterMass']['removedAtBounds']:.1f} of {st['waterMass']['emitted']:.1f} kg left the domain")


def fig3b(r):
    m = r.stats("fig3b_cube_on_cloth_wet", 40)["waterMass"]
    print(f"fig3b: {m['heldInCloth']:.1f} kg of {m['emitted']:.1f} kg held by the cloth (frame 40)")


def fig4(r):
    for frame in (12, 28):
        s, y = r.saturation("fig4_absorption", frame), r.ply("fig4_absorption", "cloth", frame)["y"]
        upper = y > np.median(y)
        print(f"fig4: frame {frame}: upper layer median S {np.median(s[upper]):.2f} S^MAX, "
              f"lower {np.median(s[~upper]):.2f}")


def fig5(r):
    for scene in ("fig5b_dip_no_gravity", "fig5c_dip_gravity"):
        s, cloth = r.saturation(scene, 100), r.ply(scene, "cloth", 100)
        level = pool_surface(r.ply(scene, "water", 100))
        print(f"fig5: {scene}: past half of S^MAX {cloth['y'][s > 0.5].max() - level:.2f} m above the water, "
              f"past a tenth {cloth['y'][s > 0.1].max() - level:.2f} m (frame 100)")


def fig6a(r):
    print(f"fig6a: {r.stats('fig6a_drip_uniform', 60)['wetting']['dripsEmitted']} drips made by frame 60")


def fig6b(r):
    print(f"fig6b: median S {np.median(r.saturation('fig6b_drip_diagonal', 60)):.2f} S^MAX (frame 60)")


def fig9(r):
    for frame in (135, 233):
        a, b = (r.ply(s, "cloth", frame) for s in ("fig9a_ball_no_sticking", "fig9b_ball_sticking"))
        d = np.sqrt((a["x"] - b["x"]) ** 2 + (a["y"] - b["y"]) ** 2 + (a["z"] - b["z"]) ** 2)
        print(f"fig9: frame {frame}: the runs' cloth particles {1e3 * d.mean():.1f} mm apart on average, "
              f"{1e2 * np.percentile(d, 99):.1f} cm at the 99th percentile, {1e2 * d.max():.1f} cm at most")


def garment(r, scene, frame):
    st = r.stats(scene, frame)
    g, m = st["garment"], st["waterMass"]
    print(f"{scene}: frame {frame}: {st['counts']['cloth']:,} vertices, lowest point {g['lowestPoint']:.4f} m, "
          f"mean height {g['meanHeight']:.5f} m, body distance {100 * g.get('meanColliderDistance', 0):.3f} cm, "
          f"{1e3 * m['heldInCloth']:.1f} g held of {m['emitted']:.3f} kg rained, {g['dropsTakenTotal']:,} drops "
          f"taken, {g['wetVertices']:,} wet vertices, mean saturation {g['meanSaturation']:.3f}")


def chen_fig8(r):
    garment(r, "chen_fig8_silk_sphere_dry", 240)
    garment(r, "chen_fig8_silk_sphere_wet", 240)


def chen_fig9(r):
    garment(r, "chen_fig9_garment_rain_dry", 300)
    garment(r, "chen_fig9_garment_rain_wet", 300)


def garments(r):
    garment(r, "garment_dress_rain", 300)
    garment(r, "garment_skirt", 90)


def sweep(r):
    """docs/sweeps.md's table: variant, D, eta^d, held water, wet area, max strain"""
    with open(os.path.join(r.work, "sweep_fig5c_wicking", "summary.csv")) as f:
        for row in csv.DictReader(f):
            print(f"sweep: | {row['variant']} | {row['wetting.diffusion.diffusivity']} | "
                  f"{row['wetting.diffusion.gravityInfluence']} | {float(row['heldWaterKg']):.2f} | "
                  f"{float(row['wetAreaFraction']):.2f} | {float(row['maxClothStrain']):.4f} |")


STILLS = {"fig1": (fig1, "fig1_jet"), "fig3a": (fig3a, "fig3a_cube_on_cloth"),
          "fig3b": (fig3b, "fig3b_cube_on_cloth_wet"), "fig4": (fig4, "fig4_absorption"),
          "fig5": (fig5, "fig5c_dip_gravity"), "fig6a": (fig6a, "fig6a_drip_uniform"),
          "fig6b": (fig6b, "fig6b_drip_diagonal"), "fig9": (fig9, "fig9b_ball_sticking"),
          "chen_fig8": (chen_fig8, "chen_fig8_silk_sphere_wet"), "chen_fig9": (chen_fig9, "chen_fig9_garment_rain_wet"),
          "garments": (garments, "garment_skirt"), "sweep": (sweep, "sweep_fig5c_wicking/v000")}


def main():
    args = sys.argv[1:]
    if args and args[0] in ("-h", "--help"):
        print(__doc__)
        return
    work = args.pop(0) if args and args[0] not in STILLS else "/tmp/soak-gallery"
    unknown = [a for a in args if a not in STILLS]
    if unknown:
        raise SystemExit(f"gallery_numbers: no still named {' '.join(unknown)} ({' '.join(STILLS)})")
    runs = Runs(work)
    for name in args or STILLS:
        measure, scene = STILLS[name]
        if runs.has(scene):
            measure(runs)
        elif args:
            raise SystemExit(f"gallery_numbers: no run of {scene} in {work}: run scripts/gallery.sh {name}")


if __name__ == "__main__":
    main()

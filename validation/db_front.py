"""Surge front of validation/dam_break.json against Martin & Moyce 1952, square column (n^2 = 1).

Martin & Moyce scale time as T = n t sqrt(g/a), n^2 = (column height)/(column width a): for the square
column T = t sqrt(g/a). The often quoted T = t sqrt(2g/a) is the same definition for their n^2 = 2
column (the one Koshizuka & Oka 1996 and most SPH papers re-run); used on the square column's data it
stretches the simulation's time by sqrt(2) and shows a ~25% lag that is not there.
(Shallow-water check in these units: Ritter's front moves at dZ/dT = 2; the measured fronts at ~1.4.)

usage: db_front.py OUT    prints T, Z = (front x + 0.9)/a (max and 99.5th percentile), Martin & Moyce's
Z at that T, the kinetic energy and, last, the kinetic energy's maximum against m g a / 2.
"""
import os
import sys

sys.path.insert(0, os.path.dirname(os.path.abspath(__file__)))
import numpy as np
import soakrun

a, g, x0 = 0.3, 9.81, -0.9  # column width = height, back wall
n = 1.0                      # n^2 = height / width
# Martin & Moyce 1952, n^2 = 1: (T, Z)
MM = np.loadtxt(os.path.join(os.path.dirname(os.path.abspath(__file__)), "martin_moyce_1952.csv"), delimiter=",")

out = sys.argv[1]
st = soakrun.stats(out)
keMax, mass = 0.0, 0.0
print("    T  Zmax Z99.5  Z_MM       ke")
for f in soakrun.frames(out):
    w = soakrun.read_vertices(os.path.join(out, f"water_{f:04d}.ply"))
    if len(w) == 0:
        continue
    T = n * st[f]["time"] * np.sqrt(g / a)
    ke = 0.5 * np.sum(w["mass"] * (w["vx"] ** 2 + w["vy"] ** 2 + w["vz"] ** 2))
    keMax, mass = max(keMax, ke), float(np.sum(w["mass"]))
    ref = f"{np.interp(T, MM[:, 0], MM[:, 1]):5.2f}" if MM[0, 0] <= T <= MM[-1, 0] else "   - "
    print(f"{T:5.2f} {(w['x'].max() - x0) / a:5.2f} {(np.percentile(w['x'], 99.5) - x0) / a:5.2f} {ref} {ke:8.3f}")
print(f"max ke {keMax:.2f} J, m g a/2 = {mass * g * a / 2:.2f} J")

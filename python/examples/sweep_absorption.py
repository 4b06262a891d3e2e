#!/usr/bin/env python3
"""Sweeps one wetting parameter, the absorption rate kappa^a of Eq. 11 (wetting.absorption.rate), on
Fig. 4's slab between two bodies of water (scenes/fig4_absorption.json), and plots the water the
cloth holds against time, one curve per rate, to a PNG.

    PYTHONPATH=build/python /usr/bin/python3 python/examples/sweep_absorption.py -o sweep.png

--quick runs two rates for a third of a second (the test suite runs it so).
"""
import argparse
import pathlib

import matplotlib

matplotlib.use("Agg")  # files only, no display
import matplotlib.pyplot as plt

import soak

SCENE = pathlib.Path(__file__).resolve().parents[2] / "scenes" / "fig4_absorption.json"


def held_water(rate, steps):
    """Times (s) and water held by the cloth (g) after each step, at absorption rate `rate`."""
    sim = soak.load(str(SCENE), [f"wetting.absorption.rate={rate}"])
    times, held = [sim.time], [1e3 * float(sim.ledger["heldInCloth"])]
    for _ in range(steps):
        sim.step()
        times.append(sim.time)
        held.append(1e3 * float(sim.ledger["heldInCloth"]))
    return times, held


def main():
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("-o", "--output", default="sweep_absorption.png", help="the PNG to write")
    parser.add_argument("--seconds", type=float, default=1.2, help="simulated time per rate")
    parser.add_argument("--quick", action="store_true", help="two rates, a third of a second")
    args = parser.parse_args()
    rates = [0.003, 0.03] if args.quick else [0.001, 0.003, 0.01, 0.03, 0.1]
    seconds = 0.33 if args.quick else args.seconds
    steps = round(seconds / soak.load(str(SCENE)).dt)

    fig, ax = plt.subplots(figsize=(7, 4.5), dpi=120)
    for rate in rates:
        times, held = held_water(rate, steps)
        ax.plot(times, held, label=f"$\\kappa^a$ = {rate:g}")
        print(f"rate {rate:g}: {held[-1]:.3f} g held after {times[-1]:.2f} s")
    ax.set_xlabel("time (s)")
    ax.set_ylabel("water held by the cloth (g)")
    ax.set_title("Fig. 4 slab: absorption rate sweep (wetting.absorption.rate)")
    ax.grid(alpha=0.3)
    ax.legend()
    fig.tight_layout()
    out = pathlib.Path(args.output)
    out.parent.mkdir(parents=True, exist_ok=True)
    fig.savefig(out)
    print(f"wrote {out}")


if __name__ == "__main__":
    main()

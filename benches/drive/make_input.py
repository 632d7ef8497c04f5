#!/usr/bin/env python3
"""Writes the drive benchmark's input force, input.csv: 19 000 samples at 1 kHz of a
multisine motor force u(t) [N] that drives a slide (mass 8 kg, viscous 20 N s/m, LuGre
friction) back and forth through many reversals. `frictionid simulate drive-sim.toml` then
simulates the slide under it; `make_record.py` joins the simulated motion with the input into
drive.csv, the record that `drive-compare.toml` fits by inverse dynamics."""

import math

RATE, SAMPLES = 1000.0, 19_000
TONES = [(60.0, 0.35, 0.0), (35.0, 1.3, 1.0), (15.0, 3.1, 2.0)]

with open("input.csv", "w") as out:
    out.write("time,u\n")
    for i in range(SAMPLES):
        t = i / RATE
        u = sum(a * math.sin(2 * math.pi * f * t + p) for a, f, p in TONES)
        out.write(f"{t:.6f},{u:.9g}\n")

#!/usr/bin/env python3
"""Joins the simulated slide's noisy velocity (SIM/record.csv) with its friction force
(SIM/trajectory.csv) plus white noise of 0.3 N (seed 11) into force.csv: time, velocity,
force, the record `gms-force-fit.toml` fits GMS to in the force domain.
Usage: python3 make_force_record.py SIM"""

import csv
import random
import sys


def rows(path):
    with open(path) as f:
        return [r for r in csv.DictReader(line for line in f if not line.startswith("#"))]


sim = rows(f"{sys.argv[1]}/record.csv")
traj = rows(f"{sys.argv[1]}/trajectory.csv")
noise = random.Random(11)
with open("force.csv", "w") as out:
    out.write("time,velocity,force\n")
    for r, t in zip(sim, traj):
        force = float(t["friction"]) + noise.gauss(0.0, 0.3)
        out.write(f"{r['time']},{r['velocity']},{force:.9g}\n")

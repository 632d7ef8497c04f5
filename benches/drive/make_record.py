#!/usr/bin/env python3
"""Joins the simulated slide's noisy velocity (SIM/record.csv, from `frictionid simulate
drive-sim.toml --out SIM`) with its input force (input.csv) into drive.csv: time, velocity,
u. Usage: python3 make_record.py SIM"""

import csv
import sys


def rows(path):
    with open(path) as f:
        return [r for r in csv.reader(line for line in f if not line.startswith("#"))][1:]


sim = rows(f"{sys.argv[1]}/record.csv")
u = rows("input.csv")
with open("drive.csv", "w") as out:
    out.write("time,velocity,u\n")
    for (t, v), (_, ui) in zip(sim, u):
        out.write(f"{t},{v},{ui}\n")

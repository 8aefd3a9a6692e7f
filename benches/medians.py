#!/usr/bin/env python3
"""Prints the median and mean of every criterion benchmark under target/criterion."""
import json
import pathlib

for path in sorted(pathlib.Path("target/criterion").glob("**/new/estimates.json")):
    e = json.loads(path.read_text())
    name = str(path.parent.parent.relative_to("target/criterion"))
    median, mean = e["median"]["point_estimate"], e["mean"]["point_estimate"]
    print(f"{name:45s} median {median / 1e3:10.2f} µs   mean {mean / 1e3:10.2f} µs")

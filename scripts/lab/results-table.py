#!/usr/bin/env python3
"""Markdown table of pipeline.sh runs: one row per set, full -> pruned in each cell.

usage: scripts/lab/results-table.py WORK SET...   (reads WORK/SET/summary.json)
"""
import json
import os
import sys

work, sets = sys.argv[1], sys.argv[2:]


def pair(e, key, fmt="%s"):
    vals = [e[v].get(key) for v in ("full", "pruned")]
    return " → ".join("–" if x is None else fmt % x for x in vals)


def false_pairs(e):
    vals = [(e[v].get("pairs") or {}).get("false") for v in ("full", "pruned")]
    return "–" if None in vals else f"{vals[0]} → {vals[1]}"


print("| set | images | pairs | false pairs | mapper s | models | registered | correct "
      "| median pos. error | median rot. error (°) |")
print("|---|---|---|---|---|---|---|---|---|---|")
for s in sets:
    path = os.path.join(work, s, "summary.json")
    if not os.path.exists(path):
        print(f"| {s} | (no result) |||||||||")
        continue
    e = json.load(open(path))
    print(f"| {s} | {e['full']['images_total']} | {pair(e, 'pairs_used')} | {false_pairs(e)} "
          f"| {pair(e, 'mapper_seconds', '%.0f')} | {pair(e, 'models')} | {pair(e, 'registered')} "
          f"| {pair(e, 'correct')} | {pair(e, 'median_position_error', '%.4f')} "
          f"| {pair(e, 'median_rotation_error_deg', '%.2f')} |")

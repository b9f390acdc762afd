#!/usr/bin/env python3
"""The table of scripts/bench/mapper.sh: per scene and mapper, medians over runs of the full and
the pruned database, and the verdict of issue 15 on the pruned one (at least 2x faster in CPU
time, no fewer registered or correct cameras, median errors within 1.5x of the full model's).

usage: mapper_table.py WORK RUNS SCENE...   (reads WORK/SCENE/{prune.json,MAPPER/VARIANT/RUN/};
writes WORK/summary.json and the same table in Markdown, as the README shows it, to WORK/table.md)
"""
import json
import os
import re
import statistics
import sys

# Seconds a mapper spends optimising over all its observations, from its log: COLMAP 3.8's bundle
# adjustment reports ("Time : 0.04 [s]"); COLMAP 4.2's global positioning and bundle adjustment
# stages ("... done in 1.9 seconds"; not its retriangulation, which also walks every pair's
# correspondences).
OPTIMISATION = re.compile(r"^\s+Time : ([0-9.e+-]+) \[s\]|"
                          r"(?:Global positioning|Iterative bundle adjustment) done in ([0-9.e+-]+)",
                          re.M)


def optimisation_seconds(log):
    """Wall seconds in bundle adjustment and global positioning, or None without a log."""
    try:
        text = open(log).read()
    except OSError:
        return None
    return sum(float(a or b) for a, b in OPTIMISATION.findall(text))


def load_run(d):
    """(wall seconds, CPU seconds, eval, optimisation seconds) of one mapper run, or None when it
    failed."""
    try:
        wall, cpu = map(float, open(f"{d}/seconds").read().split())
        return wall, cpu, json.load(open(f"{d}/eval.json")), optimisation_seconds(f"{d}/mapper.log")
    except (OSError, ValueError):
        return None


def median(values):
    values = [v for v in values if v is not None]
    return statistics.median(values) if values else None


def variant_row(runs):
    ev = [r[2] for r in runs]
    return {
        "runs": len(runs),
        "wall": median(r[0] for r in runs),
        "cpu": median(r[1] for r in runs),
        "cpu_each": [round(r[1], 1) for r in runs],
        "registered": median(e["registered"] for e in ev),
        "correct": median(e["correct"] for e in ev),
        "images": ev[0]["images_ground_truth"],
        "pos": median(e["median_position_error"] for e in ev),
        "rot": median(e["median_rotation_error_deg"] for e in ev),
        # What the bundle adjustments work on (None from an eval before session 8).
        "observations": median(e.get("observations") for e in ev),
        "optimisation": median(r[3] for r in runs),
    }


def verdict(full, pruned, ratio):
    within = lambda a, b: a is None or b is None or a <= 1.5 * b
    problems = []
    if pruned["registered"] < full["registered"] or pruned["correct"] < full["correct"]:
        problems.append("fewer cameras")
    if not within(pruned["pos"], full["pos"]) or not within(pruned["rot"], full["rot"]):
        problems.append("errors > 1.5x")
    if ratio < 2:
        # Why, where the logs tell: the share of the full run spent optimising over the
        # observations, and the share of those the prune kept.
        why = ""
        if full["optimisation"] and full["wall"] and full["observations"] and pruned["observations"]:
            why = (f" (optimising {full['optimisation'] / full['wall']:.0%} of the full run, "
                   f"{pruned['observations'] / full['observations']:.0%} of its observations kept)")
        problems.append("< 2x" + why)
    return ", ".join(problems) or "pass"


def fmt(value, spec):
    return "-" if value is None else spec % value


def markdown_row(scene, mapper, pairs, full, pruned, ratio, why):
    """One README row: full -> pruned for each measure."""
    arrow = lambda key, spec: f"{fmt(full[key], spec)} → {fmt(pruned[key], spec)}"
    return (f"| {scene} | {mapper} | {pairs['full']} → {pairs['pruned']} | "
            f"{arrow('cpu', '%.1f')} | {ratio:.2f}x | {arrow('registered', '%g')} | "
            f"{arrow('correct', '%g')} | {arrow('pos', '%.1e')} | {arrow('rot', '%.2f')} | "
            f"{arrow('observations', '%d')} | {arrow('optimisation', '%.1f')} | {why} |")


def main():
    work, runs, scenes = sys.argv[1], int(sys.argv[2]), sys.argv[3:]
    print(f"{'scene':<10} {'mapper':<8} {'db':<6} {'pairs':>5} {'wall s':>7} {'CPU s':>7} "
          f"{'ratio':>5} {'registered':>10} {'correct':>7} {'med. pos':>8} {'med. rot':>8} "
          f"{'obs.':>7} {'opt. s':>6}  verdict")
    summary = {}
    markdown = ["| scene | mapper | pairs full → pruned | CPU s full → pruned | ratio | registered | "
                "correct | med. pos. error | med. rot. error | observations | optimisation s | verdict |",
                "|---|---|---|---|---|---|---|---|---|---|---|---|"]
    for scene in scenes:
        base = f"{work}/{scene}"
        if not os.path.exists(f"{base}/prune.json"):
            continue
        prune = json.load(open(f"{base}/prune.json"))
        pairs = {"full": prune["pairs_total"], "pruned": prune["pairs_selected"]}
        for mapper in sorted(m for m in os.listdir(base) if os.path.isdir(f"{base}/{m}")):
            rows = {}
            for variant in ("full", "pruned"):
                got = [load_run(f"{base}/{mapper}/{variant}/{r}") for r in range(1, runs + 1)]
                if any(got):
                    rows[variant] = variant_row([g for g in got if g])
            if len(rows) < 2:
                print(f"{scene:<10} {mapper:<8} (a variant has no successful run)")
                continue
            full, pruned = rows["full"], rows["pruned"]
            ratio = full["cpu"] / pruned["cpu"]
            why = verdict(full, pruned, ratio)
            for variant, r in rows.items():
                last = variant == "pruned"
                print(f"{scene:<10} {mapper:<8} {variant:<6} {pairs[variant]:>5} {r['wall']:>7.1f} "
                      f"{r['cpu']:>7.1f} {'%.2f' % ratio if last else '':>5} "
                      f"{'%g/%d' % (r['registered'], r['images']):>10} {r['correct']:>7g} "
                      f"{fmt(r['pos'], '%.1e'):>8} {fmt(r['rot'], '%.3f'):>8} "
                      f"{fmt(r['observations'], '%d'):>7} {fmt(r['optimisation'], '%.1f'):>6}  "
                      f"{why if last else ''}")
            markdown.append(markdown_row(scene, mapper, pairs, full, pruned, ratio, why))
            binding = [c for c in prune["criteria"] if c.get("binding")]
            summary[f"{scene}/{mapper}"] = {
                "pairs": pairs, "flow": prune["flow"], "cpu_ratio": ratio, "verdict": why,
                "criterion": binding[0] if binding else None, **rows}
    print(f"(medians of {runs} interleaved runs; ratio = full / pruned CPU seconds; positions as "
          f"fractions of the ground truth's extent, rotations in degrees; files: {work})")
    json.dump(summary, open(f"{work}/summary.json", "w"), indent=1)
    open(f"{work}/table.md", "w").write("\n".join(markdown) + "\n")


main()

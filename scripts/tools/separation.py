#!/usr/bin/env python3
"""How well each prior separates true from false pairs on a real COLMAP database.

usage: scripts/tools/separation.py SCORES.csv LABELS.csv
  SCORES.csv  from `vgsel-colmap prune --scores` (one row per view-graph pair)
  LABELS.csv  from `vgsel-colmap eval --database_path DB --ground_truth GT --labels`

Prints, per column, the AUC of true pairs over false pairs (1 = every true pair scores above
every false one, 0.5 = no separation; for `cost` lower is better, so its AUC is of -cost), and
the kept rates of true and false pairs.
"""
import csv
import sys


def auc(pos, neg):
    """Mann-Whitney AUC with ties counted half."""
    if not pos or not neg:
        return float("nan")
    ranked = sorted([(v, 1) for v in pos] + [(v, 0) for v in neg])
    rank_sum, k = 0.0, 0
    while k < len(ranked):
        j = k
        while j < len(ranked) and ranked[j][0] == ranked[k][0]:
            j += 1
        mid = (k + 1 + j) / 2
        rank_sum += mid * sum(1 for x in ranked[k:j] if x[1])
        k = j
    return (rank_sum - len(pos) * (len(pos) + 1) / 2) / (len(pos) * len(neg))


scores = list(csv.DictReader(open(sys.argv[1])))
labels = {(r["image_id1"], r["image_id2"]): r["true_pair"] == "1"
          for r in csv.DictReader(open(sys.argv[2]))}
rows = [(r, labels[(r["image_id1"], r["image_id2"])]) for r in scores
        if (r["image_id1"], r["image_id2"]) in labels]
n_true = sum(1 for _, t in rows if t)
print(f"{len(rows)} labelled pairs: {n_true} true, {len(rows) - n_true} false")
print(f"{'column':<28} {'AUC':>6} {'pairs with a value':>18}")
for col in scores[0]:
    if col in ("image_id1", "image_id2", "kept"):
        continue
    sign = -1.0 if col == "cost" else 1.0
    pos = [sign * float(r[col]) for r, t in rows if t and r[col] != ""]
    neg = [sign * float(r[col]) for r, t in rows if not t and r[col] != ""]
    print(f"{col:<28} {auc(pos, neg):>6.3f} {len(pos) + len(neg):>18}")
kept_true = sum(1 for r, t in rows if t and r["kept"] == "1")
kept_false = sum(1 for r, t in rows if not t and r["kept"] == "1")
print(f"kept: {kept_true}/{n_true} true, {kept_false}/{len(rows) - n_true} false")

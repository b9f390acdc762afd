#!/usr/bin/env bash
# The repair loop on the demo scene with COLMAP 4.2's mappers (MAPPERS: global, incremental) or
# COLMAP 3.8's (colmap3.8), over several fresh matchings:
# each run matches the rendered images (COLMAP 3.8 and pycolmap 4.2, as colmap4-mappers.sh; COLMAP
# 3.8 alone where MAPPERS is colmap3.8),
# prunes a copy (PRUNE_ARGS, default --preset disambiguation), maps it, runs `check` on the
# model, and where check gives `prune --model` something to act on (its report's `repair`: a
# ghost's blamed pairs, or pairs that place a misplaced group, join clean models or place an
# image no model registered) prunes again
# with --model and maps once more. Every model is scored against the ground truth. It does not
# map the full database, so, unlike scripts/pipeline.sh's loop, it has no full model's evidence.
# Prints one row per run and mapper, after the loop its answer (its last run the check calls
# clean, else its last, as pipeline.sh); writes WORKDIR/loop.json.
# SCENE, NUM_IMAGES, SEED: another rendered design (demo-matching.sh). TURNS: the loop's turns at
# most [3], each passing every earlier model to `prune --model`. REPAIR_INIT_ANGLE: COLMAP 3.8's
# initial-pair angle in the repair turns (--Mapper.init_min_tri_angle) [COLMAP's own, 16]; the
# first mapper run keeps COLMAP's defaults. 8 was measured and not adopted (docs/check.md).
# LEFT_OUT: in a repair turn with COLMAP 3.8, map the images the database links and the run left
# out on their own into the turn's folder (scripts/map-left-out.sh, as the README says) [1]; 0:
# not (the loop before session 23).
# usage: scripts/lab/repair-loop.sh [WORKDIR] [RUNS] [MAPPERS]
#        (defaults: target/repair-loop, 5, "global incremental")
set -euo pipefail
cd "$(dirname "$0")/../.."
work=${1:-target/repair-loop}
runs=${2:-5}
mappers=${3:-global incremental}
turns=${TURNS:-3}
# shellcheck source=scripts/lab/demo-matching.sh
source scripts/lab/demo-matching.sh
demo_setup "$work"
map_with() { # MAPPER DB OUT STEP: COLMAP 3.8's mapper (colmap3.8) or pycolmap's (global,
  # incremental); STEP above 1: a repair turn's run
  local init=() repair=
  [ "$4" -gt 1 ] && repair=1
  [ -n "$repair" ] && [ -n "${REPAIR_INIT_ANGLE:-}" ] &&
    init=(--Mapper.init_min_tri_angle "$REPAIR_INIT_ANGLE")
  if [ "$1" = colmap3.8 ]; then
    mkdir -p "$3"
    # A repair turn's selection can leave COLMAP 3.8 no initial pair: that turn makes no model.
    nice colmap mapper --database_path "$2" --image_path "$images" --output_path "$3" \
      "${init[@]}" >"$3.log" 2>&1 || grep -q "failed to create sparse model" "$3.log"
    echo '{}' >"$3.json"
    # Every run of the loop, the first too: a piece that starts a model stays apart, only
    # images that start none are placed by their matches (docs/check.md).
    if [ "$turns" -gt 0 ] && [ "${LEFT_OUT:-1}" = 1 ]; then
      VGSEL=$bin nice scripts/map-left-out.sh "$2" "$images" "$3" "${init[@]}" >/dev/null
    fi
  else
    nice "$PY" scripts/ci/colmap4.py map "$1" "$2" "$images" "$3" >"$3.json" 2>"$3.log"
  fi
}
score() { # MODEL DB -> correct/registered/models as JSON
  "$bin" eval --model "$1" --ground_truth "$work/scene/gt" --database_path "$2" --baseline "$dir/full.db"
}
for run in $(seq 1 "$runs"); do
  for matcher in colmap3.8 pycolmap4.2; do
    # COLMAP 3.8 alone maps no pycolmap matching (it cannot read 4.2's schema): skip it.
    [ "$mappers/$matcher" = colmap3.8/pycolmap4.2 ] && continue
    dir=$work/$run/$matcher
    mkdir -p "$dir"
    echo "run $run: $matcher matching" >&2
    match_demo "$matcher" "$images" "$dir"
    for mapper in $mappers; do
      # COLMAP 3.8 cannot read the schema pycolmap 4.2 writes.
      [ "$mapper/$matcher" = colmap3.8/pycolmap4.2 ] && continue
      db=$dir/$mapper.db
      cp "$dir/full.db" "$db"
      # shellcheck disable=SC2086 # PRUNE_ARGS is a list of options
      "$bin" prune -q ${PRUNE_ARGS:---preset disambiguation} --database_path "$db"
      models=()
      for step in $(seq 1 $((turns + 1))); do
        model=$dir/${mapper}_$step
        map_with "$mapper" "$db" "$model" "$step"
        score "$model" "$db" >"$model.eval.json"
        if [ -z "$(ls -A "$model")" ]; then
          # The turn made no model: the loop stops there, recorded as such.
          echo '{"no_model": true, "repair": {}}' >"$model.check.json"
          break
        fi
        status=0
        # The earlier turns' models (the list `prune --model` gets) as --earlier_model.
        "$bin" check --model "$model" --database_path "$db" "${models[@]/#--model/--earlier_model}" \
          --report "$model.check.json" >"$model.check.txt" || status=$?
        [ "$status" -eq 0 ] || [ "$status" -eq 3 ] || exit "$status"
        # Another turn where the check gives `prune --model` something to act on.
        python3 -c 'import json, sys; sys.exit(not any(json.load(open(sys.argv[1]))["repair"].values()))' \
          "$model.check.json" && [ "$step" -le "$turns" ] || break
        models+=(--model "$model")
        # shellcheck disable=SC2086
        "$bin" prune -q ${PRUNE_ARGS:---preset disambiguation} --database_path "$db" "${models[@]}"
      done
    done
  done
done
python3 - "$work" "$runs" "$mappers" "$num_images" <<'PY'
import json, os, sys
sys.path.insert(0, "scripts/lab")
import loop_answer  # the loop's answer, pipeline.sh's rule
work, runs, mappers, n = sys.argv[1], int(sys.argv[2]), sys.argv[3].split(), int(sys.argv[4])
rows = []
verdict = lambda c: next((k.replace("_", " ") for k in ("no_model", "ghosted", "misplaced", "unanchored")
                          if c.get(k)), "clean")
print(f"{'run':>3} {'matching':<12} {'mapper':<10} {'first: correct':>14} {'check':>10} "
      f"{'turns':>5} {'after the loop: correct':>23} {'models':>6} {'check':>10}")
for run in range(1, runs + 1):
    for matcher in ["colmap3.8", "pycolmap4.2"]:
        for mapper in mappers:
            base = f"{work}/{run}/{matcher}/{mapper}"
            steps = []
            while os.path.exists(f"{base}_{len(steps) + 1}.eval.json"):
                e = json.load(open(f"{base}_{len(steps) + 1}.eval.json"))
                c = json.load(open(f"{base}_{len(steps) + 1}.check.json"))
                steps.append(dict(correct=e.get("correct", 0), registered=e["registered"],
                                  models=e["models"], ghosted=c.get("ghosted", False),
                                  misplaced=c.get("misplaced", False),
                                  unanchored=c.get("unanchored", False),
                                  no_model=c.get("no_model", False)))
            if not steps:
                continue
            answer = loop_answer.answer(steps)
            rows.append(dict(run=run, matching=matcher, mapper=mapper, steps=steps, answer=answer))
            first, last = steps[0], steps[answer]
            after = (f"{last['correct']:>20}/{n} {last['models']:>6} {verdict(last):>10}"
                     if len(steps) > 1 else f"{'(not needed)':>23} {'':>6} {'':>10}")
            print(f"{run:>3} {matcher:<12} {mapper:<10} {first['correct']:>11}/{n} "
                  f"{verdict(first):>10} {len(steps) - 1:>5} {after}")
final = [r["steps"][r["answer"]]["correct"] for r in rows]
print(f"after the loop: {n}/{n} correct in {sum(c == n for c in final)} of {len(final)} runs; "
      f"before it: {sum(r['steps'][0]['correct'] == n for r in rows)} of {len(rows)}")
json.dump(rows, open(f"{work}/loop.json", "w"), indent=1)
PY

#!/usr/bin/env bash
# Images to two reconstructions: COLMAP features and exhaustive matching, a pruned copy of the
# database by vgsel-colmap, the mapper on the full and on the pruned database, and (given a
# ground-truth model) `vgsel-colmap eval` of both. Prints one side-by-side table (with REPAIR,
# each run's `check` verdict too) and writes WORKDIR/summary.json (each run's eval under its
# name, full, pruned, repairedK, in that order, with its `check` verdict; the loop's answer; the
# ground truth's folder). COLMAP 3.8 (`colmap`) by default; COLMAP 4.2 through pycolmap (MATCHER,
# MAPPER), in the venv scripts/ci/pycolmap-venv.sh makes.
#
# usage: scripts/pipeline.sh IMAGES WORKDIR [GT]
#   IMAGES   folder of images (never modified; large images are downscaled by COLMAP for SIFT
#            through MAX_IMAGE_SIZE, keypoints stay in full-resolution pixels)
#   WORKDIR  created if missing; features, matches and the full model are not redone when
#            present (delete WORKDIR to start again); the prune and its mapper always run
#   GT       ground-truth COLMAP model (text or binary); images are matched by name
# environment (defaults in brackets):
#   PRUNE_ARGS      extra `vgsel-colmap prune` options [none: prune's defaults; with REPAIR, the
#                   loop's preset: --preset disambiguation]
#   CHECK_ARGS      with REPAIR, `vgsel-colmap check` options for the loop's checks and its
#                   `prune --model` runs alike, e.g. "--bare_weight 0.5" [none]
#   MAX_IMAGE_SIZE  SIFT image size [1024]       MAX_FEATURES  SIFT features per image [2048]
#   CAMERA_MODEL    [SIMPLE_RADIAL]              CAMERA_PARAMS known intrinsics, e.g. "f,cx,cy" []
#   SINGLE_CAMERA   one camera for all images [1]
#   DATABASE        a database already matched from IMAGES: copied as WORKDIR/full.db (read,
#                   never changed) instead of extracting and matching []
#   MATCHER         colmap3.8 (`colmap feature_extractor`, `exhaustive_matcher`) or pycolmap4.2
#                   [colmap3.8]
#   MAPPER          colmap3.8 (`colmap mapper`), or COLMAP 4.2's incremental or global mapper
#                   (each run on a copy of its database, which COLMAP 4 would migrate) [colmap3.8]
#   VGSEL           the vgsel-colmap binary [in a checkout target/release/vgsel-colmap, built if
#                   missing; installed, vgsel-colmap on PATH]
#   REPAIR          N > 0: the repair loop (docs/check.md), at most N turns: `vgsel-colmap
#                   check` on the last model, and where its report's `repair` is not empty
#                   (a ghost's pairs to blame, or pairs that place a misplaced group, join
#                   clean models or place an image no model registered), `prune --model` with
#                   every model so far and one more mapper run, a row `repairedK` per turn
#                   [0]; the full database's model is checked too: where it is ghosted and
#                   the pruned selection kept what glued it, or the pruned model, whose
#                   check gives the loop nothing to act on, places most of that ghost's
#                   groups as it does (repair_loop.py),
#                   it is the first of those models and the first turn runs whatever the
#                   pruned model's check says (else, ghosted, it is each turn's check's and
#                   prune's --earlier_model: its ghost refutes, blames nothing); a turn
#                   whose prune selects what the last run mapped ends the loop; in the
#                   loop's runs, the pruned one's too, the images the database links and
#                   an incremental mapper left out (a piece the blame cut off: COLMAP 3.8 starts no second model from narrow
#                   pairs, and COLMAP drops models under 10 images) are mapped on their own,
#                   pieces of 3 kept (scripts/map-left-out.sh), into sparse_VARIANT/left,
#                   counted in the mapper's seconds (README); a run whose mapper makes no
#                   model (COLMAP 3.8 found no initial pair: an outcome, recorded as such)
#                   ends the loop, the model before it stands; the loop's answer
#                   (WORKDIR/answer, summary.json's loop_answer) is its last run the check
#                   calls clean (not the pruned run where the full model's evidence came
#                   first), else the full run where the check calls it clean or the pruned
#                   run made no model, else its last run
set -euo pipefail
[ $# -ge 2 ] || { echo "usage: $0 IMAGES WORKDIR [GT]" >&2; exit 2; }
# This checkout, or the package's copy of its scripts (/usr/share/vgsel-colmap, run as
# vgsel-colmap-pipeline).
here=$(cd "$(dirname "$(readlink -f "$0")")/.." && pwd)
images=$(cd "$1" && pwd)
mkdir -p "$2"
work=$(cd "$2" && pwd)
gt=${3:+$(cd "$3" && pwd)}
if [ "${REPAIR:-0}" -gt 0 ]; then
  # The loop is measured with the disambiguation preset. The general one has no fitness floor:
  # a turn's flow, larger to reach every image once the blamed pairs are gone, can take more
  # false pairs than the first selection (castle: 14 -> 29, 20 -> 10 of 30 right; docs/check.md).
  prune_args=${PRUNE_ARGS---preset disambiguation}
  [[ $prune_args == *disambiguation* ]] || echo "pipeline: warning: REPAIR without a" \
    "disambiguation preset in PRUNE_ARGS: the loop is measured with --preset disambiguation" >&2
else
  # prune's own defaults, as a user's `vgsel-colmap prune` gets them.
  prune_args=${PRUNE_ARGS-}
fi
# The loop's check options, for its `check` runs and its `prune --model` alike.
check_args=${CHECK_ARGS-}
if [ -n "${VGSEL:-}" ]; then
  bin=$VGSEL
elif [ -f "$here/Cargo.toml" ]; then
  bin=$here/target/release/vgsel-colmap
  [ -x "$bin" ] || (cd "$here" && cargo build --release --quiet)
else
  bin=$(command -v vgsel-colmap) || { echo "pipeline: vgsel-colmap is not on PATH" >&2; exit 2; }
fi
log() { echo "pipeline: $*" >&2; }
# Whether run VARIANT made a model (COLMAP 3.8 can make none: an empty sparse_VARIANT).
made_model() { [ -n "$(ls -A "$work/sparse_$1")" ]; }
matcher=${MATCHER:-colmap3.8} mapper=${MAPPER:-colmap3.8}
case "$matcher/$mapper" in
  colmap3.8/colmap3.8 | */incremental | */global) ;;
  pycolmap4.2/colmap3.8) echo "pipeline: COLMAP 3.8's mapper cannot read COLMAP 4's database" >&2; exit 2 ;;
  *) echo "pipeline: MATCHER is colmap3.8 or pycolmap4.2, MAPPER colmap3.8, incremental or global" >&2; exit 2 ;;
esac
[ "$matcher/$mapper" = colmap3.8/colmap3.8 ] || py=$(bash "$here/scripts/ci/pycolmap-venv.sh")

# Seconds taken by a command, its output going to a log file; fails with the log's tail, unless
# the log says $tolerated (an outcome, not a failure; set for one call: `tolerated=... timed`).
timed() {
  local logfile=$1
  shift
  local start
  start=$(date +%s.%N)
  if ! nice "$@" >"$logfile" 2>&1 && ! { [ -n "${tolerated:-}" ] && grep -q "$tolerated" "$logfile"; }; then
    tail -n 20 "$logfile" >&2
    echo "pipeline: failed: $* (log: $logfile)" >&2
    exit 1
  fi
  echo "$(date +%s.%N) - $start" | bc
}

if [ ! -f "$work/full.db.done" ]; then
  rm -f "$work/full.db"
  if [ -n "${DATABASE:-}" ]; then
    [ -f "$DATABASE" ] || { echo "pipeline: DATABASE $DATABASE: no such file" >&2; exit 2; }
    log "the matched database $DATABASE, copied"
    # SQLite's backup, opened read-only: a copy whole even where the source has a -wal file.
    python3 -c 'import sqlite3, sys
sqlite3.connect(f"file:{sys.argv[1]}?mode=ro", uri=True).backup(sqlite3.connect(sys.argv[2]))' \
      "$DATABASE" "$work/full.db"
    t_extract=0 t_match=0
  elif [ "$matcher" = colmap3.8 ]; then
    log "features and exhaustive matching by $matcher ($(ls "$images" | wc -l) images)"
    camera=(--ImageReader.camera_model "${CAMERA_MODEL:-SIMPLE_RADIAL}"
      --ImageReader.single_camera "${SINGLE_CAMERA:-1}")
    [ -n "${CAMERA_PARAMS:-}" ] && camera+=(--ImageReader.camera_params "$CAMERA_PARAMS")
    t_extract=$(timed "$work/extract.log" colmap feature_extractor --database_path "$work/full.db" \
      --image_path "$images" "${camera[@]}" --SiftExtraction.use_gpu 0 \
      --SiftExtraction.max_image_size "${MAX_IMAGE_SIZE:-1024}" \
      --SiftExtraction.max_num_features "${MAX_FEATURES:-2048}")
    t_match=$(timed "$work/match.log" colmap exhaustive_matcher --database_path "$work/full.db" \
      --SiftMatching.use_gpu 0)
  else
    log "features and exhaustive matching by $matcher ($(ls "$images" | wc -l) images)"
    # pycolmap extracts and matches in one call: its seconds are the extraction's.
    t_extract=$(timed "$work/extract.log" "$py" "$here/scripts/ci/colmap4.py" database "$images" \
      "$work/full.db" --camera_model "${CAMERA_MODEL:-SIMPLE_RADIAL}" \
      --single_camera "${SINGLE_CAMERA:-1}" --camera_params "${CAMERA_PARAMS:-}" \
      --max_image_size "${MAX_IMAGE_SIZE:-1024}" --max_features "${MAX_FEATURES:-2048}")
    t_match=0
  fi
  echo "$t_extract $t_match" >"$work/full.db.done"
fi
read -r t_extract t_match <"$work/full.db.done"
# A full model mapped by another mapper is mapped again.
[ "$(cat "$work/full.mapper" 2>/dev/null)" = "$mapper" ] || rm -f "$work/sparse_full.seconds"
echo "$mapper" >"$work/full.mapper"

log "prune $prune_args"
# shellcheck disable=SC2086 # PRUNE_ARGS is a list of options
"$bin" prune -q --database_path "$work/full.db" --output "$work/pruned.db" --overwrite \
  --report "$work/prune.json" $prune_args
# The pruned database was just rewritten, so its reconstruction is redone.
rm -f "$work/sparse_pruned.seconds"

# The loop's second mapper run (scripts/map-left-out.sh): the images its database links and
# its first run left out, mapped into sparse_VARIANT/left; its seconds are added to the run's.
map_left_out() {
  local variant=$1 sparse=$work/sparse_$1 first seconds
  local with=(VGSEL="$bin") options=(--Mapper.extract_colors 0)
  [ "$mapper" = colmap3.8 ] || with+=(PYCOLMAP="$py") options=()
  seconds=$(timed "$work/left_$variant.log" env "${with[@]}" "$here/scripts/map-left-out.sh" \
    "$work/$variant.db" "$images" "$sparse" "${options[@]}")
  [ -s "$sparse.left.txt" ] &&
    log "mapper on the $(wc -l <"$sparse.left.txt") images the $variant model left out"
  first=$(cat "$sparse.seconds.part")
  echo "$first + $seconds" | bc >"$sparse.seconds.part"
}

# The mapper on one database of WORKDIR (full, pruned or repaired) and the eval of its model.
map_and_eval() {
  local variant=$1 sparse=$work/sparse_$1
  if [ ! -f "$sparse.seconds" ]; then
    rm -rf "$sparse"
    mkdir -p "$sparse"
    log "$mapper mapper on the $variant database"
    if [ "$mapper" = colmap3.8 ]; then
      # COLMAP 3.8 can find no initial pair (a repair turn's selection, or a scene it cannot
      # start at all): that run makes no model, an outcome.
      tolerated="failed to create sparse model" timed "$work/mapper_$variant.log" colmap mapper \
        --database_path "$work/$variant.db" --image_path "$images" --output_path "$sparse" \
        --Mapper.extract_colors 0 >"$sparse.seconds.part"
    else
      # COLMAP 4 migrates the database it opens: it maps a copy, so that every database here
      # stays as its matcher wrote it. No model at all is an outcome, an empty folder.
      cp "$work/$variant.db" "$work/mapper_$variant.db"
      timed "$work/mapper_$variant.log" "$py" "$here/scripts/ci/colmap4.py" map "$mapper" \
        "$work/mapper_$variant.db" "$images" "$sparse" >"$sparse.seconds.part"
      rm -f "$work/mapper_$variant.db"
    fi
    # The loop maps the images an incremental run left out on their own before checking it,
    # the pruned run's too: a piece that starts a model stays apart, only images that start
    # none are placed by their matches (docs/check.md, "Cameras lost beside a clean model").
    if [ "$mapper" != global ] && { [[ $variant == repaired* ]] ||
      { [ "$variant" = pruned ] && [ "${REPAIR:-0}" -gt 0 ]; }; }; then
      map_left_out "$variant"
    fi
    # The seconds mark the run done: written once it is (a failed run leaves none).
    mv "$sparse.seconds.part" "$sparse.seconds"
  fi
  eval_args=(--model "$sparse" --database_path "$work/$variant.db")
  [ -n "$gt" ] && eval_args+=(--ground_truth "$gt")
  [ "$variant" != full ] && eval_args+=(--baseline "$work/full.db")
  "$bin" eval "${eval_args[@]}" >"$work/eval_$variant.json"
}
map_and_eval full
map_and_eval pruned
rm -f "$work"/eval_repaired*.json "$work"/sparse_repaired*.seconds "$work/answer" \
  "$work"/check_*.json
last=pruned models=() earlier=() answer= full_evidence= full_clean= full_ghost=()
# The full model's evidence taken (for the reason `$1` says): the first model of every turn's
# prune and every check's earlier model, and the pruned run no answer.
take_full_model() {
  log "$1: its evidence comes first"
  full_evidence=1 models=(--model "$work/sparse_full") full_ghost=()
  earlier=(--earlier_model "$work/sparse_full")
}
# The full database's model is evidence too where the check calls it ghosted and the pruned
# selection kept what glued it: the pruned model can be the same ghost, hidden from the check
# (the twin: docs/check.md, "The full model in the loop", scripts/repair_loop.py), so
# its blame joins every turn's and the loop takes its first turn.
if [ "${REPAIR:-0}" -gt 0 ] && made_model full; then
  status=0
  # shellcheck disable=SC2086 # CHECK_ARGS is a list of options
  "$bin" check --model "$work/sparse_full" --database_path "$work/full.db" \
    --report "$work/check_full.json" $check_args >"$work/check_full.txt" || status=$?
  cat "$work/check_full.txt" >&2
  [ "$status" = 0 ] || [ "$status" = 3 ] || exit "$status"
  [ "$status" = 3 ] || full_clean=1
  # Its ghost, without its blame, refutes what a turn's check would place where it had it and
  # finds it again in a turn's model (an orbit's first images left on the other copy). Not in
  # the pruned run's check: where that run is the full model's ghost, hidden, same-ghost below
  # takes the full model's evidence whole.
  [ "$status" = 0 ] || full_ghost=(--earlier_model "$work/sparse_full")
  if share=$("$here/scripts/repair_loop.py" full-model "$work/check_full.json" "$work/pruned.db"); then
    take_full_model "the full model's ghost blames $share of the pruned selection"
  fi
fi
# Every model is checked, the last turn's too, after the models before it (a clean model's
# pieces an earlier ghost had put onto each other join); a turn runs where the check gives
# `prune --model` something to act on (its report's `repair`: pairs a ghost blames, pairs that
# place a misplaced group, join clean models or place an image no model registered).
for turn in $(seq 1 $((${REPAIR:-0} + 1))); do
  [ "${REPAIR:-0}" -gt 0 ] || break
  if ! made_model "$last"; then
    log "the $last run made no model: nothing to check"
    break
  fi
  status=0
  # shellcheck disable=SC2086
  ghost=()
  [ "$last" = pruned ] || ghost=("${full_ghost[@]}")
  "$bin" check --model "$work/sparse_$last" --database_path "$work/$last.db" "${ghost[@]}" \
    "${earlier[@]}" \
    --report "$work/check_$last.json" $check_args >"$work/check_$last.txt" || status=$?
  cat "$work/check_$last.txt" >&2
  [ "$status" = 0 ] || [ "$status" = 3 ] || exit "$status"
  acts=1
  "$here/scripts/repair_loop.py" acts "$work/check_$last.json" || acts=
  # A pruned model the check gives nothing to act on (clean, or flagged only by an image that
  # matches a third place) that places most of each group of the full model's ghost as it
  # does is that ghost, hidden from the check (the plain design at 38 images): the full
  # model's evidence comes first after all, whatever share of the selection it blames.
  if [ -z "$acts" ] && [ "$last" = pruned ] && [ -z "$full_evidence" ] &&
    [ -f "$work/check_full.json" ] && shares=$("$here/scripts/repair_loop.py" same-ghost \
      "$bin" "$work/check_full.json" "$work/sparse_pruned"); then
    take_full_model "the pruned model places the full model's ghost as it does ($shares of its groups)"
  fi
  # A clean verdict answers, but the pruned run's where the full model's ghost came first:
  # there it is that ghost hidden (the twin's, every one at hand).
  [ "$status" = 0 ] && { [ "$last" != pruned ] || [ -z "$full_evidence" ]; } && answer=$last
  { [ "$turn" = 1 ] && [ -n "$full_evidence" ]; } || [ -n "$acts" ] || break
  [ "$turn" -le "$REPAIR" ] || break
  models+=(--model "$work/sparse_$last")
  earlier+=(--earlier_model "$work/sparse_$last")
  log "turn $turn: prune --model with the check's evidence (a ghost, a misplaced group or image, pieces or lost images)"
  # shellcheck disable=SC2086
  "$bin" prune -q --database_path "$work/full.db" --output "$work/repaired$turn.db" --overwrite \
    --report "$work/prune_repaired$turn.json" "${models[@]}" "${full_ghost[@]}" \
    $prune_args $check_args
  if "$here/scripts/repair_loop.py" same-selection "$work/$last.db" "$work/repaired$turn.db"; then
    log "turn $turn selects what the $last run mapped: the loop stops"
    break
  fi
  log "mapper again (turn $turn)"
  map_and_eval "repaired$turn"
  if ! made_model "repaired$turn"; then
    log "turn $turn made no model: the loop stops, the $last model stands"
    break
  fi
  last=repaired$turn
done
# The loop's answer: its last run the check calls clean, where a later turn's run is not (the
# pieces a clean run's join or placement kept, made a ghost by the next mapper run: streets 128
# and 147 of docs/check.md, 44 and 29 of 44 right against 23 and 19); else its last run.
if [ "${REPAIR:-0}" -gt 0 ]; then
  if [ -n "$answer" ]; then
    [ "$answer" = "$last" ] ||
      log "the $last model is not clean and the $answer model is: the loop's answer is sparse_$answer"
  elif ! made_model "$last" && made_model full; then
    # COLMAP 3.8 can start no model from the pruned selection (a short street's narrow pairs):
    # the full database's model, what COLMAP alone gives, is then the answer, not nothing.
    answer=full
    log "the $last run made no model: the loop's answer is the full database's model, sparse_full"
  elif [ -n "$full_clean" ]; then
    # No run of the loop is clean and COLMAP alone gave a model the check calls clean (the
    # adjacent design, where the preset ghosts what the full database maps right and a turn
    # can leave an image the repair cannot act on): that model is the answer.
    answer=full
    log "no run of the loop is clean and the full database's model is: the loop's answer is sparse_full"
  else
    answer=$last
    if made_model "$last"; then
      log "no run is clean: the loop's answer is its last run, sparse_$last, which check calls wrong ($work/check_$last.txt)"
    fi
  fi
  echo "$answer" >"$work/answer"
fi

python3 - "$work" "$t_extract" "$t_match" "$gt" <<'EOF'
import json, os, sys
work, t_extract, t_match, gt = sys.argv[1], float(sys.argv[2]), float(sys.argv[3]), sys.argv[4]


def verdict(variant):
    """`check`'s verdict on the run's models (the loop's check), "-" where it did not run."""
    try:
        c = json.load(open(f"{work}/check_{variant}.json"))
    except FileNotFoundError:
        return "-"
    return c["verdict"]


rows = {}
turns = sorted(int(f[len("eval_repaired"):-5]) for f in os.listdir(work)
               if f.startswith("eval_repaired") and f.endswith(".json"))
for v in ["full", "pruned"] + [f"repaired{k}" for k in turns]:
    try:
        e = json.load(open(f"{work}/eval_{v}.json"))
    except FileNotFoundError:
        continue
    e["mapper_seconds"] = float(open(f"{work}/sparse_{v}.seconds").read())
    e["check"] = verdict(v)
    rows[v] = e
fmt = lambda x, f: "-" if x is None else f % x

print(f"{'database':<10} {'pairs':>6} {'mapper s':>9} {'models':>6} {'registered':>10} "
      f"{'correct':>7} {'med. pos':>9} {'med. rot':>9} {'false pairs':>11} {'check':>10}")
# An image registered in several models is `correct` by its best registration: a run with more
# wrong registrations than wrong cameras has one wrong in another of its models (a ghost beside a
# small copy), and is marked.
elsewhere = {}
for v, e in rows.items():
    p = e.get("pairs") or {}
    correct = fmt(e.get("correct"), "%d")
    wrong = e.get("wrong_registrations", 0)
    if "correct" in e and wrong > e["registered"] - e["correct"]:
        elsewhere[v], correct = wrong, correct + "*"
    print(f"{v:<10} {e['pairs_used']:>6} {e['mapper_seconds']:>9.1f} {e['models']:>6} "
          f"{str(e['registered']) + '/' + str(e['images_total']):>10} "
          f"{correct:>7} {fmt(e.get('median_position_error'), '%.4f'):>9} "
          f"{fmt(e.get('median_rotation_error_deg'), '%.2f°'):>9} {fmt(p.get('false'), '%d'):>11} "
          f"{e['check']:>10}")
for v, n in elsewhere.items():
    print(f"* {v}: an image registered in more than one model is wrong in one of them "
          f"({n} wrong registrations)")
summary = {"extract_seconds": t_extract, "match_seconds": t_match, "ground_truth": gt or None,
           "prune": json.load(open(f"{work}/prune.json")), **rows}
if os.path.exists(f"{work}/answer"):
    answer = summary["loop_answer"] = open(f"{work}/answer").read().strip()
    verdict = rows.get(answer, {}).get("check", "-")
    flagged = f" (check: {verdict}; no run was clean)" if verdict not in ("clean", "-") else ""
    print(f"the repair loop's answer: {answer}{flagged}")
json.dump(summary, open(f"{work}/summary.json", "w"), indent=1)
print(f"(position errors are fractions of the ground truth's extent; files: {work})")
EOF

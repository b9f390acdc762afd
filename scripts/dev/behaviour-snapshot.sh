#!/usr/bin/env bash
# Everything a user can observe of a vgsel-colmap binary on one database, written to a folder so
# that two binaries (before and after a refactoring) compare with `diff -r`: every --help text,
# completions, the man page, a generated database and graph, and for every preset and the options that change how a run resolves its parameters the report JSON (timings and clocks removed),
# the --scores CSV, the pair list, the plots, the pruned database's SQL dump (run times removed),
# inspect, both exports and the restored dump.
# usage: scripts/dev/behaviour-snapshot.sh BINARY DATABASE OUTDIR
set -euo pipefail
[ $# -eq 3 ] || { echo "usage: $0 BINARY DATABASE OUTDIR" >&2; exit 2; }
bin=$(realpath "$1")
db=$(realpath "$2")
rm -rf "$3"
mkdir -p "$3"
out=$(realpath "$3")
cd "$out"

# JSON without the keys whose values are clocks.
strip_times() {
  python3 -c '
import json, sys
def clean(v):
    if isinstance(v, dict):
        return {k: clean(x) for k, x in v.items() if k not in ("timings", "time")}
    if isinstance(v, list):
        return [clean(x) for x in v]
    return v
print(json.dumps(clean(json.load(sys.stdin)), indent=1, sort_keys=True))'
}
dump() { sqlite3 "$1" .dump | sed -E "s/'[0-9]{4}-[0-9]{2}-[0-9]{2}T[0-9:.]+Z'/'TIME'/g"; }

"$bin" --help >help.txt
for sub in prune restore inspect solve eval export completions man; do
  "$bin" "$sub" --help >"help-$sub.txt"
done
for sub in images database graph; do
  "$bin" generate "$sub" --help >"help-generate-$sub.txt"
done
"$bin" completions bash >completions.bash
# The evaluation tooling's outputs: a synthetic database with its ground truth, a paper graph.
"$bin" -q generate database --output gen.db --ground_truth gen-gt >/dev/null
dump gen.db >generated.sql
rm -f gen.db*
"$bin" -q generate graph --images 50 --pairs 400 --output generated.graph >/dev/null
"$bin" man >man.1

# Each variant: a folder name and prune options (every preset, and the options that change how
# the parameters resolve: a fixed flow, criteria, completion, order, arc rules, weights, floor).
variants=(
  "general|--preset general"
  "disambiguation|--preset disambiguation"
  "global|--preset disambiguation-global"
  "global-sequence|--preset disambiguation-global --order name --sequence_window 3 --pair_mean arithmetic"
  "paper|--preset paper-disambiguation --order name"
  "sequence|--preset disambiguation --order name --sequence_window 3 --keep_neighbours 2 --min_pair_fitness 0.5 --weights unique_tracks=0.5"
  "fixed|--flow 30 --min_num_matches 20"
  "criteria|--min_image_fraction 1 --min_pairs_per_image 3 --min_pairs_each 2 --biconnected true --spanning_forests 1 --min_track_observations 50 --min_track_length_ratio 0.5"
)
for variant in "${variants[@]}"; do
  preset=${variant%%|*}
  read -r -a options <<<"${variant#*|}"
  mkdir "$preset"
  cp "$db" "$preset/in.db"
  "$bin" -q prune --database_path "$preset/in.db" "${options[@]}" --dry_run \
    --report "$preset/dry.json" --scores "$preset/scores.csv" --pairs_out "$preset/pairs.txt" \
    --plots "$preset/plots"
  "$bin" -q prune --database_path "$preset/in.db" "${options[@]}" --output "$preset/pruned.db" \
    --report "$preset/report.json"
  for f in dry report; do strip_times <"$preset/$f.json" >"$preset/$f.clean.json"; rm "$preset/$f.json"; done
  dump "$preset/pruned.db" >"$preset/pruned.sql"
  "$bin" inspect --database_path "$preset/pruned.db" --json >"$preset/inspect.json"
  "$bin" -q export --database_path "$preset/pruned.db" --format dot --output "$preset/graph.dot"
  "$bin" -q export --database_path "$preset/pruned.db" --format graphml --output "$preset/graph.graphml"
  "$bin" -q restore --database_path "$preset/pruned.db"
  dump "$preset/pruned.db" >"$preset/restored.sql"
  rm -f "$preset"/in.db* "$preset"/pruned.db*
done
dump "$db" >original.sql
for variant in "${variants[@]}"; do
  cmp -s original.sql "${variant%%|*}/restored.sql" || exit_restore=1
done
[ -z "${exit_restore:-}" ] && echo "restore exact" >restore.txt

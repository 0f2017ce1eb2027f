#!/usr/bin/env bash
# farm_test.sh BUILD_DIR SOURCE_DIR WORK_DIR: the Slurm farm of docs/store.md on a one-node
# cluster started here (slurm_cluster.sh; skipped, exit 77, without Slurm and munge): a bake
# job and a render array of 3 shards sharing a store. Checks every frame is bit-identical
# to a one-process render of the range, and that the shards filled no tile (the bake filled
# each once).
set -euo pipefail
build="$1" source="$2" work="$3"
mpshade="$build/app/mpshade"
scene="$source/examples/courtyard/scene.json"
rm -rf "$work"
mkdir -p "$work"
"$source/tests/farm/slurm_cluster.sh" "$work/cluster" \
  "$source/scripts/farm_slurm.sh" "$scene" --out "$work/farm" --frames 0:6 --shards 3 \
  --store "$work/store" --mpshade "$mpshade" --size 96x54 --cpus 1 --wait
MPSHADE_STORE=off "$mpshade" render "$scene" --frames 0:6 --size 96x54 --quiet \
  --out "$work/one"
for f in 0 1 2 3 4 5; do
  name=$(printf 'frame_%04d.exr' "$f")
  idiff -fail 0 -warn 0 "$work/one/$name" "$work/farm/$name" >/dev/null ||
    { echo "farm_test: $name differs from the one-process render" >&2; exit 1; }
done
python3 - "$work/farm" <<'PY'
import glob, json, sys
stats = sorted(glob.glob(sys.argv[1] + "/stats_*.json"))
assert len(stats) == 3, stats
filled = sum(f["tiles_filled"] for s in stats for f in json.load(open(s))["frames"])
read = sum(f["tiles_from_store"] for s in stats for f in json.load(open(s))["frames"])
assert filled == 0, "the shards filled %d tile(s) the bake should have" % filled
assert read > 0, "the shards read nothing from the store"
print("farm_test: 6 frames bit-identical to one render; shards read %d tiles, filled none" % read)
PY
grep -q "baked frames 0:6" "$work"/farm/slurm-bake-*.log

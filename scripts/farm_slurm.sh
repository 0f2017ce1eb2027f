#!/usr/bin/env bash
# farm_slurm.sh -- renders a scene on a Slurm cluster (docs/store.md, "A farm"): one job
# bakes the frames' shader-map tiles into a shared store, then a job array, started once
# the bake succeeded, renders the frames in shards, each planned over the whole range so
# every frame is the bits one render of the range gives.
#
#   scripts/farm_slurm.sh SCENE --out DIR --frames A:B --shards N --store DIR
#                         [--mpshade PATH] [--size WxH] [--spp N] [--cpus N] [--wait]
#                         [-- EXTRA RENDER OPTIONS]
#
# DIR and the store must be on a file system every node sees. Prints the two job ids;
# with --wait, waits for the array and exits with its status. Retried array tasks render
# only the frames not yet written (--skip-existing).
set -euo pipefail

usage() { sed -n '2,14p' "$0" | sed 's/^# \{0,1\}//' >&2; exit 2; }

scene="" out="" frames="" shards="" store="" size="" spp="" cpus=1 wait=0
mpshade="$(command -v mpshade || true)"
extra=()
[ $# -ge 1 ] || usage
scene="$1"; shift
while [ $# -gt 0 ]; do
  case "$1" in
    --out) out="$2"; shift 2 ;;
    --frames) frames="$2"; shift 2 ;;
    --shards) shards="$2"; shift 2 ;;
    --store) store="$2"; shift 2 ;;
    --mpshade) mpshade="$2"; shift 2 ;;
    --size) size="$2"; shift 2 ;;
    --spp) spp="$2"; shift 2 ;;
    --cpus) cpus="$2"; shift 2 ;;
    --wait) wait=1; shift ;;
    --) shift; extra=("$@"); break ;;
    *) echo "farm_slurm.sh: unknown option '$1'" >&2; usage ;;
  esac
done
[ -n "$out" ] && [ -n "$frames" ] && [ -n "$shards" ] && [ -n "$store" ] || usage
[ -x "$mpshade" ] || { echo "farm_slurm.sh: no mpshade binary (--mpshade PATH)" >&2; exit 2; }
[[ "$frames" =~ ^([0-9]+):([0-9]+)$ ]] || { echo "farm_slurm.sh: --frames A:B" >&2; exit 2; }
first="${BASH_REMATCH[1]}" last="${BASH_REMATCH[2]}"
[[ "$shards" =~ ^[1-9][0-9]*$ ]] || { echo "farm_slurm.sh: --shards N, N >= 1" >&2; exit 2; }
[ "$last" -gt "$first" ] || { echo "farm_slurm.sh: --frames A:B with B > A" >&2; exit 2; }

scene="$(realpath "$scene")"
mkdir -p "$out" "$store"
out="$(realpath "$out")" store="$(realpath "$store")" mpshade="$(realpath "$mpshade")"
common=(--store "$store" --threads "$cpus")
[ -n "$size" ] && common+=(--size "$size")
[ -n "$spp" ] && common+=(--spp "$spp")
quote() { printf '%q ' "$@"; }

# The bake: every tile the frames read, filled once, into the shared store.
bake=$(sbatch --parsable --job-name=mpshade-bake --cpus-per-task="$cpus" \
  --output="$out/slurm-bake-%j.log" \
  --wrap="$(quote "$mpshade" bake "$scene" --frames "$frames" "${common[@]}")")

# The shards: contiguous chunks of the range, each planned over all of it.
chunk=$(( (last - first + shards - 1) / shards ))
render=$(quote "$mpshade" render "$scene" --out "$out" --plan-frames "$frames" \
  --shard-stats --skip-existing "${common[@]}" "${extra[@]}")
script="a=\$(( $first + SLURM_ARRAY_TASK_ID * $chunk )); b=\$(( a + $chunk )); \
[ \$b -gt $last ] && b=$last; [ \$a -ge \$b ] && exit 0; $render --frames \$a:\$b"
wait_flag=()
[ "$wait" = 1 ] && wait_flag=(--wait)
echo "mpshade farm: bake job $bake; render array of $shards shard(s) of $chunk frame(s)" >&2
array=$(sbatch --parsable "${wait_flag[@]}" --job-name=mpshade-render \
  --dependency=afterok:"$bake" --array=0-$((shards - 1)) --cpus-per-task="$cpus" \
  --output="$out/slurm-render-%A_%a.log" --wrap="$script")
echo "$bake $array"

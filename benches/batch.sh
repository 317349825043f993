#!/usr/bin/env bash
# The batch's targets (issue "A lab's archive in one command"; results in docs/performance.md):
# an archive of 200 series × 8 images × 1024² uint16 (3.4 GB, `synth-series` with seeds 1…200),
# page cache warm, on this machine's cores:
#
#   * the time to read the bytes once (`cat > /dev/null`), the floor;
#   * a shell loop of `contactscope analyze` over the series (the same per-series folders);
#   * `contactscope batch` over the archive (those folders, the tables, batch.json, the QC page,
#     and every input hashed with SHA-256);
#   * peak memory (GNU time, maximum resident set) of the batch and of one `analyze`;
#   * the tables' write time (batch.json's timings_s.tables);
#   * a re-run of the unchanged archive, and one after one file changed.
#
# The loop and the batch alternate, REPEAT times each, every run into a folder of its own made
# after the earlier ones were removed and synced (ext4 slows file creation right after many
# deletions; both suffer it alike this way). Medians are printed as a markdown table.
#
#   cargo build --release && benches/batch.sh            # ~10 min the first time (data)
#   BENCH_DIR=/data/cs-batch REPEAT=5 benches/batch.sh
set -euo pipefail
ROOT=$(cd "$(dirname "$0")/.." && pwd)
BIN=${CONTACTSCOPE_BIN:-$ROOT/target/release/contactscope}
DIR=${BENCH_DIR:-/tmp/cs-batch-bench}
SERIES=${SERIES:-200}
REPEAT=${REPEAT:-3}
TIME=/usr/bin/time
[ -x "$BIN" ] || { echo "build first: cargo build --release" >&2; exit 1; }
[ -x "$TIME" ] || { echo "GNU time is needed (Debian package time)" >&2; exit 1; }

mkdir -p "$DIR/archive"
cd "$DIR"
echo "data: $SERIES series in $DIR/archive" >&2
seq 1 "$SERIES" | xargs -P "$(nproc)" -I{} sh -c \
  'n=$(printf %03d {}); [ -f archive/s$n/manifest.csv ] || "$0" synth-series --size 1024 --seed {} --out archive/s$n >/dev/null' "$BIN"
bytes=$(cat archive/*/series.tif | wc -c)

now() { date +%s.%N; }
median() { sort -g | awk '{a[NR]=$1} END {print (NR % 2) ? a[(NR+1)/2] : (a[NR/2] + a[NR/2+1]) / 2}'; }
fresh() { rm -rf "$DIR"/run-*; sync; sleep 2; }

cat archive/*/series.tif >/dev/null
cat_s=()
for _ in 1 2 3; do
  t0=$(now); cat archive/*/series.tif >/dev/null; t1=$(now)
  cat_s+=("$(echo "$t1 - $t0" | bc -l)")
done

loop_s=(); batch_s=(); batch_kb=(); batch_cpu=()
for r in $(seq 1 "$REPEAT"); do
  fresh
  mkdir "run-loop-$r"
  t0=$(now)
  for d in archive/s*; do "$BIN" analyze "$d" --out "run-loop-$r/$(basename "$d")" -q >/dev/null; done
  t1=$(now)
  loop_s+=("$(echo "$t1 - $t0" | bc -l)")
  fresh
  t0=$(now)
  "$TIME" -f "%M %U %S" -o mem.txt "$BIN" batch archive --out "run-batch-$r" -q >/dev/null
  t1=$(now)
  batch_s+=("$(echo "$t1 - $t0" | bc -l)")
  read -r kb user sys < mem.txt
  batch_kb+=("$kb")
  batch_cpu+=("$(echo "$user + $sys" | bc -l)")
  echo "run $r: loop ${loop_s[-1]} s, batch ${batch_s[-1]} s, ${batch_kb[-1]} kB" >&2
done
last="run-batch-$REPEAT"
tables_s=$(python3 -c "import json,sys; print(json.load(open('$last/batch.json'))['timings_s']['tables'])")
"$TIME" -f %M -o mem.txt "$BIN" analyze archive/s001 --out analyze-one -q >/dev/null
one_kb=$(cat mem.txt)
rm -rf analyze-one

rerun_s=()
for _ in 1 2 3; do
  t0=$(now); "$BIN" batch archive --out "$last" -q >/dev/null; t1=$(now)
  rerun_s+=("$(echo "$t1 - $t0" | bc -l)")
done
# One file changed: series 100 gets another seed's images (restored afterwards).
cp archive/s100/series.tif series100.tif.bak
"$BIN" synth-series --size 1024 --seed 9999 --out changed >/dev/null
cp changed/series.tif archive/s100/series.tif
t0=$(now); out=$("$BIN" batch archive --out "$last" -q); t1=$(now)
changed_s=$(echo "$t1 - $t0" | bc -l)
changed_line=$(echo "$out" | grep '^batch:')
mv series100.tif.bak archive/s100/series.tif
rm -rf changed
"$BIN" batch archive --out "$last" -q >/dev/null

m() { printf '%s\n' "$@" | median; }
loop=$(m "${loop_s[@]}"); batch=$(m "${batch_s[@]}"); catm=$(m "${cat_s[@]}")
rerun=$(m "${rerun_s[@]}"); kb=$(m "${batch_kb[@]}"); cpu=$(m "${batch_cpu[@]}")
gb=$(echo "$bytes / 1000000000" | bc -l)
cat <<EOF

| what | median of $REPEAT (3 for cat and re-runs) |
|---|---|
| data | $SERIES series, $(printf '%.2f' "$gb") GB |
| \`cat\` of every TIFF to /dev/null | $(printf '%.2f' "$catm") s ($(printf '%.1f' "$(echo "$gb / $catm" | bc -l)") GB/s) |
| shell loop of \`analyze\` | $(printf '%.2f' "$loop") s |
| \`batch\` | $(printf '%.2f' "$batch") s ($(printf '%.2f' "$(echo "$gb / $batch" | bc -l)") GB/s of image data, hashing included) |
| \`batch\` CPU time (user + system) | $(printf '%.2f' "$cpu") s on $(nproc) cores |
| loop / batch | $(printf '%.2f' "$(echo "$loop / $batch" | bc -l)")× |
| peak memory: batch / one \`analyze\` | $kb kB / $one_kb kB ($(printf '%.2f' "$(echo "$kb / $one_kb" | bc -l)")×) |
| tables written (1,600 image rows) | $(printf '%.4f' "$tables_s") s |
| re-run, unchanged | $(printf '%.3f' "$rerun") s ($(printf '%.1f' "$(echo "100 * $rerun / $batch" | bc -l)") % of the batch) |
| re-run, one file changed | $(printf '%.3f' "$changed_s") s: $changed_line |
EOF
rm -rf "$DIR"/run-* mem.txt

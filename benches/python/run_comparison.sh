#!/usr/bin/env bash
# contactscope CLI vs tifffile + scikit-image on the same files, plus peak memory.
#
#   benches/python/run_comparison.sh            # from the repository root, after `cargo build --release`
#
# Generates under /tmp/cs-bench (override with CS_BENCH_DIR; nothing is written in the repo):
#   cmp/files_raw       40 × 1024² uint16 single-page TIFFs (contactscope synth-series --layout files)
#   cmp/multipage_raw   the same 40 images as one multi-page TIFF
#   cmp/files_lzw       files_raw re-saved by tifffile with compression='lzw'
#   cmp/multipage_lzw   multipage_raw re-saved the same way
#   big/files, big/multipage   500 × 512² series (peak-memory check)
# and writes results/: hyperfine JSON, python_baseline JSON, peak RSS table, agreement check.
#
# Needs: hyperfine and GNU time (/usr/bin/time), python3 with tifffile, scikit-image, imagecodecs
# (pip install tifffile scikit-image imagecodecs). Falls back to a bash timing loop without
# hyperfine.
set -euo pipefail

REPO=$(cd "$(dirname "$0")/../.." && pwd)
ROOT=${CS_BENCH_DIR:-/tmp/cs-bench}
CS=$REPO/target/release/contactscope
PY=$REPO/benches/python/python_baseline.py
RUNS=${RUNS:-10}
RES=$ROOT/results
mkdir -p "$ROOT/cmp" "$ROOT/big" "$RES"

if [[ ! -x $CS ]]; then
    (cd "$REPO" && cargo build --release)
fi
command -v hyperfine >/dev/null || apt-get install -y hyperfine >/dev/null 2>&1 || true
[[ -x /usr/bin/time ]] || apt-get install -y time >/dev/null 2>&1

# The forces: 40 (and 500) log-spaced 4…400 mN, three decimals (benches/series.rs builds the
# same 40-force string).
forces() { python3 -c "import sys; n=int(sys.argv[1]); print(','.join(f'{4*100**(i/(n-1)):.3f}' for i in range(n))+'mN')" "$1"; }
F40=$(forces 40)
F500=$(forces 500)

machine() {
    echo "nproc: $(nproc)"
    grep -m1 'model name' /proc/cpuinfo
    free -g | sed -n 2p
    uname -r
    rustc --version
    "$CS" --version
    python3 -c 'import sys,numpy,tifffile,skimage,imagecodecs; print("python", sys.version.split()[0], "numpy", numpy.__version__, "tifffile", tifffile.__version__, "scikit-image", skimage.__version__, "imagecodecs", imagecodecs.__version__)'
    hyperfine --version 2>/dev/null || true
}
machine | tee "$RES/machine.txt"

# ---- data -----------------------------------------------------------------------------------
gen() { # layout out size forces
    [[ -e $2/manifest.csv ]] || "$CS" synth-series --size "$3" --forces "$4" --layout "$1" --out "$2" >/dev/null
}
echo "generating data under $ROOT …"
gen files "$ROOT/cmp/files_raw" 1024 "$F40"
gen multipage "$ROOT/cmp/multipage_raw" 1024 "$F40"
[[ -e $ROOT/cmp/files_lzw/load_40.tif ]] || python3 "$PY" --to-lzw "$ROOT/cmp/files_raw" "$ROOT/cmp/files_lzw"
[[ -e $ROOT/cmp/multipage_lzw/series.tif ]] || python3 "$PY" --to-lzw "$ROOT/cmp/multipage_raw/series.tif" "$ROOT/cmp/multipage_lzw"
gen files "$ROOT/big/files" 512 "$F500"
gen multipage "$ROOT/big/multipage" 512 "$F500"
du -sh "$ROOT"/cmp/* "$ROOT"/big/* | tee "$RES/sizes.txt"
"$CS" info "$ROOT/cmp/multipage_lzw/series.tif" | tee "$RES/info_multipage_lzw.txt"

declare -A INPUT=(
    [files_raw]=$ROOT/cmp/files_raw
    [multipage_raw]=$ROOT/cmp/multipage_raw/series.tif
    [files_lzw]=$ROOT/cmp/files_lzw
    [multipage_lzw]=$ROOT/cmp/multipage_lzw/series.tif
)
LAYOUTS=(files_raw multipage_raw files_lzw multipage_lzw)

# ---- contactscope timings -------------------------------------------------------------------
cs_cmd() { # layout memory_mib
    echo "$CS analyze ${INPUT[$1]} --forces $F40 --out $ROOT/out/$1-m$2 --quiet --memory-mib $2"
}
for layout in "${LAYOUTS[@]}"; do
    for mem in 128 0; do
        cmd=$(cs_cmd "$layout" "$mem")
        if command -v hyperfine >/dev/null; then
            hyperfine --warmup 2 --runs "$RUNS" -N --export-json "$RES/hyperfine_${layout}_m$mem.json" \
                --command-name "contactscope $layout --memory-mib $mem" "$cmd"
        else
            $cmd # warm-up
            for _ in $(seq "$RUNS"); do
                s=$(date +%s.%N); $cmd; e=$(date +%s.%N)
                echo "$e - $s" | bc
            done | tee "$RES/loop_${layout}_m$mem.txt"
        fi
    done
done

# ---- python baseline (one process per layout, so peak RSS is per layout) ---------------------
for layout in "${LAYOUTS[@]}"; do
    /usr/bin/time -v -o "$RES/time_python_$layout.txt" \
        python3 "$PY" --runs 5 --forces "$F40" --out "$ROOT/python-out" "$layout=${INPUT[$layout]}" \
        >"$RES/python_$layout.json"
    python3 -c "import json,sys; r=json.load(open(sys.argv[1]))['layouts'][sys.argv[2]]; print(f\"python {sys.argv[2]}: best {r['best_s']:.3f} s, median {r['median_s']:.3f} s, phases {r['best_phases_s']}\")" \
        "$RES/python_$layout.json" "$layout"
done

# ---- 500 × 512² timings (contactscope; the python run is in the peak-RSS section below) ------
command -v hyperfine >/dev/null && for layout in files multipage; do
    input=$ROOT/big/$layout
    [[ $layout == multipage ]] && input=$input/series.tif
    for mem in 128 0; do
        hyperfine --warmup 1 --runs 5 -N --export-json "$RES/hyperfine_big_${layout}_m$mem.json" \
            --command-name "contactscope 500x512 $layout --memory-mib $mem" \
            "$CS analyze $input --forces $F500 --out $ROOT/out/bigh-$layout-m$mem --quiet --memory-mib $mem"
    done
done

# ---- peak RSS --------------------------------------------------------------------------------
rss() { # label command…
    local label=$1; shift
    /usr/bin/time -v -o "$RES/time_$label.txt" "$@" >"$RES/stdout_$label.txt"
    printf '%-34s %8.1f MB  %6s s\n' "$label" \
        "$(awk '/Maximum resident/ {print $6/1024}' "$RES/time_$label.txt")" \
        "$(awk -F': ' '/Elapsed/ {print $2}' "$RES/time_$label.txt")"
}
{
    echo "# peak RSS (GNU time 'Maximum resident set size', MiB) and wall time"
    for layout in "${LAYOUTS[@]}"; do
        for mem in 128 0; do
            # shellcheck disable=SC2046
            rss "cs_40x1024_${layout}_m$mem" $(cs_cmd "$layout" "$mem")
        done
    done
    for layout in files multipage; do
        input=$ROOT/big/$layout
        [[ $layout == multipage ]] && input=$input/series.tif
        for mem in 128 32 0; do
            rss "cs_500x512_${layout}_m$mem" "$CS" analyze "$input" --forces "$F500" \
                --out "$ROOT/out/big-$layout-m$mem" --quiet --memory-mib "$mem"
        done
    done
    for layout in "${LAYOUTS[@]}"; do
        printf '%-34s %8.1f MB  (5 runs + warm-up in one process)\n' "python_40x1024_$layout" \
            "$(awk '/Maximum resident/ {print $6/1024}' "$RES/time_python_$layout.txt")"
    done
    rss python_500x512_files python3 "$PY" --runs 3 --forces "$F500" --out "$ROOT/python-out" \
        "big_files=$ROOT/big/files"
} | tee "$RES/peak_rss.txt"

# ---- agreement: thresholds and contact pixels ------------------------------------------------
python3 - "$ROOT" "$RES" <<'PYEOF' | tee "$RES/agreement.txt"
import csv, json, sys
root, res = sys.argv[1], sys.argv[2]
for layout in ["files_raw", "multipage_raw", "files_lzw", "multipage_lzw"]:
    py = json.load(open(f"{res}/python_{layout}.json"))["layouts"][layout]
    for mem in (128, 0):
        rows = list(csv.DictReader(open(f"{root}/out/{layout}-m{mem}/areas.csv")))
        t = {float(r["threshold"]) for r in rows}
        cs = [int(r["contact_pixels"]) for r in rows]
        diff = [a - b for a, b in zip(cs, py["contact_pixels"])]
        print(f"{layout:14} m{mem:<3}: threshold contactscope {sorted(t)} python {py['threshold']}; "
              f"contact pixels {sum(cs)} vs {py['contact_pixels_total']} "
              f"(difference {sum(cs) - py['contact_pixels_total']}, max per image {max(map(abs, diff))})")
# 500 × 512²: contactscope (both layouts, every budget) against the python run on big/files
py = list(csv.DictReader(open(f"{root}/python-out/big_files.csv")))
for layout in ["files", "multipage"]:
    for mem in (128, 32, 0):
        cs = list(csv.DictReader(open(f"{root}/out/big-{layout}-m{mem}/areas.csv")))
        a = [int(r["contact_pixels"]) for r in cs]
        b = [int(r["contact_pixels"]) for r in py]
        print(f"500x512 {layout:9} m{mem:<3}: threshold contactscope {sorted({float(r['threshold']) for r in cs})} "
              f"python {sorted({float(r['threshold']) for r in py})}; contact pixels {sum(a)} vs {sum(b)} "
              f"(max per image {max(abs(x - y) for x, y in zip(a, b))})")
# every column of one layout
cs = list(csv.DictReader(open(f"{root}/out/files_raw-m0/areas.csv")))
py = list(csv.DictReader(open(f"{root}/python-out/files_raw.csv")))
for k in ["contact_pixels", "area_um2", "mean_intensity", "integrated_intensity", "background_mean",
          "patches", "largest_patch_um2", "mean_pressure_MPa", "equivalent_radius_um"]:
    rel = max(abs(float(a[k]) - float(b[k])) / max(abs(float(b[k])), 1e-300) for a, b in zip(cs, py))
    print(f"files_raw column {k:22} max relative difference {rel:.1e}")
PYEOF

# ---- summaries ---------------------------------------------------------------------------------
python3 - "$RES" "$REPO" <<'PYEOF' | tee "$RES/summary.txt"
import glob, json, os, sys
res, repo = sys.argv[1], sys.argv[2]
print("hyperfine (contactscope analyze, whole CLI run incl. plots and summary.json):")
for p in sorted(glob.glob(f"{res}/hyperfine_*.json")):
    r = json.load(open(p))["results"][0]
    print(f"  {r['command']:60} mean {r['mean']*1e3:7.1f} ± {r['stddev']*1e3:5.1f} ms  "
          f"median {r['median']*1e3:7.1f} ms  user {r['user']*1e3:6.1f}  system {r['system']*1e3:6.1f} ms")
print("python baseline (in-process, best / median of 5 after a warm-up):")
for p in sorted(glob.glob(f"{res}/python_*.json")):
    for name, r in json.load(open(p))["layouts"].items():
        ph = " ".join(f"{k} {v*1e3:.0f}" for k, v in r["best_phases_s"].items())
        print(f"  {name:14} best {r['best_s']*1e3:7.1f} ms  median {r['median_s']*1e3:7.1f} ms  (best run: {ph} ms)")
crit = os.path.join(repo, "target/criterion")
if os.path.isdir(crit):
    print("criterion (last `cargo bench --bench series`, estimates of the 'new' run):")
    for p in sorted(glob.glob(f"{crit}/*/*/new/estimates.json")):
        e = json.load(open(p))
        name = "/".join(p.split(os.sep)[-4:-2])
        print(f"  {name:42} mean {e['mean']['point_estimate']/1e6:9.3f} ms  "
              f"median {e['median']['point_estimate']/1e6:9.3f} ms  sd {e['std_dev']['point_estimate']/1e6:7.3f} ms")
PYEOF
echo "results in $RES"

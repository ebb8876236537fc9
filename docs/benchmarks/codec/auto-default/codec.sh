#!/bin/bash
# Issue 18: default codec (zstd where it saves >= 1/8, decoded in parallel during device creation)
# against --codec none; per-pass pipeline build times, cold and warm.
set -u
cd "$(dirname "$0")"
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $OUT/gpu.txt
nproc >> $OUT/gpu.txt
R=$OUT/runs; mkdir -p $R
C="./kiln compile pica_pica/scene.gltf --config ../tests/scenes/pica_pica.toml"
( time $C -o auto.kiln ) > $OUT/compile-auto.txt 2>&1
$C -o none.kiln --codec none > $OUT/compile-none.txt 2>&1
$C -o zstd.kiln --codec zstd > $OUT/compile-zstd.txt 2>&1
for f in auto none zstd; do ./kiln inspect $f.kiln > $OUT/inspect-$f.txt 2>&1; done
ls -l *.kiln pica_pica/scene.* > $OUT/sizes.txt; du -sb pica_pica >> $OUT/sizes.txt
P="--bench --json --size 1600x900 --frames 20"
cold() { n=$1; f=$2; shift 2; __GL_SHADER_DISK_CACHE=0 ./kiln-play $f.kiln $P --no-pipeline-cache "$@" > $R/$n.json 2> $R/$n.err; }
warm() { n=$1; f=$2; shift 2; ./kiln-play $f.kiln $P "$@" > $R/$n.json 2> $R/$n.err; }
for i in 1 2 3; do cold cold-auto-$i auto; cold cold-none-$i none; done
warm fill auto
for i in 1 2 3 4 5; do warm warm-auto-$i auto; warm warm-none-$i none; warm warm-zstd-$i zstd; done
python3 - <<'PY' > $OUT/summary.txt
import json,glob,os,statistics as st
R=os.environ['OUT']+'/runs'
rows={}
for f in sorted(glob.glob(R+'/*.json')):
    n=os.path.basename(f)[:-5]
    try: l=json.load(open(f))['load']
    except Exception as e: print(n,'ERR',e); continue
    k=n.rsplit('-',1)[0]
    rows.setdefault(k,[]).append(l)
    print(n, 'first', round(l['first_frame_since_start_ms'],1), 'dev', round(l['instance_and_device_ms'],1), 'prep', round(l['prepare_ms'],1), 'decwall', round(l['decode_wall_ms'],1), 'dec', round(l['decode_ms'],1), 'pipes', round(l['pipelines_ms'],1), 'upload', round(l['upload_ms'],1), [(p['pass'],round(p['ms'],1)) for p in l['pipelines_by_pass']])
for k,ls in rows.items():
    print(k,'median first',st.median(l['first_frame_since_start_ms'] for l in ls))
PY
cat $OUT/summary.txt

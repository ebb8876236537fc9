#!/bin/bash
# Issue 18 final figures: file sizes (pica_pica, cornell_box; default, none, zstd, rgba8) and the
# first frame warm and cold, textures streamed (default) or not.
set -u
cd "$(dirname "$0")"
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $OUT/gpu.txt
C="./kiln compile pica_pica/scene.gltf --config ../tests/scenes/pica_pica.toml -q"
$C -o auto.kiln; $C -o none.kiln --codec none; $C -o zstd.kiln --codec zstd; $C -o rgba8.kiln --texture-format rgba8
K="./kiln compile cornell_box/scene.gltf --config ../tests/scenes/cornell_box.toml -q"
$K -o cb-auto.kiln; $K -o cb-none.kiln --codec none; $K -o cb-zstd.kiln --codec zstd
ls -l *.kiln > $OUT/sizes.txt; du -sb pica_pica cornell_box >> $OUT/sizes.txt
./kiln inspect auto.kiln > $OUT/inspect-auto.txt 2>&1; ./kiln inspect cb-auto.kiln > $OUT/inspect-cb-auto.txt 2>&1
R=/tmp/runs; mkdir -p $R
P="--bench --json --size 1600x900 --frames 20"
cold() { n=$1; shift; __GL_SHADER_DISK_CACHE=0 ./kiln-play auto.kiln $P --no-pipeline-cache "$@" > $R/$n.json 2> $R/$n.err; }
warm() { n=$1; shift; ./kiln-play auto.kiln $P "$@" > $R/$n.json 2> $R/$n.err; }
for i in 1 2 3 4 5; do cold cold-stream-$i; cold cold-whole-$i --no-texture-streaming; done
warm fill; warm fill2
for i in 1 2 3 4 5; do warm warm-stream-$i; warm warm-whole-$i --no-texture-streaming; done
python3 - <<'PY' > $OUT/summary.txt
import json,glob,os,statistics as st
R='/tmp/runs'; rows={}
for f in sorted(glob.glob(R+'/*.json')):
    n=os.path.basename(f)[:-5]
    try: l=json.load(open(f))['load']
    except Exception as e: print(n,'ERR',e); continue
    rows.setdefault(n.rsplit('-',1)[0],[]).append(l)
    print(n,'first',round(l['first_frame_since_start_ms'],1),'resident',round(l['resident_since_start_ms'],1),'refined',round(l.get('textures_refined_since_start_ms',0),1),'coarse',l.get('coarse_texture_bytes'),'fine',l.get('refined_texture_bytes'),'dev',round(l['instance_and_device_ms'],1),'decwall',round(l['decode_wall_ms'],1),'pipes',round(l['pipelines_ms'],1),'upload',round(l['upload_ms'],1),'rest',round(l['rest_upload_ms'],1),[(p['pass'],round(p['ms'],1)) for p in l['pipelines_by_pass']])
for k,ls in rows.items():
    print(k,'median first',round(st.median(l['first_frame_since_start_ms'] for l in ls),1),'median refined',round(st.median(l.get('textures_refined_since_start_ms',0) for l in ls),1),'median upload',round(st.median(l['upload_ms'] for l in ls),1))
PY
cat $OUT/summary.txt | tail -6

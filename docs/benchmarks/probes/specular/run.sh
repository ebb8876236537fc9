#!/bin/bash
set -u
cd "$(dirname "$0")"; mkdir -p /tmp/p; tar xzf pack.tgz -C /tmp/p
B=/tmp/p/bin; S=/tmp/p/scenes
L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
$B/kiln compile $S/box/CornellBox-Original.obj -c $S/box/camera.toml --shaft-variants none -o /tmp/box.kiln -q >> $L 2>&1
echo "== pica" >> $L
timeout 250 $B/kiln-bench $S/pica.kiln --effects frame --techniques frame:probes,frame:baked --frames-accumulated 1,4 --size 1600x900 --reference-spp 2048 -q -o /tmp/bo --json > $OUT/pica.json 2>> $L
echo "bench rc=$?" >> $L
timeout 250 $B/kiln-bench $S/pica.kiln --effects frame --techniques frame:probes --frames-accumulated 1,4 --size 1600x900 --reference-spp 4096 -q -o /tmp/bo4 >> $L 2>&1
echo "== box" >> $L
timeout 250 $B/kiln-bench /tmp/box.kiln --effects frame --techniques frame:probes --frames-accumulated 1,4 --size 1600x900 --reference-spp 4096 -q -o /tmp/bb --json > $OUT/box.json 2>> $L
echo "bench rc=$?" >> $L
for f in pica box; do python3 -c "
import json,sys
r=json.load(open('$OUT/$f.json'))
for p in r['points']: print('$f', p['label'], round(p['frame_ms'],3), round(p['error']['flip'],4))
" >> $L; done
echo "== timing" >> $L
timeout 60 $B/kiln-play $S/pica.kiln --headless --bench --frames 200 --size 1600x900 --gbuffer visibility >> $L 2>&1

#!/bin/bash
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
cd /tmp
$B/kiln compile $S/pica_pica/scene.gltf --config $S/pica_pica.toml --shaft-variants none -o pica.kiln -q >> $L 2>&1
$B/kiln compile $S/box/CornellBox-Original.obj -c $S/box/camera.toml --shaft-variants none -o box.kiln -q >> $L 2>&1
echo "== pica frame chart" >> $L
( time timeout 280 $B/kiln-bench pica.kiln --effects frame --frames-accumulated 1,4,64 --size 1600x900 --reference-spp 4096 -q -o /tmp/bp --json > $OUT/pica.json ) 2>> $L
cp /tmp/bp/results.json $OUT/pica-results.json 2>/dev/null
echo "== box frame chart" >> $L
( time timeout 200 $B/kiln-bench box.kiln --effects frame --techniques frame:probes,frame:baked,frame:rt-4 --frames-accumulated 1,4,64 --size 1600x900 --reference-spp 4096 -q -o /tmp/bb --json > $OUT/box.json ) 2>> $L
for f in pica box; do python3 -c "
import json
r=json.load(open('$OUT/$f.json'))
for p in r['points']:
  e=p['error']; print('$f', p['label'], round(p['frame_ms'],3), round(e['flip'],4), '%.3g'%e['relmse'])
" >> $L 2>&1; done
echo "== timing" >> $L
timeout 60 $B/kiln-play pica.kiln --headless --bench --frames 200 --size 1600x900 --gbuffer visibility >> $L 2>&1
timeout 60 $B/kiln-play pica.kiln --headless --bench --frames 200 --size 1600x900 >> $L 2>&1

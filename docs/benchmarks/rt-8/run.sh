#!/bin/bash
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
cd /tmp
$B/kiln compile $S/box/CornellBox-Original.obj -c $S/box/camera.toml -o box.kiln -q >> $L 2>&1
$B/kiln compile $S/pica_pica/scene.gltf --config $S/pica_pica.toml --shaft-variants none -o pica.kiln -q >> $L 2>&1
for s in box pica; do
( time timeout 280 $B/kiln-bench $s.kiln --effects frame --frames-accumulated 1,4,64 --size 1600x900 --reference-spp 4096 -q -o /tmp/b$s --json > $OUT/$s.json ) 2>> $L
python3 -c "
import json
r=json.load(open('$OUT/$s.json'))
for p in r['points']:
  e=p['error']; print('$s', p['label'], p.get('frames'), round(p['frame_ms'],3), round(e['flip'],4), '%.3g'%e['rel_mse'])
" >> $L 2>&1
done
echo done >> $L

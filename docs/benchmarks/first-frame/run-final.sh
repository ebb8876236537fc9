#!/bin/bash
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
cd /tmp
$B/kiln compile $S/pica_pica/scene.gltf --config $S/pica_pica.toml --shaft-variants none -o pica.kiln -q >> $L 2>&1
( time timeout 280 $B/kiln-bench pica.kiln --effects frame --frames-accumulated 1,4,64 --size 1600x900 --reference-spp 4096 -q -o /tmp/bp --json > $OUT/pica.json ) 2>> $L
python3 -c "
import json
r=json.load(open('$OUT/pica.json'))
for p in r['points']:
  e=p['error']; print('pica', p['label'], round(p['frame_ms'],3), round(e['flip'],4), '%.3g'%e['rel_mse'])
" >> $L 2>&1

#!/bin/bash
# probes, probes-rt and probes-rt-refl on four scenes, 1600x900: FLIP at 1 and 16 frames against
# a 2048-spp reference, GPU ms (medians of 100 frames).
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w6; mkdir -p $W
L=$OUT/log6.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
comp() { local name=$1; shift; $B/kiln compile "$@" -o $W/$name.kiln -q > $W/$name.compile.txt 2>&1; echo "compile $name rc=$?" >> $L; }
comp toycar $S/toycar/glTF/ToyCar.gltf --environment studio
comp lamp $S/lamp/glTF/LightsPunctualLamp.gltf --environment studio
comp helmet $S/helmet/glTF-Binary/DamagedHelmet.glb --environment studio
comp pica $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none
SZ=1600x900
for n in toycar lamp helmet pica; do
  timeout 100 $B/kiln-play $W/$n.kiln --reference --spp 2048 --size $SZ -o $W/$n-ref.exr 2>&1 | tail -1 >> $L
  for p in probes probes-rt probes-rt-refl; do
    for fr in 1 16; do
      echo "== $n $p $fr frames" >> $L
      timeout 60 $B/kiln-play $W/$n.kiln --headless --size $SZ --preset $p --frames $fr -o $W/x.exr > /dev/null 2>>$W/err.txt || echo FAILED >> $L
      $B/kiln-bench --diff $W/$n-ref.exr $W/x.exr -o $W/d 2>&1 | head -1 >> $L
    done
    timeout 60 $B/kiln-play $W/$n.kiln --headless --size $SZ --preset $p --bench --frames 100 --json > $W/b.json 2>/dev/null
    python3 -c "
import json; d=json.load(open('$W/b.json')); ps=d['passes']
print('ms', ' '.join('%s=%.3f'%(p['pass'],p['median_ms']) for p in ps if p['pass'] in ('total','reflections','ssr')))" >> $L 2>&1
  done
done
echo done >> $L

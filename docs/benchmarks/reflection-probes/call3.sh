#!/bin/bash
# Reflection hits lit by the probes: pica_pica and the McGuire box, old and new binary, 1600x900.
set -u
B=/tmp/p/bin; S=/tmp/p/scenes; W=/tmp/w3; mkdir -p $W
L=$OUT/log3.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
$B/kiln compile $S/pica_pica/scene.gltf -c $S/pica_pica.toml --shaft-variants none -o $W/pica.kiln -q > $W/c1.txt 2>&1; echo "compile pica rc=$?" >> $L
$B/kiln compile $S/mcguire/CornellBox-Original.obj -c $S/mcguire/camera.toml --shaft-variants none -o $W/box.kiln -q > $W/c2.txt 2>&1; echo "compile box rc=$?" >> $L
SZ=1600x900
for f in pica box; do
  timeout 150 $B/kiln-play $W/$f.kiln --reference --spp 4096 --size $SZ -o $W/${f}_ref.exr > /dev/null 2>>$L; echo "ref $f rc=$?" >> $L
done
run() { local bin=$1 f=$2 name=$3; shift 3; echo "== $bin $f $name: $*" >> $L; timeout 60 $B/$bin $W/$f.kiln --headless --size $SZ "$@" -o $W/x.exr > /dev/null 2>>$W/play.txt || echo "FAILED" >> $L; $B/kiln-bench --diff $W/${f}_ref.exr $W/x.exr -o $W/d | grep hdr-flip >> $L; cp $W/d/flip.png $OUT/${f}_${name}_${bin}.png 2>/dev/null; }
for f in pica box; do
 for bin in kiln-play-old kiln-play; do
  run $bin $f rt8_64 --preset rt-8 --frames 64
  run $bin $f rt_16 --preset rt --frames 16
  run $bin $f prtr_1 --preset probes-rt --reflections rt --frames 1
  run $bin $f prtr_16 --preset probes-rt --reflections rt --frames 16
 done
 run kiln-play $f prt_16 --preset probes-rt --frames 16
 run kiln-play $f prtrh_16 --preset probes-rt --reflections rt --reflection-res half --frames 16
done
rm -f $OUT/*old*.png $OUT/*rt_16*.png $OUT/*prtr_1_*.png $OUT/*prtrh*
# Frame times (medians of 200 frames), alternating binaries.
for r in 1 2; do for f in pica box; do for bin in kiln-play-old kiln-play; do
  for args in "--preset probes-rt" "--preset probes-rt --reflections rt" "--preset probes-rt --reflections rt --reflection-res half" "--preset rt"; do
    echo "== time r$r $bin $f $args" >> $L
    timeout 60 $B/$bin $W/$f.kiln --headless --size $SZ $args --bench --frames 200 --json > $W/b.json 2>/dev/null
    python3 -c "
import json; d=json.load(open('$W/b.json')); ps=d['passes']
print(' '.join('%s=%.3f'%(p['pass'],p['median_ms']) for p in ps if p['pass'] in ('total','reflections','probes','shadows')))" >> $L 2>&1
  done
done; done; done
echo done >> $L

#!/usr/bin/env bash
# Issue 14 (final code): seed 000's 20-row table at 1920x1080 on pica_pica and cornell_box
# (pixel rotation; row 19 also tile), SSR timings against rt reflections, the reflections chart.
set -uo pipefail
for f in .gl/*.deb; do dpkg -x "$f" / >/dev/null; done; ldconfig
B=.devrun/new
S=.devrun/scenes
[ -f /tmp/pica.kiln ] || $B/kiln compile $S/pica_pica/scene.gltf --config $S/pica_pica.toml --shaft-variants none -q -o /tmp/pica.kiln
[ -f /tmp/cornell.kiln ] || $B/kiln compile $S/cornell_box/scene.gltf --config $S/cornell_box.toml --shaft-variants none -q -o /tmp/cornell.kiln
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/gpu.txt 2>&1
bench() { local scene=$1 name=$2; shift 2; $B/kiln-play /tmp/$scene.kiln --bench --json --size 1920x1080 --frames 100 "$@" > $OUT/bench-$scene-$name.json 2>> $OUT/log.txt; }
for scene in pica cornell; do
  bench $scene base --gbuffer visibility
  row=0
  for mip in nearest voting; do
    for res in quarter half; do
      for n in 16 32 64 128 256; do
        row=$((row+1))
        bench $scene row$row --gbuffer visibility --gi ssgi --ssgi-mip $mip --ssgi-res $res --ssgi-samples $n
      done
    done
  done
  bench $scene row19-tile --gbuffer visibility --gi ssgi --ssgi-rotation tile
  bench $scene full128 --gbuffer visibility --gi ssgi --ssgi-res full
  bench $scene rtgi --gbuffer visibility --gi rt
  bench $scene ssr --gbuffer visibility --reflections ssr
  for st in 16 32 96; do bench $scene ssr-$st --gbuffer visibility --reflections ssr --ssr-steps $st; done
  bench $scene rtrefl --gbuffer visibility --reflections rt
  bench $scene rtrefl-half --gbuffer visibility --reflections rt --reflection-res half
  bench $scene ssr-ssgi --gbuffer visibility --reflections ssr --gi ssgi
done
echo "benches done $(date)" >> $OUT/log.txt
/usr/bin/time -f "wall %e s" timeout 280 $B/kiln-bench /tmp/pica.kiln --effects reflections --techniques reflections:none,reflections:rt,reflections:ssr --size 1600x900 --reference-spp 512 --out /tmp/o-refl -q >> $OUT/log.txt 2>&1
mkdir -p $OUT/sweep-refl; (cd /tmp/o-refl && cp results.json results.csv index.html *.svg $OUT/sweep-refl/ 2>/dev/null)
for t in "none" "ssr --reflections ssr" "rtrefl --reflections rt" "ssgi --gi ssgi" "ssgitile --gi ssgi --ssgi-rotation tile"; do
  set -- $t; n=$1; shift
  $B/kiln-play /tmp/pica.kiln -o $OUT/pica-$n.exr --size 960x540 --frames 16 --gbuffer visibility "$@" 2>> $OUT/log.txt
done
$B/kiln-play /tmp/pica.kiln -o $OUT/pica-ssgi-1f.exr --size 960x540 --frames 2 --gbuffer visibility --gi ssgi --ssgi-frames 1 2>> $OUT/log.txt
$B/kiln-play /tmp/pica.kiln -o $OUT/pica-ssgitile-1f.exr --size 960x540 --frames 2 --gbuffer visibility --gi ssgi --ssgi-frames 1 --ssgi-rotation tile 2>> $OUT/log.txt
cd $OUT && tar czf /tmp/r.tgz . && find $OUT -mindepth 1 -delete && mv /tmp/r.tgz $OUT/

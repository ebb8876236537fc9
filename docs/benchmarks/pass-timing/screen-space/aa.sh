#!/usr/bin/env bash
# Issue 14: GPU times of taa, the reprojected history, sao and gtao at 1920x1080 on pica_pica;
# kiln-bench's aa and ao charts; the moving-camera chart along a 60-frame path.
set -uo pipefail
for f in .gl/*.deb; do dpkg -x "$f" / >/dev/null; done; ldconfig
B=.devrun/new
S=.devrun/scenes
[ -f /tmp/pica.kiln ] || $B/kiln compile $S/pica_pica/scene.gltf --config $S/pica_pica.toml --shaft-variants none -q -o /tmp/pica.kiln
nvidia-smi --query-gpu=name,driver_version --format=csv > $OUT/gpu.txt 2>&1
bench() { local name=$1; shift; $B/kiln-play /tmp/pica.kiln --bench --json --size 1920x1080 --frames 100 "$@" > $OUT/bench-$name.json 2>> $OUT/log.txt; }
bench base --gbuffer visibility
bench taa --gbuffer visibility --aa taa
bench sao-half --gbuffer visibility --ao sao
bench sao-full --gbuffer visibility --ao sao --ao-res full
bench gtao --gbuffer visibility --ao gtao
bench gtao-hi --gbuffer visibility --ao gtao --ao-slices 4 --ao-steps 6
bench rtao --gbuffer visibility --ao rt
bench rt --gbuffer visibility --shadows rt --ao rt --reflections rt
bench rt-reproject --gbuffer visibility --shadows rt --ao rt --reflections rt --aa reproject --camera-path $S/pica_path.txt
bench rt-taa --gbuffer visibility --shadows rt --ao rt --reflections rt --aa taa --camera-path $S/pica_path.txt
echo "benches done $(date)" >> $OUT/log.txt
/usr/bin/time -f "wall %e s" $B/kiln-bench /tmp/pica.kiln --effects aa,ao --size 1600x900 --reference-spp 512 --out /tmp/o-charts -q >> $OUT/log.txt 2>&1
/usr/bin/time -f "wall %e s" $B/kiln-bench /tmp/pica.kiln --effects frame --techniques frame:baked,frame:baked-taa,frame:rt,frame:rt-reproject,frame:rt-taa --camera-path $S/pica_path.txt --path-frames 60 --size 1600x900 --reference-spp 512 --out /tmp/o-path -q >> $OUT/log.txt 2>&1
for n in charts path; do mkdir -p $OUT/sweep-$n; (cd /tmp/o-$n && cp results.json results.csv index.html *.svg $OUT/sweep-$n/ 2>/dev/null); done
cd $OUT && tar czf /tmp/aa.tgz . && find $OUT -mindepth 1 -delete && mv /tmp/aa.tgz $OUT/

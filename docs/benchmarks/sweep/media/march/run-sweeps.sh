#!/usr/bin/env bash
# kiln-bench's media chart against the one-bounce reference (direct light, single scattering).
set -uo pipefail
for f in .gl/*.deb; do dpkg -x "$f" / >/dev/null; done; ldconfig
B=.devrun/new
S=.devrun/scenes
[ -f /tmp/pica_fog.kiln ] || $B/kiln compile $S/pica_pica/scene.gltf --config $S/pica_fog.toml --shaft-variants none -q -o /tmp/pica_fog.kiln
[ -f /tmp/cornell_fog.kiln ] || $B/kiln compile $S/cornell_box/scene.gltf --config $S/cornell_fog.toml --shaft-variants none -q -o /tmp/cornell_fog.kiln
/usr/bin/time -f "wall %e s" $B/kiln-bench /tmp/cornell_fog.kiln --effects media --size 800x600 --reference-spp 4096 --out /tmp/o2-cornell -q >> $OUT/log.txt 2>&1
/usr/bin/time -f "wall %e s" $B/kiln-bench /tmp/pica_fog.kiln --effects media --size 1600x900 --reference-spp 1024 --out /tmp/o2-pica -q >> $OUT/log.txt 2>&1
for n in cornell pica; do mkdir -p $OUT/sweep-$n; (cd /tmp/o2-$n && cp results.json results.csv index.html *.svg *.png $OUT/sweep-$n/ 2>/dev/null); done
cd $OUT && tar czf /tmp/media2.tgz . && find $OUT -mindepth 1 -delete && mv /tmp/media2.tgz $OUT/

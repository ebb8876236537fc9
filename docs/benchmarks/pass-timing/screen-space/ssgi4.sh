#!/usr/bin/env bash
# Issue 14: kiln-bench's gi chart (ssgi's knobs against rt at equal time) and ao+gi, on pica_pica.
set -uo pipefail
for f in .gl/*.deb; do dpkg -x "$f" / >/dev/null; done; ldconfig
B=.devrun/new
S=.devrun/scenes
[ -f /tmp/pica.kiln ] || $B/kiln compile $S/pica_pica/scene.gltf --config $S/pica_pica.toml --shaft-variants none -q -o /tmp/pica.kiln
bench() { local scene=$1 name=$2; shift 2; $B/kiln-play /tmp/$scene.kiln --bench --json --size 1920x1080 --frames 100 "$@" > $OUT/bench-$scene-$name.json 2>> $OUT/log.txt; }
bench pica row19-default --gbuffer visibility --gi ssgi
/usr/bin/time -f "wall %e s" timeout 500 $B/kiln-bench /tmp/pica.kiln --effects gi --techniques gi:none,gi:rt,gi:ssgi --frames-accumulated 1,16 --size 1600x900 --reference-spp 512 --out /tmp/o-gi -q >> $OUT/log.txt 2>&1
mkdir -p $OUT/sweep-gi; (cd /tmp/o-gi && cp results.json results.csv index.html *.svg $OUT/sweep-gi/ 2>/dev/null)
cd $OUT && tar czf /tmp/r.tgz . && find $OUT -mindepth 1 -delete && mv /tmp/r.tgz $OUT/

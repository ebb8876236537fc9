#!/usr/bin/env bash
set -uo pipefail
for f in .gl/*.deb; do dpkg -x "$f" / >/dev/null; done; ldconfig
B=.devrun/new
S=.devrun/scenes
[ -f /tmp/pica.kiln ] || $B/kiln compile $S/pica_pica/scene.gltf --config $S/pica_pica.toml --shaft-variants none -q -o /tmp/pica.kiln
bench() { local name=$1; shift; $B/kiln-play /tmp/pica.kiln --bench --json --size 1920x1080 --frames 100 "$@" > $OUT/bench-$name.json 2>> $OUT/log.txt; }
bench taa --gbuffer visibility --aa taa
bench sao-half --gbuffer visibility --ao sao
bench gtao --gbuffer visibility --ao gtao
for f in $OUT/*.json; do echo $f; python3 -c "
import json
d=json.load(open('$f')); print({x['pass']:round(x['median_ms'],3) for x in d['passes']})"; done

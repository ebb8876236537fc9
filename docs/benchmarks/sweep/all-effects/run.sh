#!/bin/bash
# Issue 43 item 5: the committed all-effects sweeps again, with today's techniques and presets.
set -u
cd "$(dirname "$0")"; mkdir -p /tmp/p; tar xzf pack.tgz -C /tmp/p
B=/tmp/p/bin; S=/tmp/p/scenes
L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version,uuid --format=csv,noheader > $L
$B/kiln compile $S/pica_pica/scene.gltf --config $S/cfg/pica_pica.toml --shaft-variants none -o /tmp/pica_pica.kiln -q >> $L 2>&1
$B/kiln compile $S/cornell_box/scene.gltf --config $S/cfg/cornell_box.toml --shaft-variants none -o /tmp/cornell_box.kiln -q >> $L 2>&1
$B/kiln compile $S/box/CornellBox-Original.obj -c $S/box/camera.toml --shaft-variants none -o /tmp/mcguire_box.kiln -q >> $L 2>&1
ls -la /tmp/*.kiln >> $L
sweep() { local name=$1 limit=$2; shift 2
  echo "== $name $*" >> $L
  local t0=$(date +%s)
  ( while sleep 5; do ps -o rss= -C kiln-bench | head -1; done ) > /tmp/rss-$name.txt 2>/dev/null & local mon=$!
  timeout $limit $B/kiln-bench /tmp/$name.kiln "$@" -q -o /tmp/out-$name >> $L 2>&1
  echo "rc=$? wall $(( $(date +%s) - t0 )) s, peak rss $(sort -n /tmp/rss-$name.txt | tail -1) kB" >> $L
  kill $mon 2>/dev/null
  tar czf $OUT/$name.tgz --exclude="out-$name/reference" -C /tmp out-$name
}
case "${1:-a}" in
  a) sweep pica_pica 330 --size 1600x900 --reference-spp 4096
     sweep cornell_box 180 --size 800x600 --reference-spp 8192 ;;
  b) sweep mcguire_box 450 --size 1600x900 --reference-spp 4096 ;;
esac

#!/bin/bash
# Issue 41's whole-frame target on the McGuire box with the probes as the GI pass.
set -u
cd "$(dirname "$0")"; mkdir -p /tmp/p; tar xzf pack.tgz -C /tmp/p
B=/tmp/p/bin; S=/tmp/p/scenes
L=$OUT/log.txt
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader > $L
$B/kiln compile $S/box/CornellBox-Original.obj -c $S/box/camera.toml --shaft-variants none -o /tmp/box.kiln -q >> $L 2>&1
echo "== kiln-bench frame: probes, rt-4 (1600x900, 4096 spp)" >> $L
timeout 250 $B/kiln-bench /tmp/box.kiln --effects frame --techniques frame:probes,frame:rt-4 --frames-accumulated 1,4 --size 1600x900 --reference-spp 4096 --keep-images -q -o /tmp/bb >> $L 2>&1
REF=$(ls /tmp/bb/images/*reference*.exr | head -1)
run() { local name=$1; shift
  for n in 1 4; do
    timeout 60 $B/kiln-play /tmp/box.kiln --headless --size 1600x900 --frames $n "$@" -o /tmp/$name-$n.exr > /dev/null 2>&1
    echo "$name frames=$n: $($B/kiln-bench --diff $REF /tmp/$name-$n.exr -o /tmp/d-$name-$n | head -1)" >> $L
  done
  echo "== timing $name: $*" >> $L
  timeout 60 $B/kiln-play /tmp/box.kiln --headless --bench --frames 200 --size 1600x900 "$@" >> $L 2>&1
}
run A --gbuffer visibility --shadows rt --gi probes
run B --gbuffer visibility --shadows rt --gi probes --denoise svgf
run C --gbuffer visibility --shadows rt --gi probes --aa none
cp /tmp/d-A-1/flip.png $OUT/box-A-1-flip.png 2>/dev/null

#!/bin/bash
cd "$(dirname "$0")"
for i in 1 2 3 4; do for v in base no_shadow; do
  __GL_SHADER_DISK_CACHE=0 ./direct_compile dv/$v.spv; NOOPT=1 __GL_SHADER_DISK_CACHE=0 ./direct_compile dv/$v.spv | sed 's/$/ NOOPT/'; done; done 2>&1 | sort

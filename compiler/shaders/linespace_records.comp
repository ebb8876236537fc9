#version 460
// The line-space bake's PNMT records on the GPU: one workgroup per cell. Each filled shaft's
// front and back ends (left by linespace_search.comp) become records in the layout, written at
// the shaft's rank among the cell's filled shafts: a hit as shafts.rs's hit_record encodes it
// (format's PnmtLayout::encode, operation for operation), a fallback from the table
// linespace_prepare.comp made per (cell triangle, pair, end).
#extension GL_GOOGLE_include_directive : require
#define KILN_BAKE_TRI_BINDING 3
#include "linespace_common.glsl"

layout(local_size_x = 256) in;

layout(std430, set = 0, binding = 0) readonly buffer ParamsB { BakeParams P; };
layout(std430, set = 0, binding = 1) readonly buffer CellsB { BakeCell cells[]; };
// Per cell triangle, pair and end: the fallback record (P.words words).
layout(std430, set = 0, binding = 2) readonly buffer FallbacksB { uint fallbacks[]; };
// Per shaft: its front and back ends, 3 words each (see FALLBACK).
layout(std430, set = 0, binding = 4) readonly buffer EndsB { uint ends[]; };
layout(std430, set = 0, binding = 5) readonly buffer BitsB { uint bits[]; };
layout(std430, set = 0, binding = 6) writeonly buffer RecordsB { uint records[]; };

// Filled shafts before each bit word of the cell (words_per_slot(8) = 1,920 at most).
shared uint sh_rank[1920];

void main() {
    uint ci = gl_WorkGroupID.x, tid = gl_LocalInvocationID.x;
    BakeCell c = cells[ci];
    uint wps = (P.shafts + 31u) / 32u;
    for (uint w = tid; w < wps; w += 256u) {
        sh_rank[w] = bitCount(bits[ci * wps + w]);
    }
    barrier();
    if (tid == 0u) {
        uint sum = 0u;
        for (uint w = 0u; w < wps; ++w) {
            uint k = sh_rank[w];
            sh_rank[w] = sum;
            sum += k;
        }
    }
    barrier();
    for (uint s = tid; s < P.shafts; s += 256u) {
        uint word = bits[ci * wps + s / 32u], b = s % 32u;
        if ((word >> b & 1u) == 0u) {
            continue;
        }
        uint rank = sh_rank[s / 32u] + bitCount(word & ((1u << b) - 1u));
        uint pair = s / P.n4;
        uint out_at = (c.record_base + rank) * 2u * P.words;
        for (uint side = 0u; side < 2u; ++side) {
            uint e = (ci * P.shafts + s) * 6u + 3u * side;
            uint code = ends[e];
            uvec4 r;
            if ((code & FALLBACK) == 0u) {
                r = hit_record(code, uintBitsToFloat(ends[e + 1u]), uintBitsToFloat(ends[e + 2u]), c, P.layout_code);
            } else {
                uint f = (((c.tri_first + (code & ~FALLBACK)) * 15u + pair) * 2u + side) * P.words;
                r = uvec4(fallbacks[f], fallbacks[f + 1u], P.words > 2u ? fallbacks[f + 2u] : 0u,
                          P.words > 3u ? fallbacks[f + 3u] : 0u);
            }
            for (uint k = 0u; k < P.words; ++k) {
                records[out_at + side * P.words + k] = r[k];
            }
        }
    }
}

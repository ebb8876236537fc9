// Decoding of BC7, BC5 and BC4 blocks (the texel buffer of the ray-traced passes holds block-
// compressed textures as stored in the file, as whole words; the raster passes sample them
// through the GPU's texture units instead). Block layouts: Khronos Data Format Specification
// 1.3, "BC4 unsigned", "BC5 unsigned" and "BC7". The includer declares `texels` (uint[]).
#ifndef KILN_BC_GLSL
#define KILN_BC_GLSL

// `count` (<= 8) bits of the 128-bit block `b` from bit `start` (bit 0 = the lowest bit of the
// first byte).
uint bc_bits(uvec4 b, uint start, uint count) {
    uint w = start >> 5u, o = start & 31u;
    uint v = b[w] >> o;
    if (o + count > 32u && w < 3u) {
        v |= b[w + 1u] << (32u - o);
    }
    return v & ((1u << count) - 1u);
}

// Channel of texel `i` (0..15, row-major) of the BC4 block in words `w0`, `w1`.
float bc4_channel(uint w0, uint w1, uint i) {
    float r0 = float(w0 & 0xffu), r1 = float((w0 >> 8u) & 0xffu);
    uint bit = 16u + 3u * i;
    uint idx;
    if (bit + 3u <= 32u) {
        idx = (w0 >> bit) & 7u;
    } else if (bit >= 32u) {
        idx = (w1 >> (bit - 32u)) & 7u;
    } else {
        idx = ((w0 >> bit) | (w1 << (32u - bit))) & 7u;
    }
    float v;
    if (idx == 0u) {
        v = r0;
    } else if (idx == 1u) {
        v = r1;
    } else if (r0 > r1) {
        v = (float(8u - idx) * r0 + float(idx - 1u) * r1) / 7.0;
    } else if (idx == 6u) {
        v = 0.0;
    } else if (idx == 7u) {
        v = 255.0;
    } else {
        v = (float(6u - idx) * r0 + float(idx - 1u) * r1) / 5.0;
    }
    return v / 255.0;
}

// Per mode: subsets, partition bits, rotation bits, index-selection bits, colour and alpha
// endpoint bits, a P-bit per endpoint or per subset, primary and secondary index bits.
const uint BC7_NS[8] = uint[](3u, 2u, 3u, 2u, 1u, 1u, 1u, 2u);
const uint BC7_PB[8] = uint[](4u, 6u, 6u, 6u, 0u, 0u, 0u, 6u);
const uint BC7_RB[8] = uint[](0u, 0u, 0u, 0u, 2u, 2u, 0u, 0u);
const uint BC7_ISB[8] = uint[](0u, 0u, 0u, 0u, 1u, 0u, 0u, 0u);
const uint BC7_CB[8] = uint[](4u, 6u, 5u, 7u, 5u, 7u, 7u, 5u);
const uint BC7_AB[8] = uint[](0u, 0u, 0u, 0u, 6u, 8u, 7u, 5u);
const uint BC7_EPB[8] = uint[](1u, 0u, 0u, 1u, 0u, 0u, 1u, 1u);
const uint BC7_SPB[8] = uint[](0u, 1u, 0u, 0u, 0u, 0u, 0u, 0u);
const uint BC7_IB[8] = uint[](3u, 3u, 2u, 2u, 2u, 2u, 4u, 2u);
const uint BC7_IB2[8] = uint[](0u, 0u, 0u, 0u, 3u, 2u, 0u, 0u);

// Two-subset partitions: bit i is texel i's subset; the second subset's anchor texel.
const uint BC7_P2[64] = uint[](
    0xccccu, 0x8888u, 0xeeeeu, 0xecc8u, 0xc880u, 0xfeecu, 0xfec8u, 0xec80u,
    0xc800u, 0xffecu, 0xfe80u, 0xe800u, 0xffe8u, 0xff00u, 0xfff0u, 0xf000u,
    0xf710u, 0x008eu, 0x7100u, 0x08ceu, 0x008cu, 0x7310u, 0x3100u, 0x8cceu,
    0x088cu, 0x3110u, 0x6666u, 0x366cu, 0x17e8u, 0x0ff0u, 0x718eu, 0x399cu,
    0xaaaau, 0xf0f0u, 0x5a5au, 0x33ccu, 0x3c3cu, 0x55aau, 0x9696u, 0xa55au,
    0x73ceu, 0x13c8u, 0x324cu, 0x3bdcu, 0x6996u, 0xc33cu, 0x9966u, 0x0660u,
    0x0272u, 0x04e4u, 0x4e40u, 0x2720u, 0xc936u, 0x936cu, 0x39c6u, 0x639cu,
    0x9336u, 0x9cc6u, 0x817eu, 0xe718u, 0xccf0u, 0x0fccu, 0x7744u, 0xee22u);
const uint BC7_A2[64] = uint[](
    15u, 15u, 15u, 15u, 15u, 15u, 15u, 15u,
    15u, 15u, 15u, 15u, 15u, 15u, 15u, 15u,
    15u, 2u, 8u, 2u, 2u, 8u, 8u, 15u,
    2u, 8u, 2u, 2u, 8u, 8u, 2u, 2u,
    15u, 15u, 6u, 8u, 2u, 8u, 15u, 15u,
    2u, 8u, 2u, 2u, 2u, 15u, 15u, 6u,
    6u, 2u, 6u, 8u, 15u, 15u, 2u, 2u,
    15u, 15u, 15u, 15u, 15u, 2u, 2u, 15u);

// Three-subset partitions: bits 2i..2i+1 are texel i's subset; the anchors of subsets 1 and 2.
const uint BC7_P3[64] = uint[](
    0xaa685050u, 0x6a5a5040u, 0x5a5a4200u, 0x5450a0a8u, 0xa5a50000u, 0xa0a05050u, 0x5555a0a0u, 0x5a5a5050u,
    0xaa550000u, 0xaa555500u, 0xaaaa5500u, 0x90909090u, 0x94949494u, 0xa4a4a4a4u, 0xa9a59450u, 0x2a0a4250u,
    0xa5945040u, 0x0a425054u, 0xa5a5a500u, 0x55a0a0a0u, 0xa8a85454u, 0x6a6a4040u, 0xa4a45000u, 0x1a1a0500u,
    0x0050a4a4u, 0xaaa59090u, 0x14696914u, 0x69691400u, 0xa08585a0u, 0xaa821414u, 0x50a4a450u, 0x6a5a0200u,
    0xa9a58000u, 0x5090a0a8u, 0xa8a09050u, 0x24242424u, 0x00aa5500u, 0x24924924u, 0x24499224u, 0x50a50a50u,
    0x500aa550u, 0xaaaa4444u, 0x66660000u, 0xa5a0a5a0u, 0x50a050a0u, 0x69286928u, 0x44aaaa44u, 0x66666600u,
    0xaa444444u, 0x54a854a8u, 0x95809580u, 0x96969600u, 0xa85454a8u, 0x80959580u, 0xaa141414u, 0x96960000u,
    0xaaaa1414u, 0xa05050a0u, 0xa0a5a5a0u, 0x96000000u, 0x40804080u, 0xa9a8a9a8u, 0xaaaaaa44u, 0x2a4a5254u);
const uint BC7_A3A[64] = uint[](
    3u, 3u, 15u, 15u, 8u, 3u, 15u, 15u,
    8u, 8u, 6u, 6u, 6u, 5u, 3u, 3u,
    3u, 3u, 8u, 15u, 3u, 3u, 6u, 10u,
    5u, 8u, 8u, 6u, 8u, 5u, 15u, 15u,
    8u, 15u, 3u, 5u, 6u, 10u, 8u, 15u,
    15u, 3u, 15u, 5u, 15u, 15u, 15u, 15u,
    3u, 15u, 5u, 5u, 5u, 8u, 5u, 10u,
    5u, 10u, 8u, 13u, 15u, 12u, 3u, 3u);
const uint BC7_A3B[64] = uint[](
    15u, 8u, 8u, 3u, 15u, 15u, 3u, 8u,
    15u, 15u, 15u, 15u, 15u, 15u, 15u, 8u,
    15u, 8u, 15u, 3u, 15u, 8u, 15u, 8u,
    3u, 15u, 6u, 10u, 15u, 15u, 10u, 8u,
    15u, 3u, 15u, 10u, 10u, 8u, 9u, 10u,
    6u, 15u, 8u, 15u, 3u, 6u, 6u, 8u,
    15u, 3u, 15u, 15u, 15u, 15u, 15u, 15u,
    15u, 15u, 15u, 15u, 3u, 15u, 15u, 8u);

const uint BC7_W2[4] = uint[](0u, 21u, 43u, 64u);
const uint BC7_W3[8] = uint[](0u, 9u, 18u, 27u, 37u, 46u, 55u, 64u);
const uint BC7_W4[16] = uint[](0u, 4u, 9u, 13u, 17u, 21u, 26u, 30u, 34u, 38u, 43u, 47u, 51u, 55u, 60u, 64u);

uint bc7_weight(uint bits, uint index) {
    return bits == 2u ? BC7_W2[index] : (bits == 3u ? BC7_W3[index] : BC7_W4[index]);
}

// An endpoint component of `bits` bits (P-bit appended when `pbit` is not ~0u), expanded to 8
// bits by repeating its high bits.
uint bc7_unquantize(uint v, uint bits, uint pbit) {
    if (pbit != ~0u) {
        v = (v << 1u) | pbit;
        bits += 1u;
    }
    v <<= 8u - bits;
    return v | (v >> bits);
}

// Texel `i` (0..15, row-major) of the BC7 block `b`, RGBA in [0, 1].
vec4 bc7_texel(uvec4 b, uint i) {
    if ((b.x & 0xffu) == 0u) {
        return vec4(0.0); // reserved mode: transparent black, as the specification asks
    }
    uint mode = uint(findLSB(b.x & 0xffu));
    uint pos = mode + 1u;
    uint ns = BC7_NS[mode];
    uint part = bc_bits(b, pos, BC7_PB[mode]);
    pos += BC7_PB[mode];
    uint rotation = bc_bits(b, pos, BC7_RB[mode]);
    pos += BC7_RB[mode];
    uint isb = bc_bits(b, pos, BC7_ISB[mode]);
    pos += BC7_ISB[mode];
    uint subset = 0u, anchor1 = 16u, anchor2 = 16u;
    if (ns == 2u) {
        subset = (BC7_P2[part] >> i) & 1u;
        anchor1 = BC7_A2[part];
    } else if (ns == 3u) {
        subset = (BC7_P3[part] >> (2u * i)) & 3u;
        anchor1 = BC7_A3A[part];
        anchor2 = BC7_A3B[part];
    }
    uint cb = BC7_CB[mode], ab = BC7_AB[mode];
    uint pbits = pos + 6u * ns * cb + 2u * ns * ab;
    uint p0 = ~0u, p1 = ~0u;
    uint index_start = pbits;
    if (BC7_EPB[mode] == 1u) {
        p0 = bc_bits(b, pbits + 2u * subset, 1u);
        p1 = bc_bits(b, pbits + 2u * subset + 1u, 1u);
        index_start += 2u * ns;
    } else if (BC7_SPB[mode] == 1u) {
        p0 = bc_bits(b, pbits + subset, 1u);
        p1 = p0;
        index_start += ns;
    }
    uvec4 e0, e1;
    for (uint c = 0u; c < 3u; c++) {
        uint at = pos + (c * 2u * ns + 2u * subset) * cb;
        e0[c] = bc7_unquantize(bc_bits(b, at, cb), cb, p0);
        e1[c] = bc7_unquantize(bc_bits(b, at + cb, cb), cb, p1);
    }
    if (ab == 0u) {
        e0.a = 255u;
        e1.a = 255u;
    } else {
        uint at = pos + 6u * ns * cb + 2u * subset * ab;
        e0.a = bc7_unquantize(bc_bits(b, at, ab), ab, p0);
        e1.a = bc7_unquantize(bc_bits(b, at + ab, ab), ab, p1);
    }
    // Primary indices: every texel IB bits but the anchors (texel 0 and each further subset's
    // anchor), which have one bit less.
    uint ib = BC7_IB[mode];
    uint before = (i > 0u ? 1u : 0u) + (anchor1 < i ? 1u : 0u) + (anchor2 < i ? 1u : 0u);
    bool anchor = i == 0u || i == anchor1 || i == anchor2;
    uint index = bc_bits(b, index_start + i * ib - before, anchor ? ib - 1u : ib);
    uint cw = bc7_weight(ib, index), aw = cw;
    uint ib2 = BC7_IB2[mode];
    if (ib2 > 0u) {
        // Secondary indices (modes 4, 5; one subset): texel 0 alone is an anchor.
        uint start2 = index_start + 16u * ib - 1u;
        uint index2 = bc_bits(b, start2 + i * ib2 - (i > 0u ? 1u : 0u), i == 0u ? ib2 - 1u : ib2);
        uint w2 = bc7_weight(ib2, index2);
        if (isb == 1u) {
            cw = w2;
        } else {
            aw = w2;
        }
    }
    uvec4 c = (uvec4(64u - cw, 64u - cw, 64u - cw, 64u - aw) * e0 + uvec4(cw, cw, cw, aw) * e1 + 32u) >> 6u;
    if (rotation == 1u) {
        c = c.agbr;
    } else if (rotation == 2u) {
        c = c.rabg;
    } else if (rotation == 3u) {
        c = c.rgab;
    }
    return vec4(c) / 255.0;
}

#endif

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

// Per mode (4 bits each, mode 0 lowest): subsets, partition bits, rotation bits, index-selection
// bits, colour and alpha endpoint bits, a P-bit per endpoint or per subset, primary and secondary
// index bits. Packed words, not arrays: each dynamically indexed array is a table the driver
// builds at every inlined copy of the decoder.
const uint BC7_NS = 0x21112323u;
const uint BC7_PB = 0x60006664u;
const uint BC7_RB = 0x00220000u;
const uint BC7_ISB = 0x00010000u;
const uint BC7_CB = 0x57757564u;
const uint BC7_AB = 0x57860000u;
const uint BC7_EPB = 0x11001001u;
const uint BC7_SPB = 0x00000010u;
const uint BC7_IB = 0x24222233u;
const uint BC7_IB2 = 0x00230000u;

uint bc7_mode_field(uint table, uint mode) {
    return (table >> (4u * mode)) & 15u;
}

// Per partition: bits 0-15 are texel i's subset in a two-subset partition (bit i); the anchor of
// its second subset (bits 16-19); the anchors of subsets 1 and 2 of the three-subset partition of
// the same number (bits 20-23, 24-27). One table where there were four.
const uint BC7_PARTITION[64] = uint[](
    0x0f3fccccu, 0x083f8888u, 0x08ffeeeeu, 0x03ffecc8u, 0x0f8fc880u, 0x0f3ffeecu, 0x03fffec8u, 0x08ffec80u,
    0x0f8fc800u, 0x0f8fffecu, 0x0f6ffe80u, 0x0f6fe800u, 0x0f6fffe8u, 0x0f5fff00u, 0x0f3ffff0u, 0x083ff000u,
    0x0f3ff710u, 0x0832008eu, 0x0f887100u, 0x03f208ceu, 0x0f32008cu, 0x08387310u, 0x0f683100u, 0x08af8cceu,
    0x0352088cu, 0x0f883110u, 0x06826666u, 0x0a62366cu, 0x0f8817e8u, 0x0f580ff0u, 0x0af2718eu, 0x08f2399cu,
    0x0f8faaaau, 0x03fff0f0u, 0x0f365a5au, 0x0a5833ccu, 0x0a623c3cu, 0x08a855aau, 0x098f9696u, 0x0affa55au,
    0x06f273ceu, 0x0f3813c8u, 0x08f2324cu, 0x0f523bdcu, 0x03f26996u, 0x06ffc33cu, 0x06ff9966u, 0x08f60660u,
    0x0f360272u, 0x03f204e4u, 0x0f564e40u, 0x0f582720u, 0x0f5fc936u, 0x0f8f936cu, 0x0f5239c6u, 0x0fa2639cu,
    0x0f5f9336u, 0x0faf9cc6u, 0x0f8f817eu, 0x0fdfe718u, 0x03ffccf0u, 0x0fc20fccu, 0x0f327744u, 0x083fee22u);

// Three-subset partitions: bits 2i..2i+1 are texel i's subset.
const uint BC7_P3[64] = uint[](
    0xaa685050u, 0x6a5a5040u, 0x5a5a4200u, 0x5450a0a8u, 0xa5a50000u, 0xa0a05050u, 0x5555a0a0u, 0x5a5a5050u,
    0xaa550000u, 0xaa555500u, 0xaaaa5500u, 0x90909090u, 0x94949494u, 0xa4a4a4a4u, 0xa9a59450u, 0x2a0a4250u,
    0xa5945040u, 0x0a425054u, 0xa5a5a500u, 0x55a0a0a0u, 0xa8a85454u, 0x6a6a4040u, 0xa4a45000u, 0x1a1a0500u,
    0x0050a4a4u, 0xaaa59090u, 0x14696914u, 0x69691400u, 0xa08585a0u, 0xaa821414u, 0x50a4a450u, 0x6a5a0200u,
    0xa9a58000u, 0x5090a0a8u, 0xa8a09050u, 0x24242424u, 0x00aa5500u, 0x24924924u, 0x24499224u, 0x50a50a50u,
    0x500aa550u, 0xaaaa4444u, 0x66660000u, 0xa5a0a5a0u, 0x50a050a0u, 0x69286928u, 0x44aaaa44u, 0x66666600u,
    0xaa444444u, 0x54a854a8u, 0x95809580u, 0x96969600u, 0xa85454a8u, 0x80959580u, 0xaa141414u, 0x96960000u,
    0xaaaa1414u, 0xa05050a0u, 0xa0a5a5a0u, 0x96000000u, 0x40804080u, 0xa9a8a9a8u, 0xaaaaaa44u, 0x2a4a5254u);

// Interpolation weight of `index` among 2^bits: round(64 index / (2^bits - 1)), the
// specification's tables of 2-, 3- and 4-bit weights.
uint bc7_weight(uint bits, uint index) {
    uint top = (1u << bits) - 1u;
    return (128u * index + top) / (2u * top);
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
    uint ns = bc7_mode_field(BC7_NS, mode);
    uint part = bc_bits(b, pos, bc7_mode_field(BC7_PB, mode));
    pos += bc7_mode_field(BC7_PB, mode);
    uint rotation = bc_bits(b, pos, bc7_mode_field(BC7_RB, mode));
    pos += bc7_mode_field(BC7_RB, mode);
    uint isb = bc_bits(b, pos, bc7_mode_field(BC7_ISB, mode));
    pos += bc7_mode_field(BC7_ISB, mode);
    uint subset = 0u, anchor1 = 16u, anchor2 = 16u;
    if (ns == 2u) {
        subset = (BC7_PARTITION[part] >> i) & 1u;
        anchor1 = (BC7_PARTITION[part] >> 16u) & 15u;
    } else if (ns == 3u) {
        subset = (BC7_P3[part] >> (2u * i)) & 3u;
        anchor1 = (BC7_PARTITION[part] >> 20u) & 15u;
        anchor2 = (BC7_PARTITION[part] >> 24u) & 15u;
    }
    uint cb = bc7_mode_field(BC7_CB, mode), ab = bc7_mode_field(BC7_AB, mode);
    uint pbits = pos + 6u * ns * cb + 2u * ns * ab;
    uint p0 = ~0u, p1 = ~0u;
    uint index_start = pbits;
    if (bc7_mode_field(BC7_EPB, mode) == 1u) {
        p0 = bc_bits(b, pbits + 2u * subset, 1u);
        p1 = bc_bits(b, pbits + 2u * subset + 1u, 1u);
        index_start += 2u * ns;
    } else if (bc7_mode_field(BC7_SPB, mode) == 1u) {
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
    uint ib = bc7_mode_field(BC7_IB, mode);
    uint before = (i > 0u ? 1u : 0u) + (anchor1 < i ? 1u : 0u) + (anchor2 < i ? 1u : 0u);
    bool anchor = i == 0u || i == anchor1 || i == anchor2;
    uint index = bc_bits(b, index_start + i * ib - before, anchor ? ib - 1u : ib);
    uint cw = bc7_weight(ib, index), aw = cw;
    uint ib2 = bc7_mode_field(BC7_IB2, mode);
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

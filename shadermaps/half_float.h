// half_float.h -- IEEE 754 binary16 conversion, for shader-map channels stored at half
// precision. Round to nearest even; values beyond the half range become +-inf; NaN stays
// NaN. Relative error at most 2^-11 for normal halves (|x| >= 2^-14), absolute error at
// most 2^-25 below that.
#pragma once

#include <cstdint>
#include <cstring>

namespace mpshade {

inline uint16_t floatToHalf(float value) {
    uint32_t f;
    std::memcpy(&f, &value, sizeof f);
    const uint32_t sign = (f >> 16) & 0x8000u;
    const uint32_t absBits = f & 0x7FFFFFFFu;
    if (absBits >= 0x7F800000u)
        return static_cast<uint16_t>(sign | (absBits > 0x7F800000u ? 0x7E00u : 0x7C00u));
    if (absBits >= 0x477FF000u) return static_cast<uint16_t>(sign | 0x7C00u);  // rounds past 65504
    if (absBits < 0x38800000u) {
        // Subnormal half (or zero): shift the significand with its implicit bit in.
        if (absBits < 0x33000000u) return static_cast<uint16_t>(sign);
        const uint32_t exponent = absBits >> 23;
        const uint32_t mantissa = (absBits & 0x7FFFFFu) | 0x800000u;
        const uint32_t shift = 126 - exponent;  // 14..24
        uint32_t h = mantissa >> shift;
        const uint32_t rest = mantissa & ((1u << shift) - 1), halfway = 1u << (shift - 1);
        if (rest > halfway || (rest == halfway && (h & 1u))) ++h;
        return static_cast<uint16_t>(sign | h);
    }
    uint32_t h = ((absBits - 0x38000000u) >> 13);
    const uint32_t rest = absBits & 0x1FFFu;
    if (rest > 0x1000u || (rest == 0x1000u && (h & 1u))) ++h;
    return static_cast<uint16_t>(sign | h);
}

inline float halfToFloat(uint16_t h) {
    const uint32_t sign = static_cast<uint32_t>(h & 0x8000u) << 16;
    const uint32_t exponent = (h >> 10) & 0x1Fu;
    uint32_t mantissa = h & 0x3FFu;
    uint32_t f;
    if (exponent == 0) {
        if (mantissa == 0) {
            f = sign;
        } else {
            int e = -1;
            do {
                ++e;
                mantissa <<= 1;
            } while ((mantissa & 0x400u) == 0);
            f = sign | static_cast<uint32_t>(127 - 15 - e) << 23 | (mantissa & 0x3FFu) << 13;
        }
    } else if (exponent == 31) {
        f = sign | 0x7F800000u | mantissa << 13;
    } else {
        f = sign | (exponent + 127 - 15) << 23 | mantissa << 13;
    }
    float out;
    std::memcpy(&out, &f, sizeof out);
    return out;
}

}  // namespace mpshade

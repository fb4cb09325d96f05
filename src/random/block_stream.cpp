#include "pegasus/random/block_stream.hpp"

#include <Random123/philox.h>

#ifdef PEGASUS_X86_KERNELS
#include <immintrin.h>
// GCC 12's AVX-512 intrinsics start some results from _mm512_undefined_*() (a variable initialised from
// itself), which -Wmaybe-uninitialized reports at every use (a GCC warning; clang has none of that name).
// Pushed, and popped at the end of the file: in a unity build the next file shares this unit.
#pragma GCC diagnostic push
#ifndef __clang__
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#endif

namespace pegasus::detail {

namespace {

// Philox4x32-10 (Salmon et al. 2011, as in Random123's philox.h): ten rounds of
//   (x0, x1, x2, x3) -> (hi(M1 x2) ^ x1 ^ k0, lo(M1 x2), hi(M0 x0) ^ x3 ^ k1, lo(M0 x0))
// with the key bumped by (W0, W1) between rounds.
constexpr std::uint32_t kM0 = 0xD2511F53u, kM1 = 0xCD9E8D57u;
constexpr std::uint32_t kW0 = 0x9E3779B9u, kW1 = 0xBB67AE85u;
constexpr int kRounds = 10;

void philox_scalar(std::uint32_t key0, std::uint32_t key1, std::uint64_t first_call, std::uint32_t stream,
                   std::uint32_t domain, int calls, double* out) {
  const r123::Philox4x32 philox;
  const r123::Philox4x32::key_type key = {{key0, key1}};
  for (int j = 0; j < calls; ++j) {
    const std::uint64_t c = first_call + static_cast<std::uint64_t>(j);
    const r123::Philox4x32::ctr_type ctr = {
        {static_cast<std::uint32_t>(c), static_cast<std::uint32_t>(c >> 32), stream, domain}};
    const auto r = philox(ctr, key);
    for (int w = 0; w < 4; ++w)
      out[4 * j + w] = (static_cast<double>(r[static_cast<std::size_t>(w)]) + 0.5) * 0x1.0p-32;
  }
}

#ifdef PEGASUS_X86_KERNELS

// The vector paths keep one Philox call per 64-bit lane, its 32-bit words in the low halves. The upper
// halves may hold garbage between rounds: the multiplies (vpmuludq) read only the low halves, XOR works
// bit by bit, and only low halves are converted at the end. A low half r becomes a double exactly:
// the bits 0x43300000'00000000 | r are the double 2^52 + r, and subtracting 2^52 - 0.5 (representable)
// leaves r + 0.5 exactly; scaling by 2^-32 is exact too, so every path equals the scalar one bit for bit.
constexpr std::uint64_t kTwo52Bits = 0x4330000000000000ull;
constexpr double kTwo52MinusHalf = 4503599627370495.5;  // 2^52 - 0.5

__attribute__((target("avx2"))) inline __m256d unit_avx2(__m256i x) {
  const __m256i low = _mm256_set1_epi64x(0xffffffffll);
  const __m256i exp_bits = _mm256_set1_epi64x(static_cast<long long>(kTwo52Bits));
  const __m256d d = _mm256_castsi256_pd(_mm256_or_si256(_mm256_and_si256(x, low), exp_bits));
  return _mm256_mul_pd(_mm256_sub_pd(d, _mm256_set1_pd(kTwo52MinusHalf)), _mm256_set1_pd(0x1.0p-32));
}

// Words x0..x3 of four calls -> out[4 call + word] (a 4 x 4 transpose).
__attribute__((target("avx2"))) inline void store_avx2(__m256i x0, __m256i x1, __m256i x2, __m256i x3,
                                                       double* o) {
  const __m256d d0 = unit_avx2(x0), d1 = unit_avx2(x1), d2 = unit_avx2(x2), d3 = unit_avx2(x3);
  const __m256d t0 = _mm256_unpacklo_pd(d0, d1), t1 = _mm256_unpackhi_pd(d0, d1);
  const __m256d t2 = _mm256_unpacklo_pd(d2, d3), t3 = _mm256_unpackhi_pd(d2, d3);
  _mm256_storeu_pd(o, _mm256_permute2f128_pd(t0, t2, 0x20));
  _mm256_storeu_pd(o + 4, _mm256_permute2f128_pd(t1, t3, 0x20));
  _mm256_storeu_pd(o + 8, _mm256_permute2f128_pd(t0, t2, 0x31));
  _mm256_storeu_pd(o + 12, _mm256_permute2f128_pd(t1, t3, 0x31));
}

__attribute__((target("avx2"))) void philox_avx2(std::uint32_t key0, std::uint32_t key1,
                                                 std::uint64_t first_call, std::uint32_t stream,
                                                 std::uint32_t domain, int calls, double* out) {
  const __m256i m0 = _mm256_set1_epi64x(kM0), m1 = _mm256_set1_epi64x(kM1);
  const __m256i lanes = _mm256_set_epi64x(3, 2, 1, 0);
  int j = 0;
  // Two groups of four calls at a time: the rounds are a dependency chain, two chains fill the pipeline.
  for (; j + 8 <= calls; j += 8) {
    const __m256i ca = _mm256_add_epi64(
        _mm256_set1_epi64x(static_cast<long long>(first_call + static_cast<std::uint64_t>(j))), lanes);
    const __m256i cb = _mm256_add_epi64(ca, _mm256_set1_epi64x(4));
    __m256i a0 = ca, a1 = _mm256_srli_epi64(ca, 32), a2 = _mm256_set1_epi64x(stream),
            a3 = _mm256_set1_epi64x(domain);
    __m256i b0 = cb, b1 = _mm256_srli_epi64(cb, 32), b2 = a2, b3 = a3;
    std::uint32_t k0 = key0, k1 = key1;
    for (int round = 0; round < kRounds; ++round) {
      const __m256i vk0 = _mm256_set1_epi64x(k0), vk1 = _mm256_set1_epi64x(k1);
      const __m256i pa0 = _mm256_mul_epu32(a0, m0), pa1 = _mm256_mul_epu32(a2, m1);
      const __m256i pb0 = _mm256_mul_epu32(b0, m0), pb1 = _mm256_mul_epu32(b2, m1);
      a0 = _mm256_xor_si256(_mm256_xor_si256(_mm256_srli_epi64(pa1, 32), a1), vk0);
      a2 = _mm256_xor_si256(_mm256_xor_si256(_mm256_srli_epi64(pa0, 32), a3), vk1);
      a1 = pa1;
      a3 = pa0;
      b0 = _mm256_xor_si256(_mm256_xor_si256(_mm256_srli_epi64(pb1, 32), b1), vk0);
      b2 = _mm256_xor_si256(_mm256_xor_si256(_mm256_srli_epi64(pb0, 32), b3), vk1);
      b1 = pb1;
      b3 = pb0;
      k0 += kW0;
      k1 += kW1;
    }
    store_avx2(a0, a1, a2, a3, out + 4 * j);
    store_avx2(b0, b1, b2, b3, out + 4 * j + 16);
  }
  if (j < calls)
    philox_scalar(key0, key1, first_call + static_cast<std::uint64_t>(j), stream, domain, calls - j,
                  out + 4 * j);
}

__attribute__((target("avx512f"))) inline __m512d unit_avx512(__m512i x) {
  const __m512i low = _mm512_set1_epi64(0xffffffffll);
  const __m512i exp_bits = _mm512_set1_epi64(static_cast<long long>(kTwo52Bits));
  const __m512d d =
      _mm512_castsi512_pd(_mm512_ternarylogic_epi64(x, low, exp_bits, 0xEA));  // (x & low) | exp
  return _mm512_mul_pd(_mm512_sub_pd(d, _mm512_set1_pd(kTwo52MinusHalf)), _mm512_set1_pd(0x1.0p-32));
}

// Words x0..x3 of eight calls -> out[4 call + word]: interleave words (0, 1) and (2, 3) of calls 0-3 and
// 4-7, then merge the pairs.
__attribute__((target("avx512f"))) inline void store_avx512(__m512i x0, __m512i x1, __m512i x2, __m512i x3,
                                                            double* o) {
  const __m512i pair_lo = _mm512_set_epi64(11, 3, 10, 2, 9, 1, 8, 0);
  const __m512i pair_hi = _mm512_set_epi64(15, 7, 14, 6, 13, 5, 12, 4);
  const __m512i quad_a = _mm512_set_epi64(11, 10, 3, 2, 9, 8, 1, 0);
  const __m512i quad_b = _mm512_set_epi64(15, 14, 7, 6, 13, 12, 5, 4);
  const __m512d d0 = unit_avx512(x0), d1 = unit_avx512(x1), d2 = unit_avx512(x2), d3 = unit_avx512(x3);
  const __m512d p01l = _mm512_permutex2var_pd(d0, pair_lo, d1),
                p23l = _mm512_permutex2var_pd(d2, pair_lo, d3);
  const __m512d p01h = _mm512_permutex2var_pd(d0, pair_hi, d1),
                p23h = _mm512_permutex2var_pd(d2, pair_hi, d3);
  _mm512_storeu_pd(o, _mm512_permutex2var_pd(p01l, quad_a, p23l));
  _mm512_storeu_pd(o + 8, _mm512_permutex2var_pd(p01l, quad_b, p23l));
  _mm512_storeu_pd(o + 16, _mm512_permutex2var_pd(p01h, quad_a, p23h));
  _mm512_storeu_pd(o + 24, _mm512_permutex2var_pd(p01h, quad_b, p23h));
}

__attribute__((target("avx512f"))) void philox_avx512(std::uint32_t key0, std::uint32_t key1,
                                                      std::uint64_t first_call, std::uint32_t stream,
                                                      std::uint32_t domain, int calls, double* out) {
  const __m512i m0 = _mm512_set1_epi64(kM0), m1 = _mm512_set1_epi64(kM1);
  const __m512i lanes = _mm512_set_epi64(7, 6, 5, 4, 3, 2, 1, 0);
  int j = 0;
  for (; j + 16 <= calls; j += 16) {
    const __m512i ca = _mm512_add_epi64(
        _mm512_set1_epi64(static_cast<long long>(first_call + static_cast<std::uint64_t>(j))), lanes);
    const __m512i cb = _mm512_add_epi64(ca, _mm512_set1_epi64(8));
    __m512i a0 = ca, a1 = _mm512_srli_epi64(ca, 32), a2 = _mm512_set1_epi64(stream),
            a3 = _mm512_set1_epi64(domain);
    __m512i b0 = cb, b1 = _mm512_srli_epi64(cb, 32), b2 = a2, b3 = a3;
    std::uint32_t k0 = key0, k1 = key1;
    for (int round = 0; round < kRounds; ++round) {
      const __m512i vk0 = _mm512_set1_epi64(k0), vk1 = _mm512_set1_epi64(k1);
      const __m512i pa0 = _mm512_mul_epu32(a0, m0), pa1 = _mm512_mul_epu32(a2, m1);
      const __m512i pb0 = _mm512_mul_epu32(b0, m0), pb1 = _mm512_mul_epu32(b2, m1);
      // 0x96: three-way XOR.
      a0 = _mm512_ternarylogic_epi64(_mm512_srli_epi64(pa1, 32), a1, vk0, 0x96);
      a2 = _mm512_ternarylogic_epi64(_mm512_srli_epi64(pa0, 32), a3, vk1, 0x96);
      a1 = pa1;
      a3 = pa0;
      b0 = _mm512_ternarylogic_epi64(_mm512_srli_epi64(pb1, 32), b1, vk0, 0x96);
      b2 = _mm512_ternarylogic_epi64(_mm512_srli_epi64(pb0, 32), b3, vk1, 0x96);
      b1 = pb1;
      b3 = pb0;
      k0 += kW0;
      k1 += kW1;
    }
    store_avx512(a0, a1, a2, a3, out + 4 * j);
    store_avx512(b0, b1, b2, b3, out + 4 * j + 32);
  }
  if (j < calls)
    philox_avx2(key0, key1, first_call + static_cast<std::uint64_t>(j), stream, domain, calls - j,
                out + 4 * j);
}

#endif

}  // namespace

void philox_uniforms(InstructionSet isa, std::uint32_t key0, std::uint32_t key1, std::uint64_t first_call,
                     std::uint32_t stream, std::uint32_t domain, int calls, double* out) {
  switch (isa) {
#ifdef PEGASUS_X86_KERNELS
    case InstructionSet::kAvx512:
      philox_avx512(key0, key1, first_call, stream, domain, calls, out);
      return;
    case InstructionSet::kAvx2Fma:
      philox_avx2(key0, key1, first_call, stream, domain, calls, out);
      return;
#endif
    default:
      philox_scalar(key0, key1, first_call, stream, domain, calls, out);
  }
}

void philox_uniforms(std::uint32_t key0, std::uint32_t key1, std::uint64_t first_call, std::uint32_t stream,
                     std::uint32_t domain, int calls, double* out) {
  philox_uniforms(best_instruction_set(), key0, key1, first_call, stream, domain, calls, out);
}

}  // namespace pegasus::detail

#ifdef PEGASUS_X86_KERNELS
#pragma GCC diagnostic pop
#endif

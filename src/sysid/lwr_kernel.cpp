// The Gram kernel and the solve's factorisation (Factor) of lwr_kernel.hpp for three instruction sets. The
// build has no -march flags, so the AVX2 and AVX-512 versions are compiled in target regions
// (core/instruction_set.hpp) and chosen at run time (lwr.cpp).
//
// Reproducibility: the three versions run the same IEEE operations in the same order (every multiply-add
// fused, std::fma in the scalar one; the project compiles without -ffast-math and with -ffp-contract=off, set
// for every compiler in CMakeLists.txt), so a refit gives the same bits whichever runs, on any x86-64
// machine, for any thread count. What is not reproducible across machines: the solve's few steps outside
// Factor (lwr.cpp: scaling, the leverage's substitution; compiled for the build's baseline instruction set)
// may round differently under another compiler, other flags or another architecture, and fit_exact uses the C
// library's exp.
#include "pegasus/sysid/lwr_kernel.hpp"

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <utility>

#include "pegasus/core/instruction_set.hpp"

#ifdef PEGASUS_X86_KERNELS
#include <immintrin.h>
#endif

namespace pegasus::sysid::detail {

namespace {

constexpr double kLog2e = 1.4426950408889634074;
constexpr double kMagic = 6755399441055744.0;          // 1.5 * 2^52: x + kMagic rounds x to an integer
constexpr double kLn2Hi = 6.93147180369123816490e-01;  // 0x3FE62E42FEE00000 (21 trailing zero bits)
constexpr double kLn2Lo = 1.90821492927058770002e-10;  // ln 2 - kLn2Hi
constexpr double kMinExpArg = -708.0;                  // exp(-708) ~ 3.3e-308, still normal
constexpr double kInfinity = std::numeric_limits<double>::infinity();
// 2^(j/8), j = 0..7, rounded to nearest (computed to 60 digits).
alignas(64) constexpr double kExp2Eighths[kLanes] = {
    0x1.0000000000000p+0, 0x1.172b83c7d517bp+0, 0x1.306fe0a31b715p+0, 0x1.4bfdad5362a27p+0,
    0x1.6a09e667f3bcdp+0, 0x1.8ace5422aa0dbp+0, 0x1.ae89f995ad3adp+0, 0x1.d5818dcfba487p+0};
// For nm = n + kMagic (|n| < 2^51), n = 8e + j: bits(nm) << 49 puts j's 3 bits just below the exponent field
// (they are cleared) and e's in it (kMagic's bits shift out), so adding it to the bits of 2^(j/8) scales that
// by 2^e.
constexpr std::uint64_t kExponentField = 0xFFF0000000000000ULL;

// The 8 lanes of a vector summed in a fixed tree order (every instruction set's hsum8 keeps it).
inline double lane_tree_sum(const double* l) {
  return ((l[0] + l[1]) + (l[2] + l[3])) + ((l[4] + l[5]) + (l[6] + l[7]));
}

// hsum8 of the instruction sets without a shuffle form: lane by lane.
inline void hsum8_lanewise(const double* v, double* out) {
  for (int i = 0; i < 8; ++i) out[i] = lane_tree_sum(v + i * kLanes);
}

constexpr std::array<double, 9> kInvFactorial = [] {
  std::array<double, 9> c{};
  double f = 1;
  for (int k = 0; k < 9; ++k) {
    if (k > 0) f *= k;  // exact
    c[static_cast<std::size_t>(k)] = 1.0 / f;
  }
  return c;
}();

}  // namespace

TilePlan tile_plan(int rows, int cols, int max_rows, int max_cols, bool weight_row) {
  TilePlan p;
  for (int r0 = 0; r0 < rows; r0 += max_rows) {
    const int r = std::min(max_rows, rows - r0);
    const int width = std::min({max_cols, 24 / r, 12});
    // As few tiles as the width allows, of balanced widths (6,6,6,2 becomes 5,5,5,5: no narrow tile that
    // loads almost as much as it multiplies).
    const int span = cols - r0, count = (span + width - 1) / width;
    for (int k = 0, c0 = r0; k < count; ++k) {
      const int c = span / count + (k < span % count ? 1 : 0);
      const TileKind kind = k > 0            ? kOffDiagonal
                            : !weight_row    ? kDiagonalTile
                            : r0 + r == rows ? kDiagonalWeightRow
                                             : kDiagonalMoments;
      p.tiles.push_back(Tile{r0, r, c0, c, p.acc_size, kind});
      p.acc_size += r * c * kLanes;
      c0 += c;
    }
  }
  return p;
}

// ------------------------------------------------------------------ scalar (any machine)
namespace scalar_isa {
struct V {
  double v[kLanes];
  static V load(const double* p) {
    V r;
    std::memcpy(r.v, p, sizeof r.v);
    return r;
  }
  void store(double* p) const { std::memcpy(p, v, sizeof v); }
  static V set(double x) {
    V r;
    std::fill(r.v, r.v + kLanes, x);
    return r;
  }
  static V zero() { return set(0.0); }
};
#define PEGASUS_LWR_LANEWISE(name, expr)   \
  inline V name(V a, V b) {                \
    V r;                                   \
    for (int i = 0; i < kLanes; ++i) {     \
      const double x = a.v[i], y = b.v[i]; \
      r.v[i] = (expr);                     \
    }                                      \
    return r;                              \
  }
PEGASUS_LWR_LANEWISE(add, x + y)
PEGASUS_LWR_LANEWISE(sub, x - y)
PEGASUS_LWR_LANEWISE(mul, x* y)
PEGASUS_LWR_LANEWISE(vmin, x < y ? x : y)
PEGASUS_LWR_LANEWISE(vmax, x > y ? x : y)
#undef PEGASUS_LWR_LANEWISE
inline V fma(V a, V b, V c) {
  V r;
  for (int i = 0; i < kLanes; ++i) r.v[i] = std::fma(a.v[i], b.v[i], c.v[i]);
  return r;
}
inline V select_le(V a, V b, V x, V y) {
  V r;
  for (int i = 0; i < kLanes; ++i) r.v[i] = a.v[i] <= b.v[i] ? x.v[i] : y.v[i];
  return r;
}
inline int count_le(V a, V b) {
  int n = 0;
  for (int i = 0; i < kLanes; ++i) n += a.v[i] <= b.v[i] ? 1 : 0;
  return n;
}
inline V pow2_table(V nm) {
  V r;
  for (int i = 0; i < kLanes; ++i) {
    const auto bits = std::bit_cast<std::uint64_t>(nm.v[i]);
    const auto table = std::bit_cast<std::uint64_t>(kExp2Eighths[bits & 7]);
    r.v[i] = std::bit_cast<double>(table + ((bits << 49) & kExponentField));
  }
  return r;
}
inline void hsum8(const double* v, double* out) { hsum8_lanewise(v, out); }
constexpr int kDistanceBlock = 2;
#include "lwr_kernel.inc"
}  // namespace scalar_isa

#ifdef PEGASUS_X86_KERNELS
// ------------------------------------------------------------------ AVX2 + FMA: two 256-bit halves
PEGASUS_BEGIN_AVX2_FMA_REGION
namespace avx2_isa {
struct V {
  __m256d lo, hi;
  static V load(const double* p) { return {_mm256_loadu_pd(p), _mm256_loadu_pd(p + 4)}; }
  void store(double* p) const {
    _mm256_storeu_pd(p, lo);
    _mm256_storeu_pd(p + 4, hi);
  }
  static V set(double x) { return {_mm256_set1_pd(x), _mm256_set1_pd(x)}; }
  static V zero() { return {_mm256_setzero_pd(), _mm256_setzero_pd()}; }
};
inline V add(V a, V b) { return {_mm256_add_pd(a.lo, b.lo), _mm256_add_pd(a.hi, b.hi)}; }
inline V sub(V a, V b) { return {_mm256_sub_pd(a.lo, b.lo), _mm256_sub_pd(a.hi, b.hi)}; }
inline V mul(V a, V b) { return {_mm256_mul_pd(a.lo, b.lo), _mm256_mul_pd(a.hi, b.hi)}; }
inline V fma(V a, V b, V c) { return {_mm256_fmadd_pd(a.lo, b.lo, c.lo), _mm256_fmadd_pd(a.hi, b.hi, c.hi)}; }
inline V vmin(V a, V b) { return {_mm256_min_pd(a.lo, b.lo), _mm256_min_pd(a.hi, b.hi)}; }
inline V vmax(V a, V b) { return {_mm256_max_pd(a.lo, b.lo), _mm256_max_pd(a.hi, b.hi)}; }
inline V select_le(V a, V b, V x, V y) {
  return {_mm256_blendv_pd(y.lo, x.lo, _mm256_cmp_pd(a.lo, b.lo, _CMP_LE_OQ)),
          _mm256_blendv_pd(y.hi, x.hi, _mm256_cmp_pd(a.hi, b.hi, _CMP_LE_OQ))};
}
inline int count_le(V a, V b) {
  return std::popcount(static_cast<unsigned>(_mm256_movemask_pd(_mm256_cmp_pd(a.lo, b.lo, _CMP_LE_OQ)))) +
         std::popcount(static_cast<unsigned>(_mm256_movemask_pd(_mm256_cmp_pd(a.hi, b.hi, _CMP_LE_OQ))));
}
inline __m256d pow2_half(__m256d nm) {
  const __m256i bits = _mm256_castpd_si256(nm);
  const __m256i j = _mm256_and_si256(bits, _mm256_set1_epi64x(7));
  const __m256i t = _mm256_castpd_si256(_mm256_i64gather_pd(kExp2Eighths, j, 8));
  const __m256i field = _mm256_set1_epi64x(static_cast<long long>(kExponentField));
  const __m256i e = _mm256_and_si256(_mm256_slli_epi64(bits, 49), field);
  return _mm256_castsi256_pd(_mm256_add_epi64(t, e));
}
inline V pow2_table(V nm) { return {pow2_half(nm.lo), pow2_half(nm.hi)}; }
inline void hsum8(const double* v, double* out) { hsum8_lanewise(v, out); }
constexpr int kDistanceBlock = 4;  // 8 accumulators of 16 registers
#include "lwr_kernel.inc"
}  // namespace avx2_isa
PEGASUS_END_TARGET_REGION

// ------------------------------------------------------------------ AVX-512: one 512-bit register
PEGASUS_BEGIN_AVX512_REGION
namespace avx512_isa {
struct V {
  __m512d v;
  static V load(const double* p) { return {_mm512_loadu_pd(p)}; }
  void store(double* p) const { _mm512_storeu_pd(p, v); }
  static V set(double x) { return {_mm512_set1_pd(x)}; }
  static V zero() { return {_mm512_setzero_pd()}; }
};
inline V add(V a, V b) { return {_mm512_add_pd(a.v, b.v)}; }
inline V sub(V a, V b) { return {_mm512_sub_pd(a.v, b.v)}; }
inline V mul(V a, V b) { return {_mm512_mul_pd(a.v, b.v)}; }
inline V fma(V a, V b, V c) { return {_mm512_fmadd_pd(a.v, b.v, c.v)}; }
// The masked forms with every lane selected: GCC 12 warns (-Wmaybe-uninitialized) on the unmasked ones'
// undefined pass-through operand.
inline V vmin(V a, V b) { return {_mm512_mask_min_pd(a.v, 0xFF, a.v, b.v)}; }
inline V vmax(V a, V b) { return {_mm512_mask_max_pd(a.v, 0xFF, a.v, b.v)}; }
inline V select_le(V a, V b, V x, V y) {
  return {_mm512_mask_blend_pd(_mm512_cmp_pd_mask(a.v, b.v, _CMP_LE_OQ), y.v, x.v)};
}
inline int count_le(V a, V b) {
  return std::popcount(static_cast<unsigned>(_mm512_cmp_pd_mask(a.v, b.v, _CMP_LE_OQ)));
}
inline V pow2_table(V nm) {
  const __m512i bits = _mm512_castpd_si512(nm.v);
  const __m512d table = _mm512_load_pd(kExp2Eighths);
  const __m512i t = _mm512_castpd_si512(_mm512_mask_permutexvar_pd(table, 0xFF, bits, table));
  const __m512i field = _mm512_set1_epi64(static_cast<long long>(kExponentField));
  const __m512i e = _mm512_and_si512(_mm512_mask_slli_epi64(bits, 0xFF, bits, 49), field);
  return {_mm512_castsi512_pd(_mm512_add_epi64(t, e))};
}
// Lane sums of 8 vectors a..h at once: pairs (l0+l1, l2+l3, ...) of two vectors interleaved, then those pairs
// summed across 128-bit lanes twice, which ends with the 8 sums in order; each sum takes lane_tree_sum's
// order. (Masked forms with every lane selected, as above, for GCC 12's warning.)
inline void hsum8(const double* v, double* out) {
  __m512d pair[4];
  for (int i = 0; i < 4; ++i) {
    const __m512d a = _mm512_loadu_pd(v + 2 * i * kLanes), b = _mm512_loadu_pd(v + (2 * i + 1) * kLanes);
    // a01 b01 a23 b23 a45 b45 a67 b67
    pair[i] = _mm512_add_pd(_mm512_mask_unpacklo_pd(a, 0xFF, a, b), _mm512_mask_unpackhi_pd(a, 0xFF, a, b));
  }
  __m512d quad[2];
  for (int i = 0; i < 2; ++i) {
    const __m512d x = pair[2 * i], y = pair[2 * i + 1];  // quad: a0-3 b0-3 a4-7 b4-7 c0-3 d0-3 c4-7 d4-7
    quad[i] = _mm512_add_pd(_mm512_mask_shuffle_f64x2(x, 0xFF, x, y, 0x88),
                            _mm512_mask_shuffle_f64x2(x, 0xFF, x, y, 0xDD));
  }
  const __m512d q0 = quad[0], q1 = quad[1];
  _mm512_storeu_pd(out, _mm512_add_pd(_mm512_mask_shuffle_f64x2(q0, 0xFF, q0, q1, 0x88),
                                      _mm512_mask_shuffle_f64x2(q0, 0xFF, q0, q1, 0xDD)));
}
constexpr int kDistanceBlock = 8;  // 8 accumulators of 32 registers
#include "lwr_kernel.inc"
}  // namespace avx512_isa
PEGASUS_END_TARGET_REGION
#endif

#ifndef PEGASUS_X86_KERNELS
// Elsewhere every entry point runs the scalar version.
namespace avx2_isa = scalar_isa;
namespace avx512_isa = scalar_isa;
#endif

void gram_scalar(const KernelData& d, const TilePlan& plan, const KernelQuery& q, KernelResult* out) {
  scalar_isa::gram(d, plan, q, out);
}
void gram_avx2(const KernelData& d, const TilePlan& plan, const KernelQuery& q, KernelResult* out) {
  avx2_isa::gram(d, plan, q, out);
}
void gram_avx512(const KernelData& d, const TilePlan& plan, const KernelQuery& q, KernelResult* out) {
  avx512_isa::gram(d, plan, q, out);
}
double invert_scalar(int m, Factor* f) { return scalar_isa::invert(m, f); }
double invert_avx2(int m, Factor* f) { return avx2_isa::invert(m, f); }
double invert_avx512(int m, Factor* f) { return avx512_isa::invert(m, f); }
void multiply_inverse_scalar(int m, const Factor& f, int count, const Row* v, Row* out) {
  scalar_isa::multiply_inverse(m, f, count, v, out);
}
void multiply_inverse_avx2(int m, const Factor& f, int count, const Row* v, Row* out) {
  avx2_isa::multiply_inverse(m, f, count, v, out);
}
void multiply_inverse_avx512(int m, const Factor& f, int count, const Row* v, Row* out) {
  avx512_isa::multiply_inverse(m, f, count, v, out);
}

double kernel_exp(double x) {
  double out[kLanes];
  scalar_isa::exp_nonpositive(scalar_isa::V::set(x)).store(out);
  return out[0];
}

}  // namespace pegasus::sysid::detail

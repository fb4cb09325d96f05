// The dense rows' kernel of the MDP solvers (mdp/solvers.hpp, detail::dense_dot4): four dot products of
// consecutive rows with V, on SSE2, AVX2 with FMA, or AVX-512.
#include <cstddef>

#include "pegasus/mdp/solvers.hpp"

#ifdef PEGASUS_X86_KERNELS
#include <immintrin.h>
#endif

namespace pegasus::detail {
namespace {

// ---- Dense rows: four dot products with one vector at a time --------------------------------------------
//
// A dense MDP's sweep is 2 x S x A multiply-adds over S x A x S probabilities (8 MB for 500 states and 4
// actions), read once per sweep. Computing four rows (a state's actions) against each loaded piece of V
// halves the loads, and wider vectors (AVX2 with FMA, AVX-512) take fewer instructions per probability.
// The path is chosen once per process from the CPU; each path sums in a fixed order, so results are
// deterministic on a given machine (paths differ from each other in the last bits: FMA rounds once).
// out[a] = sum_k p[a * stride + k] v[k] for a = 0..3.

void dot4_sse2(const double* p, std::size_t stride, const double* v, int n, double* out) {
  const double* p1 = p + stride;
  const double* p2 = p1 + stride;
  const double* p3 = p2 + stride;
#ifdef PEGASUS_X86_KERNELS
  __m128d a0 = _mm_setzero_pd(), a1 = a0, a2 = a0, a3 = a0;
  int k = 0;
  for (; k + 2 <= n; k += 2) {
    const __m128d x = _mm_loadu_pd(v + k);
    a0 = _mm_add_pd(a0, _mm_mul_pd(_mm_loadu_pd(p + k), x));
    a1 = _mm_add_pd(a1, _mm_mul_pd(_mm_loadu_pd(p1 + k), x));
    a2 = _mm_add_pd(a2, _mm_mul_pd(_mm_loadu_pd(p2 + k), x));
    a3 = _mm_add_pd(a3, _mm_mul_pd(_mm_loadu_pd(p3 + k), x));
  }
  double s[4][2];
  _mm_storeu_pd(s[0], a0);
  _mm_storeu_pd(s[1], a1);
  _mm_storeu_pd(s[2], a2);
  _mm_storeu_pd(s[3], a3);
  for (int a = 0; a < 4; ++a) out[a] = s[a][0] + s[a][1];
#else
  int k = 0;
  for (int a = 0; a < 4; ++a) out[a] = 0.0;
#endif
  for (; k < n; ++k) {
    out[0] += p[k] * v[k];
    out[1] += p1[k] * v[k];
    out[2] += p2[k] * v[k];
    out[3] += p3[k] * v[k];
  }
}

#ifdef PEGASUS_X86_KERNELS

// GCC 12's AVX-512 intrinsics start some results from _mm512_undefined_*() (a variable initialised from
// itself), which -Wmaybe-uninitialized and -Wuninitialized report at every use.
#pragma GCC diagnostic push
#ifndef __clang__  // a GCC warning; clang has none of that name
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif
#pragma GCC diagnostic ignored "-Wuninitialized"

__attribute__((target("avx2,fma"))) inline double hsum_avx2(__m256d x) {
  const __m128d lo = _mm256_castpd256_pd128(x), hi = _mm256_extractf128_pd(x, 1);
  const __m128d s = _mm_add_pd(lo, hi);
  return _mm_cvtsd_f64(_mm_add_sd(s, _mm_unpackhi_pd(s, s)));
}

__attribute__((target("avx2,fma"))) void dot4_avx2(const double* p, std::size_t stride, const double* v,
                                                   int n, double* out) {
  const double* q[4] = {p, p + stride, p + 2 * stride, p + 3 * stride};
  // Two accumulators per row: eight independent FMA chains cover the FMA latency.
  __m256d acc[4][2];
  for (auto& r : acc) r[0] = r[1] = _mm256_setzero_pd();
  int k = 0;
  for (; k + 8 <= n; k += 8) {
    const __m256d x0 = _mm256_loadu_pd(v + k), x1 = _mm256_loadu_pd(v + k + 4);
    for (int a = 0; a < 4; ++a) {
      acc[a][0] = _mm256_fmadd_pd(_mm256_loadu_pd(q[a] + k), x0, acc[a][0]);
      acc[a][1] = _mm256_fmadd_pd(_mm256_loadu_pd(q[a] + k + 4), x1, acc[a][1]);
    }
  }
  for (int a = 0; a < 4; ++a) {
    double t = hsum_avx2(_mm256_add_pd(acc[a][0], acc[a][1]));
    for (int j = k; j < n; ++j) t += q[a][j] * v[j];
    out[a] = t;
  }
}

__attribute__((target("avx512f"))) void dot4_avx512(const double* p, std::size_t stride, const double* v,
                                                    int n, double* out) {
  const double* q[4] = {p, p + stride, p + 2 * stride, p + 3 * stride};
  __m512d acc[4][2];
  for (auto& r : acc) r[0] = r[1] = _mm512_setzero_pd();
  int k = 0;
  for (; k + 16 <= n; k += 16) {
    const __m512d x0 = _mm512_loadu_pd(v + k), x1 = _mm512_loadu_pd(v + k + 8);
    for (int a = 0; a < 4; ++a) {
      acc[a][0] = _mm512_fmadd_pd(_mm512_loadu_pd(q[a] + k), x0, acc[a][0]);
      acc[a][1] = _mm512_fmadd_pd(_mm512_loadu_pd(q[a] + k + 8), x1, acc[a][1]);
    }
  }
  // The remainder (fewer than 16) as one masked 8-wide step and a masked tail, zeros elsewhere.
  for (; k < n; k += 8) {
    const __mmask8 m = static_cast<__mmask8>(n - k >= 8 ? 0xff : (1u << (n - k)) - 1u);
    const __m512d x = _mm512_maskz_loadu_pd(m, v + k);
    for (int a = 0; a < 4; ++a) acc[a][0] = _mm512_fmadd_pd(_mm512_maskz_loadu_pd(m, q[a] + k), x, acc[a][0]);
  }
  for (int a = 0; a < 4; ++a) out[a] = _mm512_reduce_add_pd(_mm512_add_pd(acc[a][0], acc[a][1]));
}

#pragma GCC diagnostic pop

#endif

DenseDot4 dot4_for(InstructionSet isa) {
  switch (isa) {
#ifdef PEGASUS_X86_KERNELS
    case InstructionSet::kAvx512:
      return dot4_avx512;
    case InstructionSet::kAvx2Fma:
      return dot4_avx2;
#endif
    default:
      return dot4_sse2;
  }
}

}  // namespace

DenseDot4 dense_dot4_kernel(InstructionSet isa) { return dot4_for(isa); }

void dense_dot4(InstructionSet isa, const double* p, std::size_t stride, const double* v, int n,
                double* out) {
  dot4_for(isa)(p, stride, v, n, out);
}

}  // namespace pegasus::detail

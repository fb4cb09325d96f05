#pragma once
// The weighted Gram kernel behind LocalRegression::fit (lwr.hpp); internal to src/sysid.
//
// Data are stored in k-d tree order in blocks of 8 points (n rounded up to 8; padding points are 0 and weigh
// 0): a block holds, for its 8 points, one vector per stored column (the Gram columns, i.e. the inputs that
// some output regresses on and then the outputs that regress on something, followed by the inputs only the
// kernel uses; the constant input is not stored, see weight_row), so the points of a chunk are one contiguous
// stretch (the whole set, about 570 KB for the shipped 3400 points, lives in L2). Kernel coordinates are
// stored divided by their bandwidths (z = x / h), so a distance needs no multiply; the sums are then those of
// the scaled inputs, which lwr.cpp maps back. Each point's data row is kept apart as a double (for the
// cross-validation window). Leaves hold up to kLeaf points and start at multiples of 8.
//
// For a query the kernel visits the leaves in storage order, skips a leaf whose bounding box lies more than
// ln(1e16) * 2 beyond the smallest squared distance seen so far (seeded by the query's own leaf), and cuts
// each run of admitted leaves that follow one another into chunks of kChunk points. For a chunk it computes,
// 8 points per vector, the squared distances d^2 = sum_d (zq_d - z_d)^2 and the weights w = exp(-d^2 / 2)
// (own polynomial, below; 0 beyond the same threshold from the smallest d^2 before the chunk), and adds the
// upper triangle of sum_i (w_i a_i) a_i' in register tiles: the rows scaled by w (a copy the first tile of
// each row group makes), the columns read straight from the data blocks. Each lane of each entry is summed in
// point order within a chunk, and chunk by chunk. Three instruction sets (scalar, AVX2+FMA, AVX-512) run the
// same operations in the same order with fused multiply-adds everywhere (std::fma in the scalar one), so they
// agree bit for bit; only the tile shapes differ.
//
// Where a refit's time goes (AVX-512, Zen 5, shipped model; interleaved runs that each leave one phase out,
// minimum over samples of 200 refits; whole refit about 17.5 us): the Gram tiles about 11.7 us (175
// multiply-adds and 13 multiplies per vector of 8 points, about 106 cycles against a floor of 94; adding each
// tile's sums into the accumulators at the end of a chunk is about 3% of the refit, and larger chunks, which
// would do that less often, no longer fit L1), the distances, weights, leaf tests and lane sums about 5.3 us
// (the exp about 1 us of it; the distances wait on the data coming in from L2), the solve about 0.7 us.
#include <array>
#include <vector>

#include "pegasus/sysid/body_model.hpp"

namespace pegasus::sysid::detail {

inline constexpr int kLanes = 8;
inline constexpr int kLeaf = 32;                      // points per leaf (a multiple of kLanes)
inline constexpr int kChunk = 192;                    // points per Gram pass (a multiple of 8 kLanes)
inline constexpr int kMaxCols = kInputs + kBodyVars;  // Gram columns at most
inline constexpr int kMaxAcc =
    kInputs * kMaxCols * kLanes;  // tile accumulators at most (tiles never overlap)

// Which tile code runs (lwr_kernel.inc: tile): off the diagonal, or the first tile of a row group, on the
// diagonal, which also sums the constant input's column (moments) when it is not stored, and in the last row
// group also stands in w for that input's row.
enum TileKind : int { kOffDiagonal = 0, kDiagonalTile = 1, kDiagonalMoments = 2, kDiagonalWeightRow = 3 };
struct Tile {
  int r0, rows, c0, cols, offset;  // entries [r0, r0+rows) x [c0, c0+cols); accumulators at offset
  TileKind kind;
};
struct TilePlan {
  std::vector<Tile> tiles;
  int acc_size = 0;
};
// Row groups of up to max_rows rows; columns from the group's first row on, in tiles of up to
// min(max_cols, 24 / rows) columns (AVX-512 keeps 24 accumulators and the rows in its 32 registers); each
// tile's kind from its place and weight_row (KernelData).
TilePlan tile_plan(int rows, int cols, int max_rows, int max_cols, bool weight_row);

struct KernelData {
  int n = 0, n_pad = 0;  // points, padded to a multiple of kLanes
  int stride = 0;        // doubles per block of kLanes points (stored columns x kLanes)
  int nd = 0;            // kernel coordinates
  int m = 0, ncols = 0;  // Gram rows (inputs), Gram columns (inputs then outputs)
  // The last Gram row is the constant input's: its column is not stored (its entries are sums of w and of the
  // scaled rows w a_r), and the kernel's columns past it sit one to the left of their Gram columns.
  bool weight_row = false;
  int leaves = 0, leaves_pad = 0;  // leaves, padded to a multiple of kLanes
  // n_pad / kLanes blocks of `stride` doubles: per block the Gram columns, then the inputs the kernel uses
  // but no output regresses on, kLanes values each (padding: 0).
  const double* a = nullptr;
  std::array<int, kInputs> kernel_col{};  // column of each kernel coordinate
  const double* row = nullptr;            // n_pad: the data row of each point (padding: -1)
  const double* box_lo = nullptr;  // nd columns of leaves_pad: leaf bounding boxes of x / h (padding: 1e150)
  const double* box_hi = nullptr;
  const int* leaf_begin = nullptr;  // leaves + 1 entries
};

// The kLanes values of stored column `col` for the block of points starting at p (a multiple of kLanes).
inline const double* block_column(const KernelData& d, int col, int p) {
  return d.a + static_cast<std::ptrdiff_t>(p / kLanes) * d.stride + static_cast<std::ptrdiff_t>(col) * kLanes;
}

struct KernelQuery {
  std::array<double, kInputs> zq{};           // the query's kernel coordinates divided by their bandwidths
  double exclude_begin = 0, exclude_end = 0;  // data rows [begin, end) weigh 0
  int seed_leaf = 0;                          // the leaf the query falls in
  double cutoff = 0;                          // skip points with d^2 > smallest d^2 + cutoff
};

struct KernelResult {
  // Upper triangle (c >= r) of sum_i w_i a_ir a_ic at [r * kMaxCols + c], r < m, c < ncols.
  std::array<double, kInputs * kMaxCols> sum{};
  double weight_sum = 0, max_weight = 0;
  int points = 0;
  double best = 0;  // the smallest squared distance (infinity when every point is excluded)
};

void gram_scalar(const KernelData& d, const TilePlan& plan, const KernelQuery& q, KernelResult* out);
void gram_avx2(const KernelData& d, const TilePlan& plan, const KernelQuery& q, KernelResult* out);
void gram_avx512(const KernelData& d, const TilePlan& plan, const KernelQuery& q, KernelResult* out);

// The factorisation behind LocalRegression's solve (lwr.cpp, ScaledInverse), on kInputs x kInputs row-major
// arrays whose entries beyond the first m rows and columns are 0, run on rows of kInputs / kLanes vectors by
// the same instruction sets as the kernel, with fused multiply-adds everywhere, so that they too agree bit
// for bit.
struct Factor {
  alignas(64) double a[kInputs][kInputs];    // in: the Jacobi-scaled matrix A (symmetric, unit diagonal)
  alignas(64) double l[kInputs][kInputs];    // out: row j holds column j of A's Cholesky factor L (l[j][i] =
                                             // L_ij, i >= j; the entries left of the diagonal are scratch)
  alignas(64) double inv[kInputs][kInputs];  // out: A^-1 = L^-T L^-1 (exactly symmetric)
  double inv_diag[kInputs];                  // out: 1 / L_ii
};
// Factorises A = L L' and inverts it; returns rcond = 1 / (|A|_1 |A^-1|_1), or 0 when a pivot is not positive
// (then l and inv are unspecified).
double invert_scalar(int m, Factor* f);
double invert_avx2(int m, Factor* f);
double invert_avx512(int m, Factor* f);
// out[o] = A^-1 v[o] for o < count.
using Row = double[kInputs];
void multiply_inverse_scalar(int m, const Factor& f, int count, const Row* v, Row* out);
void multiply_inverse_avx2(int m, const Factor& f, int count, const Row* v, Row* out);
void multiply_inverse_avx512(int m, const Factor& f, int count, const Row* v, Row* out);

// exp(x) for x <= 0 by the kernel's polynomial (0 below -708), one value, scalar path: for tests.
double kernel_exp(double x);

}  // namespace pegasus::sysid::detail

#include "pegasus/envs/interval_mdp.hpp"

#include <bit>

#include "pegasus/core/error.hpp"

namespace pegasus {
namespace {

std::uint64_t binomial(int n, int k) {
  if (k < 0 || k > n) return 0;
  std::uint64_t c = 1;
  for (int j = 1; j <= k; ++j) c = c * static_cast<std::uint64_t>(n - k + j) / static_cast<std::uint64_t>(j);
  return c;
}

// The rank-th k-subset of {0..n-1} in colexicographic order, as a bit mask.
std::uint32_t unrank_subset(int n, int k, std::uint64_t rank) {
  std::uint32_t mask = 0;
  for (int element = n - 1; k > 0; --element) {
    const std::uint64_t below = binomial(element, k);  // subsets whose largest element is < element
    if (rank >= below) {
      mask |= 1u << element;
      rank -= below;
      --k;
    }
  }
  return mask;
}

}  // namespace

std::uint64_t IntervalMdp::action_count(int level) {
  std::uint64_t total = 0;
  for (int k = 1; k <= level; ++k) total += binomial(1 << k, 1 << (k - 1));
  return total;
}

std::uint32_t IntervalMdp::bins_of(Action i, int* level) {
  for (int k = 1; k <= kMaxLevel; ++k) {
    const std::uint64_t here = binomial(1 << k, 1 << (k - 1));
    if (i < here) {
      *level = k;
      return unrank_subset(1 << k, 1 << (k - 1), i);
    }
    i -= here;
  }
  throw InputError("interval MDP: action index beyond the enumerated levels");
}

double IntervalMdp::measure(Action i) {
  int k = 0;
  const std::uint32_t bins = bins_of(i, &k);
  return static_cast<double>(std::popcount(bins)) / static_cast<double>(1u << k);
}

bool IntervalMdp::in_set(Action i, double p) {
  int k = 0;
  const std::uint32_t bins = bins_of(i, &k);
  const auto bin = static_cast<std::uint32_t>(p * static_cast<double>(1u << k));
  return (bins >> (bin < (1u << k) ? bin : (1u << k) - 1)) & 1u;
}

}  // namespace pegasus

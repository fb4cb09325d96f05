#include "pegasus/mdp/finite_mdp.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "pegasus/core/error.hpp"

namespace pegasus {

namespace {
constexpr double kSumTolerance = 1e-9;
}  // namespace

bool FiniteMdp::has_absorbing_states() const {
  return std::any_of(absorbing.begin(), absorbing.end(), [](std::uint8_t x) { return x != 0; });
}

void FiniteMdp::refresh_expected_reward() {
  expected_reward.assign(num_rows(), 0.0);
  for (std::size_t r = 0; r < num_rows(); ++r) {
    double sum = 0.0;
    for (std::uint32_t k = row_start[r]; k < row_start[r + 1]; ++k) sum += probability[k] * reward[k];
    expected_reward[r] = sum;
  }
}

FiniteMdpBuilder::FiniteMdpBuilder(int num_states, int num_actions, double gamma)
    : S_(num_states), A_(num_actions), gamma_(gamma) {
  if (num_states < 1) throw InputError(fmt::format("mdp: expected at least 1 state, got {}", num_states));
  if (num_actions < 1) throw InputError(fmt::format("mdp: expected at least 1 action, got {}", num_actions));
  if (!(gamma >= 0.0 && gamma <= 1.0))
    throw InputError(fmt::format("mdp: gamma must lie in [0, 1], got {}", gamma));
  const auto rows = static_cast<std::size_t>(S_) * static_cast<std::size_t>(A_);
  rows_.resize(rows);
  given_.assign(rows, 0);
  state_reward_.assign(static_cast<std::size_t>(S_), 0.0);
  state_action_reward_.assign(rows, 0.0);
  initial_.assign(static_cast<std::size_t>(S_), 0.0);
  absorbing_.assign(static_cast<std::size_t>(S_), 0);
}

#define PEGASUS_CHECK_STATE(s, what) \
  if ((s) < 0 || (s) >= S_) throw InputError(fmt::format("mdp: {} {} outside [0, {})", what, s, S_));
#define PEGASUS_CHECK_ACTION(a) \
  if ((a) < 0 || (a) >= A_) throw InputError(fmt::format("mdp: action {} outside [0, {})", a, A_));

void FiniteMdpBuilder::set_absorbing(int s) {
  PEGASUS_CHECK_STATE(s, "absorbing state");
  absorbing_[static_cast<std::size_t>(s)] = 1;
}

void FiniteMdpBuilder::set_state_reward(int s, double r) {
  PEGASUS_CHECK_STATE(s, "state");
  state_reward_[static_cast<std::size_t>(s)] = r;
}

void FiniteMdpBuilder::set_state_action_reward(int s, int a, double r) {
  PEGASUS_CHECK_STATE(s, "state");
  PEGASUS_CHECK_ACTION(a);
  state_action_reward_[static_cast<std::size_t>(s) * A_ + a] = r;
}

void FiniteMdpBuilder::add_transition(int s, int a, int next, double probability, double reward) {
  PEGASUS_CHECK_STATE(s, "state");
  PEGASUS_CHECK_ACTION(a);
  PEGASUS_CHECK_STATE(next, "successor state");
  if (!(probability >= 0.0 && probability <= 1.0))
    throw InputError(fmt::format("mdp: P(s={}, a={}, s'={}) = {} outside [0, 1]", s, a, next, probability));
  if (!std::isfinite(reward))
    throw InputError(fmt::format("mdp: R(s={}, a={}, s'={}) is not finite", s, a, next));
  const auto r = static_cast<std::size_t>(s) * A_ + a;
  given_[r] = 1;
  if (probability == 0.0) return;
  auto& row = rows_[r];
  for (auto& e : row) {
    if (e.next == next) {  // merge duplicates: keep the expected reward of the merged entry
      const double p = std::min(1.0, e.p + probability);  // a sum may round to 1 + 2^-52
      e.r = (e.p * e.r + probability * reward) / (e.p + probability);
      e.p = p;
      return;
    }
  }
  row.push_back({next, probability, reward});
}

void FiniteMdpBuilder::set_initial(int s, double probability) {
  PEGASUS_CHECK_STATE(s, "initial state");
  if (!(probability >= 0.0 && probability <= 1.0))
    throw InputError(fmt::format("mdp: initial probability of state {} = {} outside [0, 1]", s, probability));
  initial_[static_cast<std::size_t>(s)] = probability;
  initial_given_ = true;
}

#undef PEGASUS_CHECK_STATE
#undef PEGASUS_CHECK_ACTION

FiniteMdp FiniteMdpBuilder::build() const {
  FiniteMdp m;
  m.num_states = S_;
  m.num_actions = A_;
  m.gamma = gamma_;
  m.absorbing = absorbing_;
  const std::size_t rows = rows_.size();
  m.row_start.assign(rows + 1, 0);
  std::size_t nnz = 0;
  for (std::size_t r = 0; r < rows; ++r) {
    const int s = static_cast<int>(r / static_cast<std::size_t>(A_));
    nnz += absorbing_[static_cast<std::size_t>(s)] ? 1 : rows_[r].size();
  }
  if (nnz >= std::numeric_limits<std::uint32_t>::max())
    throw InputError(fmt::format("mdp: {} transitions exceed the 2^32 limit of the row index", nnz));
  m.next_state.reserve(nnz);
  m.probability.reserve(nnz);
  m.reward.reserve(nnz);
  for (std::size_t r = 0; r < rows; ++r) {
    const int s = static_cast<int>(r / static_cast<std::size_t>(A_));
    const int a = static_cast<int>(r % static_cast<std::size_t>(A_));
    if (absorbing_[static_cast<std::size_t>(s)]) {
      m.next_state.push_back(s);
      m.probability.push_back(1.0);
      m.reward.push_back(0.0);
    } else {
      if (!given_[r]) throw InputError(fmt::format("mdp: no transitions given for state {} action {}", s, a));
      auto row = rows_[r];
      std::sort(row.begin(), row.end(), [](const Entry& x, const Entry& y) { return x.next < y.next; });
      const double extra = state_reward_[static_cast<std::size_t>(s)] + state_action_reward_[r];
      for (const auto& e : row) {
        m.next_state.push_back(e.next);
        m.probability.push_back(e.p);
        m.reward.push_back(e.r + extra);
      }
    }
    m.row_start[r + 1] = static_cast<std::uint32_t>(m.next_state.size());
  }
  m.refresh_expected_reward();
  if (initial_given_) {
    m.initial = initial_;
  } else {
    m.initial.assign(static_cast<std::size_t>(S_), 0.0);
    int live = 0;
    for (int s = 0; s < S_; ++s) live += absorbing_[static_cast<std::size_t>(s)] ? 0 : 1;
    for (int s = 0; s < S_; ++s) {
      if (live == 0) {
        m.initial[static_cast<std::size_t>(s)] = 1.0 / S_;
      } else if (!absorbing_[static_cast<std::size_t>(s)]) {
        m.initial[static_cast<std::size_t>(s)] = 1.0 / live;
      }
    }
  }
  validate(m);
  return m;
}

void validate(const FiniteMdp& m, const std::string& what) {
  if (m.num_states < 1) throw InputError(fmt::format("{}: expected at least 1 state", what));
  if (m.num_actions < 1) throw InputError(fmt::format("{}: expected at least 1 action", what));
  if (!(m.gamma >= 0.0 && m.gamma <= 1.0))
    throw InputError(fmt::format("{}: gamma must lie in [0, 1], got {}", what, m.gamma));
  const std::size_t S = static_cast<std::size_t>(m.num_states);
  const std::size_t rows = m.num_rows();
  if (m.row_start.size() != rows + 1 || m.row_start.front() != 0)
    throw InputError(fmt::format("{}: row_start must have S*A+1 = {} entries starting at 0", what, rows + 1));
  const std::size_t nnz = m.row_start.back();
  if (m.next_state.size() != nnz || m.probability.size() != nnz || m.reward.size() != nnz)
    throw InputError(fmt::format("{}: transition arrays must all have {} entries", what, nnz));
  if (m.expected_reward.size() != rows || m.absorbing.size() != S || m.initial.size() != S)
    throw InputError(fmt::format("{}: per-row or per-state arrays have the wrong size", what));
  for (std::size_t r = 0; r < rows; ++r) {
    const int s = static_cast<int>(r / static_cast<std::size_t>(m.num_actions));
    const int a = static_cast<int>(r % static_cast<std::size_t>(m.num_actions));
    if (m.row_start[r + 1] < m.row_start[r])
      throw InputError(fmt::format("{}: row_start decreases at row {}", what, r));
    double sum = 0.0;
    for (std::uint32_t k = m.row_start[r]; k < m.row_start[r + 1]; ++k) {
      const int n = m.next_state[k];
      const double p = m.probability[k];
      if (n < 0 || n >= m.num_states)
        throw InputError(
            fmt::format("{}: state {} action {}: successor {} outside [0, {})", what, s, a, n, m.num_states));
      if (!(p >= 0.0 && p <= 1.0))
        throw InputError(fmt::format("{}: state {} action {}: probability {} of successor {} outside [0, 1]",
                                     what, s, a, p, n));
      if (!std::isfinite(m.reward[k]))
        throw InputError(
            fmt::format("{}: state {} action {}: reward of successor {} is not finite", what, s, a, n));
      if (m.is_absorbing(s) && (n != s || m.reward[k] != 0.0))
        throw InputError(fmt::format(
            "{}: absorbing state {} must loop to itself with reward 0 under action {}", what, s, a));
      sum += p;
    }
    if (std::abs(sum - 1.0) > kSumTolerance)
      throw InputError(fmt::format(
          "{}: state {} action {}: probabilities sum to {:.12g}, expected 1 within 1e-9", what, s, a, sum));
  }
  double dsum = 0.0;
  for (std::size_t s = 0; s < S; ++s) {
    const double p = m.initial[s];
    if (!(p >= 0.0 && p <= 1.0))
      throw InputError(fmt::format("{}: initial probability {} of state {} outside [0, 1]", what, p, s));
    dsum += p;
  }
  if (std::abs(dsum - 1.0) > kSumTolerance)
    throw InputError(
        fmt::format("{}: initial distribution sums to {:.12g}, expected 1 within 1e-9", what, dsum));
  if (m.gamma == 1.0) check_proper(m, what);
}

std::optional<int> find_improper_state(const FiniteMdp& m) {
  // Greatest-fixed-point elimination: a state leaves X once none of its actions keeps the whole support in
  // X. outside[r] counts the successors of row r outside X; a row "traps" while outside[r] == 0.
  const int S = m.num_states, A = m.num_actions;
  std::vector<std::uint8_t> in_x(static_cast<std::size_t>(S));
  for (int s = 0; s < S; ++s) in_x[static_cast<std::size_t>(s)] = m.is_absorbing(s) ? 0 : 1;
  std::vector<int> outside(m.num_rows(), 0);
  std::vector<int> trapping(static_cast<std::size_t>(S), 0);  // rows of s with outside == 0
  // Predecessor lists (row ids that have s as a successor), CSR-built.
  std::vector<std::uint32_t> pred_start(static_cast<std::size_t>(S) + 1, 0);
  for (std::size_t k = 0; k < m.num_entries(); ++k)
    ++pred_start[static_cast<std::size_t>(m.next_state[k]) + 1];
  for (int s = 0; s < S; ++s)
    pred_start[static_cast<std::size_t>(s) + 1] += pred_start[static_cast<std::size_t>(s)];
  std::vector<std::uint32_t> pred_row(m.num_entries());
  {
    std::vector<std::uint32_t> fill(pred_start.begin(), pred_start.end() - 1);
    for (std::size_t r = 0; r < m.num_rows(); ++r)
      for (std::uint32_t k = m.row_start[r]; k < m.row_start[r + 1]; ++k)
        pred_row[fill[static_cast<std::size_t>(m.next_state[k])]++] = static_cast<std::uint32_t>(r);
  }
  std::vector<int> queue;
  for (int s = 0; s < S; ++s) {
    if (!in_x[static_cast<std::size_t>(s)]) continue;
    for (int a = 0; a < A; ++a) {
      const std::size_t r = m.row(s, a);
      for (std::uint32_t k = m.row_start[r]; k < m.row_start[r + 1]; ++k)
        if (!in_x[static_cast<std::size_t>(m.next_state[k])]) ++outside[r];
      if (outside[r] == 0) ++trapping[static_cast<std::size_t>(s)];
    }
    if (trapping[static_cast<std::size_t>(s)] == 0) queue.push_back(s);
  }
  for (int s : queue) in_x[static_cast<std::size_t>(s)] = 0;
  for (std::size_t qi = 0; qi < queue.size(); ++qi) {
    const int t = queue[qi];
    for (std::uint32_t j = pred_start[static_cast<std::size_t>(t)];
         j < pred_start[static_cast<std::size_t>(t) + 1]; ++j) {
      const std::size_t r = pred_row[j];
      const int s = static_cast<int>(r / static_cast<std::size_t>(A));
      if (!in_x[static_cast<std::size_t>(s)]) continue;
      if (outside[r]++ == 0 && --trapping[static_cast<std::size_t>(s)] == 0) {
        in_x[static_cast<std::size_t>(s)] = 0;
        queue.push_back(s);
      }
    }
  }
  for (int s = 0; s < S; ++s)
    if (in_x[static_cast<std::size_t>(s)]) return s;
  return std::nullopt;
}

void check_proper(const FiniteMdp& m, const std::string& what) {
  if (const auto s = find_improper_state(m))
    throw InputError(fmt::format(
        "{}: gamma = 1 requires a proper MDP, but from state {} some policy never reaches an absorbing state",
        what, *s));
}

FiniteMdp with_gamma(FiniteMdp mdp, double gamma) {
  mdp.gamma = gamma;
  validate(mdp);
  return mdp;
}

double max_abs_reward(const FiniteMdp& m) {
  double best = 0.0;
  for (std::size_t k = 0; k < m.num_entries(); ++k) best = std::max(best, std::abs(m.reward[k]));
  return best;
}

}  // namespace pegasus

#pragma once
// The "hashed" remap of §4.6: g'(s, a, p) = g(s, a, h_{s,a}(p)) with h_{s,a}(p) = fract(k(s,a) p) and
// k(s,a) drawn uniformly from {1, ..., 1000} for each (s, a) (footnote 12). g' describes the same
// (PO)MDP as g, but is a far more "complex" function of p, so PEGASUS should do no better with it.
#include <cmath>
#include <cstdint>
#include <cstring>
#include <span>
#include <type_traits>

#include "pegasus/models/model.hpp"

namespace pegasus {

// A 64-bit key for a state or action: the value itself for integers, FNV-1a of the object's bytes for
// other trivially copyable types without padding.
template <class T>
std::uint64_t model_key(const T& value) {
  if constexpr (std::is_integral_v<T> || std::is_enum_v<T>) {
    return static_cast<std::uint64_t>(value);
  } else {
    static_assert(std::has_unique_object_representations_v<T> || std::is_floating_point_v<T> ||
                      std::is_trivially_copyable_v<T>,
                  "model_key needs a trivially copyable state/action");
    unsigned char bytes[sizeof(T)];
    std::memcpy(bytes, &value, sizeof(T));
    std::uint64_t h = 1469598103934665603ull;
    for (unsigned char b : bytes) h = (h ^ b) * 1099511628211ull;
    return h;
  }
}

template <SimulativeModel M>
class HashedModel {
 public:
  using State = typename M::State;
  using Action = typename M::Action;
  using Observation = typename M::Observation;

  static constexpr std::uint32_t kMaxMultiplier = 1000;

  HashedModel(M base, std::uint64_t hash_seed) : base_(std::move(base)), keys_(hash_seed) {
    check_noise_dims(base_);
  }

  const M& base() const { return base_; }
  int state_dim() const { return base_.state_dim(); }
  int noise_dim() const { return base_.noise_dim(); }
  int initial_noise_dim() const { return base_.initial_noise_dim(); }
  ActionSpace action_space() const { return base_.action_space(); }
  State initial_state(std::span<const double> p0) const { return base_.initial_state(p0); }
  bool terminal(const State& s) const { return base_.terminal(s); }
  Observation observe(const State& s) const { return base_.observe(s); }
  double reward(const State& s, const Action& a, const State& next) const {
    return transition_reward(base_, s, a, next);
  }
  double event_fraction(const State& s, const Action& a, const State& next) const {
    return transition_event_fraction(base_, s, a, next);
  }

  // k(s, a) for noise coordinate j, in {1, ..., 1000}.
  std::uint32_t multiplier(const State& s, const Action& a, int j) const {
    const std::uint64_t ks = model_key(s), ka = model_key(a);
    const std::uint64_t bits =
        keys_.bits64(RngDomain::kModelHash, static_cast<std::uint32_t>(ks ^ (ks >> 32)),
                     static_cast<std::uint32_t>(ka ^ (ka >> 32)), static_cast<std::uint32_t>(j));
    return 1 + static_cast<std::uint32_t>(bits % kMaxMultiplier);
  }

  State step(const State& s, const Action& a, std::span<const double> p) const {
    NoiseBuffer hashed(p.size());
    for (std::size_t j = 0; j < p.size(); ++j) {
      const double x = static_cast<double>(multiplier(s, a, static_cast<int>(j))) * p[j];
      hashed[j] = x - std::floor(x);  // fract(k p)
    }
    return base_.step(s, a, hashed.span());
  }

 private:
  M base_;
  CounterRng keys_;
};

}  // namespace pegasus

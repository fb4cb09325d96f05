#pragma once
// The identified helicopter as a deterministic simulative model g(s, a, p) in world coordinates (thesis
// §5.2.1-5.2.2, Eqs 5.5-5.6), for PEGASUS (the hover issue).
//
// Stepping at 50 Hz from a model identified at rate R (10 Hz by default): every `refit_every` steps the local
// regression is refitted at the current state and control (§5.2.2: "refit the linearity at 10 Hz"); in
// between the coefficients are held. One 50 Hz step changes each body variable by
//   (known part + beta'x) * dt / dt_R + sqrt(var * dt / dt_R) * Phi^{-1}(p_k)
// (§5.2.2: a 10 Hz model s' = s + f + eps becomes s' = s + f/5 + eps' with var(eps') = var(eps)/5), var the
// predictive variance of Eq 5.4 at the refit point. p has one uniform per body variable (noise_dim 8).
// A model identified with AR(1) noise (identify.hpp: NoiseCorrelation) splits each variable's noise into a
// white part, (1 - share) var dt / dt_R per step, and an AR part carried in the state (`colored`) with the
// correlation rho^(dt / dt_R) per step, scaled so that one model step's sum of it has the variance share *
// var of the identification; p then has a second uniform per body variable (noise_dim 16), and the AR part
// starts from its stationary distribution (initial_noise_dim 14).
//
// Crash (footnote 13): when X'WX is singular to numerical precision at a refit, or when the query leaves the
// data's support: no training point within `support_bandwidths` bandwidths in the kernel's metric (largest
// weight below exp(-support_bandwidths^2 / 2)); also when |roll| or |pitch| exceeds max_tilt_rad or the state
// is not finite, and (each off by default) when the position leaves the start's set point by more than
// max_position_error_m, the speed exceeds max_speed_mps or any Euler-angle rate max_rate_radps (a judged
// cost's envelope, vehicle/vehicle.hpp's [envelope]). The crashing transition pays crash_reward (-50000) and
// the state is absorbing.
//
// Wind (issue 53; off by default, and then no arithmetic and no draw changes): the air moves at
//   w_W = wind + wind_sigma * (n0, n1, 0) + gust
// with (n0, n1) standard normal draws of the scenario's start (one steady wind per scenario, horizontal) and
// `gust` an AR(1) process per world axis of standard deviation gust_sigma and correlation time gust_tau_s
// (g' = rho g + sigma sqrt(1 - rho^2) n, rho = exp(-dt / tau); it starts from its stationary distribution).
// The identified model steps the motion relative to the air (its regression queried at the airspeed), and the
// air frame moves on at w through the step: the model's velocity-dependent forces (drag, flapping) act on the
// airspeed, and the ground velocity is the air-relative one plus w. Draws: wind_sigma > 0 adds 2 start
// uniforms, gust_sigma > 0 adds 3 start and 3 per-step uniforms after the model's own, so every other draw
// keeps its place.
#include <array>
#include <limits>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "pegasus/models/action_space.hpp"
#include "pegasus/sysid/identify.hpp"
#include "pegasus/vehicle/disturbance.hpp"

namespace pegasus::sysid {

// How often the local regression is refitted by default, wherever the model is stepped (hover and
// manoeuvre training, the as-trained errors identify reports, horizon_mse): every kRefitSeconds, the thesis's
// 10 Hz (§5.2.2: "refit the linearity at 10 Hz"), whatever the model's own rate. A refit costs about a
// microsecond per training row per refit on one core (15,000 rows at 25 Hz from 10 minutes of logs: ~100 us),
// and refitting at every step of a 25 Hz model made one hover evaluation cost 3.1 CPU s against 1.1 s at
// 0.1 s, for a starting policy's U-hat within 0.3% (bench/heli_bench.cpp BM_HeliHoverUhat25Hz; issue 53).
inline constexpr double kRefitSeconds = 0.1;
// Steps of 1 / step_rate_hz between refits: kRefitSeconds rounded to the nearest step, at least 1 (50 Hz: 5,
// 25 Hz: 3, 10 Hz and slower: 1).
int refit_steps_at(double step_rate_hz);

struct LearnedModelOptions {
  double dt = 0.02;               // s, 50 Hz (§5.1)
  int refit_every = 5;            // steps between refits (§5.2.2)
  double support_bandwidths = 4;  // support margin (see above)
  double crash_reward = -50000;   // footnote 13
  double max_tilt_rad = 1.0;
  double max_position_error_m = std::numeric_limits<double>::infinity();  // from start's x, y, z
  double max_speed_mps = std::numeric_limits<double>::infinity();
  double max_rate_radps = std::numeric_limits<double>::infinity();
  Disturbance disturbance{};
  bool noise = true;  // false: the mean model (p ignored)
  std::array<double, kLogStates> start{0, 0, -10, 0, 0, 0, 0, 0, 0, 0, 0, 0};  // s0 before perturbation
  double start_pos_sigma = 0, start_vel_sigma = 0;  // s0 perturbation from p0 (initial_noise_dim 6)
  bool IsValid(std::string* error) const;
};

class LearnedHeliModel {
 public:
  struct State {
    SimState sim{};
    std::array<InputVec, kBodyVars> beta{};  // held coefficients of the last refit
    BodyVec variance = BodyVec::Zero();      // predictive variance at the last refit, per model step
    BodyVec colored = BodyVec::Zero();       // the AR part of the noise of the last step (AR(1) models)
    std::array<double, 3> wind{0, 0, 0};     // the scenario's steady wind, m/s (W)
    std::array<double, 3> gust{0, 0, 0};     // the gust process's value, m/s (W)
    int step = 0;
    bool crashed = false;
  };
  using Action = std::array<double, 4>;
  using Observation = std::array<double, kLogStates>;

  LearnedHeliModel(std::shared_ptr<const IdentifiedModel> model, LearnedModelOptions options = {});

  int state_dim() const { return kLogStates; }
  int noise_dim() const { return own_noise_dim() + (gusty() ? 3 : 0); }
  int initial_noise_dim() const {
    return own_initial_noise_dim() + (options_.disturbance.wind_sigma > 0 ? 2 : 0) + (gusty() ? 3 : 0);
  }
  ActionSpace action_space() const;
  State initial_state(std::span<const double> p0) const;
  State step(const State& s, const Action& a, std::span<const double> p) const;
  bool terminal(const State& s) const { return s.crashed; }
  Observation observe(const State& s) const { return s.sim.world; }
  // Only the crash is priced here; the task's reward (Eq 5.9-5.10) wraps this model.
  double reward(const State& s, const Action&, const State& next) const {
    return (!s.crashed && next.crashed) ? options_.crash_reward : 0.0;
  }
  const IdentifiedModel& model() const { return *model_; }
  const LearnedModelOptions& options() const { return options_; }

 private:
  std::shared_ptr<const IdentifiedModel> model_;
  LearnedModelOptions options_;
  double min_weight_;
  int own_noise_dim() const { return colored_ ? 2 * kBodyVars : kBodyVars; }
  int own_initial_noise_dim() const { return colored_ ? 6 + kBodyVars : 6; }
  bool gusty() const { return options_.noise && options_.disturbance.gust_sigma > 0; }
  std::array<double, 3> air_of(const State& s) const;  // the air's velocity, W
  bool outside_envelope(const SimState& s) const;
  bool colored_ = false;  // the identified model has AR(1) noise (and options_.noise is on)
  // Per body variable: the AR part's correlation per step, its stationary variance per step as a fraction of
  // the model step's variance, and the white part's variance per step as that fraction.
  BodyVec rho_step_ = BodyVec::Zero(), colored_scale_ = BodyVec::Zero(), white_scale_ = BodyVec::Zero();
};

}  // namespace pegasus::sysid

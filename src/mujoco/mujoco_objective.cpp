#include "pegasus/mujoco/mujoco_objective.hpp"

#include "pegasus/optimizers/run_progress.hpp"
#include "pegasus/parallel/mpi.hpp"

namespace pegasus {

MujocoObjective::MujocoObjective(std::shared_ptr<const MujocoEnvironment> env,
                                 std::shared_ptr<const MujocoPolicy> policy, ScenarioSet scenarios,
                                 const ExecutionContext& where, bool normalize)
    : env_(std::move(env)),
      policy_(std::move(policy)),
      scenarios_(std::move(scenarios)),
      pool_(where.pool),
      ranks_(where.ranks),
      normalize_(normalize),
      normalizer_(env_->observation_dim(), env_->task().observation_clip),
      moments_(env_->observation_dim()),
      scenario_moments_(static_cast<std::size_t>(scenarios_.size()),
                        ObservationMoments(env_->observation_dim())),
      start_(std::chrono::steady_clock::now()) {}

void MujocoObjective::count_batch(std::size_t thetas) {
  const auto m = static_cast<std::size_t>(scenarios_.size());
  for (std::size_t k = 0; k < thetas * m; ++k) {
    control_steps_ += static_cast<std::int64_t>(steps_[k]);
    crashes_ += static_cast<std::int64_t>(crashed_[k]);
  }
  rollouts_ += static_cast<std::int64_t>(thetas * m);
  for (std::size_t t = 0; t < thetas; ++t) {
    ++evaluations_;
    double sum = 0.0;
    for (std::size_t i = 0; i < m; ++i) sum += returns_[t * m + i];
    if (!std::isfinite(sum) && nonfinite_evaluations_++ == 0) first_nonfinite_evaluation_ = evaluations_;
    if (first_success_.has_value()) continue;
    bool all = true;
    for (std::size_t i = 0; i < m; ++i) all = all && success_[t * m + i] != 0.0;
    if (all)
      first_success_ = FirstSuccess{
          .evaluation = evaluations_,
          .control_steps = control_steps_,
          .seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start_).count()};
  }
}

std::unique_ptr<MujocoSlot> MujocoObjective::acquire() {
  {
    const std::lock_guard lock(slots_mutex_);
    if (!free_slots_.empty()) {
      auto slot = std::move(free_slots_.back());
      free_slots_.pop_back();
      return slot;
    }
  }
  return std::make_unique<MujocoSlot>(*env_);
}

void MujocoObjective::release(std::unique_ptr<MujocoSlot> slot) {
  const std::lock_guard lock(slots_mutex_);
  free_slots_.push_back(std::move(slot));
}

double MujocoObjective::evaluate(std::span<const double> theta) {
  const Theta one(theta.begin(), theta.end());
  double value = 0.0;
  evaluate_batch(std::span<const Theta>(&one, 1), std::span<double>(&value, 1));
  return value;
}

void MujocoObjective::evaluate_batch(std::span<const Theta> thetas, std::span<double> values) {
  const auto m = static_cast<std::size_t>(scenarios_.size());
  const std::size_t n = thetas.size() * m;
  returns_.assign(n, 0.0);
  steps_.assign(n, 0.0);
  crashed_.assign(n, 0.0);
  success_.assign(n, 0.0);
  const mpi::Share share = mpi::collective_share(ranks_);
  auto body = [&](std::size_t j) {
    const std::size_t k = share.item(j);
    auto slot = acquire();
    const MujocoRolloutResult r =
        env_->rollout(*policy_, thetas[k / m], normalizer_, scenarios_, static_cast<int>(k % m), *slot);
    release(std::move(slot));
    returns_[k] = r.training_return;  // U-hat of the reward the search maximises
    steps_[k] = r.steps;
    crashed_[k] = r.crashed ? 1.0 : 0.0;
    success_[k] = r.success ? 1.0 : 0.0;
  };
  const std::size_t owned = share.count(n);
  if (pool_) {
    pool_->parallel_for(owned, body, 1);
  } else {
    for (std::size_t j = 0; j < owned; ++j) body(j);
  }
  mpi::allgather_shares(returns_, share);
  mpi::allgather_shares(steps_, share);
  mpi::allgather_shares(crashed_, share);
  mpi::allgather_shares(success_, share);
  for (std::size_t t = 0; t < thetas.size(); ++t) {
    double sum = 0.0;
    for (std::size_t i = 0; i < m; ++i) sum += returns_[t * m + i];
    values[t] = sum / static_cast<double>(m);
  }
  count_batch(thetas.size());
}

std::vector<MujocoRolloutResult> MujocoObjective::rollout_all(std::span<const double> theta,
                                                              const ScenarioSet& scenarios) {
  std::vector<MujocoRolloutResult> out(static_cast<std::size_t>(scenarios.size()));
  auto body = [&](std::size_t i) {
    auto slot = acquire();
    out[i] = env_->rollout(*policy_, theta, normalizer_, scenarios, static_cast<int>(i), *slot);
    release(std::move(slot));
  };
  if (pool_) {
    pool_->parallel_for(out.size(), body, 1);
  } else {
    for (std::size_t i = 0; i < out.size(); ++i) body(i);
  }
  return out;
}

double MujocoObjective::EvaluateAndUpdateNormalizer(std::span<const double> theta) {
  if (!normalize_) return central_value_ = evaluate(theta);
  const auto m = static_cast<std::size_t>(scenarios_.size());
  returns_.assign(m, 0.0);
  steps_.assign(m, 0.0);
  crashed_.assign(m, 0.0);
  success_.assign(m, 0.0);
  auto body = [&](std::size_t i) {
    auto slot = acquire();
    ObservationMoments& moments = scenario_moments_[i];
    moments.reset();
    const MujocoRolloutResult r =
        env_->rollout(*policy_, theta, normalizer_, scenarios_, static_cast<int>(i), *slot, &moments);
    release(std::move(slot));
    returns_[i] = r.training_return;
    steps_[i] = r.steps;
    crashed_[i] = r.crashed ? 1.0 : 0.0;
    success_[i] = r.success ? 1.0 : 0.0;
  };
  if (pool_) {
    pool_->parallel_for(m, body, 1);
  } else {
    for (std::size_t i = 0; i < m; ++i) body(i);
  }
  double sum = 0.0;
  for (std::size_t i = 0; i < m; ++i) {
    sum += returns_[i];
    moments_.merge(scenario_moments_[i]);
  }
  count_batch(1);
  moments_.freeze_into(&normalizer_);
  return central_value_ = sum / static_cast<double>(m);
}

nlohmann::json MujocoObjective::NormalizerState() const {
  nlohmann::json counters = {{"control_steps", control_steps_},
                             {"rollouts", rollouts_},
                             {"crashes", crashes_},
                             {"evaluations", evaluations_},
                             {"nonfinite_evaluations", nonfinite_evaluations_},
                             {"first_nonfinite_evaluation", first_nonfinite_evaluation_}};
  if (first_success_)
    counters["first_success"] = {{"evaluation", first_success_->evaluation},
                                 {"control_steps", first_success_->control_steps},
                                 {"seconds", DoubleToJson(first_success_->seconds)}};
  return {{"moments", moments_.to_json()}, {"counters", counters}};
}

void MujocoObjective::RestoreFrozenNormalizer(const nlohmann::json& frozen) {
  moments_ = ObservationMoments::from_json(frozen, env_->observation_dim());
  if (normalize_) moments_.freeze_into(&normalizer_);
}

void MujocoObjective::RestoreNormalizer(const nlohmann::json& state) {
  RestoreFrozenNormalizer(StateField(state, "moments"));
  const nlohmann::json& counters = StateField(state, "counters");
  control_steps_ = StateInteger(counters, "control_steps");
  rollouts_ = StateInteger(counters, "rollouts");
  crashes_ = StateInteger(counters, "crashes");
  evaluations_ = StateInteger(counters, "evaluations");
  // Absent from checkpoints written before they were counted.
  nonfinite_evaluations_ =
      counters.contains("nonfinite_evaluations") ? StateInteger(counters, "nonfinite_evaluations") : 0;
  first_nonfinite_evaluation_ = counters.contains("first_nonfinite_evaluation")
                                    ? StateInteger(counters, "first_nonfinite_evaluation")
                                    : 0;
  first_success_.reset();
  if (counters.contains("first_success")) {
    const nlohmann::json& f = counters.at("first_success");
    first_success_ = FirstSuccess{
        .evaluation = StateInteger(f, "evaluation"),
        .control_steps = StateInteger(f, "control_steps"),
        .seconds = DoubleFromJson(StateField(f, "seconds"), "normalizer.counters.first_success.seconds")};
  }
}

}  // namespace pegasus

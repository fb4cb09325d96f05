#pragma once
// theta -> U-hat(theta) on a MuJoCo environment (thesis §4.4.2, Eq 4.22): the mean discounted return of
// the policy over m fixed scenarios, each a full rollout's randomness. The return is of the training reward:
// the task's reward with its training-only terms (MujocoRolloutResult::training_return), which is the task's
// reward itself when it has none.
//
// Work is parallel over (theta, scenario) pairs on the context's thread pool and split across its ranks
// (ExecutionContext, parallel/mpi.hpp); every pair writes its own slot and sums run in scenario order, so
// U-hat, the step counts and the crash counts are bit-identical for any number of threads and ranks. Each
// thread takes an mjData slot from a small free list for the length of one rollout: slots are made the first
// time more rollouts run at once than slots exist (at most one per thread), never inside a rollout.
//
// Observation normalisation (ARS "V2", optimizers/augmented_random_search.hpp): EvaluateAndUpdateNormalizer
// runs theta's m rollouts on every rank (no communication: each rank computes them all, the same bits),
// merges their observation statistics in scenario order into the running moments and freezes them.
#include <atomic>
#include <chrono>
#include <cstdint>
#include <limits>
#include <memory>
#include <mutex>
#include <optional>
#include <utility>
#include <vector>

#include "pegasus/mujoco/mujoco_env.hpp"
#include "pegasus/optimizers/augmented_random_search.hpp"
#include "pegasus/optimizers/objective.hpp"
#include "pegasus/parallel/execution_context.hpp"

namespace pegasus {

class MujocoObjective final : public Objective, public ObservationNormalizing {
 public:
  // normalize = false keeps the identity normalisation (EvaluateAndUpdateNormalizer then only evaluates).
  MujocoObjective(std::shared_ptr<const MujocoEnvironment> env, std::shared_ptr<const MujocoPolicy> policy,
                  ScenarioSet scenarios, const ExecutionContext& where, bool normalize = true);

  const ParameterSpec& parameters() const override { return policy_->parameters(); }
  double evaluate(std::span<const double> theta) override;
  void evaluate_batch(std::span<const Theta> thetas, std::span<double> values) override;

  double EvaluateAndUpdateNormalizer(std::span<const double> theta) override;
  // U-hat of the last EvaluateAndUpdateNormalizer call (ARS's central policy of an iteration), handed out
  // once: NaN when there was none since the last take (the other methods have no central policy).
  double TakeCentralValue() {
    return std::exchange(central_value_, std::numeric_limits<double>::quiet_NaN());
  }
  nlohmann::json NormalizerState() const override;
  void RestoreNormalizer(const nlohmann::json& state) override;
  // The running moments the frozen normaliser was made from (the normaliser is a function of them).
  nlohmann::json FrozenNormalizer() const override { return moments_.to_json(); }
  void RestoreFrozenNormalizer(const nlohmann::json& frozen) override;

  const ObservationNormalizer& normalizer() const { return normalizer_; }
  const MujocoEnvironment& environment() const { return *env_; }
  // Totals over every rollout this objective ran (all ranks): control steps (times frame_skip for physics
  // steps), rollouts and crashed rollouts.
  std::int64_t control_steps() const { return control_steps_; }
  std::int64_t rollouts() const { return rollouts_; }
  std::int64_t crashes() const { return crashes_; }
  // Evaluations whose U-hat was not finite (NaN or infinite), and the number of the first (0: none): a search
  // that met one is no success (issue 51).
  std::int64_t nonfinite_evaluations() const { return nonfinite_evaluations_; }
  std::int64_t first_nonfinite_evaluation() const { return first_nonfinite_evaluation_; }
  // The first evaluated theta whose rollouts all met the task's success criterion on the training
  // scenarios: its evaluation number (1-based, in the optimizer's order), the control steps run up to and
  // including its batch, and the wall seconds since this objective was made (or carried by a checkpoint).
  struct FirstSuccess {
    std::int64_t evaluation = 0, control_steps = 0;
    double seconds = 0.0;
  };
  const std::optional<FirstSuccess>& first_success() const { return first_success_; }

  // Per-scenario results of theta on `scenarios` with the frozen normaliser, computed on this rank alone
  // (for final evaluations; not counted in the totals).
  std::vector<MujocoRolloutResult> rollout_all(std::span<const double> theta, const ScenarioSet& scenarios);

 private:
  class SlotLease;
  std::unique_ptr<MujocoSlot> acquire();
  void release(std::unique_ptr<MujocoSlot> slot);
  // Adds the batch's counts (steps_, crashed_, success_ of `thetas` thetas) to the totals, in order.
  void count_batch(std::size_t thetas);

  std::shared_ptr<const MujocoEnvironment> env_;
  std::shared_ptr<const MujocoPolicy> policy_;
  ScenarioSet scenarios_;
  ThreadPool* pool_;
  mpi::Communicator ranks_;  // split evaluate_batch's pairs; the other evaluations run on this rank alone
  bool normalize_;
  ObservationNormalizer normalizer_;
  ObservationMoments moments_;
  std::vector<ObservationMoments> scenario_moments_;         // one per scenario, merged in order
  std::vector<double> returns_, steps_, crashed_, success_;  // per (theta, scenario) pair
  std::int64_t control_steps_ = 0, rollouts_ = 0, crashes_ = 0, evaluations_ = 0;
  std::int64_t nonfinite_evaluations_ = 0, first_nonfinite_evaluation_ = 0;
  double central_value_ = std::numeric_limits<double>::quiet_NaN();
  std::optional<FirstSuccess> first_success_;
  std::chrono::steady_clock::time_point start_;
  std::mutex slots_mutex_;
  std::vector<std::unique_ptr<MujocoSlot>> free_slots_;
};

}  // namespace pegasus

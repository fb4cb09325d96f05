// The shaping experiments' config sections (experiments/runs/shaping_config.hpp).
#include "pegasus/experiments/runs/shaping_config.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <sstream>
#include <string>
#include <vector>

namespace pegasus {
namespace {

std::vector<std::string> split_list(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream in(text);
  std::string item;
  while (std::getline(in, item, ',')) {
    item.erase(0, item.find_first_not_of(' '));
    item.erase(item.find_last_not_of(' ') + 1);
    out.push_back(item);
  }
  return out;
}

}  // namespace

void declare_shaping_learning_config(ConfigSchema& s, ShapingWorld world) {
  const bool grid = world == ShapingWorld::kGridworld;
  const ShapingExperimentOptions d;  // the gridworld's; the flag world's size and curves are its own
  if (grid) {
    s.add_int("size", d.size, "grid side n: start (0, 0), goal (n-1, n-1); the thesis used 10 and 50")
        .range(2, 1000);
  } else {
    s.add_int("size", 5, "flag world: 5 (5x5, 5 flags) or 8 (8x8, 7 flags)")
        .validate([](const FieldValue& v) {
          const auto n = std::get<std::int64_t>(v);
          return n == 5 || n == 8 ? std::string() : std::string("5 or 8");
        });
  }
  s.add_int("runs", d.runs, "independent Sarsa runs per potential (the thesis averaged 40)").range(1, 100000);
  s.add_int("trials", d.trials, "trials (episodes from start to goal) per run").range(1, 10000000);
  const std::vector<std::string> allowed = grid ? std::vector<std::string>{"none", "half", "phi0"}
                                                : std::vector<std::string>{"none", "half", "phi0", "phi1"};
  s.add_string(
       "potentials", grid ? fmt::format("{}", fmt::join(d.potentials, ",")) : "none,phi0,phi1",
       grid ? "curves to learn: none, half (0.5 Phi0), phi0 (-manhattan/0.8)"
            : "curves to learn: none, phi0 (flags collected), phi1 (remaining route/0.8), half (0.5 Phi0)")
      .validate([allowed](const FieldValue& v) {
        const auto items = split_list(std::get<std::string>(v));
        std::string expected = "a comma-separated list of distinct names from";
        for (const auto& a : allowed) expected += " " + a;
        if (items.empty()) return expected;
        for (std::size_t i = 0; i < items.size(); ++i) {
          if (std::find(allowed.begin(), allowed.end(), items[i]) == allowed.end()) return expected;
          if (std::find(items.begin(), items.begin() + static_cast<std::ptrdiff_t>(i), items[i]) !=
              items.begin() + static_cast<std::ptrdiff_t>(i))
            return expected;
        }
        return std::string();
      });
  s.add_double("alpha", d.alpha, "Sarsa learning rate (thesis: 0.02)").greater_than(0).max(1);
  s.add_double("epsilon", d.epsilon, "epsilon-greedy exploration rate (thesis: 0.1)").range(0, 1);
  // Below 1: with moves that always go where intended, a policy that walks into a wall never reaches the
  // goal, and the undiscounted world then has no finite values to learn.
  s.add_double("intended", d.intended,
               "probability a move goes the intended way, else a uniformly random direction (below 1: the "
               "world is undiscounted)")
      .greater_than(0)
      .less_than(1);
  s.add_int("max_steps_per_trial", d.max_steps_per_trial,
            "a trial is cut off after this many steps (and counted)")
      .min(1);
}

ShapingExperimentOptions read_shaping_learning_config(const ConfigSchema& c, ShapingWorld world,
                                                      std::uint64_t seed, int threads) {
  ShapingExperimentOptions o;
  o.world = world;
  o.size = static_cast<int>(c.get_int("size"));
  o.potentials = split_list(c.get_string("potentials"));
  o.runs = static_cast<int>(c.get_int("runs"));
  o.trials = static_cast<int>(c.get_int("trials"));
  o.alpha = c.get_double("alpha");
  o.epsilon = c.get_double("epsilon");
  o.intended = c.get_double("intended");
  o.max_steps_per_trial = c.get_int("max_steps_per_trial");
  o.seed = seed;
  o.threads = threads;
  return o;  // run_shaping_learning checks it
}

// ---- shaping progress-bonus ------------------------------------------------------------------------------

void declare_progress_bonus_config(ConfigSchema& s) {
  const ProgressBonusOptions d;
  s.add_int("size", d.size, "grid side n: start (0, 0), goal (n-1, n-1)").range(2, 1000);
  s.add_double("bonus", d.bonus, "reward for a step that ends closer to the goal (shuttling pays when > 2)")
      .greater_than(0)
      .less_than(1e9);
  s.add_int("episodes", d.episodes, "Sarsa episodes per learner").range(1, 10000000);
  s.add_double("alpha", d.alpha, "Sarsa learning rate").greater_than(0).max(1);
  s.add_double("epsilon", d.epsilon, "epsilon-greedy exploration rate").range(0, 1);
  s.add_double("gamma", d.gamma, "discount of the learners (and of the potential-based F)").range(0, 1);
  s.add_int("max_steps_per_episode", d.max_steps_per_episode, "an episode is cut off after this many steps")
      .min(1);
}

ProgressBonusOptions read_progress_bonus_config(const ConfigSchema& c, std::uint64_t seed) {
  ProgressBonusOptions o;
  o.size = static_cast<int>(c.get_int("size"));
  o.bonus = c.get_double("bonus");
  o.episodes = static_cast<int>(c.get_int("episodes"));
  o.alpha = c.get_double("alpha");
  o.epsilon = c.get_double("epsilon");
  o.gamma = c.get_double("gamma");
  o.max_steps_per_episode = c.get_int("max_steps_per_episode");
  o.seed = seed;
  return o;
}

void declare_shaping_audit_config(ConfigSchema& s) {
  s.add_string("mdp", "", "the MDP, a pegasus-mdp JSON file (format: include/pegasus/mdp/mdp_json.hpp)")
      .input_file();
  s.add_string("shaping", "",
               "the shaping reward F(s, a, s'), a pegasus-shaping JSON file (shaping_table.hpp)")
      .input_file();
  s.add_double("tolerance", ShapingAuditRunOptions{}.tolerance,
               "relative tolerance: residuals below tolerance * (1 + max |F|) count as zero")
      .greater_than(0)
      .less_than(1);
  s.add_int("print_limit", ShapingAuditRunOptions{}.print_limit,
            "print Phi for at most this many states (all of them go to potential.csv)")
      .min(0);
}

ShapingAuditRunOptions read_shaping_audit_config(const ConfigSchema& c) {
  return {.mdp_file = c.get_path("mdp"),
          .shaping_file = c.get_path("shaping"),
          .tolerance = c.get_double("tolerance"),
          .print_limit = static_cast<int>(c.get_int("print_limit"))};
}

}  // namespace pegasus

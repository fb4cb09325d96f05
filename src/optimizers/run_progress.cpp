#include "pegasus/optimizers/run_progress.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "pegasus/core/error.hpp"

namespace pegasus {

using nlohmann::json;

json DoubleToJson(double value) {
  if (std::isnan(value)) return "nan";
  if (std::isinf(value)) return value > 0 ? "inf" : "-inf";
  return value;
}

double DoubleFromJson(const json& value, std::string_view field) {
  if (value.is_number()) return value.get<double>();
  if (value.is_string()) {
    const auto& text = value.get_ref<const std::string&>();
    if (text == "nan") return std::numeric_limits<double>::quiet_NaN();
    if (text == "inf") return std::numeric_limits<double>::infinity();
    if (text == "-inf") return -std::numeric_limits<double>::infinity();
  }
  throw InputError(fmt::format("checkpoint {}: expected a number or \"nan\", \"inf\", \"-inf\", got {}",
                               field, value.dump()));
}

json VectorToJson(std::span<const double> values) {
  json out = json::array();
  for (const double v : values) out.push_back(DoubleToJson(v));
  return out;
}

std::vector<double> VectorFromJson(const json& values, std::string_view field) {
  if (!values.is_array()) throw InputError(fmt::format("checkpoint {}: expected an array of numbers", field));
  std::vector<double> out;
  out.reserve(values.size());
  for (const auto& v : values) out.push_back(DoubleFromJson(v, field));
  return out;
}

json SummaryToJson(const OptimizerSummary& s) {
  json history = json::array();
  for (const auto& r : s.history)
    history.push_back({r.iteration, r.evaluations, DoubleToJson(r.value), r.seconds});
  return {{"method", s.method},
          {"termination", std::string(TerminationTypeName(s.termination_type))},
          {"message", s.message},
          {"iterations", s.iterations},
          {"evaluations", s.evaluations},
          {"initial_value", DoubleToJson(s.initial_value)},
          {"best_value", DoubleToJson(s.best_value)},
          {"best_theta", VectorToJson(s.best_theta)},
          {"final_step", DoubleToJson(s.final_step)},
          {"wall_seconds", s.wall_seconds},
          {"history", history}};
}

OptimizerSummary SummaryFromJson(const json& j, std::string_view field) {
  const std::string f(field);
  OptimizerSummary s;
  s.method = j.at("method").get<std::string>();
  const std::string t = j.at("termination").get<std::string>();
  for (auto type :
       {TerminationType::kConvergence, TerminationType::kMaxIterations, TerminationType::kMaxEvaluations,
        TerminationType::kSearchComplete, TerminationType::kFailure})
    if (TerminationTypeName(type) == t) s.termination_type = type;
  s.message = j.at("message").get<std::string>();
  s.iterations = j.at("iterations").get<std::int64_t>();
  s.evaluations = j.at("evaluations").get<std::int64_t>();
  s.initial_value = DoubleFromJson(j.at("initial_value"), f + ".initial_value");
  s.best_value = DoubleFromJson(j.at("best_value"), f + ".best_value");
  s.best_theta = VectorFromJson(j.at("best_theta"), f + ".best_theta");
  s.final_step = DoubleFromJson(j.at("final_step"), f + ".final_step");
  s.wall_seconds = j.at("wall_seconds").get<double>();
  for (const auto& r : j.at("history"))
    s.history.push_back({.iteration = r.at(0).get<std::int64_t>(),
                         .evaluations = r.at(1).get<std::int64_t>(),
                         .value = DoubleFromJson(r.at(2), f + ".history"),
                         .seconds = r.at(3).get<double>()});
  return s;
}

namespace {

const json& Field(const json& object, const char* name, std::string_view context) {
  const auto it = object.find(name);
  if (it == object.end()) throw InputError(fmt::format("checkpoint: missing field {}{}", context, name));
  return *it;
}

std::int64_t IntegerField(const json& object, const char* name) {
  const json& value = Field(object, name, "");
  if (!value.is_number_integer()) throw InputError(fmt::format("checkpoint {}: expected an integer", name));
  return value.get<std::int64_t>();
}

}  // namespace

const json& StateField(const json& state, const char* name) { return Field(state, name, "state."); }

std::int64_t StateInteger(const json& state, const char* name) {
  const json& value = StateField(state, name);
  if (!value.is_number_integer())
    throw InputError(fmt::format("checkpoint state.{}: expected an integer", name));
  return value.get<std::int64_t>();
}

std::uint64_t StateUnsigned(const json& state, const char* name) {
  const json& value = StateField(state, name);
  if (!value.is_number_unsigned())
    throw InputError(fmt::format("checkpoint state.{}: expected a non-negative integer", name));
  return value.get<std::uint64_t>();
}

std::string CheckpointMethod(const json& checkpoint) {
  if (!checkpoint.is_object() || !checkpoint.contains("format") || checkpoint["format"] != kCheckpointFormat)
    throw InputError(fmt::format("checkpoint: expected a JSON object with format \"{}\"", kCheckpointFormat));
  const json& method = Field(checkpoint, "method", "");
  if (!method.is_string()) throw InputError("checkpoint method: expected a string");
  return method.get<std::string>();
}

bool RejectOption(std::string* error, std::string_view field, std::string_view expected, double got) {
  if (error) *error = fmt::format("{}: expected {}, got {}", field, expected, got);
  return false;
}

bool OptimizerRunOptions::IsValidFor(std::string_view method, std::string* error) const {
  auto fail = [error](std::string message) {
    if (error) *error = std::move(message);
    return false;
  };
  if (checkpoint_every < 0)
    return fail(fmt::format("checkpoint_every: expected >= 0 (0 = off), got {}", checkpoint_every));
  if (checkpoint_every > 0 && !on_checkpoint)
    return fail("on_checkpoint: expected a callback when checkpoint_every > 0");
  if (resume_from) {
    std::string found;
    try {
      found = CheckpointMethod(*resume_from);
    } catch (const InputError& e) {
      return fail(fmt::format("resume_from: {}", e.what()));
    }
    if (found != method)
      return fail(fmt::format("resume_from: expected a checkpoint written by method \"{}\", got \"{}\"",
                              method, found));
  }
  return true;
}

RunProgress::RunProgress(std::string method, const ParameterSpec& spec, IterationCallbacks callbacks)
    : method_(std::move(method)),
      callbacks_(std::move(callbacks)),
      initial_value_(std::numeric_limits<double>::quiet_NaN()),
      best_value_(std::numeric_limits<double>::quiet_NaN()),
      started_(std::chrono::steady_clock::now()) {
  for (const auto& p : spec.all()) parameter_names_.push_back(p.name);
  best_theta_ = spec.initial();
  history_.reserve(256);
}

bool RunProgress::Offer(std::span<const double> theta, double value) {
  if (has_best_ && !IsImprovement(value, best_value_)) return false;
  has_best_ = true;
  best_value_ = value;
  std::copy(theta.begin(), theta.end(), best_theta_.begin());
  return true;
}

bool RunProgress::EndIteration(double seconds) {
  ++iterations_;
  history_.push_back({iterations_, evaluations_, best_value_, seconds});
  bool go_on = true;
  for (IterationCallback* callback : callbacks_) {
    const IterationReport report{
        method_, history_.back(),
        has_best_ ? std::span<const double>(best_theta_) : std::span<const double>()};
    if ((*callback)(report) == CallbackReturnType::kTerminate) go_on = false;
  }
  return go_on;
}

bool RunProgress::BudgetSpent(std::int64_t max_iterations, std::int64_t max_evaluations,
                              std::int64_t next_evaluations, TerminationType* termination,
                              std::string* message, std::string_view iteration) const {
  if (iterations_ >= max_iterations) {
    *termination = TerminationType::kMaxIterations;
    *message = fmt::format("reached max_iterations = {}", max_iterations);
    return true;
  }
  if (evaluations_ + next_evaluations > max_evaluations) {
    *termination = TerminationType::kMaxEvaluations;
    *message = fmt::format("{} needs {} more evaluations; {} of max_evaluations = {} used", iteration,
                           next_evaluations, evaluations_, max_evaluations);
    return true;
  }
  return false;
}

double RunProgress::Seconds() const {
  return seconds_before_resume_ +
         std::chrono::duration<double>(std::chrono::steady_clock::now() - started_).count();
}

json RunProgress::Checkpoint(json state, bool include_history) const {
  json history = json::array();
  if (include_history)
    for (const auto& r : history_)
      history.push_back({r.iteration, r.evaluations, DoubleToJson(r.value), DoubleToJson(r.seconds)});
  return json{{"format", kCheckpointFormat},
              {"version", kCheckpointVersion},
              {"method", method_},
              {"parameters", parameter_names_},
              {"iterations", iterations_},
              {"evaluations", evaluations_},
              {"elapsed_seconds", Seconds()},
              {"initial_value", DoubleToJson(initial_value_)},
              {"has_best", has_best_},
              {"best_value", DoubleToJson(best_value_)},
              {"best_theta", VectorToJson(best_theta_)},
              {"history", std::move(history)},
              {"state", std::move(state)}};
}

const json& RunProgress::Resume(const json& checkpoint, bool restore_counters) {
  try {
    return ResumeUnchecked(checkpoint, restore_counters);
  } catch (const json::exception& e) {
    throw InputError(fmt::format("checkpoint: malformed ({})", e.what()));
  }
}

const json& RunProgress::ResumeUnchecked(const json& checkpoint, bool restore_counters) {
  const std::string method = CheckpointMethod(checkpoint);
  if (method != method_)
    throw InputError(fmt::format("checkpoint method: expected \"{}\", got \"{}\"", method_, method));
  if (IntegerField(checkpoint, "version") != kCheckpointVersion)
    throw InputError(fmt::format("checkpoint version: expected {}", kCheckpointVersion));
  const json& names = Field(checkpoint, "parameters", "");
  if (!names.is_array() || names.get<std::vector<std::string>>() != parameter_names_)
    throw InputError(fmt::format("checkpoint parameters: expected the names [{}] of this problem",
                                 fmt::join(parameter_names_, ", ")));
  const json& state = Field(checkpoint, "state", "");
  if (!state.is_object()) throw InputError("checkpoint state: expected an object");

  resumed_ = true;
  seconds_before_resume_ = DoubleFromJson(Field(checkpoint, "elapsed_seconds", ""), "elapsed_seconds");
  if (!restore_counters) return state;

  iterations_ = IntegerField(checkpoint, "iterations");
  evaluations_ = IntegerField(checkpoint, "evaluations");
  initial_value_ = DoubleFromJson(Field(checkpoint, "initial_value", ""), "initial_value");
  has_best_ = Field(checkpoint, "has_best", "").get<bool>();
  best_value_ = DoubleFromJson(Field(checkpoint, "best_value", ""), "best_value");
  Theta best = VectorFromJson(Field(checkpoint, "best_theta", ""), "best_theta");
  if (best.size() != best_theta_.size())
    throw InputError(fmt::format("checkpoint best_theta: expected {} values", best_theta_.size()));
  best_theta_ = std::move(best);
  history_.clear();
  for (const auto& row : Field(checkpoint, "history", "")) {
    if (!row.is_array() || row.size() != 4)
      throw InputError("checkpoint history: expected rows [iteration, evaluations, value, seconds]");
    history_.push_back({row[0].get<std::int64_t>(), row[1].get<std::int64_t>(),
                        DoubleFromJson(row[2], "history value"), DoubleFromJson(row[3], "history seconds")});
  }
  return state;
}

void RunProgress::Finish(TerminationType type, std::string message, OptimizerSummary* summary) {
  summary->method = method_;
  summary->parameter_names = parameter_names_;
  summary->termination_type = type;
  summary->message = std::move(message);
  summary->iterations = iterations_;
  summary->evaluations = evaluations_;
  summary->replayed_evaluations = replayed_evaluations_;
  summary->resumed = resumed_;
  summary->initial_value = initial_value_;
  summary->best_value = best_value_;
  summary->best_theta = best_theta_;
  summary->wall_seconds = Seconds();
  summary->history = std::move(history_);
  history_.clear();
}

Theta StartingTheta(const ParameterSpec& spec, const Theta& requested) {
  if (requested.empty()) return spec.initial();
  if (requested.size() != spec.size())
    throw InputError(fmt::format("starting theta: expected {} values (one per parameter), got {}",
                                 spec.size(), requested.size()));
  Theta theta = requested;
  for (std::size_t i = 0; i < theta.size(); ++i)
    if (!std::isfinite(theta[i]))
      throw InputError(fmt::format("starting theta: parameter {} is not finite", spec[i].name));
  spec.clamp(theta);
  return theta;
}

}  // namespace pegasus

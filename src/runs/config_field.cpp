// One config field: its bounds, choices and checks, and the sentence that says what it expects.
#include <fmt/format.h>

#include <algorithm>
#include <cmath>

#include "config_values.hpp"
#include "pegasus/core/error.hpp"
#include "pegasus/runs/config.hpp"

namespace pegasus {

using detail::is_int_type;
using detail::is_number_type;
using detail::toml_quoted;

ConfigField::ConfigField(std::string name, FieldType type, FieldValue default_value, std::string help)
    : name_(std::move(name)), type_(type), default_(std::move(default_value)), help_(std::move(help)) {
  std::replace(help_.begin(), help_.end(), '\n', ' ');
}

ConfigField& ConfigField::min(double lo) {
  if (!is_number_type(type_)) throw std::logic_error("min() on non-numeric field " + name_);
  lo_ = Bound{lo, true};
  return *this;
}
ConfigField& ConfigField::max(double hi) {
  if (!is_number_type(type_)) throw std::logic_error("max() on non-numeric field " + name_);
  hi_ = Bound{hi, true};
  return *this;
}
ConfigField& ConfigField::greater_than(double lo) {
  if (!is_number_type(type_)) throw std::logic_error("greater_than() on non-numeric field " + name_);
  lo_ = Bound{lo, false};
  return *this;
}
ConfigField& ConfigField::bounds(const NumberSetting& setting) {
  if (setting.lower_open)
    greater_than(setting.lower);
  else
    min(setting.lower);
  return max(setting.upper);
}
ConfigField& ConfigField::less_than(double hi) {
  if (!is_number_type(type_)) throw std::logic_error("less_than() on non-numeric field " + name_);
  hi_ = Bound{hi, false};
  return *this;
}
ConfigField& ConfigField::choices(std::vector<std::string> allowed) {
  if (type_ != FieldType::kString) throw std::logic_error("choices() on non-string field " + name_);
  choices_ = std::move(allowed);
  return *this;
}
ConfigField& ConfigField::min_size(std::size_t n) {
  if (type_ != FieldType::kIntList && type_ != FieldType::kDoubleList && type_ != FieldType::kStringList) {
    throw std::logic_error("min_size() on non-list field " + name_);
  }
  min_size_ = n;
  return *this;
}
ConfigField& ConfigField::size(std::size_t n) {
  min_size(n);
  exact_size_ = true;
  return *this;
}
ConfigField& ConfigField::validate(Validator check) {
  validators_.push_back(std::move(check));
  return *this;
}
ConfigField& ConfigField::input_file(Digest digest) {
  if (type_ != FieldType::kString && type_ != FieldType::kStringList)
    throw std::logic_error("ConfigField::input_file: " + name_ + " is no string or list of strings");
  input_file_ = true;
  input_digest_ = std::move(digest);
  return *this;
}

ConfigField& ConfigField::affects_results(bool yes) {
  affects_results_ = yes;
  return *this;
}

bool ConfigField::in_bounds(double x) const {
  if (std::isnan(x)) return false;
  if (lo_ && (lo_->inclusive ? x < lo_->value : x <= lo_->value)) return false;
  if (hi_ && (hi_->inclusive ? x > hi_->value : x >= hi_->value)) return false;
  return true;
}

std::string ConfigField::expectation() const {
  auto bound = [&](double v) {
    if (is_int_type(type_) && std::abs(v) < 9e18 && v == std::floor(v)) {
      return std::to_string(static_cast<std::int64_t>(v));
    }
    return format_double(v);
  };
  std::string bounds;
  if (lo_ && hi_) {
    bounds = fmt::format("in {}{}, {}{}", lo_->inclusive ? '[' : '(', bound(lo_->value), bound(hi_->value),
                         hi_->inclusive ? ']' : ')');
  } else if (lo_) {
    bounds = fmt::format("{} {}", lo_->inclusive ? ">=" : ">", bound(lo_->value));
  } else if (hi_) {
    bounds = fmt::format("{} {}", hi_->inclusive ? "<=" : "<", bound(hi_->value));
  }
  auto with = [&](const std::string& what) { return bounds.empty() ? what : what + " " + bounds; };
  switch (type_) {
    case FieldType::kInt:
      return with("an integer");
    case FieldType::kDouble:
      return with("a number");
    case FieldType::kBool:
      return "true or false";
    case FieldType::kString: {
      if (choices_.empty()) return "a string";
      std::string out = "one of ";
      for (std::size_t i = 0; i < choices_.size(); ++i) out += (i ? ", " : "") + toml_quoted(choices_[i]);
      return out;
    }
    case FieldType::kIntList:
    case FieldType::kDoubleList: {
      const char* what = type_ == FieldType::kIntList ? "integers" : "numbers";
      std::string out =
          exact_size_ ? fmt::format("a list of {} {}", min_size_, what) : fmt::format("a list of {}", what);
      if (min_size_ > 0 && !exact_size_) out += fmt::format(" (at least {})", min_size_);
      if (!bounds.empty()) out += ", each " + bounds;
      return out;
    }
    case FieldType::kStringList:
      if (exact_size_) return fmt::format("a list of {} strings", min_size_);
      return min_size_ > 0 ? fmt::format("a list of strings (at least {})", min_size_) : "a list of strings";
  }
  return "?";
}

std::string ConfigField::check(const FieldValue& value) const {
  const auto size_ok = [&](std::size_t n) { return n >= min_size_ && (!exact_size_ || n == min_size_); };
  bool ok = true;
  switch (type_) {
    case FieldType::kInt:
      ok = in_bounds(static_cast<double>(std::get<std::int64_t>(value)));
      break;
    case FieldType::kDouble:
      ok = in_bounds(std::get<double>(value));
      break;
    case FieldType::kBool:
      break;
    case FieldType::kString:
      ok = choices_.empty() ||
           std::find(choices_.begin(), choices_.end(), std::get<std::string>(value)) != choices_.end();
      break;
    case FieldType::kIntList: {
      const auto& xs = std::get<std::vector<std::int64_t>>(value);
      ok = size_ok(xs.size()) && std::all_of(xs.begin(), xs.end(), [&](std::int64_t x) {
             return in_bounds(static_cast<double>(x));
           });
      break;
    }
    case FieldType::kDoubleList: {
      const auto& xs = std::get<std::vector<double>>(value);
      ok = size_ok(xs.size()) && std::all_of(xs.begin(), xs.end(), [&](double x) { return in_bounds(x); });
      break;
    }
    case FieldType::kStringList:
      ok = size_ok(std::get<std::vector<std::string>>(value).size());
      break;
  }
  if (!ok) return expectation();
  // Every number read from a user is finite: an `inf` that passed a one-sided bound would be refused later
  // under an internal name, or run to a meaningless result (issue 16).
  // A field whose own default is not finite (an "unbounded" limit) takes such values on purpose.
  auto all_finite = [&](const FieldValue& v) {
    if (type_ == FieldType::kDouble) return std::isfinite(std::get<double>(v));
    if (type_ == FieldType::kDoubleList) {
      const auto& xs = std::get<std::vector<double>>(v);
      return std::all_of(xs.begin(), xs.end(), [](double x) { return std::isfinite(x); });
    }
    return true;
  };
  const bool non_finite = all_finite(default_) && !all_finite(value);
  if (non_finite) {
    std::string expected = expectation();
    for (const std::string_view plain : {"a number", "a list of numbers"}) {
      if (expected.starts_with(plain)) {
        expected.insert(plain == "a number" ? 2 : 10, "finite ");
        break;
      }
    }
    return expected;
  }
  for (const auto& validator : validators_) {
    std::string expected = validator(value);
    if (!expected.empty()) return expected;
  }
  return {};
}

}  // namespace pegasus

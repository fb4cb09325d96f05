// ULog's basic types and the values of a parsed file: type sizes and names, a parameter's value, a topic's
// fields and columns, topics by name and instance.
#include <fmt/format.h>

#include <algorithm>
#include <array>
#include <string_view>

#include "pegasus/core/error.hpp"
#include "pegasus/logs/ulog.hpp"
#include "ulog_bytes.hpp"

namespace pegasus::logs {

namespace detail {

double decode(UlogType type, const std::uint8_t* p) {
  switch (type) {
    case UlogType::kInt8:
      return load<std::int8_t>(p);
    case UlogType::kUint8:
    case UlogType::kBool:
    case UlogType::kChar:
      return load<std::uint8_t>(p);
    case UlogType::kInt16:
      return load<std::int16_t>(p);
    case UlogType::kUint16:
      return load<std::uint16_t>(p);
    case UlogType::kInt32:
      return load<std::int32_t>(p);
    case UlogType::kUint32:
      return load<std::uint32_t>(p);
    case UlogType::kInt64:
      return static_cast<double>(load<std::int64_t>(p));
    case UlogType::kUint64:
      return static_cast<double>(load<std::uint64_t>(p));
    case UlogType::kFloat:
      return load<float>(p);
    case UlogType::kDouble:
      return load<double>(p);
    case UlogType::kNested:
      break;
  }
  return 0;
}

}  // namespace detail

namespace {

struct BasicTypeName {
  std::string_view name;
  UlogType type;
};
constexpr std::array<BasicTypeName, 12> kBasicTypes = {{{"int8_t", UlogType::kInt8},
                                                        {"uint8_t", UlogType::kUint8},
                                                        {"int16_t", UlogType::kInt16},
                                                        {"uint16_t", UlogType::kUint16},
                                                        {"int32_t", UlogType::kInt32},
                                                        {"uint32_t", UlogType::kUint32},
                                                        {"int64_t", UlogType::kInt64},
                                                        {"uint64_t", UlogType::kUint64},
                                                        {"float", UlogType::kFloat},
                                                        {"double", UlogType::kDouble},
                                                        {"bool", UlogType::kBool},
                                                        {"char", UlogType::kChar}}};

}  // namespace

std::size_t ulog_type_size(UlogType type) {
  switch (type) {
    case UlogType::kInt8:
    case UlogType::kUint8:
    case UlogType::kBool:
    case UlogType::kChar:
      return 1;
    case UlogType::kInt16:
    case UlogType::kUint16:
      return 2;
    case UlogType::kInt32:
    case UlogType::kUint32:
    case UlogType::kFloat:
      return 4;
    case UlogType::kInt64:
    case UlogType::kUint64:
    case UlogType::kDouble:
      return 8;
    case UlogType::kNested:
      break;
  }
  return 0;
}

std::optional<UlogType> ulog_basic_type(std::string_view name) {
  for (const auto& b : kBasicTypes)
    if (b.name == name) return b.type;
  return std::nullopt;
}

std::optional<double> UlogValue::as_number() const {
  const auto t = ulog_basic_type(type);
  if (!t || *t == UlogType::kChar || raw.size() != ulog_type_size(*t)) return std::nullopt;
  return detail::decode(*t, reinterpret_cast<const std::uint8_t*>(raw.data()));
}

const UlogLeaf* UlogTopic::find(std::string_view field) const {
  for (const UlogLeaf& l : leaves)
    if (l.name == field) return &l;
  return nullptr;
}

double UlogTopic::value(const UlogLeaf& leaf, std::size_t row) const {
  return detail::decode(leaf.type, data.data() + row * record_size + leaf.offset);
}

std::vector<double> UlogTopic::column(std::string_view field, std::string_view file) const {
  const UlogLeaf* leaf = find(field);
  if (!leaf) {
    std::string names;
    for (const UlogLeaf& l : leaves) names += (names.empty() ? "" : ", ") + l.name;
    throw InputError(fmt::format("{}: topic {} (instance {}) has no field '{}'; its fields: {}", file, name,
                                 multi_id, field, names));
  }
  if (leaf->count != 1)
    throw InputError(fmt::format("{}: field {}.{} is a string, expected a number", file, name, field));
  std::vector<double> out(rows());
  for (std::size_t r = 0; r < rows(); ++r) out[r] = value(*leaf, r);
  return out;
}

const UlogTopic* UlogFile::topic(std::string_view name, int multi_id) const {
  for (const UlogTopic& t : topics)
    if (t.name == name && t.multi_id == multi_id) return &t;
  return nullptr;
}

std::vector<int> UlogFile::instances(std::string_view name) const {
  std::vector<int> out;
  for (const UlogTopic& t : topics)
    if (t.name == name) out.push_back(t.multi_id);
  std::sort(out.begin(), out.end());
  return out;
}

}  // namespace pegasus::logs

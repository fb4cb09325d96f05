#include "pegasus/logs/ulog.hpp"

#include <fmt/format.h>
#include <fmt/ranges.h>

#include <algorithm>
#include <bit>
#include <cstring>
#include <fstream>

#include "pegasus/core/error.hpp"
#include "pegasus/io/atomic_file.hpp"
#include "ulog_bytes.hpp"

namespace pegasus::logs {

static_assert(std::endian::native == std::endian::little,
              "the ULog reader copies little-endian values as they are");

namespace {

using detail::load;

constexpr std::array<std::uint8_t, 7> kMagic = {0x55, 0x4c, 0x6f, 0x67, 0x01, 0x12, 0x35};
constexpr std::array<std::uint8_t, 8> kSyncMagic = {0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12};
constexpr std::size_t kHeaderBytes = 16;
constexpr std::size_t kMessageHeaderBytes = 3;
// Bounds that only a corrupt file reaches: they keep a hostile file from making the reader allocate without
// limit through nested arrays (a data message is at most 65535 bytes, so no logged format is larger).
constexpr std::size_t kMaxFormatBytes = 1 << 16;
constexpr std::size_t kMaxLeaves = 1 << 14;

bool name_char(char c, bool allow_path) {
  return (c >= 'a' && c <= 'z') || (c >= 'A' && c <= 'Z') || (c >= '0' && c <= '9') || c == '_' ||
         (allow_path && (c == '-' || c == '/'));
}

bool valid_name(std::string_view s, bool allow_path) {
  return !s.empty() && std::all_of(s.begin(), s.end(), [&](char c) { return name_char(c, allow_path); });
}

// A printable excerpt of untrusted text for an error message.
std::string excerpt(std::string_view s) {
  std::string out;
  for (char c : s.substr(0, 60)) out += (c >= 32 && c < 127) ? c : '?';
  if (s.size() > 60) out += "...";
  return "'" + out + "'";
}

class Parser {
 public:
  Parser(std::span<const std::uint8_t> bytes, std::string_view name, const UlogReadOptions& options)
      : b_(bytes), name_(name), options_(options) {}

  UlogFile run() {
    read_header();
    count_records();
    std::size_t pos = kHeaderBytes;
    const std::size_t n = b_.size();
    while (pos < n) {
      // A message cut by an appended-data offset is discarded; reading resumes at the offset (the spec's
      // rule for data appended to a log that stopped in the middle of a message).
      const std::size_t boundary = next_boundary(pos);
      const std::size_t limit = std::min(boundary, n);
      if (pos + kMessageHeaderBytes > limit) {
        if (boundary < n) {
          pos = skip_to_boundary(pos, boundary);
          continue;
        }
        truncated(pos,
                  fmt::format("a 3-byte message header, found {} bytes before the end of the file", n - pos));
        break;
      }
      const std::size_t size = load<std::uint16_t>(&b_[pos]);
      const char type = static_cast<char>(b_[pos + 2]);
      const std::size_t end = pos + kMessageHeaderBytes + size;
      if (end > limit) {
        if (boundary < n) {
          pos = skip_to_boundary(pos, boundary);
          continue;
        }
        truncated(pos, fmt::format("a '{}' message of {} bytes, found {} bytes before the end of the file",
                                   printable(type), size, n - pos - kMessageHeaderBytes));
        break;
      }
      message(pos, type, b_.subspan(pos + kMessageHeaderBytes, size));
      pos = end;
    }
    return std::move(f_);
  }

 private:
  [[noreturn]] void fail(std::size_t offset, const std::string& what) const {
    throw InputError(fmt::format("{}: byte {}: {}", name_, offset, what));
  }
  static char printable(char c) { return (c >= 32 && c < 127) ? c : '?'; }

  void read_header() {
    if (b_.size() < kHeaderBytes)
      fail(b_.size(), fmt::format("expected the 16-byte ULog header, found a file of {} bytes", b_.size()));
    for (std::size_t i = 0; i < kMagic.size(); ++i)
      if (b_[i] != kMagic[i]) fail(i, "expected the ULog file magic 55 4c 6f 67 01 12 35 ('ULog')");
    f_.version = b_[7];
    f_.start_us = load<std::uint64_t>(&b_[8]);
  }

  // A first pass over the message headers only: data messages and their bytes per msg_id, so that each
  // topic's buffers are allocated once, at their final size, when it is subscribed. A hint only (a corrupt
  // file is found by the real pass); the reservation is bounded by twice the bytes the messages carry.
  void count_records() {
    for (std::size_t pos = kHeaderBytes; pos + kMessageHeaderBytes <= b_.size();) {
      const std::size_t size = load<std::uint16_t>(&b_[pos]);
      if (pos + kMessageHeaderBytes + size > b_.size()) break;
      if (b_[pos + 2] == 'D' && size >= 2) {
        const std::uint16_t id = load<std::uint16_t>(&b_[pos + kMessageHeaderBytes]);
        if (id >= record_count_.size()) {  // sized by the largest msg_id, not by all 65536
          record_count_.resize(id + 1u, 0);
          record_bytes_.resize(id + 1u, 0);
        }
        ++record_count_[id];
        record_bytes_[id] += size - 2;
      }
      pos += kMessageHeaderBytes + size;
    }
  }

  std::size_t next_boundary(std::size_t pos) const {
    for (std::size_t o : boundaries_)
      if (o > pos) return o;
    return SIZE_MAX;
  }
  std::size_t skip_to_boundary(std::size_t pos, std::size_t boundary) {
    f_.discarded_bytes += boundary - pos;
    return boundary;
  }

  void truncated(std::size_t pos, const std::string& what) {
    if (options_.truncated_tail == UlogReadOptions::TruncatedTail::kError)
      fail(pos, "the file ends inside a message: expected " + what);
    f_.truncated_at = pos;
  }

  void need(std::size_t pos, char type, std::span<const std::uint8_t> p, std::size_t at_least) const {
    if (p.size() < at_least)
      fail(pos,
           fmt::format("expected a '{}' message of at least {} bytes, found {}", type, at_least, p.size()));
  }

  void message(std::size_t pos, char type, std::span<const std::uint8_t> p) {
    switch (type) {
      case 'B':
        return flag_bits(pos, p);
      case 'F':
        return format(pos, p);
      case 'I':
        return info(pos, p);
      case 'M':
        return multi_info(pos, p);
      case 'P':
        return parameter(pos, p);
      case 'Q':
        return default_parameter(pos, p);
      case 'A':
        in_data_ = true;
        return subscribe(pos, p);
      case 'R': {
        need(pos, type, p, 2);
        if (const std::uint16_t id = load<std::uint16_t>(p.data()); id < topic_of_id_.size())
          topic_of_id_[id] = -1;
        return;
      }
      case 'D':
        return data(pos, p);
      case 'L': {
        in_data_ = true;
        need(pos, type, p, 9);
        f_.log_lines.push_back(UlogLogLine{.level = p[0],
                                           .tag = -1,
                                           .timestamp = load<std::uint64_t>(&p[1]),
                                           .text = std::string(p.begin() + 9, p.end())});
        return;
      }
      case 'C': {
        in_data_ = true;
        need(pos, type, p, 11);
        f_.log_lines.push_back(UlogLogLine{.level = p[0],
                                           .tag = load<std::uint16_t>(&p[1]),
                                           .timestamp = load<std::uint64_t>(&p[3]),
                                           .text = std::string(p.begin() + 11, p.end())});
        return;
      }
      case 'S': {
        need(pos, type, p, 8);
        if (!std::equal(kSyncMagic.begin(), kSyncMagic.end(), p.begin()))
          fail(pos, "expected the sync magic 2f 73 13 20 25 0c bb 12 in an 'S' message");
        ++f_.sync_messages;
        return;
      }
      case 'O': {
        need(pos, type, p, 2);
        f_.dropouts.push_back({last_timestamp_, load<std::uint16_t>(p.data()), pos});
        return;
      }
      default:
        ++f_.unknown_messages;  // the spec: unknown messages are skipped
        return;
    }
  }

  void flag_bits(std::size_t pos, std::span<const std::uint8_t> p) {
    if (pos != kHeaderBytes) fail(pos, "expected the flag bits ('B') message only right after the header");
    need(pos, 'B', p, 40);  // longer ones carry future fields, ignored as the spec says
    std::copy_n(p.begin(), 8, f_.compat_flags.begin());
    std::copy_n(p.begin() + 8, 8, f_.incompat_flags.begin());
    for (std::size_t i = 0; i < 3; ++i) f_.appended_offsets[i] = load<std::uint64_t>(&p[16 + 8 * i]);
    for (std::size_t i = 0; i < 8; ++i) {
      const std::uint8_t unknown = i == 0 ? f_.incompat_flags[0] & ~std::uint8_t{1} : f_.incompat_flags[i];
      if (unknown != 0)
        fail(pos + 3 + 8 + i,
             fmt::format("unknown incompatible flag bits {:#04x} in incompat_flags[{}]: this log "
                         "needs a newer reader (only DATA_APPENDED, bit 0 of byte 0, is known)",
                         unknown, i));
    }
    if (f_.incompat_flags[0] & 1) {
      std::uint64_t last = 0;
      for (std::size_t i = 0; i < 3; ++i) {
        const std::uint64_t o = f_.appended_offsets[i];
        if (o == 0) continue;
        if (o <= pos + 3 + p.size() || o <= last)
          fail(pos + 3 + 16 + 8 * i,
               fmt::format("expected appended_offsets[{}] after the flag bits message and after the previous "
                           "offset, found {}",
                           i, o));
        last = o;
        if (o < b_.size()) boundaries_.push_back(static_cast<std::size_t>(o));
      }
    }
  }

  void format(std::size_t pos, std::span<const std::uint8_t> p) {
    const std::string_view text(reinterpret_cast<const char*>(p.data()), p.size());
    const auto colon = text.find(':');
    if (colon == std::string_view::npos)
      fail(pos, fmt::format("expected a format 'name:type field;...', found {}", excerpt(text)));
    UlogFormat fm;
    fm.name = std::string(text.substr(0, colon));
    if (!valid_name(fm.name, true) || ulog_basic_type(fm.name))
      fail(pos, fmt::format("expected a format name of a-z A-Z 0-9 _ - / (not a basic type), found {}",
                            excerpt(fm.name)));
    std::string_view rest = text.substr(colon + 1);
    while (!rest.empty()) {
      const auto semi = rest.find(';');
      const std::string_view field = rest.substr(0, semi);
      rest = semi == std::string_view::npos ? std::string_view() : rest.substr(semi + 1);
      if (field.empty()) continue;
      const auto space = field.find(' ');
      if (space == std::string_view::npos)
        fail(pos, fmt::format("format {}: expected a field 'type name', found {}", fm.name, excerpt(field)));
      std::string_view type = field.substr(0, space);
      UlogField fd;
      fd.name = std::string(field.substr(space + 1));
      if (!valid_name(fd.name, false))
        fail(pos, fmt::format("format {}: expected a field name of a-z A-Z 0-9 _, found {}", fm.name,
                              excerpt(fd.name)));
      if (const auto bracket = type.find('['); bracket != std::string_view::npos) {
        const std::string_view count = type.substr(bracket + 1);
        int n = 0;
        bool ok = count.size() >= 2 && count.back() == ']' && count.size() <= 7;
        for (std::size_t i = 0; ok && i + 1 < count.size(); ++i) {
          ok = count[i] >= '0' && count[i] <= '9';
          n = n * 10 + (count[i] - '0');
        }
        if (!ok || n <= 0)
          fail(pos, fmt::format("format {}: expected an array type 'type[n]' with n > 0, found {}", fm.name,
                                excerpt(type)));
        fd.array_size = n;
        type = type.substr(0, bracket);
      }
      fd.type_name = std::string(type);
      if (const auto basic = ulog_basic_type(type)) {
        fd.type = *basic;
      } else if (valid_name(type, true)) {
        fd.type = UlogType::kNested;
      } else {
        fail(pos, fmt::format("format {}: expected a basic type or a format name, found {}", fm.name,
                              excerpt(type)));
      }
      fm.fields.push_back(std::move(fd));
    }
    if (fm.fields.empty()) fail(pos, fmt::format("format {}: expected at least one field", fm.name));
    if (const auto it = f_.formats.find(fm.name); it != f_.formats.end()) {
      if (format_text_[fm.name] != text)
        fail(pos, fmt::format("format {} defined a second time, differently", fm.name));
      return;
    }
    format_text_[fm.name] = std::string(text);
    f_.formats.emplace(fm.name, std::move(fm));
  }

  // Sizes and leaves of a format and of the formats it nests (which may be defined after it).
  UlogFormat& resolve(std::size_t pos, const std::string& name, int depth) {
    const auto it = f_.formats.find(name);
    if (it == f_.formats.end())
      fail(pos, fmt::format("expected a format message ('F') defining {}", excerpt(name)));
    UlogFormat& fm = it->second;
    if (fm.resolved) return fm;
    if (std::find(resolving_.begin(), resolving_.end(), name) != resolving_.end())
      fail(pos, fmt::format("format {} nests itself (through {})", name, fmt::join(resolving_, " > ")));
    if (depth > 32) fail(pos, fmt::format("format {} is nested over 32 levels deep", name));
    resolving_.push_back(name);
    std::size_t offset = 0;
    std::vector<UlogLeaf> leaves;
    std::size_t trailing = 0;
    for (const UlogField& fd : fm.fields) {
      const std::size_t count = fd.array_size == 0 ? 1 : static_cast<std::size_t>(fd.array_size);
      std::size_t elem = ulog_type_size(fd.type);
      const UlogFormat* nested = nullptr;
      if (fd.type == UlogType::kNested) {
        nested = &resolve(pos, fd.type_name, depth + 1);
        elem = nested->size;
      }
      const std::size_t bytes = elem * count;
      if (bytes > kMaxFormatBytes || offset + bytes > kMaxFormatBytes)
        fail(pos, fmt::format("format {} is over {} bytes", name, kMaxFormatBytes));
      trailing = fd.padding() ? trailing + bytes : 0;
      if (!fd.padding()) {
        if (fd.type == UlogType::kChar && fd.array_size > 0) {
          leaves.push_back({fd.name, UlogType::kChar, offset, count});
        } else {
          for (std::size_t i = 0; i < count; ++i) {
            const std::string path = fd.array_size == 0 ? fd.name : fmt::format("{}[{}]", fd.name, i);
            if (nested) {
              if (leaves.size() + nested->leaves.size() > kMaxLeaves)
                fail(pos, fmt::format("format {} has over {} fields", name, kMaxLeaves));
              for (const UlogLeaf& l : nested->leaves)
                leaves.push_back({path + "." + l.name, l.type, offset + i * elem + l.offset, l.count});
            } else {
              if (leaves.size() >= kMaxLeaves)
                fail(pos, fmt::format("format {} has over {} fields", name, kMaxLeaves));
              leaves.push_back({path, fd.type, offset + i * elem, 1});
            }
          }
        }
      }
      offset += bytes;
    }
    resolving_.pop_back();
    fm.size = offset;
    fm.trailing_padding = trailing;
    fm.leaves = std::move(leaves);
    fm.resolved = true;
    return fm;
  }

  void subscribe(std::size_t pos, std::span<const std::uint8_t> p) {
    need(pos, 'A', p, 4);
    const int multi_id = p[0];
    const std::uint16_t msg_id = load<std::uint16_t>(&p[1]);
    const std::string name(p.begin() + 3, p.end());
    const UlogFormat& fm = resolve(pos, name, 0);
    const auto ts = std::find_if(fm.leaves.begin(), fm.leaves.end(),
                                 [](const UlogLeaf& l) { return l.name == "timestamp"; });
    if (ts == fm.leaves.end() || ts->type != UlogType::kUint64)
      fail(pos, fmt::format("expected a 'uint64_t timestamp' field in format {} (it is subscribed)", name));
    if (msg_id >= topic_of_id_.size()) topic_of_id_.resize(msg_id + 1u, -1);
    if (topic_of_id_[msg_id] >= 0)
      fail(pos, fmt::format("msg_id {} is subscribed a second time without an 'R' message", msg_id));
    int index = -1;
    for (std::size_t i = 0; i < f_.topics.size(); ++i)
      if (f_.topics[i].name == name && f_.topics[i].multi_id == multi_id) index = static_cast<int>(i);
    if (index < 0) {
      const bool keep = options_.topics.empty() || std::find(options_.topics.begin(), options_.topics.end(),
                                                             name) != options_.topics.end();
      UlogTopic t;
      t.name = name;
      t.multi_id = multi_id;
      t.record_size = fm.size;
      t.leaves = fm.leaves;
      if (keep) {
        if (msg_id < record_count_.size()) {
          const std::size_t rows = record_count_[msg_id];
          t.timestamps.reserve(rows);
          t.offsets.reserve(rows);
          t.data.reserve(std::min(rows * fm.size, 2 * record_bytes_[msg_id]));
        }
      }
      f_.topics.push_back(std::move(t));
      index = static_cast<int>(f_.topics.size() - 1);
      state_.push_back({ts->offset, fm.size - fm.trailing_padding, keep});
    }
    topic_of_id_[msg_id] = index;
  }

  void data(std::size_t pos, std::span<const std::uint8_t> p) {
    need(pos, 'D', p, 2);
    const std::uint16_t msg_id = load<std::uint16_t>(p.data());
    const int index = msg_id < topic_of_id_.size() ? topic_of_id_[msg_id] : -1;
    if (index < 0)
      fail(pos, fmt::format("expected a subscription ('A') of msg_id {} before its data", msg_id));
    UlogTopic& t = f_.topics[static_cast<std::size_t>(index)];
    const TopicState& st = state_[static_cast<std::size_t>(index)];
    const std::size_t len = p.size() - 2;
    if (len < st.min_bytes || len > t.record_size)
      fail(pos, fmt::format("expected {} data bytes for {} (its format{}), found {}", t.record_size, t.name,
                            st.min_bytes < t.record_size
                                ? fmt::format(", or {} without the trailing padding", st.min_bytes)
                                : "",
                            len));
    const std::uint8_t* record = p.data() + 2;
    const auto timestamp = load<std::uint64_t>(record + st.timestamp_offset);
    last_timestamp_ = std::max(last_timestamp_, timestamp);
    ++f_.data_messages;
    if (!st.keep) return;
    t.timestamps.push_back(timestamp);
    t.offsets.push_back(pos);
    t.data.insert(t.data.end(), record, record + len);
    if (len < t.record_size) t.data.resize(t.data.size() + (t.record_size - len), 0);
  }

  // "type name" + value, the body of 'I', 'M', 'P' and 'Q' after their leading bytes.
  std::pair<std::string, UlogValue> key_value(std::size_t pos, char type, std::span<const std::uint8_t> p) {
    const std::size_t key_len = p[0];
    if (1 + key_len > p.size())
      fail(pos, fmt::format("expected a '{}' message holding its {}-byte key, found {} bytes", type, key_len,
                            p.size() - 1));
    const std::string_view key(reinterpret_cast<const char*>(p.data()) + 1, key_len);
    const auto space = key.find(' ');
    if (space == std::string_view::npos || space == 0 || space + 1 == key.size())
      fail(pos, fmt::format("expected a '{}' key 'type name', found {}", type, excerpt(key)));
    UlogValue v;
    v.type = std::string(key.substr(0, space));
    v.raw = std::string(reinterpret_cast<const char*>(p.data()) + 1 + key_len, p.size() - 1 - key_len);
    return {std::string(key.substr(space + 1)), std::move(v)};
  }

  void info(std::size_t pos, std::span<const std::uint8_t> p) {
    need(pos, 'I', p, 1);
    auto [key, value] = key_value(pos, 'I', p);
    f_.info[key] = std::move(value);
  }
  void multi_info(std::size_t pos, std::span<const std::uint8_t> p) {
    need(pos, 'M', p, 2);
    const bool continued = p[0] != 0;
    auto [key, value] = key_value(pos, 'M', p.subspan(1));
    auto& list = f_.multi_info[key];
    if (!continued || list.empty()) list.emplace_back();
    list.back().push_back(std::move(value));
  }
  void parameter(std::size_t pos, std::span<const std::uint8_t> p) {
    need(pos, 'P', p, 1);
    auto [key, value] = key_value(pos, 'P', p);
    const auto number = value.as_number();
    if ((value.type != "int32_t" && value.type != "float") || !number)
      fail(pos,
           fmt::format("expected a parameter of type int32_t or float with a 4-byte value, found {} {} of "
                       "{} bytes",
                       excerpt(value.type), excerpt(key), value.raw.size()));
    if (in_data_)
      f_.parameter_changes.push_back({last_timestamp_, key, *number});
    else
      f_.parameters[key] = std::move(value);
  }
  void default_parameter(std::size_t pos, std::span<const std::uint8_t> p) {
    need(pos, 'Q', p, 2);
    auto [key, value] = key_value(pos, 'Q', p.subspan(1));
    f_.default_parameters[key] = std::move(value);
  }

  struct TopicState {
    std::size_t timestamp_offset = 0;
    std::size_t min_bytes = 0;  // the record without its trailing padding
    bool keep = true;
  };

  std::span<const std::uint8_t> b_;
  std::string_view name_;
  const UlogReadOptions& options_;
  UlogFile f_;
  std::vector<int> topic_of_id_;             // msg_id -> index in f_.topics, -1 when not subscribed
  std::vector<std::uint32_t> record_count_;  // msg_id -> data messages (count_records)
  std::vector<std::size_t> record_bytes_;    // msg_id -> their payload bytes
  std::vector<TopicState> state_;
  std::map<std::string, std::string> format_text_;
  std::vector<std::string> resolving_;   // formats being resolved, outermost first (finds cycles)
  std::vector<std::size_t> boundaries_;  // appended-data offsets inside the file, ascending
  std::uint64_t last_timestamp_ = 0;
  bool in_data_ = false;
};

}  // namespace

UlogFile parse_ulog(std::span<const std::uint8_t> bytes, std::string_view name,
                    const UlogReadOptions& options) {
  return Parser(bytes, name, options).run();
}

UlogFile read_ulog(const std::filesystem::path& file, const UlogReadOptions& options) {
  std::string bytes;
  try {
    bytes = read_file(file);
  } catch (const std::exception& e) {
    const std::string reason = read_failure_reason(e);
    throw InputError(fmt::format("{}: cannot read the ULog file ({})", file.string(), reason));
  }
  return parse_ulog(
      std::span<const std::uint8_t>(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size()),
      file.string(), options);
}

}  // namespace pegasus::logs

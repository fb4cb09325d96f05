#pragma once
// A reader for PX4's ULog flight logs, written from the format PX4 documents
// (docs/en/dev_log/ulog_file_format.md): hand-written because no Debian package reads ULog.
//
// Layout: a 16-byte header (magic "ULog" 01 12 35, version byte, uint64 start time in us), then messages,
// each a 3-byte header (uint16 size without the header, uint8 type) and its payload, all little-endian:
//   definitions  'B' flag bits (compat/incompat flags, appended-data offsets), 'F' formats ("name:type field;
//                ..." with arrays "type[n]" and nested formats), 'I' info, 'M' multi-info, 'P' parameters,
//                'Q' default parameters;
//   data         'A' subscriptions (msg_id, multi_id = the instance of a multi-instance topic), 'R', 'D' data
//                of a subscription, 'L' / 'C' (tagged) log strings, 'S' sync, 'O' dropouts, and I/M/P/Q
//                again.
// Unknown message types are skipped (the spec requires it); unknown incompatible flag bits are refused.
//
// Errors: a corrupt file throws InputError "FILE: byte OFFSET: what was expected, found what". A file cut off
// in the middle of its last message (a logger that lost power) is read up to the last whole message, as the
// spec requires, and `truncated_at` says where; UlogReadOptions::truncated_tail = kError refuses it instead.
// Data of every subscription are stored as whole records in one contiguous buffer per topic instance: no
// allocation per data message beyond the buffer's growth.
#include <array>
#include <cstddef>
#include <cstdint>
#include <filesystem>
#include <map>
#include <optional>
#include <span>
#include <string>
#include <string_view>
#include <vector>

namespace pegasus::logs {

// The basic types of a format field; kNested is another format.
enum class UlogType : std::uint8_t {
  kInt8,
  kUint8,
  kInt16,
  kUint16,
  kInt32,
  kUint32,
  kInt64,
  kUint64,
  kFloat,
  kDouble,
  kBool,
  kChar,
  kNested
};
// The size in bytes of a basic type (0 for kNested); the type of a name ("float"), nullopt if not basic.
std::size_t ulog_type_size(UlogType type);
std::optional<UlogType> ulog_basic_type(std::string_view name);

// A field as the format message declares it.
struct UlogField {
  std::string name;
  std::string type_name;  // "float", or the nested format's name
  UlogType type = UlogType::kUint8;
  int array_size = 0;  // 0: a scalar; n: type[n]
  bool padding() const { return name.starts_with("_padding"); }
};

// A scalar leaf of a resolved format, named by its path ("q[0]", "gyro_rad[2]", "esc[1].rpm"); char arrays
// stay one leaf (a string) of `count` bytes. Offsets are from the start of the record.
struct UlogLeaf {
  std::string name;
  UlogType type = UlogType::kUint8;
  std::size_t offset = 0;
  std::size_t count = 1;
};

struct UlogFormat {
  std::string name;
  std::vector<UlogField> fields;
  // Filled when the format is first resolved (a subscription or a nested use): its size in bytes, its
  // leaves, and the bytes of padding at its end that a writer may leave out of a data message.
  std::size_t size = 0;
  std::size_t trailing_padding = 0;
  std::vector<UlogLeaf> leaves;
  bool resolved = false;
};

// The records of one subscribed topic instance (name, multi_id).
class UlogTopic {
 public:
  std::string name;
  int multi_id = 0;
  std::size_t record_size = 0;
  std::vector<UlogLeaf> leaves;
  std::vector<std::uint64_t> timestamps;  // us, of each record
  std::vector<std::size_t> offsets;       // byte offset of each record's 'D' message (for errors)
  std::vector<std::uint8_t> data;         // records back to back, record_size bytes each

  std::size_t rows() const { return timestamps.size(); }
  // The leaf of a field path; nullptr when the format has none.
  const UlogLeaf* find(std::string_view field) const;
  // One numeric field of every record as doubles; InputError naming the topic and field when missing or a
  // string (`file` names the log in the message).
  std::vector<double> column(std::string_view field, std::string_view file = "ulog") const;
  // The field of record `row` as a double (numeric leaves only).
  double value(const UlogLeaf& leaf, std::size_t row) const;
};

struct UlogLogLine {
  int level = 0;  // the raw byte: '0' (emergency) .. '7' (debug) as the Linux kernel's, in PX4's logs
  int tag = -1;   // 'C' messages only
  std::uint64_t timestamp = 0;
  std::string text;
};

struct UlogDropout {
  std::uint64_t after_timestamp = 0;  // us: the last data timestamp read before the mark
  int duration_ms = 0;
  std::size_t offset = 0;  // byte offset of the 'O' message
};

// A typed key-value of an 'I', 'M', 'P' or 'Q' message: the key's type ("char[8]", "int32_t", "float") and
// the raw little-endian value.
struct UlogValue {
  std::string type;
  std::string raw;
  std::string as_string() const { return raw; }
  // int32_t, uint32_t, float, double, ... decoded; nullopt for strings and arrays.
  std::optional<double> as_number() const;
};

struct UlogParameterChange {
  std::uint64_t after_timestamp = 0;
  std::string name;
  double value = 0;
};

struct UlogFile {
  int version = 0;
  std::uint64_t start_us = 0;  // header timestamp
  std::array<std::uint8_t, 8> compat_flags{}, incompat_flags{};
  std::array<std::uint64_t, 3> appended_offsets{};
  std::map<std::string, UlogFormat> formats;
  std::map<std::string, UlogValue> info;
  std::map<std::string, std::vector<std::vector<UlogValue>>>
      multi_info;                               // key -> messages (continued joined)
  std::map<std::string, UlogValue> parameters;  // values at the start of the log
  std::map<std::string, UlogValue> default_parameters;
  std::vector<UlogParameterChange> parameter_changes;  // 'P' in the data section
  std::vector<UlogTopic> topics;                       // in order of first subscription
  std::vector<UlogLogLine> log_lines;
  std::vector<UlogDropout> dropouts;
  std::size_t sync_messages = 0;
  std::size_t data_messages = 0;            // 'D' read (stored or not)
  std::size_t unknown_messages = 0;         // skipped message types
  std::size_t discarded_bytes = 0;          // cut messages before an appended-data offset
  std::optional<std::size_t> truncated_at;  // offset of a last message cut off by the end of the file

  // The topic instance, or nullptr.
  const UlogTopic* topic(std::string_view name, int multi_id = 0) const;
  // Instances logged of a topic name, ascending.
  std::vector<int> instances(std::string_view name) const;
};

struct UlogReadOptions {
  enum class TruncatedTail { kDiscard, kError };
  // A last message cut off by the end of the file: discarded (the spec's rule) or an InputError.
  TruncatedTail truncated_tail = TruncatedTail::kDiscard;
  // Store the data of these topic names only (all when empty); others are checked and counted, not kept.
  std::vector<std::string> topics;
};

// Parses a whole ULog image; `name` stands for the file in messages.
UlogFile parse_ulog(std::span<const std::uint8_t> bytes, std::string_view name,
                    const UlogReadOptions& options = {});
// Reads and parses a file; InputError naming the file when it cannot be read.
UlogFile read_ulog(const std::filesystem::path& file, const UlogReadOptions& options = {});

}  // namespace pegasus::logs

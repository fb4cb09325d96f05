// The ULog reader on hand-built byte streams: every message type, nested formats defined after their use,
// multi-instance topics, omitted trailing padding, appended data, dropouts, corrupt input naming the byte
// offset, and truncation at every byte of a small file.
#include "pegasus/logs/ulog.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdint>
#include <cstring>
#include <string>
#include <vector>

#include "pegasus/core/error.hpp"
#include "support/input_error.hpp"
#include "ulog_builder.hpp"

namespace {

using namespace pegasus;
using namespace pegasus::logs;
using test_support::Bytes;
using test_support::input_error_message;
using test_support::UlogBuilder;

// sensor: 44 bytes (timestamp 8, n 2 x 10, name 4, d 8, ok 1, trailing padding 3).
Bytes sensor_record(std::uint64_t t, float a0, std::int16_t b01, double d, bool full = true) {
  Bytes r;
  r.put(t);
  r.put(a0).put(std::int16_t{-3}).put(b01).zeros(2);               // n[0]: a, b[0], b[1], nested padding
  r.put(2.5f).put(std::int16_t{7}).put(std::int16_t{8}).zeros(2);  // n[1]
  r.text("abcd").put(d).put(std::uint8_t{1});
  if (full) r.zeros(3);
  return r;
}

Bytes all_types_record(std::uint64_t t) {
  Bytes r;
  r.put(t).put(std::int8_t{-5}).put(std::uint8_t{250}).put(std::int16_t{-300}).put(std::uint16_t{60000});
  r.put(std::int32_t{-70000}).put(std::uint32_t{4000000000u}).put(std::int64_t{-5000000000});
  r.put(0.25f).put(-1e300).put(std::uint8_t{1}).text("x");
  return r;
}

UlogBuilder full_log() {
  UlogBuilder b;
  b.flag_bits(1, 0);
  b.format("sensor:uint64_t timestamp;nested_t[2] n;char[4] name;double d;bool ok;uint8_t[3] _padding0;");
  b.format("nested_t:float a;int16_t[2] b;uint8_t[2] _padding0;");
  b.format(
      "all_types:uint64_t timestamp;int8_t i8;uint8_t u8;int16_t i16;uint16_t u16;int32_t i32;uint32_t u32;"
      "int64_t i64;float f;double d;bool b;char c;");
  b.info("char[3] sys_name", {'P', 'X', '4'});
  b.info("uint32_t ver_sw_release", Bytes().put(std::uint32_t{0x010402FF}).bytes());
  b.multi_info(false, "char[5] perf", "hello");
  b.multi_info(true, "char[6] perf", " world");
  b.multi_info(false, "char[3] perf", "two");
  b.parameter("int32_t MC_ROLL", std::int32_t{3});
  b.parameter("float MC_GAIN", 1.5f);
  b.default_parameter(std::uint8_t{1}, "float MC_GAIN", 2.0f);
  b.subscribe(0, 0, "sensor");
  b.subscribe(1, 1, "sensor");
  b.subscribe(0, 2, "all_types");
  b.data(0, sensor_record(100, 1.25f, 11, 0.5));
  b.data(1, sensor_record(150, -1.0f, 12, 1.5, /*full=*/false));  // the trailing padding left out
  b.sync();
  b.log('6', 160, "armed");
  b.tagged_log('4', 7, 170, "low battery");
  b.dropout(25);
  b.data(0, sensor_record(200, 2.5f, 13, -0.5));
  b.parameter("float MC_GAIN", 2.5f);
  b.data(2, all_types_record(210));
  b.message('Z', {1, 2, 3});  // an unknown type: skipped
  b.unsubscribe(1);
  return b;
}

UlogFile parse(const UlogBuilder& b, const UlogReadOptions& o = {}) {
  return parse_ulog(b.bytes(), "t.ulg", o);
}

TEST(UlogReader, DecodesEveryMessageType) {
  const UlogFile f = parse(full_log());
  EXPECT_EQ(f.version, 1);
  EXPECT_EQ(f.start_us, 1000u);
  EXPECT_EQ(f.compat_flags[0], 1);
  EXPECT_EQ(f.info.at("sys_name").as_string(), "PX4");
  EXPECT_EQ(f.info.at("sys_name").type, "char[3]");
  EXPECT_EQ(*f.info.at("ver_sw_release").as_number(), 0x010402FF);
  ASSERT_EQ(f.multi_info.at("perf").size(), 2u);
  ASSERT_EQ(f.multi_info.at("perf")[0].size(), 2u);  // "hello" continued by " world"
  EXPECT_EQ(f.multi_info.at("perf")[0][0].raw + f.multi_info.at("perf")[0][1].raw, "hello world");
  EXPECT_EQ(f.multi_info.at("perf")[1][0].raw, "two");
  EXPECT_EQ(*f.parameters.at("MC_ROLL").as_number(), 3);
  EXPECT_EQ(*f.parameters.at("MC_GAIN").as_number(), 1.5);
  EXPECT_EQ(*f.default_parameters.at("MC_GAIN").as_number(), 2.0);
  ASSERT_EQ(f.parameter_changes.size(), 1u);
  EXPECT_EQ(f.parameter_changes[0].name, "MC_GAIN");
  EXPECT_EQ(f.parameter_changes[0].value, 2.5);
  EXPECT_EQ(f.parameter_changes[0].after_timestamp, 200u);
  ASSERT_EQ(f.log_lines.size(), 2u);
  EXPECT_EQ(f.log_lines[0].level, '6');
  EXPECT_EQ(f.log_lines[0].tag, -1);
  EXPECT_EQ(f.log_lines[0].timestamp, 160u);
  EXPECT_EQ(f.log_lines[0].text, "armed");
  EXPECT_EQ(f.log_lines[1].tag, 7);
  EXPECT_EQ(f.log_lines[1].text, "low battery");
  EXPECT_EQ(f.sync_messages, 1u);
  ASSERT_EQ(f.dropouts.size(), 1u);
  EXPECT_EQ(f.dropouts[0].duration_ms, 25);
  EXPECT_EQ(f.dropouts[0].after_timestamp, 150u);
  EXPECT_EQ(f.unknown_messages, 1u);
  EXPECT_EQ(f.data_messages, 4u);
  EXPECT_FALSE(f.truncated_at.has_value());

  const UlogTopic* all = f.topic("all_types");
  ASSERT_NE(all, nullptr);
  ASSERT_EQ(all->rows(), 1u);
  const std::vector<std::pair<const char*, double>> expected = {{"i8", -5},
                                                                {"u8", 250},
                                                                {"i16", -300},
                                                                {"u16", 60000},
                                                                {"i32", -70000},
                                                                {"u32", 4000000000},
                                                                {"i64", -5000000000.0},
                                                                {"f", 0.25},
                                                                {"d", -1e300},
                                                                {"b", 1},
                                                                {"c", 'x'}};
  for (const auto& [name, value] : expected) EXPECT_EQ(all->column(name)[0], value) << name;
}

TEST(UlogReader, ResolvesNestedFormatsDefinedAfterTheirUse) {
  const UlogFile f = parse(full_log());
  const UlogTopic* s = f.topic("sensor", 0);
  ASSERT_NE(s, nullptr);
  EXPECT_EQ(s->record_size, 44u);
  std::vector<std::string> names;
  std::vector<std::size_t> offsets;
  for (const auto& l : s->leaves) {
    names.push_back(l.name);
    offsets.push_back(l.offset);
  }
  EXPECT_EQ(names, (std::vector<std::string>{"timestamp", "n[0].a", "n[0].b[0]", "n[0].b[1]", "n[1].a",
                                             "n[1].b[0]", "n[1].b[1]", "name", "d", "ok"}));
  EXPECT_EQ(offsets, (std::vector<std::size_t>{0, 8, 12, 14, 18, 22, 24, 28, 32, 40}));
  EXPECT_EQ(s->find("name")->count, 4u);
  EXPECT_EQ(s->timestamps, (std::vector<std::uint64_t>{100, 200}));
  EXPECT_EQ(s->column("n[0].a"), (std::vector<double>{1.25, 2.5}));
  EXPECT_EQ(s->column("n[0].b[0]"), (std::vector<double>{-3, -3}));
  EXPECT_EQ(s->column("n[0].b[1]"), (std::vector<double>{11, 13}));
  EXPECT_EQ(s->column("n[1].b[1]"), (std::vector<double>{8, 8}));
  EXPECT_EQ(s->column("d"), (std::vector<double>{0.5, -0.5}));
  EXPECT_NE(input_error_message([&] { s->column("name"); }).find("is a string"), std::string::npos);
  EXPECT_NE(input_error_message([&] { s->column("nope", "t.ulg"); }).find("t.ulg: topic sensor"),
            std::string::npos);
}

TEST(UlogReader, KeepsMultiInstanceTopicsApartAndFillsOmittedTrailingPadding) {
  const UlogFile f = parse(full_log());
  EXPECT_EQ(f.instances("sensor"), (std::vector<int>{0, 1}));
  const UlogTopic* s1 = f.topic("sensor", 1);
  ASSERT_NE(s1, nullptr);
  EXPECT_EQ(s1->timestamps, (std::vector<std::uint64_t>{150}));
  EXPECT_EQ(s1->column("n[0].b[1]"), (std::vector<double>{12}));
  EXPECT_EQ(s1->data.size(), 44u);  // the record is stored whole, its padding zero
  EXPECT_EQ(f.topic("sensor", 2), nullptr);
}

TEST(UlogReader, StoresOnlyTheTopicsAskedFor) {
  const UlogFile f = parse(full_log(), {.topics = {"all_types"}});
  EXPECT_EQ(f.topic("all_types")->rows(), 1u);
  EXPECT_EQ(f.topic("sensor")->rows(), 0u);
  EXPECT_EQ(f.data_messages, 4u);  // still read and checked
}

TEST(UlogReader, ResumesAtAppendedDataAfterACutMessage) {
  UlogBuilder b;
  const std::size_t flag_offset = b.size();
  b.flag_bits(0, 1, 0);  // offset patched below
  b.format("pos:uint64_t timestamp;float x;");
  b.subscribe(0, 0, "pos");
  b.data(0, Bytes().put(std::uint64_t{1}).put(1.0f));
  UlogBuilder cut;
  cut.data(0, Bytes().put(std::uint64_t{2}).put(2.0f));
  // The logger stopped 5 bytes into a data message; the crash dump was appended after it.
  b.raw(std::vector<std::uint8_t>(cut.bytes().begin() + 16, cut.bytes().begin() + 21));
  const std::uint64_t appended = b.size();
  b.data(0, Bytes().put(std::uint64_t{3}).put(3.0f));
  b.data(0, Bytes().put(std::uint64_t{4}).put(4.0f));
  std::vector<std::uint8_t> bytes = b.bytes();
  std::memcpy(&bytes[flag_offset + 3 + 16], &appended, 8);
  const UlogFile f = parse_ulog(bytes, "t.ulg");
  EXPECT_EQ(f.appended_offsets[0], appended);
  EXPECT_EQ(f.topic("pos")->timestamps, (std::vector<std::uint64_t>{1, 3, 4}));
  EXPECT_EQ(f.topic("pos")->column("x"), (std::vector<double>{1, 3, 4}));
  EXPECT_EQ(f.discarded_bytes, 5u);
}

TEST(UlogReader, RefusesUnknownIncompatibleFlags) {
  UlogBuilder b;
  b.flag_bits(0, 0, 0, /*incompat_byte7=*/4);
  const std::string m = input_error_message([&] { parse(b); });
  EXPECT_NE(m.find("t.ulg: byte 34: unknown incompatible flag bits 0x04 in incompat_flags[7]"),
            std::string::npos)
      << m;
}

// Each corrupt input's message names the file, the byte offset of the bad message and what was expected.
TEST(UlogReader, CorruptInputNamesTheByteOffset) {
  struct Case {
    std::string name;
    std::vector<std::uint8_t> bytes;
    std::string expected;
  };
  std::vector<Case> cases;
  {
    auto bytes = full_log().bytes();
    bytes[3] = 'X';
    cases.push_back({"magic", bytes, "byte 3: expected the ULog file magic"});
  }
  {
    const auto bytes = full_log().bytes();
    cases.push_back({"short header", std::vector<std::uint8_t>(bytes.begin(), bytes.begin() + 10),
                     "byte 10: expected the 16-byte ULog header"});
  }
  {
    UlogBuilder b;
    b.format("pos:uint64_t timestamp;float x;").subscribe(0, 0, "pos");
    const auto at = b.size();
    b.data(5, Bytes().put(std::uint64_t{1}).put(1.0f));
    cases.push_back({"unknown msg_id", b.bytes(),
                     "byte " + std::to_string(at) + ": expected a subscription ('A') of msg_id 5"});
  }
  {
    UlogBuilder b;
    b.format("pos:uint64_t timestamp;float x;").subscribe(0, 0, "pos");
    const auto at = b.size();
    b.data(0, Bytes().put(std::uint64_t{1}).put(std::uint16_t{1}));
    cases.push_back(
        {"short data", b.bytes(), "byte " + std::to_string(at) + ": expected 12 data bytes for pos"});
  }
  {
    UlogBuilder b;
    const auto at = b.size();
    b.subscribe(0, 0, "nothing");
    cases.push_back({"undefined format", b.bytes(),
                     "byte " + std::to_string(at) + ": expected a format message ('F') defining 'nothing'"});
  }
  {
    UlogBuilder b;
    b.format("a:uint64_t timestamp;b x;").format("b:a y;");
    const auto at = b.size();
    b.subscribe(0, 0, "a");
    cases.push_back({"circular", b.bytes(), "byte " + std::to_string(at) + ": format a nests itself"});
  }
  {
    UlogBuilder b;
    b.format("a:float x;");
    const auto at = b.size();
    b.subscribe(0, 0, "a");
    cases.push_back({"no timestamp", b.bytes(),
                     "byte " + std::to_string(at) + ": expected a 'uint64_t timestamp' field"});
  }
  {
    UlogBuilder b;
    const auto at = b.size();
    b.format("a uint64_t timestamp;");
    cases.push_back(
        {"no colon", b.bytes(), "byte " + std::to_string(at) + ": expected a format 'name:type field;...'"});
  }
  {
    UlogBuilder b;
    const auto at = b.size();
    b.format("a:uint64_t timestamp;float[0] x;");
    cases.push_back(
        {"empty array", b.bytes(),
         "byte " + std::to_string(at) + ": format a: expected an array type 'type[n]' with n > 0"});
  }
  {
    UlogBuilder b;
    b.format("a:uint64_t timestamp;");
    const auto at = b.size();
    b.message('S', {1, 2, 3, 4, 5, 6, 7, 8});
    cases.push_back({"sync", b.bytes(), "byte " + std::to_string(at) + ": expected the sync magic"});
  }
  {
    UlogBuilder b;
    b.format("a:uint64_t timestamp;");
    const auto at = b.size();
    b.flag_bits(0, 0);
    cases.push_back({"late flag bits", b.bytes(),
                     "byte " + std::to_string(at) +
                         ": expected the flag bits ('B') message only right after the header"});
  }
  {
    UlogBuilder b;
    const auto at = b.size();
    b.parameter("double X", 1.0);
    cases.push_back({"parameter type", b.bytes(),
                     "byte " + std::to_string(at) + ": expected a parameter of type int32_t or float"});
  }
  {
    UlogBuilder b;
    const auto at = b.size();
    b.message('A', {0, 0});
    cases.push_back({"short subscription", b.bytes(),
                     "byte " + std::to_string(at) + ": expected a 'A' message of at least 4 bytes, found 2"});
  }
  {
    UlogBuilder b;
    const auto at = b.size();
    b.message('I', {9, 'a'});
    cases.push_back({"info key", b.bytes(),
                     "byte " + std::to_string(at) + ": expected a 'I' message holding its 9-byte key"});
  }
  for (const auto& c : cases) {
    const std::string m = input_error_message([&] { parse_ulog(c.bytes, "t.ulg"); });
    EXPECT_EQ(m.rfind("t.ulg: byte ", 0), 0u) << c.name << ": " << m;
    EXPECT_NE(m.find(c.expected), std::string::npos) << c.name << ": " << m;
  }
}

// The byte offsets where full_log()'s messages start, and its end.
std::vector<std::size_t> message_starts(const std::vector<std::uint8_t>& bytes) {
  std::vector<std::size_t> starts;
  std::size_t pos = 16;
  while (pos < bytes.size()) {
    starts.push_back(pos);
    pos += 3 + (bytes[pos] | (bytes[pos + 1] << 8));
  }
  starts.push_back(pos);
  return starts;
}

// Cut at every byte: before the header's end an error at the cut; after it the records read are a prefix of
// the whole file's, and the cut message is discarded (the spec's rule) or refused (kError) at its offset.
TEST(UlogReader, TruncationAtEveryByteKeepsWholeMessagesOrNamesTheCut) {
  const auto full_bytes = full_log().bytes();
  const UlogFile full = parse_ulog(full_bytes, "t.ulg");
  const auto starts = message_starts(full_bytes);
  ASSERT_EQ(starts.back(), full_bytes.size());
  for (std::size_t n = 0; n < full_bytes.size(); ++n) {
    const std::vector<std::uint8_t> cut(full_bytes.begin(),
                                        full_bytes.begin() + static_cast<std::ptrdiff_t>(n));
    if (n < 16) {
      EXPECT_EQ(input_error_message([&] { parse_ulog(cut, "t.ulg"); }),
                "t.ulg: byte " + std::to_string(n) + ": expected the 16-byte ULog header, found a file of " +
                    std::to_string(n) + " bytes");
      continue;
    }
    const std::size_t last = *(std::upper_bound(starts.begin(), starts.end(), n) - 1);
    const bool at_boundary = last == n;
    const UlogFile f = parse_ulog(cut, "t.ulg");
    EXPECT_EQ(f.truncated_at.has_value(), !at_boundary) << n;
    if (!at_boundary) {
      EXPECT_EQ(*f.truncated_at, last) << n;
    }
    for (const UlogTopic& t : f.topics) {
      const UlogTopic* whole = full.topic(t.name, t.multi_id);
      ASSERT_NE(whole, nullptr);
      ASSERT_LE(t.rows(), whole->rows());
      EXPECT_TRUE(std::equal(t.timestamps.begin(), t.timestamps.end(), whole->timestamps.begin())) << n;
      EXPECT_TRUE(std::equal(t.data.begin(), t.data.end(), whole->data.begin())) << n;
    }
    const std::string strict = input_error_message([&] {
      parse_ulog(cut, "t.ulg", {.truncated_tail = UlogReadOptions::TruncatedTail::kError, .topics = {}});
    });
    if (at_boundary) {
      EXPECT_EQ(strict, "(no error)") << n;
    } else
      EXPECT_EQ(strict.rfind(
                    "t.ulg: byte " + std::to_string(last) + ": the file ends inside a message: expected", 0),
                0u)
          << n << ": " << strict;
  }
}

}  // namespace

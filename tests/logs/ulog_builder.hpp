#pragma once
// Hand-built ULog byte streams for the reader's tests, written byte by byte from PX4's format document (so a
// mistake in the reader is not repeated here by sharing code with it).
#include <cstdint>
#include <cstring>
#include <string>
#include <string_view>
#include <vector>

namespace pegasus::test_support {

// Little-endian bytes of one record or payload.
class Bytes {
 public:
  // resize and memcpy rather than insert: GCC 12 at -O3 warns falsely (nonnull) inside vector::insert.
  template <class T>
  Bytes& put(T value) {
    return raw(&value, sizeof(T));
  }
  Bytes& text(std::string_view s) { return raw(s.data(), s.size()); }
  Bytes& raw(const void* data, std::size_t n) {
    if (n == 0) return *this;
    const std::size_t at = bytes_.size();
    bytes_.resize(at + n);
    std::memcpy(bytes_.data() + at, data, n);
    return *this;
  }
  Bytes& append(const std::vector<std::uint8_t>& more) { return raw(more.data(), more.size()); }
  Bytes& zeros(std::size_t n) {
    bytes_.resize(bytes_.size() + n, 0);
    return *this;
  }
  const std::vector<std::uint8_t>& bytes() const { return bytes_; }

 private:
  std::vector<std::uint8_t> bytes_;
};

class UlogBuilder {
 public:
  explicit UlogBuilder(std::uint8_t version = 1, std::uint64_t start_us = 1000) {
    append({0x55, 0x4c, 0x6f, 0x67, 0x01, 0x12, 0x35, version});
    append(Bytes().put(start_us).bytes());
  }
  UlogBuilder& message(char type, const std::vector<std::uint8_t>& payload) {
    append(
        Bytes().put(static_cast<std::uint16_t>(payload.size())).put(static_cast<std::uint8_t>(type)).bytes());
    append(payload);
    return *this;
  }
  UlogBuilder& flag_bits(std::uint8_t compat0, std::uint8_t incompat0, std::uint64_t offset0 = 0,
                         std::uint8_t incompat_byte7 = 0) {
    Bytes p;
    p.put(compat0)
        .zeros(7)
        .put(incompat0)
        .zeros(6)
        .put(incompat_byte7)
        .put(offset0)
        .put(std::uint64_t{0})
        .put(std::uint64_t{0});
    return message('B', p.bytes());
  }
  UlogBuilder& format(std::string_view text) { return message('F', Bytes().text(text).bytes()); }
  UlogBuilder& info(std::string_view key, const std::vector<std::uint8_t>& value) {
    return message('I', Bytes().put(static_cast<std::uint8_t>(key.size())).text(key).append(value).bytes());
  }
  UlogBuilder& multi_info(bool continued, std::string_view key, std::string_view value) {
    Bytes p;
    p.put(static_cast<std::uint8_t>(continued))
        .put(static_cast<std::uint8_t>(key.size()))
        .text(key)
        .text(value);
    return message('M', p.bytes());
  }
  template <class T>
  UlogBuilder& parameter(std::string_view key, T value) {
    Bytes p;
    p.put(static_cast<std::uint8_t>(key.size())).text(key).put(value);
    return message('P', p.bytes());
  }
  template <class T>
  UlogBuilder& default_parameter(std::uint8_t types, std::string_view key, T value) {
    Bytes p;
    p.put(types).put(static_cast<std::uint8_t>(key.size())).text(key).put(value);
    return message('Q', p.bytes());
  }
  UlogBuilder& subscribe(std::uint8_t multi_id, std::uint16_t msg_id, std::string_view name) {
    return message('A', Bytes().put(multi_id).put(msg_id).text(name).bytes());
  }
  UlogBuilder& unsubscribe(std::uint16_t msg_id) { return message('R', Bytes().put(msg_id).bytes()); }
  UlogBuilder& data(std::uint16_t msg_id, const Bytes& record) {
    return message('D', Bytes().put(msg_id).append(record.bytes()).bytes());
  }
  UlogBuilder& log(std::uint8_t level, std::uint64_t timestamp, std::string_view text) {
    return message('L', Bytes().put(level).put(timestamp).text(text).bytes());
  }
  UlogBuilder& tagged_log(std::uint8_t level, std::uint16_t tag, std::uint64_t timestamp,
                          std::string_view text) {
    return message('C', Bytes().put(level).put(tag).put(timestamp).text(text).bytes());
  }
  UlogBuilder& sync() { return message('S', {0x2F, 0x73, 0x13, 0x20, 0x25, 0x0C, 0xBB, 0x12}); }
  UlogBuilder& dropout(std::uint16_t ms) { return message('O', Bytes().put(ms).bytes()); }
  UlogBuilder& raw(const std::vector<std::uint8_t>& bytes) {
    append(bytes);
    return *this;
  }

  std::size_t size() const { return b_.size(); }
  const std::vector<std::uint8_t>& bytes() const { return b_; }

 private:
  void append(const std::vector<std::uint8_t>& bytes) {
    if (bytes.empty()) return;
    const std::size_t at = b_.size();
    b_.resize(at + bytes.size());
    std::memcpy(b_.data() + at, bytes.data(), bytes.size());
  }
  std::vector<std::uint8_t> b_;
};

}  // namespace pegasus::test_support

#pragma once
// skelgraph's conventions on top of MCAP: the schema of every skelgraph type
// is the whole IDL (encoding `omgidl`, name = the DDS type name), messages are
// the CDR payload exactly as DDS sends it (encoding `cdr`, with the 4-byte
// encapsulation header), and each channel's metadata names the DDS type and
// whether it is keyed. What the recorder, `bag import` and the tests write.

#include <cstdint>
#include <map>
#include <string>
#include <string_view>

#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/msg/cdr.hpp"

namespace skelgraph::recording {

class BagWriter {
 public:
  explicit BagWriter(const std::string& path, mcap::WriterOptions options = {});

  // A serialized sample of `type_name` (one of ours or any other DDS type: then
  // the schema is empty unless `idl` is given).
  void write_cdr(const std::string& topic, const std::string& type_name, bool keyed, std::string_view cdr,
                 std::uint64_t log_time, std::uint64_t publish_time);
  template <class T>
  void write(const std::string& topic, const T& value, std::uint64_t log_time, std::uint64_t publish_time) {
    const auto bytes = msg::to_cdr(value);
    write_cdr(topic, msg::MessageTraits<T>::name, T::isKeyDefined(),
              std::string_view(reinterpret_cast<const char*>(bytes.data()), bytes.size()), log_time, publish_time);
  }
  void write_metadata(const std::string& name, const mcap::KeyValues& values) { w_.write_metadata({name, values}); }
  void flush() { w_.flush(); }
  void close() { w_.close(); }
  mcap::Writer& mcap() { return w_; }

 private:
  mcap::Writer w_;
  std::map<std::string, std::uint16_t> channels_;  // by topic + type
  std::map<std::uint16_t, std::uint32_t> sequence_;
};

}  // namespace skelgraph::recording

#include "skelgraph/recording/bag.hpp"

#include "skelgraph/msg/idl_text.hpp"
#include "skelgraph/msg/message_table.hpp"

namespace skelgraph::recording {

BagWriter::BagWriter(const std::string& path, mcap::WriterOptions options)
    : w_(path, std::move(options)) {}

void BagWriter::write_cdr(const std::string& topic, const std::string& type_name, bool keyed, std::string_view cdr,
                          std::uint64_t log_time, std::uint64_t publish_time) {
  const auto key = topic + '\n' + type_name;
  auto it = channels_.find(key);
  if (it == channels_.end()) {
    std::uint16_t schema = 0;
    if (msg::find_message(type_name) != nullptr) schema = w_.add_schema(type_name, "omgidl", msg::idl_text());
    const auto id = w_.add_channel(schema, topic, "cdr", {{"dds_type", type_name}, {"keyed", keyed ? "true" : "false"}});
    it = channels_.emplace(key, id).first;
  }
  w_.write({it->second, sequence_[it->second]++, log_time, publish_time, cdr});
}

}  // namespace skelgraph::recording

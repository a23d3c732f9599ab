// libFuzzer target for the MCAP reader: any bytes must give either a result
// or an McapError, never a crash, a hang or an out-of-bounds read (run under
// AddressSanitizer). Build and run: tools/run fuzz [SECONDS].
#include <cstddef>
#include <cstdint>
#include <string>

#include "skelgraph/mcap/mcap.hpp"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace skelgraph::mcap;
  const Reader reader(std::string(reinterpret_cast<const char*>(data), size), "fuzz.mcap");
  try {
    reader.validate();
  } catch (const McapError&) {
  }
  try {
    std::size_t n = 0;
    reader.for_each_message([&](const Channel&, const Schema*, const Message& m) { n += m.data.size(); });
  } catch (const McapError&) {
  }
  try {
    (void)reader.summary();
  } catch (const McapError&) {
  }
  return 0;
}

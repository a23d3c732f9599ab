// Mending .oni recordings for Debian's OniFile player (see oni_source.hpp).
//
// The file, as OpenNI2's recorder writes it: a 24-byte header, then records.
// Each record starts with a 28-byte header (magic "NIR\0", type, node id,
// fields size including this header, payload size, undo position: u32 x5 + u64,
// little-endian, packed) and continues with its fields and payload. A general
// property record (type 6) has fields: u32 name length, the name (NUL-padded),
// u32 data size, the data. A node-added record (types 2, 12, 13) introduces a
// stream; the end record (11) closes the file.
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <vector>

#include "skelgraph/openni2/oni_source.hpp"

namespace skelgraph::openni2 {

namespace {

constexpr std::uint32_t kRecordMagic = 0x0052494E;  // "NIR\0"
constexpr std::size_t kFileHeader = 24, kRecordHeader = 28;
enum : std::uint32_t { kNodeAdded1004 = 2, kGeneralProp = 6, kEnd = 11, kNodeAdded1005 = 12, kNodeAdded = 13 };
constexpr const char* kCropping = "xnCropping";
constexpr const char* kSpare = "xnSupportedPixelFormats";  // only lists pixel formats; playback does not need it
constexpr std::size_t kCroppingSize = 12;                // XnCropping: enabled (4 bytes), x, y, width, height (u16)

std::uint32_t u32(const std::vector<char>& d, std::size_t at) {
  std::uint32_t v;
  std::memcpy(&v, d.data() + at, 4);
  return v;
}
void put_u32(std::vector<char>& d, std::size_t at, std::uint32_t v) { std::memcpy(d.data() + at, &v, 4); }

struct PropRecord {
  std::size_t offset, fields;
  std::string name;
};

}  // namespace

int oni_add_cropping(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  if (!in) throw std::runtime_error(path + ": cannot open");
  std::vector<char> data((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  in.close();
  if (data.size() < kFileHeader || std::memcmp(data.data(), "NI10", 4) != 0) {
    throw std::runtime_error(path + ": not an OpenNI recording (no NI10 header)");
  }
  std::set<std::uint32_t> streams;
  std::map<std::uint32_t, std::vector<PropRecord>> props;  // node -> general properties
  std::size_t off = kFileHeader;
  bool ended = false;
  while (!ended && off + kRecordHeader <= data.size()) {
    if (u32(data, off) != kRecordMagic) {
      throw std::runtime_error(path + ": malformed record at byte " + std::to_string(off));
    }
    const std::uint32_t type = u32(data, off + 4), node = u32(data, off + 8);
    const std::size_t fields = u32(data, off + 12), payload = u32(data, off + 16);
    if (fields < kRecordHeader || off + fields + payload > data.size()) {
      throw std::runtime_error(path + ": record at byte " + std::to_string(off) + " runs past the end of the file");
    }
    if (type == kNodeAdded || type == kNodeAdded1005 || type == kNodeAdded1004) streams.insert(node);
    if (type == kGeneralProp && fields >= kRecordHeader + 4) {
      const std::size_t name_len = u32(data, off + kRecordHeader);
      if (kRecordHeader + 4 + name_len <= fields) {
        const char* name = data.data() + off + kRecordHeader + 4;
        props[node].push_back({off, fields, std::string(name, strnlen(name, name_len))});
      }
    }
    ended = type == kEnd;
    off += fields + payload;
  }
  // Debian's recorder pads every finalised file with zeros to twice its length
  // (its truncate adds the old position to the new); nothing after the end record is read.
  const bool padded = ended && off < data.size();
  if (padded) data.resize(off);
  int mended = 0;
  for (const auto node : streams) {
    const auto& list = props[node];
    bool has = false;
    const PropRecord* spare = nullptr;
    for (const auto& p : list) {
      has = has || p.name == kCropping;
      // Room for: name length, "xnCropping\0", data size, the cropping.
      if (p.name == kSpare && p.fields >= kRecordHeader + 4 + std::strlen(kCropping) + 1 + 4 + kCroppingSize) spare = &p;
    }
    if (has) continue;
    if (spare == nullptr) {
      throw std::runtime_error(path + ": stream " + std::to_string(node) +
                               " has no cropping property and no record that can carry one");
    }
    // Rewrite in place: the name takes whatever room the cropping leaves.
    const std::size_t name_len = spare->fields - kRecordHeader - 4 - 4 - kCroppingSize;
    std::size_t at = spare->offset + kRecordHeader;
    put_u32(data, at, static_cast<std::uint32_t>(name_len));
    at += 4;
    std::memset(data.data() + at, 0, name_len);
    std::memcpy(data.data() + at, kCropping, std::strlen(kCropping));
    at += name_len;
    put_u32(data, at, kCroppingSize);
    at += 4;
    std::memset(data.data() + at, 0, kCroppingSize);  // disabled, whole image
    ++mended;
  }
  if (mended > 0 || padded) {
    const std::string tmp = path + ".mending";
    {
      std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
      out.write(data.data(), static_cast<std::streamsize>(data.size()));
      if (!out) throw std::runtime_error(tmp + ": cannot write");
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) throw std::runtime_error(path + ": cannot replace");
  }
  return mended;
}

}  // namespace skelgraph::openni2

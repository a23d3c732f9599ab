#include "skelgraph/mcap/mcap.hpp"

#include <fcntl.h>
#include <lz4frame.h>
#include <sys/mman.h>
#include <sys/stat.h>
#include <unistd.h>
#include <zlib.h>
#include <zstd.h>

#include <cerrno>
#include <cstring>
#include <fstream>
#include <sstream>

namespace skelgraph::mcap {

namespace {

constexpr char kMagic[] = {'\x89', 'M', 'C', 'A', 'P', '0', '\r', '\n'};
constexpr std::size_t kMagicSize = sizeof(kMagic);
constexpr std::uint64_t kMaxUncompressedChunk = 256ull << 20;  // refuse to inflate past this

enum Op : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

std::uint32_t crc32_of(std::string_view s, std::uint32_t crc = 0) {
  // zlib's crc32 is the CRC-32 (IEEE 802.3) MCAP uses; it takes at most uInt bytes per call.
  std::size_t done = 0;
  while (done < s.size()) {
    const std::size_t n = std::min<std::size_t>(s.size() - done, 1u << 30);
    crc = static_cast<std::uint32_t>(
        ::crc32(crc, reinterpret_cast<const Bytef*>(s.data() + done), static_cast<uInt>(n)));
    done += n;
  }
  return crc;
}

// Little-endian serialisation of record bodies.
struct Out {
  std::string s;
  template <class T>
  void le(T v) {
    for (std::size_t i = 0; i < sizeof(T); ++i) s.push_back(static_cast<char>((static_cast<std::uint64_t>(v) >> (8 * i)) & 0xff));
  }
  void u8(std::uint8_t v) { le(v); }
  void u16(std::uint16_t v) { le(v); }
  void u32(std::uint32_t v) { le(v); }
  void u64(std::uint64_t v) { le(v); }
  void str(std::string_view v) {
    u32(static_cast<std::uint32_t>(v.size()));
    s.append(v);
  }
  void bytes64(std::string_view v) {
    u64(v.size());
    s.append(v);
  }
  void map_ss(const KeyValues& m) {
    Out inner;
    for (const auto& [k, v] : m) {
      inner.str(k);
      inner.str(v);
    }
    str(inner.s);
  }
};

std::string record(std::uint8_t op, const std::string& body) {
  Out o;
  o.u8(op);
  o.u64(body.size());
  o.s += body;
  return o.s;
}

// Bounds-checked reading; every failure names the file offset.
class In {
 public:
  In(std::string_view data, std::uint64_t base, const std::string& name) : d_(data), base_(base), name_(name) {}
  std::uint64_t pos() const { return pos_; }
  std::uint64_t offset() const { return base_ + pos_; }
  std::uint64_t left() const { return d_.size() - pos_; }
  bool done() const { return pos_ == d_.size(); }
  void need(std::uint64_t n, const char* what) const {
    if (n > left()) {
      std::ostringstream os;
      os << name_ << ": truncated " << what << ": needs " << n << " bytes, " << left() << " left";
      throw McapError(os.str(), offset());
    }
  }
  template <class T>
  T le(const char* what) {
    need(sizeof(T), what);
    std::uint64_t v = 0;
    for (std::size_t i = 0; i < sizeof(T); ++i) v |= static_cast<std::uint64_t>(static_cast<unsigned char>(d_[pos_ + i])) << (8 * i);
    pos_ += sizeof(T);
    return static_cast<T>(v);
  }
  std::uint8_t u8(const char* w) { return le<std::uint8_t>(w); }
  std::uint16_t u16(const char* w) { return le<std::uint16_t>(w); }
  std::uint32_t u32(const char* w) { return le<std::uint32_t>(w); }
  std::uint64_t u64(const char* w) { return le<std::uint64_t>(w); }
  std::string_view take(std::uint64_t n, const char* what) {
    need(n, what);
    auto v = d_.substr(pos_, n);
    pos_ += n;
    return v;
  }
  std::string str(const char* what) { return std::string(take(u32(what), what)); }
  KeyValues map_ss(const char* what) {
    In m(take(u32(what), what), offset() , name_);
    KeyValues out;
    while (!m.done()) {
      auto k = m.str(what);
      out[k] = m.str(what);
    }
    return out;
  }
  std::string_view rest() { return take(left(), "record"); }

 private:
  std::string_view d_;
  std::uint64_t base_;
  const std::string& name_;
  std::uint64_t pos_ = 0;
};

// Compresses into `out` (its capacity is kept from chunk to chunk); returns the
// packed bytes: `raw` itself without compression.
std::string_view compress(Compression c, const std::string& raw, std::string& out) {
  if (c == Compression::None) return raw;
  if (c == Compression::Lz4) {
    out.resize(LZ4F_compressFrameBound(raw.size(), nullptr));
    const auto n = LZ4F_compressFrame(out.data(), out.size(), raw.data(), raw.size(), nullptr);
    if (LZ4F_isError(n)) throw McapError(std::string("lz4 compression failed: ") + LZ4F_getErrorName(n));
    out.resize(n);
  } else {
    out.resize(ZSTD_compressBound(raw.size()));
    const auto n = ZSTD_compress(out.data(), out.size(), raw.data(), raw.size(), 1);
    if (ZSTD_isError(n)) throw McapError(std::string("zstd compression failed: ") + ZSTD_getErrorName(n));
    out.resize(n);
  }
  return out;
}

std::string decompress(const std::string& compression, std::string_view data, std::uint64_t size, std::uint64_t at,
                       const std::string& name) {
  if (compression.empty()) {
    if (data.size() != size) throw McapError(name + ": chunk records length differs from its uncompressed size", at);
    return std::string(data);
  }
  if (size > kMaxUncompressedChunk) {
    throw McapError(name + ": chunk claims " + std::to_string(size) + " uncompressed bytes (limit 256 MiB)", at);
  }
  std::string out(size, '\0');
  if (compression == "zstd") {
    const auto n = ZSTD_decompress(out.data(), out.size(), data.data(), data.size());
    if (ZSTD_isError(n) || n != size) throw McapError(name + ": zstd chunk does not decompress to its stated size", at);
    return out;
  }
  if (compression == "lz4") {
    LZ4F_dctx* ctx = nullptr;
    if (LZ4F_isError(LZ4F_createDecompressionContext(&ctx, LZ4F_VERSION))) throw McapError("lz4: no context");
    std::size_t in_done = 0, out_done = 0;
    bool ok = true;
    while (in_done < data.size() && out_done <= out.size()) {
      std::size_t in_n = data.size() - in_done, out_n = out.size() - out_done;
      const auto r = LZ4F_decompress(ctx, out.data() + out_done, &out_n, data.data() + in_done, &in_n, nullptr);
      if (LZ4F_isError(r) || (in_n == 0 && out_n == 0)) {
        ok = false;
        break;
      }
      in_done += in_n;
      out_done += out_n;
      if (r == 0) break;  // frame complete
    }
    LZ4F_freeDecompressionContext(ctx);
    if (!ok || out_done != size) throw McapError(name + ": lz4 chunk does not decompress to its stated size", at);
    return out;
  }
  throw McapError(name + ": unknown chunk compression '" + compression + "'", at);
}

}  // namespace

McapError::McapError(const std::string& what, std::optional<std::uint64_t> offset)
    : std::runtime_error(offset ? what + " (at byte " + std::to_string(*offset) + ")" : what), offset_(offset) {}

const char* compression_name(Compression c) {
  switch (c) {
    case Compression::Lz4: return "lz4";
    case Compression::Zstd: return "zstd";
    default: return "";
  }
}

std::optional<Compression> compression_from_name(std::string_view n) {
  if (n.empty() || n == "none") return Compression::None;
  if (n == "lz4") return Compression::Lz4;
  if (n == "zstd") return Compression::Zstd;
  return std::nullopt;
}

std::string schema_body(const Schema& sc) {
  Out o;
  o.u16(sc.id);
  o.str(sc.name);
  o.str(sc.encoding);
  o.str(sc.data);
  return o.s;
}

std::string channel_body(const Channel& c) {
  Out o;
  o.u16(c.id);
  o.u16(c.schema_id);
  o.str(c.topic);
  o.str(c.message_encoding);
  o.map_ss(c.metadata);
  return o.s;
}

// ---------------------------------------------------------------- writer

struct Writer::ChunkIndex {
  std::uint64_t start_time, end_time, offset, length;
  std::map<std::uint16_t, std::uint64_t> index_offsets;
  std::uint64_t index_length;
  std::string compression;
  std::uint64_t compressed_size, uncompressed_size;
};

Writer::Writer(const std::string& path, WriterOptions options) : path_(path), opt_(std::move(options)) {
  file_ = std::fopen(path.c_str(), "wb");
  if (file_ == nullptr) throw McapError("cannot create " + path + ": " + std::strerror(errno));
  put(kMagic, kMagicSize);
  Out h;
  h.str(opt_.profile);
  h.str(opt_.library);
  write_record(kHeader, h.s);
}

std::uint64_t Writer::chunk_count() const { return chunk_indexes_.size(); }

Writer::~Writer() {
  if (file_ == nullptr) return;
  try {
    close();
  } catch (...) {
    if (file_ != nullptr) std::fclose(file_);
    file_ = nullptr;
  }
}

void Writer::put(const void* data, std::size_t n) {
  if (file_ == nullptr) throw McapError(path_ + ": writer is closed");
  if (std::fwrite(data, 1, n, file_) != n) {
    throw McapError("cannot write " + path_ + ": " + std::strerror(errno), offset_);
  }
  if (!in_summary_) data_crc_ = crc32_of({static_cast<const char*>(data), n}, data_crc_);
  offset_ += n;
}

void Writer::write_record(std::uint8_t op, std::string_view body, std::string_view tail) {
  // Opcode and length, then the body as it is: no copy of a megabyte chunk per record.
  Out h;
  h.u8(op);
  h.u64(body.size() + tail.size());
  put(h.s.data(), h.s.size());
  put(body.data(), body.size());
  if (!tail.empty()) put(tail.data(), tail.size());
}

std::uint16_t Writer::add_schema(const std::string& name, const std::string& encoding, const std::string& data) {
  for (const auto& s : schemas_) {
    if (s.name == name && s.encoding == encoding && s.data == data) return s.id;
  }
  if (schemas_.size() >= 65535) throw McapError(path_ + ": too many schemas");
  Schema s{static_cast<std::uint16_t>(schemas_.size() + 1), name, encoding, data};
  chunk_ += record(kSchema, schema_body(s));
  schemas_.push_back(std::move(s));
  return schemas_.back().id;
}

std::uint16_t Writer::add_channel(std::uint16_t schema_id, const std::string& topic, const std::string& encoding,
                                  const KeyValues& metadata) {
  if (schema_id > schemas_.size()) throw McapError(path_ + ": channel '" + topic + "' names an unknown schema");
  for (const auto& c : channels_) {
    if (c.schema_id == schema_id && c.topic == topic && c.message_encoding == encoding && c.metadata == metadata) return c.id;
  }
  if (channels_.size() >= 65535) throw McapError(path_ + ": too many channels");
  Channel c{static_cast<std::uint16_t>(channels_.size() + 1), schema_id, topic, encoding, metadata};
  chunk_ += record(kChannel, channel_body(c));
  channels_.push_back(std::move(c));
  return channels_.back().id;
}

void Writer::write(const Message& m) {
  if (m.channel_id == 0 || m.channel_id > channels_.size()) {
    throw McapError(path_ + ": message on unknown channel " + std::to_string(m.channel_id));
  }
  const std::uint64_t at = chunk_.size();
  Out o;
  o.u8(kMessage);
  o.u64(2 + 4 + 8 + 8 + m.data.size());
  o.u16(m.channel_id);
  o.u32(m.sequence);
  o.u64(m.log_time);
  o.u64(m.publish_time);
  chunk_ += o.s;
  chunk_.append(m.data);
  chunk_message_index_[m.channel_id].emplace_back(m.log_time, at);
  if (!chunk_has_messages_) {
    chunk_start_ = chunk_end_ = m.log_time;
    chunk_has_messages_ = true;
  }
  chunk_start_ = std::min(chunk_start_, m.log_time);
  chunk_end_ = std::max(chunk_end_, m.log_time);
  if (message_count_ == 0) first_time_ = last_time_ = m.log_time;
  first_time_ = std::min(first_time_, m.log_time);
  last_time_ = std::max(last_time_, m.log_time);
  ++message_count_;
  ++channel_counts_[m.channel_id];
  if (chunk_.size() >= opt_.chunk_size) close_chunk();
}

void Writer::close_chunk() {
  if (chunk_.empty()) return;
  const std::string_view packed = compress(opt_.compression, chunk_, packed_);
  ChunkIndex ci;
  ci.start_time = chunk_has_messages_ ? chunk_start_ : 0;
  ci.end_time = chunk_has_messages_ ? chunk_end_ : 0;
  ci.offset = offset_;
  ci.compression = compression_name(opt_.compression);
  ci.compressed_size = packed.size();
  ci.uncompressed_size = chunk_.size();
  Out o;
  o.u64(ci.start_time);
  o.u64(ci.end_time);
  o.u64(chunk_.size());
  o.u32(crc32_of(chunk_));
  o.str(ci.compression);
  o.u64(packed.size());
  write_record(kChunk, o.s, packed);  // the packed records follow the chunk's header fields
  ci.length = offset_ - ci.offset;
  const std::uint64_t index_start = offset_;
  for (const auto& [channel, entries] : chunk_message_index_) {
    ci.index_offsets[channel] = offset_;
    Out mi, arr;
    for (const auto& [time, at] : entries) {
      arr.u64(time);
      arr.u64(at);
    }
    mi.u16(channel);
    mi.str(arr.s);
    write_record(kMessageIndex, mi.s);
  }
  ci.index_length = offset_ - index_start;
  chunk_indexes_.push_back(std::move(ci));
  chunk_.clear();
  chunk_message_index_.clear();
  chunk_has_messages_ = false;
}

void Writer::write_metadata(const Metadata& m) {
  close_chunk();  // metadata lives outside chunks
  const std::uint64_t at = offset_;
  Out o;
  o.str(m.name);
  o.map_ss(m.values);
  write_record(kMetadata, o.s);
  metadata_index_offsets_.emplace_back(at, offset_ - at);
  metadata_names_.push_back(m.name);
}

void Writer::flush() {
  close_chunk();
  if (std::fflush(file_) != 0 || ::fsync(fileno(file_)) != 0) {
    throw McapError("cannot flush " + path_ + ": " + std::strerror(errno), offset_);
  }
}

void Writer::close() {
  if (file_ == nullptr) return;
  close_chunk();
  Out de;
  de.u32(data_crc_);
  write_record(kDataEnd, de.s);

  // Summary: groups by opcode, each indexed by a Summary Offset record.
  in_summary_ = true;
  const std::uint64_t summary_start = offset_;
  std::string summary;
  std::vector<std::tuple<std::uint8_t, std::uint64_t, std::uint64_t>> groups;
  auto group = [&](std::uint8_t op, const std::vector<std::string>& bodies) {
    if (bodies.empty()) return;
    const std::uint64_t start = summary_start + summary.size();
    for (const auto& b : bodies) summary += record(op, b);
    groups.emplace_back(op, start, summary_start + summary.size() - start);
  };
  std::vector<std::string> bodies;
  for (const auto& s : schemas_) bodies.push_back(schema_body(s));
  group(kSchema, bodies);
  bodies.clear();
  for (const auto& c : channels_) bodies.push_back(channel_body(c));
  group(kChannel, bodies);
  bodies.clear();
  {
    Out o;
    o.u64(message_count_);
    o.u16(static_cast<std::uint16_t>(schemas_.size()));
    o.u32(static_cast<std::uint32_t>(channels_.size()));
    o.u32(0);  // attachments
    o.u32(static_cast<std::uint32_t>(metadata_names_.size()));
    o.u32(static_cast<std::uint32_t>(chunk_indexes_.size()));
    o.u64(message_count_ ? first_time_ : 0);
    o.u64(message_count_ ? last_time_ : 0);
    Out counts;
    for (const auto& [id, n] : channel_counts_) {
      counts.u16(id);
      counts.u64(n);
    }
    o.str(counts.s);
    group(kStatistics, {o.s});
  }
  for (const auto& ci : chunk_indexes_) {
    Out o, offsets;
    o.u64(ci.start_time);
    o.u64(ci.end_time);
    o.u64(ci.offset);
    o.u64(ci.length);
    for (const auto& [id, at] : ci.index_offsets) {
      offsets.u16(id);
      offsets.u64(at);
    }
    o.str(offsets.s);
    o.u64(ci.index_length);
    o.str(ci.compression);
    o.u64(ci.compressed_size);
    o.u64(ci.uncompressed_size);
    bodies.push_back(o.s);
  }
  group(kChunkIndex, bodies);
  bodies.clear();
  for (std::size_t i = 0; i < metadata_names_.size(); ++i) {
    Out o;
    o.u64(metadata_index_offsets_[i].first);
    o.u64(metadata_index_offsets_[i].second);
    o.str(metadata_names_[i]);
    bodies.push_back(o.s);
  }
  group(kMetadataIndex, bodies);
  put(summary.data(), summary.size());
  const std::uint64_t summary_offset_start = offset_;
  std::string offsets;
  for (const auto& [op, start, length] : groups) {
    Out o;
    o.u8(op);
    o.u64(start);
    o.u64(length);
    offsets += record(kSummaryOffset, o.s);
  }
  put(offsets.data(), offsets.size());
  Out f;
  f.u8(kFooter);
  f.u64(8 + 8 + 4);
  f.u64(summary_start);
  f.u64(summary_offset_start);
  const std::uint32_t summary_crc = crc32_of(f.s, crc32_of(offsets, crc32_of(summary)));
  f.u32(summary_crc);
  put(f.s.data(), f.s.size());
  put(kMagic, kMagicSize);
  const bool ok = std::fflush(file_) == 0 && ::fsync(fileno(file_)) == 0;
  const int err = errno;
  const bool closed = std::fclose(file_) == 0;
  file_ = nullptr;
  if (!ok || !closed) throw McapError("cannot finish " + path_ + ": " + std::strerror(err));
}

// ---------------------------------------------------------------- reader

struct Reader::Scan {
  Summary summary;
  const MessageCallback* on_message = nullptr;
  std::uint64_t chunks = 0;
  std::uint64_t messages = 0;
  std::uint64_t summary_start = 0, summary_offset_start = 0;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> chunk_records;  // offset, length
  std::vector<std::pair<std::uint64_t, std::uint64_t>> indexed_chunks;  // from the summary
  std::vector<std::uint64_t> chunk_index_at;                             // where each of those index records is
  std::optional<std::uint64_t> stats_messages;
};

namespace {

struct Mapping {
  void* data = nullptr;
  std::size_t size = 0;
  Mapping(void* d, std::size_t n) : data(d), size(n) {}
  Mapping(const Mapping&) = delete;
  Mapping& operator=(const Mapping&) = delete;
  ~Mapping() { ::munmap(data, size); }
};

// The file's bytes, mapped read-only: recordings of depth streams are many GB.
std::pair<std::shared_ptr<const void>, std::string_view> map_file(const std::string& path) {
  const int fd = ::open(path.c_str(), O_RDONLY | O_CLOEXEC);
  if (fd < 0) throw McapError("cannot open " + path + ": " + std::strerror(errno));
  struct stat st {};
  if (::fstat(fd, &st) != 0 || !S_ISREG(st.st_mode)) {
    const int err = errno;
    ::close(fd);
    throw McapError("cannot read " + path + ": " + (S_ISREG(st.st_mode) ? std::strerror(err) : "not a regular file"));
  }
  const auto n = static_cast<std::size_t>(st.st_size);
  if (n == 0) {
    ::close(fd);
    return {nullptr, std::string_view()};
  }
  void* p = ::mmap(nullptr, n, PROT_READ, MAP_PRIVATE, fd, 0);
  const int err = errno;
  ::close(fd);
  if (p == MAP_FAILED) throw McapError("cannot map " + path + ": " + std::strerror(err));
  ::madvise(p, n, MADV_SEQUENTIAL);
  auto m = std::make_shared<Mapping>(p, n);
  return {m, std::string_view(static_cast<const char*>(p), n)};
}

}  // namespace

Reader::Reader(const std::string& path) : name_(path) {
  auto [storage, bytes] = map_file(path);
  storage_ = std::move(storage);
  bytes_ = bytes;
  mapped_ = storage_ != nullptr;
}

Reader::Reader(std::string bytes, std::string name) : name_(std::move(name)) {
  auto owned = std::make_shared<const std::string>(std::move(bytes));
  bytes_ = *owned;
  storage_ = std::move(owned);
}

namespace {

Schema parse_schema(In& r) {
  Schema s;
  s.id = r.u16("schema id");
  s.name = r.str("schema name");
  s.encoding = r.str("schema encoding");
  s.data = r.str("schema data");
  return s;
}

Channel parse_channel(In& r) {
  Channel c;
  c.id = r.u16("channel id");
  c.schema_id = r.u16("channel schema id");
  c.topic = r.str("channel topic");
  c.message_encoding = r.str("channel message encoding");
  c.metadata = r.map_ss("channel metadata");
  return c;
}

Message parse_message(In& r) {
  Message m;
  m.channel_id = r.u16("message channel");
  m.sequence = r.u32("message sequence");
  m.log_time = r.u64("message log time");
  m.publish_time = r.u64("message publish time");
  m.data = r.rest();
  return m;
}

Metadata parse_metadata(In& r) {
  Metadata m;
  m.name = r.str("metadata name");
  m.values = r.map_ss("metadata");
  return m;
}

// A chunk record's records, decompressed and CRC-checked (`at`: the record's offset).
std::string read_chunk(In& r, std::uint64_t at, const std::string& name) {
  r.u64("chunk start time");
  r.u64("chunk end time");
  const auto size = r.u64("chunk uncompressed size");
  const auto crc = r.u32("chunk crc");
  const auto compression = r.str("chunk compression");
  const auto packed = r.take(r.u64("chunk records length"), "chunk records");
  std::string raw = decompress(compression, packed, size, at, name);
  if (crc != 0 && crc != crc32_of(raw)) throw McapError(name + ": chunk CRC mismatch", at);
  return raw;
}

}  // namespace

void Reader::scan(Scan& s, bool strict) const {
  const std::string_view all(bytes_);
  if (all.size() < 2 * kMagicSize || std::memcmp(all.data(), kMagic, kMagicSize) != 0) {
    throw McapError(name_ + ": not an MCAP file (no MCAP magic at the start)", 0);
  }
  In file(all.substr(kMagicSize), kMagicSize, name_);
  auto next_record = [&](std::uint8_t* op, std::uint64_t* at) {
    *at = file.offset();
    *op = file.u8("record opcode");
    const auto len = file.u64("record length");
    return In(file.take(len, "record"), file.offset() - len, name_);
  };
  std::uint8_t op = 0;
  std::uint64_t at = 0;
  {
    In h = next_record(&op, &at);
    if (op != kHeader) throw McapError(name_ + ": the first record is not a Header", at);
    s.summary.profile = h.str("header profile");
    s.summary.library = h.str("header library");
  }
  auto handle_inner = [&](std::uint8_t iop, In& r, std::uint64_t rat) {
    if (iop == kSchema) {
      auto sc = parse_schema(r);
      if (sc.id != 0) s.summary.schemas[sc.id] = std::move(sc);
    } else if (iop == kChannel) {
      auto c = parse_channel(r);
      if (c.schema_id != 0 && !s.summary.schemas.count(c.schema_id)) {
        throw McapError(name_ + ": channel " + std::to_string(c.id) + " names schema " + std::to_string(c.schema_id) +
                            " before it is defined", rat);
      }
      s.summary.channels[c.id] = std::move(c);
    } else if (iop == kMessage) {
      const Message m = parse_message(r);
      const auto ch = s.summary.channels.find(m.channel_id);
      if (ch == s.summary.channels.end()) {
        throw McapError(name_ + ": message on channel " + std::to_string(m.channel_id) + " before the channel is defined", rat);
      }
      if (s.messages == 0) s.summary.message_start_time = s.summary.message_end_time = m.log_time;
      s.summary.message_start_time = std::min(s.summary.message_start_time, m.log_time);
      s.summary.message_end_time = std::max(s.summary.message_end_time, m.log_time);
      ++s.messages;
      ++s.summary.channel_message_counts[m.channel_id];
      if (s.on_message != nullptr && *s.on_message) {
        const auto sc = s.summary.schemas.find(ch->second.schema_id);
        (*s.on_message)(ch->second, sc == s.summary.schemas.end() ? nullptr : &sc->second, m);
      }
    }
    // Other records inside chunks are ignored, as the specification asks.
  };
  bool data_end = false;
  // Pages of the mapping behind the scan are given back every 8 MiB (the file's
  // contents stay in the page cache; touched again, they are mapped again).
  const auto page = static_cast<std::uint64_t>(::sysconf(_SC_PAGESIZE));
  std::uint64_t released = 0;
  const auto release_behind = [&](std::uint64_t upto) {
    if (!mapped_ || upto < released + (8u << 20)) return;
    const std::uint64_t end = upto / page * page;
    ::madvise(const_cast<char*>(all.data()) + released, end - released, MADV_DONTNEED);
    released = end;
  };
  while (!file.done()) {
    release_behind(file.offset());
    In r = next_record(&op, &at);
    if (op == kDataEnd) {
      const auto crc = r.u32("data section crc");
      if (strict && crc != 0 && crc != crc32_of(all.substr(0, at))) {
        throw McapError(name_ + ": data section CRC mismatch", at);
      }
      data_end = true;
      break;
    }
    if (op == kHeader || op == kFooter) throw McapError(name_ + ": unexpected record 0x0" + std::to_string(op) + " in the data section", at);
    if (op == kMessageIndex) {
      s.summary.has_message_indexes = true;
      continue;
    }
    if (op == kAttachment) {
      ++s.summary.attachment_count;
      continue;
    }
    if (op == kChunk) {
      const std::string raw = read_chunk(r, at, name_);
      In inner(raw, 0, name_);
      while (!inner.done()) {
        const auto iat = inner.offset();
        const auto iop = inner.u8("record opcode in chunk");
        In ir(inner.take(inner.u64("record length in chunk"), "record in chunk"), 0, name_);
        try {
          handle_inner(iop, ir, at);
        } catch (const McapError& e) {
          throw McapError(std::string(e.what()) + " in the chunk at byte " + std::to_string(at) + ", its byte " + std::to_string(iat));
        }
      }
      s.chunk_records.emplace_back(at, file.offset() - at);
      ++s.chunks;
    } else if (op == kMetadata) {
      s.summary.metadata.push_back(parse_metadata(r));
    } else {
      handle_inner(op, r, at);
    }
  }
  if (!data_end) {
    throw McapError(name_ + ": no Data End record: the file was not finished (skelgraph bag recover can salvage it)",
                    file.offset());
  }
  // Summary and summary offsets, then the footer and the magic.
  const std::uint64_t footer_at = all.size() - kMagicSize - (1 + 8 + 20);
  if (all.size() < kMagicSize + kMagicSize + 29 || std::memcmp(all.data() + all.size() - kMagicSize, kMagic, kMagicSize) != 0) {
    throw McapError(name_ + ": no MCAP magic at the end", all.size());
  }
  while (file.offset() < footer_at) {
    In r = next_record(&op, &at);
    if (op == kStatistics) {
      s.stats_messages = r.u64("statistics message count");
      s.summary.has_statistics = true;
    } else if (op == kAttachmentIndex) {
      s.summary.has_attachment_indexes = true;
    } else if (op == kMetadataIndex) {
      s.summary.has_metadata_indexes = true;
    } else if (op == kSummaryOffset) {
      s.summary.has_summary_offsets = true;
    } else if (op == kChunkIndex) {
      s.summary.has_chunk_indexes = true;
      r.u64("chunk index start");
      r.u64("chunk index end");
      const auto off = r.u64("chunk index offset");
      const auto len = r.u64("chunk index length");
      s.indexed_chunks.emplace_back(off, len);
      s.chunk_index_at.push_back(at);
    } else if (op == kFooter) {
      throw McapError(name_ + ": footer before the end of the file", at);
    }
  }
  if (file.offset() != footer_at) throw McapError(name_ + ": the summary runs into the footer", file.offset());
  In f = next_record(&op, &at);
  if (op != kFooter) throw McapError(name_ + ": the last record is not a Footer", at);
  s.summary_start = f.u64("footer summary start");
  s.summary_offset_start = f.u64("footer summary offset start");
  const auto crc = f.u32("footer summary crc");
  s.summary.indexed = s.summary_start != 0;
  if (strict && crc != 0 && s.summary_start != 0) {
    if (s.summary_start > footer_at) throw McapError(name_ + ": footer's summary start is past the footer", at);
    if (crc != crc32_of(all.substr(s.summary_start, footer_at + 1 + 8 + 16 - s.summary_start))) {
      throw McapError(name_ + ": summary CRC mismatch", at);
    }
  }
  s.summary.message_count = s.messages;
  s.summary.chunk_count = s.chunks;
}

void Reader::validate() const {
  Scan s;
  scan(s, true);
  if (s.stats_messages && *s.stats_messages != s.messages) {
    throw McapError(name_ + ": statistics count " + std::to_string(*s.stats_messages) + " messages, the file has " +
                    std::to_string(s.messages));
  }
  // Chunk indexes are optional; those a file has must match its chunks.
  if (s.summary.has_chunk_indexes && s.indexed_chunks != s.chunk_records) {
    // Name the first that disagree: an index pointing beside its chunk, or a chunk no index names.
    std::size_t i = 0;
    while (i < s.indexed_chunks.size() && i < s.chunk_records.size() && s.indexed_chunks[i] == s.chunk_records[i]) ++i;
    const auto where = [](const std::pair<std::uint64_t, std::uint64_t>& c) {
      return "byte " + std::to_string(c.first) + ", " + std::to_string(c.second) + " bytes";
    };
    if (i < s.indexed_chunks.size()) {
      throw McapError(name_ + ": chunk indexes do not match the chunks in the file: index " + std::to_string(i + 1) +
                          " names a chunk at " + where(s.indexed_chunks[i]) + ", the file's chunk " + std::to_string(i + 1) +
                          (i < s.chunk_records.size() ? " is at " + where(s.chunk_records[i]) : std::string(" does not exist")),
                      s.chunk_index_at[i]);
    }
    throw McapError(name_ + ": chunk indexes do not match the chunks in the file: chunk " + std::to_string(i + 1) + " at " +
                        where(s.chunk_records[i]) + " has no index (" + std::to_string(s.indexed_chunks.size()) + " indexes, " +
                        std::to_string(s.chunk_records.size()) + " chunks)",
                    s.chunk_records[i].first);
  }
}

Summary Reader::summary() const {
  Scan s;
  scan(s, false);
  return s.summary;
}

void Reader::for_each_message(const MessageCallback& cb) const {
  Scan s;
  s.on_message = &cb;
  scan(s, false);
}

// ---------------------------------------------------------------- recovery

RecoveryReport recover(const std::string& in_path, const std::string& out_path, WriterOptions options) {
  const auto [storage, bytes] = map_file(in_path);
  if (bytes.size() < kMagicSize || std::memcmp(bytes.data(), kMagic, kMagicSize) != 0) {
    throw McapError(in_path + ": not an MCAP file (no MCAP magic at the start)", 0);
  }
  RecoveryReport rep;
  rep.input_size = bytes.size();
  Writer w(out_path, std::move(options));
  std::map<std::uint16_t, std::uint16_t> schema_ids, channel_ids;
  std::map<std::uint16_t, Schema> schemas;
  auto take = [&](std::uint8_t op, In& r) {
    if (op == kSchema) {
      auto s = parse_schema(r);
      if (s.id != 0) schema_ids[s.id] = w.add_schema(s.name, s.encoding, s.data);
    } else if (op == kChannel) {
      auto c = parse_channel(r);
      const auto sid = c.schema_id == 0 ? 0 : schema_ids.at(c.schema_id);
      channel_ids[c.id] = w.add_channel(sid, c.topic, c.message_encoding, c.metadata);
    } else if (op == kMessage) {
      Message m = parse_message(r);
      m.channel_id = channel_ids.at(m.channel_id);
      w.write(m);
      ++rep.messages;
    } else if (op == kMetadata) {
      w.write_metadata(parse_metadata(r));
    }
  };
  In file(std::string_view(bytes).substr(kMagicSize), kMagicSize, in_path);
  rep.bytes_read = kMagicSize;
  try {
    while (!file.done()) {
      const auto at = file.offset();
      const auto op = file.u8("record opcode");
      const auto len = file.u64("record length");
      In r(file.take(len, "record"), file.offset() - len, in_path);
      if (op == kDataEnd) break;
      if (op == kChunk) {
        const std::string raw = read_chunk(r, at, in_path);
        // Parse the whole chunk before taking any of it: a chunk is kept whole or not at all.
        std::vector<std::pair<std::uint8_t, std::string_view>> records;
        In inner(raw, 0, in_path);
        while (!inner.done()) {
          const auto iop = inner.u8("record opcode in chunk");
          records.emplace_back(iop, inner.take(inner.u64("record length in chunk"), "record in chunk"));
        }
        for (auto& [iop, body] : records) {
          In ir(body, 0, in_path);
          take(iop, ir);
        }
        ++rep.chunks;
      } else if (op != kHeader) {
        take(op, r);
      }
      rep.bytes_read = file.offset();
    }
  } catch (const std::exception& e) {
    rep.stopped_because = e.what();
  }
  w.close();
  return rep;
}

std::uint64_t copy_messages(const Reader& in, Writer& out, const std::function<bool(const Channel&)>& keep,
                            const Reader::MessageCallback& after) {
  for (const auto& m : in.summary().metadata) out.write_metadata(m);
  std::map<std::uint16_t, std::uint16_t> channels;  // input channel -> output channel
  std::uint64_t copied = 0;
  in.for_each_message([&](const Channel& ch, const Schema* schema, const Message& m) {
    if (keep && !keep(ch)) return;
    auto& mapped = channels[ch.id];
    if (mapped == 0) {
      const auto sid = schema ? out.add_schema(schema->name, schema->encoding, schema->data) : std::uint16_t{0};
      mapped = out.add_channel(sid, ch.topic, ch.message_encoding, ch.metadata);
    }
    Message copy = m;
    copy.channel_id = mapped;
    out.write(copy);
    ++copied;
    if (after) after(ch, schema, m);
  });
  return copied;
}

}  // namespace skelgraph::mcap

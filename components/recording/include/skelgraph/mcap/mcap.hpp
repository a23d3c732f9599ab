#pragma once
// MCAP files (https://mcap.dev/spec), written and read by our own code: no
// MCAP package exists in Debian. The writer chunks messages (optionally lz4 or
// zstd compressed), with CRCs, message indexes, chunk indexes, statistics and
// a summary; the reader checks every length against the bytes that are there
// and every CRC, and names the offset of what is wrong. No DDS here.

#include <cstdint>
#include <cstdio>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <stdexcept>
#include <string>
#include <string_view>
#include <vector>

namespace skelgraph::mcap {

// Anything wrong with a file: what, and at which byte offset when it applies.
class McapError : public std::runtime_error {
 public:
  McapError(const std::string& what, std::optional<std::uint64_t> offset = std::nullopt);
  std::optional<std::uint64_t> offset() const { return offset_; }

 private:
  std::optional<std::uint64_t> offset_;
};

using KeyValues = std::map<std::string, std::string>;

struct Schema {
  std::uint16_t id = 0;
  std::string name;      // e.g. "skelgraph::msg::Skeleton"
  std::string encoding;  // e.g. "omgidl"
  std::string data;      // e.g. the IDL text
};

struct Channel {
  std::uint16_t id = 0;
  std::uint16_t schema_id = 0;
  std::string topic;
  std::string message_encoding;  // e.g. "cdr"
  KeyValues metadata;
};

struct Message {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0;      // ns
  std::uint64_t publish_time = 0;  // ns
  std::string_view data;           // valid during the call that hands it out
};

struct Metadata {
  std::string name;
  KeyValues values;
};

enum class Compression { None, Lz4, Zstd };
const char* compression_name(Compression c);  // "", "lz4", "zstd"
std::optional<Compression> compression_from_name(std::string_view name);  // also "none"

struct WriterOptions {
  std::string profile;                // MCAP profile ("" = none of the well-known ones)
  std::string library = "skelgraph";  // free-form writer name
  Compression compression = Compression::None;
  std::uint64_t chunk_size = 1 << 20;  // a chunk is closed when its records reach this many bytes
};

class Writer {
 public:
  // Creates (truncates) `path`. Throws McapError naming the path and the reason.
  Writer(const std::string& path, WriterOptions options = {});
  ~Writer();  // closes the file if close() was not called (errors are swallowed there: call close())
  Writer(const Writer&) = delete;
  Writer& operator=(const Writer&) = delete;

  // Ids are assigned here (from 1); adding an identical schema or channel again returns the first id.
  std::uint16_t add_schema(const std::string& name, const std::string& encoding, const std::string& data);
  std::uint16_t add_channel(std::uint16_t schema_id, const std::string& topic, const std::string& message_encoding,
                            const KeyValues& metadata = {});
  void write(const Message& message);  // throws McapError for an unknown channel
  void write_metadata(const Metadata& metadata);
  // Ends the current chunk and pushes everything to the operating system, so a
  // writer killed afterwards loses nothing written before this call.
  void flush();
  // Writes the summary and footer; the file is complete. Throws McapError on I/O errors.
  void close();

  std::uint64_t bytes_written() const { return offset_; }
  std::uint64_t message_count() const { return message_count_; }
  std::uint64_t chunk_count() const;
  const std::string& path() const { return path_; }

 private:
  struct ChunkIndex;
  void put(const void* data, std::size_t n);  // to the file, counting and CRC'ing
  void write_record(std::uint8_t op, std::string_view body, std::string_view tail = {});
  void close_chunk();

  std::string path_;
  WriterOptions opt_;
  std::FILE* file_ = nullptr;
  std::uint64_t offset_ = 0;
  std::uint32_t data_crc_ = 0;
  bool in_summary_ = false;
  std::vector<Schema> schemas_;
  std::vector<Channel> channels_;
  std::string chunk_;   // uncompressed records of the open chunk
  std::string packed_;  // the chunk compressed (kept: no fresh megabyte per chunk)
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_message_index_;
  std::uint64_t chunk_start_ = 0, chunk_end_ = 0;
  bool chunk_has_messages_ = false;
  std::vector<ChunkIndex> chunk_indexes_;
  std::vector<std::pair<std::uint64_t, std::uint64_t>> metadata_index_offsets_;  // offset, length
  std::vector<std::string> metadata_names_;
  std::map<std::uint16_t, std::uint64_t> channel_counts_;
  std::uint64_t message_count_ = 0, first_time_ = 0, last_time_ = 0;
};

// What `Reader::summary()` finds: from the summary section when the file has
// one, else by reading the whole data section.
struct Summary {
  std::string profile, library;
  std::map<std::uint16_t, Schema> schemas;
  std::map<std::uint16_t, Channel> channels;
  std::uint64_t message_count = 0;
  std::uint64_t chunk_count = 0;
  std::uint64_t message_start_time = 0, message_end_time = 0;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts;
  std::vector<Metadata> metadata;
  std::uint64_t attachment_count = 0;
  bool indexed = false;  // had a summary section
  // What the summary section (and the data section's message indexes) hold:
  // all optional; what is missing is read by scanning the data section.
  bool has_statistics = false, has_chunk_indexes = false, has_message_indexes = false,
       has_attachment_indexes = false, has_metadata_indexes = false, has_summary_offsets = false;
};

class Reader {
 public:
  // Maps the file read-only (memory is the page cache, not a copy; one chunk
  // at a time is decompressed; a scan releases the pages behind it, so a
  // process reading a file of any size holds a few MB of it). Throws McapError (not an MCAP file, too
  // short, unreadable). The file must not shrink while a Reader is open.
  explicit Reader(const std::string& path);
  // From bytes already in memory (`name` for messages).
  Reader(std::string bytes, std::string name);

  // Checks the structure: magic at both ends, every record's length, header
  // first, footer last, every CRC (chunks, data section, summary), chunk
  // indexes against their chunks. Throws McapError at the first problem.
  void validate() const;
  Summary summary() const;
  // Every message in file order (chunks decompressed and CRC-checked), with its channel and schema.
  using MessageCallback = std::function<void(const Channel&, const Schema*, const Message&)>;
  void for_each_message(const MessageCallback& cb) const;

  std::uint64_t size() const { return bytes_.size(); }
  const std::string& name() const { return name_; }

 private:
  struct Scan;
  void scan(Scan& s, bool strict) const;

  std::shared_ptr<const void> storage_;  // the mapping, or the bytes given
  std::string_view bytes_;
  bool mapped_ = false;  // a scan gives back the pages it has read (the process's memory stays small on GB files)
  std::string name_;
};

// Salvages what a killed writer left: every complete, CRC-valid chunk (and
// record outside chunks) up to the first truncated or damaged record, written
// to `out` as a complete, indexed file.
struct RecoveryReport {
  std::uint64_t messages = 0, chunks = 0;
  std::uint64_t bytes_read = 0;    // of the input, up to the end of the last good record
  std::uint64_t input_size = 0;
  std::string stopped_because;     // empty when the whole input was complete
};
RecoveryReport recover(const std::string& in_path, const std::string& out_path, WriterOptions options = {});

// Copies a file's metadata and messages into `out` as they are (schemas and
// channels added once each), leaving out the channels `keep` refuses;
// `after` sees each copied message (with the input's channel and schema).
// Returns how many messages were copied.
std::uint64_t copy_messages(const Reader& in, Writer& out, const std::function<bool(const Channel&)>& keep,
                            const Reader::MessageCallback& after = {});

}  // namespace skelgraph::mcap

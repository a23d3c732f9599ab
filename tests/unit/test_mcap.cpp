// The MCAP library: round trips, every compression, CRCs, damaged and
// truncated files (clear errors, never a crash), recovery of a killed writer.
#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "skelgraph/mcap/mcap.hpp"

using namespace skelgraph::mcap;

namespace {

std::string temp_path(const std::string& name) {
  const auto dir = std::filesystem::temp_directory_path() / ("skelgraph_mcap_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  return (dir / name).string();
}

std::string slurp(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void spit(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary);
  out << bytes;
}

std::string payload(int i) { return std::string(static_cast<std::size_t>(10 + i % 50), static_cast<char>('a' + i % 26)); }

// Writes n messages on two channels; returns the path.
std::string write_file(const std::string& name, Compression c, int n, std::uint64_t chunk_size = 4096) {
  const auto path = temp_path(name);
  WriterOptions opt;
  opt.compression = c;
  opt.chunk_size = chunk_size;
  Writer w(path, opt);
  const auto s = w.add_schema("skelgraph::msg::Test", "omgidl", "module skelgraph { module msg { struct Test { long x; }; }; };");
  const auto a = w.add_channel(s, "skelgraph/a", "cdr", {{"keyed", "true"}});
  const auto b = w.add_channel(s, "skelgraph/b", "cdr");
  EXPECT_EQ(w.add_channel(s, "skelgraph/a", "cdr", {{"keyed", "true"}}), a);  // the same channel again
  w.write_metadata({"session", {{"label", "walk_1"}, {"host", "vm"}}});
  for (int i = 0; i < n; ++i) {
    const auto data = payload(i);
    w.write({i % 3 == 0 ? b : a, static_cast<std::uint32_t>(i), 1000u + 10u * i, 999u + 10u * i, data});
  }
  w.close();
  return path;
}

}  // namespace

TEST(Mcap, RoundTripsEveryMessageWithEachCompression) {
  for (auto c : {Compression::None, Compression::Lz4, Compression::Zstd}) {
    SCOPED_TRACE(compression_name(c));
    const auto path = write_file(std::string("rt_") + compression_name(c) + ".mcap", c, 500);
    const Reader r(path);
    EXPECT_NO_THROW(r.validate());
    const auto s = r.summary();
    EXPECT_TRUE(s.indexed);
    EXPECT_EQ(s.library, "skelgraph");
    EXPECT_EQ(s.message_count, 500u);
    EXPECT_GT(s.chunk_count, 3u);  // 4 KiB chunks
    ASSERT_EQ(s.channels.size(), 2u);
    EXPECT_EQ(s.channels.at(1).topic, "skelgraph/a");
    EXPECT_EQ(s.channels.at(1).metadata.at("keyed"), "true");
    EXPECT_EQ(s.schemas.at(1).encoding, "omgidl");
    EXPECT_EQ(s.message_start_time, 1000u);
    EXPECT_EQ(s.message_end_time, 1000u + 10u * 499);
    EXPECT_EQ(s.channel_message_counts.at(2), 167u);
    ASSERT_EQ(s.metadata.size(), 1u);
    EXPECT_EQ(s.metadata[0].values.at("label"), "walk_1");
    int i = 0;
    r.for_each_message([&](const Channel& ch, const Schema* schema, const Message& m) {
      ASSERT_NE(schema, nullptr);
      EXPECT_EQ(schema->name, "skelgraph::msg::Test");
      EXPECT_EQ(ch.topic, i % 3 == 0 ? "skelgraph/b" : "skelgraph/a");
      EXPECT_EQ(m.sequence, static_cast<std::uint32_t>(i));
      EXPECT_EQ(m.log_time, 1000u + 10u * i);
      EXPECT_EQ(m.publish_time, 999u + 10u * i);
      EXPECT_EQ(std::string(m.data), payload(i));
      ++i;
    });
    EXPECT_EQ(i, 500);
  }
}

TEST(Mcap, CompressionShrinksRepetitiveData) {
  const auto plain = std::filesystem::file_size(write_file("c_none.mcap", Compression::None, 2000, 1 << 20));
  const auto zstd = std::filesystem::file_size(write_file("c_zstd.mcap", Compression::Zstd, 2000, 1 << 20));
  const auto lz4 = std::filesystem::file_size(write_file("c_lz4.mcap", Compression::Lz4, 2000, 1 << 20));
  EXPECT_LT(zstd * 3, plain);
  EXPECT_LT(lz4 * 2, plain);
}

TEST(Mcap, DamageIsFoundAndNamedWithItsOffset) {
  const auto path = write_file("damage.mcap", Compression::None, 200);
  const auto good = slurp(path);
  // A flipped byte inside the first chunk's records.
  std::string bad = good;
  const auto chunk_at = bad.find("skelgraph/a");  // the channel record, inside the first chunk
  ASSERT_NE(chunk_at, std::string::npos);
  bad[chunk_at + 3] ^= 0x20;
  try {
    Reader(bad, "flipped.mcap").validate();
    FAIL() << "a flipped byte went unnoticed";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("chunk CRC mismatch"), std::string::npos) << e.what();
    ASSERT_TRUE(e.offset().has_value());
    EXPECT_LT(*e.offset(), chunk_at);
  }
  // Not MCAP at all.
  try {
    Reader(std::string("hello, world, this is not a recording"), "hello.txt").validate();
    FAIL();
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("not an MCAP file"), std::string::npos) << e.what();
  }
  // An absurd record length.
  bad = good;
  for (int k = 0; k < 8; ++k) bad[8 + 1 + k] = '\x7f';  // the header's length
  try {
    Reader(bad, "long.mcap").validate();
    FAIL();
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("truncated record"), std::string::npos) << e.what();
    EXPECT_EQ(e.offset().value_or(0), 17u);
  }
  // A summary byte flipped: the summary CRC catches it.
  bad = good;
  bad[bad.size() - 60] ^= 0x01;
  EXPECT_THROW(Reader(bad, "summary.mcap").validate(), McapError);
}

// The summary and its indexes are optional (a file read by scanning is
// valid); indexes that are there must match the data.
TEST(Mcap, IndexesThatContradictTheChunksAreADefect) {
  const auto path = write_file("indexed.mcap", Compression::None, 200);
  const auto good = slurp(path);
  ASSERT_NO_THROW(Reader(good, "good.mcap").validate());
  const auto u64 = [](const std::string& b, std::size_t at) {
    std::uint64_t v = 0;
    for (int k = 7; k >= 0; --k) v = (v << 8) | static_cast<unsigned char>(b[at + static_cast<std::size_t>(k)]);
    return v;
  };
  // Footer: opcode, length, summary start, summary offset start, summary CRC, then the magic.
  const std::size_t footer = good.size() - 8 - (1 + 8 + 8 + 8 + 4);
  const auto summary_start = u64(good, footer + 1 + 8);
  ASSERT_GT(summary_start, 0u);
  // The first chunk index in the summary: move the chunk it points at by one byte.
  std::size_t at = summary_start;
  while (at < footer && good[at] != '\x08') at += 1 + 8 + u64(good, at + 1);
  ASSERT_LT(at, footer) << "no chunk index";
  std::string bad = good;
  const std::size_t offset_field = at + 1 + 8 + 8 + 8;  // after message start and end times
  bad[offset_field] = static_cast<char>(bad[offset_field] + 1);
  for (int k = 0; k < 4; ++k) bad[footer + 1 + 8 + 8 + 8 + static_cast<std::size_t>(k)] = 0;  // summary CRC: none
  try {
    Reader(bad, "moved.mcap").validate();
    FAIL() << "a chunk index pointing beside its chunk went unnoticed";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("chunk indexes do not match the chunks in the file"), std::string::npos) << e.what();
    ASSERT_TRUE(e.offset().has_value()) << e.what();
    EXPECT_EQ(*e.offset(), at) << "the offset of the index record that is wrong: " << e.what();
  }
  EXPECT_EQ(Reader(bad, "moved.mcap").summary().message_count, Reader(good, "good.mcap").summary().message_count);
  const auto s = Reader(good, "good.mcap").summary();
  EXPECT_TRUE(s.has_chunk_indexes && s.has_statistics && s.has_message_indexes);
}

TEST(Mcap, EveryTruncationIsAClearErrorNeverACrash) {
  const auto good = slurp(write_file("trunc.mcap", Compression::Lz4, 60, 512));
  for (std::size_t n = 0; n < good.size(); ++n) {
    const Reader r(good.substr(0, n), "cut.mcap");
    EXPECT_THROW(r.validate(), McapError) << "cut at " << n;
    EXPECT_THROW(r.summary(), McapError) << "cut at " << n;
  }
}

TEST(Mcap, RecoverSalvagesEveryFlushedChunkOfAKilledWriter) {
  const auto path = temp_path("killed.mcap");
  std::string snapshot;
  {
    Writer w(path);  // uncompressed, so the test can find where a message lies
    const auto s = w.add_schema("T", "omgidl", "struct T { long x; };");
    const auto c = w.add_channel(s, "skelgraph/a", "cdr");
    for (int i = 0; i < 300; ++i) {
      const auto data = payload(i);
      w.write({c, static_cast<std::uint32_t>(i), static_cast<std::uint64_t>(i), static_cast<std::uint64_t>(i), data});
      if (i % 100 == 99) w.flush();  // what the recorder does every second
    }
    for (int i = 300; i < 350; ++i) {
      const auto data = payload(i);
      w.write({c, static_cast<std::uint32_t>(i), static_cast<std::uint64_t>(i), static_cast<std::uint64_t>(i), data});
    }
    snapshot = slurp(path);  // the file as a SIGKILL would leave it: 300 flushed, 50 still in memory
  }
  // The kill came in the middle of writing the third chunk.
  const auto mid_third = snapshot.rfind(payload(250));
  ASSERT_NE(mid_third, std::string::npos);
  spit(path, snapshot.substr(0, mid_third));
  EXPECT_THROW(Reader(path).validate(), McapError);
  const auto out = temp_path("recovered.mcap");
  const auto rep = recover(path, out);
  EXPECT_EQ(rep.chunks, 2u);
  EXPECT_EQ(rep.messages, 200u);
  EXPECT_NE(rep.stopped_because.find("truncated"), std::string::npos) << rep.stopped_because;
  const Reader r(out);
  EXPECT_NO_THROW(r.validate());
  EXPECT_EQ(r.summary().message_count, 200u);
  // Cut in the third chunk's message index: the chunk itself is whole and comes back.
  spit(path, snapshot.substr(0, snapshot.size() - 3));
  EXPECT_EQ(recover(path, out).messages, 300u);
  // The whole snapshot (nothing cut): all 300 flushed messages come back.
  spit(path, snapshot);
  EXPECT_EQ(recover(path, out).messages, 300u);
  EXPECT_EQ(Reader(out).summary().message_count, 300u);
}

TEST(Mcap, WriterRefusesWhatItCannotDo) {
  EXPECT_THROW(Writer("/nonexistent-dir/x.mcap"), McapError);
  try {
    Writer w("/nonexistent-dir/x.mcap");
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("No such file or directory"), std::string::npos) << e.what();
  }
  Writer w(temp_path("refuse.mcap"));
  EXPECT_THROW(w.write({7, 0, 0, 0, "x"}), McapError);       // no such channel
  EXPECT_THROW(w.add_channel(9, "t", "cdr"), McapError);     // no such schema
  EXPECT_EQ(compression_from_name("zstd"), Compression::Zstd);
  EXPECT_FALSE(compression_from_name("gzip").has_value());
}

// Inputs the fuzzer found interesting or crashing (tests/fuzz/regressions): each reads or fails cleanly.
TEST(Mcap, FuzzRegressionInputsNeverCrash) {
  const char* src = std::getenv("SKELGRAPH_SOURCE_DIR");
  const auto dir = std::filesystem::path(src ? src : ".") / "tests" / "fuzz" / "regressions";
  ASSERT_TRUE(std::filesystem::is_directory(dir)) << dir;
  int files = 0;
  for (const auto& e : std::filesystem::directory_iterator(dir)) {
    if (e.path().filename() == ".keep") continue;
    ++files;
    const Reader r(slurp(e.path().string()), e.path().filename().string());
    try {
      r.validate();
      r.for_each_message([](const Channel&, const Schema*, const Message&) {});
    } catch (const McapError&) {
    }
  }
  EXPECT_GE(files, 1);
}

TEST(Mcap, ReaderNamesWhatIsNotARecording) {
  try {
    Reader r(std::string("/"));
    FAIL() << "a directory was accepted";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("not a regular file"), std::string::npos) << e.what();
  }
  const auto empty = temp_path("empty.mcap");
  spit(empty, "");
  try {
    Reader(empty).validate();
    FAIL() << "an empty file was accepted";
  } catch (const McapError& e) {
    EXPECT_NE(std::string(e.what()).find("not an MCAP file"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Reader(temp_path("does-not-exist.mcap")), McapError);
}

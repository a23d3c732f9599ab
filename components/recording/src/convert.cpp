#include "skelgraph/recording/convert.hpp"

#include <filesystem>
#include <fstream>
#include <iomanip>
#include <map>

#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/msg/cdr.hpp"
#include "skelgraph/msg/schema.hpp"
#include "skelgraph/playback/bvh.hpp"
#include "skelgraph/recording/bag.hpp"
#include "skelgraph/recording/session_recorder.hpp"
#include "skelgraph/runtime/topics.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

namespace skelgraph::recording {

std::uint64_t import_skeletons(playback::Format format, const std::vector<std::string>& files,
                               const playback::ReadOptions& options, const std::string& out, mcap::Compression compression,
                               const std::function<void(const std::string&, std::size_t)>& on_file) {
  mcap::WriterOptions wo;
  wo.compression = compression;
  BagWriter bag(out, wo);
  std::uint64_t frames = 0;
  for (const auto& f : files) {
    const auto rec = playback::read_recording(format, f, options);
    mcap::KeyValues meta = rec.metadata;
    meta["format"] = rec.format;
    meta["source"] = f;
    bag.write_metadata("import", meta);
    for (const auto& s : rec.frames) {
      if (s.stamp_ns < 0) throw ConvertError(f + ": negative time stamp " + std::to_string(s.stamp_ns) + " cannot be recorded");
      const auto t = static_cast<std::uint64_t>(s.stamp_ns);
      bag.write(runtime::topics::kSkeletonRaw.name, skeleton::to_msg(s), t, t);
      ++frames;
    }
    if (on_file) on_file(f, rec.frames.size());
  }
  bag.close();
  return frames;
}

MocapImportSummary import_mocap(const MocapImport& o) {
  playback::BvhOptions b;
  b.units_to_m = o.units == "mm" ? 0.001 : o.units == "m" ? 1.0 : o.units == "in" ? 0.0254 : 0.01;
  if (!o.transform.empty()) b.target_from_mocap = calib::read_transform_file(o.transform, o.mocap_id);
  if (!o.time_points.empty()) b.time_points = playback::read_bvh_time_points(o.time_points);
  if (!o.mapping.empty()) b.joints = playback::read_bvh_mapping(o.mapping);
  b.frame_id = o.frame_id;
  mcap::WriterOptions wo;
  wo.compression = mcap::Compression::Zstd;
  BagWriter bag(o.out, wo);
  MocapImportSummary r;
  std::optional<std::uint64_t> first;
  if (!o.add_to.empty()) {
    const mcap::Reader reader(o.add_to);
    r.copied = mcap::copy_messages(
        reader, bag.mcap(),
        [](const mcap::Channel& ch) { return ch.topic != runtime::topics::kSkeletonTruth.name; },  // replaced by the mocap
        [&](const mcap::Channel&, const mcap::Schema*, const mcap::Message& m) {
          if (!first || m.log_time < *first) first = m.log_time;
        });
  }
  b.time_offset_s = o.time_offset ? *o.time_offset : first ? 1e-9 * static_cast<double>(*first) : 0.0;
  r.time_offset_s = b.time_offset_s;
  const auto rec = playback::bvh_recording(o.file, playback::read_bvh(o.file), b);
  for (const auto& s : rec.frames) {
    if (s.stamp_ns < 0) throw ConvertError(o.file + ": negative time stamp; give --time-offset");
    const auto t = static_cast<std::uint64_t>(s.stamp_ns);
    bag.write(runtime::topics::kSkeletonTruth.name, skeleton::to_msg(s), t, t);
  }
  bag.write_metadata("mocap", {{"source", o.file}, {"units", o.units}, {"frame_id", o.frame_id}, {"joints", rec.metadata.at("joints")}});
  bag.close();
  r.truth_frames = rec.frames.size();
  r.span_s = rec.frames.size() > 1 ? 1e-9 * static_cast<double>(rec.frames.back().stamp_ns - rec.frames.front().stamp_ns) : 0.0;
  return r;
}

std::vector<std::pair<std::string, std::size_t>> export_skeletons(const std::string& file, SkeletonCsv format,
                                                                  const std::string& dir) {
  const mcap::Reader reader(file);
  std::map<std::string, playback::Recording> by_stream;  // "<topic tail>_<sensor>"
  reader.for_each_message([&](const mcap::Channel& ch, const mcap::Schema* schema, const mcap::Message& m) {
    if (schema == nullptr || schema->name != msg::MessageTraits<msg::Skeleton>::name) return;
    auto s = skeleton::from_msg(msg::from_cdr<msg::Skeleton>(m.data.data(), m.data.size()));
    const auto tail = ch.topic.substr(ch.topic.rfind('/') + 1);
    auto& rec = by_stream[file_safe(tail + "_" + s.sensor_id)];
    rec.format = "generic";
    rec.metadata["topic"] = ch.topic;
    rec.metadata["source"] = file;
    rec.frames.push_back(std::move(s));
  });
  std::filesystem::create_directories(dir);
  std::vector<std::pair<std::string, std::size_t>> written;
  for (auto& [name, rec] : by_stream) {
    const auto path = std::filesystem::path(dir) / (name + ".csv");
    std::ofstream out(path);
    if (!out) throw std::runtime_error("cannot write " + path.string());
    if (format == SkeletonCsv::Generic) {
      playback::write_generic_csv(rec, out);
    } else {
      out << "stamp_ns,time_s,person_id,frame_number";
      for (std::size_t j = 0; j < skeleton::kJointCount; ++j) {
        const std::string n = skeleton::joint_name(skeleton::joint_at(j));
        out << "," << n << "_x," << n << "_y," << n << "_z," << n << "_conf";
      }
      out << "\n" << std::setprecision(9);
      const auto t0 = rec.frames.empty() ? 0 : rec.frames.front().stamp_ns;
      for (const auto& s : rec.frames) {
        out << s.stamp_ns << "," << static_cast<double>(s.stamp_ns - t0) * 1e-9 << "," << s.person_id << ","
            << s.frame_number;
        for (const auto& j : s.joints) {
          out << "," << j.position.x() << "," << j.position.y() << "," << j.position.z() << "," << j.confidence;
        }
        out << "\n";
      }
    }
    if (!out.flush()) throw std::runtime_error("error writing " + path.string());
    written.emplace_back(path.string(), rec.frames.size());
  }
  return written;
}

}  // namespace skelgraph::recording

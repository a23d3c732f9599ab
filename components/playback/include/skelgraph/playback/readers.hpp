#pragma once
// Readers for recorded skeleton data sets, mapping each format's joints into
// the canonical 15 (tables in components/playback/README.md). A library: the
// playback component and the offline tools use it alike, no DDS.

#include <cstddef>
#include <map>
#include <optional>
#include <ostream>
#include <string>
#include <string_view>
#include <vector>

#include "skelgraph/playback/csv.hpp"
#include "skelgraph/skeleton/skeleton.hpp"

namespace skelgraph::playback {

enum class Format {
  Generic,      // skelgraph's own CSV (write_generic_csv writes it)
  KinderGator,  // Kinect v1, 20 joints, X/Y/Z, ms since midnight UTC
  KinectV2,     // Kinect v2 body file (laban/): ticks, 25 joints x (X, Y, Z, TrackingState)
  MultiTrack,   // KinectMultiTrack CSV: two Kinect v2 sensors, several people, ", " separated
  GesturePhase, // UCI gesture-phase CSV: 6 points, per-frame phase labels
  Msrc12,       // MSRC-12: Kinect v1, 20 joints, space-separated, µs; gesture action points in a .tagstream beside it
};
const char* format_name(Format f);  // "generic", "kinder-gator", "kinect-v2", "multitrack", "gesture-phase"
std::optional<Format> format_from_name(std::string_view name);
std::vector<std::string> format_names();

struct ReadOptions {
  enum class OnError { Stop, Skip };
  OnError on_error = OnError::Stop;  // Stop: the first bad line throws DataError
  std::string sensor_id;             // overrides the format's default sensor id (multitrack: a prefix)
};

struct ReadReport {
  std::size_t lines = 0;            // data lines read
  std::size_t skipped = 0;          // bad lines skipped (OnError::Skip)
  std::size_t repeated_stamps = 0;  // frames with the same stamp as the one before (kept)
  std::size_t last_line = 0;        // the file's last line read (where "no frames" is reported)
  std::size_t empty_frames = 0;     // lines without a skeleton (MSRC-12: all zeros), left out
  std::vector<std::string> problems;  // the first 20 messages of skipped lines
};

// A labelled moment or span of a recording: an action point (MSRC-12's tags:
// start_ns == end_ns) or a range, on the frames' clock.
struct Annotation {
  std::string label;
  std::int64_t start_ns = 0, end_ns = 0;
};

struct Recording {
  std::string format;
  std::string source;                          // the file read
  std::map<std::string, std::string> metadata;  // e.g. action, subject, gesture
  std::vector<skeleton::Skeleton> frames;       // in time order
  std::vector<std::string> frame_labels;        // per frame when the format has them (gesture-phase), else empty
  // Joints the canonical 15 leave out, one position per frame (NaN: not
  // reported), when the format has them: "left_wrist", "right_wrist" (Kinect
  // v1 and v2, gesture-phase); "pelvis", "left_ankle", "right_ankle" (v1, v2);
  // "upper_neck", "left_hand_tip", "right_hand_tip", "left_thumb",
  // "right_thumb" (v2, multitrack). The generic CSV keeps them all.
  // Gesture features can use them offline; the skeleton topics do not carry them.
  std::map<std::string, std::vector<Eigen::Vector3d>> extra_joints;
  std::vector<Annotation> annotations;          // in time order, when the format has them
  ReadReport report;
};

// Throws DataError (file:line: what was expected) on bad input under
// OnError::Stop, and under either policy when the file gives no skeleton frame
// at all (empty, header only, every line bad, or nobody tracked).
Recording read_recording(Format format, const std::string& path, const ReadOptions& options = {});

// MSRC-12's annotation file (FILE.tagstream: a header `XQPCTick;Tag`, then
// `<tick>;<gesture name>` per instance): action points on the skeleton file's
// clock (tick -> µs as the data set's load_tagstream.m: (tick * 1000 + 49875 / 2)
// / 49875). Throws DataError naming file:line.
std::vector<Annotation> read_tagstream(const std::string& path);

// An annotation file for any recording, CSV with a header: `label,start_s,end_s`
// (seconds from the recording's first frame) or `label,start_frame,end_frame`
// (frame indices, 0-based, inclusive); an action point has start == end.
// `recording` gives the clock. Throws DataError naming file:line (a start
// after its end, a frame outside the recording, an unknown header).
std::vector<Annotation> read_annotation_csv(const std::string& path, const Recording& recording);

// Per-frame labels (gesture-phase) as ranges: each run of one label becomes
// an annotation from its first to its last frame; labels in `rest` are none.
std::vector<Annotation> annotations_from_frame_labels(const Recording& recording,
                                                      const std::vector<std::string>& rest = {"Rest", "rest", "none", ""});

// The annotations of a recording file, in this order: FILE's stem +
// ".annotations.csv" beside it (read_annotation_csv), else the format's own
// (MSRC-12's .tagstream, already in recording.annotations; gesture-phase's
// per-frame labels). Empty when there are none.
std::vector<Annotation> annotations_of(const Recording& recording);

// "FILE: N bad lines skipped (first: ...)" when lines were skipped, else "".
std::string skipped_summary(const Recording& recording);

// skelgraph's own CSV: "# skelgraph skeleton csv v1", "# key: value" metadata
// lines, a header, then one row per skeleton with every joint's position,
// orientation and confidence, and every extra joint's position
// (extra_<name>_x/_y/_z, empty where it was not reported). Reading it back
// gives the same recording.
void write_generic_csv(const Recording& recording, std::ostream& out);

}  // namespace skelgraph::playback

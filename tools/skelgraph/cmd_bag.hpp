#pragma once
// `skelgraph bag`: what its subcommands (cmd_bag*.cpp) share.

#include <utility>

#include "cli.hpp"
#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/playback/readers.hpp"
#include "skelgraph/recording/convert.hpp"

namespace skelgraph::cli::bag_cmd {

// A bad file is the user's input: exit 2 with what and where.
template <class F>
auto file_input(F&& f) {
  return cli::user_input<mcap::McapError, playback::DataError, recording::ConvertError, calib::CalibFileError>(
      std::forward<F>(f));
}

// bag import, import-bvh and export (cmd_bag_convert.cpp).
void add_convert_commands(CLI::App& bag, Action& run);

}  // namespace skelgraph::cli::bag_cmd

#pragma once
// `skelgraph bag`: what its subcommands (cmd_bag*.cpp) share.

#include "cli.hpp"
#include "skelgraph/calib/calib_file.hpp"
#include "skelgraph/mcap/mcap.hpp"
#include "skelgraph/playback/readers.hpp"
#include "skelgraph/recording/convert.hpp"

namespace skelgraph::cli::bag_cmd {

// A bad file is the user's input: exit 2 with what and where.
template <class F>
auto user_input(F&& f) {
  try {
    return f();
  } catch (const mcap::McapError& e) {
    throw UsageError(e.what());
  } catch (const playback::DataError& e) {
    throw UsageError(e.what());
  } catch (const recording::ConvertError& e) {
    throw UsageError(e.what());
  } catch (const calib::CalibFileError& e) {
    throw UsageError(e.what());
  }
}

// bag import, import-bvh and export (cmd_bag_convert.cpp).
void add_convert_commands(CLI::App& bag, Action& run);

}  // namespace skelgraph::cli::bag_cmd

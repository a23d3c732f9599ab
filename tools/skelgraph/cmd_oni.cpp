// skelgraph oni: OpenNI2 devices and .oni recordings (info, mend).

#include <chrono>
#include <cstdio>

#include <nlohmann/json.hpp>

#include "cli.hpp"
#include "skelgraph/openni2/oni_source.hpp"

namespace skelgraph::cli {

void add_oni_command(CLI::App& app, GlobalOptions&, Action& run) {
  auto* cmd = app.add_subcommand("oni", "OpenNI2 depth devices and .oni recordings: info, mend");
  cmd->require_subcommand(1);

  struct InfoOpts {
    std::string uri;
    bool read = false, json = false;
  };
  auto io = std::make_shared<InfoOpts>();
  auto* info = cmd->add_subcommand("info", "Open a device or recording and describe its depth stream");
  info->add_option("uri", io->uri, "an .oni file, \"Dummy\", \"any\" or a device URI")->required();
  info->add_flag("--read", io->read, "read every frame of a recording as fast as possible and count them");
  info->add_flag("--json", io->json, "print JSON");
  info->callback([io, &run] {
    run = [io] {
      openni2::OniOptions o;
      o.uri = io->uri;
      o.speed = 0.0;
      openni2::OniSource src(o);
      nlohmann::json out = {{"uri", io->uri},
                            {"device", src.description()},
                            {"is_file", src.is_file()},
                            {"frames", src.frame_count()},
                            {"width", src.intrinsics().width},
                            {"height", src.intrinsics().height},
                            {"fps", src.fps()},
                            {"fx", src.intrinsics().fx},
                            {"fy", src.intrinsics().fy},
                            {"intrinsics_from_device", src.intrinsics_from_device()}};
      if (io->read) {
        if (!src.is_file()) throw UsageError("--read is for recordings; '" + io->uri + "' is a device");
        const auto t0 = std::chrono::steady_clock::now();
        std::uint64_t n = 0, valid = 0, pixels = 0;
        while (!src.at_end()) {
          const auto f = src.next(std::chrono::milliseconds(100));
          if (!f) continue;
          ++n;
          valid += f->valid_count();
          pixels += f->mm.size();
        }
        const double s = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
        out["frames_read"] = n;
        out["valid_fraction"] = pixels > 0 ? static_cast<double>(valid) / static_cast<double>(pixels) : 0.0;
        out["read_s"] = s;
      }
      if (io->json) {
        std::printf("%s\n", out.dump(2).c_str());
      } else {
        std::printf("%s\n  intrinsics fx %.1f fy %.1f (%s)\n", src.description().c_str(), src.intrinsics().fx,
                    src.intrinsics().fy, src.intrinsics_from_device() ? "from the device" : "Kinect-like, assumed");
        if (io->read) {
          std::printf("  read %llu frames in %.2f s, %.1f %% of pixels with a reading\n",
                      static_cast<unsigned long long>(out["frames_read"].get<std::uint64_t>()), out["read_s"].get<double>(),
                      100.0 * out["valid_fraction"].get<double>());
        }
      }
      return 0;
    };
  });

  struct MendOpts {
    std::vector<std::string> files;
    bool json = false;
  };
  auto mo = std::make_shared<MendOpts>();
  auto* mend = cmd->add_subcommand(
      "mend", "Make recordings of devices without a cropping property (the Dummy device) playable by OpenNI2's "
              "player; files that need nothing are left as they are");
  mend->add_option("files", mo->files, ".oni files")->required()->check(CLI::ExistingFile);
  mend->add_flag("--json", mo->json, "print JSON");
  mend->callback([mo, &run] {
    run = [mo] {
      nlohmann::json out = nlohmann::json::array();
      for (const auto& f : mo->files) {
        const int n = openni2::oni_add_cropping(f);
        out.push_back({{"file", f}, {"streams_mended", n}});
        if (!mo->json) std::printf("%s: %s\n", f.c_str(), n > 0 ? ("mended " + std::to_string(n) + " stream(s)").c_str() : "nothing to mend");
      }
      if (mo->json) std::printf("%s\n", out.dump(2).c_str());
      return 0;
    };
  });
}

}  // namespace skelgraph::cli

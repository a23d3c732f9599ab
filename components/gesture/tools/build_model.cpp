// Trains a built-in gesture model at build time (builtin_models.hpp):
//   build_model NAME OUT.json
// "sim": pointing, on the simulator's sessions exactly as `skelgraph gesture sim`
// trains with its defaults (kTrainSessions, seed 1, hard negatives).
#include <cstdio>
#include <exception>
#include <string>

#include "skelgraph/gesture/sim_sessions.hpp"

int main(int argc, char** argv) {
  using namespace skelgraph::gesture;
  if (argc != 3) {
    std::fprintf(stderr, "usage: build_model NAME OUT.json (NAME: sim)\n");
    return 2;
  }
  const std::string name = argv[1], out = argv[2];
  try {
    if (name != "sim") {
      std::fprintf(stderr, "build_model: no recipe for model '%s' (known: sim)\n", name.c_str());
      return 2;
    }
    std::size_t clips = 0;
    const auto model = train_on_sim(kTrainSessions, 1, sim_classifier_options(), &clips);
    model.save(out);
    std::printf("build_model: %s trained on %zu clips of %d simulated sessions (and their quiet sessions) -> %s\n", name.c_str(),
                clips, kTrainSessions, out.c_str());
  } catch (const std::exception& e) {
    std::fprintf(stderr, "build_model: %s\n", e.what());
    return 1;
  }
  return 0;
}

// What a skeleton source costs per sample: building the wire message (the
// generated type's constructors; see idl/patch_generated.cmake) and running
// the simulator. Run: tools/run bench (JSON in build/bench/).
#include <benchmark/benchmark.h>

#include <memory>

#include "skelgraph/sim/simulation.hpp"
#include "skelgraph/skeleton/skeleton_msg.hpp"

using namespace skelgraph;

static void BM_SkeletonToMsg(benchmark::State& state) {
  skeleton::Skeleton s;
  s.sensor_id = "sensor1";
  for (auto& j : s.joints) j.confidence = skeleton::kTracked;
  for (auto _ : state) {
    auto m = skeleton::to_msg(s);
    benchmark::DoNotOptimize(m);
  }
}
BENCHMARK(BM_SkeletonToMsg);

// One simulated second: truth at 30 Hz plus `range(0)` sensors' trackers, one person.
static void BM_SimulateOneSecond(benchmark::State& state) {
  sim::SimConfig cfg;
  cfg.scenario.name = "point";
  cfg.scenario.repeats = 50;
  cfg.sensors = sim::default_sensors(static_cast<int>(state.range(0)));
  auto sim = std::make_unique<sim::Simulation>(cfg);
  double t = 0;
  std::size_t events = 0;
  for (auto _ : state) {
    t += 1.0;
    if (t > sim->duration()) {
      state.PauseTiming();
      sim = std::make_unique<sim::Simulation>(cfg);
      t = 1.0;
      state.ResumeTiming();
    }
    events += sim->advance(t).size();
  }
  state.counters["events_per_s"] = benchmark::Counter(static_cast<double>(events), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_SimulateOneSecond)->Arg(1)->Arg(2)->Arg(4)->Unit(benchmark::kMillisecond);

BENCHMARK_MAIN();

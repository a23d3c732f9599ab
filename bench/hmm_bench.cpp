// Baum-Welch and forward-pass speed of the gesture HMM core on the issue's
// reference problem (7 states, 8-D full covariance, 100 sequences x 100
// frames, 10 iterations), single thread. Writes the data it trained on (for
// the pomegranate side of bench/hmm_bench.sh) and prints JSON.
// Usage: hmm_bench DATA_OUT.json
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <fstream>
#include <limits>
#include <random>

#include "skelgraph/gesture/gaussian_mixture.hpp"

using namespace skelgraph::gesture;

int main(int argc, char** argv) {
  if (argc != 2) {
    std::fprintf(stderr, "usage: hmm_bench DATA_OUT.json\n");
    return 2;
  }
  // Data: a random walk through 7 regimes in 8-D, so the model has structure to find.
  std::mt19937_64 rng(1);
  std::normal_distribution<double> n(0, 1);
  std::vector<Eigen::VectorXd> centres;
  for (int s = 0; s < 7; ++s) {
    Eigen::VectorXd c(8);
    for (int d = 0; d < 8; ++d) c(d) = 3 * n(rng);
    centres.push_back(c);
  }
  std::vector<Sequence> data;
  nlohmann::json dump = nlohmann::json::array();
  for (int i = 0; i < 100; ++i) {
    Sequence x(100, 8);
    int s = 0;
    for (int t = 0; t < 100; ++t) {
      if (std::uniform_real_distribution<double>(0, 1)(rng) < 0.1) s = (s + 1) % 7;
      for (int d = 0; d < 8; ++d) x(t, d) = centres[static_cast<std::size_t>(s)](d) + n(rng);
    }
    data.push_back(x);
    nlohmann::json seq = nlohmann::json::array();
    for (int t = 0; t < 100; ++t) {
      std::vector<double> r(8);
      for (int d = 0; d < 8; ++d) r[static_cast<std::size_t>(d)] = x(t, d);
      seq.push_back(r);
    }
    dump.push_back(seq);
  }
  std::ofstream(argv[1]) << dump.dump();
  TrainOptions o;
  o.states = 7;
  o.mixtures = 1;
  o.covariance = Covariance::Full;
  o.max_iterations = 10;
  o.tolerance = -std::numeric_limits<double>::infinity();  // always the full 10
  using clock = std::chrono::steady_clock;
  // The best of 10 runs (this machine's timings vary from run to run), of
  // the whole training and of the initialisation alone (segmentation,
  // k-means and the E-step that scores it): their difference over the
  // iterations is Baum-Welch alone, as pomegranate's figure is.
  TrainReport rep;
  GaussianHmm h;
  const auto best_of = [&](const TrainOptions& opt) {
    double best = 1e300;
    for (int run = 0; run < 10; ++run) {
      const auto t0 = clock::now();
      h = GaussianHmm::train(data, opt, &rep);
      best = std::min(best, std::chrono::duration<double>(clock::now() - t0).count());
    }
    return best;
  };
  TrainOptions init_only = o;
  init_only.max_iterations = 0;
  const double init_s = best_of(init_only);
  const double train_s = best_of(o);
  const int reps = 2000;
  double sink = 0, fwd_ms = 1e300;
  for (int run = 0; run < 3; ++run) {
    const auto t1 = clock::now();
    for (int i = 0; i < reps; ++i) sink += h.log_likelihood(data[static_cast<std::size_t>(i % 100)]);
    fwd_ms = std::min(fwd_ms, std::chrono::duration<double, std::milli>(clock::now() - t1).count() / reps);
  }
  std::printf("{\"iterations\": %d, \"train_s\": %.4f, \"init_s\": %.4f, \"per_iteration_ms\": %.3f, "
              "\"per_iteration_incl_init_ms\": %.3f, \"forward_100_frames_ms\": %.4f, "
              "\"final_log_likelihood\": %.3f, \"checksum\": %.3f}\n",
              rep.iterations, train_s, init_s, 1000 * (train_s - init_s) / rep.iterations, 1000 * train_s / rep.iterations,
              fwd_ms, rep.log_likelihood.back(), sink);
  return 0;
}

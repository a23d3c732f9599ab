// The HMM core: forward, Viterbi and state posteriors against brute force
// over every path, covariances kept positive definite on degenerate data,
// emissions far from the origin against the Gaussians evaluated directly,
// no underflow on long sequences, streaming equals batch, Baum-Welch raises
// the likelihood and finds the generating model's states, save/load and
// malformed models; the same HMM over a categorical emission model.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <random>
#include <string>

#include <unistd.h>

#include <Eigen/Cholesky>
#include <Eigen/Eigenvalues>

#include "skelgraph/gesture/gaussian_mixture.hpp"

using namespace skelgraph::gesture;
using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

GaussianMixture gauss(std::vector<double> mean, double sd) {
  GaussianMixture g;
  const auto d = static_cast<Eigen::Index>(mean.size());
  g.weights = VectorXd::Ones(1);
  g.means = {Eigen::Map<VectorXd>(mean.data(), d)};
  g.covs = {MatrixXd::Identity(d, d) * sd * sd};
  return g;
}

// Three states in 2-D, a loop 0 -> 1 -> 2 -> 0.
GaussianHmm three_states() {
  GaussianHmm h;
  VectorXd start(3);
  start << 0.6, 0.3, 0.1;
  MatrixXd a(3, 3);
  a << 0.8, 0.15, 0.05, 0.05, 0.8, 0.15, 0.15, 0.05, 0.8;
  auto g2 = gauss({0, 3}, 0.7);
  g2.weights = VectorXd::Constant(2, 0.5);
  g2.means.push_back((VectorXd(2) << 0.5, 4).finished());
  g2.covs.push_back((MatrixXd(2, 2) << 0.4, 0.1, 0.1, 0.3).finished());
  h.set(start, a, GaussianMixtureEmission(2, Covariance::Full, {gauss({0, 0}, 0.5), gauss({3, 0}, 0.5), g2}));
  return h;
}

Sequence sample(const GaussianHmm& h, int T, std::mt19937_64& rng, std::vector<int>* states = nullptr) {
  const VectorXd start = h.start();
  const MatrixXd a = h.transitions();
  const auto draw = [&](const VectorXd& p) {
    double r = std::uniform_real_distribution<double>(0, 1)(rng);
    for (Eigen::Index i = 0; i < p.size(); ++i) {
      if ((r -= p(i)) <= 0) return static_cast<int>(i);
    }
    return static_cast<int>(p.size() - 1);
  };
  Sequence x(T, h.dim());
  int s = draw(start);
  std::normal_distribution<double> n(0, 1);
  for (int t = 0; t < T; ++t) {
    if (t > 0) s = draw(a.row(s).transpose());
    if (states) states->push_back(s);
    const auto& g = h.emission().mixtures()[static_cast<std::size_t>(s)];
    const int m = draw(g.weights);
    const Eigen::LLT<MatrixXd> llt(g.covs[static_cast<std::size_t>(m)]);
    VectorXd z(h.dim());
    for (int d = 0; d < h.dim(); ++d) z(d) = n(rng);
    x.row(t) = (g.means[static_cast<std::size_t>(m)] + MatrixXd(llt.matrixL()) * z).transpose();
  }
  return x;
}

}  // namespace

TEST(Hmm, ForwardAndViterbiMatchBruteForce) {
  const GaussianHmm h = three_states();
  std::mt19937_64 rng(1);
  const Sequence x = sample(h, 6, rng);
  const VectorXd start = h.start();
  const MatrixXd a = h.transitions();
  double total = 0, best = -1;
  std::vector<int> best_path, path(6);
  std::function<void(int, double)> walk = [&](int t, double p) {
    if (t == 6) {
      total += p;
      if (p > best) best = p, best_path = path;
      return;
    }
    for (int s = 0; s < 3; ++s) {
      path[static_cast<std::size_t>(t)] = s;
      const double e = std::exp(h.emission().mixtures()[static_cast<std::size_t>(s)].log_pdf(x.row(t).transpose()));
      walk(t + 1, p * (t == 0 ? start(s) : a(path[static_cast<std::size_t>(t - 1)], s)) * e);
    }
  };
  walk(0, 1.0);
  EXPECT_NEAR(h.log_likelihood(x), std::log(total), 1e-9);
  double lp = 0;
  EXPECT_EQ(h.viterbi(x, &lp), best_path);
  EXPECT_NEAR(lp, std::log(best), 1e-9);
  const MatrixXd post = h.posteriors(x);
  for (Eigen::Index t = 0; t < post.rows(); ++t) EXPECT_NEAR(post.row(t).sum(), 1.0, 1e-9);
}

// Posterior state probabilities against brute force: for every path of a
// tiny model, P(path, x) with each emission evaluated directly from its
// Gaussian formula; gamma[t][i] = sum of P(path, x) over paths in state i at
// t, over P(x). Overlapping emissions keep the posteriors away from 0 and 1.
TEST(Hmm, PosteriorsMatchBruteForce) {
  const auto normal = [](double x, double mu, double sd) {
    return std::exp(-0.5 * (x - mu) * (x - mu) / (sd * sd)) / std::sqrt(2 * M_PI * sd * sd);
  };
  struct Case {
    VectorXd start;
    MatrixXd a;
    std::vector<std::vector<std::array<double, 3>>> mix;  // per state: {weight, mean, sd} per component
    std::vector<double> x;
  };
  std::vector<Case> cases;
  {
    Case c;  // three states, one of them a two-component mixture
    c.start = (VectorXd(3) << 0.5, 0.3, 0.2).finished();
    c.a = (MatrixXd(3, 3) << 0.6, 0.3, 0.1, 0.2, 0.5, 0.3, 0.25, 0.15, 0.6).finished();
    c.mix = {{{1.0, 0.0, 1.0}}, {{1.0, 1.2, 0.8}}, {{0.4, 2.5, 0.6}, {0.6, -0.5, 1.5}}};
    c.x = {0.3, 1.7, -0.4, 2.9, 1.1};
    cases.push_back(c);
  }
  {
    Case c;  // two states, left-right (zeros in start and transitions), 4 frames
    c.start = (VectorXd(2) << 1.0, 0.0).finished();
    c.a = (MatrixXd(2, 2) << 0.7, 0.3, 0.0, 1.0).finished();
    c.mix = {{{1.0, 0.0, 1.0}}, {{1.0, 1.0, 1.3}}};
    c.x = {-0.2, 0.9, 0.4, 1.6};
    cases.push_back(c);
  }
  for (std::size_t k = 0; k < cases.size(); ++k) {
    const Case& c = cases[k];
    const int n = static_cast<int>(c.start.size());
    const int T = static_cast<int>(c.x.size());
    std::vector<GaussianMixture> em;
    for (const auto& comps : c.mix) {
      GaussianMixture g;
      g.weights.resize(static_cast<Eigen::Index>(comps.size()));
      for (std::size_t m = 0; m < comps.size(); ++m) {
        g.weights(static_cast<Eigen::Index>(m)) = comps[m][0];
        g.means.push_back(VectorXd::Constant(1, comps[m][1]));
        g.covs.push_back(MatrixXd::Constant(1, 1, comps[m][2] * comps[m][2]));
      }
      em.push_back(g);
    }
    GaussianHmm h;
    h.set(c.start, c.a, GaussianMixtureEmission(1, Covariance::Full, em));
    const auto emit = [&](int s, double x) {
      double p = 0;
      for (const auto& comp : c.mix[static_cast<std::size_t>(s)]) p += comp[0] * normal(x, comp[1], comp[2]);
      return p;
    };
    MatrixXd joint = MatrixXd::Zero(T, n);  // sum of P(path, x) over paths in state i at t
    double total = 0;
    std::vector<int> path(static_cast<std::size_t>(T));
    std::function<void(int, double)> walk = [&](int t, double p) {
      if (t == T) {
        total += p;
        for (int u = 0; u < T; ++u) joint(u, path[static_cast<std::size_t>(u)]) += p;
        return;
      }
      for (int s = 0; s < n; ++s) {
        path[static_cast<std::size_t>(t)] = s;
        const double step = t == 0 ? c.start(s) : c.a(path[static_cast<std::size_t>(t - 1)], s);
        walk(t + 1, p * step * emit(s, c.x[static_cast<std::size_t>(t)]));
      }
    };
    walk(0, 1.0);
    ASSERT_GT(total, 0);
    const MatrixXd want = joint / total;
    const Sequence x = Eigen::Map<const VectorXd>(c.x.data(), T);
    const MatrixXd got = h.posteriors(x);
    ASSERT_EQ(got.rows(), T);
    ASSERT_EQ(got.cols(), n);
    for (int t = 0; t < T; ++t) {
      for (int i = 0; i < n; ++i) EXPECT_NEAR(got(t, i), want(t, i), 1e-9) << "case " << k << ", t " << t << ", state " << i;
    }
    EXPECT_NEAR(h.log_likelihood(x), std::log(total), 1e-9) << "case " << k;
    // The control: the posteriors are neither the filtered (forward-only)
    // ones nor all near 0 or 1, so a wrong backward pass would show.
    const GaussianHmm::Pass fwd = h.pass(x, false);
    double differ = 0, spread = 0;
    for (int t = 0; t < T; ++t) {
      for (int i = 0; i < n; ++i) {
        differ = std::max(differ, std::abs(fwd.alpha(t, i) - want(t, i)));
        spread = std::max(spread, std::min(want(t, i), 1 - want(t, i)));
      }
    }
    EXPECT_GT(differ, 0.01) << "case " << k;
    EXPECT_GT(spread, 0.1) << "case " << k;
  }
}

// Degenerate training data: a feature constant over every frame (variance
// exactly 0) and two features exactly equal (a rank-deficient covariance).
// Regularisation must keep every covariance positive definite, full and
// diagonal, with mixtures and either initialisation, and the likelihoods
// finite. The control: the same training with regularisation 0 is refused.
TEST(Hmm, RegularisationKeepsDegenerateCovariancesPositiveDefinite) {
  std::mt19937_64 rng(12);
  std::normal_distribution<double> noise(0, 0.3);
  const auto sequence = [&](int T) {
    Sequence x(T, 4);
    for (int t = 0; t < T; ++t) {
      const double v = 2.0 * (3 * t / T) + noise(rng);  // three phases: around 0, 2, 4
      x.row(t) << v, 0.5, v, 0.1;                         // 0.5: its mean is exact, so the centred column is exactly 0
    }
    return x;
  };
  std::vector<Sequence> data;
  for (int i = 0; i < 20; ++i) data.push_back(sequence(30 + i % 5));
  const Sequence fresh = sequence(40);
  for (const auto cov : {Covariance::Full, Covariance::Diagonal}) {
    for (const int mixtures : {1, 2}) {
      for (const auto init : {Init::Segments, Init::KMeans}) {
        const std::string what = std::string(cov == Covariance::Full ? "full" : "diagonal") + ", " + std::to_string(mixtures) +
                                 " mixtures, " + (init == Init::KMeans ? "kmeans" : "segments");
        TrainOptions o;
        o.states = 3;
        o.mixtures = mixtures;
        o.covariance = cov;
        o.init = init;
        o.max_iterations = 30;
        GaussianHmm h;
        TrainReport rep;
        ASSERT_NO_THROW(h = GaussianHmm::train(data, o, &rep)) << what;
        ASSERT_FALSE(rep.log_likelihood.empty()) << what;
        for (const double ll : rep.log_likelihood) EXPECT_TRUE(std::isfinite(ll)) << what;
        for (const auto& g : h.emission().mixtures()) {
          for (const auto& s : g.covs) {
            ASSERT_EQ(s.rows(), 4);
            EXPECT_TRUE(s.allFinite()) << what;
            EXPECT_TRUE(s.isApprox(s.transpose())) << what;
            EXPECT_EQ(Eigen::LLT<MatrixXd>(s).info(), Eigen::Success) << what << "\n" << s;
            EXPECT_GT(Eigen::SelfAdjointEigenSolver<MatrixXd>(s).eigenvalues().minCoeff(), 0.0) << what << "\n" << s;
            if (cov == Covariance::Diagonal) {
              EXPECT_EQ(s(0, 2), 0.0) << what;
            }
          }
        }
        for (const auto& x : data) EXPECT_TRUE(std::isfinite(h.log_likelihood(x))) << what;
        EXPECT_TRUE(std::isfinite(h.log_likelihood(fresh))) << what;
        EXPECT_NO_THROW(h.posteriors(fresh)) << what;
        // A frame off by a hair (0.01) in a feature that never varied costs a
        // bounded amount, not the -1e12 a variance of 1e-15 would charge.
        Sequence nudged = fresh;
        nudged.col(1).array() += 0.01;
        EXPECT_GT(h.log_likelihood(nudged), h.log_likelihood(fresh) - 10.0 * static_cast<double>(fresh.rows())) << what;
        // The control: without regularisation the constant feature's variance is 0.
        o.regularisation = 0;
        EXPECT_THROW(GaussianHmm::train(data, o), ModelError) << what;
      }
    }
  }
}

// Two models compared by their scores (as a classifier compares its classes)
// trained on data with one extra feature that never varies: with a spread
// they share for it, the extra feature moves both scores by the same amount,
// so the difference between them is what it is without the feature. Each
// model's own mean spread instead would shift one against the other.
TEST(Hmm, AConstantFeatureShiftsNoModelAgainstAnotherWithASharedSpread) {
  std::mt19937_64 rng(5);
  const auto data_of = [&](double scale) {
    std::normal_distribution<double> noise(0, scale);
    std::vector<Sequence> d;
    for (int i = 0; i < 15; ++i) {
      Sequence x(40, 2);
      for (int t = 0; t < 40; ++t) x.row(t) << (t < 20 ? 0.0 : 1.0) + noise(rng), noise(rng);
      d.push_back(x);
    }
    return d;
  };
  const auto with_constant = [](std::vector<Sequence> d) {
    for (auto& x : d) {
      Sequence y(x.rows(), 3);
      y << x, Eigen::VectorXd::Constant(x.rows(), 0.5);
      x = y;
    }
    return d;
  };
  const auto a = data_of(0.1), b = data_of(0.6);  // the two models' features spread differently
  const Sequence test = data_of(0.3).front();
  Sequence test3(test.rows(), 3);
  test3 << test, Eigen::VectorXd::Constant(test.rows(), 0.5);
  TrainOptions o;
  o.states = 2;
  o.covariance = Covariance::Diagonal;
  const double gap = GaussianHmm::train(a, o).log_likelihood(test) - GaussianHmm::train(b, o).log_likelihood(test);
  TrainOptions shared = o;
  shared.constant_spread = Eigen::Vector3d(0.2, 0.2, 0.2);
  const double gap3 = GaussianHmm::train(with_constant(a), shared).log_likelihood(test3) -
                      GaussianHmm::train(with_constant(b), shared).log_likelihood(test3);
  EXPECT_NEAR(gap3, gap, 1e-6 * std::abs(gap));
  // The control: each model's own mean spread for the constant feature.
  const double own = GaussianHmm::train(with_constant(a), o).log_likelihood(test3) - GaussianHmm::train(with_constant(b), o).log_likelihood(test3);
  EXPECT_GT(std::abs(own - gap), 1.0);
  TrainOptions wrong = o;
  wrong.constant_spread = Eigen::Vector2d(0.2, 0.2);
  EXPECT_THROW(GaussianHmm::train(with_constant(a), wrong), ModelError);
}

TEST(Hmm, LongSequencesDoNotUnderflowAndStreamingMatches) {
  const GaussianHmm h = three_states();
  std::mt19937_64 rng(2);
  const Sequence x = sample(h, 20000, rng);
  const double ll = h.log_likelihood(x);
  EXPECT_TRUE(std::isfinite(ll));
  EXPECT_LT(ll, -20000);  // far below what a plain product of probabilities could hold
  GaussianHmm::Stream s(h);
  double streamed = 0;
  for (Eigen::Index t = 0; t < x.rows(); ++t) streamed = s.step(x.row(t).transpose());
  EXPECT_NEAR(streamed, ll, 1e-6 * std::abs(ll));
  EXPECT_EQ(h.viterbi(x).size(), 20000u);
}

TEST(Hmm, BaumWelchFindsTheGeneratingStates) {
  const GaussianHmm truth = three_states();
  std::mt19937_64 rng(3);
  std::vector<Sequence> data;
  for (int i = 0; i < 60; ++i) data.push_back(sample(truth, 40 + 5 * (i % 7), rng));  // different lengths
  TrainOptions o;
  o.states = 3;
  o.mixtures = 2;
  TrainReport rep;
  const GaussianHmm h = GaussianHmm::train(data, o, &rep);
  ASSERT_GE(rep.log_likelihood.size(), 3u);
  for (std::size_t i = 1; i < rep.log_likelihood.size(); ++i) {
    EXPECT_GE(rep.log_likelihood[i], rep.log_likelihood[i - 1] - 1e-6 * std::abs(rep.log_likelihood[i - 1])) << i;
  }
  EXPECT_TRUE(rep.converged);
  // Close to the generating model on fresh data (per frame).
  double ll_truth = 0, ll_fit = 0, frames = 0;
  for (int i = 0; i < 20; ++i) {
    const Sequence x = sample(truth, 60, rng);
    ll_truth += truth.log_likelihood(x);
    ll_fit += h.log_likelihood(x);
    frames += 60;
  }
  EXPECT_GT(ll_fit / frames, ll_truth / frames - 0.05);
  // Each true state's mean is near one learnt component.
  for (const auto& want : {VectorXd((VectorXd(2) << 0, 0).finished()), VectorXd((VectorXd(2) << 3, 0).finished())}) {
    double best = 1e9;
    for (const auto& g : h.emission().mixtures()) {
      for (const auto& m : g.means) best = std::min(best, (m - want).norm());
    }
    EXPECT_LT(best, 0.2);
  }
  // Deterministic with the seed.
  const GaussianHmm again = GaussianHmm::train(data, o);
  EXPECT_DOUBLE_EQ(again.log_likelihood(data[0]), h.log_likelihood(data[0]));
  // A left-right chain over k-means clusters (which come in no order) is refused.
  TrainOptions lrk = o;
  lrk.left_right = true;
  lrk.init = Init::KMeans;
  EXPECT_THROW(GaussianHmm::train(data, lrk), ModelError);
  // Diagonal covariances and a left-right topology train too.
  o.covariance = Covariance::Diagonal;
  o.left_right = true;
  const GaussianHmm lr = GaussianHmm::train(data, o);
  EXPECT_EQ(lr.transitions()(2, 0), 0.0);
  EXPECT_EQ(lr.emission().mixtures()[0].covs[0](0, 1), 0.0);
}

// States visited in no particular order: k-means initialisation puts a state
// on each cluster of frames, with uniform start and transitions, before any
// Baum-Welch iteration; cutting the sequences into equal parts would mix them.
TEST(Hmm, KMeansInitialisationStartsAStateOnEachCluster) {
  GaussianHmm truth = three_states();
  MatrixXd uniform = MatrixXd::Constant(3, 3, 1.0 / 3);
  truth.set(VectorXd::Constant(3, 1.0 / 3), uniform,
            GaussianMixtureEmission(2, Covariance::Full, {gauss({0, 0}, 0.3), gauss({4, 0}, 0.3), gauss({0, 4}, 0.3)}));
  std::mt19937_64 rng(5);
  std::vector<Sequence> data;
  for (int i = 0; i < 30; ++i) data.push_back(sample(truth, 50, rng));
  TrainOptions o;
  o.states = 3;
  o.covariance = Covariance::Diagonal;
  o.max_iterations = 0;  // the initial model itself
  const auto nearest = [](const GaussianHmm& h, const VectorXd& want) {
    double best = 1e9;
    for (const auto& g : h.emission().mixtures()) best = std::min(best, (g.means[0] - want).norm());
    return best;
  };
  const std::vector<VectorXd> centres = {(VectorXd(2) << 0, 0).finished(), (VectorXd(2) << 4, 0).finished(),
                                         (VectorXd(2) << 0, 4).finished()};
  o.init = Init::KMeans;
  const GaussianHmm k = GaussianHmm::train(data, o);
  for (const auto& c : centres) EXPECT_LT(nearest(k, c), 0.1);
  EXPECT_NEAR(k.transitions()(0, 1), 1.0 / 3, 1e-12);
  EXPECT_NEAR(k.start()(2), 1.0 / 3, 1e-12);
  o.init = Init::Segments;
  const GaussianHmm seg = GaussianHmm::train(data, o);
  double worst = 0;
  for (const auto& c : centres) worst = std::max(worst, nearest(seg, c));
  EXPECT_GT(worst, 1.0);  // the control: equal parts of shuffled states start on mixtures of them
}

// restarts = R keeps, of R trainings from different seeds, the one with the
// highest final training likelihood.
TEST(Hmm, RestartsKeepTheBestFit) {
  const GaussianHmm truth = three_states();
  std::mt19937_64 rng(11);
  std::vector<Sequence> data;
  for (int i = 0; i < 20; ++i) data.push_back(sample(truth, 30 + 3 * i, rng));
  TrainOptions o;
  o.states = 4;
  o.init = Init::KMeans;
  o.seed = 8;
  o.restarts = 5;
  TrainReport best;
  const GaussianHmm h = GaussianHmm::train(data, o, &best);
  std::vector<double> finals;
  for (int r = 0; r < 5; ++r) {
    TrainOptions one = o;
    one.restarts = 1;
    one.seed = o.seed + 0x9E3779B97F4A7C15ULL * static_cast<std::uint64_t>(r);
    TrainReport rep;
    GaussianHmm::train(data, one, &rep);
    finals.push_back(rep.log_likelihood.back());
  }
  const double top = *std::max_element(finals.begin(), finals.end());
  EXPECT_DOUBLE_EQ(best.log_likelihood.back(), top);
  EXPECT_GT(top, *std::min_element(finals.begin(), finals.end()));  // the seeds do differ, so the choice matters
  EXPECT_LT(finals[0], top);  // and keeping the first training would not be the best
  double total = 0;
  for (const auto& x : data) total += h.log_likelihood(x);
  EXPECT_NEAR(total, top, 1e-6 * std::abs(top));
}

// The forward pass in log space, each emission straight from its Gaussians
// (Cholesky factors), none of the batched quadratic-feature arithmetic.
double log_space_forward(const GaussianHmm& h, const Sequence& x) {
  const auto n = h.states();
  const MatrixXd log_a = h.transitions().array().log().matrix();
  VectorXd alpha = h.start().array().log().matrix(), next(n);
  for (Eigen::Index t = 0; t < x.rows(); ++t) {
    for (int j = 0; j < n; ++j) {
      const double e = h.emission().mixtures()[static_cast<std::size_t>(j)].log_pdf(x.row(t).transpose());
      next(j) = e + (t == 0 ? alpha(j) : log_sum_exp(alpha + log_a.col(j)));
    }
    alpha = next;
  }
  return log_sum_exp(alpha);
}

TEST(Hmm, FramesFarFromTheOriginKeepTheirPrecision) {
  // Narrow Gaussians 1000 units from the origin: expanding (x - mu)' P (x - mu)
  // about the origin would cancel away most of the digits.
  for (const auto cov : {Covariance::Full, Covariance::Diagonal}) {
    GaussianHmm h = three_states();
    VectorXd start = h.start();
    std::vector<GaussianMixture> em = h.emission().mixtures();
    for (auto& g : em) {
      for (std::size_t m = 0; m < g.means.size(); ++m) {
        g.means[m].array() += 1000.0;
        g.covs[m] *= 0.01;
        if (cov == Covariance::Diagonal) g.covs[m] = MatrixXd(g.covs[m].diagonal().asDiagonal());
      }
    }
    GaussianHmm far;
    far.set(start, h.transitions(), GaussianMixtureEmission(2, cov, em));
    std::mt19937_64 rng(7);
    for (int i = 0; i < 5; ++i) {
      const Sequence x = sample(far, 50, rng);
      const double want = log_space_forward(far, x);
      EXPECT_NEAR(far.log_likelihood(x), want, 1e-9 * std::abs(want));
    }
  }
  // Training on data moved by 1000 finds the same model, moved.
  const GaussianHmm truth = three_states();
  std::mt19937_64 rng(8);
  std::vector<Sequence> near, moved;
  for (int i = 0; i < 30; ++i) {
    near.push_back(sample(truth, 40, rng));
    moved.push_back(near.back().array() + 1000.0);
  }
  TrainOptions o;
  o.states = 3;
  o.mixtures = 2;
  o.max_iterations = 20;
  const GaussianHmm a = GaussianHmm::train(near, o), b = GaussianHmm::train(moved, o);
  for (std::size_t i = 0; i < 5; ++i) {
    EXPECT_NEAR(b.log_likelihood(moved[i]), a.log_likelihood(near[i]), 1e-6 * std::abs(a.log_likelihood(near[i])));
  }
}

TEST(Hmm, SaveLoadAndMalformedModels) {
  const GaussianHmm h = three_states();
  const auto j = h.to_json();
  const GaussianHmm back = GaussianHmm::from_json(nlohmann::json::parse(j.dump()));
  std::mt19937_64 rng(4);
  const Sequence x = sample(h, 50, rng);
  EXPECT_NEAR(back.log_likelihood(x), h.log_likelihood(x), 1e-9);
  const auto error_of = [](nlohmann::json m) {
    try {
      GaussianHmm::from_json(m);
    } catch (const ModelError& e) {
      return std::string(e.what());
    }
    return std::string("(no error)");
  };
  auto bad = j;
  bad["version"] = 7;
  EXPECT_NE(error_of(bad).find("version 7 is not supported"), std::string::npos);
  bad = j;
  bad.erase("transitions");
  EXPECT_NE(error_of(bad).find("missing 'transitions'"), std::string::npos);
  bad = j;
  bad["transitions"][1][0] = 0.5;
  EXPECT_NE(error_of(bad).find("'transitions' row 1 sums to"), std::string::npos);
  bad = j;
  bad["emissions"][2]["covariances"][1] = {{1.0, 2.0}, {2.0, 1.0}};
  EXPECT_NE(error_of(bad).find("not positive definite"), std::string::npos);
  bad = j;
  bad["format"] = "other";
  EXPECT_NE(error_of(bad).find("not a skelgraph HMM"), std::string::npos);
  // Training input problems are clear too.
  TrainOptions o;
  EXPECT_THROW(GaussianHmm::train({}, o), ModelError);
  EXPECT_THROW(GaussianHmm::train({MatrixXd::Zero(5, 2), MatrixXd::Zero(5, 3)}, o), ModelError);
  EXPECT_THROW(h.log_likelihood(MatrixXd::Zero(4, 3)), ModelError);
}

// --- Another emission model: Hmm<> over categorical emissions ---

namespace {

// One categorical distribution per state over a single feature whose values
// are the symbols 0..K-1 (any other value is impossible): an emission model
// written here, to show Hmm<> takes any that meets hmm.hpp's requirements.
class Categorical {
 public:
  struct Workspace {};
  class Trainer;

  Categorical() = default;
  explicit Categorical(MatrixXd p) : p_(std::move(p)), log_p_(p_.array().log().matrix()) {}  // N x K, rows sum to 1
  int states() const { return static_cast<int>(p_.rows()); }
  int dim() const { return 1; }
  const MatrixXd& p() const { return p_; }

  void log_probabilities(const Sequence& x, Workspace&, Eigen::Ref<Rows> logb) const {
    for (Eigen::Index t = 0; t < x.rows(); ++t) logb.row(t) = log_p(x(t, 0)).transpose();
  }
  void log_probabilities(const VectorXd& x, Eigen::Ref<VectorXd> logb) const { logb = log_p(x(0)); }

  void to_json(nlohmann::json& model) const {
    nlohmann::json rows = nlohmann::json::array();
    for (Eigen::Index j = 0; j < p_.rows(); ++j) {
      const VectorXd row = p_.row(j).transpose();
      rows.push_back(std::vector<double>(row.data(), row.data() + row.size()));
    }
    model["categorical"] = rows;
  }
  static Categorical from_json(const nlohmann::json& model, int states, int dim) {
    const auto& rows = model.at("categorical");
    if (dim != 1 || static_cast<int>(rows.size()) != states) throw ModelError("categorical: one feature, a row per state");
    MatrixXd p(states, static_cast<Eigen::Index>(rows.at(0).size()));
    for (int j = 0; j < states; ++j) {
      const auto row = rows.at(static_cast<std::size_t>(j)).get<std::vector<double>>();
      p.row(j) = Eigen::Map<const Eigen::RowVectorXd>(row.data(), static_cast<Eigen::Index>(row.size()));
    }
    return Categorical(p);
  }

 private:
  VectorXd log_p(double v) const {
    const auto k = static_cast<Eigen::Index>(v);
    if (static_cast<double>(k) != v || k < 0 || k >= p_.cols()) return VectorXd::Constant(p_.rows(), -INFINITY);
    return log_p_.col(k);
  }
  MatrixXd p_, log_p_;
};

// Add-one counts per state for the first emissions, expected counts (sums of
// posteriors) for each next.
class Categorical::Trainer {
 public:
  Trainer(const std::vector<Sequence>& data, const TrainOptions& o) : N_(o.states) {
    for (const auto& x : data) {
      first_.push_back(static_cast<Eigen::Index>(symbols_.size()));
      for (Eigen::Index t = 0; t < x.rows(); ++t) {
        if (x(t, 0) != std::floor(x(t, 0)) || x(t, 0) < 0) throw ModelError("categorical: symbols are 0, 1, 2, ...");
        symbols_.push_back(static_cast<Eigen::Index>(x(t, 0)));
      }
    }
    counts_ = MatrixXd::Zero(N_, *std::max_element(symbols_.begin(), symbols_.end()) + 1);
  }
  Categorical initialise(const std::vector<int>& state, std::mt19937_64&) {
    MatrixXd c = MatrixXd::Ones(N_, counts_.cols());
    for (std::size_t f = 0; f < symbols_.size(); ++f) c(state[f], symbols_[f]) += 1;
    return Categorical(c.array().colwise() / c.rowwise().sum().array());
  }
  const Rows& log_probabilities(const Categorical& e) {
    logb_.resize(static_cast<Eigen::Index>(symbols_.size()), N_);
    for (std::size_t f = 0; f < symbols_.size(); ++f) logb_.row(static_cast<Eigen::Index>(f)) = e.log_p_.col(symbols_[f]).transpose();
    return logb_;
  }
  void accumulate(std::size_t s, const Eigen::Ref<const Rows>& gamma) {
    for (Eigen::Index t = 0; t < gamma.rows(); ++t) {
      counts_.col(symbols_[static_cast<std::size_t>(first_[s] + t)]) += gamma.row(t).transpose();
    }
  }
  Categorical finish(const Categorical& e, std::mt19937_64&) {
    MatrixXd p = e.p();
    for (int j = 0; j < N_; ++j) {
      if (counts_.row(j).sum() > 0) p.row(j) = counts_.row(j) / counts_.row(j).sum();  // else as it was
    }
    counts_.setZero();
    return Categorical(p);
  }

 private:
  const int N_;
  std::vector<Eigen::Index> symbols_, first_;
  MatrixXd counts_;
  Rows logb_;
};

static_assert(is_emission_v<Categorical> && is_emission_v<GaussianMixtureEmission>);
static_assert(!is_emission_v<GaussianMixture> && !is_emission_v<Eigen::MatrixXd>);

}  // namespace

// A known two-state categorical model: forward, Viterbi, posteriors and the
// streaming step against brute force over every path of a short sequence;
// Baum-Welch on samples of it finds it again; save and load.
TEST(Hmm, ACategoricalEmissionPlugsIn) {
  VectorXd start(2);
  start << 0.7, 0.3;
  MatrixXd a(2, 2), p(2, 3);
  a << 0.9, 0.1, 0.2, 0.8;
  p << 0.7, 0.2, 0.1, 0.1, 0.3, 0.6;
  Hmm<Categorical> truth;
  truth.set(start, a, Categorical(p));
  Sequence x(7, 1);
  x << 0, 2, 2, 1, 0, 2, 1;
  double total = 0, best = -1;
  MatrixXd joint = MatrixXd::Zero(7, 2);
  std::vector<int> path(7), best_path;
  std::function<void(int, double)> walk = [&](int t, double pr) {
    if (t == 7) {
      total += pr;
      if (pr > best) best = pr, best_path = path;
      for (int u = 0; u < 7; ++u) joint(u, path[static_cast<std::size_t>(u)]) += pr;
      return;
    }
    for (int s = 0; s < 2; ++s) {
      path[static_cast<std::size_t>(t)] = s;
      const double step = t == 0 ? start(s) : a(path[static_cast<std::size_t>(t - 1)], s);
      walk(t + 1, pr * step * p(s, static_cast<Eigen::Index>(x(t, 0))));
    }
  };
  walk(0, 1.0);
  EXPECT_NEAR(truth.log_likelihood(x), std::log(total), 1e-12);
  double lp = 0;
  EXPECT_EQ(truth.viterbi(x, &lp), best_path);
  EXPECT_NEAR(lp, std::log(best), 1e-12);
  EXPECT_LT((truth.posteriors(x) - joint / total).cwiseAbs().maxCoeff(), 1e-12);
  Hmm<Categorical>::Stream stream(truth);
  double streamed = 0;
  for (Eigen::Index t = 0; t < x.rows(); ++t) streamed = stream.step(x.row(t).transpose());
  EXPECT_NEAR(streamed, std::log(total), 1e-12);
  Sequence impossible = x;
  impossible(3, 0) = 5;
  EXPECT_EQ(truth.log_likelihood(impossible), -INFINITY);

  // Training from samples finds the model again (states in either order).
  std::mt19937_64 rng(21);
  const auto draw = [&](const VectorXd& pr) {
    double r = std::uniform_real_distribution<double>(0, 1)(rng);
    for (Eigen::Index i = 0; i + 1 < pr.size(); ++i) {
      if ((r -= pr(i)) <= 0) return static_cast<int>(i);
    }
    return static_cast<int>(pr.size() - 1);
  };
  std::vector<Sequence> data;
  for (int i = 0; i < 200; ++i) {
    Sequence y(60, 1);
    int s = draw(start);
    for (int t = 0; t < 60; ++t) {
      if (t > 0) s = draw(a.row(s).transpose());
      y(t, 0) = draw(p.row(s).transpose());
    }
    data.push_back(y);
  }
  TrainOptions o;
  o.states = 2;
  o.init = Init::KMeans;
  o.tolerance = 1e-9;
  o.max_iterations = 500;
  TrainReport rep;
  const auto h = Hmm<Categorical>::train(data, o, &rep);
  EXPECT_TRUE(rep.converged);
  for (std::size_t i = 1; i < rep.log_likelihood.size(); ++i) {
    EXPECT_GE(rep.log_likelihood[i], rep.log_likelihood[i - 1] - 1e-9 * std::abs(rep.log_likelihood[i - 1])) << i;
  }
  const int first = h.emission().p()(0, 0) > h.emission().p()(1, 0) ? 0 : 1;  // the state that mostly emits 0
  const std::array<int, 2> order{first, 1 - first};
  for (int i = 0; i < 2; ++i) {
    EXPECT_NEAR(h.start()(order[i]), start(i), 0.1) << i;
    for (int j = 0; j < 2; ++j) EXPECT_NEAR(h.transitions()(order[i], order[j]), a(i, j), 0.03) << i << j;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(h.emission().p()(order[i], k), p(i, k), 0.03) << i << k;
  }
  double ll_truth = 0, ll_fit = 0;
  for (const auto& y : data) ll_truth += truth.log_likelihood(y), ll_fit += h.log_likelihood(y);
  EXPECT_NEAR(ll_fit, rep.log_likelihood.back(), 1e-9 * std::abs(ll_fit));
  EXPECT_GE(ll_fit, ll_truth);  // the maximum likelihood fit of this very data

  const auto back = Hmm<Categorical>::from_json(nlohmann::json::parse(h.to_json().dump()));
  EXPECT_EQ(back.to_json(), h.to_json());
  EXPECT_DOUBLE_EQ(back.log_likelihood(x), h.log_likelihood(x));
}

// --- Peer check: pomegranate (an independent implementation) on the same model ---

#include <cstdlib>
#include <filesystem>
#include <fstream>

TEST(HmmPeer, PomegranateAgreesOnLikelihoodAndViterbi) {
  const auto dir = std::filesystem::temp_directory_path() / ("skelgraph_hmm_peer_" + std::to_string(::getpid()));
  std::filesystem::create_directories(dir);
  for (const auto cov : {Covariance::Full, Covariance::Diagonal}) {
    GaussianHmm h = three_states();
    if (cov == Covariance::Diagonal) {
      // The same model with diagonal covariances, trained so the numbers are not round.
      std::mt19937_64 rng(5);
      std::vector<Sequence> data;
      for (int i = 0; i < 30; ++i) data.push_back(sample(h, 50, rng));
      TrainOptions o;
      o.states = 3;
      o.mixtures = 2;
      o.covariance = Covariance::Diagonal;
      h = GaussianHmm::train(data, o);
    }
    std::mt19937_64 rng(6);
    nlohmann::json in{{"model", h.to_json()}, {"sequences", nlohmann::json::array()}};
    std::vector<Sequence> seqs;
    for (int T : {5, 20, 60, 200}) {
      seqs.push_back(sample(h, T, rng));
      nlohmann::json rows = nlohmann::json::array();
      for (Eigen::Index t = 0; t < T; ++t) rows.push_back({seqs.back()(t, 0), seqs.back()(t, 1)});
      in["sequences"].push_back(rows);
    }
    std::ofstream(dir / "in.json") << in.dump();
    const std::string cmd = "/usr/bin/python3 " + std::string(SKELGRAPH_SOURCE_DIR) + "/tests/support/pomegranate_peer.py " +
                            (dir / "in.json").string() + " " + (dir / "out.json").string();
    ASSERT_EQ(std::system(cmd.c_str()), 0) << cmd << " (needs Debian's python3-pomegranate; tools/run installs it)";
    const auto out = nlohmann::json::parse(std::ifstream(dir / "out.json"));
    for (std::size_t i = 0; i < seqs.size(); ++i) {
      const double ours = h.log_likelihood(seqs[i]), theirs = out["log_probability"][i].get<double>();
      EXPECT_NEAR(ours, theirs, 1e-6 * std::abs(theirs)) << "sequence " << i;
      double vlp = 0;
      EXPECT_EQ(h.viterbi(seqs[i], &vlp), out["viterbi"][i].get<std::vector<int>>()) << "sequence " << i;
      EXPECT_NEAR(vlp, out["viterbi_log_probability"][i].get<double>(), 1e-6 * std::abs(vlp)) << "sequence " << i;
    }
  }
  std::filesystem::remove_all(dir);
}

// --- Arm features ---

#include "skelgraph/gesture/features.hpp"

namespace {
using skelgraph::skeleton::JointId;
using skelgraph::skeleton::Skeleton;

// Shoulders at y 1.4, the right arm's elbow and hand where given, left arm hanging.
Skeleton pose(const Eigen::Vector3d& r_elbow, const Eigen::Vector3d& r_hand, std::int64_t t_ns) {
  Skeleton s;
  s.stamp_ns = t_ns;
  for (auto& j : s.joints) j.confidence = skelgraph::skeleton::kTracked;
  s[JointId::LeftShoulder].position = {0.2, 1.4, 2};
  s[JointId::LeftElbow].position = {0.2, 1.1, 2};
  s[JointId::LeftHand].position = {0.2, 0.8, 2};
  s[JointId::RightShoulder].position = {-0.2, 1.4, 2};
  s[JointId::RightElbow].position = r_elbow;
  s[JointId::RightHand].position = r_hand;
  return s;
}
}  // namespace

TEST(Features, AnglesToTheVerticalAndSpeedsOverTheRealInterval) {
  EXPECT_EQ(feature_names(FeatureSet::Thesis8).size(), 8u);
  EXPECT_EQ(feature_names(FeatureSet::Extended).size(), 16u);
  EXPECT_EQ(feature_names(FeatureSet::Thesis8)[2], "right_upper_arm_angle");
  FeatureStream fs;
  // Right arm pointing straight forward (horizontal), left arm hanging.
  auto x = fs.step(pose({-0.2, 1.4, 1.7}, {-0.2, 1.4, 1.4}, 0));
  EXPECT_NEAR(x(0), M_PI, 1e-9);      // left upper arm down
  EXPECT_NEAR(x(1), M_PI, 1e-9);      // left forearm down
  EXPECT_NEAR(x(2), M_PI / 2, 1e-9);  // right upper arm horizontal
  EXPECT_NEAR(x(3), M_PI / 2, 1e-9);
  EXPECT_EQ(x.tail(4), Eigen::VectorXd::Zero(4));  // no speed on the first frame
  // 50 ms later the right forearm points 0.1 rad higher: 2 rad/s.
  const Eigen::Vector3d e(-0.2, 1.4, 1.7);
  x = fs.step(pose(e, e + 0.3 * Eigen::Vector3d(0, std::sin(0.1), -std::cos(0.1)), 50'000'000));
  EXPECT_NEAR(x(3), M_PI / 2 - 0.1, 1e-9);
  EXPECT_NEAR(x(7), 2.0, 1e-6);
  EXPECT_NEAR(x(6), 0.0, 1e-9);
  // 1 ms later another 0.1 rad: the interval counts as min_interval (20 ms), so 5 rad/s, not 100.
  x = fs.step(pose(e, e + 0.3 * Eigen::Vector3d(0, std::sin(0.2), -std::cos(0.2)), 51'000'000));
  EXPECT_NEAR(x(7), 5.0, 1e-6);
}

TEST(Features, MissingJointsAreHeldAndMarked) {
  const Eigen::Vector3d e(-0.2, 1.4, 1.7), h(-0.2, 1.4, 1.4);
  std::vector<Skeleton> clip{pose(e, h, 0), pose(e, h, 33'000'000), pose(e, h, 66'000'000)};
  clip[0][JointId::RightHand].confidence = skelgraph::skeleton::kInferred;  // before the first good value
  clip[2][JointId::RightHand].confidence = skelgraph::skeleton::kInferred;  // after
  clip[2][JointId::RightHand].position = {5, 5, 5};                         // ignored
  const auto f = features_of(clip);
  EXPECT_EQ(f.complete, (std::vector<bool>{false, true, false}));
  EXPECT_NEAR(f.x(0, 3), M_PI / 2, 1e-9);  // took the first good value
  EXPECT_NEAR(f.x(2, 3), M_PI / 2, 1e-9);  // held
  EXPECT_EQ(f.x(2, 7), 0.0);               // a held angle does not move
  // Extended: elbow bend 0 (straight arm), hand at shoulder height.
  FeatureOptions o;
  o.set = FeatureSet::Extended;
  const auto g = features_of({pose(e, h, 0)}, o);
  EXPECT_EQ(g.x.cols(), 16);
  EXPECT_NEAR(g.x(0, 6), 0.0, 1e-6);   // right elbow bend
  EXPECT_NEAR(g.x(0, 7), 0.0, 1e-9);   // right hand height in upper-arm lengths
  EXPECT_NEAR(g.x(0, 5), -2.0, 1e-9);  // left hand 0.6 m below the shoulder, upper arm 0.3 m
}

TEST(Features, HandsUseTheWristsWhenGiven) {
  const auto names = feature_names(FeatureSet::Hands);
  ASSERT_EQ(names.size(), 16u);  // per arm 2 angles + forearm out, per arm 2 hand values, speeds of the first 6
  EXPECT_EQ(names[2], "left_forearm_out");
  EXPECT_EQ(names[3], "right_upper_arm_angle");
  EXPECT_EQ(names[6], "left_hand_angle");
  EXPECT_EQ(names[9], "right_hand_length");
  EXPECT_EQ(names[15], "right_forearm_out_speed");
  EXPECT_TRUE(needs_wrists(FeatureSet::Hands));
  EXPECT_FALSE(needs_wrists(FeatureSet::Extended));
  // Right arm forward with the palm raised (the hand segment points up), left arm hanging.
  const Eigen::Vector3d e(-0.2, 1.4, 1.7), h(-0.2, 1.5, 1.45);
  Wrists w;
  w.right = {-0.2, 1.4, 1.45};  // forearm 0.25 m, hand segment 0.1 m straight up
  w.left = {0.2, 0.95, 2};      // forearm 0.15 m, hand segment 0.15 m down
  FeatureOptions o;
  o.set = FeatureSet::Hands;
  const std::vector<Wrists> wrists{w};
  const auto f = features_of({pose(e, h, 0)}, o, &wrists);
  EXPECT_EQ(f.complete, std::vector<bool>{true});
  EXPECT_NEAR(f.x(0, 6), M_PI, 1e-9);     // left hand segment down
  EXPECT_NEAR(f.x(0, 7), 1.0, 1e-9);      // as long as the left forearm
  EXPECT_NEAR(f.x(0, 8), 0.0, 1e-9);      // right hand segment straight up
  EXPECT_NEAR(f.x(0, 9), 0.4, 1e-9);      // 0.1 / 0.25
  EXPECT_NEAR(f.x(0, 3), M_PI / 2, 1e-9);  // the thesis angles as in thesis8
  EXPECT_NEAR(f.x(0, 5), 0.0, 1e-9);      // right forearm neither out nor across
  // Forearm out to the right side (the right shoulder is at -x here), then across the body.
  const std::vector<Wrists> two{w, w};
  const auto g = features_of({pose(e, e + Eigen::Vector3d(-0.3, 0, 0), 0), pose(e, e + Eigen::Vector3d(0.3, 0, 0), 100'000'000)}, o, &two);
  EXPECT_NEAR(g.x(0, 5), 1.0, 1e-9);
  EXPECT_NEAR(g.x(1, 5), -1.0, 1e-9);
  EXPECT_NEAR(g.x(1, 15), 20.0, 1e-6);  // |-1 - 1| over 0.1 s
  // Without wrists the hand values are missing: held (0 before any) and the frame incomplete.
  const auto n = features_of({pose(e, h, 0)}, o);
  EXPECT_EQ(n.complete, std::vector<bool>{false});
  EXPECT_EQ(n.x(0, 8), 0.0);
  EXPECT_THROW(features_of({pose(e, h, 0), pose(e, h, 1)}, o, &wrists), std::invalid_argument);  // one wrist per frame
}

TEST(Features, ArmModelsSeeTheActiveArmAndItsHand) {
  const auto names = feature_names(FeatureSet::Arm);
  ASSERT_EQ(names.size(), 16u);  // per arm 2 angles + forearm out, per arm hand forward + sway, speeds of the first 6
  EXPECT_EQ(names[6], "left_hand_forward");
  EXPECT_EQ(names[9], "right_hand_sway");
  EXPECT_TRUE(needs_wrists(FeatureSet::Arm));
  EXPECT_TRUE(one_arm(FeatureSet::Arm));
  EXPECT_FALSE(one_arm(FeatureSet::Hands));
  // The right arm held forward (+z is forward for this pose's shoulders), the hand segment 0.1 m further on.
  const Eigen::Vector3d e(-0.2, 1.4, 2.3), h(-0.2, 1.4, 2.65);
  Wrists w;
  w.right = {-0.2, 1.4, 2.55};  // upper arm 0.3 m + forearm 0.25 m
  w.left = {0.2, 0.95, 2};
  FeatureOptions o;
  o.set = FeatureSet::Arm;
  // A hand waved from the wrist: the segment turns out, in, out, ... every
  // frame for a second; then held out; in the last frame it points forward.
  std::vector<Skeleton> frames;
  std::vector<Wrists> wrists;
  for (int i = 0; i < 60; ++i) {
    const double side = i < 30 && i % 2 ? 0.1 : -0.1;  // out is -x on the right
    frames.push_back(pose(e, w.right + Eigen::Vector3d(side, 0, 0), i * 33'333'333LL));
    wrists.push_back(w);
  }
  frames.back() = pose(e, h, 59 * 33'333'333LL);
  const auto f = features_of(frames, o, &wrists);
  EXPECT_NEAR(f.x(59, 8), 0.1 / 0.55, 1e-9);  // right hand forward, in arm lengths
  EXPECT_NEAR(f.x(0, 9), 0.0, 1e-12);          // sway: one frame has no spread
  EXPECT_NEAR(f.x(29, 9), 1.0, 0.05);          // +-1 in turn over the last 0.5 s
  EXPECT_NEAR(f.x(58, 9), 0.0, 1e-9);          // still (hand out, -x) for the last 0.5 s
  EXPECT_GT(f.x(59, 9), 0.1);                  // the last frame turns it forward: spread again
  // The model sees the right arm only.
  const Sequence v = model_view(f.x, FeatureSet::Arm);
  ASSERT_EQ(v.cols(), 8);
  EXPECT_EQ(v(59, 3), f.x(59, 8));  // right_upper_arm_angle, forearm_angle, forearm_out, hand_forward, ...
  EXPECT_EQ(model_view(f.x, FeatureSet::Hands).cols(), 16);
}

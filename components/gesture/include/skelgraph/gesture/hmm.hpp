#pragma once
// Continuous hidden Markov models with Gaussian-mixture emissions (full or
// diagonal covariances), with no underflow on any length: forward log-likelihood,
// Viterbi path, state posteriors, a streaming forward step for live use, and
// Baum-Welch training over many sequences of different lengths. Eigen only;
// models save to and load from versioned JSON.

#include <cstdint>
#include <stdexcept>
#include <string>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace skelgraph::gesture {

// One observation per row: T x D.
using Sequence = Eigen::MatrixXd;

// Bad model file or bad training input; the message says what and where.
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class Covariance { Full, Diagonal };

// How training picks its first parameters. Segments: each sequence cut into N
// equal parts, state j from the j-th part of every sequence (suits gestures,
// which pass through their phases in order). KMeans: k-means++ over all frames
// pooled, a state per cluster, uniform start and transitions (pomegranate's
// from_samples; depends more on the seed).
enum class Init { Segments, KMeans };

struct GaussianMixture {
  Eigen::VectorXd weights;               // M, sum 1
  std::vector<Eigen::VectorXd> means;    // M x D
  std::vector<Eigen::MatrixXd> covs;     // M x (D x D); diagonal models keep zeros off the diagonal
  // Cached for log_pdf: inverse Cholesky factors and log normalisers.
  void prepare();
  double log_pdf(const Eigen::VectorXd& x) const;                      // log sum_m w_m N(x; mu_m, S_m)
  void log_pdf_components(const Eigen::VectorXd& x, Eigen::VectorXd& out) const;  // log w_m + log N_m
  // After prepare(): component m's inverse covariance and log w_m + its log normaliser.
  Eigen::MatrixXd precision(std::size_t m) const { return inv_l_[m].transpose() * inv_l_[m]; }
  double log_norm(std::size_t m) const { return log_norm_(static_cast<Eigen::Index>(m)); }

 private:
  std::vector<Eigen::MatrixXd> inv_l_;  // L^-1 with S = L L^T
  Eigen::VectorXd log_norm_;
};

struct TrainOptions {
  int states = 7;
  int mixtures = 1;
  Covariance covariance = Covariance::Full;
  bool left_right = false;      // transitions only to the same or the next state
  Init init = Init::Segments;
  int restarts = 1;             // train this many times from different seeds, keep the highest training likelihood
  int max_iterations = 100;
  double tolerance = 1e-4;      // stop when the mean log-likelihood per frame improves less than this
  double regularisation = 1e-3;  // added to covariance diagonals, times each dimension's variance over all data
  // The spread a dimension that never varies in this model's data takes
  // instead (regularisation and initial covariance). Empty: the mean over the
  // model's other dimensions. Models whose scores are compared (a classifier's)
  // should share one, so a feature constant everywhere shifts none against another.
  Eigen::VectorXd constant_spread;
  std::uint64_t seed = 1;
};

// Each feature's variance over every frame of `data` (the features' means in
// `mean` if given). A feature that never varies (a joint a recording lacks,
// filled with a constant) has no spread of its own: it gets `constant(d)` if
// given, else the mean variance of the features that do vary (1 if none does).
Eigen::VectorXd feature_spread(const std::vector<const Sequence*>& data, const Eigen::VectorXd& constant = {},
                               Eigen::VectorXd* mean = nullptr);

struct TrainReport {
  int iterations = 0;
  bool converged = false;
  std::vector<double> log_likelihood;  // total over the sequences, after initialisation and after each iteration
};

class BaumWelch;

class Hmm {
 public:
  Hmm() = default;
  Hmm(int states, int dim, Covariance covariance);

  int states() const { return static_cast<int>(log_start_.size()); }
  int dim() const { return dim_; }
  Covariance covariance() const { return covariance_; }

  // Parameters (probabilities, not logs), checked: rows sum to 1, weights
  // sum to 1, covariances symmetric positive definite. Throws ModelError.
  void set(const Eigen::VectorXd& start, const Eigen::MatrixXd& transitions, std::vector<GaussianMixture> emissions);
  Eigen::VectorXd start() const;
  Eigen::MatrixXd transitions() const;
  const std::vector<GaussianMixture>& emissions() const { return emissions_; }

  double log_likelihood(const Sequence& x) const;               // forward; -inf for an impossible sequence
  std::vector<int> viterbi(const Sequence& x, double* log_prob = nullptr) const;
  Eigen::MatrixXd posteriors(const Sequence& x) const;          // T x N, each row sums to 1

  // Baum-Welch (hmm.cpp's BaumWelch: initialisation, then expectation and
  // maximisation until the gain per frame falls below the tolerance).
  static Hmm train(const std::vector<Sequence>& data, const TrainOptions& options, TrainReport* report = nullptr);

  nlohmann::json to_json() const;
  static Hmm from_json(const nlohmann::json& j);  // throws ModelError naming the field

  // Forward pass one frame at a time (live recognition).
  class Stream {
   public:
    explicit Stream(const Hmm& model) : model_(&model) {}
    double step(const Eigen::VectorXd& x);  // log-likelihood of all frames so far
    const Eigen::VectorXd& log_alpha() const { return alpha_; }
    int frames() const { return frames_; }
    void reset() { frames_ = 0; }

   private:
    const Hmm* model_;
    Eigen::VectorXd alpha_;
    int frames_ = 0;
  };

  // Forward and backward in scaled probabilities (each frame's emissions
  // scaled by their largest, alpha normalised every frame): no exp or log per
  // cell, matrix products instead, and no underflow on any length.
  struct Pass {
    using Rows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;  // a frame is contiguous
    Rows comp;               // T x (sum of M): log w_m + log N_m per state's components
    Rows logb;               // T x N
    Rows B;                  // T x N, exp(logb - rowmax)
    Rows alpha, beta;        // scaled: rows of alpha sum to 1; alpha .* beta = posteriors
    Eigen::VectorXd scale;   // c_t
    double log_likelihood = 0;
  };
  Pass pass(const Sequence& x, bool with_backward) const;

 private:
  friend class BaumWelch;  // training's steps (hmm.cpp)
  // log w_m + log N_m per state's components (comp, T x sum of M) and log b_j (logb, T x N) for every frame of x.
  void emissions_of(const Eigen::MatrixXd& x, Eigen::Ref<Pass::Rows> comp, Eigen::Ref<Pass::Rows> logb) const;
  void states_of(const Eigen::Ref<const Pass::Rows>& comp, Eigen::Ref<Pass::Rows> logb) const;  // logb from comp
  // Every component's coefficients on the quadratic features of frames taken from `centre` (hmm.cpp).
  void quadratic_coefficients(const Eigen::VectorXd& centre, Eigen::MatrixXd& c) const;
  Eigen::VectorXd centre_;  // the components' mean, where emissions_of takes frames from
  Eigen::MatrixXd quad_;    // quadratic_coefficients(centre_)
  // The scaled forward (and backward) recursions over frames with log emissions logb;
  // fills B, alpha, scale (and beta); returns the log-likelihood (-inf: impossible).
  double forward_backward(const Eigen::Ref<const Pass::Rows>& logb, Eigen::Ref<Pass::Rows> B, Eigen::Ref<Pass::Rows> alpha,
                          Eigen::Ref<Pass::Rows> beta, Eigen::Ref<Eigen::VectorXd> scale, bool with_backward) const;
  std::vector<Eigen::Index> offsets_;  // first column of each state's components in Pass::comp

  int dim_ = 0;
  Covariance covariance_ = Covariance::Full;
  Eigen::VectorXd log_start_, start_;
  Eigen::MatrixXd log_trans_, trans_;
  std::vector<GaussianMixture> emissions_;
};

double log_sum_exp(const Eigen::VectorXd& v);

}  // namespace skelgraph::gesture

#pragma once
// Continuous hidden Markov models over a pluggable emission model, with no
// underflow on any length: forward log-likelihood, Viterbi path, state
// posteriors, a streaming forward step for live use, and Baum-Welch training
// over many sequences of different lengths. Eigen only; models save to and
// load from versioned JSON. Hmm<Emission> is the model (as mlpack's
// HMM<Distribution>); the emission models we use, Gaussian mixtures with full
// or diagonal covariances, are in gaussian_mixture.hpp (GaussianHmm).

#include <cstddef>
#include <cstdint>
#include <random>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <utility>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

namespace skelgraph::gesture {

// One observation per row: T x D.
using Sequence = Eigen::MatrixXd;

// A value per frame and state (or component), each frame's contiguous: log emissions, alpha, beta.
using Rows = Eigen::Matrix<double, Eigen::Dynamic, Eigen::Dynamic, Eigen::RowMajor>;

// Bad model file or bad training input; the message says what and where.
class ModelError : public std::runtime_error {
 public:
  using std::runtime_error::runtime_error;
};

enum class Covariance { Full, Diagonal };  // of the Gaussian-mixture emissions

// How training picks its first parameters. Segments: each sequence cut into N
// equal parts, state j from the j-th part of every sequence (suits gestures,
// which pass through their phases in order). KMeans: k-means++ over all frames
// pooled, a state per cluster, uniform start and transitions (pomegranate's
// from_samples; depends more on the seed).
enum class Init { Segments, KMeans };

struct TrainOptions {
  int states = 7;
  int mixtures = 1;             // the Gaussian-mixture emissions' components per state
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

double log_sum_exp(const Eigen::VectorXd& v);

// An emission model is the emission part of an HMM over all its states
// (gaussian_mixture.hpp's; test_hmm.cpp has a categorical one). Hmm<E> asks of
// E, default-constructible (is_emission_v checks it):
//   int states() const, int dim() const;
//   E::Workspace, default-constructible: scratch of the batched evaluation (Hmm::Pass keeps one);
//   void log_probabilities(const Sequence& x, E::Workspace& w, Eigen::Ref<Rows> logb) const:
//     log b_j(x_t) of every frame of x (T x D) into logb (T x N);
//   void log_probabilities(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> logb) const: one frame;
//   void to_json(nlohmann::json& model) const: its fields into the model's object;
//   static E from_json(const nlohmann::json& model, int states, int dim): throws ModelError naming the field;
//   E::Trainer, Baum-Welch's emission side, made once per training; frames are
//   numbered over the sequences stacked in order:
//     Trainer(const std::vector<Sequence>& data, const TrainOptions& o);
//     E initialise(const std::vector<int>& state, std::mt19937_64& rng): from frame f assigned to state[f];
//     const Rows& log_probabilities(const E& e): log b_j of every frame (F x N) under e;
//     void accumulate(std::size_t s, const Eigen::Ref<const Rows>& gamma): sequence s's state
//       posteriors (T x N) under the model last given to log_probabilities();
//     E finish(const E& e, std::mt19937_64& rng): the M-step from the sequences accumulated
//       since the last finish (e: the current emissions).
namespace detail {
template <class E, class T = typename E::Trainer, class W = typename E::Workspace>
using emission_checks = std::void_t<
    std::enable_if_t<std::is_default_constructible_v<E> && std::is_default_constructible_v<W>>,
    std::enable_if_t<std::is_convertible_v<decltype(std::declval<const E&>().states()), int>>,
    std::enable_if_t<std::is_convertible_v<decltype(std::declval<const E&>().dim()), int>>,
    decltype(std::declval<const E&>().log_probabilities(std::declval<const Sequence&>(), std::declval<W&>(),
                                                        std::declval<Eigen::Ref<Rows>>())),
    decltype(std::declval<const E&>().log_probabilities(std::declval<const Eigen::VectorXd&>(),
                                                        std::declval<Eigen::Ref<Eigen::VectorXd>>())),
    decltype(std::declval<const E&>().to_json(std::declval<nlohmann::json&>())),
    std::enable_if_t<std::is_same_v<decltype(E::from_json(std::declval<const nlohmann::json&>(), 1, 1)), E>>,
    std::enable_if_t<std::is_constructible_v<T, const std::vector<Sequence>&, const TrainOptions&>>,
    std::enable_if_t<std::is_same_v<
        decltype(std::declval<T&>().initialise(std::declval<const std::vector<int>&>(), std::declval<std::mt19937_64&>())), E>>,
    std::enable_if_t<std::is_convertible_v<decltype(std::declval<T&>().log_probabilities(std::declval<const E&>())), const Rows&>>,
    decltype(std::declval<T&>().accumulate(std::size_t{}, std::declval<const Eigen::Ref<const Rows>&>())),
    std::enable_if_t<std::is_same_v<decltype(std::declval<T&>().finish(std::declval<const E&>(), std::declval<std::mt19937_64&>())), E>>>;
template <class E, class = void>
struct is_emission : std::false_type {};
template <class E>
struct is_emission<E, emission_checks<E>> : std::true_type {};
}  // namespace detail
template <class E>
inline constexpr bool is_emission_v = detail::is_emission<E>::value;

namespace detail {

double safe_log(double p);  // -inf for p <= 0
// Throws ModelError unless v is finite, non-negative and sums to 1; `what` names it.
void check_probabilities(const Eigen::VectorXd& v, const std::string& what);
// k-means++ then Lloyd iterations; a cluster per point.
std::vector<int> kmeans(const std::vector<Eigen::VectorXd>& pts, int k, std::mt19937_64& rng);
// Model file fields: o[key] or ModelError "missing 'key'<where>"; a list of numbers; n lists of n numbers.
const nlohmann::json& json_field(const nlohmann::json& o, const char* key, const std::string& where);
Eigen::VectorXd json_vector(const nlohmann::json& a, const std::string& what);
Eigen::MatrixXd json_matrix(const nlohmann::json& a, const std::string& what, Eigen::Index n);
nlohmann::json json_rows(const Eigen::MatrixXd& m);
// Checks what training needs of its input (hmm.cpp; throws ModelError); the number of frames.
std::size_t check_training(const std::vector<Sequence>& data, const TrainOptions& o);

// Start and transition probabilities and the recursions over them given each
// frame's log emissions: the part of an HMM no emission model changes.
class MarkovChain {
 public:
  // Probabilities, checked: rows sum to 1. Throws ModelError.
  void set(const Eigen::VectorXd& start, const Eigen::MatrixXd& transitions);
  int states() const { return static_cast<int>(start_.size()); }
  const Eigen::VectorXd& start() const { return start_; }
  const Eigen::MatrixXd& transitions() const { return trans_; }

  // Forward and backward in scaled probabilities (each frame's emissions
  // scaled by their largest, alpha normalised every frame): no exp or log per
  // cell, matrix products instead, and no underflow on any length. Fills B
  // (exp(logb - rowmax)), alpha, scale (and beta); the log-likelihood (-inf: impossible).
  double forward_backward(const Eigen::Ref<const Rows>& logb, Eigen::Ref<Rows> B, Eigen::Ref<Rows> alpha,
                          Eigen::Ref<Rows> beta, Eigen::Ref<Eigen::VectorXd> scale, bool with_backward) const;
  std::vector<int> viterbi(const Eigen::Ref<const Rows>& logb, double* log_prob) const;  // in logs
  // The forward step in logs: alpha from the previous frame's (the first frame: none) and this frame's log emissions.
  void step(Eigen::VectorXd& alpha, const Eigen::VectorXd& logb, bool first) const;

  void to_json(nlohmann::json& model) const;  // "start", "transitions"
  static MarkovChain from_json(const nlohmann::json& model, int states);

  class Trainer;  // its side of Baum-Welch

 private:
  Eigen::VectorXd log_start_, start_;
  Eigen::MatrixXd log_trans_, trans_;
  Rows trans_rows_;  // trans_ with row i contiguous (trans_ has column j)
};

// Baum-Welch's side of the chain: the first state of every frame and the
// first probabilities, the recursions over every sequence, start and
// transitions re-estimated. Every frame of every sequence stacked in order.
class MarkovChain::Trainer {
 public:
  Trainer(const std::vector<Sequence>& data, const TrainOptions& o);
  // Init::Segments: frame t of a T-frame sequence in state t N / T; Init::KMeans: a state per k-means cluster.
  std::vector<int> initial_states(std::mt19937_64& rng) const;
  MarkovChain initial() const;  // start and transitions as the options' shape asks
  // Forward-backward of every sequence under `c` with log emissions logb (F x N); the total log-likelihood.
  double expectation(const MarkovChain& c, const Rows& logb);
  // After expectation(): every frame's state posteriors (F x N); the new start and transitions.
  const Rows& posteriors();
  MarkovChain maximisation(const MarkovChain& c);
  std::size_t sequences() const { return first_.size() - 1; }
  Eigen::Index first(std::size_t s) const { return first_[s]; }  // sequence s's first frame
  Eigen::Index length(std::size_t s) const { return first_[s + 1] - first_[s]; }

 private:
  const std::vector<Sequence>& data_;
  const int N_;
  const bool left_right_;
  const Init init_;
  std::vector<Eigen::Index> first_;  // and the number of frames last
  Rows B_, alpha_, beta_, W_, gamma_;
  Eigen::VectorXd scale_, start_acc_;
};

}  // namespace detail

template <class Emission>
class BaumWelch;

template <class Emission>
class Hmm {
  static_assert(is_emission_v<Emission>, "Hmm<Emission>: Emission lacks what an emission model needs (hmm.hpp)");

 public:
  Hmm() = default;
  explicit Hmm(Emission emission);  // uniform start and transitions

  int states() const { return chain_.states(); }
  int dim() const { return emission_.dim(); }

  // Start and transition probabilities (not logs), checked: rows sum to 1, one
  // state of emissions per state. Throws ModelError.
  void set(const Eigen::VectorXd& start, const Eigen::MatrixXd& transitions, Emission emission);
  Eigen::VectorXd start() const { return chain_.start(); }
  Eigen::MatrixXd transitions() const { return chain_.transitions(); }
  const Emission& emission() const { return emission_; }

  double log_likelihood(const Sequence& x) const;               // forward; -inf for an impossible sequence
  std::vector<int> viterbi(const Sequence& x, double* log_prob = nullptr) const;
  Eigen::MatrixXd posteriors(const Sequence& x) const;          // T x N, each row sums to 1

  // Baum-Welch (BaumWelch: initialisation, then expectation and maximisation
  // until the gain per frame falls below the tolerance).
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

  // Forward and backward over a sequence (detail::MarkovChain::forward_backward).
  struct Pass {
    using Rows = gesture::Rows;
    typename Emission::Workspace emission;  // the emission model's scratch
    Rows logb;               // T x N
    Rows B;                  // T x N, exp(logb - rowmax)
    Rows alpha, beta;        // scaled: rows of alpha sum to 1; alpha .* beta = posteriors
    Eigen::VectorXd scale;   // c_t
    double log_likelihood = 0;
  };
  Pass pass(const Sequence& x, bool with_backward) const;

 private:
  friend class BaumWelch<Emission>;
  void set(detail::MarkovChain chain, Emission emission);
  detail::MarkovChain chain_;
  Emission emission_;
};

// Baum-Welch over many sequences in its three steps, as mlpack's HMM::Train
// is laid out: initialise() the first model, expectation() of the counts
// under the current one, maximisation() into new parameters. The chain's side
// and the emissions' (Emission::Trainer) each take every sequence once.
template <class Emission>
class BaumWelch {
 public:
  BaumWelch(const std::vector<Sequence>& data, const TrainOptions& o) : rng_(o.seed), chain_(data, o), emission_(data, o) {}
  // A state for every frame (TrainOptions::init), the emissions from them, start and transitions of the options' shape.
  Hmm<Emission> initialise();
  // Forward-backward of every sequence under h; the total log-likelihood.
  double expectation(const Hmm<Emission>& h);
  // New parameters for h from the last expectation().
  void maximisation(Hmm<Emission>& h);

 private:
  std::mt19937_64 rng_;
  detail::MarkovChain::Trainer chain_;
  typename Emission::Trainer emission_;
};

}  // namespace skelgraph::gesture

#include "skelgraph/gesture/hmm_impl.hpp"

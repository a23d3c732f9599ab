#pragma once
// Gaussian-mixture emissions (full or diagonal covariances) for Hmm<Emission>
// (hmm.hpp), and GaussianHmm, the HMM the gesture classifier uses.

#include <cstddef>
#include <random>
#include <vector>

#include <Eigen/Core>
#include <nlohmann/json.hpp>

#include "skelgraph/gesture/hmm.hpp"

namespace skelgraph::gesture {

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

// A Gaussian mixture per state, every state's covariances full or diagonal.
// The emissions of every frame and every state's components are one matrix
// product of the frames' quadratic features (gaussian_mixture.cpp), and so
// are Baum-Welch's sums.
class GaussianMixtureEmission {
 public:
  struct Workspace {
    Rows comp;  // T x (sum of M): log w_m + log N_m per state's components
  };
  class Trainer;

  GaussianMixtureEmission() = default;
  GaussianMixtureEmission(int states, int dim, Covariance covariance);  // N(0, I) in every state
  // Checked: weights sum to 1, means of `dim` values, covariances symmetric
  // positive definite. Throws ModelError.
  GaussianMixtureEmission(int dim, Covariance covariance, std::vector<GaussianMixture> mixtures);

  int states() const { return static_cast<int>(mixtures_.size()); }
  int dim() const { return dim_; }
  Covariance covariance() const { return covariance_; }
  const std::vector<GaussianMixture>& mixtures() const { return mixtures_; }

  void log_probabilities(const Sequence& x, Workspace& w, Eigen::Ref<Rows> logb) const;
  void log_probabilities(const Eigen::VectorXd& x, Eigen::Ref<Eigen::VectorXd> logb) const;

  void to_json(nlohmann::json& model) const;  // "covariance", "emissions"
  static GaussianMixtureEmission from_json(const nlohmann::json& model, int states, int dim);

 private:
  void states_of(const Eigen::Ref<const Rows>& comp, Eigen::Ref<Rows> logb) const;  // logb from comp
  // Every component's coefficients on the quadratic features of frames taken from `centre`.
  void quadratic_coefficients(const Eigen::VectorXd& centre, Eigen::MatrixXd& c) const;

  int dim_ = 0;
  Covariance covariance_ = Covariance::Full;
  std::vector<GaussianMixture> mixtures_;
  std::vector<Eigen::Index> offsets_;  // first column of each state's components in Workspace::comp
  Eigen::VectorXd centre_;  // the components' mean, where log_probabilities takes frames from
  Eigen::MatrixXd quad_;    // quadratic_coefficients(centre_)
};

// Baum-Welch's side of the emissions (TrainOptions' mixtures, covariance,
// regularisation, constant_spread). Every frame of every sequence is stacked
// once, centred on the frames' mean, as quadratic features (Q), so the
// emissions of an iteration are the one product Q C and its statistics Q^T R.
class GaussianMixtureEmission::Trainer {
 public:
  Trainer(const std::vector<Sequence>& data, const TrainOptions& o);
  // k-means within a state for its mixtures.
  GaussianMixtureEmission initialise(const std::vector<int>& state, std::mt19937_64& rng);
  const Rows& log_probabilities(const GaussianMixtureEmission& e);
  void accumulate(std::size_t s, const Eigen::Ref<const Rows>& gamma);
  // A component nothing belongs to starts again on a random frame.
  GaussianMixtureEmission finish(const GaussianMixtureEmission& e, std::mt19937_64& rng);

 private:
  const std::vector<Sequence>& data_;
  const Covariance covariance_;
  const int N_, M_;
  const Eigen::Index D_;
  Eigen::VectorXd mean_, reg_;
  Eigen::MatrixXd global_cov_;
  std::vector<Eigen::Index> first_;  // each sequence's first row in the stacked frames
  std::vector<bool> accumulated_;
  Eigen::MatrixXd Q_, C_, R_;
  Rows comp_, logb_;
};

using GaussianHmm = Hmm<GaussianMixtureEmission>;

extern template class Hmm<GaussianMixtureEmission>;
extern template class BaumWelch<GaussianMixtureEmission>;

}  // namespace skelgraph::gesture

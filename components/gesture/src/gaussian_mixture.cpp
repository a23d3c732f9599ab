#include "skelgraph/gesture/gaussian_mixture.hpp"

#include <algorithm>
#include <cmath>
#include <string>

#include <Eigen/Cholesky>

namespace skelgraph::gesture {

using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {

// Frames as quadratic features q(x) = [1, x, x_a x_b (a <= b)] (diagonal
// covariances: [1, x, x_a^2]), x taken from a centre near the data (a
// model's mean, the training frames' mean) so that no large terms cancel:
// a Gaussian's log density is linear in q, and so are the sums Baum-Welch
// needs, so the emissions of every frame and component are the one product
// Q C, and an iteration's statistics the one product Q^T R.
Eigen::Index quadratic_size(Eigen::Index d, Covariance c) { return 1 + d + (c == Covariance::Full ? d * (d + 1) / 2 : d); }

MatrixXd quadratic_features(const MatrixXd& xc, Covariance c) {
  const auto d = xc.cols();
  MatrixXd q(xc.rows(), quadratic_size(d, c));
  q.col(0).setOnes();
  q.middleCols(1, d) = xc;
  Eigen::Index col = 1 + d;
  for (Eigen::Index a = 0; a < d; ++a) {
    for (Eigen::Index b = a; b < (c == Covariance::Full ? d : a + 1); ++b) q.col(col++) = xc.col(a).cwiseProduct(xc.col(b));
  }
  return q;
}

// The coefficients with q(x) . c = log w + log N(x; mu, S) for x and mu centred alike.
void quadratic_coefficients(const VectorXd& mu_c, const MatrixXd& precision, double log_norm, Covariance cov,
                            Eigen::Ref<VectorXd> c) {
  const auto d = mu_c.size();
  const VectorXd pm = precision * mu_c;
  c(0) = log_norm - 0.5 * mu_c.dot(pm);
  c.segment(1, d) = pm;
  Eigen::Index col = 1 + d;
  for (Eigen::Index a = 0; a < d; ++a) {
    for (Eigen::Index b = a; b < (cov == Covariance::Full ? d : a + 1); ++b) c(col++) = a == b ? -0.5 * precision(a, a) : -precision(a, b);
  }
}

// Mean (centred) and covariance from a component's column of Q^T R.
void moments(const Eigen::Ref<const VectorXd>& s, Eigen::Index d, Covariance cov, VectorXd& mu_c, MatrixXd& out) {
  const double n = s(0);
  mu_c = s.segment(1, d) / n;
  out = MatrixXd::Zero(d, d);
  Eigen::Index col = 1 + d;
  for (Eigen::Index a = 0; a < d; ++a) {
    for (Eigen::Index b = a; b < (cov == Covariance::Full ? d : a + 1); ++b) {
      out(a, b) = out(b, a) = s(col++) / n - mu_c(a) * mu_c(b);
    }
  }
}

MatrixXd shape(const MatrixXd& cov, Covariance c, const VectorXd& reg) {
  MatrixXd out = c == Covariance::Diagonal ? MatrixXd(cov.diagonal().asDiagonal()) : MatrixXd(0.5 * (cov + cov.transpose()));
  out.diagonal() += reg;
  return out;
}

}  // namespace

// --- Gaussian mixtures ---

void GaussianMixture::prepare() {
  const auto m = static_cast<std::size_t>(weights.size());
  if (means.size() != m || covs.size() != m) throw ModelError("mixture: weights, means and covariances differ in count");
  inv_l_.resize(m);
  log_norm_.resize(static_cast<Eigen::Index>(m));
  for (std::size_t k = 0; k < m; ++k) {
    const auto d = means[k].size();
    if (covs[k].rows() != d || covs[k].cols() != d) throw ModelError("mixture: covariance " + std::to_string(k) + " is not D x D");
    if (!covs[k].isApprox(covs[k].transpose(), 1e-9)) throw ModelError("mixture: covariance " + std::to_string(k) + " is not symmetric");
    const Eigen::LLT<MatrixXd> llt(covs[k]);
    if (llt.info() != Eigen::Success) throw ModelError("mixture: covariance " + std::to_string(k) + " is not positive definite");
    const MatrixXd L = llt.matrixL();
    inv_l_[k] = L.triangularView<Eigen::Lower>().solve(MatrixXd::Identity(d, d));
    log_norm_(static_cast<Eigen::Index>(k)) = detail::safe_log(weights(static_cast<Eigen::Index>(k))) -
                                               0.5 * (static_cast<double>(d) * std::log(2 * M_PI)) -
                                               L.diagonal().array().log().sum();
  }
}

void GaussianMixture::log_pdf_components(const VectorXd& x, VectorXd& out) const {
  out.resize(log_norm_.size());
  for (Eigen::Index k = 0; k < log_norm_.size(); ++k) {
    const VectorXd z = inv_l_[static_cast<std::size_t>(k)] * (x - means[static_cast<std::size_t>(k)]);
    out(k) = log_norm_(k) - 0.5 * z.squaredNorm();
  }
}

double GaussianMixture::log_pdf(const VectorXd& x) const {
  VectorXd c;
  log_pdf_components(x, c);
  return log_sum_exp(c);
}

// --- The emissions ---

GaussianMixtureEmission::GaussianMixtureEmission(int states, int dim, Covariance covariance)
    : GaussianMixtureEmission(dim, covariance, [&] {
        std::vector<GaussianMixture> em(static_cast<std::size_t>(std::max(states, 0)));
        for (auto& e : em) {
          e.weights = VectorXd::Ones(1);
          e.means = {VectorXd::Zero(dim)};
          e.covs = {MatrixXd::Identity(dim, dim)};
        }
        return em;
      }()) {}

GaussianMixtureEmission::GaussianMixtureEmission(int dim, Covariance covariance, std::vector<GaussianMixture> mixtures)
    : dim_(dim), covariance_(covariance), mixtures_(std::move(mixtures)) {
  for (std::size_t j = 0; j < mixtures_.size(); ++j) {
    detail::check_probabilities(mixtures_[j].weights, "mixture weights of state " + std::to_string(j));
    for (const auto& m : mixtures_[j].means) {
      if (m.size() != dim_) throw ModelError("model: a mean of state " + std::to_string(j) + " has " + std::to_string(m.size()) + " values, expected " + std::to_string(dim_));
    }
    try {
      mixtures_[j].prepare();
    } catch (const ModelError& e) {
      throw ModelError(std::string(e.what()) + " (state " + std::to_string(j) + ")");
    }
  }
  Eigen::Index off = 0;
  for (const auto& e : mixtures_) {
    offsets_.push_back(off);
    off += e.weights.size();
  }
  offsets_.push_back(off);
  centre_ = VectorXd::Zero(dim_);
  for (const auto& e : mixtures_) {
    for (const auto& m : e.means) centre_ += m / static_cast<double>(off);
  }
  quadratic_coefficients(centre_, quad_);
}

void GaussianMixtureEmission::log_probabilities(const Sequence& x, Workspace& w, Eigen::Ref<Rows> logb) const {
  if (x.cols() != dim_) throw ModelError("sequence has " + std::to_string(x.cols()) + " features per frame, the model " + std::to_string(dim_));
  w.comp.resize(x.rows(), offsets_.back());
  w.comp.noalias() = quadratic_features(x.rowwise() - centre_.transpose(), covariance_) * quad_;
  states_of(w.comp, logb);
}

void GaussianMixtureEmission::log_probabilities(const VectorXd& x, Eigen::Ref<VectorXd> logb) const {
  for (std::size_t j = 0; j < mixtures_.size(); ++j) logb(static_cast<Eigen::Index>(j)) = mixtures_[j].log_pdf(x);
}

void GaussianMixtureEmission::quadratic_coefficients(const VectorXd& centre, MatrixXd& c) const {
  c.resize(quadratic_size(dim_, covariance_), offsets_.back());
  for (int j = 0; j < states(); ++j) {
    const auto& g = mixtures_[static_cast<std::size_t>(j)];
    for (std::size_t m = 0; m < g.means.size(); ++m) {
      gesture::quadratic_coefficients(g.means[m] - centre, g.precision(m), g.log_norm(m), covariance_,
                                      c.col(offsets_[static_cast<std::size_t>(j)] + static_cast<Eigen::Index>(m)));
    }
  }
}

void GaussianMixtureEmission::states_of(const Eigen::Ref<const Rows>& comp, Eigen::Ref<Rows> logb) const {
  for (int j = 0; j < states(); ++j) {
    const auto off = offsets_[static_cast<std::size_t>(j)], m = offsets_[static_cast<std::size_t>(j) + 1] - off;
    if (m == 1) {
      logb.col(j) = comp.col(off);
    } else {
      const VectorXd mx = comp.middleCols(off, m).rowwise().maxCoeff();
      logb.col(j) = mx.array() + ((comp.middleCols(off, m).colwise() - mx).array().exp().rowwise().sum()).log();
    }
  }
}

void GaussianMixtureEmission::to_json(nlohmann::json& model) const {
  nlohmann::json em = nlohmann::json::array();
  for (const auto& g : mixtures_) {
    nlohmann::json means = nlohmann::json::array(), covs = nlohmann::json::array();
    for (const auto& m : g.means) means.push_back(std::vector<double>(m.data(), m.data() + m.size()));
    for (const auto& c : g.covs) covs.push_back(detail::json_rows(c));
    em.push_back({{"weights", std::vector<double>(g.weights.data(), g.weights.data() + g.weights.size())},
                  {"means", means},
                  {"covariances", covs}});
  }
  model["covariance"] = covariance_ == Covariance::Full ? "full" : "diagonal";
  model["emissions"] = em;
}

GaussianMixtureEmission GaussianMixtureEmission::from_json(const nlohmann::json& model, int states, int dim) {
  const std::string cov = detail::json_field(model, "covariance", "").get<std::string>();
  if (cov != "full" && cov != "diagonal") throw ModelError("model: 'covariance' must be \"full\" or \"diagonal\", got \"" + cov + "\"");
  const auto& em = detail::json_field(model, "emissions", "");
  if (!em.is_array() || static_cast<int>(em.size()) != states) throw ModelError("model: 'emissions' expects one mixture per state");
  std::vector<GaussianMixture> mixtures;
  for (int s = 0; s < states; ++s) {
    const auto& e = em[static_cast<std::size_t>(s)];
    const std::string where = " in emissions[" + std::to_string(s) + "]";
    GaussianMixture g;
    g.weights = detail::json_vector(detail::json_field(e, "weights", where), "'weights'" + where);
    const auto& means = detail::json_field(e, "means", where);
    const auto& covs = detail::json_field(e, "covariances", where);
    if (!means.is_array() || !covs.is_array() || static_cast<Eigen::Index>(means.size()) != g.weights.size() ||
        static_cast<Eigen::Index>(covs.size()) != g.weights.size()) {
      throw ModelError("model: 'weights', 'means' and 'covariances' differ in count" + where);
    }
    for (std::size_t m = 0; m < means.size(); ++m) {
      g.means.push_back(detail::json_vector(means[m], "'means'" + where));
      g.covs.push_back(detail::json_matrix(covs[m], "'covariances'" + where, dim));
    }
    mixtures.push_back(std::move(g));
  }
  return GaussianMixtureEmission(dim, cov == "full" ? Covariance::Full : Covariance::Diagonal, std::move(mixtures));
}

// --- Training ---

GaussianMixtureEmission::Trainer::Trainer(const std::vector<Sequence>& data, const TrainOptions& o)
    : data_(data), covariance_(o.covariance), N_(o.states), M_(o.mixtures), D_(data.front().cols()) {
  // Regularisation scaled to each feature's spread over all data. A feature
  // that never varies takes the spread given (a classifier's, shared by its
  // models) or the others' mean, so that a test frame off by a hair in it is
  // not worth -1e12 (with a floor of 1e-12 it was).
  if (o.constant_spread.size() != 0 && o.constant_spread.size() != D_)
    throw ModelError("constant_spread has " + std::to_string(o.constant_spread.size()) + " values for " +
                     std::to_string(D_) + "-dimensional data");
  std::vector<const Sequence*> all_data;
  for (const auto& x : data) all_data.push_back(&x);
  const VectorXd spread = feature_spread(all_data, o.constant_spread, &mean_);
  reg_ = o.regularisation * spread;
  global_cov_ = MatrixXd(spread.asDiagonal());
  // Every frame of every sequence stacked once, centred, as quadratic
  // features; the work matrices sized for them.
  first_.assign(data_.size() + 1, 0);
  for (std::size_t s = 0; s < data_.size(); ++s) first_[s + 1] = first_[s] + data_[s].rows();
  const auto F = first_.back();
  const int K = N_ * M_;  // components of all states, in Workspace::comp's column order
  {
    MatrixXd xc(F, D_);
    for (std::size_t s = 0; s < data_.size(); ++s) xc.middleRows(first_[s], data_[s].rows()) = data_[s].rowwise() - mean_.transpose();
    Q_ = quadratic_features(xc, covariance_);
  }
  C_.resize(Q_.cols(), K);
  R_.resize(F, K);
  comp_.resize(F, K);
  logb_.resize(F, N_);
  accumulated_.assign(data_.size(), false);
}

GaussianMixtureEmission GaussianMixtureEmission::Trainer::initialise(const std::vector<int>& state, std::mt19937_64& rng) {
  const int N = N_, M = M_;
  const auto D = D_;
  std::vector<std::vector<VectorXd>> by_state(static_cast<std::size_t>(N));
  std::size_t f = 0;
  for (const auto& x : data_) {
    for (Eigen::Index t = 0; t < x.rows(); ++t) by_state[static_cast<std::size_t>(state[f++])].push_back(x.row(t).transpose());
  }
  std::vector<GaussianMixture> em(static_cast<std::size_t>(N));
  for (int j = 0; j < N; ++j) {
    auto& pts = by_state[static_cast<std::size_t>(j)];
    if (pts.empty()) pts.push_back(mean_);  // more states than frames in every sequence, or an empty k-means cluster
    const auto label = detail::kmeans(pts, M, rng);
    auto& g = em[static_cast<std::size_t>(j)];
    g.weights = VectorXd::Zero(M);
    for (int m = 0; m < M; ++m) {
      VectorXd mu = VectorXd::Zero(D);
      int cnt = 0;
      for (std::size_t i = 0; i < pts.size(); ++i) {
        if (label[i] == m) mu += pts[i], ++cnt;
      }
      MatrixXd cov = global_cov_;
      if (cnt > 0) {
        mu /= cnt;
        if (cnt > 1) {
          cov.setZero();
          for (std::size_t i = 0; i < pts.size(); ++i) {
            if (label[i] == m) cov += (pts[i] - mu) * (pts[i] - mu).transpose();
          }
          cov /= cnt;
        }
      } else {
        mu = pts[std::uniform_int_distribution<std::size_t>(0, pts.size() - 1)(rng)];
      }
      g.weights(m) = std::max(1.0, static_cast<double>(cnt));
      g.means.push_back(mu);
      g.covs.push_back(shape(cov, covariance_, reg_));
    }
    g.weights /= g.weights.sum();
  }
  return GaussianMixtureEmission(static_cast<int>(D), covariance_, std::move(em));
}

const Rows& GaussianMixtureEmission::Trainer::log_probabilities(const GaussianMixtureEmission& e) {
  e.quadratic_coefficients(mean_, C_);
  comp_.noalias() = Q_ * C_;
  e.states_of(comp_, logb_);
  return logb_;
}

void GaussianMixtureEmission::Trainer::accumulate(std::size_t s, const Eigen::Ref<const Rows>& gamma) {
  // Each component's responsibility for each frame (R); finish() takes its weighted sums.
  const auto b = first_[s], T = first_[s + 1] - b;
  for (int j = 0; j < N_; ++j) {
    const auto off = static_cast<Eigen::Index>(j) * M_;
    for (int m = 0; m < M_; ++m) {
      if (M_ == 1) R_.col(off).segment(b, T) = gamma.col(j);
      else R_.col(off + m).segment(b, T) = gamma.col(j).cwiseProduct((comp_.col(off + m).segment(b, T) - logb_.col(j).segment(b, T)).array().exp().matrix());
    }
  }
  accumulated_[s] = true;
}

GaussianMixtureEmission GaussianMixtureEmission::Trainer::finish(const GaussianMixtureEmission& /*e*/, std::mt19937_64& rng) {
  const int N = N_, M = M_;
  for (std::size_t s = 0; s < data_.size(); ++s) {
    if (!accumulated_[s]) R_.middleRows(first_[s], first_[s + 1] - first_[s]).setZero();
    accumulated_[s] = false;
  }
  const MatrixXd S = Q_.transpose() * R_;  // per component: sum r, sum r x, sum r x_a x_b
  std::vector<GaussianMixture> em(static_cast<std::size_t>(N));
  for (int j = 0; j < N; ++j) {
    auto& g = em[static_cast<std::size_t>(j)];
    const auto off = static_cast<Eigen::Index>(j) * M;
    g.weights = VectorXd::Zero(M);
    for (int m = 0; m < M; ++m) {
      const auto k = off + m;
      const double n = S(0, k);
      if (n < 1e-6) {
        // A component nothing belongs to: start it again on a random frame.
        const auto& x = data_[std::uniform_int_distribution<std::size_t>(0, data_.size() - 1)(rng)];
        g.means.push_back(x.row(std::uniform_int_distribution<Eigen::Index>(0, x.rows() - 1)(rng)).transpose());
        g.covs.push_back(shape(global_cov_, covariance_, reg_));
        g.weights(m) = 1e-3;
        continue;
      }
      VectorXd mu;
      MatrixXd cov;
      moments(S.col(k), D_, covariance_, mu, cov);
      mu += mean_;
      g.means.push_back(mu);
      g.covs.push_back(shape(cov, covariance_, reg_));
      g.weights(m) = n;
    }
    g.weights /= g.weights.sum();
  }
  return GaussianMixtureEmission(static_cast<int>(D_), covariance_, std::move(em));
}

template class Hmm<GaussianMixtureEmission>;
template class BaumWelch<GaussianMixtureEmission>;

}  // namespace skelgraph::gesture

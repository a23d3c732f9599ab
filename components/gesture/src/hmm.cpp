#include "skelgraph/gesture/hmm.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Cholesky>

namespace skelgraph::gesture {

using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {
constexpr double kNegInf = -std::numeric_limits<double>::infinity();
double safe_log(double p) { return p > 0 ? std::log(p) : kNegInf; }
}  // namespace

double log_sum_exp(const VectorXd& v) {
  const double m = v.maxCoeff();
  if (m == kNegInf) return kNegInf;
  return m + std::log((v.array() - m).exp().sum());
}

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
    log_norm_(static_cast<Eigen::Index>(k)) = safe_log(weights(static_cast<Eigen::Index>(k))) -
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

void GaussianMixture::log_pdf_components(const MatrixXd& X, Eigen::Ref<MatrixXd> out) const {
  for (Eigen::Index k = 0; k < log_norm_.size(); ++k) {
    const auto ku = static_cast<std::size_t>(k);
    const MatrixXd Z = (X.rowwise() - means[ku].transpose()) * inv_l_[ku].transpose();
    out.col(k) = (log_norm_(k) - 0.5 * Z.rowwise().squaredNorm().array()).matrix();
  }
}

double GaussianMixture::log_pdf(const VectorXd& x) const {
  VectorXd c;
  log_pdf_components(x, c);
  return log_sum_exp(c);
}

// --- The model ---

Hmm::Hmm(int states, int dim, Covariance covariance) : dim_(dim), covariance_(covariance) {
  std::vector<GaussianMixture> em(static_cast<std::size_t>(states));
  for (auto& e : em) {
    e.weights = VectorXd::Ones(1);
    e.means = {VectorXd::Zero(dim)};
    e.covs = {MatrixXd::Identity(dim, dim)};
  }
  set(VectorXd::Constant(states, 1.0 / states), MatrixXd::Constant(states, states, 1.0 / states), std::move(em));
}

void Hmm::set(const VectorXd& start, const MatrixXd& transitions, std::vector<GaussianMixture> emissions) {
  const auto n = start.size();
  if (n < 1) throw ModelError("model: no states");
  if (transitions.rows() != n || transitions.cols() != n) throw ModelError("model: transitions are not N x N");
  if (static_cast<Eigen::Index>(emissions.size()) != n) throw ModelError("model: one emission mixture per state expected");
  const auto prob_vector = [](const VectorXd& v, const std::string& what) {
    if (!v.allFinite() || (v.array() < 0).any()) throw ModelError("model: " + what + " has negative or non-finite entries");
    if (std::abs(v.sum() - 1.0) > 1e-6) throw ModelError("model: " + what + " sums to " + std::to_string(v.sum()) + ", expected 1");
  };
  prob_vector(start, "'start'");
  for (Eigen::Index i = 0; i < n; ++i) prob_vector(transitions.row(i).transpose(), "'transitions' row " + std::to_string(i));
  for (std::size_t j = 0; j < emissions.size(); ++j) {
    prob_vector(emissions[j].weights, "mixture weights of state " + std::to_string(j));
    for (const auto& m : emissions[j].means) {
      if (m.size() != dim_) throw ModelError("model: a mean of state " + std::to_string(j) + " has " + std::to_string(m.size()) + " values, expected " + std::to_string(dim_));
    }
    try {
      emissions[j].prepare();
    } catch (const ModelError& e) {
      throw ModelError(std::string(e.what()) + " (state " + std::to_string(j) + ")");
    }
  }
  log_start_ = start.unaryExpr(&safe_log);
  log_trans_ = transitions.unaryExpr(&safe_log);
  start_ = start;
  trans_ = transitions;
  emissions_ = std::move(emissions);
  offsets_.clear();
  Eigen::Index off = 0;
  for (const auto& e : emissions_) {
    offsets_.push_back(off);
    off += e.weights.size();
  }
  offsets_.push_back(off);
}

VectorXd Hmm::start() const { return start_; }
MatrixXd Hmm::transitions() const { return trans_; }

MatrixXd Hmm::log_emissions(const Sequence& x) const {
  if (x.cols() != dim_) throw ModelError("sequence has " + std::to_string(x.cols()) + " features per frame, the model " + std::to_string(dim_));
  MatrixXd comp(x.rows(), offsets_.back()), b(x.rows(), states());
  for (int j = 0; j < states(); ++j) {
    const auto off = offsets_[static_cast<std::size_t>(j)], m = offsets_[static_cast<std::size_t>(j) + 1] - off;
    emissions_[static_cast<std::size_t>(j)].log_pdf_components(x, comp.middleCols(off, m));
    for (Eigen::Index t = 0; t < x.rows(); ++t) b(t, j) = log_sum_exp(comp.row(t).segment(off, m).transpose());
  }
  return b;
}

Hmm::Pass Hmm::pass(const Sequence& x, bool with_backward) const {
  if (x.cols() != dim_) throw ModelError("sequence has " + std::to_string(x.cols()) + " features per frame, the model " + std::to_string(dim_));
  Pass p;
  const auto T = x.rows();
  const int N = states();
  p.comp.resize(T, offsets_.back());
  p.logb.resize(T, N);
  for (int j = 0; j < N; ++j) {
    const auto off = offsets_[static_cast<std::size_t>(j)], m = offsets_[static_cast<std::size_t>(j) + 1] - off;
    emissions_[static_cast<std::size_t>(j)].log_pdf_components(x, p.comp.middleCols(off, m));
    if (m == 1) {
      p.logb.col(j) = p.comp.col(off);
    } else {
      const VectorXd mx = p.comp.middleCols(off, m).rowwise().maxCoeff();
      p.logb.col(j) = mx.array() + ((p.comp.middleCols(off, m).colwise() - mx).array().exp().rowwise().sum()).log();
    }
  }
  const VectorXd rowmax = p.logb.rowwise().maxCoeff();
  p.B = (p.logb.colwise() - rowmax).array().exp().matrix();
  p.alpha.resize(T, N);
  p.scale.resize(T);
  p.log_likelihood = 0;
  Eigen::RowVectorXd prior(N);
  for (Eigen::Index t = 0; t < T; ++t) {
    if (!std::isfinite(rowmax(t))) {
      p.log_likelihood = kNegInf;  // no state can emit this frame
      return p;
    }
    if (t == 0) prior = start_.transpose();
    else prior.noalias() = p.alpha.row(t - 1) * trans_;
    p.alpha.row(t) = prior.cwiseProduct(p.B.row(t));
    p.scale(t) = p.alpha.row(t).sum();
    if (!(p.scale(t) > 0)) {
      p.log_likelihood = kNegInf;
      return p;
    }
    p.alpha.row(t) /= p.scale(t);
    p.log_likelihood += std::log(p.scale(t)) + rowmax(t);
  }
  if (with_backward) {
    p.beta.resize(T, N);
    p.beta.row(T - 1).setOnes();
    VectorXd v(N), w(N);
    for (Eigen::Index t = T - 2; t >= 0; --t) {
      v = p.B.row(t + 1).cwiseProduct(p.beta.row(t + 1)).transpose();
      w.noalias() = trans_ * v;
      p.beta.row(t) = w.transpose() / p.scale(t + 1);
    }
  }
  return p;
}

double Hmm::log_likelihood(const Sequence& x) const {
  if (x.rows() == 0) return 0.0;
  return pass(x, false).log_likelihood;
}

std::vector<int> Hmm::viterbi(const Sequence& x, double* log_prob) const {
  const auto T = x.rows();
  const int N = states();
  std::vector<int> path(static_cast<std::size_t>(T));
  if (T == 0) {
    if (log_prob) *log_prob = 0;
    return path;
  }
  const MatrixXd logb = log_emissions(x);
  MatrixXd delta(T, N);
  Eigen::MatrixXi psi(T, N);
  delta.row(0) = (log_start_ + logb.row(0).transpose()).transpose();
  for (Eigen::Index t = 1; t < T; ++t) {
    for (int j = 0; j < N; ++j) {
      Eigen::Index arg = 0;
      const double best = (delta.row(t - 1).transpose() + log_trans_.col(j)).maxCoeff(&arg);
      delta(t, j) = best + logb(t, j);
      psi(t, j) = static_cast<int>(arg);
    }
  }
  Eigen::Index last = 0;
  const double best = delta.row(T - 1).maxCoeff(&last);
  if (log_prob) *log_prob = best;
  path[static_cast<std::size_t>(T - 1)] = static_cast<int>(last);
  for (Eigen::Index t = T - 1; t > 0; --t) path[static_cast<std::size_t>(t - 1)] = psi(t, path[static_cast<std::size_t>(t)]);
  return path;
}

MatrixXd Hmm::posteriors(const Sequence& x) const {
  const Pass p = pass(x, true);
  if (!std::isfinite(p.log_likelihood)) throw ModelError("posteriors: the sequence is impossible under the model");
  MatrixXd g = p.alpha.cwiseProduct(p.beta);
  for (Eigen::Index t = 0; t < g.rows(); ++t) g.row(t) /= g.row(t).sum();
  return g;
}

double Hmm::Stream::step(const VectorXd& x) {
  const Hmm& m = *model_;
  const int N = m.states();
  VectorXd logb(N);
  for (int j = 0; j < N; ++j) logb(j) = m.emissions_[static_cast<std::size_t>(j)].log_pdf(x);
  if (frames_ == 0) {
    alpha_ = m.log_start_ + logb;
  } else {
    VectorXd next(N), tmp(N);
    for (int j = 0; j < N; ++j) {
      tmp = alpha_ + m.log_trans_.col(j);
      next(j) = log_sum_exp(tmp) + logb(j);
    }
    alpha_ = next;
  }
  ++frames_;
  return log_sum_exp(alpha_);
}

// --- Training ---

namespace {

// k-means++ then Lloyd iterations; returns a cluster per point.
std::vector<int> kmeans(const std::vector<VectorXd>& pts, int k, std::mt19937_64& rng) {
  const auto n = pts.size();
  std::vector<int> label(n, 0);
  if (k <= 1 || n == 0) return label;
  std::vector<VectorXd> centres{pts[std::uniform_int_distribution<std::size_t>(0, n - 1)(rng)]};
  std::vector<double> d2(n);
  while (static_cast<int>(centres.size()) < k) {
    double total = 0;
    for (std::size_t i = 0; i < n; ++i) {
      d2[i] = std::numeric_limits<double>::infinity();
      for (const auto& c : centres) d2[i] = std::min(d2[i], (pts[i] - c).squaredNorm());
      total += d2[i];
    }
    if (total <= 0) {
      centres.push_back(pts[std::uniform_int_distribution<std::size_t>(0, n - 1)(rng)]);
      continue;
    }
    double r = std::uniform_real_distribution<double>(0, total)(rng);
    std::size_t pick = 0;
    for (; pick + 1 < n && r > d2[pick]; ++pick) r -= d2[pick];
    centres.push_back(pts[pick]);
  }
  for (int it = 0; it < 50; ++it) {
    bool changed = false;
    for (std::size_t i = 0; i < n; ++i) {
      int best = 0;
      double bd = std::numeric_limits<double>::infinity();
      for (int c = 0; c < k; ++c) {
        const double d = (pts[i] - centres[static_cast<std::size_t>(c)]).squaredNorm();
        if (d < bd) bd = d, best = c;
      }
      changed = changed || label[i] != best;
      label[i] = best;
    }
    if (!changed && it > 0) break;
    for (int c = 0; c < k; ++c) {
      VectorXd sum = VectorXd::Zero(pts[0].size());
      int cnt = 0;
      for (std::size_t i = 0; i < n; ++i) {
        if (label[i] == c) sum += pts[i], ++cnt;
      }
      if (cnt > 0) centres[static_cast<std::size_t>(c)] = sum / cnt;
    }
  }
  return label;
}

MatrixXd shape(const MatrixXd& cov, Covariance c, const VectorXd& reg) {
  MatrixXd out = c == Covariance::Diagonal ? MatrixXd(cov.diagonal().asDiagonal()) : MatrixXd(0.5 * (cov + cov.transpose()));
  out.diagonal() += reg;
  return out;
}

}  // namespace

Hmm Hmm::train(const std::vector<Sequence>& data, const TrainOptions& o, TrainReport* report) {
  if (data.empty()) throw ModelError("training: no sequences");
  if (o.states < 1 || o.mixtures < 1) throw ModelError("training: states and mixtures must be >= 1");
  const auto D = data.front().cols();
  std::size_t frames = 0;
  for (std::size_t s = 0; s < data.size(); ++s) {
    if (data[s].cols() != D) throw ModelError("training: sequence " + std::to_string(s) + " has " + std::to_string(data[s].cols()) + " features, the first " + std::to_string(D));
    if (data[s].rows() == 0) throw ModelError("training: sequence " + std::to_string(s) + " is empty");
    if (!data[s].allFinite()) throw ModelError("training: sequence " + std::to_string(s) + " has NaN or infinite values");
    frames += static_cast<std::size_t>(data[s].rows());
  }
  const int N = o.states, M = o.mixtures;
  // Regularisation scaled to each feature's spread over all data.
  VectorXd mean = VectorXd::Zero(D), var = VectorXd::Zero(D);
  for (const auto& x : data) mean += x.colwise().sum().transpose();
  mean /= static_cast<double>(frames);
  for (const auto& x : data) var += (x.rowwise() - mean.transpose()).array().square().colwise().sum().matrix().transpose();
  var /= static_cast<double>(frames);
  const VectorXd reg = o.regularisation * var.cwiseMax(1e-12);
  const MatrixXd global_cov = MatrixXd(var.cwiseMax(1e-12).asDiagonal());

  // Initialisation: each sequence cut into N equal parts, state j taking the
  // j-th part of every sequence; k-means within a state for its mixtures.
  std::mt19937_64 rng(o.seed);
  std::vector<std::vector<VectorXd>> by_state(static_cast<std::size_t>(N));
  for (const auto& x : data) {
    for (Eigen::Index t = 0; t < x.rows(); ++t) {
      by_state[static_cast<std::size_t>(t * N / x.rows())].push_back(x.row(t).transpose());
    }
  }
  std::vector<GaussianMixture> em(static_cast<std::size_t>(N));
  for (int j = 0; j < N; ++j) {
    auto& pts = by_state[static_cast<std::size_t>(j)];
    if (pts.empty()) pts.push_back(mean);  // more states than frames in every sequence
    const auto label = kmeans(pts, M, rng);
    auto& g = em[static_cast<std::size_t>(j)];
    g.weights = VectorXd::Zero(M);
    for (int m = 0; m < M; ++m) {
      VectorXd mu = VectorXd::Zero(D);
      int cnt = 0;
      for (std::size_t i = 0; i < pts.size(); ++i) {
        if (label[i] == m) mu += pts[i], ++cnt;
      }
      MatrixXd cov = global_cov;
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
      g.covs.push_back(shape(cov, o.covariance, reg));
    }
    g.weights /= g.weights.sum();
  }
  VectorXd start = VectorXd::Zero(N);
  MatrixXd trans = MatrixXd::Zero(N, N);
  if (o.left_right) {
    start(0) = 1.0;
    for (int i = 0; i < N; ++i) {
      if (i + 1 < N) trans(i, i) = 0.6, trans(i, i + 1) = 0.4;
      else trans(i, i) = 1.0;
    }
  } else {
    start.setConstant(N > 1 ? 0.3 / (N - 1) : 1.0);
    start(0) = N > 1 ? 0.7 : 1.0;
    for (int i = 0; i < N; ++i) {
      if (N == 1) {
        trans(i, i) = 1.0;
        continue;
      }
      trans.row(i).setConstant(0.1 / (N - 1));
      trans(i, i) += 0.6;
      trans(i, (i + 1) % N) += 0.3;
      trans.row(i) /= trans.row(i).sum();
    }
  }
  Hmm h(N, static_cast<int>(D), o.covariance);
  h.set(start, trans, em);

  TrainReport rep;
  double previous = kNegInf;
  for (int iter = 0; iter <= o.max_iterations; ++iter) {
    // E-step over every sequence with the current parameters.
    VectorXd start_acc = VectorXd::Zero(N);
    MatrixXd trans_acc = MatrixXd::Zero(N, N);
    std::vector<VectorXd> n_acc(static_cast<std::size_t>(N), VectorXd::Zero(M));
    std::vector<std::vector<VectorXd>> x_acc(static_cast<std::size_t>(N), std::vector<VectorXd>(static_cast<std::size_t>(M), VectorXd::Zero(D)));
    std::vector<std::vector<MatrixXd>> xx_acc(static_cast<std::size_t>(N), std::vector<MatrixXd>(static_cast<std::size_t>(M), MatrixXd::Zero(D, D)));
    double total = 0;
    for (const auto& x : data) {
      const auto T = x.rows();
      const Pass p = h.pass(x, true);
      if (!std::isfinite(p.log_likelihood)) {
        throw ModelError("training: a sequence has zero likelihood under the model (a left-right model shorter than it needs?)");
      }
      total += p.log_likelihood;
      const MatrixXd gamma = p.alpha.cwiseProduct(p.beta);  // rows sum to 1
      start_acc += gamma.row(0).transpose();
      if (T > 1) {
        // xi summed over time: A .* (alpha[0..T-2]^T * (B .* beta)[1..T-1] / c)
        const MatrixXd W = (p.B.bottomRows(T - 1).cwiseProduct(p.beta.bottomRows(T - 1))).array().colwise() /
                           p.scale.tail(T - 1).array();
        trans_acc += h.trans_.cwiseProduct(p.alpha.topRows(T - 1).transpose() * W);
      }
      for (int j = 0; j < N; ++j) {
        const auto off = h.offsets_[static_cast<std::size_t>(j)];
        for (int m = 0; m < M; ++m) {
          const VectorXd r = gamma.col(j).cwiseProduct((p.comp.col(off + m) - p.logb.col(j)).array().exp().matrix());
          n_acc[static_cast<std::size_t>(j)](m) += r.sum();
          x_acc[static_cast<std::size_t>(j)][static_cast<std::size_t>(m)] += x.transpose() * r;
          // sum_t r_t x_t x_t^T as a symmetric rank-k update (half the work of a full product).
          const MatrixXd xs = (x.array().colwise() * r.array().sqrt()).matrix();
          xx_acc[static_cast<std::size_t>(j)][static_cast<std::size_t>(m)].selfadjointView<Eigen::Lower>().rankUpdate(xs.transpose());
        }
      }
    }
    rep.log_likelihood.push_back(total);
    const double gain = (total - previous) / static_cast<double>(frames);
    if (iter > 0 && gain < o.tolerance) {
      rep.converged = true;
      break;
    }
    if (iter == o.max_iterations) break;
    previous = total;
    rep.iterations = iter + 1;
    // M-step.
    VectorXd new_start = start_acc / start_acc.sum();
    MatrixXd new_trans = h.transitions();
    for (int i = 0; i < N; ++i) {
      const double s = trans_acc.row(i).sum();
      if (s > 1e-300) new_trans.row(i) = trans_acc.row(i) / s;
    }
    std::vector<GaussianMixture> new_em(static_cast<std::size_t>(N));
    for (int j = 0; j < N; ++j) {
      auto& g = new_em[static_cast<std::size_t>(j)];
      const auto& nj = n_acc[static_cast<std::size_t>(j)];
      g.weights = VectorXd::Zero(M);
      for (int m = 0; m < M; ++m) {
        const double n = nj(m);
        if (n < 1e-6) {
          // A component nothing belongs to: start it again on a random frame.
          const auto& x = data[std::uniform_int_distribution<std::size_t>(0, data.size() - 1)(rng)];
          g.means.push_back(x.row(std::uniform_int_distribution<Eigen::Index>(0, x.rows() - 1)(rng)).transpose());
          g.covs.push_back(shape(global_cov, o.covariance, reg));
          g.weights(m) = 1e-3;
          continue;
        }
        const VectorXd mu = x_acc[static_cast<std::size_t>(j)][static_cast<std::size_t>(m)] / n;
        const MatrixXd xx = xx_acc[static_cast<std::size_t>(j)][static_cast<std::size_t>(m)].selfadjointView<Eigen::Lower>();
        const MatrixXd cov = xx / n - mu * mu.transpose();
        g.means.push_back(mu);
        g.covs.push_back(shape(cov, o.covariance, reg));
        g.weights(m) = n;
      }
      g.weights /= g.weights.sum();
    }
    h.set(new_start, new_trans, std::move(new_em));
  }
  if (report) *report = rep;
  return h;
}

// --- JSON ---

nlohmann::json Hmm::to_json() const {
  nlohmann::json em = nlohmann::json::array();
  for (const auto& g : emissions_) {
    nlohmann::json means = nlohmann::json::array(), covs = nlohmann::json::array();
    for (const auto& m : g.means) means.push_back(std::vector<double>(m.data(), m.data() + m.size()));
    for (const auto& c : g.covs) {
      nlohmann::json rows = nlohmann::json::array();
      for (Eigen::Index r = 0; r < c.rows(); ++r) {
        const VectorXd row = c.row(r).transpose();
        rows.push_back(std::vector<double>(row.data(), row.data() + row.size()));
      }
      covs.push_back(rows);
    }
    em.push_back({{"weights", std::vector<double>(g.weights.data(), g.weights.data() + g.weights.size())},
                  {"means", means},
                  {"covariances", covs}});
  }
  const VectorXd s = start();
  const MatrixXd a = transitions();
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index r = 0; r < a.rows(); ++r) {
    const VectorXd row = a.row(r).transpose();
    rows.push_back(std::vector<double>(row.data(), row.data() + row.size()));
  }
  return {{"format", "skelgraph-hmm"},
          {"version", 1},
          {"states", states()},
          {"dim", dim_},
          {"covariance", covariance_ == Covariance::Full ? "full" : "diagonal"},
          {"start", std::vector<double>(s.data(), s.data() + s.size())},
          {"transitions", rows},
          {"emissions", em}};
}

Hmm Hmm::from_json(const nlohmann::json& j) {
  const auto need = [&](const nlohmann::json& o, const char* key, const std::string& where) -> const nlohmann::json& {
    if (!o.is_object() || !o.contains(key)) throw ModelError("model: missing '" + std::string(key) + "'" + where);
    return o.at(key);
  };
  if (!j.is_object() || j.value("format", "") != "skelgraph-hmm") throw ModelError("model: not a skelgraph HMM (expected \"format\": \"skelgraph-hmm\")");
  if (need(j, "version", "") != 1) throw ModelError("model: version " + j.at("version").dump() + " is not supported (expected 1)");
  const auto vec = [](const nlohmann::json& a, const std::string& what) {
    if (!a.is_array()) throw ModelError("model: " + what + " expects a list of numbers");
    VectorXd v(static_cast<Eigen::Index>(a.size()));
    for (std::size_t i = 0; i < a.size(); ++i) {
      if (!a[i].is_number()) throw ModelError("model: " + what + " expects numbers, got " + a[i].dump());
      v(static_cast<Eigen::Index>(i)) = a[i].get<double>();
    }
    return v;
  };
  const auto mat = [&](const nlohmann::json& a, const std::string& what, Eigen::Index n) {
    if (!a.is_array() || static_cast<Eigen::Index>(a.size()) != n) throw ModelError("model: " + what + " expects " + std::to_string(n) + " rows");
    MatrixXd m(n, n);
    for (Eigen::Index r = 0; r < n; ++r) {
      const VectorXd row = vec(a[static_cast<std::size_t>(r)], what + " row " + std::to_string(r));
      if (row.size() != n) throw ModelError("model: " + what + " row " + std::to_string(r) + " has " + std::to_string(row.size()) + " values, expected " + std::to_string(n));
      m.row(r) = row.transpose();
    }
    return m;
  };
  const int n = need(j, "states", "").get<int>();
  const int d = need(j, "dim", "").get<int>();
  const std::string cov = need(j, "covariance", "").get<std::string>();
  if (cov != "full" && cov != "diagonal") throw ModelError("model: 'covariance' must be \"full\" or \"diagonal\", got \"" + cov + "\"");
  if (n < 1 || d < 1) throw ModelError("model: 'states' and 'dim' must be >= 1");
  Hmm h(n, d, cov == "full" ? Covariance::Full : Covariance::Diagonal);
  const VectorXd start = vec(need(j, "start", ""), "'start'");
  if (start.size() != n) throw ModelError("model: 'start' has " + std::to_string(start.size()) + " values, expected " + std::to_string(n));
  const MatrixXd trans = mat(need(j, "transitions", ""), "'transitions'", n);
  const auto& em = need(j, "emissions", "");
  if (!em.is_array() || static_cast<int>(em.size()) != n) throw ModelError("model: 'emissions' expects one mixture per state");
  std::vector<GaussianMixture> mixtures;
  for (int s = 0; s < n; ++s) {
    const auto& e = em[static_cast<std::size_t>(s)];
    const std::string where = " in emissions[" + std::to_string(s) + "]";
    GaussianMixture g;
    g.weights = vec(need(e, "weights", where), "'weights'" + where);
    const auto& means = need(e, "means", where);
    const auto& covs = need(e, "covariances", where);
    if (!means.is_array() || !covs.is_array() || static_cast<Eigen::Index>(means.size()) != g.weights.size() ||
        static_cast<Eigen::Index>(covs.size()) != g.weights.size()) {
      throw ModelError("model: 'weights', 'means' and 'covariances' differ in count" + where);
    }
    for (std::size_t m = 0; m < means.size(); ++m) {
      g.means.push_back(vec(means[m], "'means'" + where));
      g.covs.push_back(mat(covs[m], "'covariances'" + where, d));
    }
    mixtures.push_back(std::move(g));
  }
  h.set(start, trans, std::move(mixtures));
  return h;
}

}  // namespace skelgraph::gesture

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
  centre_ = VectorXd::Zero(dim_);
  for (const auto& e : emissions_) {
    for (const auto& m : e.means) centre_ += m / static_cast<double>(off);
  }
  quadratic_coefficients(centre_, quad_);
}

VectorXd Hmm::start() const { return start_; }
MatrixXd Hmm::transitions() const { return trans_; }

void Hmm::emissions_of(const MatrixXd& x, Eigen::Ref<Pass::Rows> comp, Eigen::Ref<Pass::Rows> logb) const {
  if (x.cols() != dim_) throw ModelError("sequence has " + std::to_string(x.cols()) + " features per frame, the model " + std::to_string(dim_));
  comp.noalias() = quadratic_features(x.rowwise() - centre_.transpose(), covariance_) * quad_;
  states_of(comp, logb);
}

void Hmm::quadratic_coefficients(const VectorXd& centre, MatrixXd& c) const {
  c.resize(quadratic_size(dim_, covariance_), offsets_.back());
  for (int j = 0; j < states(); ++j) {
    const auto& g = emissions_[static_cast<std::size_t>(j)];
    for (std::size_t m = 0; m < g.means.size(); ++m) {
      gesture::quadratic_coefficients(g.means[m] - centre, g.precision(m), g.log_norm(m), covariance_,
                                      c.col(offsets_[static_cast<std::size_t>(j)] + static_cast<Eigen::Index>(m)));
    }
  }
}

void Hmm::states_of(const Eigen::Ref<const Pass::Rows>& comp, Eigen::Ref<Pass::Rows> logb) const {
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

namespace {

// Rows of a row-major matrix (or a block of one) as a pointer and a stride.
struct RowsView {
  double* data;
  Eigen::Index stride;
  double* row(Eigen::Index t) const { return data + t * stride; }
};

// The scaled forward (and backward) recursions. NN > 0 fixes the number of
// states at compile time, so that the N x N loops unroll into straight
// vector code (N is 2-10 in practice); NN = 0 takes N at run time.
template <int NN>
double forward_backward_kernel(int n, const double* start, const double* A_cols, const double* A_rows, RowsView logb,
                               RowsView B, RowsView alpha, RowsView beta, double* scale, Eigen::Index T, bool with_backward) {
  const int N = NN > 0 ? NN : n;
  double ll = 0;
  constexpr int kMaxStack = 16;
  double stack[kMaxStack];
  std::vector<double> heap(N > kMaxStack ? static_cast<std::size_t>(N) : 0);
  double* __restrict v = N > kMaxStack ? heap.data() : stack;
  for (Eigen::Index t = 0; t < T; ++t) {
    // Emissions scaled by the frame's largest.
    const double* __restrict lb = logb.row(t);
    double mx = lb[0];
    for (int j = 1; j < N; ++j) mx = std::max(mx, lb[j]);
    if (!std::isfinite(mx)) return kNegInf;  // no state can emit this frame
    double* __restrict b = B.row(t);
    for (int j = 0; j < N; ++j) b[j] = std::exp(lb[j] - mx);
    double* __restrict a = alpha.row(t);
    if (t == 0) {
      for (int j = 0; j < N; ++j) a[j] = start[j] * b[j];
    } else {
      const double* __restrict prev = alpha.row(t - 1);
      for (int j = 0; j < N; ++j) v[j] = 0;
      for (int i = 0; i < N; ++i) {
        const double p = prev[i];
        const double* __restrict row = A_rows + static_cast<std::ptrdiff_t>(i) * N;
        for (int j = 0; j < N; ++j) v[j] += p * row[j];
      }
      for (int j = 0; j < N; ++j) a[j] = v[j] * b[j];
    }
    double c = 0;
    for (int j = 0; j < N; ++j) c += a[j];
    if (!(c > 0)) return kNegInf;
    const double inv = 1.0 / c;
    for (int j = 0; j < N; ++j) a[j] *= inv;
    scale[t] = c;
    ll += std::log(c) + mx;
  }
  if (with_backward) {
    for (int j = 0; j < N; ++j) beta.row(T - 1)[j] = 1.0;
    for (Eigen::Index t = T - 2; t >= 0; --t) {
      const double* __restrict b = B.row(t + 1);
      const double* __restrict nb = beta.row(t + 1);
      double* __restrict out = beta.row(t);
      const double inv = 1.0 / scale[t + 1];
      for (int i = 0; i < N; ++i) out[i] = 0;
      for (int j = 0; j < N; ++j) {
        const double w = b[j] * nb[j] * inv;
        const double* __restrict col = A_cols + static_cast<std::ptrdiff_t>(j) * N;
        for (int i = 0; i < N; ++i) out[i] += col[i] * w;
      }
    }
  }
  return ll;
}

}  // namespace

double Hmm::forward_backward(const Eigen::Ref<const Pass::Rows>& logb, Eigen::Ref<Pass::Rows> B, Eigen::Ref<Pass::Rows> alpha,
                             Eigen::Ref<Pass::Rows> beta, Eigen::Ref<VectorXd> scale, bool with_backward) const {
  const int N = states();
  const Pass::Rows A_rows = trans_;  // row i contiguous: a_i*; trans_ (column-major) has column j contiguous
  const RowsView lb{const_cast<double*>(logb.data()), logb.outerStride()};
  const RowsView b{B.data(), B.outerStride()}, a{alpha.data(), alpha.outerStride()};
  const RowsView be{with_backward ? beta.data() : nullptr, with_backward ? beta.outerStride() : 0};
  const auto run = [&](auto kernel) {
    return kernel(N, start_.data(), trans_.data(), A_rows.data(), lb, b, a, be, scale.data(), logb.rows(), with_backward);
  };
  switch (N) {
    case 2: return run(forward_backward_kernel<2>);
    case 3: return run(forward_backward_kernel<3>);
    case 4: return run(forward_backward_kernel<4>);
    case 5: return run(forward_backward_kernel<5>);
    case 6: return run(forward_backward_kernel<6>);
    case 7: return run(forward_backward_kernel<7>);
    case 8: return run(forward_backward_kernel<8>);
    default: return run(forward_backward_kernel<0>);
  }
}

Hmm::Pass Hmm::pass(const Sequence& x, bool with_backward) const {
  if (x.cols() != dim_) throw ModelError("sequence has " + std::to_string(x.cols()) + " features per frame, the model " + std::to_string(dim_));
  Pass p;
  const auto T = x.rows();
  const int N = states();
  p.comp.resize(T, offsets_.back());
  p.logb.resize(T, N);
  emissions_of(x, p.comp, p.logb);
  p.B.resize(T, N);
  p.alpha.resize(T, N);
  p.scale.resize(T);
  p.beta.resize(with_backward ? T : 0, N);
  p.log_likelihood = forward_backward(p.logb, p.B, p.alpha, p.beta, p.scale, with_backward);
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
  Pass::Rows comp(T, offsets_.back()), logb(T, N);
  emissions_of(x, comp, logb);
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

VectorXd feature_spread(const std::vector<const Sequence*>& data, const VectorXd& constant, VectorXd* mean_out) {
  if (data.empty()) throw ModelError("feature_spread: no sequences");
  const auto D = data.front()->cols();
  VectorXd mean = VectorXd::Zero(D), var = VectorXd::Zero(D);
  double frames = 0;
  for (const auto* x : data) mean += x->colwise().sum().transpose(), frames += static_cast<double>(x->rows());
  mean /= frames;
  for (const auto* x : data) var += (x->rowwise() - mean.transpose()).array().square().colwise().sum().matrix().transpose();
  var /= frames;
  double typical = 0;
  int varied = 0;
  for (Eigen::Index d = 0; d < D; ++d)
    if (var(d) > 1e-12) typical += var(d), ++varied;
  typical = varied > 0 ? typical / varied : 1.0;
  for (Eigen::Index d = 0; d < D; ++d)
    if (var(d) <= 1e-12) var(d) = constant.size() == D && constant(d) > 1e-12 ? constant(d) : typical;
  if (mean_out) *mean_out = mean;
  return var;
}

// Baum-Welch over many sequences in its three steps, as mlpack's HMM::Train
// is laid out: initialise() the first model, expectation() of the counts
// under the current one, maximisation() into new parameters. Every frame of
// every sequence is stacked once, centred, as quadratic features (Q), so an
// iteration's emissions are the one product Q C and its statistics Q^T R.
class BaumWelch {
 public:
  BaumWelch(const std::vector<Sequence>& data, const TrainOptions& o, std::size_t frames)
      : data_(data), o_(o), frames_(frames), N_(o.states), M_(o.mixtures), D_(data.front().cols()), rng_(o.seed) {
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
  }

  // The first parameters. Init::Segments: each sequence cut into N equal
  // parts, state j taking the j-th part of every sequence; Init::KMeans: a
  // state per k-means cluster of all frames. Then k-means within a state for
  // its mixtures; the transitions as the options' shape asks.
  Hmm initialise() {
    const int N = N_, M = M_;
    const auto D = D_;
    std::vector<std::vector<VectorXd>> by_state(static_cast<std::size_t>(N));
    if (o_.init == Init::KMeans) {
      std::vector<VectorXd> all;
      all.reserve(frames_);
      for (const auto& x : data_)
        for (Eigen::Index t = 0; t < x.rows(); ++t) all.push_back(x.row(t).transpose());
      const auto label = kmeans(all, N, rng_);
      for (std::size_t i = 0; i < all.size(); ++i) by_state[static_cast<std::size_t>(label[i])].push_back(std::move(all[i]));
    } else {
      for (const auto& x : data_) {
        for (Eigen::Index t = 0; t < x.rows(); ++t) {
          by_state[static_cast<std::size_t>(t * N / x.rows())].push_back(x.row(t).transpose());
        }
      }
    }
    std::vector<GaussianMixture> em(static_cast<std::size_t>(N));
    for (int j = 0; j < N; ++j) {
      auto& pts = by_state[static_cast<std::size_t>(j)];
      if (pts.empty()) pts.push_back(mean_);  // more states than frames in every sequence, or an empty k-means cluster
      const auto label = kmeans(pts, M, rng_);
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
          mu = pts[std::uniform_int_distribution<std::size_t>(0, pts.size() - 1)(rng_)];
        }
        g.weights(m) = std::max(1.0, static_cast<double>(cnt));
        g.means.push_back(mu);
        g.covs.push_back(shape(cov, o_.covariance, reg_));
      }
      g.weights /= g.weights.sum();
    }
    VectorXd start = VectorXd::Zero(N);
    MatrixXd trans = MatrixXd::Zero(N, N);
    if (o_.left_right) {
      start(0) = 1.0;
      for (int i = 0; i < N; ++i) {
        if (i + 1 < N) trans(i, i) = 0.6, trans(i, i + 1) = 0.4;
        else trans(i, i) = 1.0;
      }
    } else if (o_.init == Init::KMeans) {
      start.setConstant(1.0 / N);
      trans.setConstant(1.0 / N);
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
    Hmm h(N, static_cast<int>(D), o_.covariance);
    h.set(start, trans, em);
    stack_frames();
    return h;
  }

  // Forward-backward over every sequence under `h`: the posteriors and
  // scaled recursions kept for maximisation(); the total log-likelihood.
  double expectation(const Hmm& h) {
    h.quadratic_coefficients(mean_, C_);
    comp_.noalias() = Q_ * C_;
    h.states_of(comp_, logb_);
    double total = 0;
    start_acc_ = VectorXd::Zero(N_);
    for (std::size_t s = 0; s < data_.size(); ++s) {
      const auto b = first_[s], T = first_[s + 1] - b;
      const double ll = h.forward_backward(logb_.middleRows(b, T), B_.middleRows(b, T), alpha_.middleRows(b, T),
                                           beta_.middleRows(b, T), scale_.segment(b, T), true);
      if (!std::isfinite(ll)) {
        throw ModelError("training: a sequence has zero likelihood under the model (a left-right model shorter than it needs?)");
      }
      total += ll;
      start_acc_ += alpha_.row(b).cwiseProduct(beta_.row(b)).transpose();
    }
    return total;
  }

  // New parameters for `h` from the last expectation().
  void maximisation(Hmm& h) {
    const int N = N_, M = M_;
    const auto F = static_cast<Eigen::Index>(frames_);
    // State posteriors (rows of alpha .* beta sum to 1) and, for xi summed
    // over time, A .* (alpha[t]^T * (B .* beta)[t+1] / c[t+1]) with no pair
    // across two sequences (W is zero on every sequence's first frame).
    const MatrixXd gamma = alpha_.cwiseProduct(beta_);
    W_ = B_.cwiseProduct(beta_);
    W_.array().colwise() /= scale_.array();
    for (std::size_t s = 0; s < data_.size(); ++s) W_.row(first_[s]).setZero();
    const MatrixXd trans_acc = h.trans_.cwiseProduct(alpha_.topRows(F - 1).transpose() * W_.bottomRows(F - 1));
    // Each component's responsibility for each frame, then its weighted sums.
    for (int j = 0; j < N; ++j) {
      const auto off = h.offsets_[static_cast<std::size_t>(j)];
      for (int m = 0; m < M; ++m) {
        if (M == 1) R_.col(off) = gamma.col(j);
        else R_.col(off + m) = gamma.col(j).cwiseProduct((comp_.col(off + m) - logb_.col(j)).array().exp().matrix());
      }
    }
    const MatrixXd S = Q_.transpose() * R_;  // per component: sum r, sum r x, sum r x_a x_b
    VectorXd new_start = start_acc_ / start_acc_.sum();
    MatrixXd new_trans = h.transitions();
    for (int i = 0; i < N; ++i) {
      const double s = trans_acc.row(i).sum();
      if (s > 1e-300) new_trans.row(i) = trans_acc.row(i) / s;
    }
    std::vector<GaussianMixture> new_em(static_cast<std::size_t>(N));
    for (int j = 0; j < N; ++j) {
      auto& g = new_em[static_cast<std::size_t>(j)];
      const auto off = h.offsets_[static_cast<std::size_t>(j)];
      g.weights = VectorXd::Zero(M);
      for (int m = 0; m < M; ++m) {
        const auto k = off + m;
        const double n = S(0, k);
        if (n < 1e-6) {
          // A component nothing belongs to: start it again on a random frame.
          const auto& x = data_[std::uniform_int_distribution<std::size_t>(0, data_.size() - 1)(rng_)];
          g.means.push_back(x.row(std::uniform_int_distribution<Eigen::Index>(0, x.rows() - 1)(rng_)).transpose());
          g.covs.push_back(shape(global_cov_, o_.covariance, reg_));
          g.weights(m) = 1e-3;
          continue;
        }
        VectorXd mu;
        MatrixXd cov;
        moments(S.col(k), D_, o_.covariance, mu, cov);
        mu += mean_;
        g.means.push_back(mu);
        g.covs.push_back(shape(cov, o_.covariance, reg_));
        g.weights(m) = n;
      }
      g.weights /= g.weights.sum();
    }
    h.set(new_start, new_trans, std::move(new_em));
  }

 private:
  // Every frame of every sequence stacked once, centred, as quadratic
  // features; the work matrices of the steps sized for them.
  void stack_frames() {
    const auto F = static_cast<Eigen::Index>(frames_);
    const int K = N_ * M_;  // components of all states, in Pass::comp's column order
    first_.assign(data_.size() + 1, 0);
    {
      MatrixXd xc(F, D_);
      for (std::size_t s = 0; s < data_.size(); ++s) {
        first_[s + 1] = first_[s] + data_[s].rows();
        xc.middleRows(first_[s], data_[s].rows()) = data_[s].rowwise() - mean_.transpose();
      }
      Q_ = quadratic_features(xc, o_.covariance);
    }
    C_.resize(Q_.cols(), K);
    R_.resize(F, K);
    comp_.resize(F, K);
    for (auto* m : {&logb_, &B_, &alpha_, &beta_, &W_}) m->resize(F, N_);
    scale_.resize(F);
  }

  const std::vector<Sequence>& data_;
  const TrainOptions& o_;
  const std::size_t frames_;
  const int N_, M_;
  const Eigen::Index D_;
  std::mt19937_64 rng_;
  VectorXd mean_, reg_;
  MatrixXd global_cov_;
  std::vector<Eigen::Index> first_;  // each sequence's first row in the stacked frames
  MatrixXd Q_, C_, R_;
  Hmm::Pass::Rows comp_, logb_, B_, alpha_, beta_, W_;
  VectorXd scale_, start_acc_;
};

Hmm Hmm::train(const std::vector<Sequence>& data, const TrainOptions& o, TrainReport* report) {
  if (data.empty()) throw ModelError("training: no sequences");
  if (o.states < 1 || o.mixtures < 1 || o.restarts < 1) throw ModelError("training: states, mixtures and restarts must be >= 1");
  if (o.left_right && o.init == Init::KMeans)
    throw ModelError("training: a left-right model needs the segments initialisation (k-means clusters come in no order)");
  const auto D = data.front().cols();
  std::size_t frames = 0;
  for (std::size_t s = 0; s < data.size(); ++s) {
    if (data[s].cols() != D) throw ModelError("training: sequence " + std::to_string(s) + " has " + std::to_string(data[s].cols()) + " features, the first " + std::to_string(D));
    if (data[s].rows() == 0) throw ModelError("training: sequence " + std::to_string(s) + " is empty");
    if (!data[s].allFinite()) throw ModelError("training: sequence " + std::to_string(s) + " has NaN or infinite values");
    frames += static_cast<std::size_t>(data[s].rows());
  }
  if (o.restarts > 1) {
    Hmm best;
    TrainReport best_report;
    double best_ll = kNegInf;
    for (int r = 0; r < o.restarts; ++r) {
      TrainOptions one = o;
      one.restarts = 1;
      one.seed = o.seed + 0x9E3779B97F4A7C15ULL * static_cast<std::uint64_t>(r);
      TrainReport rep;
      Hmm h = train(data, one, &rep);
      const double ll = rep.log_likelihood.empty() ? kNegInf : rep.log_likelihood.back();
      if (r == 0 || ll > best_ll) best = std::move(h), best_report = rep, best_ll = ll;
    }
    if (report) *report = best_report;
    return best;
  }
  BaumWelch bw(data, o, frames);
  Hmm h = bw.initialise();
  TrainReport rep;
  double previous = kNegInf;
  for (int iter = 0; iter <= o.max_iterations; ++iter) {
    const double total = bw.expectation(h);
    rep.log_likelihood.push_back(total);
    const double gain = (total - previous) / static_cast<double>(frames);
    if (iter > 0 && gain < o.tolerance) {
      rep.converged = true;
      break;
    }
    if (iter == o.max_iterations) break;
    previous = total;
    rep.iterations = iter + 1;
    bw.maximisation(h);
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

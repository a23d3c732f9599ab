#include "skelgraph/gesture/hmm.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace skelgraph::gesture {

using Eigen::MatrixXd;
using Eigen::VectorXd;

namespace {
constexpr double kNegInf = -std::numeric_limits<double>::infinity();
}  // namespace

double log_sum_exp(const VectorXd& v) {
  const double m = v.maxCoeff();
  if (m == kNegInf) return kNegInf;
  return m + std::log((v.array() - m).exp().sum());
}

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

namespace detail {

double safe_log(double p) { return p > 0 ? std::log(p) : kNegInf; }

void check_probabilities(const VectorXd& v, const std::string& what) {
  if (!v.allFinite() || (v.array() < 0).any()) throw ModelError("model: " + what + " has negative or non-finite entries");
  if (std::abs(v.sum() - 1.0) > 1e-6) throw ModelError("model: " + what + " sums to " + std::to_string(v.sum()) + ", expected 1");
}

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

const nlohmann::json& json_field(const nlohmann::json& o, const char* key, const std::string& where) {
  if (!o.is_object() || !o.contains(key)) throw ModelError("model: missing '" + std::string(key) + "'" + where);
  return o.at(key);
}

VectorXd json_vector(const nlohmann::json& a, const std::string& what) {
  if (!a.is_array()) throw ModelError("model: " + what + " expects a list of numbers");
  VectorXd v(static_cast<Eigen::Index>(a.size()));
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (!a[i].is_number()) throw ModelError("model: " + what + " expects numbers, got " + a[i].dump());
    v(static_cast<Eigen::Index>(i)) = a[i].get<double>();
  }
  return v;
}

MatrixXd json_matrix(const nlohmann::json& a, const std::string& what, Eigen::Index n) {
  if (!a.is_array() || static_cast<Eigen::Index>(a.size()) != n) throw ModelError("model: " + what + " expects " + std::to_string(n) + " rows");
  MatrixXd m(n, n);
  for (Eigen::Index r = 0; r < n; ++r) {
    const VectorXd row = json_vector(a[static_cast<std::size_t>(r)], what + " row " + std::to_string(r));
    if (row.size() != n) throw ModelError("model: " + what + " row " + std::to_string(r) + " has " + std::to_string(row.size()) + " values, expected " + std::to_string(n));
    m.row(r) = row.transpose();
  }
  return m;
}

nlohmann::json json_rows(const MatrixXd& m) {
  nlohmann::json rows = nlohmann::json::array();
  for (Eigen::Index r = 0; r < m.rows(); ++r) {
    const VectorXd row = m.row(r).transpose();
    rows.push_back(std::vector<double>(row.data(), row.data() + row.size()));
  }
  return rows;
}

std::size_t check_training(const std::vector<Sequence>& data, const TrainOptions& o) {
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
  return frames;
}

// --- The chain ---

void MarkovChain::set(const VectorXd& start, const MatrixXd& transitions) {
  const auto n = start.size();
  if (n < 1) throw ModelError("model: no states");
  if (transitions.rows() != n || transitions.cols() != n) throw ModelError("model: transitions are not N x N");
  check_probabilities(start, "'start'");
  for (Eigen::Index i = 0; i < n; ++i) check_probabilities(transitions.row(i).transpose(), "'transitions' row " + std::to_string(i));
  log_start_ = start.unaryExpr(&safe_log);
  log_trans_ = transitions.unaryExpr(&safe_log);
  start_ = start;
  trans_ = transitions;
  trans_rows_ = transitions;
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

double MarkovChain::forward_backward(const Eigen::Ref<const Rows>& logb, Eigen::Ref<Rows> B, Eigen::Ref<Rows> alpha,
                                     Eigen::Ref<Rows> beta, Eigen::Ref<VectorXd> scale, bool with_backward) const {
  const int N = states();
  const RowsView lb{const_cast<double*>(logb.data()), logb.outerStride()};
  const RowsView b{B.data(), B.outerStride()}, a{alpha.data(), alpha.outerStride()};
  const RowsView be{with_backward ? beta.data() : nullptr, with_backward ? beta.outerStride() : 0};
  const auto run = [&](auto kernel) {
    return kernel(N, start_.data(), trans_.data(), trans_rows_.data(), lb, b, a, be, scale.data(), logb.rows(), with_backward);
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

std::vector<int> MarkovChain::viterbi(const Eigen::Ref<const Rows>& logb, double* log_prob) const {
  const auto T = logb.rows();
  const int N = states();
  std::vector<int> path(static_cast<std::size_t>(T));
  if (T == 0) {
    if (log_prob) *log_prob = 0;
    return path;
  }
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

void MarkovChain::step(VectorXd& alpha, const VectorXd& logb, bool first) const {
  const int N = states();
  if (first) {
    alpha = log_start_ + logb;
    return;
  }
  VectorXd next(N), tmp(N);
  for (int j = 0; j < N; ++j) {
    tmp = alpha + log_trans_.col(j);
    next(j) = log_sum_exp(tmp) + logb(j);
  }
  alpha = next;
}

void MarkovChain::to_json(nlohmann::json& model) const {
  model["start"] = std::vector<double>(start_.data(), start_.data() + start_.size());
  model["transitions"] = json_rows(trans_);
}

MarkovChain MarkovChain::from_json(const nlohmann::json& model, int states) {
  const VectorXd start = json_vector(json_field(model, "start", ""), "'start'");
  if (start.size() != states) throw ModelError("model: 'start' has " + std::to_string(start.size()) + " values, expected " + std::to_string(states));
  MarkovChain c;
  c.set(start, json_matrix(json_field(model, "transitions", ""), "'transitions'", states));
  return c;
}

// --- The chain's side of Baum-Welch ---

MarkovChain::Trainer::Trainer(const std::vector<Sequence>& data, const TrainOptions& o)
    : data_(data), N_(o.states), left_right_(o.left_right), init_(o.init) {
  first_.assign(data.size() + 1, 0);
  for (std::size_t s = 0; s < data.size(); ++s) first_[s + 1] = first_[s] + data[s].rows();
  const auto F = first_.back();
  for (auto* m : {&B_, &alpha_, &beta_, &W_, &gamma_}) m->resize(F, N_);
  scale_.resize(F);
}

std::vector<int> MarkovChain::Trainer::initial_states(std::mt19937_64& rng) const {
  if (init_ == Init::KMeans) {
    std::vector<VectorXd> all;
    all.reserve(static_cast<std::size_t>(first_.back()));
    for (const auto& x : data_)
      for (Eigen::Index t = 0; t < x.rows(); ++t) all.push_back(x.row(t).transpose());
    return kmeans(all, N_, rng);
  }
  std::vector<int> state;
  state.reserve(static_cast<std::size_t>(first_.back()));
  for (const auto& x : data_)
    for (Eigen::Index t = 0; t < x.rows(); ++t) state.push_back(static_cast<int>(t * N_ / x.rows()));
  return state;
}

MarkovChain MarkovChain::Trainer::initial() const {
  const int N = N_;
  VectorXd start = VectorXd::Zero(N);
  MatrixXd trans = MatrixXd::Zero(N, N);
  if (left_right_) {
    start(0) = 1.0;
    for (int i = 0; i < N; ++i) {
      if (i + 1 < N) trans(i, i) = 0.6, trans(i, i + 1) = 0.4;
      else trans(i, i) = 1.0;
    }
  } else if (init_ == Init::KMeans) {
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
  MarkovChain c;
  c.set(start, trans);
  return c;
}

double MarkovChain::Trainer::expectation(const MarkovChain& c, const Rows& logb) {
  double total = 0;
  start_acc_ = VectorXd::Zero(N_);
  for (std::size_t s = 0; s < data_.size(); ++s) {
    const auto b = first_[s], T = first_[s + 1] - b;
    const double ll = c.forward_backward(logb.middleRows(b, T), B_.middleRows(b, T), alpha_.middleRows(b, T),
                                         beta_.middleRows(b, T), scale_.segment(b, T), true);
    if (!std::isfinite(ll)) {
      throw ModelError("training: a sequence has zero likelihood under the model (a left-right model shorter than it needs?)");
    }
    total += ll;
    start_acc_ += alpha_.row(b).cwiseProduct(beta_.row(b)).transpose();
  }
  return total;
}

const Rows& MarkovChain::Trainer::posteriors() {
  gamma_ = alpha_.cwiseProduct(beta_);  // rows of alpha .* beta sum to 1
  return gamma_;
}

MarkovChain MarkovChain::Trainer::maximisation(const MarkovChain& c) {
  const int N = N_;
  const auto F = first_.back();
  // xi summed over time: A .* (alpha[t]^T * (B .* beta)[t+1] / c[t+1]) with no
  // pair across two sequences (W is zero on every sequence's first frame).
  W_ = B_.cwiseProduct(beta_);
  W_.array().colwise() /= scale_.array();
  for (std::size_t s = 0; s < data_.size(); ++s) W_.row(first_[s]).setZero();
  const MatrixXd trans_acc = c.trans_.cwiseProduct(alpha_.topRows(F - 1).transpose() * W_.bottomRows(F - 1));
  const VectorXd new_start = start_acc_ / start_acc_.sum();
  MatrixXd new_trans = c.transitions();
  for (int i = 0; i < N; ++i) {
    const double s = trans_acc.row(i).sum();
    if (s > 1e-300) new_trans.row(i) = trans_acc.row(i) / s;
  }
  MarkovChain out;
  out.set(new_start, new_trans);
  return out;
}

}  // namespace detail

}  // namespace skelgraph::gesture

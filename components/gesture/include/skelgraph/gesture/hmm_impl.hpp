#pragma once
// Hmm<Emission> and BaumWelch<Emission> (hmm.hpp); the emission-free parts
// are in hmm.cpp.

#include <cmath>
#include <limits>

#include "skelgraph/gesture/hmm.hpp"

namespace skelgraph::gesture {

template <class Emission>
Hmm<Emission>::Hmm(Emission emission) {
  const int n = emission.states();
  set(Eigen::VectorXd::Constant(n, 1.0 / n), Eigen::MatrixXd::Constant(n, n, 1.0 / n), std::move(emission));
}

template <class Emission>
void Hmm<Emission>::set(const Eigen::VectorXd& start, const Eigen::MatrixXd& transitions, Emission emission) {
  detail::MarkovChain chain;
  chain.set(start, transitions);
  set(std::move(chain), std::move(emission));
}

template <class Emission>
void Hmm<Emission>::set(detail::MarkovChain chain, Emission emission) {
  if (emission.states() != chain.states())
    throw ModelError("model: emissions for " + std::to_string(emission.states()) + " states, transitions for " +
                     std::to_string(chain.states()));
  chain_ = std::move(chain);
  emission_ = std::move(emission);
}

template <class Emission>
typename Hmm<Emission>::Pass Hmm<Emission>::pass(const Sequence& x, bool with_backward) const {
  if (x.cols() != dim()) throw ModelError("sequence has " + std::to_string(x.cols()) + " features per frame, the model " + std::to_string(dim()));
  Pass p;
  const auto T = x.rows();
  const int N = states();
  p.logb.resize(T, N);
  emission_.log_probabilities(x, p.emission, p.logb);
  p.B.resize(T, N);
  p.alpha.resize(T, N);
  p.scale.resize(T);
  p.beta.resize(with_backward ? T : 0, N);
  p.log_likelihood = chain_.forward_backward(p.logb, p.B, p.alpha, p.beta, p.scale, with_backward);
  return p;
}

template <class Emission>
double Hmm<Emission>::log_likelihood(const Sequence& x) const {
  if (x.rows() == 0) return 0.0;
  return pass(x, false).log_likelihood;
}

template <class Emission>
std::vector<int> Hmm<Emission>::viterbi(const Sequence& x, double* log_prob) const {
  if (x.rows() == 0) {
    if (log_prob) *log_prob = 0;
    return {};
  }
  if (x.cols() != dim()) throw ModelError("sequence has " + std::to_string(x.cols()) + " features per frame, the model " + std::to_string(dim()));
  typename Emission::Workspace w;
  Rows logb(x.rows(), states());
  emission_.log_probabilities(x, w, logb);
  return chain_.viterbi(logb, log_prob);
}

template <class Emission>
Eigen::MatrixXd Hmm<Emission>::posteriors(const Sequence& x) const {
  const Pass p = pass(x, true);
  if (!std::isfinite(p.log_likelihood)) throw ModelError("posteriors: the sequence is impossible under the model");
  Eigen::MatrixXd g = p.alpha.cwiseProduct(p.beta);
  for (Eigen::Index t = 0; t < g.rows(); ++t) g.row(t) /= g.row(t).sum();
  return g;
}

template <class Emission>
double Hmm<Emission>::Stream::step(const Eigen::VectorXd& x) {
  const Hmm& m = *model_;
  Eigen::VectorXd logb(m.states());
  m.emission_.log_probabilities(x, logb);
  m.chain_.step(alpha_, logb, frames_ == 0);
  ++frames_;
  return log_sum_exp(alpha_);
}

template <class Emission>
Hmm<Emission> Hmm<Emission>::train(const std::vector<Sequence>& data, const TrainOptions& o, TrainReport* report) {
  const std::size_t frames = detail::check_training(data, o);
  if (o.restarts > 1) {
    Hmm best;
    TrainReport best_report;
    double best_ll = -std::numeric_limits<double>::infinity();
    for (int r = 0; r < o.restarts; ++r) {
      TrainOptions one = o;
      one.restarts = 1;
      one.seed = o.seed + 0x9E3779B97F4A7C15ULL * static_cast<std::uint64_t>(r);
      TrainReport rep;
      Hmm h = train(data, one, &rep);
      const double ll = rep.log_likelihood.empty() ? -std::numeric_limits<double>::infinity() : rep.log_likelihood.back();
      if (r == 0 || ll > best_ll) best = std::move(h), best_report = rep, best_ll = ll;
    }
    if (report) *report = best_report;
    return best;
  }
  BaumWelch<Emission> bw(data, o);
  Hmm h = bw.initialise();
  TrainReport rep;
  double previous = -std::numeric_limits<double>::infinity();
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

template <class Emission>
nlohmann::json Hmm<Emission>::to_json() const {
  nlohmann::json j{{"format", "skelgraph-hmm"}, {"version", 1}, {"states", states()}, {"dim", dim()}};
  chain_.to_json(j);
  emission_.to_json(j);
  return j;
}

template <class Emission>
Hmm<Emission> Hmm<Emission>::from_json(const nlohmann::json& j) {
  if (!j.is_object() || j.value("format", "") != "skelgraph-hmm") throw ModelError("model: not a skelgraph HMM (expected \"format\": \"skelgraph-hmm\")");
  if (detail::json_field(j, "version", "") != 1) throw ModelError("model: version " + j.at("version").dump() + " is not supported (expected 1)");
  const int n = detail::json_field(j, "states", "").get<int>();
  const int d = detail::json_field(j, "dim", "").get<int>();
  if (n < 1 || d < 1) throw ModelError("model: 'states' and 'dim' must be >= 1");
  detail::MarkovChain chain = detail::MarkovChain::from_json(j, n);
  Hmm h;
  h.set(std::move(chain), Emission::from_json(j, n, d));
  return h;
}

// --- Training ---

template <class Emission>
Hmm<Emission> BaumWelch<Emission>::initialise() {
  const std::vector<int> state = chain_.initial_states(rng_);
  Emission e = emission_.initialise(state, rng_);
  Hmm<Emission> h;
  h.set(chain_.initial(), std::move(e));
  return h;
}

template <class Emission>
double BaumWelch<Emission>::expectation(const Hmm<Emission>& h) {
  return chain_.expectation(h.chain_, emission_.log_probabilities(h.emission_));
}

template <class Emission>
void BaumWelch<Emission>::maximisation(Hmm<Emission>& h) {
  const Rows& gamma = chain_.posteriors();
  for (std::size_t s = 0; s < chain_.sequences(); ++s) emission_.accumulate(s, gamma.middleRows(chain_.first(s), chain_.length(s)));
  Emission e = emission_.finish(h.emission_, rng_);
  h.set(chain_.maximisation(h.chain_), std::move(e));
}

}  // namespace skelgraph::gesture

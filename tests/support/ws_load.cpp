// Load on the viewer: N WebSocket clients reading frames for S seconds, plus
// the clients that must not disturb anyone: one that never reads (stalled),
// one that sends malformed messages, one that drops its connection
// mid-stream over and over. Prints a JSON report: per reading client the
// frames per second and the delay from the frame's making (its made_ns,
// CLOCK_MONOTONIC on this host) to its arrival, early and late in the run.
//   ws_load --port 8080 [--clients 20] [--seconds 30]
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstring>
#include <ctime>
#include <memory>
#include <thread>
#include <string>
#include <vector>

#include <boost/asio.hpp>
#include <boost/beast/core.hpp>
#include <boost/beast/websocket.hpp>
#include <nlohmann/json.hpp>

namespace beast = boost::beast;
namespace websocket = beast::websocket;
namespace net = boost::asio;
using tcp = net::ip::tcp;

namespace {

std::int64_t mono_ns() {
  timespec ts{};
  clock_gettime(CLOCK_MONOTONIC, &ts);
  return std::int64_t(ts.tv_sec) * 1'000'000'000 + ts.tv_nsec;
}

double percentile(std::vector<double> v, double p) {
  if (v.empty()) return -1;
  std::sort(v.begin(), v.end());
  return v[std::min(v.size() - 1, static_cast<std::size_t>(p * (v.size() - 1) + 0.5))];
}

struct Options {
  std::string host = "127.0.0.1";
  std::string port = "8080";
  int clients = 20;
  double seconds = 30;
};

// A reading client: counts frames and their delay.
class Reader : public std::enable_shared_from_this<Reader> {
 public:
  Reader(net::io_context& ioc, const Options& o, std::int64_t t0, std::int64_t t_end)
      : ws_(ioc), resolver_(ioc), o_(o), t0_(t0), t_end_(t_end) {}
  void start() {
    resolver_.async_resolve(o_.host, o_.port, [self = shared_from_this()](beast::error_code ec, tcp::resolver::results_type r) {
      if (ec) return self->fail("resolve", ec);
      beast::get_lowest_layer(self->ws_).async_connect(r, [self](beast::error_code ec2, tcp::endpoint) {
        if (ec2) return self->fail("connect", ec2);
        self->ws_.async_handshake(self->o_.host, "/ws", [self](beast::error_code ec3) {
          if (ec3) return self->fail("handshake", ec3);
          self->read();
        });
      });
    });
  }
  nlohmann::json report() const {
    const double span_s = (o_.seconds - 5.0 > 0 ? o_.seconds - 5.0 : o_.seconds);
    return {{"frames", frames_},
            {"frames_per_s", frames_late_ / span_s},
            {"seq_gaps", seq_gaps_},
            {"delay_ms_early_median", percentile(delay_early_, 0.5)},
            {"delay_ms_late_median", percentile(delay_late_, 0.5)},
            {"delay_ms_late_p99", percentile(delay_late_, 0.99)},
            {"error", error_}};
  }

 private:
  void read() {
    ws_.async_read(buf_, [self = shared_from_this()](beast::error_code ec, std::size_t) {
      if (ec) return self->fail("read", ec);
      const auto now = mono_ns();
      const auto m = nlohmann::json::parse(beast::buffers_to_string(self->buf_.data()), nullptr, false);
      self->buf_.consume(self->buf_.size());
      if (m.is_object() && m.value("type", "") == "frame") {
        ++self->frames_;
        const double delay_ms = (now - m.value("made_ns", std::int64_t{0})) / 1e6;
        const auto seq = m.value("seq", std::uint64_t{0});
        if (self->last_seq_ != 0 && seq != self->last_seq_ + 1) self->seq_gaps_ += 1;
        self->last_seq_ = seq;
        if (now - self->t0_ < 5'000'000'000) self->delay_early_.push_back(delay_ms);
        else {
          self->delay_late_.push_back(delay_ms);
          ++self->frames_late_;
        }
      }
      if (now >= self->t_end_) {
        beast::error_code ignored;
        self->ws_.close(websocket::close_code::normal, ignored);
        return;
      }
      self->read();
    });
  }
  void fail(const char* what, beast::error_code ec) {
    if (mono_ns() < t_end_) error_ = std::string(what) + ": " + ec.message();
  }

  websocket::stream<beast::tcp_stream> ws_;
  tcp::resolver resolver_;
  Options o_;
  std::int64_t t0_, t_end_;
  beast::flat_buffer buf_;
  std::uint64_t frames_ = 0, frames_late_ = 0, last_seq_ = 0, seq_gaps_ = 0;
  std::vector<double> delay_early_, delay_late_;
  std::string error_;
};

// receive_buffer > 0: the socket's receive buffer, set before connecting so the
// window it offers is that small from the start.
websocket::stream<tcp::socket> connect_sync(net::io_context& ioc, const Options& o, int receive_buffer = 0) {
  tcp::resolver resolver(ioc);
  websocket::stream<tcp::socket> ws(ioc);
  const auto endpoints = resolver.resolve(o.host, o.port);
  if (receive_buffer > 0) {
    ws.next_layer().open(endpoints.begin()->endpoint().protocol());
    ws.next_layer().set_option(net::socket_base::receive_buffer_size(receive_buffer));
    ws.next_layer().connect(endpoints.begin()->endpoint());
  } else {
    net::connect(ws.next_layer(), endpoints);
  }
  ws.handshake(o.host, "/ws");
  return ws;
}

}  // namespace

int main(int argc, char** argv) {
  Options o;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string a = argv[i], v = argv[i + 1];
    if (a == "--port") o.port = v;
    else if (a == "--host") o.host = v;
    else if (a == "--clients") o.clients = std::stoi(v);
    else if (a == "--seconds") o.seconds = std::stod(v);
    else {
      std::fprintf(stderr, "usage: ws_load --port P [--host H] [--clients N] [--seconds S]\n");
      return 2;
    }
  }
  const auto t0 = mono_ns();
  const auto t_end = t0 + static_cast<std::int64_t>(o.seconds * 1e9);
  net::io_context ioc;
  std::vector<std::shared_ptr<Reader>> readers;
  for (int i = 0; i < o.clients; ++i) {
    readers.push_back(std::make_shared<Reader>(ioc, o, t0, t_end));
    readers.back()->start();
  }
  std::thread io([&] { ioc.run(); });

  nlohmann::json misc;
  // Stalled: handshakes, then never reads; its socket buffers fill up.
  net::io_context side;
  auto stalled = connect_sync(side, o, 4096);  // a small receive buffer fills sooner
  // Malformed: answered with errors, the connection stays usable; an oversized message ends only that connection.
  int errors_answered = 0;
  bool still_open_after_garbage = false, closed_after_oversize = false;
  try {
    auto bad = connect_sync(side, o);
    const std::vector<std::string> junk = {"not json", "[1,2,3]", R"({"cmd":42})", R"({"cmd":"play","kind":"rewind"})",
                                           R"({"cmd":"play","kind":"speed"})", std::string(300, '{')};
    for (const auto& j : junk) bad.write(net::buffer(j));
    beast::flat_buffer b;
    int reads = 0;
    while (errors_answered < static_cast<int>(junk.size()) && reads++ < 400) {
      bad.read(b);
      const auto m = nlohmann::json::parse(beast::buffers_to_string(b.data()), nullptr, false);
      b.consume(b.size());
      if (m.is_object() && m.value("type", "") == "error") ++errors_answered;
    }
    // Still receiving frames after the junk.
    bad.read(b);
    still_open_after_garbage = nlohmann::json::parse(beast::buffers_to_string(b.data()), nullptr, false).value("type", "") == "frame";
    b.consume(b.size());
    try {  // the server may close the connection while the message is still being written
      bad.write(net::buffer(std::string(100000, 'x')));
      for (int i = 0; i < 1000; ++i) {
        bad.read(b);
        b.consume(b.size());
      }
    } catch (const beast::system_error&) {
      closed_after_oversize = true;
    }
  } catch (const std::exception& e) {
    misc["malformed_client_error"] = e.what();
  }
  // Churn: connect, read a frame or two, drop the TCP connection without a close frame; again.
  int churned = 0;
  while (mono_ns() < t_end - 1'000'000'000) {
    try {
      auto c = connect_sync(side, o);
      beast::flat_buffer b;
      c.read(b);
      c.next_layer().close();  // abrupt: no WebSocket close
      ++churned;
    } catch (const std::exception& e) {
      misc["churn_error"] = e.what();
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));
  }
  io.join();

  nlohmann::json clients = nlohmann::json::array();
  std::vector<double> rates, late_medians;
  int failed = 0;
  for (const auto& r : readers) {
    auto j = r->report();
    rates.push_back(j["frames_per_s"].get<double>());
    late_medians.push_back(j["delay_ms_late_median"].get<double>());
    if (!j["error"].get<std::string>().empty()) ++failed;
    clients.push_back(std::move(j));
  }
  misc["errors_answered"] = errors_answered;
  misc["still_open_after_garbage"] = still_open_after_garbage;
  misc["closed_after_oversize"] = closed_after_oversize;
  misc["churned_connections"] = churned;
  const nlohmann::json out = {{"clients", o.clients},
                              {"seconds", o.seconds},
                              {"failed_clients", failed},
                              {"frames_per_s_min", *std::min_element(rates.begin(), rates.end())},
                              {"frames_per_s_median", percentile(rates, 0.5)},
                              {"delay_ms_late_median_max", *std::max_element(late_medians.begin(), late_medians.end())},
                              {"misbehaving", misc},
                              {"per_client", clients}};
  std::printf("%s\n", out.dump(1).c_str());
  return 0;
}

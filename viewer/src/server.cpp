#include "viewer/server.h"

#include "http_server.h"
#include "page.h"
#include "viewer/encode.h"
#include "viewer/queue.h"

#include <unistd.h>
#include <cerrno>
#include <csignal>
#include <cstdio>
#include <set>
#include <stdexcept>
#include <thread>

namespace viewer {
using common::dump_json;
using common::Json;
namespace {

using Clock = std::chrono::steady_clock;
double elapsed_ms(Clock::time_point start) {
  return std::chrono::duration<double, std::milli>(Clock::now() - start).count();
}

// SIGINT/SIGTERM may arrive on any thread (TBB's workers do not block them), so the handler
// only writes a byte to a pipe; a watcher thread reads it and stops the server.
int g_signal_pipe[2] = {-1, -1};
extern "C" void on_stop_signal(int) {
  const char byte = 's';
  [[maybe_unused]] const ssize_t n = write(g_signal_pipe[1], &byte, 1);
}

class StopSignals {
 public:
  StopSignals() {
    if (pipe(g_signal_pipe) != 0) throw std::runtime_error("prtr view: cannot create a pipe");
    struct sigaction sa {};
    sa.sa_handler = on_stop_signal;
    sigemptyset(&sa.sa_mask);
    sigaction(SIGINT, &sa, &old_int_);
    sigaction(SIGTERM, &sa, &old_term_);
    // A browser closing a connection mid-frame must not kill the server.
    std::signal(SIGPIPE, SIG_IGN);
  }
  ~StopSignals() {
    sigaction(SIGINT, &old_int_, nullptr);
    sigaction(SIGTERM, &old_term_, nullptr);
    close(g_signal_pipe[0]);
    close(g_signal_pipe[1]);
  }
  // Blocks until a signal (or wake()).
  void wait() {
    char byte = 0;
    while (read(g_signal_pipe[0], &byte, 1) < 0 && errno == EINTR) {
    }
  }
  void wake() { on_stop_signal(0); }

 private:
  struct sigaction old_int_ {
  }, old_term_{};
};

using detail::HttpHead;
using detail::HttpResponse;
using detail::text_response;

HttpResponse frame_response(const FramePtr& frame) {
  if (!frame->request_error.empty()) return text_response(400, frame->request_error);
  if (!frame->server_error.empty())
    return text_response(500, "rendering failed: " + frame->server_error);
  std::call_once(frame->encoded, [&] {
    const auto start = Clock::now();
    std::vector<std::uint8_t> rgb = render::tone_map_rgb8(frame->image, frame->state.exposure);
    if (frame->overlay)
      composite_overlay(rgb, frame->image.width, frame->image.height, *frame->overlay,
                        frame->overlay_opacity);
    frame->jpeg = encode_jpeg(rgb, frame->image.width, frame->image.height);
    frame->encode_ms = elapsed_ms(start);
  });
  HttpResponse res;
  res.content_type = "image/jpeg";
  res.body.assign(frame->jpeg.begin(), frame->jpeg.end());
  res.headers = {{"Cache-Control", "no-store"}, {"X-Prtr-Frame", dump_json(frame_header(*frame))}};
  return res;
}

HttpResponse handle_frame(FrameQueue& queue, const ServedInfo& served, const std::string& query) {
  ViewState state;
  try {
    state = parse_view_request(parse_query(query), served.limits, served.defaults);
  } catch (const RequestError& e) {
    return text_response(400, e.what());
  }
  try {
    return frame_response(queue.submit(state).get());
  } catch (const QueueRefused& e) {
    return text_response(503, e.what());
  }
}

// A web page the user visits may reach 127.0.0.1 through DNS rebinding: its requests carry
// its own host name. Only the address the server listens on and localhost are served.
bool allowed_host(const std::string& host_header, const ServerOptions& options, int port) {
  const std::string port_text = std::to_string(port);
  const std::size_t colon = host_header.rfind(':');
  if (colon == std::string::npos || host_header.compare(colon + 1, std::string::npos, port_text))
    return false;
  const std::string name = host_header.substr(0, colon);
  return name == options.host || name == "localhost";
}

// The routes, read-only: every path answers GET and HEAD, other methods 405.
class Routes {
 public:
  Routes(FrameQueue& queue, const ServedInfo& served, const ServerOptions& options)
      : queue_(queue), served_(served), options_(options), info_(dump_json(served.info)) {}
  void set_port(int port) { port_ = port; }

  HttpResponse operator()(const HttpHead& req) const {
    const std::string* host = req.field("host");
    if (host == nullptr || !allowed_host(*host, options_, port_)) {
      const std::string port = std::to_string(port_);
      return text_response(421, "Host '" + (host ? *host : std::string()) +
                                    "' is not this server; use " + options_.host + ":" + port +
                                    " or localhost:" + port);
    }
    if (req.method != "GET" && req.method != "HEAD") {
      // RFC 9110 Sec. 15.6.2: 501 for a method the server does not know at all.
      static const std::set<std::string> known = {"POST",    "PUT",     "DELETE", "PATCH",
                                                  "OPTIONS", "CONNECT", "TRACE"};
      if (known.count(req.method) == 0)
        return text_response(501, req.method + " is not an HTTP method prtr view knows");
      HttpResponse res = text_response(405, req.method + " is not allowed; prtr view answers GET");
      res.headers = {{"Allow", "GET, HEAD"}};
      return res;
    }
    // The raw query, split here and parsed strictly by parse_query.
    const std::size_t mark = req.target.find('?');
    const std::string path = req.target.substr(0, mark);
    const std::string query = mark == std::string::npos ? "" : req.target.substr(mark + 1);
    if (path == "/") {
      HttpResponse res;
      res.content_type = "text/html; charset=utf-8";
      res.body = view_page_html();
      return res;
    }
    if (path == "/api/info") {
      HttpResponse res;
      res.content_type = "application/json";
      res.body = info_;
      return res;
    }
    if (path == "/frame") return handle_frame(queue_, served_, query);
    // Browsers ask for it on every page load; no icon, and no 404 in their console.
    if (path == "/favicon.ico") return HttpResponse{204, {}, {}, {}};
    return text_response(404, "not found");
  }

 private:
  FrameQueue& queue_;
  const ServedInfo& served_;
  const ServerOptions& options_;
  const std::string info_;
  int port_ = 0;
};

// The render loop: one job at a time until the queue stops.
void render_jobs(FrameSource& scene, FrameQueue& queue) {
  while (std::optional<FrameQueue::Job> job = queue.take()) {
    const double queued = elapsed_ms(job->submitted);
    std::shared_ptr<RenderedFrame> frame = scene.render(job->state);
    frame->stats.queue_ms = queued;
    frame->stats.requests = job->requests;
    job->promise.set_value(std::move(frame));
  }
}

}  // namespace

Json frame_header(const RenderedFrame& f) {
  const ViewState& s = f.state;
  const FrameStats& t = f.stats;
  return Json{{"kind", t.kind},
              {"seq", s.seq},
              {"width", s.width},
              {"height", s.height},
              {"mode", render::kModeNames.name(s.mode)},
              {"strategy", s.strategy},
              {"probe", s.probe},
              {"overlay", kOverlayNames.name(s.overlay)},
              {"aa", s.samples},
              {"env_yaw", s.env_yaw},
              {"env_pitch", s.env_pitch},
              {"cam_yaw", s.cam_yaw},
              {"cam_pitch", s.cam_pitch},
              {"zoom", s.zoom},
              {"passes", t.passes},
              {"average_overdraw", t.average_overdraw},
              {"clusters_per_pass", t.clusters_per_pass},
              {"register_budget", t.register_budget},
              {"queue_ms", t.queue_ms},
              {"setup_ms", t.setup_ms},
              {"render_ms", t.render_ms},
              {"frame_ms", t.frame_ms},
              {"readback_ms", t.readback_ms},
              {"cpu_ms", t.cpu_ms},
              {"gl_ms", t.gl_ms},
              {"overlay_ms", t.overlay_ms},
              {"difference_rms", t.difference_rms},
              {"difference_max", t.difference_max},
              {"encode_ms", f.encode_ms},
              {"requests", t.requests},
              {"clusters", t.clusters},
              {"pcs", t.pcs},
              {"order", t.order},
              {"compressing", t.compressing},
              {"compress_progress", t.compress_progress},
              {"compress_error", t.compress_error}};
}

void serve_view(FrameSource& scene, const ServedInfo& served, const ServerOptions& options) {
  FrameQueue queue;
  Routes routes(queue, served, options);
  detail::HttpServerOptions http;
  http.host = options.host;
  http.port = options.port;
  http.max_connections = std::size_t(options.max_connections);
  detail::HttpServer server(http, [&routes](const HttpHead& req) { return routes(req); });
  routes.set_port(server.port());
  StopSignals signals;
  std::printf("prtr view: http://%s:%d/\n", options.host.c_str(), server.port());
  std::fflush(stdout);
  std::thread connections([&] { server.serve(); });
  std::thread watcher([&] {
    signals.wait();
    queue.stop();
    server.stop();
  });
  render_jobs(scene, queue);
  server.stop();
  signals.wake();  // the watcher, when the loop ended without a signal
  watcher.join();
  connections.join();
  const FrameQueue::Counters c = queue.counters();
  std::printf("prtr view: stopped after %llu frame requests (%llu coalesced)\n",
              static_cast<unsigned long long>(c.requests),
              static_cast<unsigned long long>(c.coalesced));
}

}  // namespace viewer

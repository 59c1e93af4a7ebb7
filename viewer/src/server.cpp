#include "viewer/server.h"

#include "connection_threads.h"

#include "page.h"
#include "viewer/encode.h"
#include "viewer/queue.h"

#include <httplib.h>

#include <sys/socket.h>
#include <unistd.h>
#include <atomic>
#include <cerrno>
#include <csignal>
#include <cstdio>
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

void send_frame(const FramePtr& frame, httplib::Response& res) {
  if (!frame->request_error.empty()) {
    res.status = 400;
    res.set_content(frame->request_error + "\n", "text/plain");
    return;
  }
  if (!frame->server_error.empty()) {
    res.status = 500;
    res.set_content("rendering failed: " + frame->server_error + "\n", "text/plain");
    return;
  }
  std::call_once(frame->encoded, [&] {
    const auto start = Clock::now();
    std::vector<std::uint8_t> rgb = render::tone_map_rgb8(frame->image, frame->state.exposure);
    if (frame->overlay)
      composite_overlay(rgb, frame->image.width, frame->image.height, *frame->overlay,
                        frame->overlay_opacity);
    frame->jpeg = encode_jpeg(rgb, frame->image.width, frame->image.height);
    frame->encode_ms = elapsed_ms(start);
  });
  res.set_header("Cache-Control", "no-store");
  res.set_header("X-Prtr-Frame", dump_json(frame_header(*frame)));
  res.set_content(std::string(frame->jpeg.begin(), frame->jpeg.end()), "image/jpeg");
}

void handle_frame(FrameQueue& queue, const ServedInfo& served, const httplib::Request& req,
                  httplib::Response& res) {
  ViewState state;
  try {
    // The raw query, not httplib's lenient parse (which keeps `w=abc=480` as w=480 and splits
    // on ';').
    const std::size_t mark = req.target.find('?');
    const std::string raw = mark == std::string::npos ? "" : req.target.substr(mark + 1);
    state = parse_view_request(parse_query(raw), served.limits, served.defaults);
  } catch (const RequestError& e) {
    res.status = 400;
    res.set_content(std::string(e.what()) + "\n", "text/plain");
    return;
  }
  try {
    send_frame(queue.submit(state).get(), res);
  } catch (const QueueRefused& e) {
    res.status = 503;
    res.set_content(std::string(e.what()) + "\n", "text/plain");
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

void refuse(httplib::Response& res, int status, const std::string& why) {
  res.status = status;
  res.set_content(why + "\n", "text/plain");
}

void add_routes(httplib::Server& server, FrameQueue& queue, const ServedInfo& served) {
  server.Get("/", [](const httplib::Request&, httplib::Response& res) {
    res.set_content(view_page_html(), "text/html; charset=utf-8");
  });
  // Browsers ask for it on every page load; no icon, and no 404 in their console.
  server.Get("/favicon.ico",
             [](const httplib::Request&, httplib::Response& res) { res.status = 204; });
  const std::string info = dump_json(served.info);
  server.Get("/api/info", [info](const httplib::Request&, httplib::Response& res) {
    res.set_content(info, "application/json");
  });
  server.Get("/frame", [&queue, &served](const httplib::Request& req, httplib::Response& res) {
    handle_frame(queue, served, req, res);
  });
  // Every path is read-only: other methods are 405 (httplib would answer 404).
  const auto not_allowed = [](const httplib::Request& req, httplib::Response& res) {
    res.set_header("Allow", "GET, HEAD");
    refuse(res, 405, req.method + " is not allowed; prtr view answers GET");
  };
  server.Post(".*", not_allowed);
  server.Put(".*", not_allowed);
  server.Patch(".*", not_allowed);
  server.Delete(".*", not_allowed);
  server.Options(".*", not_allowed);
  server.set_error_handler([](const httplib::Request&, httplib::Response& res) {
    if (res.body.empty())
      res.set_content(res.status == 404 ? "not found\n" : "bad request\n", "text/plain");
  });
  server.set_exception_handler(
      [](const httplib::Request&, httplib::Response& res, std::exception_ptr ep) {
        res.status = 500;
        try {
          std::rethrow_exception(ep);
        } catch (const std::exception& e) {
          res.set_content(std::string("internal error: ") + e.what() + "\n", "text/plain");
        } catch (...) {
          res.set_content("internal error\n", "text/plain");
        }
      });
}

int bind(httplib::Server& server, const ServerOptions& options) {
  const int port = options.port == 0
                       ? server.bind_to_any_port(options.host)
                       : (server.bind_to_port(options.host, options.port) ? options.port : -1);
  if (port <= 0)
    throw std::runtime_error("prtr view: cannot listen on " + options.host + ":" +
                             std::to_string(options.port) +
                             " (in use, or not an address of this machine); choose another "
                             "--port or --host");
  return port;
}

// The render loop: one job at a time until the queue stops.
void render_jobs(ViewScene& scene, FrameQueue& queue) {
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
  return Json{{"seq", s.seq},
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

void serve_view(ViewScene& scene, const ServedInfo& served, const ServerOptions& options) {
  FrameQueue queue;
  httplib::Server server;
  const auto connections = std::size_t(options.max_connections);
  server.new_task_queue = [connections] {
    return new detail::ConnectionThreads(connections, std::chrono::milliseconds(500));
  };
  // Headers and body go out in separate writes: with Nagle's algorithm the body waits for
  // the client's delayed ACK (~40 ms on Linux), longer than a small frame takes to render.
  server.set_tcp_nodelay(true);
  // SO_REUSEADDR only (a restart need not wait out TIME_WAIT). httplib's default adds
  // SO_REUSEPORT, with which a second viewer binds the same port and takes half the requests.
  server.set_socket_options([](socket_t sock) {
    int yes = 1;
    setsockopt(sock, SOL_SOCKET, SO_REUSEADDR, &yes, sizeof yes);
  });
  add_routes(server, queue, served);
  const int port = bind(server, options);
  server.set_pre_routing_handler([&options, port](const httplib::Request& req,
                                                  httplib::Response& res) {
    if (allowed_host(req.get_header_value("Host"), options, port))
      return httplib::Server::HandlerResponse::Unhandled;
    refuse(res, 421,
           "Host '" + req.get_header_value("Host") + "' is not this server; use " + options.host +
               ":" + std::to_string(port) + " or localhost:" + std::to_string(port));
    return httplib::Server::HandlerResponse::Handled;
  });
  StopSignals signals;
  std::printf("prtr view: http://%s:%d/\n", options.host.c_str(), port);
  std::fflush(stdout);
  std::atomic<bool> listening_ended{false};
  std::thread http([&] {
    server.listen_after_bind();
    listening_ended = true;
  });
  std::thread watcher([&] {
    signals.wait();
    queue.stop();
    server.stop();
  });
  render_jobs(scene, queue);
  // stop() does nothing before listening has begun, so repeat it until the loop has ended.
  while (!listening_ended) {
    server.stop();
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  signals.wake();  // the watcher, when the loop ended without a signal
  watcher.join();
  http.join();
  const FrameQueue::Counters c = queue.counters();
  std::printf("prtr view: stopped after %llu frame requests (%llu coalesced)\n",
              static_cast<unsigned long long>(c.requests),
              static_cast<unsigned long long>(c.coalesced));
}

}  // namespace viewer

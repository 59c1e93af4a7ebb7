// viewer/server.h: the HTTP side of `prtr view` (its own HTTP/1.1 server in
// viewer/src/http_server.h: keep-alive, pipelined requests answered in order, half-closed
// requests answered). Routes: GET / (the page), GET /api/info (what does not change, JSON),
// GET /frame?... (a JPEG of the state the query describes, viewer/request.h; its statistics in
// the X-Prtr-Frame header as JSON), GET /favicon.ico (204); HEAD on each. Anything else is
// 404, another method 405 (501 for one HTTP does not define), a Host other than the listening
// address or localhost 421 (DNS rebinding); a bad query is 400 with a one-line reason
// (viewer/request.h, parsed from the raw query); 503 while stopping. The port is bound
// exclusively: a second viewer on it fails to start. Request threads parse, queue
// (viewer/queue.h), wait and encode; the calling thread renders, since the GL context is
// current there.
#pragma once

#include "common/json.h"
#include "viewer/frame_source.h"
#include "viewer/request.h"

#include <string>

namespace viewer {

struct ServerOptions {
  std::string host = "127.0.0.1";
  int port = 8080;  // 0: any free port (the printed URL says which)
  // Connections served at once, each on its own thread (viewer/src/connection_threads.h);
  // past this, new ones wait. Enough for a few tabs, a load test's 50 clients and 20 slow ones.
  int max_connections = 128;
};

struct ServedInfo {
  common::Json info;  // /api/info
  ViewLimits limits;
  ViewState defaults;
};

// Prints "prtr view: http://HOST:PORT/" on stdout (flushed), then serves and renders (with
// `scene`, on the calling thread) until SIGINT or SIGTERM, and returns normally. Throws
// std::runtime_error when it cannot listen.
void serve_view(FrameSource& scene, const ServedInfo& served, const ServerOptions& options);

// The X-Prtr-Frame header of a frame: its state and timings.
common::Json frame_header(const RenderedFrame& frame);

}  // namespace viewer

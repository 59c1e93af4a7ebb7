// prtr view's request handling without a network: the query parser (every bad parameter is
// refused with a one-line reason naming it), the per-client queue (the newest request wins,
// coalesced requests share one frame, clients are served in turn), the JPEG path (the tone
// map against render::tone_map itself, a JPEG round trip through libjpeg-turbo's decoder),
// and the camera and environment a state asks for.
#include "viewer/compressions.h"
#include "viewer/encode.h"
#include "viewer/frame.h"
#include "viewer/queue.h"
#include "viewer/request.h"
#include "viewer/scene.h"

#include "meshes/procedural.h"
#include "render/image.h"

#include "difference.h"  // viewer/src: the difference view is private to the viewer

#include <gtest/gtest.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <future>
#include <numbers>
#include <random>
#include <stdexcept>
#include <thread>

namespace {

using viewer::FrameQueue;
using viewer::QueryParams;
using viewer::RequestError;
using viewer::ViewLimits;
using viewer::ViewState;

ViewLimits limits() {
  ViewLimits l;
  l.probe_count = 3;
  l.cluster_count = 16;
  l.uncompressed = false;
  l.max_clusters = 100;
  l.max_components = 12;
  l.launch_order = 4;  // glossy: 16 rows x 3 colours a term
  l.launch_components = 2;
  l.max_order = 8;
  return l;
}

TEST(ViewRequest, NoParametersGiveTheDefaults) {
  ViewState d;
  d.width = 320;
  d.probe = 2;
  const ViewState s = viewer::parse_view_request({}, limits(), d);
  EXPECT_EQ(s.width, 320);
  EXPECT_EQ(s.probe, 2);
  EXPECT_EQ(s.mode, render::Mode::kDecoupled);
}

TEST(ViewRequest, EveryParameterLandsInTheState) {
  const QueryParams q = {
      {"client", "tab-1_x"}, {"seq", "42"},         {"w", "640"},          {"h", "474"},
      {"env_yaw", "-30.5"},  {"env_pitch", "12"},   {"cam_yaw", "90"},     {"cam_pitch", "-45"},
      {"zoom", "1.5"},       {"mode", "multipass"}, {"strategy", "order"}, {"budget", "512"},
      {"cpp", "4"},          {"probe", "1"},        {"exposure", "-1.25"}, {"overlay", "overdraw"},
      {"aa", "2"},           {"clusters", "40"},    {"pcs", "3"},          {"order", "5"}};
  const ViewState s = viewer::parse_view_request(q, limits());
  EXPECT_EQ(s.client, "tab-1_x");
  EXPECT_EQ(s.seq, 42u);
  EXPECT_EQ(s.width, 640);
  EXPECT_EQ(s.height, 474);
  EXPECT_EQ(s.env_yaw, -30.5);
  EXPECT_EQ(s.env_pitch, 12);
  EXPECT_EQ(s.cam_yaw, 90);
  EXPECT_EQ(s.cam_pitch, -45);
  EXPECT_EQ(s.zoom, 1.5);
  EXPECT_EQ(s.mode, render::Mode::kMultipass);
  EXPECT_EQ(s.strategy, "order");
  EXPECT_EQ(s.register_budget, 512);
  EXPECT_EQ(s.clusters_per_pass, 4);
  EXPECT_EQ(s.probe, 1);
  EXPECT_EQ(s.exposure, -1.25);
  EXPECT_EQ(s.overlay, viewer::Overlay::kOverdraw);
  EXPECT_EQ(s.samples, 2);
  EXPECT_EQ(s.clusters, 40);
  EXPECT_EQ(s.pcs, 3);
  EXPECT_EQ(s.order, 5);
  EXPECT_EQ(q.size(), viewer::view_parameter_names().size());  // all of them were covered
}

TEST(ViewRequest, BadParametersAreRefusedNamingThem) {
  struct Case {
    QueryParams query;
    std::string named;
  };
  const std::vector<Case> cases = {
      {{{"bogus", "1"}}, "bogus"},
      {{{"w", "640"}, {"w", "320"}}, "w"},
      {{{"w", "0"}}, "w"},
      {{{"w", "99999"}}, "w"},
      {{{"h", "abc"}}, "h"},
      {{{"h", ""}}, "h"},
      {{{"w", " 64"}}, "w"},
      {{{"w", "64x"}}, "w"},
      {{{"w", "+64"}}, "w"},
      {{{"w", "4096"}, {"h", "4096"}}, "w x h"},
      {{{"env_yaw", "nan"}}, "env_yaw"},
      {{{"env_yaw", "NaN"}}, "env_yaw"},
      {{{"env_pitch", "inf"}}, "env_pitch"},
      {{{"env_yaw", "1e300"}}, "env_yaw"},
      {{{"env_yaw", "0x10"}}, "env_yaw"},
      {{{"cam_pitch", "90"}}, "cam_pitch"},
      {{{"zoom", "0"}}, "zoom"},
      {{{"zoom", "-1"}}, "zoom"},
      {{{"mode", "fast"}}, "mode"},
      {{{"mode", "uncompressed"}}, "mode"},  // no transfer set in these limits
      {{{"strategy", "best"}}, "strategy"},
      {{{"budget", "-1"}}, "budget"},
      {{{"budget", "99999999999"}}, "budget"},
      {{{"cpp", "17"}}, "cpp"},
      {{{"probe", "3"}}, "probe"},
      {{{"probe", "-1"}}, "probe"},
      {{{"probe", "../../etc/passwd"}}, "probe"},
      {{{"exposure", "nan"}}, "exposure"},
      {{{"exposure", "21"}}, "exposure"},
      {{{"overlay", "both"}}, "overlay"},
      {{{"client", "../x"}}, "client"},
      {{{"client", std::string(33, 'a')}}, "client"},
      {{{"client", ""}}, "client"},
      {{{"seq", "-1"}}, "seq"},
      {{{"aa", "0"}}, "aa"},
      {{{"aa", "5"}}, "aa"},
      {{{"aa", "4"}, {"w", "4096"}, {"h", "2048"}}, "aa=4"},
  };
  for (const Case& c : cases) {
    try {
      viewer::parse_view_request(c.query, limits());
      ADD_FAILURE() << "accepted " << c.query.begin()->first << "=" << c.query.begin()->second;
    } catch (const RequestError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(c.named), std::string::npos) << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
      EXPECT_LT(what.size(), 200u) << what;
    }
  }
}

TEST(ViewRequest, PassesMustFitInThePagesWords) {
  // 120 registers a cluster, 4096 in the context: the page is told what would fit, by name.
  ViewLimits l = limits();
  l.registers_per_cluster = 120;
  l.max_register_budget = 4096;
  const auto refusal = [&](const QueryParams& q) {
    try {
      viewer::parse_view_request(q, l);
    } catch (const RequestError& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  EXPECT_EQ(refusal({{"budget", "100"}}),
            "budget=100: below one cluster's 120 registers; use 0 (the context's 4096) or 120 to "
            "4096");
  EXPECT_EQ(refusal({{"budget", "240"}, {"cpp", "3"}}),
            "cpp=3: 2 clusters fit the budget of 240 registers; use 0 (all that fit) or 1 to 2");
  EXPECT_EQ(refusal({{"budget", "5000"}}).rfind("budget=", 0), 0u);
  EXPECT_EQ(refusal({{"budget", "240"}, {"cpp", "2"}}), "(accepted)");
  EXPECT_EQ(refusal({{"cpp", "16"}}), "(accepted)");  // 34 fit the context's budget
}

TEST(ViewRequest, OtherCompressionsAreBoundedAndPriceTheirPasses) {
  const auto refusal = [](const QueryParams& q, const ViewLimits& l) {
    try {
      viewer::parse_view_request(q, l);
    } catch (const RequestError& e) {
      return std::string(e.what());
    }
    return std::string("(accepted)");
  };
  ViewLimits l = limits();
  EXPECT_EQ(refusal({{"clusters", "101"}}, l).rfind("clusters=", 0), 0u);
  EXPECT_EQ(refusal({{"pcs", "13"}}, l).rfind("pcs=", 0), 0u);
  EXPECT_EQ(refusal({{"clusters", "0"}, {"pcs", "0"}}, l), "(accepted)");  // the launch's
  // A pass holds at most the asked-for clusters, not the launch's 16.
  EXPECT_EQ(refusal({{"clusters", "40"}, {"cpp", "30"}}, l), "(accepted)");
  EXPECT_EQ(refusal({{"cpp", "30"}}, l).rfind("cpp=", 0), 0u);
  // One cluster of 3 PCs costs (3 + 1) x 48 / 4 = 48 registers: 2 fit a budget of 100.
  l.max_register_budget = 4096;
  EXPECT_EQ(refusal({{"pcs", "3"}, {"budget", "100"}, {"cpp", "3"}}, l),
            "cpp=3: 2 clusters fit the budget of 100 registers; use 0 (all that fit) or 1 to 2");
  EXPECT_EQ(refusal({{"pcs", "3"}, {"budget", "100"}, {"cpp", "2"}}, l), "(accepted)");
  // Another SH order prices a term at its own rows: order 4 has 3 x 16 = 48 floats a term,
  // so the launch's 3 PCs cost 48 registers at order 4 where the budget of 100 fits 2.
  l.launch_order = 6;
  l.launch_components = 3;
  l.max_order = 8;
  EXPECT_EQ(refusal({{"order", "4"}, {"budget", "100"}, {"cpp", "3"}}, l),
            "cpp=3: 2 clusters fit the budget of 100 registers; use 0 (all that fit) or 1 to 2");
  EXPECT_EQ(refusal({{"order", "4"}, {"budget", "100"}, {"cpp", "2"}}, l), "(accepted)");
  EXPECT_EQ(refusal({{"order", "9"}}, l).rfind("order=", 0), 0u);
  EXPECT_EQ(refusal({{"order", "0"}}, l), "(accepted)");
  // A viewer without other compressions takes only the launch's.
  l.max_clusters = l.max_components = l.max_order = 0;
  EXPECT_EQ(refusal({{"clusters", "0"}}, l), "(accepted)");
  EXPECT_EQ(refusal({{"clusters", "8"}}, l),
            "clusters='8': this viewer offers only its launch compression");
}

// A compression made on request: the launch's is shown until the new one is ready, then the
// new one; a failure is reported and leaves the shown one; the launch's is one request away.
TEST(ViewCompressions, TheOldOneIsShownUntilTheNewOneIsReady) {
  cpca::CompressedSet launch;
  launch.cluster_count = 16;
  launch.component_count = 4;
  launch.order = 6;
  std::promise<void> release;
  std::shared_future<void> gate = release.get_future().share();
  std::atomic<int> made{0};
  viewer::Compressions c(
      {launch, "launch.prtx"}, [&](int clusters, int pcs, int order, const auto& progress) {
        progress(0.5);
        gate.wait();
        if (clusters == 7) throw std::runtime_error("7 clusters refused");
        ++made;
        cpca::CompressedSet s;
        s.cluster_count = clusters;
        s.component_count = pcs;
        s.order = order;
        // Another order comes from another bake.
        return viewer::Compression{s, order == 6 ? "launch.prtx" : "order" + std::to_string(order)};
      });
  viewer::CompressionStatus st = c.choose(8, 0);
  EXPECT_TRUE(st.pending);
  EXPECT_EQ(st.shown->cluster_count, 16);
  const auto wait_ready = [&](int clusters, int pcs, int order = 0) {
    for (int i = 0; i < 2000; ++i) {
      st = c.choose(clusters, pcs, order);
      if (!st.pending) return;
      std::this_thread::sleep_for(std::chrono::milliseconds(5));
    }
    FAIL() << "not ready in 10 s";
  };
  for (int i = 0; i < 200 && st.progress < 0.5; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(5));
    st = c.choose(8, 0);
  }
  EXPECT_EQ(st.progress, 0.5);
  EXPECT_EQ(st.shown->cluster_count, 16);  // still the launch's
  release.set_value();
  wait_ready(8, 0);
  EXPECT_EQ(st.shown->cluster_count, 8);
  EXPECT_EQ(st.shown->component_count, 4);  // pcs 0: the launch's
  wait_ready(7, 2);
  EXPECT_EQ(st.error, "7 clusters refused");
  EXPECT_EQ(st.shown->cluster_count, 8);  // the failure leaves the shown one
  st = c.choose(0, 0);
  EXPECT_FALSE(st.pending);
  EXPECT_EQ(st.shown->cluster_count, 16);
  EXPECT_EQ(st.transfer, "launch.prtx");
  st = c.choose(8, 4);  // made once, kept
  EXPECT_FALSE(st.pending);
  EXPECT_EQ(made.load(), 1);
  // Another SH order is another compression, with its own bake; the launch's order is 0's.
  wait_ready(8, 4, 3);
  EXPECT_EQ(st.shown->order, 3);
  EXPECT_EQ(st.transfer, "order3");
  EXPECT_EQ(made.load(), 2);
  st = c.choose(8, 4, 6);
  EXPECT_FALSE(st.pending);
  EXPECT_EQ(st.shown->order, 6);
  EXPECT_EQ(made.load(), 2);
}

TEST(ViewRequest, RawQueriesAreSplitStrictly) {
  const QueryParams q = viewer::parse_query("w=480&mode=cpu&client=a%2Db&probe=1+");
  const QueryParams expected{{"w", "480"}, {"mode", "cpu"}, {"client", "a-b"}, {"probe", "1 "}};
  EXPECT_EQ(q, expected);
  EXPECT_TRUE(viewer::parse_query("").empty());
  // Each malformed query is refused with a one-line reason naming what is wrong.
  const std::pair<std::string, std::string> bad[] = {
      {"w=abc=480", "'=' in its value"},
      {"mode=bogus=cpu", "'=' in its value"},
      {"w=960;h=710", "';'"},
      {"w=480&w=480", "repeated"},
      {"client=a&client=a", "repeated"},
      {"w", "no value"},
      {"w=1&&h=2", "empty parameter"},
      {"w=1&", "empty parameter"},
      {"w=%zz", "%-escape"},
      {"w=%4", "%-escape"},
  };
  for (const auto& [query, reason] : bad) {
    try {
      viewer::parse_query(query);
      ADD_FAILURE() << "accepted " << query;
    } catch (const RequestError& e) {
      const std::string what = e.what();
      EXPECT_NE(what.find(reason), std::string::npos) << query << ": " << what;
      EXPECT_EQ(what.find('\n'), std::string::npos) << what;
    }
  }
}

TEST(ViewRequest, UncompressedIsAcceptedWhenTheTransferIsAtHand) {
  ViewLimits l = limits();
  l.uncompressed = true;
  EXPECT_EQ(viewer::parse_view_request({{"mode", "uncompressed"}}, l).mode,
            render::Mode::kUncompressed);
}

ViewState state_of(const std::string& client, std::uint64_t seq, double yaw = 0) {
  ViewState s;
  s.client = client;
  s.seq = seq;
  s.env_yaw = yaw;
  return s;
}

std::shared_ptr<viewer::RenderedFrame> frame_for(const ViewState& s) {
  auto f = std::make_shared<viewer::RenderedFrame>();
  f->state = s;
  return f;
}

TEST(ViewDifference, RelativeLuminanceAgainstTheReference) {
  // 4 x 1: background, a pixel 5 % too bright, one exact, one dark pixel under the floor.
  render::Image reference{4, 1, {0, 0, 0, 0, 1, 1, 1, 1, 2, 2, 2, 1, 0, 0, 0, 1}};
  render::Image test = reference;
  for (int c = 0; c < 3; ++c) test.rgba[4 + c] = 1.05f;
  test.rgba[12] = 0.01f;  // red only: luminance 0.2126 x 0.01
  const render::Colour8 key{255, 0, 255};
  viewer::detail::DifferenceStats d;
  const render::Picture p = viewer::detail::difference_picture(test, reference, 0.1, key, &d);
  EXPECT_EQ(p.at(0, 0), key);                                     // background stays see-through
  EXPECT_EQ(p.at(1, 0), viewer::detail::difference_colour(0.5));  // 5 % of a 10 % scale
  EXPECT_EQ(p.at(2, 0), viewer::detail::difference_colour(0.0));
  // Floor: 1 % of the mean reference luminance over the 3 covered pixels, (1 + 2 + 0) / 3.
  const double dark = 0.2126 * 0.01 / 0.01;
  EXPECT_NEAR(d.max, dark, 1e-6);
  EXPECT_NEAR(d.rms, std::sqrt((0.05 * 0.05 + dark * dark) / 3), 1e-6);
  EXPECT_THROW(viewer::detail::difference_picture(test, render::Image{2, 1, std::vector<float>(8)},
                                                  0.1, key),
               std::invalid_argument);
}

TEST(ViewQueue, NewerRequestsOfAClientReplaceTheWaitingOneAndShareItsFrame) {
  FrameQueue q;
  auto first = q.submit(state_of("a", 1, 10));
  auto second = q.submit(state_of("a", 2, 20));
  auto late_old = q.submit(state_of("a", 1, 99));  // overtaken on another connection
  EXPECT_EQ(q.waiting(), 1u);
  std::optional<FrameQueue::Job> job = q.take();
  ASSERT_TRUE(job);
  EXPECT_EQ(job->state.seq, 2u);
  EXPECT_EQ(job->state.env_yaw, 20);
  EXPECT_EQ(job->requests, 3);
  job->promise.set_value(frame_for(job->state));
  for (auto* f : {&first, &second, &late_old}) EXPECT_EQ(f->get()->state.seq, 2u);
  EXPECT_EQ(q.counters().coalesced, 2u);
  // Once taken, the next request is a new job.
  auto third = q.submit(state_of("a", 3));
  EXPECT_EQ(q.waiting(), 1u);
  EXPECT_EQ(q.take()->state.seq, 3u);
}

TEST(ViewQueue, ClientsAreServedInTurnAndKeepTheirPlace) {
  FrameQueue q;
  q.submit(state_of("a", 1));
  q.submit(state_of("b", 1));
  q.submit(state_of("a", 2));  // coalesced: a keeps its place ahead of b
  q.submit(state_of("c", 1));
  EXPECT_EQ(q.take()->state.client, "a");
  q.submit(state_of("a", 3));  // a new job, behind b and c
  EXPECT_EQ(q.take()->state.client, "b");
  EXPECT_EQ(q.take()->state.client, "c");
  const auto last = q.take();
  EXPECT_EQ(last->state.client, "a");
  EXPECT_EQ(last->state.seq, 3u);
}

TEST(ViewQueue, RefusesTooManyClientsAndFailsWaitersOnStop) {
  FrameQueue q(2);
  auto a = q.submit(state_of("a", 1));
  auto b = q.submit(state_of("b", 1));
  EXPECT_THROW(q.submit(state_of("c", 1)), viewer::QueueRefused);
  EXPECT_NO_THROW(q.submit(state_of("a", 2)));  // a waiting client may still coalesce
  q.stop();
  EXPECT_THROW(a.get(), viewer::QueueRefused);
  EXPECT_THROW(b.get(), viewer::QueueRefused);
  EXPECT_FALSE(q.take());
  EXPECT_THROW(q.submit(state_of("a", 3)), viewer::QueueRefused);
}

// Four clients submit as fast as they can while one thread renders: every request gets a
// frame of its own client, never older than itself.
TEST(ViewQueue, ConcurrentClientsEachGetTheirNewestFrame) {
  FrameQueue q;
  std::thread renderer([&] {
    while (auto job = q.take()) job->promise.set_value(frame_for(job->state));
  });
  std::vector<std::thread> clients;
  std::atomic<int> answered{0}, wrong{0};
  for (int c = 0; c < 4; ++c)
    clients.emplace_back([&, c] {
      const std::string id = "client" + std::to_string(c);
      for (std::uint64_t seq = 1; seq <= 200; ++seq) {
        const viewer::FramePtr f = q.submit(state_of(id, seq)).get();
        if (f->state.client != id || f->state.seq < seq) ++wrong;
        ++answered;
      }
    });
  for (auto& t : clients) t.join();
  q.stop();
  renderer.join();
  EXPECT_EQ(answered.load(), 800);
  EXPECT_EQ(wrong.load(), 0);
}

TEST(ViewEncode, ToneMapMatchesRenderToneMapExactly) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> log_value(-12.f, 8.f);
  for (double exposure : {0.0, -2.5, 3.0}) {
    render::Image image;
    image.width = 256;
    image.height = 64;
    image.rgba.resize(std::size_t(image.width) * image.height * 4);
    for (std::size_t i = 0; i < image.rgba.size(); ++i)
      image.rgba[i] = i % 97 == 0 ? -1.f : std::exp2(log_value(rng));
    const std::vector<std::uint8_t> rgb = render::tone_map_rgb8(image, exposure);
    int mismatches = 0;
    for (std::size_t p = 0; p < std::size_t(image.width) * image.height; ++p)
      for (int c = 0; c < 3; ++c) {
        const auto expected =
            std::uint8_t(std::lround(255.f * render::tone_map(image.rgba[p * 4 + c], exposure)));
        mismatches += rgb[p * 3 + c] != expected;
      }
    EXPECT_EQ(mismatches, 0) << "exposure " << exposure;
  }
}

TEST(ViewEncode, JpegRoundTripAndOverlay) {
  const int w = 64, h = 48;
  std::vector<std::uint8_t> rgb(std::size_t(w) * h * 3);
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      std::uint8_t* p = &rgb[(std::size_t(y) * w + x) * 3];
      p[0] = std::uint8_t(x * 4);
      p[1] = std::uint8_t(y * 5);
      p[2] = 128;
    }
  render::Picture overlay(w, h, viewer::kOverlayTransparent);
  overlay.set(10, 10, {0, 0, 0});
  std::vector<std::uint8_t> mixed = rgb;
  viewer::composite_overlay(mixed, w, h, overlay, 0.5);
  EXPECT_EQ(mixed[(10 * w + 10) * 3 + 2], 64);  // half of 128 over black
  mixed[(10 * w + 10) * 3 + 0] = rgb[(10 * w + 10) * 3 + 0];
  mixed[(10 * w + 10) * 3 + 1] = rgb[(10 * w + 10) * 3 + 1];
  mixed[(10 * w + 10) * 3 + 2] = rgb[(10 * w + 10) * 3 + 2];
  EXPECT_EQ(mixed, rgb);  // every transparent pixel untouched

  const std::vector<std::uint8_t> jpeg = viewer::encode_jpeg(rgb, w, h, 90);
  ASSERT_GT(jpeg.size(), 4u);
  EXPECT_EQ(jpeg[0], 0xFF);
  EXPECT_EQ(jpeg[1], 0xD8);
  int dw = 0, dh = 0;
  const std::vector<std::uint8_t> back = viewer::decode_jpeg(jpeg, dw, dh);
  EXPECT_EQ(dw, w);
  EXPECT_EQ(dh, h);
  double error = 0;
  for (std::size_t i = 0; i < rgb.size(); ++i) error += std::abs(int(back[i]) - int(rgb[i]));
  EXPECT_LT(error / double(rgb.size()), 3.0);
  EXPECT_THROW(viewer::encode_jpeg(rgb, w + 1, h), std::invalid_argument);
}

TEST(ViewCamera, OrbitAndZoomMoveTheEyeAboutTheTarget) {
  const meshes::Mesh mesh = meshes::make_sphere(1.f, 16, 8);
  const render::CameraPlacement flags;
  ViewState s;
  s.width = 64;
  s.height = 48;
  const render::Camera base = viewer::view_camera(flags, mesh, s);
  EXPECT_EQ(base.width, 64);
  const double distance = (base.eye - base.target).norm();
  s.zoom = 2;
  const render::Camera closer = viewer::view_camera(flags, mesh, s);
  EXPECT_NEAR((closer.eye - closer.target).norm(), distance / 2, 1e-9);
  s.zoom = 1;
  s.cam_yaw = 90;
  const render::Camera side = viewer::view_camera(flags, mesh, s);
  // The default camera looks down -Z; a quarter turn about +Y looks down -X.
  const Eigen::Vector3d forward = (side.target - side.eye).normalized();
  EXPECT_NEAR(forward.x(), -1.0, 1e-9);
  EXPECT_NEAR((side.eye - side.target).norm(), distance, 1e-9);
  EXPECT_NO_THROW(side.validate());
  const Eigen::Matrix3d none = viewer::environment_rotation(Eigen::Vector3d::UnitY(), ViewState{});
  EXPECT_TRUE(none.isApprox(Eigen::Matrix3d::Identity()));
  ViewState turned;
  turned.env_yaw = 90;
  const Eigen::Matrix3d r = viewer::environment_rotation(Eigen::Vector3d::UnitY(), turned);
  EXPECT_TRUE((r * Eigen::Vector3d::UnitZ()).isApprox(Eigen::Vector3d::UnitX(), 1e-12));
}

}  // namespace
